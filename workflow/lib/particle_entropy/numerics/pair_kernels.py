"""The compiled loops of MTPT on a pair list in d dimensions: Eq. 17's weights with pair-averaged
tensors, and Eqs. 16-18.

Kept apart from pair_transfer so that what only reads results (the Fig. 10 plot, the workflow's
parse) does not load numba."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _root_det_and_form(a, r, low, z):
    """(sqrt(det a), r^T a^-1 r) of a symmetric d x d tensor by its Cholesky factor ``low`` (work
    arrays ``low``, ``z``); (0, 0) when ``a`` is not positive definite."""
    d = r.size
    root = 1.0
    for c in range(d):
        s = a[c, c]
        for k in range(c):
            s -= low[c, k] * low[c, k]
        if s <= 0.0:
            return 0.0, 0.0
        low[c, c] = math.sqrt(s)
        root *= low[c, c]
        for row in range(c + 1, d):
            t = a[row, c]
            for k in range(c):
                t -= low[row, k] * low[c, k]
            low[row, c] = t / low[c, c]
    q = 0.0
    for c in range(d):  # L z = r, so z.z = r^T a^-1 r
        t = r[c]
        for k in range(c):
            t -= low[c, k] * z[k]
        z[c] = t / low[c, c]
        q += z[c] * z[c]
    return root, q


@njit(cache=True)
def pair_weights(points, tensors, pairs, period, dt):
    """W_ij = exp(-r^T D_ij^-1 r / (8 dt)) / sqrt(det D_ij), D_ij = (D_i + D_j) / 2, per listed pair;
    r is the minimum image along directions of period > 0; 0 where D_ij is not positive definite."""
    d = points.shape[1]
    w = np.zeros(pairs.shape[0])
    dbar = np.empty((d, d))
    low = np.zeros((d, d))
    r = np.empty(d)
    z = np.empty(d)
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        for a in range(d):
            da = points[i, a] - points[j, a]
            p = period[a]
            if p > 0.0:
                if da > 0.5 * p:
                    da -= p
                elif da < -0.5 * p:
                    da += p
            r[a] = da
            for b in range(d):
                dbar[a, b] = 0.5 * (tensors[i, a, b] + tensors[j, a, b])
        root, q = _root_det_and_form(dbar, r, low, z)
        if root > 0.0:
            w[k] = math.exp(-q / (8.0 * dt)) / root
    return w


@njit(cache=True)
def pair_weights_diagonal(points, diagonals, pairs, period, dt):
    """``pair_weights`` for diagonal tensors, given as (N, d) diagonals: the same W_ij without the
    factorisation (a third of the time per pair)."""
    d = points.shape[1]
    w = np.zeros(pairs.shape[0])
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        q = 0.0
        det = 1.0
        for a in range(d):
            dbar = 0.5 * (diagonals[i, a] + diagonals[j, a])
            if dbar <= 0.0:
                det = 0.0
                break
            da = abs(points[i, a] - points[j, a])
            p = period[a]
            if p > 0.0:
                da = min(da, p - da)
            q += da * da / dbar
            det *= dbar
        if det > 0.0:
            w[k] = math.exp(-q / (8.0 * dt)) / math.sqrt(det)
    return w


@njit(cache=True)
def self_weights(tensors):
    """W_ii = 1 / sqrt(det D_i), infinite where D_i is not positive definite."""
    n, d = tensors.shape[0], tensors.shape[1]
    out = np.empty(n)
    low = np.zeros((d, d))
    zero = np.zeros(d)
    z = np.empty(d)
    for i in range(n):
        root, _ = _root_det_and_form(tensors[i], zero, low, z)
        out[i] = 1.0 / root if root > 0.0 else np.inf
    return out


@njit(cache=True)
def pair_transfer(pairs, w, w_self, m, beta):
    """Eqs. 16-18 on a pair list: returns (new masses, substeps, beta * max_i sum_{j != i} P_ij)."""
    n = m.size
    off = np.zeros(n)
    for k in range(pairs.shape[0]):
        off[pairs[k, 0]] += w[k]
        off[pairs[k, 1]] += w[k]
    inv_r = np.zeros(n)  # 1 / r_i, r_i = W_ii + sum_{j != i} W_ij: 0 where W_ii is infinite
    for i in range(n):
        if w_self[i] < np.inf:
            inv_r[i] = 1.0 / (w_self[i] + off[i])
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
