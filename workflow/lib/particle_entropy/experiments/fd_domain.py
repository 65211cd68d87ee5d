"""Controlled experiment behind Fig. 8's late error rise: the implicit FD of Section 6.1 with one
setting changed (domain length at the same dx, time step, or the reference of the SSE, Eq. 44).

The paper's run holds the end nodes of [-6, 6] at zero. The Gaussian's standard deviation
sqrt(2 D t) reaches 1.41 at t = 1000, so the ends sit at 4.2 standard deviations: they absorb
mass (2 erfc(3) = 4.4e-5 by t = 1000) and pull the solution to zero near x = +-6, where the free
Gaussian reference is not zero. From t ~ 800 that misfit exceeds the fine grids' own (time-step)
error, their SSE rises and COMIC's optimum moves to a coarser grid. ``domain_experiment`` measures it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np

from ..core import measures as M
from ..core.case import SettingError
from ..core.runconfig import FD_MIN_INTERVALS, RunConfig
from ..core.settings import PAPER

if TYPE_CHECKING:  # pandas and the FD model (numba) load when the experiment runs, not when a config is checked
    import pandas as pd

REFERENCES = ("unit", "exact", "fd_mass", "images")
DEFAULT_TIMES = tuple(float(t) for t in range(100, 1001, 50))


def gaussian(x: np.ndarray, D: float, t: float) -> np.ndarray:
    """Free-space solution from a unit delta, exp(-x^2 / 4Dt) / sqrt(4 pi D t) (the Gaussian of Eq. 14)."""
    var = 2.0 * D * t
    return np.exp(-0.5 * x * x / var) / math.sqrt(2.0 * math.pi * var)


def _mass_on_domain(x: np.ndarray, D: float, t: float, dx: float) -> float:
    """Share of the sampled Gaussian's sum over the infinite lattice k dx on the nodes ``x``."""
    var = 2.0 * D * t
    inside = np.exp(-0.5 * x * x / var).sum()
    beyond = float(x.max()) + dx * np.arange(1, math.ceil(12.0 * math.sqrt(var) / dx) + 2)
    outside = 2.0 * np.exp(-0.5 * beyond * beyond / var).sum()
    return float(inside / (inside + outside))


def reference(
    x: np.ndarray, D: float, t: float, dx: float, length: float, kind: str = "unit", mass: float = 1.0
) -> np.ndarray:
    """Reference of the SSE (Eq. 44) at the nodes ``x`` of [-length/2, length/2].

    ``unit``: the paper's, the Gaussian N(0, 2 D t) sampled and normalised to unit mass on the nodes;
    ``exact``: the same with the sampled Gaussian's own mass on the domain (normalised over the
    nodes k dx of the whole line instead: the mass beyond +-length/2 is not put back inside);
    ``fd_mass``: the ``unit`` one scaled to ``mass`` (the FD's own mass);
    ``images``: the exact solution with zero concentration at x = +-length/2, the ``exact``
    Gaussian plus its images, sum_k (-1)^k G(x - k length), |k| <= 2.
    """
    if kind not in REFERENCES:
        raise ValueError(f"reference must be one of {', '.join(REFERENCES)}, got {kind!r}")
    g = M.analytic_sampled(x, D, t, dx)
    if kind == "fd_mass":
        return g * mass
    if kind in ("exact", "images") and D * t > 0:
        g = g * _mass_on_domain(x, D, t, dx)
        if kind == "images":
            for k in (-2, -1, 1, 2):
                g = g + (-1) ** k * gaussian(x - k * length, D, t)
    return g


def grid_intervals(n: int, length: float, ref_length: float) -> int:
    """Intervals on a domain of ``length`` at the spacing dx = ref_length / n of grid n; SettingError
    (named `n`) unless an even whole number >= FD_MIN_INTERVALS (4), so that a node sits at x = 0
    with an interior node either side (RunConfig.check)."""
    m = n * length / ref_length
    whole = math.isfinite(m) and abs(m - round(m)) <= 1e-9 * max(1.0, abs(m))
    if not whole or round(m) < FD_MIN_INTERVALS or round(m) % 2:
        raise SettingError(
            "n",
            n,
            f"a grid whose dx = {ref_length:g} / n fits an even whole number (>= {FD_MIN_INTERVALS}) of times in "
            f"{length:g}",
        )
    return int(round(m))


