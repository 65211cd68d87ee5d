"""The compiled loops of the shear flow's mass transfer (Appendix B, Eqs. 16-18 on a pair list).

Kept apart from shear2d so that what only reads shear results (the Fig. 10 plot, the workflow's
parse) does not load numba."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def pair_weights(x, y, v, pairs, length, alpha_L, alpha_T, dt):
    """W_ij of shear2d.pair_kernel (Eq. 17 with the pair-averaged tensor) for each listed pair."""
    w = np.zeros(pairs.shape[0])
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        vbar = 0.5 * (v[i] + v[j])
        if vbar <= 0.0:
            continue
        dx = abs(x[i] - x[j])
        dx = min(dx, length - dx)
        dy = y[i] - y[j]
        q = dx * dx / alpha_L
        if alpha_T > 0.0:
            q += dy * dy / alpha_T
        elif dy != 0.0:
            continue
        w[k] = math.exp(-q / (8.0 * vbar * dt)) / vbar
    return w


@njit(cache=True)
def pair_transfer(pairs, w, v, m, beta):
    """Eqs. 16-18 on a pair list: returns (new masses, substeps, beta * max_i sum_{j != i} P_ij)."""
    n = m.size
    off = np.zeros(n)
    for k in range(pairs.shape[0]):
        off[pairs[k, 0]] += w[k]
        off[pairs[k, 1]] += w[k]
    inv_r = np.zeros(n)  # 1 / r_i, r_i = W_ii + sum_{j != i} W_ij, W_ii = 1 / v_i (infinite at v_i = 0)
    for i in range(n):
        if v[i] > 0.0:
            inv_r[i] = 1.0 / (1.0 / v[i] + off[i])
    p = np.empty(pairs.shape[0])
    offdiag = np.zeros(n)
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        p[k] = 0.5 * w[k] * (inv_r[i] + inv_r[j])  # P_ij = P_ji
        offdiag[i] += p[k]
        offdiag[j] += p[k]
    c_max = beta * offdiag.max() if n > 0 else 0.0
    # split so that b * offdiag stays a hair below 1 (round-off margin)
    substeps = max(1, math.ceil(c_max / (1.0 - 1e-9)))
    b = beta / substeps
    for _ in range(substeps):
        gain = np.zeros(n)
        for k in range(pairs.shape[0]):
            i, j = pairs[k, 0], pairs[k, 1]
            gain[i] += p[k] * m[j]
            gain[j] += p[k] * m[i]
        m = m * (1.0 - b * offdiag) + b * gain  # non-negative terms only
    return m, substeps, c_max
