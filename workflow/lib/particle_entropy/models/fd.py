"""Finite differences for 1-D diffusion (Section 6.1, Fig. 8): implicit (backward Euler, the
paper's) and explicit (forward Euler, refused from its stability limit r = 1/2 on). With a uniform
velocity v (a scene), the implicit scheme gains an advection term on the fixed grid: first-order
upwind (monotone; numerical dispersion v dx / 2) or central differences (second order; oscillates
where the grid Peclet number v dx / D exceeds 2); or Leonard's explicit ULTIMATE-QUICKEST (tvd:
third order where the plume is smooth, monotone everywhere, at a Courant number |v| dt / dx <= 1),
split from a backward-Euler dispersion step.

Every step balances its mass: the interior's mass falls by exactly the flux into the two end nodes
held at zero (the boundary of Fig. 8, fd_domain.py), to round-off. A step that loses or invents more
raises MassError naming the mass error: such a run is a failure, never a score."""

from __future__ import annotations

import math

import numpy as np

from ..core import measures as M
from ..core.registry import COURANT_SLACK
from ..core.runconfig import RunConfig
from ..numerics.compiled import kernels
from .conservation import MassError

# a step's mass error (interior mass before - after - outflow) beyond this many ulps of the step's
# largest terms is no round-off: the sums of N + 1 terms and the solve's residual (1 + 4 r + |p|) times eps
MASS_ULPS = 64.0


def check_balance(before: np.ndarray, after: np.ndarray, outflow: float, scale: float) -> None:
    """MassError unless sum(before) - sum(after) equals ``outflow`` (the flux into the zero end
    nodes, per dx) to round-off: ``scale`` (>= 1, the step matrix's largest row sum) times the sums'
    magnitude and length in ulps."""
    lost = float(before.sum()) - float(after.sum()) - outflow
    size = float(np.abs(before).sum()) + float(np.abs(after).sum()) + abs(outflow)
    tol = MASS_ULPS * np.finfo(np.float64).eps * scale * size * max(1.0, math.sqrt(before.size))
    if not abs(lost) <= tol:
        raise MassError(
            f"fd step lost mass: mass error {lost:.3g} (interior {float(before.sum()):.17g} -> "
            f"{float(after.sum()):.17g}, boundary outflow {outflow:.3g}) beyond round-off {tol:.3g}"
        )


def grid(cfg: RunConfig) -> tuple[np.ndarray, float]:
    """Nodes lo + k dx, k = 0..N, dx = length / N (both end nodes held at zero): the paper's
    [-L/2, L/2], lengthened by a scene's path v t_final (RunConfig.fd_span)."""
    dx = cfg.fd_dx
    lo = -cfg.fd_length / 2.0 if cfg.at_rest else cfg.fd_span()[0]
    return lo + dx * np.arange(cfg.n + 1), dx