def _report_steps(times: Iterable[float], dt: float) -> np.ndarray:
    steps = np.asarray([t / dt for t in times], dtype=np.float64)
    k = np.rint(steps).astype(np.int64)
    if np.any(np.abs(steps - k) > 1e-6) or np.any(k < 0):
        raise ValueError(f"report times must be whole multiples of the step {dt}")
    return k


def run_case(
    n: int,
    fd_length: float = PAPER["fd_length"],
    fd_dt: float = PAPER["fd_dt"],
    times: Iterable[float] = DEFAULT_TIMES,
    D: float = PAPER["D"],
    ref_length: float = PAPER["fd_length"],
    references: Iterable[str] = ("unit",),
    x_edge: float = 4.0,
) -> list[dict]:
    """Implicit FD (backward Euler, fd.ImplicitSolver) of grid ``n`` (dx = ref_length / n) on
    [-fd_length/2, fd_length/2] with zero end nodes; the measures at ``times`` per reference."""
    from ..models import fd

    n_int = grid_intervals(n, fd_length, ref_length)
    cfg = RunConfig.of(method="fd", kernel="implicit", n=n_int, D=D, fd_length=fd_length, dt0=fd_dt).resolved()
    x, dx = fd.grid(cfg)
    c = fd.initial_concentration(cfg)
    solver = fd.ImplicitSolver(n_int - 1, D * fd_dt / dx**2)
    edge = np.abs(x) > x_edge
    steps = _report_steps(times, fd_dt)
    order = np.argsort(steps)
    rows = []
    done = 0
    for k in steps[order]:
        for _ in range(k - done):
            c[1:-1] = solver.solve(c[1:-1])
        done = k
        t = k * fd_dt
        mass = float(c.sum() * dx)
        for kind in references:
            d = c - reference(x, D, t, dx, fd_length, kind, mass)
            d2 = d * d
            sse = float(d2.sum())
            rows.append(
                {
                    "n": int(n),
                    "n_intervals": n_int,
                    "dx": dx,
                    "fd_length": float(fd_length),
                    "fd_dt": float(fd_dt),
                    "reference": kind,
                    "time": t,
                    "SSE": sse,
                    "n_sse": x.size,
                    "ln_SSE_over_N": math.log(sse / x.size) if sse > 0 else -math.inf,
                    "COMIC": M.comic(sse, x.size, dx),
                    "SSE_edge": float(d2[edge].sum()),
                    "edge_fraction": float(d2[edge].sum()) / sse if sse > 0 else 0.0,
                    "mass_total": mass,
                    "mass_loss": 1.0 - mass,
                    "max_abs_error": float(np.abs(d).max()),
                    "x_max_error": float(abs(x[np.argmax(np.abs(d))])),
                }
            )
    return rows


def domain_experiment(
    n_list: Iterable[int] = (1000, 3000, 10000),
    fd_lengths: Iterable[float] = (12.0, 24.0),
    fd_dts: Iterable[float] = (PAPER["fd_dt"],),
    times: Iterable[float] = DEFAULT_TIMES,
    D: float = PAPER["D"],
    ref_length: float = PAPER["fd_length"],
    references: Iterable[str] = ("unit",),
    x_edge: float = 4.0,
) -> pd.DataFrame:
    """Tidy table of SSE (Eq. 44), ln(SSE/N) and COMIC = -ln dx + 2 ln(SSE/N) (Eq. 43) and the FD
    mass, per grid n (dx = ref_length / n, fixed across lengths), domain length, step and time."""
    import pandas as pd

    times = tuple(times)
    references = tuple(references)
    rows = []
    for dt in fd_dts:
        for length in fd_lengths:
            for n in n_list:
                rows += run_case(n, length, dt, times, D, ref_length, references, x_edge)
    return pd.DataFrame(rows)


def comic_optimum(table: pd.DataFrame) -> pd.DataFrame:
    """Grid n of least COMIC (Eq. 43) per domain length, step, reference and time."""
    keys = ["fd_length", "fd_dt", "reference", "time"]
    best = table.loc[table.groupby(keys)["COMIC"].idxmin(), [*keys, "n", "COMIC"]]
    return best.reset_index(drop=True)
