"""MTPT mass transfer with the symmetric transfer matrix (Eqs. 16-21).

W_ij = exp(-(x_i - x_j)^2 / (2 sigma^2)) (Eq. 17 or 21, the prefactor cancels on normalising),
r_i = sum_j W_ij, and P_ij = (W_ij / r_i + W_ij / r_j) / 2: the average of the row- and the
column-normalised kernel matrix, self term included. The update (Eq. 19) is

    m_i <- m_i + beta * sum_j P_ij (m_j - m_i),

built from the products W 1, W (1/r), W m and W (m/r), computed in two Gauss-transform
passes a step (W 1, then W [1/r, m, m/r] together); P is never stored.
The explicit update keeps masses non-negative while beta * sum_{j != i} P_ij <= 1 for every
i. Where it is not (the SPH beta exceeds 1 at late times), the step is split into
``substeps`` equal pieces of beta with the same P, each of them positivity-preserving;
the count is returned so that callers record it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .gauss import FGT_TOLERANCE, choose_method, gauss_transform


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
    """One mass-transfer step m_i <- m_i + beta sum_j P_ij (m_j - m_i) (Eq. 19); x sorted."""
    if x.size < 2 or beta == 0.0:
        return TransferResult(m.copy(), 1, 0.0)
    if method == "auto":  # one choice for all transforms of this step
        method = choose_method(x, x, sigma, truncation)
    r = gauss_transform(x, x, np.ones_like(x), sigma, truncation, method, tolerance=tolerance)
    inv_r = 1.0 / r
    # one pass gives W (1/r) for the row sums of P and W m, W (m/r) for the first substep
    W3 = gauss_transform(x, x, np.vstack([inv_r, m, m * inv_r]), sigma, truncation, method, tolerance=tolerance)
    rowsum = 0.5 * (1.0 + W3[0])
    offdiag = rowsum - inv_r  # sum_{j != i} P_ij, since P_ii = W_ii / r_i = 1 / r_i
    c_max = float(beta * offdiag.max())
    # split so that b * offdiag stays a hair below 1 (round-off margin)
    substeps = max(1, math.ceil(c_max / (1.0 - 1e-9)))
    b = beta / substeps
    keep = 1.0 - b * offdiag  # >= 0 by the choice of substeps
    Wm, Wmr = W3[1], W3[2]
    for k in range(substeps):
        if k > 0:
            Wm, Wmr = gauss_transform(x, x, np.vstack([m, m * inv_r]), sigma, truncation, method, tolerance=tolerance)
        # sum_{j != i} W_ij q_j for q = m and q = m / r: sums of non-negative terms. The
        # fast transform leaves them within its tolerance (1e-17 of the summed mass in reach
        # by default), which can dip below 0 where all neighbours are empty; 0 is their bound.
        s1 = np.maximum(Wm - m, 0.0)
        s2 = np.maximum(Wmr - m * inv_r, 0.0)
        m = m * keep + b * 0.5 * (s1 * inv_r + s2)
    return TransferResult(m, substeps, c_max)
