"""Run one candidate of a reactive scene (experiments/reactive.py): its transport, as the conservative
run does it (``cfg``, a RunConfig), with the scene's reaction after every step, to a per-step table.

- FD: every species carried by the case's own transport step on the fixed grid (models/fd.py), then
  every node reacted over dt by the closed-form kinetics (core/reactions.py): sequential
  non-iterative operator splitting, transport then reaction (Lie's order; Valocchi & Malmstead 1992;
  as RT3D reacts MT3D's nodes, Clement 1997).
- MTPT: the random walk with (1 - eta) D, then every species exchanged with eta D by one transfer
  matrix (Eq. 19; collision or SPH kernel), then every particle reacted over dt at its
  concentrations m / dV (Benson & Bolster 2016; Schmidt, Pankavich & Benson 2017).
- PT: each particle carries A's mass; a decay scales every mass by exp(-lambda dt) (exact, so C_A
  is the kernel reconstruction times the mass left). A + B -> C on particles needs separate A and
  B particles and a probabilistic pair reaction (Benson & Meerschaert 2008): models/reactive.py.

Every step's reaction balances to round-off (A + C and B + C keep their totals: check_reaction); no
mass goes negative, since the kinetics are exact. A row records the masses of A, B and the product
made so far; the last row also the errors against the reference: SSE of C_A at the scene's points
(SSE_points) and the product mass's relative error (product_error).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pyarrow as pa

from ..core import measures as M
from ..core.reactions import Reaction
from ..core.records import Recorder
from ..core.runconfig import RunConfig
from ..core.timegrid import time_steps, times
from .conservation import MassError

REACTION_ULPS = 64.0  # a reaction step's imbalance beyond this many ulps of its sums is no round-off


def check_reaction(before: float, after: float, made: float, t: float) -> None:
    """MassError unless a species' total fell by exactly the product ``made`` in a step, to round-off."""
    size = abs(before) + abs(after) + abs(made)
    tol = REACTION_ULPS * np.finfo(np.float64).eps * max(size, np.finfo(np.float64).tiny)
    if not abs(before - after - made) <= tol:
        raise MassError(f"a reaction step at t = {t:.6g} lost {before - after - made:.3g} (round-off {tol:.3g})")


def react(reaction: Reaction, a: np.ndarray, b: np.ndarray, volume, dt: float, t: float):
    """The masses a, b on nodes or particles of ``volume`` (dx or dV) after dt of the kinetics at their
    concentrations m / volume -> (a, b, product made per node or particle), balanced (check_reaction)."""
    a_new, b_new, made = reaction.kinetics.react(a / volume, b / volume, dt)
    a_new, b_new, made = a_new * volume, b_new * volume, made * volume
    total = float(made.sum())
    check_reaction(float(a.sum()), float(a_new.sum()), total, t)
    if reaction.kinetics.CONSUMES_B:
        check_reaction(float(b.sum()), float(b_new.sum()), total, t)
    return a_new, b_new, made


def _row(rec: Recorder, k: int, t: float, dt: float, a, b, made: float, volume: float, extra: dict) -> None:
    mass_a = float(a.sum())
    rec.add(
        step=k,
        time=t,
        dt=dt,
        mass_A=mass_a,
        mass_B=float(b.sum()),
        mass_C=made,
        mass_total=mass_a + made,  # A's own: 1 but for what left an FD window's ends
        mass_min=float(min(a.min(), b.min())),
        dV=volume,
        **extra,
    )


def _judge(cfg: RunConfig, ref: dict, x, c_a, mass_c: float) -> dict:
    """The errors of a run's last state against the reference: SSE of C_A at the scene's points (the
    model's concentration linearly interpolated there, measures.at_points) and |M_C / M_C,ref - 1|."""
    model = M.at_points(ref["points"], x, c_a)
    err = M.sse(model, ref["a_points"])
    product = ref["product_mass"]
    return {
        **_NAN,
        "SSE_points": err,
        "COMIC_points": M.comic(err, model.size, cfg.fd_dx if cfg.method == "fd" else cfg.dV),
        "product_error": abs(mass_c / product - 1.0) if product > 0 else math.nan,
    }


# a reactive run's columns beside the conservative run's: its errors at t_final (last row only) and
# no entropy (a reactive scene's reference has none: its measure is rmse of C_A or product)
_NAN = dict.fromkeys(
    ("SSE_points", "COMIC_points", "product_error", "H_C", "H_C_analytic", "E", "E_analytic"), math.nan
)


