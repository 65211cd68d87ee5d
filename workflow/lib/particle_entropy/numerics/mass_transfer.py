"""MTPT mass transfer with the symmetric transfer matrix (Eqs. 16-21).

W_ij = exp(-(x_i - x_j)^2 / (2 sigma^2)) (Eq. 17 or 21, the prefactor cancels on normalising),
r_i = sum_j W_ij, and P_ij = (W_ij / r_i + W_ij / r_j) / 2: the average of the row- and the
column-normalised kernel matrix, self term included. The update (Eq. 19) is

    m_i <- m_i + beta * sum_j P_ij (m_j - m_i),

built from the products W 1, W (1/r), W m and W (m/r), computed in two Gauss-transform
passes a step (W 1, then W [1/r, m, m/r] together); P is never stored.
The explicit update keeps masses non-negative while beta * sum_{j != i} P_ij <= 1 for every
particle i holding mass (empty particles only receive). Where it is not (the SPH beta
exceeds 1), the step is split into ``substeps`` equal pieces of beta with the same P, each
positivity-preserving for every particle (a split step carries mass several kernel widths);
the count is returned so that callers record it.

Several species (masses of shape (species, N)) move by the same P and the same substeps: the
species' rows are exchanged together (``_transfer_species``); one species keeps the single row's
path, which skips the particles out of reach of any mass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .compiled import kernels
from .gauss import FGT_TOLERANCE, choose_method, cutoff_radius, gauss_transform


@dataclass(frozen=True)
class TransferResult:
    mass: np.ndarray
    substeps: int
    max_offdiag_beta: float  # beta * max_i sum_{j != i} P_ij, before splitting


def transfer_matrix_dense(x: np.ndarray, sigma: float, truncation: float | None = None) -> np.ndarray:
    """Dense P (Eq. 18, symmetrised) for small N: references and tests only."""
    d = x[:, None] - x[None, :]
    W = np.exp(-0.5 * (d / sigma) ** 2)
    if truncation is not None:
        W[np.abs(d) > truncation * sigma] = 0.0
    r = W.sum(axis=1)
    return 0.5 * (W / r[:, None] + W / r[None, :])


def mass_transfer(
    x: np.ndarray,
    m: np.ndarray,
    sigma: float,
    beta: float,
    truncation: float | None = None,
    method: str = "auto",
    tolerance: float = FGT_TOLERANCE,
) -> TransferResult:
    """One mass-transfer step m_i <- m_i + beta sum_j P_ij (m_j - m_i) (Eq. 19); x sorted; ``m`` of
    shape (N,) or (species, N), each row a species moved by the same P (the result has m's shape).

    Only particles within the kernel's reach of a mass-holding particle can change, so
    while they are few (early times of a delta initial condition) the step is computed on
    them alone; the result is the same sum.
    """
    if m.ndim == 2:
        if m.shape[0] > 1:
            return _transfer_species(x, m, sigma, beta, truncation, method, tolerance)
        res = mass_transfer(x, m[0], sigma, beta, truncation, method, tolerance)
        return TransferResult(res.mass[None, :], res.substeps, res.max_offdiag_beta)
    if x.size < 2 or beta == 0.0:
        return TransferResult(m.copy(), 1, 0.0)
    if method == "auto":  # one choice for all transforms of this step
        method = choose_method(x, x, sigma, truncation)
    reach = cutoff_radius(sigma, truncation)
    active = _reach_of_mass(x, m, reach)
    if active is not None:
        res = _transfer_near_mass(x, m, active, sigma, beta, truncation, method, tolerance)
        if res is not None:
            return res
    return _transfer_all(x, m, sigma, beta, truncation, method, tolerance)


def _reach_of_mass(x, m, reach) -> np.ndarray | None:
    """Mask of particles within ``reach`` of a particle with m != 0, when at most half are."""
    if 2 * np.count_nonzero(m) > x.size:
        return None
    holders = np.flatnonzero(m)
    lo = np.searchsorted(x, x[holders] - reach, side="left")
    hi = np.searchsorted(x, x[holders] + reach, side="right")
    cover = np.zeros(x.size + 1, dtype=np.int64)
    np.add.at(cover, lo, 1)
    np.add.at(cover, hi, -1)
    active = np.cumsum(cover[:-1]) > 0
    return active if 2 * np.count_nonzero(active) <= x.size else None


def _substeps(c):
    """Substeps that keep m_i (1 - b offdiag_i) >= 0 (b = beta / substeps) given
    c = beta * max offdiag, with a hair of margin for round-off."""
    return max(1, math.ceil(c / (1.0 - 1e-9)))


def _split(c: float, c_all: float, beta: float) -> tuple[int, float, float]:
    """(substeps, the c they guard, beta of each) from c = beta max offdiag over the mass holders and
    c_all over every particle: a split step carries mass several kernel widths, so it guards all."""
    substeps = _substeps(c)
    if substeps > 1:
        c = c_all
        substeps = _substeps(c)
    return substeps, c, beta / substeps


def _transfer_near_mass(x, m, active, sigma, beta, truncation, method, tolerance):
    """The step on the particles within reach of mass (targets) with all particles as
    sources of the row sums r; None when it needs substeps (mass then travels further)."""
    xa = np.ascontiguousarray(x[active])
    ma = np.ascontiguousarray(m[active])
    r = gauss_transform(xa, x, np.ones_like(x), sigma, truncation, method, tolerance=tolerance)
    inv_r, q = kernels().weights(r, ma)
    # every particle within reach of a mass holder is in xa: its sums over xa are complete
    W3 = gauss_transform(xa, xa, q, sigma, truncation, method, tolerance=tolerance)
    offdiag, c, _ = kernels().offdiag(W3[0], inv_r, ma, beta)
    if _substeps(c) > 1:
        return None
    out = m.copy()
    out[active] = kernels().update(ma, offdiag, beta, W3[1], W3[2], inv_r)
    return TransferResult(out, 1, c)


def _transfer_all(x, m, sigma, beta, truncation, method, tolerance):
    r = gauss_transform(x, x, np.ones_like(x), sigma, truncation, method, tolerance=tolerance)
    inv_r, q = kernels().weights(r, m)
    # one pass gives W (1/r) for the row sums of P and W m, W (m/r) for the first substep
    W3 = gauss_transform(x, x, q, sigma, truncation, method, tolerance=tolerance)
    offdiag, c, c_all = kernels().offdiag(W3[0], inv_r, m, beta)
    substeps, c, b = _split(c, c_all, beta)
    Wm, Wmr = W3[1], W3[2]
    for k in range(substeps):
        if k > 0:
            Wm, Wmr = gauss_transform(x, x, np.vstack([m, m * inv_r]), sigma, truncation, method, tolerance=tolerance)
        m = kernels().update(m, offdiag, b, Wm, Wmr, inv_r)
    return TransferResult(m, substeps, c)


def _transfer_species(x, masses, sigma, beta, truncation, method, tolerance) -> TransferResult:
    """Eq. 19 for several species at once: each row of ``masses`` (species, N) exchanged by the same
    P and the same number of substeps. The kernel's row sums r are computed once and
    W [1/r, m_1, m_1/r, m_2, m_2/r, ...] in one pass. The substeps are chosen for the particles
    that hold any species, so that the species see one linear operator (their sum moves as one
    species would): carrying each row on its own could split the step differently for each."""
    masses = np.ascontiguousarray(masses, dtype=np.float64)
    if x.size < 2 or beta == 0.0:
        return TransferResult(masses.copy(), 1, 0.0)
    if method == "auto":
        method = choose_method(x, x, sigma, truncation)
    r = gauss_transform(x, x, np.ones_like(x), sigma, truncation, method, tolerance=tolerance)
    inv_r = 1.0 / r
    ns = masses.shape[0]
    q = np.empty((1 + 2 * ns, x.size))
    q[0] = inv_r
    q[1::2] = masses
    q[2::2] = masses * inv_r
    W = gauss_transform(x, x, q, sigma, truncation, method, tolerance=tolerance)
    held = np.any(masses != 0.0, axis=0).astype(np.float64)
    offdiag, c, c_all = kernels().offdiag(W[0], inv_r, held, beta)
    substeps, c, b = _split(c, c_all, beta)
    out = masses.copy()
    for k in range(substeps):
        if k > 0:
            q = np.empty((2 * ns, x.size))
            q[0::2] = out
            q[1::2] = out * inv_r
            W = gauss_transform(x, x, q, sigma, truncation, method, tolerance=tolerance)
            W = np.vstack([W[:1], W])  # rows 1::2 and 2::2 as in the first pass
        for i in range(ns):
            out[i] = kernels().update(out[i], offdiag, b, W[1 + 2 * i], W[2 + 2 * i], inv_r)
    return TransferResult(out, substeps, c)
