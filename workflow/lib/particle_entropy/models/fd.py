"""Finite differences for 1-D diffusion (Section 6.1, Fig. 8): implicit (backward Euler, the
paper's) and explicit (forward Euler, refused past its stability limit r = 1/2). With a uniform
velocity v (a scene), the implicit scheme gains an advection term on the fixed grid: first-order
upwind (monotone; numerical dispersion v dx / 2) or central differences (second order; oscillates
where the grid Peclet number v dx / D exceeds 2)."""

from __future__ import annotations

import math

import numpy as np

from ..core import measures as M
from ..core.runconfig import RunConfig
from ..numerics.compiled import kernels


def grid(cfg: RunConfig) -> tuple[np.ndarray, float]:
    """Nodes lo + k dx, k = 0..N, dx = length / N (both end nodes held at zero): the paper's
    [-L/2, L/2], lengthened by a scene's path v t_final (RunConfig.fd_span)."""
    if cfg.at_rest:
        dx = cfg.fd_length / cfg.n
        return -cfg.fd_length / 2.0 + dx * np.arange(cfg.n + 1), dx
    lo, length = cfg.fd_span()
    dx = length / cfg.n
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


def solver(cfg: RunConfig, dt: float, dx: float):
    """The solver of one step dt on the interior nodes: the case's diffusion scheme, with the
    advection term when v != 0 (implicit only)."""
    r = cfg.D * dt / dx**2
    if cfg.v != 0.0:
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
        return kernels().thomas_solve(self._inv_piv, self._upper, self.r, c_interior)


class AdvectionSolver:
    """(I - r A + p B) c^{n+1} = c^n, backward Euler with r = D dt / dx^2 and the Courant number
    p = v dt / dx: B the upwind difference (c_i - c_{i-1} for v > 0, c_{i+1} - c_i for v < 0) or
    the central one (c_{i+1} - c_{i-1}) / 2. Tridiagonal, factorised once by LAPACK's dgttrf and
    solved by dgttrs (scipy.linalg.lapack)."""

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
        self._solve = lapack.dgttrs

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        dl, d, du, du2, ipiv, _ = self._factors
        out, info = self._solve(dl, d, du, du2, ipiv, c_interior)
        return out


class ExplicitSolver:
    """Forward Euler c^{n+1} = c^n + r (c_{i-1} - 2 c_i + c_{i+1}); callers ensure r <= 1/2."""

    def __init__(self, n_interior: int, r: float):
        self.r = r

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        padded = np.concatenate([[0.0], c_interior, [0.0]])
        return c_interior + self.r * (padded[:-2] - 2.0 * c_interior + padded[2:])


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
    """Load the compiled solver before the timed steps."""
    ImplicitSolver(8, 0.1).solve(np.ones(8))
