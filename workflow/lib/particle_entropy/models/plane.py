"""The three models' start and measures in the plane (d = 2, issue 52), as fd.py, mtpt.py and pt.py
give them on the line; their steps are the shared ones (models/simulate.py runs both).

- FD: the n x n grid of core/plane.grid_span, the source's exact cell masses on it (sources2d.cell_masses),
  each step fd.transport by models/fd2d.py's solver (backward Euler with the full tensor).
- MTPT: N particles uniform at random on the square of side Omega around the source, each carrying
  the source's mass in its sampling volume dV = Omega^2 / N (its density there times dV; a point's on
  the particle nearest to it), then normalised to one; each step the walk with (1 - eta) D
  (models/walk.py) and the exchange with eta D (numerics/particles2d.mtpt_exchange_2d).
- PT: N particles of mass 1 / N drawn from the source, each step the walk with D; the concentration
  is the kernel estimate with H = N^(-1/3) Sigma, Sigma the exact plume's covariance
  (particles2d.plume_bandwidth_2d: Eq. 22 at d = 2).

Measures (a row's columns as on the line): H_C = -sum p ln p of the masses (nodes, particles, or PT's
estimate on MEASURE_GRID^2 cells over the plume), dV the cell or sampling area [L^2], H_I = H_C +
ln dV, E = exp(H_I) [L^2] (Eq. 8), and the SSE of the concentration at the scene's 15 x 15 points
(Reference2D.points) against the exact one [L^-4]. The SSE, PT's H_C and the exact solution's H_C and
E are computed at the last step only (a triangulation, a kernel sum, a box's entropy quadrature:
NaN before); FD's and MTPT's H_C at every step. PT's mass is its N particles' of 1 / N, 1
whatever the estimate's cells hold.
"""

from __future__ import annotations

import math

import numpy as np

from ..core import measures as M
from ..core import plane as P

MEASURE_GRID = 128  # PT's estimate is summed on 128 x 128 cells over its plume, +- PT_REACH sd each axis
PT_REACH = 5.0


# -------------------------------------------------------------------------------------------- FD
def fd_grid(cfg):
    """The run's n x n grid (core/plane.grid_span: the window and path, a node on the source's centre)."""
    from .fd2d import Grid

    (x0, y0), (dx, dy) = P.grid_span(cfg)
    return Grid(float(x0), float(y0), float(dx), float(dy), cfg.n, cfg.n)


def fd_start(cfg):
    """(grid, nodes (n + 1, n + 1)): the source's exact cell masses over the cell area, the ring zero."""
    g = fd_grid(cfg)
    x, y = g.nodes()
    c = np.zeros((g.nx + 1, g.ny + 1))
    c[1:-1, 1:-1] = cfg.source.cell_masses(x[1:-1], y[1:-1], g.dx, g.dy) / (g.dx * g.dy)
    return g, c


def fd_solver(cfg, g, dt: float):
    """The solver of one step dt on the grid's interior (models/fd2d.py)."""
    from .fd2d import solver

    return solver(np.asarray(cfg.D), np.asarray(cfg.v), g, dt, cfg.advection)