def initial_concentration(cfg: RunConfig) -> np.ndarray:
    """The paper's discrete delta, 1 / dx at the centre node; a scene's source as node masses
    (Source.masses) over dx."""
    x, dx = grid(cfg)
    if cfg.at_rest:
        c = np.zeros_like(x)
        c[cfg.n // 2] = 1.0 / dx
        return c
    return cfg.source.masses(x, dx) / dx


def transport(solve, rows: np.ndarray) -> None:
    """One transport step of every species row of ``rows`` (species, N + 1) or, on a d-dimensional grid,
    (species, N_1 + 1, ..., N_d + 1), in place: each row's interior by the step's solver ``solve``
    (``solver``), its boundary nodes held (the zero boundary, or a background's departure from itself). The
    solver keeps what its last solve sent out through the boundary, per dx (or cell area), in ``last_outflow``."""
    inner = (slice(1, -1),) * (rows.ndim - 1)
    for row in rows:
        row[inner] = solve.solve(row[inner])


def species_masses(rows: np.ndarray, dx: float, background: float) -> np.ndarray:
    """The node masses (A, B, C) of FD's transported rows: each row's concentration times dx, B's row
    being its departure from the uniform ``background`` [M/L] (its node mass C0 dx added back) [M]."""
    masses = rows * dx
    masses[1] = masses[1] + background * dx
    return masses


def species_rows(masses: np.ndarray, dx: float, background: float) -> np.ndarray:
    """The inverse of species_masses: the rows FD's transport carries (concentrations; B's as its departure
    from ``background``, which every scheme, the TVD limiter included, carries unchanged) [M/L]."""
    rows = masses / dx
    rows[1] = (masses[1] - background * dx) / dx
    return rows


def solver(cfg: RunConfig, dt: float, dx: float):
    """The solver of one step dt on the interior nodes: the case's diffusion scheme, with the
    advection term when v != 0 (implicit only)."""
    r = cfg.D * dt / dx**2
    if cfg.v != 0.0:
        if cfg.kernel != "implicit":  # RunConfig.check refuses it: never run another scheme than named
            raise ValueError(f"fd kernel {cfg.kernel!r} has no advection term: implicit when v != 0")
        if cfg.advection == "tvd":
            return TVDSolver(cfg.n - 1, r, cfg.v * dt / dx)
        return AdvectionSolver(cfg.n - 1, r, cfg.v * dt / dx, cfg.advection)
    return (ExplicitSolver if cfg.kernel == "explicit" else ImplicitSolver)(cfg.n - 1, r)


def grid_peclet(v: float, dx: float, D: float) -> float:
    """|v| dx / D: central differences oscillate above 2 [-]."""
    return abs(v) * dx / D if D > 0 else math.inf


class ImplicitSolver:
    """(I - r A) c^{n+1} = c^n on the interior nodes, r = D dt / dx^2; factorised once
    (Thomas algorithm: O(N) memory and work, stable since the matrix is diagonally dominant)."""

    def __init__(self, n_interior: int, r: float):
        self.r = float(r)
        self._inv_piv, self._upper = kernels().thomas_factor(n_interior, self.r)

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        out = kernels().thomas_solve(self._inv_piv, self._upper, self.r, c_interior)
        # summing (I - r A) c' = c: sum c - sum c' = r (c'_1 + c'_M), the flux into the zero ends
        self.last_outflow = self.r * (out[0] + out[-1])
        check_balance(c_interior, out, self.last_outflow, 1.0 + 4.0 * self.r)
        return out


class AdvectionSolver:
    """(I - r A + p B) c^{n+1} = c^n, backward Euler with r = D dt / dx^2 and the Courant number
    p = v dt / dx: B the upwind difference (c_i - c_{i-1} for v > 0, c_{i+1} - c_i for v < 0) or
    the central one (c_{i+1} - c_{i-1}) / 2. Tridiagonal, factorised once by LAPACK's dgttrf and
    solved by dgttrs' sweeps compiled with subnormal results flushed to zero (thomas.gt_solve: a
    decaying tail otherwise runs on subnormals, 6x slower)."""

    def __init__(self, n_interior: int, r: float, p: float, scheme: str):
        from scipy.linalg import lapack

        if scheme == "upwind":
            lower, diag, upper = -r - max(p, 0.0), 1.0 + 2.0 * r + abs(p), -r + min(p, 0.0)
        elif scheme == "central":
            lower, diag, upper = -r - 0.5 * p, 1.0 + 2.0 * r, -r + 0.5 * p
        else:
            raise ValueError(f"advection scheme {scheme!r}: upwind or central")
        self.r, self.p, self.scheme = float(r), float(p), scheme
        dl = np.full(n_interior - 1, lower)
        d = np.full(n_interior, diag)
        du = np.full(n_interior - 1, upper)
        self._factors = lapack.dgttrf(dl, d, du)
        if self._factors[-1] != 0:
            raise ValueError(f"the advection-diffusion matrix is singular (dgttrf info {self._factors[-1]})")

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        dl, d, du, du2, ipiv, _ = self._factors
        out = kernels().gt_solve(dl, d, du, du2, ipiv, c_interior)
        self.last_outflow = self.outflow(out)
        check_balance(c_interior, out, self.last_outflow, 1.0 + 4.0 * self.r + 2.0 * abs(self.p))
        return out

    def outflow(self, c: np.ndarray) -> float:
        """The mass per dx that the step's solution ``c`` sends into the zero end nodes: diffusion's
        r (c_1 + c_M) plus the advective flux, the sum of p B c over the interior."""
        p = self.p
        if self.scheme == "upwind":
            advected = p * c[-1] if p > 0 else -p * c[0]
        else:
            advected = 0.5 * p * (c[-1] - c[0])
        return self.r * (c[0] + c[-1]) + advected


def quickest_faces(c: np.ndarray, cr: float) -> np.ndarray:
    """ULTIMATE-QUICKEST face values phi_{k+1/2}, k = 0..M, of the M interior nodes ``c`` for a flow
    in +x at Courant number 0 < cr <= 1, between the zero end nodes and zero ghosts beyond them
    (Leonard 1991, CMAME 88: QUICKEST's third-order value held by the universal limiter)."""
    padded = np.zeros(c.size + 4)
    padded[2:-2] = c
    up, centre, down = padded[:-3], padded[1:-2], padded[2:-1]  # upstream, central, downstream node of a face
    curv = down - 2.0 * centre + up
    # QUICKEST (Leonard 1979) for pure advection: 1/2 (C + D) - cr/2 (D - C) - (1 - cr^2)/6 (D - 2C + U)
    face = centre + 0.5 * (1.0 - cr) * (down - centre) - (1.0 - cr * cr) / 6.0 * curv
    # universal limiter: where C lies strictly between U and D (|curv| < |D - U|), the face value lies
    # between C and the nearer of D and U + (C - U) / cr; elsewhere (an extremum, a flat) it is C, upwind's
    delta = down - up
    reach = up + (centre - up) / cr
    far = np.where(delta > 0.0, np.minimum(down, reach), np.maximum(down, reach))
    held = np.minimum(np.maximum(face, np.minimum(centre, far)), np.maximum(centre, far))
    return np.where(np.abs(curv) < np.abs(delta), held, centre)


def advect_tvd_numpy(c: np.ndarray, p: float) -> tuple[np.ndarray, float]:
    """One explicit step c_i - |p| (phi_{i+1/2} - phi_{i-1/2}) in flux form (quickest_faces, faces taken
    upstream of the flow's sign) at Courant number p = v dt / dx, |p| <= 1 -> (c', the mass per dx that
    leaves through the two end faces). The readable form; runs take advect_tvd, its compiled twin."""
    cr = abs(p)
    ahead = c if p > 0 else c[::-1]
    faces = quickest_faces(ahead, cr)
    out = ahead - cr * (faces[1:] - faces[:-1])
    return (out if p > 0 else out[::-1].copy()), cr * (float(faces[-1]) - float(faces[0]))


def advect_tvd(c: np.ndarray, p: float) -> tuple[np.ndarray, float]:
    """advect_tvd_numpy compiled (numerics/thomas.tvd_advect: the same bits, one pass, no temporaries)."""
    return kernels().tvd_advect(np.ascontiguousarray(c, dtype=np.float64), float(p))


class TVDSolver:
    """Leonard's ULTIMATE-QUICKEST advection (advect_tvd, explicit, |p| = |v| dt / dx <= 1), then
    backward-Euler dispersion (I - r A) c^{n+1} = c* (ImplicitSolver): Lie operator splitting."""

    def __init__(self, n_interior: int, r: float, p: float):
        if not abs(p) <= 1.0 + COURANT_SLACK:  # RunConfig.check refuses it
            raise ValueError(f"tvd advection at Courant number {abs(p):.17g}: at most 1")
        self.r, self.p = float(r), max(-1.0, min(1.0, float(p)))  # within round-off of 1: 1
        self._diffuse = ImplicitSolver(n_interior, self.r)

    def advect(self, c_interior: np.ndarray) -> np.ndarray:
        """The advection substep, its mass balanced against the flux through the end faces."""
        out, outflow = advect_tvd(c_interior, self.p)
        check_balance(c_interior, out, outflow, 1.0 + 4.0 * abs(self.p))
        self._advected_out = outflow
        return out

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        out = self._diffuse.solve(self.advect(c_interior))
        self.last_outflow = self._advected_out + self._diffuse.last_outflow
        return out


class ExplicitSolver:
    """Forward Euler c^{n+1} = c^n + r (c_{i-1} - 2 c_i + c_{i+1}); RunConfig.check ensures r < 1/2."""

    def __init__(self, n_interior: int, r: float):
        self.r = r

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        padded = np.concatenate([[0.0], c_interior, [0.0]])
        out = c_interior + self.r * (padded[:-2] - 2.0 * c_interior + padded[2:])
        self.last_outflow = self.r * (c_interior[0] + c_interior[-1])
        check_balance(c_interior, out, self.last_outflow, 1.0 + 4.0 * self.r)
        return out


def measure(cfg: RunConfig, x: np.ndarray, c: np.ndarray, dx: float, t: float) -> dict:
    """H_C of the node masses c dx (Eq. 7 with dV = dx), E, SSE over all nodes, COMIC (Eq. 43), and
    both at the measurement points (the nodal c linearly interpolated, measures.sse_points)."""
    p = c * dx
    total = float(p.sum())
    h_c = M.entropy_discrete(p / total) if total > 0 else -math.inf
    ref = cfg.reference(t)
    err = M.sse(c, ref.sampled(x, dx))
    n = x.size
    points = cfg.points(t)
    err_points = ref.sse_points(points, x, c, dx)
    length = cfg.fd_length if cfg.at_rest else cfg.fd_span()[1]
    return {
        "H_D": h_c,
        "H_C": h_c,
        "H_I": h_c + math.log(dx),
        "H_PMF": M.entropy_pmf(h_c, length, cfg.n),  # dV = L / N intervals
        "E": M.dilution_index(h_c, dx),
        "SSE": err,
        "n_sse": n,
        "AIC": M.aic(err, n),
        "COMIC": M.comic(err, n, dx),
        "SSE_points": err_points,
        "COMIC_points": M.comic(err_points, points.size, dx),
        "dV": dx,
        "mass_total": total,
        "mass_min": float(c.min() * dx),
    }


def warm_up(cfg: RunConfig) -> None:
    """Load the compiled solver, and LAPACK's where the case advects implicitly, before the timed steps."""
    ImplicitSolver(8, 0.1).solve(np.ones(8))
    if cfg.v != 0.0:
        (TVDSolver(8, 0.1, 0.1) if cfg.advection == "tvd" else AdvectionSolver(8, 0.1, 0.1, cfg.advection)).solve(
            np.ones(8)
        )
