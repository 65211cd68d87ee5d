"""The authors' sequential pairwise mass transfer (reference MATLAB code), for comparison.

Not the paper's equations: particle i in order exchanges with each partner j > i within the
cut-off, partners in random order, dm = beta (m_i - m_j) W_ij / r_i with r_i the row sum of i
alone, and masses clipped at zero after every exchange (so mass is not conserved exactly).
The project's ../shared/docs/experiments.md states these facts about that code; here they are re-implemented from that
description to measure how far the symmetric matrix of Eqs. 16-21 is from it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _sequential(x, m, sigma, radius, beta, keys):
    n = x.shape[0]
    inv2s2 = 0.5 / (sigma * sigma)
    lo = 0
    hi = 0
    order = np.empty(n, np.int64)
    kk = np.empty(n)
    for i in range(n):
        while x[lo] < x[i] - radius:
            lo += 1
        if hi < i + 1:
            hi = i + 1
        while hi < n and x[hi] <= x[i] + radius:
            hi += 1
        r = 0.0
        for j in range(lo, hi):
            d = x[i] - x[j]
            r += math.exp(-d * d * inv2s2)
        cnt = hi - (i + 1)
        for c in range(cnt):
            order[c] = i + 1 + c
            kk[c] = keys[i + 1 + c]
        idx = np.argsort(kk[:cnt])
        for c in range(cnt):
            j = order[idx[c]]
            d = x[i] - x[j]
            v = math.exp(-d * d * inv2s2) / r
            dm = beta * (m[i] - m[j]) * v
            m[i] = max(0.0, m[i] - dm)
            m[j] = max(0.0, m[j] + dm)
    return m


def sequential_transfer(
    x: np.ndarray, m: np.ndarray, sigma: float, beta: float, truncation: float | None, rng: np.random.Generator
) -> np.ndarray:
    """One step of the authors' loop on sorted positions; partners ordered by random keys."""
    radius = (9.0 if truncation is None else float(truncation)) * sigma
    keys = rng.random(x.size)
    return _sequential(np.ascontiguousarray(x), m.copy(), float(sigma), float(radius), float(beta), keys)