def bilinear(g, c: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The nodal c (nx + 1, ny + 1) bilinearly interpolated at ``points`` (M, 2); 0 outside the grid."""
    u = (points[:, 0] - g.x0) / g.dx
    w = (points[:, 1] - g.y0) / g.dy
    inside = (u >= 0) & (u <= g.nx) & (w >= 0) & (w <= g.ny)
    i = np.clip(np.floor(u).astype(int), 0, g.nx - 1)
    j = np.clip(np.floor(w).astype(int), 0, g.ny - 1)
    a, b = u - i, w - j
    out = (1 - a) * (1 - b) * c[i, j] + a * (1 - b) * c[i + 1, j] + (1 - a) * b * c[i, j + 1] + a * b * c[i + 1, j + 1]
    return np.where(inside, out, 0.0)


def fd_at(g, c: np.ndarray):
    """FD's concentration at points (M, 2), as its run is scored: the nodes bilinearly interpolated."""
    return lambda points: bilinear(g, c, points)


def fd_measure(cfg, g, c: np.ndarray, t: float, last: bool) -> dict:
    """H_C of the node masses c dx dy (Eq. 7 with dV = dx dy), E, and at the last step the SSE at the points."""
    dV = g.dx * g.dy
    return _row(cfg, c.ravel() * dV, dV, t, fd_at(g, c) if last else None)


# ------------------------------------------------------------------------------------------ MTPT
def particles_start(cfg, rng) -> tuple[np.ndarray, np.ndarray]:
    """MTPT's N positions (N, 2), uniform on the square of side Omega around the source, and their
    masses: the source's shape on them (source_weights), summing to 1; with a release none yet (its
    mass enters them step by step, models/release_step.py)."""
    centre = cfg.source.centre
    x = centre + cfg.omega * (rng.random((cfg.n, 2)) - 0.5)
    if cfg.release is not None:
        return x, np.zeros(cfg.n)
    return x, source_weights(cfg, x)


def source_weights(cfg, x) -> np.ndarray:
    """The source's unit mass on particles at x (N, 2): its density times dV, normalised to 1 (a point's
    on the particle nearest it)."""
    from ..core.reference2d import Reference2D

    centre = cfg.source.centre
    if cfg.source.kind == "point":
        m = np.zeros(x.shape[0])
        m[int(np.argmin(np.sum((x - centre) ** 2, axis=1)))] = 1.0
        return m
    m = Reference2D(cfg.source, cfg.D, cfg.v, 0.0).density(x) * cfg.dV
    total = m.sum()
    if not total > 0:
        raise ValueError(f"none of the {x.shape[0]} particles lies on the source: raise n or shrink omega")
    return m / total


def mtpt_step(cfg, x, m, dt: float, rng):
    """Carried by v dt, walked with (1 - eta) D, exchanged with eta D -> (x, m, mean neighbours, substeps)."""
    from ..numerics.particles2d import mtpt_exchange_2d
    from .walk import walk

    D = np.asarray(cfg.D)
    x = x + np.asarray(cfg.v) * dt
    if cfg.eta < 1.0:
        x = walk(x, ((1.0 - cfg.eta) * D)[None], dt, rng)
    done = mtpt_exchange_2d(x, m, D, cfg.eta, dt)
    return x, done.mass, done.mean_neighbours, done.substeps


def mtpt_at(cfg, x, m):
    """MTPT's concentration at points (M, 2), as its run is scored: m / dV on the particles' triangles
    (particles2d.mtpt_concentration_2d)."""
    from ..numerics.particles2d import mtpt_concentration_2d

    return lambda points: mtpt_concentration_2d(points, x, m, cfg.dV)


def mtpt_measure(cfg, x, m, t: float, last: bool) -> dict:
    """H_C of the masses (dV = Omega^2 / N), E and, at the last step, the SSE at the points (mtpt_at)."""
    return _row(cfg, m, cfg.dV, t, mtpt_at(cfg, x, m) if last else None)


# -------------------------------------------------------------------------------------------- PT
def pt_start(cfg, rng) -> np.ndarray:
    """PT's N positions (N, 2) drawn from the source; with a release none yet (release_step.Batches)."""
    if cfg.release is not None:
        return np.empty((0, 2))
    return cfg.source.positions(cfg.n, rng)


def pt_step(cfg, x, dt: float, rng) -> np.ndarray:
    """Carried by v dt and walked with D (models/walk.py)."""
    from .walk import walk

    return walk(x, np.asarray(cfg.D)[None], dt, rng, v=np.asarray(cfg.v))


def pt_bandwidth(cfg, t: float, n: int | None = None) -> np.ndarray:
    """H = N^(-1/3) Sigma(t), the exact plume's covariance (particles2d.plume_bandwidth_2d), for ``n``
    particles (default N); a release's Sigma is its puffs' mean (core/released.py) [L^2]."""
    from ..numerics.particles2d import plume_bandwidth_2d

    return plume_bandwidth_2d(cfg.n if n is None else n, cfg.reference(t).kernel_covariance)


def pt_at(cfg, x, t: float, mass: float | None = None):
    """PT's concentration at points (M, 2) at time t, as its run is scored: the kernel estimate with
    H = pt_bandwidth (particles2d.kde_2d), of unit mass, or with a release of the ``mass`` its particles hold."""
    from ..numerics.particles2d import kde_2d

    if mass is None:
        H = pt_bandwidth(cfg, t)
        return lambda points: kde_2d(points, x, H)
    H = pt_bandwidth(cfg, t, x.shape[0])
    return lambda points: mass * kde_2d(points, x, H)


def at_points(cfg, state):
    """A finished 2-D run's concentration at points (M, 2) from its final state (models/simulate.py's
    columns x, y and c or mass), by the rule its run was scored with (fd_at, mtpt_at, pt_at)."""
    if cfg.method == "fd":
        g = fd_grid(cfg)
        return fd_at(g, np.asarray(state["c"], dtype=np.float64).reshape(g.nx + 1, g.ny + 1))
    x = np.column_stack([np.asarray(state["x"], dtype=np.float64), np.asarray(state["y"], dtype=np.float64)])
    if cfg.method == "mtpt":
        return mtpt_at(cfg, x, np.asarray(state["mass"], dtype=np.float64))
    mass = None if cfg.release is None else float(np.sum(state["mass"]))
    return pt_at(cfg, x, cfg.t_final, mass)


def pt_measure(cfg, x, t: float, last: bool, m_p: float | None = None) -> dict:
    """At the last step: the kernel estimate on MEASURE_GRID^2 cells over +- PT_REACH sd of the plume
    (H_C of its cell masses, dV the cell area) and at the points; before it only the mass. ``m_p``: a
    release's particle mass, its particles those released so far; None: N particles of 1 / N."""
    n = x.shape[0]
    if m_p is None:
        mass = {"beta": 0.0, "substeps": 1, "mass_total": 1.0, "mass_min": 1.0 / n}  # N particles of 1 / N
    else:
        mass = {"beta": 0.0, "substeps": 1, "mass_total": n * m_p, "mass_min": m_p if n else math.nan}
    if not last or not n:
        return {**_row(cfg, np.ones(1), math.nan, t, None, entropy=False), "h": math.nan, **mass}
    H = pt_bandwidth(cfg, t, None if m_p is None else n)
    ref = cfg.reference(t)
    half = PT_REACH * np.sqrt(np.diag(ref.covariance + H))
    ticks = [np.linspace(-h, h, MEASURE_GRID) for h in half]
    dV = float((ticks[0][1] - ticks[0][0]) * (ticks[1][1] - ticks[1][0]))
    gx, gy = np.meshgrid(*ticks, indexing="ij")
    at = pt_at(cfg, x, t, None if m_p is None else n * m_p)
    c = at(ref.centre + np.column_stack([gx.ravel(), gy.ravel()]))
    return {**_row(cfg, c * dV, dV, t, at), "h": math.sqrt(P.major(H)), **mass}


# ------------------------------------------------------------------------------------- the row
def _row(cfg, masses: np.ndarray, dV: float, t: float, at_points, entropy: bool = True) -> dict:
    """A 2-D row: H_C, H_I, E of ``masses`` on cells (or particles) of area dV, the SSE at the points of
    ``at_points(points)`` (NaN without it), the exact solution's, the total and least mass."""
    total = float(masses.sum())
    h_c = M.entropy_discrete(masses / total) if entropy and total > 0 else math.nan
    row = {
        "H_C": h_c,
        "H_I": h_c + math.log(dV) if entropy else math.nan,
        "E": M.dilution_index(h_c, dV) if entropy else math.nan,
        "SSE_points": math.nan,
        "COMIC_points": math.nan,
        "dV": dV,
        "mass_total": total,
        "mass_min": float(masses.min()),
    }
    if at_points is None:  # the exact H_I of a box is a quadrature (up to seconds): at the judged step only
        return row
    ref = cfg.reference(t)
    if t > 0:
        points = cfg.points(t)
        row["SSE_points"] = M.sse(at_points(points), ref.density(points))
        row["COMIC_points"] = M.comic(row["SSE_points"], len(points), dV)  # Eq. 43 at the points
    if t > 0 or cfg.source.kind != "point":
        row["H_C_analytic"] = ref.h_i() - math.log(dV) if entropy else math.nan
        row["E_analytic"] = ref.dilution()
    return row