def _run_fd(cfg: RunConfig, reaction: Reaction, ref: dict, dts, ts, rec: Recorder) -> None:
    from . import fd

    x, dx = fd.grid(cfg)
    a = fd.initial_concentration(cfg) * dx  # node masses
    b = reaction.b_masses(x, dx)
    b[0] = b[-1] = 0.0  # the end nodes are held at zero (models/fd.py)
    made = 0.0
    _row(rec, 0, 0.0, 0.0, a, b, made, dx, _NAN)
    solvers: dict = {}
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        if dt not in solvers:
            solvers[dt] = fd.solver(cfg, dt, dx)
        a[1:-1] = solvers[dt].solve(a[1:-1] / dx) * dx
        b[1:-1] = solvers[dt].solve(b[1:-1] / dx) * dx
        a, b, step_made = react(reaction, a, b, dx, dt, t)
        made += float(step_made.sum())
        last = k == len(dts)
        _row(rec, k, t, dt, a, b, made, dx, _judge(cfg, ref, x, a / dx, made) if last else _NAN)


def _run_mtpt(cfg: RunConfig, reaction: Reaction, ref: dict, dts, ts, rec: Recorder) -> None:
    from ..core.registry import SCHEME_RECORDS
    from ..numerics.mass_transfer import mass_transfer
    from . import mtpt

    if SCHEME_RECORDS[cfg.scheme].sequential:
        raise ValueError(f"scheme {cfg.scheme!r}: a reactive run transfers every species by one matrix (symmetric)")
    rng = cfg.rng()
    x, a, _ = mtpt.initial_state(cfg, rng)  # sorted positions, A's masses
    dV = cfg.dV
    b = reaction.b_masses(x, dV)
    made = 0.0
    _row(rec, 0, 0.0, 0.0, a, b, made, dV, {"substeps": 1})
    d_walk = (1.0 - cfg.eta) * cfg.D
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        if cfg.v != 0.0:
            x = x + cfg.v * dt
        if d_walk > 0:
            x = x + math.sqrt(2.0 * d_walk * dt) * rng.standard_normal(x.size)
            order = np.argsort(x, kind="stable")
            x, a, b = x[order], a[order], b[order]
        sigma, beta = mtpt.kernel_for_step(cfg, dt, t)
        substeps = 1
        if sigma > 0.0 and beta > 0.0:
            moved = []
            for m in (a, b):
                res = mass_transfer(x, m, sigma, beta, cfg.truncation, cfg.transfer_method, cfg.transfer_tolerance)
                moved.append(res.mass)
                substeps = max(substeps, res.substeps)
            a, b = moved
        a, b, step_made = react(reaction, a, b, dV, dt, t)
        made += float(step_made.sum())
        extra = _judge(cfg, ref, x, a / dV, made) if k == len(dts) else _NAN
        _row(rec, k, t, dt, a, b, made, dV, {"substeps": substeps, **extra})


def _run_pt(cfg: RunConfig, reaction: Reaction, ref: dict, dts, ts, rec: Recorder) -> None:
    from . import pt

    if reaction.kind != "decay":
        raise ValueError("PT carries a decay here; A + B -> C on particles is models/reactive.py's pair reaction")
    rng = cfg.rng()
    x = np.sort(pt.initial_positions(cfg, rng))
    left = 1.0  # the mass A keeps: every particle's share times exp(-lambda t)
    empty = np.zeros(1)
    _row(rec, 0, 0.0, 0.0, np.array([left]), empty, 0.0, cfg.dV, _NAN)
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        x = np.sort(pt.walk(x, cfg.D, dt, rng, cfg.v))
        a, _, step_made = react(reaction, np.array([left]), empty, 1.0, dt, t)
        left = float(a[0])
        made = 1.0 - left
        extra = _NAN
        if k == len(dts):
            grid, c, _, _ = pt.reconstruct(cfg, x, t)
            extra = _judge(cfg, ref, grid, left * c, made)
        _row(rec, k, t, dt, np.array([left]), empty, made, cfg.dV, extra)


def run_arrow(cfg: RunConfig, reaction: Reaction, ref: dict, progress: Callable[[str], None] | None = None) -> pa.Table:
    """Simulate ``cfg`` with ``reaction`` against the reference ``ref`` (experiments/reactive.read) ->
    its per-step Arrow table."""
    from .simulate import warm_up

    cfg = cfg.resolved()
    grid = "exact" if cfg.method == "fd" else cfg.time_grid
    dts = time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, grid)
    warm_up(cfg)
    size = cfg.n + 1 if cfg.method == "fd" else cfg.n
    rec = Recorder(cfg.case_columns(), len(dts), progress, size=size)
    runner = {"pt": _run_pt, "mtpt": _run_mtpt, "fd": _run_fd}[cfg.method]
    runner(cfg, reaction, ref, dts, times(dts, cfg.t_final if grid == "exact" else None), rec)
    return rec.table()


def run_seeds_arrow(cfg: RunConfig, reaction: Reaction, ref: dict, seeds, progress=None) -> pa.Table:
    """run_arrow for each seed, the tables concatenated."""
    parts = []
    for seed in seeds:
        if progress:
            progress(f"seed {seed}")
        parts.append(run_arrow(replace(cfg, seed=int(seed)), reaction, ref, progress))
    return pa.concat_tables(parts, promote_options="default")
