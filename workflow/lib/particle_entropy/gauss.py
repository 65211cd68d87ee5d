"""Discrete Gauss transforms in 1-D: out[k, i] = sum_j exp(-(y_i - x_j)^2 / (2 sigma^2)) q[k, j].

These sums are the only O(N^2)-looking work of the project (MTPT transfer weights,
Eqs. 17 and 21, and kernel reconstructions, Eq. 10). Two exact-to-round-off methods
share one entry point, :func:`gauss_transform`; neither builds an N x N matrix:

* ``direct``: windowed sum over sorted sources, O(N x neighbours) time, O(N) memory.
  Used for truncated kernels (exactly the pairs with |y - x| <= truncation * sigma) and
  whenever the neighbour count is small.
* ``taylor``: sources are grouped in boxes of width sigma; each box carries ``P_TERMS``
  Taylor moments of exp(u v) (u, v: source and target offsets from the box centre in
  units of sigma). Truncation error < 1e-17 of the kernel's peak (see ``P_TERMS``), so
  the transform stays symmetric to round-off and MTPT conserves mass to round-off.
  O(N x P_TERMS x boxes-in-range) time, independent of the neighbour count.

For the untruncated Gaussian both methods drop pairs farther apart than
``CUTOFF_SIGMAS`` sigma, where the kernel is below exp(-CUTOFF_SIGMAS^2 / 2) = 2.6e-18,
i.e. below double-precision resolution of the self term (which is 1).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

CUTOFF_SIGMAS = 9.0
P_TERMS = 24
# The Taylor method wins once a target sees more sources than this (measured crossover,
# see benchmarks/bench_transfer.py).
DIRECT_MAX_NEIGHBOURS = 150.0


@njit(cache=True)
def _direct(y, x, q, sigma, radius, skip_self):
    nk, ns = q.shape
    nt = y.shape[0]
    out = np.zeros((nk, nt))
    inv2s2 = 0.5 / (sigma * sigma)
    lo = 0
    hi = 0
    for i in range(nt):
        yi = y[i]
        while lo < ns and x[lo] < yi - radius:
            lo += 1
        if hi < lo:
            hi = lo
        while hi < ns and x[hi] <= yi + radius:
            hi += 1
        for j in range(lo, hi):
            if skip_self and j == i:
                continue
            d = yi - x[j]
            w = math.exp(-d * d * inv2s2)
            for k in range(nk):
                out[k, i] += w * q[k, j]
    return out


@njit(cache=True)
def _taylor_moments(x, q, sigma, x0, nbox_guess, p):
    """Box ids, box centres and Taylor moments A[b, n, k] of sorted sources."""
    nk, ns = q.shape
    ids = np.empty(ns, np.int64)
    for j in range(ns):
        ids[j] = int(math.floor((x[j] - x0) / sigma))
    # unique (sorted) box ids
    nb = 0
    for j in range(ns):
        if j == 0 or ids[j] != ids[j - 1]:
            nb += 1
    centres = np.empty(nb)
    A = np.zeros((nb, p, nk))
    b = -1
    inv_fact = np.empty(p)
    inv_fact[0] = 1.0
    for n in range(1, p):
        inv_fact[n] = inv_fact[n - 1] / n
    for j in range(ns):
        if j == 0 or ids[j] != ids[j - 1]:
            b += 1
            centres[b] = x0 + (ids[j] + 0.5) * sigma
        u = (x[j] - centres[b]) / sigma
        g = math.exp(-0.5 * u * u)
        un = 1.0
        for n in range(p):
            c = g * un * inv_fact[n]
            for k in range(nk):
                A[b, n, k] += c * q[k, j]
            un *= u
    return centres, A


@njit(cache=True)
def _taylor_eval(y, centres, A, sigma, radius):
    nb, p, nk = A.shape
    nt = y.shape[0]
    out = np.zeros((nk, nt))
    reach = radius + 0.5 * sigma
    lo = 0
    hi = 0
    acc = np.empty(nk)
    for i in range(nt):
        yi = y[i]
        while lo < nb and centres[lo] < yi - reach:
            lo += 1
        if hi < lo:
            hi = lo
        while hi < nb and centres[hi] <= yi + reach:
            hi += 1
        for b in range(lo, hi):
            v = (yi - centres[b]) / sigma
            for k in range(nk):
                acc[k] = A[b, p - 1, k]
            for n in range(p - 2, -1, -1):
                for k in range(nk):
                    acc[k] = acc[k] * v + A[b, n, k]
            g = math.exp(-0.5 * v * v)
            for k in range(nk):
                out[k, i] += g * acc[k]
    return out


def neighbour_count(y: np.ndarray, x: np.ndarray, radius: float) -> float:
    """Mean number of sources within ``radius`` of a target (sorted inputs)."""
    if y.size == 0 or x.size == 0:
        return 0.0
    hi = np.searchsorted(x, y + radius, side="right")
    lo = np.searchsorted(x, y - radius, side="left")
    return float(np.mean(hi - lo))


def choose_method(y, x, sigma, truncation) -> str:
    """Pick ``direct`` or ``taylor`` for this transform (see module docstring)."""
    if truncation is not None:
        return "direct"
    if neighbour_count(y, x, CUTOFF_SIGMAS * sigma) <= DIRECT_MAX_NEIGHBOURS:
        return "direct"
    return "taylor"


def gauss_transform(
    y: np.ndarray,
    x: np.ndarray,
    q: np.ndarray,
    sigma: float,
    truncation: float | None = None,
    method: str = "auto",
    skip_self: bool = False,
) -> np.ndarray:
    """Return out[k, i] = sum_j exp(-(y_i - x_j)^2 / (2 sigma^2)) q[k, j].

    ``y`` and ``x`` must be sorted ascending; ``q`` has shape (k, len(x)) or (len(x),).
    ``truncation``: None for the whole Gaussian, else drop pairs with |y - x| > truncation * sigma.
    ``skip_self`` (only when ``y is x``): leave out the j == i term (direct method only).
    """
    y = np.ascontiguousarray(y, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    squeeze = q.ndim == 1
    q2 = np.ascontiguousarray(np.atleast_2d(q))
    if q2.shape[1] != x.shape[0]:
        raise ValueError(f"weights have {q2.shape[1]} columns for {x.shape[0]} sources")
    if not (sigma > 0 and math.isfinite(sigma)):
        raise ValueError(f"sigma must be positive and finite, got {sigma!r}")
    if method == "auto":
        method = choose_method(y, x, sigma, truncation)
    radius = (CUTOFF_SIGMAS if truncation is None else float(truncation)) * sigma
    if method == "direct":
        out = _direct(y, x, q2, float(sigma), float(radius), bool(skip_self))
    elif method == "taylor":
        if truncation is not None:
            raise ValueError("the taylor method evaluates the untruncated kernel only")
        if skip_self:
            raise ValueError("skip_self is only supported by the direct method")
        if x.size == 0:
            out = np.zeros((q2.shape[0], y.size))
        else:
            centres, A = _taylor_moments(x, q2, float(sigma), float(x[0]), 0, P_TERMS)
            out = _taylor_eval(y, centres, A, float(sigma), float(radius))
    else:
        raise ValueError(f"method must be 'auto', 'direct' or 'taylor', got {method!r}")
    return out[0] if squeeze else out
