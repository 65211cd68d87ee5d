"""Run one candidate of a reactive scene (experiments/reactive.py): its transport, as the conservative
run does it (``cfg``, a RunConfig), with the scene's reaction after every step, to a per-step table.

- FD: every species (A, B, C) carried by the case's own transport step on the fixed grid (models/fd.py),
  then every node reacted over dt by the closed-form kinetics (core/reactions.py): sequential
  non-iterative operator splitting, transport then reaction (Lie's order; Valocchi & Malmstead 1992;
  as RT3D reacts MT3D's nodes, Clement 1997): the loop of models/fd_reactive.steps.
- MTPT: the random walk with (1 - eta) D, then every species exchanged with eta D by one transfer
  matrix (Eq. 19; collision or SPH kernel), then every particle reacted over dt at its
  concentrations m / dV (Benson & Bolster 2016; Schmidt, Pankavich & Benson 2017).
- PT: A and B on particles of their own, of equal mass, walking with D; a decay turns each A into C
  with probability 1 - exp(-lambda dt), A + B -> C takes each pair with Benson & Meerschaert's
  (2008) probability k m_p dt v(s) (models/reactive.py), on the periodic domain Omega in the frame
  moving with v; C_A and C_C are each species' kernel reconstruction (models/pt.py) times its mass.

Every step's reaction balances to round-off (A + C and B + C keep their totals, no mass is negative:
models/reactive.check_species_mass). A row records the masses of A, B and the product
made so far, A + C still held (mass_total) and the fraction of B + C lost (mass_lost_BC: FD's
window ends let both totals out, particles none); the last row also the errors against the
reference: the SSE of C_A and of C_C at the scene's points (SSE_points, SSE_points_C) and the
product mass's relative error (product_error).
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


def _row(rec: Recorder, k: int, t: float, dt: float, a, b, c, made: float, volume: float, lost_bc: float, extra: dict):
    mass_a, mass_c = float(a.sum()), float(c.sum())
    rec.add(
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


def _judge(cfg: RunConfig, ref: dict, x, c_a, mass_c: float, x_c=None, c_c=None) -> dict:
    """The errors of a run's last state against the reference: the SSE of C_A and of C_C at the scene's
    points (the model's concentrations linearly interpolated there, measures.at_points; C_C on ``x_c``,
    by default A's ``x``) and |M_C / M_C,ref - 1|."""
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


# a reactive run's columns beside the conservative run's: its errors at t_final (last row only) and
# no entropy (a reactive scene's reference has none: its measure is rmse of C_A or product)
_NAN = dict.fromkeys(
    ("SSE_points", "SSE_points_C", "COMIC_points", "product_error", "H_C", "H_C_analytic", "E", "E_analytic"),
    math.nan,
)


def _run_fd(cfg: RunConfig, reaction: Reaction, ref: dict, dts, ts, rec: Recorder) -> None:
    """FD: A, B and C carried by the case's transport step and every node reacted (fd_reactive.steps)."""
    from . import fd
    from .fd_reactive import steps

    x, dx = fd.grid(cfg)
    a = fd.initial_concentration(cfg) * dx  # node masses
    # B's ends: a plume's are held at zero, as A's (models/fd.py); a uniform background's at C0, so
    # that B neither drains through them nor enters B-free with the flow: its departure from C0 is
    # carried with zero ends (every scheme, the TVD limiter included, is unchanged by a constant)
    background = reaction.b_uniform * dx if reaction.b_source is None else 0.0
    b = reaction.b_masses(x, dx)
    b[0] = b[-1] = background
    masses = np.vstack([a, b, np.zeros_like(a)])
    # B + C lost through the window's ends, as a fraction of B's mass (a uniform B's departure from
    # C0, which only the reaction makes, in units of A's unit mass)
    b_total, scale = float((b - background).sum()), reaction.b_mass if reaction.b_source is not None else 1.0

    def lost_bc(b, c) -> float:
        return 0.0 if reaction.kind == "decay" else (b_total - float((b - background).sum() + c.sum())) / scale

    _row(rec, 0, 0.0, 0.0, a, b, masses[2], 0.0, dx, 0.0, _NAN)
    solvers: dict = {}

    def solver(dt: float):
        if dt not in solvers:
            solvers[dt] = fd.solver(cfg, dt, dx)
        return solvers[dt]

    for k, t, dt, (a, b, c), made in steps(solver, masses, reaction.kinetics, dx, dts, ts, background):
        extra = _judge(cfg, ref, x, a / dx, made, c_c=c / dx) if k == len(dts) else _NAN
        _row(rec, k, t, dt, a, b, c, made, dx, lost_bc(b, c), extra)


def _run_mtpt(cfg: RunConfig, reaction: Reaction, ref: dict, dts, ts, rec: Recorder) -> None:
    from . import mtpt
    from .reactive import A, B, C, CollisionKernel, SPHKernel, mtpt_step

    rng = cfg.rng()
    x, a, _ = mtpt.initial_state(cfg, rng)  # sorted positions, A's masses
    dV = cfg.dV
    masses = np.vstack([a, reaction.b_masses(x, dV), np.zeros_like(a)])
    _row(rec, 0, 0.0, 0.0, masses[A], masses[B], masses[C], 0.0, dV, 0.0, {**_NAN, "substeps": 1})
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        if cfg.v != 0.0:  # carried by the flow: a uniform shift leaves the order and the exchange alone
            x = x + cfg.v * dt
        h, _ = mtpt.kernel_for_step(cfg, dt, t)
        kernel = SPHKernel(h) if cfg.kernel == "sph" else CollisionKernel()
        x, masses, substeps = mtpt_step(x, masses, reaction.kinetics, dV, cfg.D, cfg.eta, dt, rng, kernel, t=t)
        made = float(masses[C].sum())
        extra = _judge(cfg, ref, x, masses[A] / dV, made, c_c=masses[C] / dV) if k == len(dts) else _NAN
        _row(rec, k, t, dt, masses[A], masses[B], masses[C], made, dV, 0.0, {"substeps": substeps, **extra})


def _run_pt(cfg: RunConfig, reaction: Reaction, ref: dict, dts, ts, rec: Recorder) -> None:
    """PT: A's particles from the source, each of mass m_p = 1 / N; B's of the same mass from its
    initial condition (C0 Omega / m_p uniform ones, or b_mass / m_p from its plume); both walk with D
    and react by particle_reaction on the periodic domain of width Omega around the source, in the
    frame moving with v (a uniform B is then uniform everywhere, as the reference's)."""
    from . import pt
    from .reactive import pt_step

    rng = cfg.rng()
    m_p, length = 1.0 / cfg.n, cfg.omega
    lo = cfg.source.centre - length / 2.0
    xa = np.mod(pt.initial_positions(cfg, rng) - lo, length)  # positions in [0, Omega), moving frame
    if reaction.kind == "decay":
        xb = np.empty(0)
    elif reaction.b_source is None:
        xb = rng.uniform(0.0, length, round(reaction.b_uniform * length / m_p))
    else:
        xb = np.mod(reaction.b_source.positions(round(reaction.b_mass / m_p), rng) - lo, length)
    xc = np.empty(0)
    one = np.ones(1)
    _row(rec, 0, 0.0, 0.0, xa.size * m_p * one, xb.size * m_p * one, 0.0 * one, 0.0, cfg.dV, 0.0, _NAN)
    for k, dt in enumerate(dts, start=1):
        t = ts[k]
        xa, xb, xc = pt_step(xa, xb, xc, reaction.kinetics, m_p, cfg.D, dt, length, rng, t=t)
        made = xc.size * m_p
        extra = _NAN
        if k == len(dts):  # A's and C's densities in the lab frame: each species' reconstruction times its mass
            (grid, c_a), (grid_c, c_c) = (_density(cfg, xs + lo + cfg.v * t, m_p, t) for xs in (xa, xc))
            extra = _judge(cfg, ref, grid, c_a, made, grid_c, c_c)
        _row(rec, k, t, dt, xa.size * m_p * one, xb.size * m_p * one, made * one, made, cfg.dV, 0.0, extra)


def _density(cfg: RunConfig, x: np.ndarray, m_p: float, t: float) -> tuple[np.ndarray, np.ndarray]:
    """A PT species' concentration from its particles' lab positions ``x``, each of mass m_p: the
    case's reconstruction (models/pt.reconstruct, a density of unit mass) times their mass; zero if
    none is left."""
    from . import pt

    if not x.size:
        return np.zeros(1), np.zeros(1)
    grid, c, _, _ = pt.reconstruct(cfg, np.sort(x), t)
    return grid, x.size * m_p * c


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
