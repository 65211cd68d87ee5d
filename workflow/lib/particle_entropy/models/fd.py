"""Finite differences for 1-D diffusion (Section 6.1, Fig. 8): implicit (backward Euler, the
paper's) and explicit (forward Euler, refused past its stability limit r = 1/2)."""

from __future__ import annotations

import math

import numpy as np

from ..core import measures as M
from ..core.runconfig import RunConfig
from ..numerics.compiled import kernels


def grid(cfg: RunConfig) -> tuple[np.ndarray, float]:
    """Nodes -L/2 + k dx, k = 0..N, dx = L / N (both end nodes held at zero)."""
    dx = cfg.fd_length / cfg.n
    return -cfg.fd_length / 2.0 + dx * np.arange(cfg.n + 1), dx


def initial_concentration(cfg: RunConfig) -> np.ndarray:
    """Discrete delta: 1 / dx at the centre node."""
    x, dx = grid(cfg)
    c = np.zeros_like(x)
    c[cfg.n // 2] = 1.0 / dx
    return c


class ImplicitSolver:
    """(I - r A) c^{n+1} = c^n on the interior nodes, r = D dt / dx^2; factorised once
    (Thomas algorithm: O(N) memory and work, stable since the matrix is diagonally dominant)."""

    def __init__(self, n_interior: int, r: float):
        self.r = float(r)
        self._inv_piv, self._upper = kernels().thomas_factor(n_interior, self.r)

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        return kernels().thomas_solve(self._inv_piv, self._upper, self.r, c_interior)


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
    err = M.sse(c, M.analytic_sampled(x, cfg.D, t, dx))
    n = x.size
    points = M.measurement_points()
    err_points = M.sse_points(points, x, c, cfg.D, t, dx)
    return {
        "H_D": h_c,
        "H_C": h_c,
        "H_I": h_c + math.log(dx),
        "H_PMF": M.entropy_pmf(h_c, cfg.fd_length, cfg.n),  # dV = L / N intervals
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
