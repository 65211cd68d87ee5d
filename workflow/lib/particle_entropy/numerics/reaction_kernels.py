"""The compiled loop of the particle-killing A + B -> C reaction of random-walk particle tracking
(Benson & Meerschaert 2008, Water Resour. Res. 44, W12201): each A particle tests the B particles
within reach in turn, in a random order of the A's, and reacts with at most one of them.

Kept apart from models/reaction_step.py so that what only reads reactive results does not load numba."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def pair_reactions(xa, order, x_near, b_near, lo, hi, start, u, p_max, inv_var8):
    """For each A particle i (taken in ``order``) and each B candidate j in lo[i]:hi[i] of the sorted
    (periodically extended) B positions ``x_near`` (``b_near``: index of that B), the pair passes
    when u < P = p_max exp(-s^2 / (8 D dt)), s = xa[i] - x_near[j], with u the pair's uniform
    (u[start[i] + j - lo[i]]); among passing pairs whose B is still unreacted, the one with the
    largest P - u reacts. Returns (partner[i]: index into x_near of A's reacting B, or -1)."""
    na = xa.shape[0]
    nb = 0
    for j in range(b_near.shape[0]):
        nb = max(nb, b_near[j] + 1)
    taken = np.zeros(nb, dtype=np.bool_)
    partner = np.full(na, -1, dtype=np.int64)
    for t in range(na):
        i = order[t]
        best = 0.0
        best_j = -1
        for j in range(lo[i], hi[i]):
            if taken[b_near[j]]:
                continue
            s = xa[i] - x_near[j]
            margin = p_max * math.exp(-s * s * inv_var8) - u[start[i] + j - lo[i]]
            if margin > best:
                best = margin
                best_j = j
        if best_j >= 0:
            partner[i] = best_j
            taken[b_near[best_j]] = True
    return partner
