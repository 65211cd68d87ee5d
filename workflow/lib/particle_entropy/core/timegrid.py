"""Time stepping of the runs: a first step dt0 growing geometrically (or fixed) to t_final."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from .registry import TIME_GRIDS

MAX_STEPS = 10_000_000


def step_count(t_final: float, dt0: float, growth: float) -> int:
    """Steps from dt0 growing by ``growth`` to reach t_final (without building them). Exact
    arithmetic where the ratio t_final / dt0 overflows a float (1e308 / 0.01): the count is
    then refused by MAX_STEPS, never an OverflowError."""
    if growth == 1.0:
        ratio = t_final / dt0
        n = math.ceil(ratio - 1e-9) if math.isfinite(ratio) else math.ceil(Fraction(t_final) / Fraction(dt0))
    else:  # smallest n with dt0 (growth^n - 1)/(growth - 1) >= t_final
        ratio = t_final * (growth - 1) / dt0
        # log1p(ratio) = log(ratio) to round-off wherever ratio overflows (> 1e308)
        log_sum = (
            math.log1p(ratio) if math.isfinite(ratio) else math.log(t_final) + math.log(growth - 1) - math.log(dt0)
        )
        n = math.ceil(log_sum / math.log(growth) - 1e-9)
    return max(n, 1)


def count_text(n: int) -> str:
    """A step count as messages give it: 14,560, or about 10^311 where digits would fill the line."""
    return f"{n:,}" if n < 10**15 else f"about 10^{len(str(n)) - 1}"


def max_first_step(t_final: float, growth: float, steps: int = MAX_STEPS) -> float:
    """The smallest dt0 that reaches t_final in ``steps`` steps growing by ``growth`` (0 where it is
    below every float: growth^steps overflows)."""
    if growth == 1.0:
        return t_final / steps
    exponent = steps * math.log(growth)
    if exponent < 700.0:  # expm1 is finite
        return t_final * (growth - 1) / math.expm1(exponent)
    return math.exp(math.log(t_final) + math.log(growth - 1) - exponent)  # expm1 = exp to round-off


def time_steps(t_final: float, dt0: float, growth: float, grid: str = "exact") -> np.ndarray:
    """Step sizes dt_n = dt0 * growth**n up to t_final: ``exact`` shortens the last step to end at
    t_final; ``authors`` keeps whole steps while t < t_final, as the authors' loop (which ends
    past t_final: 175 steps, t = 1021.1 for the paper's settings).

    ``growth = 1`` gives a fixed step. A t_final shorter than dt0 gives one step of t_final
    (exact) or of dt0 (authors).
    """
    if grid not in TIME_GRIDS:
        raise ValueError(f"time grid must be one of {', '.join(TIME_GRIDS)}, got {grid!r}")
    if not (t_final > 0 and math.isfinite(t_final)):
        raise ValueError(f"t_final must be positive and finite, got {t_final!r}")
    if not (dt0 > 0 and math.isfinite(dt0)):
        raise ValueError(f"dt0 must be positive and finite, got {dt0!r}")
    if not (growth >= 1 and math.isfinite(growth)):
        raise ValueError(f"dt growth must be >= 1, got {growth!r}")
    n = step_count(t_final, dt0, growth)
    if n > MAX_STEPS:
        raise ValueError(
            f"{n} time steps needed for t_final={t_final} with dt0={dt0}, growth={growth}; at most {MAX_STEPS} allowed"
        )
    dt = dt0 * growth ** np.arange(n, dtype=np.float64)
    if grid == "authors":
        return _whole_steps(dt, t_final)
    t_before_last = float(np.cumsum(dt[:-1])[-1]) if n > 1 else 0.0  # same sums as times()
    if t_before_last >= t_final:  # round-off in n: the last step would vanish
        dt = dt[:-1]
        t_before_last = float(np.cumsum(dt[:-1])[-1]) if dt.size > 1 else 0.0
    dt[-1] = t_final - t_before_last  # exact end, no cancellation
    return dt


def _whole_steps(dt: np.ndarray, t_final: float) -> np.ndarray:
    """Steps taken while the clock, advanced step by step, is below t_final."""
    t = np.cumsum(dt)
    # n above may be one short or long by round-off: keep steps that start before t_final
    start = t - dt
    while start[-1] < t_final and t[-1] < t_final:
        dt = np.append(dt, dt[-1] * (dt[-1] / dt[-2] if dt.size > 1 else 1.0))
        t = np.cumsum(dt)
        start = t - dt
    return dt[start < t_final]


def times(dt: np.ndarray, t_final: float | None = None) -> np.ndarray:
    """Output times t_0 = 0, t_1, ..., t_n for step sizes ``dt``; t_n is set to ``t_final`` if given."""
    t = np.concatenate([[0.0], np.cumsum(dt)])
    if t_final is not None:
        t[-1] = t_final
    return t


def steps_growing_with_time(t_end: float, dt0: float, growth: float = 0.0, dt_max: float = math.inf) -> np.ndarray:
    """Step sizes reaching t_end exactly: dt0 while growth * t < dt0, then growth * t (steps that keep a
    fixed fraction of the time elapsed, as the segregation runs need), never above dt_max; the last one
    cut to land on t_end (time_steps grows each step by a factor instead)."""
    out, t = [], 0.0
    while t < t_end * (1.0 - 1e-12):
        dt = min(max(dt0, growth * t), dt_max, t_end - t)
        out.append(dt)
        t += dt
    return np.array(out)
