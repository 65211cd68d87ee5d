"""The compiled loops of the MTPT mass transfer (numerics/mass_transfer.py states the update):
the weights of the second pass, the row sums of P and the update itself. Only numba-compiled
code lives here (see numerics/compiled.py)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def weights(r, m):
    """1/r and the (3, N) right-hand sides [1/r, m, m/r] of the second pass."""
    n = m.shape[0]
    inv_r = np.empty(n)
    q = np.empty((3, n))
    for i in range(n):
        ir = 1.0 / r[i]
        inv_r[i] = ir
        q[0, i] = ir
        q[1, i] = m[i]
        q[2, i] = m[i] * ir
    return inv_r, q


@njit(cache=True)
def offdiag(W_inv_r, inv_r, m, beta):
    """sum_{j != i} P_ij = (1 + sum_j W_ij / r_j) / 2 - 1 / r_i (P_ii = 1 / r_i), and beta times
    its maximum over mass-holding particles and over all particles."""
    n = m.shape[0]
    out = np.empty(n)
    c_mass = 0.0
    c_all = 0.0
    for i in range(n):
        o = 0.5 * (1.0 + W_inv_r[i]) - inv_r[i]
        out[i] = o
        c_all = max(c_all, beta * o)
        if m[i] != 0.0:
            c_mass = max(c_mass, beta * o)
    return out, c_mass, c_all


@njit(cache=True)
def update(m, offdiag, b, Wm, Wmr, inv_r):
    """m (1 - b offdiag) + b/2 (sum_{j != i} W_ij m_j / r_i + sum_{j != i} W_ij m_j / r_j)."""
    # Both sums are of non-negative terms. The fast transform leaves them within its
    # tolerance (registry.FGT_TOLERANCE of the summed mass in reach by default), which can dip below 0 where
    # all neighbours are empty; 0 is their bound.
    n = m.shape[0]
    out = np.empty(n)
    for i in range(n):
        s1 = max(Wm[i] - m[i], 0.0)
        s2 = max(Wmr[i] - m[i] * inv_r[i], 0.0)
        out[i] = m[i] * (1.0 - b * offdiag[i]) + 0.5 * b * (s1 * inv_r[i] + s2)
    return out
