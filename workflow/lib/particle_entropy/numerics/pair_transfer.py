"""MTPT's mass transfer on a pair list in d dimensions (Eqs. 16-18) with Eq. 17's collision kernel
written with the pair-averaged tensor D_ij = (D_i + D_j) / 2 of per-particle tensors D_i.

W_ij = exp(-r^T D_ij^-1 r / (8 dt)) / sqrt(det D_ij) and W_ii = 1 / sqrt(det D_i): Eq. 17 in d
dimensions, a Gaussian of covariance 4 D_ij dt, without the factor (8 pi dt)^(-d/2) that every
weight shares and Eq. 18's normalisation cancels. A tensor that is not positive definite (D = 0,
a particle on a no-flow wall) makes the kernel a delta: a pair with such a D_ij gets W_ij = 0 (the
limit for r != 0), a particle with such a D_i an infinite W_ii, so its row of W / rowsum vanishes
and it exchanges only through the column-normalised half of P. A direction in which every D is 0
is no direction of the transfer: leave it out of ``points`` and ``tensors`` and zero the weights
of the pairs that differ in it.

Units: positions [L], tensors [L^2/T], dt [T]; weights in [T^(-d/2) L^(-d)] up to that factor.
"""

from __future__ import annotations

import numpy as np


def _tensors(D, n: int, d: int) -> np.ndarray:
    """Per-particle diagonals (N, d) or tensors (N, d, d), C-contiguous float64; else ValueError."""
    D = np.ascontiguousarray(D, dtype=np.float64)
    if D.shape not in ((n, d), (n, d, d)):
        raise ValueError(f"tensors must be (N, d) diagonals or (N, d, d), N = {n}, d = {d}; not {D.shape}")
    return D


def _points(points) -> np.ndarray:
    pts = np.asarray(points, dtype=np.float64)
    return np.ascontiguousarray(pts[:, None] if pts.ndim == 1 else pts)


def _period(period, d: int) -> np.ndarray:
    """(d,) periods, 0 for an open direction (None or 0 in ``period``)."""
    if period is None:
        return np.zeros(d)
    period = np.broadcast_to(np.array(period, dtype=object), (d,))
    return np.array([0.0 if p is None else float(p) for p in period])


def pair_weights(points, tensors, pairs, dt: float, period=None) -> np.ndarray:
    """W_ij of the listed pairs (n_pairs, 2) for positions (N,) or (N, d) and per-particle
    ``tensors``, (N, d) diagonals or (N, d, d); r is the minimum image along a direction of
    ``period`` (positions there must lie in [0, period))."""
    from . import pair_kernels  # numba: loaded by the jobs that step

    pts = _points(points)
    n, d = pts.shape
    t = _tensors(tensors, n, d)
    loop = pair_kernels.pair_weights_diagonal if t.ndim == 2 else pair_kernels.pair_weights
    pairs = np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)
    return loop(pts, t, pairs, _period(period, d), float(dt))


def self_weights(tensors) -> np.ndarray:
    """W_ii = 1 / sqrt(det D_i) of per-particle (N, d) diagonals or (N, d, d) tensors, infinite
    where D_i is not positive definite."""
    t = np.asarray(tensors, dtype=np.float64)
    t = _tensors(t, t.shape[0], t.shape[1])
    if t.ndim == 3:
        from .pair_kernels import self_weights as loop

        return loop(t)
    det = np.prod(t, axis=1)
    definite = np.all(t > 0.0, axis=1) & (det > 0.0)  # det may underflow
    return np.divide(1.0, np.sqrt(np.where(definite, det, 1.0)), out=np.full(det.size, np.inf), where=definite)


def transfer(pairs, w, w_self, m, beta: float) -> tuple[np.ndarray, int, float]:
    """m_i <- m_i + beta sum_j P_ij (m_j - m_i) (Eq. 16), P = (W / rowsum + W / colsum) / 2 (Eq. 18)
    over the listed pairs, row sums r_i = W_ii + sum_j W_ij. The step is split into ``substeps``
    equal parts of beta when beta * max_i sum_{j != i} P_ij > 1, so masses stay non-negative.
    -> (masses, substeps, beta * max_i sum_{j != i} P_ij)."""
    from .pair_kernels import pair_transfer as loop

    pairs = np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)
    out, substeps, c_max = loop(
        pairs,
        np.ascontiguousarray(w, dtype=np.float64),
        np.ascontiguousarray(w_self, dtype=np.float64),
        np.array(m, dtype=np.float64),
        float(beta),
    )
    return out, int(substeps), float(c_max)


def tensor_transfer(points, tensors, pairs, m, beta: float, dt: float, period=None) -> tuple[np.ndarray, int, float]:
    """One transfer (``transfer``) with the weights of ``pair_weights`` and ``self_weights``."""
    pts = _points(points)
    t = _tensors(tensors, *pts.shape)
    w = pair_weights(pts, t, pairs, dt, period)
    return transfer(pairs, w, self_weights(t), m, beta)
