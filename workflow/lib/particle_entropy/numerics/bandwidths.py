"""Kernel widths (bandwidths) of the paper: collision kernel (Eq. 17), h_DE (Eq. 23), h_SPH (Eq. 26);
the compiled loops are the *_kernels modules."""

from __future__ import annotations

import math

import numpy as np

from ..core.registry import SPH_CONSTANT

CUTOFF_SIGMAS = 9.0  # kernel widths searched when the kernel is not truncated


def cutoff_radius(sigma: float, truncation: float | None) -> float:
    """Distance beyond which a kernel of width ``sigma`` is dropped: ``truncation`` widths (the
    authors' cut), or CUTOFF_SIGMAS for the whole Gaussian (below round-off of the self term)."""
    return (CUTOFF_SIGMAS if truncation is None else float(truncation)) * sigma


def collision_sigma(eta: float, D: float, dt: float) -> float:
    """Standard deviation of the collision kernel, variance 4 eta D dt (Eq. 17)."""
    return math.sqrt(4.0 * eta * D * dt)


def h_de(n: int, variance: float) -> float:
    """Density-estimation bandwidth h_DE = 1.06 N^(-1/5) sqrt(variance) (Eq. 23), ``variance`` the
    plume's (Reference.variance): 2 D t from the paper's point, plus the source's own."""
    return 1.06 * n ** (-0.2) * math.sqrt(variance)


def h_sph(n: int, omega: float, variance: float, constant: float = SPH_CONSTANT) -> float:
    """Adaptive SPH bandwidth h_SPH = 0.82 variance^(2/5) (N / Omega)^(-1/5) (Eq. 26; registry.SPH_CONSTANT),
    ``variance`` the plume's (Reference.variance): 2 D t from the paper's point, plus the source's own."""
    return constant * variance**0.4 * (n / omega) ** (-0.2)


def beta_sph(eta: float, D: float, dt: float, h: float) -> float:
    """Mass-transfer coefficient beta = 2 eta D dt / h^2 (Eq. 20)."""
    return 2.0 * eta * D * dt / (h * h)


def truncated_variance_fraction(k: float | None) -> float:
    """Variance of a Gaussian cut at k widths over the whole one's: 1 - 2k phi(k) / (2 Phi(k) - 1)."""
    if k is None:
        return 1.0
    phi = math.exp(-0.5 * k * k) / math.sqrt(2.0 * math.pi)
    return 1.0 - 2.0 * k * phi / math.erf(k / math.sqrt(2.0))


def gaussian_pdf(x: np.ndarray, var: float) -> np.ndarray:
    """Zero-mean Gaussian density with variance ``var``."""
    return np.exp(-0.5 * x * x / var) / math.sqrt(2.0 * math.pi * var)
