"""MTPT mass transfer of several species by one transfer matrix (numerics/mass_transfer.py states the
update, Eq. 19): each row of a (species, N) mass array moves by the same P and the same substeps.

A separate module, not a branch of mass_transfer.py, so that the single-species runs' code (and
their code hashes, pipeline/codeversion.py) stays as it is; it calls the same compiled loops.
"""

from __future__ import annotations

import math

import numpy as np

from .compiled import kernels
from .gauss import FGT_TOLERANCE, choose_method, gauss_transform
from .mass_transfer import TransferResult


def substeps_for(c: float) -> int:
    """Equal pieces of beta that keep every guarded mass non-negative, given c = beta * max_i sum_{j != i}
    P_ij: the rule of mass_transfer.py (ceil(c), with a hair of margin for round-off)."""
    return max(1, math.ceil(c / (1.0 - 1e-9)))


def mass_transfer_species(
    x: np.ndarray,
    masses: np.ndarray,
    sigma: float,
    beta: float,
    truncation: float | None = None,
    method: str = "auto",
    tolerance: float = FGT_TOLERANCE,
) -> TransferResult:
    """Eq. 19 for several species at once: each row of ``masses`` (species, N) exchanged by the same
    P and the same number of substeps; x sorted. The kernel's row sums r are computed once and
    W [1/r, m_1, m_1/r, m_2, m_2/r, ...] in one pass. The substeps are chosen for the particles
    that hold any species, so that the species see one linear operator (their sum moves as one
    species would): carrying each row through ``mass_transfer`` could split the step differently
    for each. ``mass`` of the result has the shape of ``masses``."""
    masses = np.ascontiguousarray(np.atleast_2d(masses), dtype=np.float64)
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
    substeps = substeps_for(c)
    if substeps > 1:  # split steps carry mass several kernel widths: guard every particle
        c = c_all
        substeps = substeps_for(c)
    b = beta / substeps
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
