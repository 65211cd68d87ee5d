"""Run one simulation, conservative or reactive, and return its per-step table (and, on request, its
final state): the one runner of every model.

A run's state carries its species as a dimension: masses (species, N) on particles and rows
(species, N + 1) on FD's nodes; PT carries one position array per species. A conservative run has one
species. Each step moves every species by its model's transport step (models/fd, mtpt, pt), then
applies the run's reaction (RunConfig.reaction, None when conservative) to the whole state: sequential
non-iterative operator splitting, transport then reaction (Lie's order; Valocchi & Malmstead 1992,
Water Resour. Res. 28: 1471; as RT3D reacts MT3D's nodes, Clement 1997), by the reaction kind's own
node and particle rules (models/reaction_step.py).

- FD: every species row on the fixed grid by the case's solver, then every node reacted over dt at
  its masses (a uniform B carried as its departure from C0: fd.species_rows).
- MTPT: the random walk with (1 - eta) D, then every species exchanged with eta D by one transfer
  matrix (Eq. 19), then every particle reacted over dt at its concentrations m / dV (Benson & Bolster
  2016; Schmidt, Pankavich & Benson 2017).
- PT: a reactive run's A, B and C particles of equal mass m_p = 1 / N walk with D on the periodic
  domain Omega around the source in the frame moving with v (a uniform B is then uniform
  everywhere, as the reference's) and react by the kind's particle rule; C_A and C_C are each
  species' kernel reconstruction (models/pt.py) times its mass.

A run with a continuous release (RunConfig.release, conservative only) starts empty and takes in, each
step, the mass its source releases over the step (models/release_step.py): FD half of it before the step's
transport and half after, on the nodes the source covers; MTPT at the step's end, on its particles as the
exact plume the step's release has become; PT as particles released at their own times within the step,
each walked from its release on.

A conservative row holds the paper's measures (each model's ``measure``) and the exact solution's; a
release's row also the mass released so far and, for FD, the mass that has left the window, and its
exact solution's scores at the last row only (core/released.py: the exact plume is a quadrature in age,
built by warm_up before the timed steps; NaN before); a reactive row the masses of A, B and the product
made so far, A + C still held (mass_total) and the fraction of B + C lost (mass_lost_BC: FD's window
ends let both totals out, particles none), and the last row also the errors against the scene's
reference: the SSE of C_A and of C_C at the scene's points (SSE_points, SSE_points_C) and the product
mass's relative error (product_error).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from ..core import measures as M
from ..core.records import Recorder, arrow_table
from ..core.runconfig import RunConfig
from ..core.timegrid import time_steps, times
from . import release_step

if TYPE_CHECKING:
    import pandas as pd


def run_arrow(cfg: RunConfig, progress: Callable[[str], None] | None = None, want_state: bool = False, reference=None):
    """Simulate ``cfg`` (defaults resolved and checked) -> (per-step Arrow table, final state or None);
    a reactive run (cfg.reaction) is judged against ``reference`` (core/reference_file.read)."""
    cfg = cfg.resolved()
    if cfg.reaction is not None and reference is None:
        raise ValueError("a reactive run needs its scene's reference to judge its last step")
    grid = "exact" if cfg.method == "fd" else cfg.time_grid
    dts = time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, grid)
    runners = {"pt": _run_pt, "mtpt": _run_mtpt, "fd": _run_fd} if cfg.dim == 1 else _PLANE
    runner = runners[cfg.method]
    warm_up(cfg)
    size = (cfg.n + 1) ** cfg.dim if cfg.method == "fd" else cfg.n
    rec = Recorder(cfg.case_columns(), len(dts), progress, size=size)
    if cfg.reaction is not None:
        rows = _Reactive(cfg, rec, reference, len(dts))
    else:
        rows = _Conservative(cfg, rec) if cfg.release is None else _Released(cfg, rec)
    state = runner(cfg, dts, times(dts, cfg.t_final if grid == "exact" else None), rows)
    table = rec.table()
    if not want_state:
        return table, None
    length = len(next(iter(state.values())))
    return table, arrow_table({k: np.asarray(v) for k, v in state.items()}, cfg.case_columns(), length)


def run(cfg: RunConfig, progress: Callable[[str], None] | None = None, want_state: bool = False, reference=None):
    """run_arrow as pandas tables: (per-step table, final state or None)."""
    table, state = run_arrow(cfg, progress, want_state, reference)
    return table.to_pandas(), None if state is None else state.to_pandas()


_WARM: set = set()


def _model(method: str):
    """The module of a method, imported when a run needs it (a job loads only its own kernels)."""
    import importlib

    return importlib.import_module(f".{method}", __package__)


def warm_up(cfg: RunConfig) -> None:
    """Load the compiled kernels this case calls (numba's on-disk cache, ~0.05-0.4 s once per
    process) and what its exact solution is computed with before the timed steps, so that step 0's
    and step 1's wall times are the steps' own; with a release, its exact plume at t_final (warm_release)."""
    if cfg.release is not None:
        warm_release(cfg)
    if cfg.dim == 2:  # the plane's steps compile their pair loops (numerics/pair_transfer) when first run
        return
    advection = cfg.advection if cfg.v != 0.0 else None  # FD in a flow: its scheme's solver
    key = (cfg.method, cfg.kernel, cfg.scheme, cfg.transfer_method, cfg.truncation is None, advection)
    if key not in _WARM:
        _model(cfg.method).warm_up(cfg)
        _WARM.add(key)
    if ("reference", cfg.source.kind) not in _WARM:
        cfg.source.warm_up()
        _WARM.add(("reference", cfg.source.kind))


def warm_release(cfg: RunConfig) -> None:
    """Build the exact plume a release run's last row is scored against (core/released.py) before the
    timed steps: its H_I and its density at the measurement points and, on the line, FD's nodes, which
    released.exact_plume keeps for that row (0.01-2 s, the quadrature in age: not the model's cost)."""
    t = cfg.t_final
    ref = cfg.reference(t)
    ref.entropy()
    ref.density(cfg.points(t))
    if cfg.dim == 1 and cfg.method == "fd":
        ref.density(_model("fd").grid(cfg)[0])


# ------------------------------------------------------------------------------------ the rows


class _Conservative:
    """A conservative run's rows: its model's measures (Eqs. 2-14) and the exact solution's."""

    def __init__(self, cfg: RunConfig, rec: Recorder):
        self.cfg, self.rec = cfg, rec

    def add(self, step: int, t: float, dt: float, meas: dict) -> None:
        if self.cfg.dim == 2:  # the plane's rows carry the exact solution's (models/plane.py); settled once
            # the exact plume's E is wider than a cell, as t > dV^2 / (4 pi e D) is on the line
            settled = bool(meas.get("E_analytic", 0.0) > meas["dV"])
            self.rec.add(step=step, time=t, dt=dt, **meas, settled=settled)
            return
        ref = self.cfg.reference(t)
        analytic = {
            "H_C_analytic": ref.h_c(meas["dV"]),
            "E_analytic": ref.dilution(),
            "settled": bool(t > M.settling_time(meas["dV"], self.cfg.D)),
        }
        self.rec.add(step=step, time=t, dt=dt, **meas, **analytic)


class _Released(_Conservative):
    """A release's rows: the conservative run's, with the mass released by then (mass_released) and the mass
    that has left an FD window (mass_outflow, which the FD runners put in ``meas``; particles 0). While the
    run holds no mass its entropies are NaN: there is nothing to normalise."""

    def add(self, step: int, t: float, dt: float, meas: dict) -> None:
        meas = {**meas, "mass_released": self.cfg.mass(t), "mass_outflow": meas.get("mass_outflow", 0.0)}
        if not meas["mass_total"] > 0:
            meas.update(dict.fromkeys(_ENTROPIES, math.nan))
        super().add(step, t, dt, meas)


_ENTROPIES = ("H_D", "H_C", "H_I", "H_PMF", "E")

# a reactive run's columns beside the conservative run's: its errors at t_final (last row only) and
# no entropy (a reactive scene's reference has none: its measure is rmse of C_A or product)
_NAN = dict.fromkeys(
    ("SSE_points", "SSE_points_C", "COMIC_points", "product_error", "H_C", "H_C_analytic", "E", "E_analytic"),
    math.nan,
)


class _Reactive:
    """A reactive run's rows: the species' masses each step, and the errors against ``ref`` at the last."""

    def __init__(self, cfg: RunConfig, rec: Recorder, ref: dict, last: int):
        self.cfg, self.rec, self.ref, self.last = cfg, rec, ref, last

    def add(self, k: int, t: float, dt: float, a, b, c, made: float, volume: float, lost_bc: float, extra: dict):
        mass_a, mass_c = float(a.sum()), float(c.sum())
        self.rec.add(
            step=k,
            time=t,
            dt=dt,
            mass_A=mass_a,
            mass_B=float(b.sum()),
            mass_C=made,
            mass_total=mass_a + mass_c,  # A + C still held: 1 but for what left an FD window's ends
            mass_lost_BC=lost_bc,
            mass_min=float(min(a.min(), b.min())),
            dV=volume,
            **extra,
        )

    def judged(self, x, c_a, mass_c: float, x_c=None, c_c=None) -> dict:
        """The last step's errors against the reference: the SSE of C_A and of C_C at the scene's points
        (the model's concentrations linearly interpolated there, measures.at_points; C_C on ``x_c``, by
        default A's ``x``) and |M_C / M_C,ref - 1|. The runners call it at the last step only (``last``)."""
        ref, cfg = self.ref, self.cfg
        model = M.at_points(ref["points"], x, c_a)
        err = M.sse(model, ref["a_points"])
        product = ref["product_mass"]
        x_c = x if x_c is None else x_c
        return {
            **_NAN,
            "SSE_points": err,
            "SSE_points_C": M.sse(M.at_points(ref["points"], x_c, c_c), ref["c_points"]),
            "COMIC_points": M.comic(err, model.size, cfg.fd_dx if cfg.method == "fd" else cfg.dV),
            "product_error": abs(mass_c / product - 1.0) if product > 0 else math.nan,
        }


# ---------------------------------------------------------------------------------- the models


def _run_fd(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rows) -> dict:
    """FD: every species row carried by the case's solver (one factorisation per distinct step
    size), then, in a reactive run, every node reacted (reaction_step.react_masses)."""
    fd = _model("fd")
    x, dx = fd.grid(cfg)
    c = fd.initial_concentration(cfg)
    entering = None
    if cfg.release is not None:  # the source's mass enters step by step, where its start would put it
        entering = release_step.fd_source(cfg, c, dx)
        c = np.zeros_like(c)
    solvers: dict = {}

    def solver(dt):
        if dt not in solvers:
            solvers[dt] = fd.solver(cfg, dt, dx)
        return solvers[dt]

    extra = {"beta": 0.0, "h": dx, "substeps": 1}
    if cfg.reaction is None:
        state = c[None, :]
        out = _Outflow(entering, dx)
        rows.add(0, 0.0, 0.0, {**fd.measure(cfg, x, c, dx, 0.0), **extra, **out.row()})
        for k, dt in enumerate(dts, start=1):
            _fd_step(solver(dt), state, entering, ts[k - 1], ts[k], out)
            rows.add(k, ts[k], dt, {**fd.measure(cfg, x, c, dx, ts[k]), **extra, **out.row()})
        return {"x": x, "c": c}
    from .reaction_step import react_masses

    reaction = cfg.reaction
    background = reaction.b_background
    # B's ends: a plume's are held at zero, as A's; a uniform background's at C0, so that B neither
    # drains through them nor enters B-free with the flow (fd.species_rows carries its departure)
    b = reaction.b_masses(x, dx)
    b[0] = b[-1] = background * dx
    masses = np.vstack([c * dx, b, np.zeros_like(c)])
    b_total = float((b - background * dx).sum())  # B's departure from its background: B + C lost is read from it
    rows.add(0, 0.0, 0.0, masses[0], masses[1], masses[2], 0.0, dx, 0.0, _NAN)
    state, made = fd.species_rows(masses, dx, background), 0.0
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        fd.transport(solver(dt), state)
        masses = fd.species_masses(state, dx, background)
        made += react_masses(reaction.kinetics, masses, dx, dt, t, "fd")
        state = fd.species_rows(masses, dx, background)
        a, b, c = masses
        lost = reaction.lost_bc(b_total, float((b - background * dx).sum()), float(c.sum()))
        extra = rows.judged(x, a / dx, made, c_c=c / dx) if k == rows.last else _NAN
        rows.add(k, t, dt, a, b, c, made, dx, lost, extra)
    return {"x": x, "c": masses[0] / dx}


class _Outflow:
    """The mass an FD run with a release has sent out of its window so far (the steps' boundary fluxes
    times the cell, dx or dx dy); without a release nothing is counted and its rows carry no column."""

    def __init__(self, entering, cell: float):
        self.entering, self.cell, self.total = entering, cell, 0.0

    def add(self, solve) -> None:
        self.total += solve.last_outflow * self.cell

    def row(self) -> dict:
        return {} if self.entering is None else {"mass_outflow": self.total}


def _fd_step(solve, state: np.ndarray, entering, t_a: float, t_b: float, out: _Outflow) -> None:
    """One FD step of ``state`` (species, nodes...) over [t_a, t_b] by ``solve`` (fd.transport); with a
    release (``entering``), half the mass released in the step added to the interior before the
    transport and half after (release_step.py), and the step's outflow counted in ``out``."""
    fd = _model("fd")
    if entering is None:
        fd.transport(solve, state)
        return
    inner = (slice(1, -1),) * (state.ndim - 1)
    state[0][inner] = entering.add(state[0][inner], t_a, t_b)
    fd.transport(solve, state)
    state[0][inner] = entering.add(state[0][inner], t_a, t_b)
    out.add(solve)


def _run_mtpt(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rows) -> dict:
    """MTPT: every species row walked and exchanged by one step (mtpt.step), then, in a reactive
    run, every particle reacted (reaction_step.react_masses)."""
    mtpt = _model("mtpt")
    rng, order_rng = cfg.rng(), cfg.rng(stream=1)
    x, m, label = mtpt.initial_state(cfg, rng)
    dV = cfg.dV
    if cfg.reaction is None:
        # a release's mass enters the particles at each step's end, as the plume it has become (release_step.py)
        entering = None if cfg.release is None else release_step.ParticleSource(cfg)
        rows.add(0, 0.0, 0.0, {**mtpt.measure(cfg, x, m, 0.0), "beta": 0.0, "h": 0.0, "substeps": 1})
        for k, dt in enumerate(dts, start=1):
            t = ts[k]
            x, m, label, h, beta, sub = mtpt.step(cfg, x, m, label, dt, t, rng, order_rng)
            if entering is not None:
                m = entering.add(m, x, ts[k - 1], t)
            rows.add(k, t, dt, {**mtpt.measure(cfg, x, m, t), "beta": beta, "h": h, "substeps": sub})
        return {"x": x, "mass": m, "c": m / dV}
    from .reaction_step import A, B, C, react_masses

    kinetics = cfg.reaction.kinetics
    masses = np.vstack([m, cfg.reaction.b_masses(x, dV), np.zeros_like(m)])
    rows.add(0, 0.0, 0.0, masses[A], masses[B], masses[C], 0.0, dV, 0.0, {**_NAN, "substeps": 1})
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        x, masses, label, _, _, sub = mtpt.step(cfg, x, masses, label, dt, t, rng, order_rng)
        react_masses(kinetics, masses, dV, dt, t, "mtpt")
        made = float(masses[C].sum())
        extra = rows.judged(x, masses[A] / dV, made, c_c=masses[C] / dV) if k == rows.last else _NAN
        rows.add(k, t, dt, masses[A], masses[B], masses[C], made, dV, 0.0, {"substeps": sub, **extra})
    return {"x": x, "mass": masses[A], "c": masses[A] / dV}


def _run_pt(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rows) -> dict:
    """PT: every species' particles walked (pt.step); a reactive run's A from the source, each of mass
    m_p = 1 / N, and B's of the same mass from its initial condition, on the periodic domain of width
    Omega around the source in the frame moving with v, reacted by the kind's particle rule."""
    pt = _model("pt")
    rng = cfg.rng()
    if cfg.reaction is None:
        if cfg.release is None:
            batches, m_p = None, None
            x = np.sort(pt.initial_positions(cfg, rng))
        else:  # particles enter at their release times (release_step.Batches)
            batches = release_step.Batches(cfg)
            m_p, x = batches.mass, np.empty(0)
        rows.add(0, 0.0, 0.0, pt.measure(cfg, x, 0.0, m_p))
        for k, dt in enumerate(dts, start=1):
            t = ts[k]
            (x,) = pt.step([x], cfg.D, dt, rng, cfg.v)
            if batches is not None:
                x = np.sort(np.concatenate([x, batches.enter(ts[k - 1], t, rng)]))
            rows.add(k, t, dt, pt.measure(cfg, x, t, m_p))
        return pt.final_state(cfg, x, t, m_p)
    from .reaction_step import react_particles

    reaction = cfg.reaction
    m_p, length = 1.0 / cfg.n, cfg.omega
    lo = cfg.source.centre - length / 2.0
    xa = np.mod(pt.initial_positions(cfg, rng) - lo, length)  # positions in [0, Omega), moving frame
    xs = [xa, reaction.b_positions(m_p, length, lo, rng), np.empty(0)]
    one = np.ones(1)
    rows.add(0, 0.0, 0.0, xs[0].size * m_p * one, xs[1].size * m_p * one, 0.0 * one, 0.0, cfg.dV, 0.0, _NAN)
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        xs = react_particles(
            reaction.kinetics, pt.step(xs, cfg.D, dt, rng, period=length), m_p, cfg.D, dt, length, rng, t
        )
        made = xs[2].size * m_p
        extra = _NAN
        if k == rows.last:  # A's and C's densities in the lab frame: each species' reconstruction times its mass
            (grid, c_a), (grid_c, c_c) = (_density(cfg, x + lo + cfg.v * t, m_p, t) for x in (xs[0], xs[2]))
            extra = rows.judged(grid, c_a, made, grid_c, c_c)
        a, b = xs[0].size * m_p * one, xs[1].size * m_p * one
        rows.add(k, t, dt, a, b, made * one, made, cfg.dV, 0.0, extra)
    return {"x": np.sort(xs[0] + lo + cfg.v * t), "mass": np.full(xs[0].size, m_p)}


def _run_plane_fd(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rows) -> dict:
    """FD in the plane: the nodes (n + 1, n + 1) carried by fd.transport with the 2-D solver (one
    solver per distinct step size: a sparse LU below 2^16 unknowns, BiCGSTAB from there, models/fd2d.py),
    measured every step (models/plane.py)."""
    from . import plane

    g, c = plane.fd_start(cfg)
    entering = None
    if cfg.release is not None:  # the source's mass enters step by step, where its start would put it
        entering = release_step.fd_source(cfg, c, g.dx * g.dy)
        c = np.zeros_like(c)
    solvers: dict = {}
    extra = {"beta": 0.0, "h": g.dx, "substeps": 1}
    out = _Outflow(entering, g.dx * g.dy)
    rows.add(0, 0.0, 0.0, {**plane.fd_measure(cfg, g, c, 0.0, False), **extra, **out.row()})
    state = c[None]
    for k, dt in enumerate(dts, start=1):
        if dt not in solvers:
            solvers[dt] = plane.fd_solver(cfg, g, dt)
        _fd_step(solvers[dt], state, entering, ts[k - 1], ts[k], out)
        rows.add(k, ts[k], dt, {**plane.fd_measure(cfg, g, c, ts[k], k == len(dts)), **extra, **out.row()})
    x, y = g.nodes()
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return {"x": gx.ravel(), "y": gy.ravel(), "c": c.ravel()}


def _run_plane_mtpt(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rows) -> dict:
    """MTPT in the plane: carried, walked with (1 - eta) D and exchanged with eta D each step (models/plane.py)."""
    from ..core.plane import major
    from ..numerics.particles2d import COLLISION_BETA
    from . import plane

    rng = cfg.rng()
    x, m = plane.particles_start(cfg, rng)
    # a release's mass enters the particles at each step's end, as the plume it has become (release_step.py)
    entering = None if cfg.release is None else release_step.ParticleSource(cfg)
    start = {"beta": 0.0, "h": 0.0, "neighbours": 0.0, "substeps": 1}
    rows.add(0, 0.0, 0.0, {**plane.mtpt_measure(cfg, x, m, 0.0, False), **start})
    d_major = major(cfg.D)  # the kernel's sd along D's major axis is sqrt(4 eta D_L dt)
    for k, dt in enumerate(dts, start=1):
        x, m, neighbours, sub = plane.mtpt_step(cfg, x, m, dt, rng)
        if entering is not None:
            m = entering.add(m, x, ts[k - 1], ts[k])
        meas = plane.mtpt_measure(cfg, x, m, ts[k], k == len(dts))
        h = math.sqrt(4.0 * cfg.eta * d_major * dt)
        rows.add(k, ts[k], dt, {**meas, "beta": COLLISION_BETA, "h": h, "neighbours": neighbours, "substeps": sub})
    return {"x": x[:, 0], "y": x[:, 1], "mass": m, "c": m / cfg.dV}


def _run_plane_pt(cfg: RunConfig, dts: np.ndarray, ts: np.ndarray, rows) -> dict:
    """PT in the plane: carried and walked with D each step, the kernel estimate at the last (models/plane.py)."""
    from . import plane

    rng = cfg.rng()
    x = plane.pt_start(cfg, rng)
    batches = None if cfg.release is None else release_step.Batches(cfg)  # particles enter at their release times
    m_p = None if batches is None else batches.mass
    rows.add(0, 0.0, 0.0, plane.pt_measure(cfg, x, 0.0, False, m_p))
    for k, dt in enumerate(dts, start=1):
        x = plane.pt_step(cfg, x, dt, rng)
        if batches is not None:
            x = np.concatenate([x, batches.enter(ts[k - 1], ts[k], rng)])
        rows.add(k, ts[k], dt, plane.pt_measure(cfg, x, ts[k], k == len(dts), m_p))
    mass = 1.0 / x.shape[0] if m_p is None else m_p
    return {"x": x[:, 0], "y": x[:, 1], "mass": np.full(x.shape[0], mass)}


# the runners of a 2-D run (RunConfig.dim): the same steps, the plane's start and measures
_PLANE = {"fd": _run_plane_fd, "mtpt": _run_plane_mtpt, "pt": _run_plane_pt}


def _density(cfg: RunConfig, x: np.ndarray, m_p: float, t: float) -> tuple[np.ndarray, np.ndarray]:
    """A PT species' concentration from its particles' lab positions ``x``, each of mass m_p: the
    case's reconstruction (models/pt.reconstruct, a density of unit mass) times their mass; zero if
    none is left."""
    pt = _model("pt")
    if not x.size:
        return np.zeros(1), np.zeros(1)
    grid, c, _, _ = pt.reconstruct(cfg, np.sort(x), t)
    return grid, x.size * m_p * c


def run_seeds_arrow(
    cfg: RunConfig, seeds, progress: Callable[[str], None] | None = None, state: bool = False, reference=None
) -> pa.Table:
    """Run ``cfg`` for each seed and concatenate the per-step tables (or final states)."""
    parts = []
    for seed in seeds:
        if progress:
            progress(f"seed {seed}")
        table, final = run_arrow(replace(cfg, seed=int(seed)), progress, state, reference)
        parts.append(final if state else table)
    return pa.concat_tables(parts, promote_options="default")


def run_seeds(
    cfg: RunConfig, seeds, progress: Callable[[str], None] | None = None, state: bool = False, reference=None
) -> pd.DataFrame:
    """run_seeds_arrow as a pandas table."""
    return run_seeds_arrow(cfg, seeds, progress, state, reference).to_pandas()
