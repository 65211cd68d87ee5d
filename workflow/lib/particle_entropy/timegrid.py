"""Time stepping of the runs: a first step dt0 growing geometrically (or fixed) to t_final."""

from __future__ import annotations

import math

import numpy as np

MAX_STEPS = 10_000_000


def time_steps(t_final: float, dt0: float, growth: float) -> np.ndarray:
    """Step sizes dt_n = dt0 * growth**n, the last one shortened to end exactly at t_final.

    ``growth = 1`` gives a fixed step. A t_final shorter than dt0 gives one step of t_final.
    """
    if not (t_final > 0 and math.isfinite(t_final)):
        raise ValueError(f"t_final must be positive and finite, got {t_final!r}")
    if not (dt0 > 0 and math.isfinite(dt0)):
        raise ValueError(f"dt0 must be positive and finite, got {dt0!r}")
    if not (growth >= 1 and math.isfinite(growth)):
        raise ValueError(f"dt growth must be >= 1, got {growth!r}")
    if growth == 1.0:
        n = math.ceil(t_final / dt0 - 1e-9)
    else:
        # smallest n with dt0 (growth^n - 1)/(growth - 1) >= t_final
        n = math.ceil(math.log1p(t_final * (growth - 1) / dt0) / math.log(growth) - 1e-9)
    n = max(n, 1)
    if n > MAX_STEPS:
        raise ValueError(
            f"{n} time steps needed for t_final={t_final} with dt0={dt0}, growth={growth}; at most {MAX_STEPS} allowed"
        )
    dt = dt0 * growth ** np.arange(n, dtype=np.float64)
    t_before_last = float(np.cumsum(dt[:-1])[-1]) if n > 1 else 0.0  # same sums as times()
    if t_before_last >= t_final:  # round-off in n: the last step would vanish
        dt = dt[:-1]
        t_before_last = float(np.cumsum(dt[:-1])[-1]) if dt.size > 1 else 0.0
    dt[-1] = t_final - t_before_last  # exact end, no cancellation
    return dt


def times(dt: np.ndarray, t_final: float | None = None) -> np.ndarray:
    """Output times t_0 = 0, t_1, ..., t_n for step sizes ``dt``; t_n is set to ``t_final`` if given."""
    t = np.concatenate([[0.0], np.cumsum(dt)])
    if t_final is not None:
        t[-1] = t_final
    return t
