"""Per-step result rows and the tidy table they make (column order in COLUMNS; what each column
means: core/columns.py, which no simulation imports)."""

from __future__ import annotations

import resource
import sys
import time
from collections.abc import Callable

import numpy as np
import pyarrow as pa

# a run table's own columns, first in this order (their meanings: columns.RECORD_COLUMN_DOCS)
COLUMNS = (
    "step",
    "time",
    "dt",
    "H_D",
    "H_C",
    "H_I",
    "H_PMF",
    "E",
    "H_C_analytic",
    "E_analytic",
    "SSE",
    "n_sse",
    "AIC",
    "COMIC",
    "SSE_points",
    "COMIC_points",
    "dV",
    "mass_total",
    "mass_min",
    "mass_released",
    "mass_outflow",
    "beta",
    "h",
    "neighbours",
    "substeps",
    "settled",
    "work",
    "wall_s",
    "peak_rss_mb",
)
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
    arrays = {k: _array(v) for k, v in columns.items()}
    for k, v in constants.items():
        arrays[k] = pa.nulls(length) if v is None else _array([v] * length)
    ordered = [c for c in COLUMNS if c in arrays]
    return pa.table({k: arrays[k] for k in ordered + [c for c in arrays if c not in COLUMNS]})


def _array(values) -> pa.Array:
    """``pa.array(values)`` built from the values' buffers where they make a float64, int64, bool
    or str column without nulls (the types pa.array infers for them): pa.array itself imports
    pandas (0.2 s) to ask whether the values are a pandas object, and a simulation job has none."""
    a = np.asarray(values)
    if a.ndim != 1 or a.size == 0:  # pa.array makes an empty list a column of nulls
        return pa.array(values)
    if a.dtype in (np.float64, np.int64):
        return pa.Array.from_buffers(
            pa.from_numpy_dtype(a.dtype), a.size, [None, pa.py_buffer(np.ascontiguousarray(a))]
        )
    if a.dtype == np.bool_:
        bits = np.packbits(a, bitorder="little")
        return pa.Array.from_buffers(pa.bool_(), a.size, [None, pa.py_buffer(bits)])
    if a.dtype.kind == "U":
        data = [s.encode() for s in a.tolist()]
        offsets = np.zeros(a.size + 1, np.int32)
        np.cumsum([len(b) for b in data], out=offsets[1:])
        return pa.Array.from_buffers(pa.string(), a.size, [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(data))])
    return pa.array(values)  # anything else (nulls, mixed or other types): as pa.array infers it


def _peak_rss_mb() -> float:
    """Peak resident set size of this process [MB] (ru_maxrss is in kB on Linux, bytes on macOS)."""
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / 2**20 if sys.platform == "darwin" else rss / 1024
