"""Per-step result rows and the tidy table they make (column meanings in COLUMNS)."""

from __future__ import annotations

import resource
import sys
import time
from collections.abc import Callable

import pyarrow as pa

COLUMNS = {
    "step": "time-step index, 0 = initial condition",
    "time": "time at the end of the step [T]",
    "dt": "step size [T] (0 for step 0)",
    "H_D": "discrete entropy of the particle masses or node masses, Eq. 2 [nats]",
    "H_C": "consistent entropy with sampling volume dV, Eqs. 6-7 (PT: of the reconstruction) [nats]",
    "H_I": "inconsistent entropy H_C + ln dV, Eq. 3 [nats]",
    "H_PMF": "H_D + ln(Omega / N), Section 5.4 [nats]",
    "E": "dilution index dV exp(H_C), Eqs. 8-9 [L]",
    "H_C_analytic": "H_C of the Gaussian, Eq. 14, same dV; -inf at t = 0 [nats]",
    "E_analytic": "sqrt(4 pi e D t), Eq. 14 into Eq. 8 [L]",
    "SSE": "sum of squared errors against the sampled, normalised Gaussian, Eq. 44 [L^-2]",
    "n_sse": "number of points in SSE (particles, nodes or reconstruction points)",
    "AIC": "2 ln(SSE / n), Eq. 41 with k = 0",
    "COMIC": "2 ln(SSE / n) - ln dV, Eq. 43",
    "SSE_points": "SSE, Eq. 44, at the m = 15 measurement points common to all models (Section 6, point 1; "
    "measures.measurement_points): the model's concentration linearly interpolated there (FD nodes, MTPT "
    "m / dV at the particles, PT its reconstruction points; 0 outside them) against the exact Gaussian "
    "density; at t = 0 against the model's discrete delta, as SSE (measures.sse_points) [L^-2]",
    "COMIC_points": "2 ln(SSE_points / m) - ln dV, Eq. 43 at the measurement points (m = 15, dV as COMIC)",
    "dV": "sampling volume [L]",
    "mass_total": "total mass (1 at t = 0)",
    "mass_min": "smallest particle or node mass",
    "beta": "mass-transfer coefficient of the step, Eq. 20 (0: no transfer)",
    "h": "kernel width of the step: MTPT transfer kernel, PT reconstruction kernel or bin width, FD dx [L]",
    "substeps": "mass-transfer substeps taken to keep masses non-negative (1: none needed)",
    "settled": "t > dV^2 / (4 pi e D): the analytic H_C is meaningful (Section 3)",
    "work": "cumulative particle-steps (or FD node-steps) including mass-transfer substeps",
    "wall_s": "wall-clock seconds spent in the step (varies between identical runs)",
    "peak_rss_mb": "peak resident memory of the process so far [MB] (varies between machines and runs)",
}
TIMING_COLUMNS = ["wall_s", "peak_rss_mb"]


class Recorder:
    """Collects one row per step and times each step; reports progress through a callback."""

    def __init__(self, case: dict, n_steps: int, progress: Callable[[str], None] | None = None, size: int = 1):
        self.case = case
        self.size = size  # particles or nodes advanced per (sub)step
        self._work = 0
        self.rows: list[dict] = []
        self.n_steps = n_steps
        self.progress = progress
        self._t0 = time.perf_counter()
        self._last = self._t0
        self._last_report = self._t0

    def add(self, **row) -> None:
        now = time.perf_counter()
        row["wall_s"] = now - self._last
        row["peak_rss_mb"] = _peak_rss_mb()
        self._work += row.get("substeps", 1) * self.size if row["step"] > 0 else 0
        row["work"] = self._work
        self._last = now
        self.rows.append(row)
        if self.progress and (now - self._last_report > 5.0 or row["step"] == self.n_steps):
            self._last_report = now
            self.progress(f"step {row['step']}/{self.n_steps} t={row['time']:.6g} elapsed={now - self._t0:.1f}s")

    def table(self) -> pa.Table:
        """The rows as a table: COLUMNS' columns in its order, then the case's (no pandas, so that a
        simulation job need not import it)."""
        names = dict.fromkeys(k for row in self.rows for k in row)
        return arrow_table({k: [row.get(k) for row in self.rows] for k in names}, self.case, len(self.rows))


def arrow_table(columns: dict, constants: dict, length: int) -> pa.Table:
    """A table of ``columns`` (name -> values) and ``constants`` (name -> the value of every row,
    replacing a column of that name in place, else added after them), COLUMNS' names first in its
    order, then the others as given."""
    arrays = {k: pa.array(v) for k, v in columns.items()}
    for k, v in constants.items():
        arrays[k] = pa.nulls(length) if v is None else pa.array([v] * length)
    ordered = [c for c in COLUMNS if c in arrays]
    return pa.table({k: arrays[k] for k in ordered + [c for c in arrays if c not in COLUMNS]})


def _peak_rss_mb() -> float:
    """Peak resident set size of this process [MB] (ru_maxrss is in kB on Linux, bytes on macOS)."""
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / 2**20 if sys.platform == "darwin" else rss / 1024
