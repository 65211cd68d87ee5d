"""Run one simulation and return its per-step table (and, on request, its final state)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from ..core import measures as M
from ..core.records import Recorder, arrow_table
from ..core.runconfig import RunConfig
from ..core.timegrid import time_steps, times
from .walk import walk

if TYPE_CHECKING:
    import pandas as pd


def _analytic_columns(cfg: RunConfig, t: float, dV: float) -> dict:
    ref = cfg.reference(t)
    return {
        "H_C_analytic": ref.h_c(dV),
        "E_analytic": ref.dilution(),
        "settled": bool(t > M.settling_time(dV, cfg.D)),
    }


def run_arrow(cfg: RunConfig, progress: Callable[[str], None] | None = None, want_state: bool = False):
    """Simulate ``cfg`` (defaults resolved and checked) -> (per-step Arrow table, final state or None)."""
    cfg = cfg.resolved()
    grid = "exact" if cfg.method == "fd" else cfg.time_grid
    dts = time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, grid)
    runner = {"pt": _run_pt, "mtpt": _run_mtpt, "fd": _run_fd}[cfg.method]
    warm_up(cfg)
    size = cfg.n + 1 if cfg.method == "fd" else cfg.n
    rec = Recorder(cfg.case_columns(), len(dts), progress, size=size)
    state = runner(cfg, dts, times(dts, cfg.t_final if grid == "exact" else None), rec)
    table = rec.table()
    if not want_state:
        return table, None
    length = len(next(iter(state.values())))
    return table, arrow_table({k: np.asarray(v) for k, v in state.items()}, cfg.case_columns(), length)


def run(cfg: RunConfig, progress: Callable[[str], None] | None = None, want_state: bool = False):
    """run_arrow as pandas tables: (per-step table, final state or None)."""
    table, state = run_arrow(cfg, progress, want_state)
    return table.to_pandas(), None if state is None else state.to_pandas()


_WARM: set = set()


def _model(method: str):
    """The module of a method, imported when a run needs it (a job loads only its own kernels)."""
    import importlib

    return importlib.import_module(f".{method}", __package__)


def warm_up(cfg: RunConfig) -> None:
    """Load the compiled kernels this case calls (numba's on-disk cache, ~0.05-0.4 s once per
    process) and what its exact solution is computed with before the timed steps, so that step 0's
    and step 1's wall times are the steps' own."""
    advection = cfg.advection if cfg.v != 0.0 else None  # FD in a flow: its scheme's solver
    key = (cfg.method, cfg.kernel, cfg.scheme, cfg.transfer_method, cfg.truncation is None, advection)
    if key not in _WARM:
        _model(cfg.method).warm_up(cfg)
        _WARM.add(key)
    if ("reference", cfg.source.kind) not in _WARM:
        cfg.source.warm_up()
        _WARM.add(("reference", cfg.source.kind))


def _row(rec: Recorder, cfg: RunConfig, step: int, t: float, dt: float, meas: dict) -> None:
    rec.add(step=step, time=t, dt=dt, **meas, **_analytic_columns(cfg, t, meas["dV"]))


def _run_pt(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rec: Recorder) -> dict:
    pt = _model("pt")
    rng = cfg.rng()
    x = np.sort(pt.initial_positions(cfg, rng))
    _row(rec, cfg, 0, 0.0, 0.0, pt.measure(cfg, x, 0.0))
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        x = np.sort(walk(x, cfg.D, dt, rng, cfg.v))
        _row(rec, cfg, k, t, dt, pt.measure(cfg, x, t))
    return pt.final_state(cfg, x, t)


def _run_mtpt(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rec: Recorder) -> dict:
    mtpt = _model("mtpt")
    rng, order_rng = cfg.rng(), cfg.rng(stream=1)
    x, m, label = mtpt.initial_state(cfg, rng)
    _row(rec, cfg, 0, 0.0, 0.0, {**mtpt.measure(cfg, x, m, 0.0), "beta": 0.0, "h": 0.0, "substeps": 1})
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        x, m, label, h, beta, sub = mtpt.step(cfg, x, m, label, dt, t, rng, order_rng)
        _row(rec, cfg, k, t, dt, {**mtpt.measure(cfg, x, m, t), "beta": beta, "h": h, "substeps": sub})
    dV = cfg.dV
    return {"x": x, "mass": m, "c": m / dV}


def _run_fd(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rec: Recorder) -> dict:
    fd = _model("fd")
    x, dx = fd.grid(cfg)
    c = fd.initial_concentration(cfg)
    extra = {"beta": 0.0, "h": dx, "substeps": 1}
    _row(rec, cfg, 0, 0.0, 0.0, {**fd.measure(cfg, x, c, dx, 0.0), **extra})
    solvers: dict = {}
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        if dt not in solvers:  # one factorisation per distinct step size (one for a fixed dt)
            solvers[dt] = fd.solver(cfg, dt, dx)
        c[1:-1] = solvers[dt].solve(c[1:-1])
        _row(rec, cfg, k, t, dt, {**fd.measure(cfg, x, c, dx, t), **extra})
    return {"x": x, "c": c}


def run_seeds_arrow(
    cfg: RunConfig, seeds, progress: Callable[[str], None] | None = None, state: bool = False
) -> pa.Table:
    """Run ``cfg`` for each seed and concatenate the per-step tables (or final states)."""
    parts = []
    for seed in seeds:
        if progress:
            progress(f"seed {seed}")
        table, final = run_arrow(replace(cfg, seed=int(seed)), progress=progress, want_state=state)
        parts.append(final if state else table)
    return pa.concat_tables(parts, promote_options="default")


def run_seeds(
    cfg: RunConfig, seeds, progress: Callable[[str], None] | None = None, state: bool = False
) -> pd.DataFrame:
    """run_seeds_arrow as a pandas table."""
    return run_seeds_arrow(cfg, seeds, progress, state).to_pandas()
