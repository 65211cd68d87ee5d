"""Discrete Gauss transforms in 1-D: out[k, i] = sum_j exp(-(y_i - x_j)^2 / (2 sigma^2)) q[k, j].

These sums are the only O(N^2)-looking work of the project (MTPT transfer weights,
Eqs. 17 and 21, and kernel reconstructions, Eq. 10). Three methods, exact to round-off,
share one entry point, :func:`gauss_transform`; none builds an N x N matrix:

* ``direct``: windowed sum over sorted sources, O(N x neighbours) time, O(N) memory.
  Used for truncated kernels (exactly the pairs with |y - x| <= truncation * sigma) and
  whenever the neighbour count is small (``auto`` below ``DIRECT_MAX_NEIGHBOURS``).
* ``fgt``: fast Gauss transform, the ``auto`` choice at large neighbour counts. Source
  boxes of width sigma carry ``FGT_TERMS`` Hermite moments, translated to Taylor
  expansions about each target box; sparse box pairs are summed exactly. Truncation error
  < 1e-18 of the kernel's peak, so the transform stays symmetric to round-off and MTPT
  conserves mass to round-off. O(N x FGT_TERMS) time plus O(boxes x FGT_TERMS^2).
* ``taylor``: per-target evaluation of each source box's Taylor moments of exp(u v);
  O(N x P_TERMS x boxes-in-range), kept as an independent cross-check of ``fgt``.

For the untruncated Gaussian all methods drop pairs farther apart than
``CUTOFF_SIGMAS`` sigma, where the kernel is below exp(-CUTOFF_SIGMAS^2 / 2) = 2.6e-18,
i.e. below double-precision resolution of the self term (which is 1).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

CUTOFF_SIGMAS = 9.0
P_TERMS = 24
# Hermite / Taylor terms of the fast Gauss transform with boxes of width sigma: the
# truncation error of both expansions is below r^p / sqrt(p!) / (1 - r), r = 1 / (2 sqrt 2),
# i.e. < 1e-18 of the kernel's peak for p = 20.
FGT_TERMS = 20
# The fast Gauss transform wins once a target sees more sources than this within the
# cut-off (measured crossover, see benchmarks/bench_transfer.py).
DIRECT_MAX_NEIGHBOURS = 300.0


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
def _direct_symmetric(x, q, sigma, radius):
    """Windowed sum with targets = sources: each pair's exp is evaluated once."""
    nk, n = q.shape
    out = q.copy()  # self terms, W_ii = 1
    inv2s2 = 0.5 / (sigma * sigma)
    hi = 0
    for i in range(n):
        if hi < i + 1:
            hi = i + 1
        while hi < n and x[hi] <= x[i] + radius:
            hi += 1
        for j in range(i + 1, hi):
            d = x[i] - x[j]
            w = math.exp(-d * d * inv2s2)
            for k in range(nk):
                out[k, i] += w * q[k, j]
                out[k, j] += w * q[k, i]
    return out


@njit(cache=True)
def _taylor_moments(x, q, sigma, x0, p):
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


@njit(cache=True)
def _boxes(z, origin, width):
    """Consecutive-box partition of sorted z: (box start indices incl. end, box centres)."""
    n = z.shape[0]
    starts = np.empty(n + 1, np.int64)
    centres = np.empty(n)
    nb = 0
    prev = -(2**62)
    for j in range(n):
        b = int(math.floor((z[j] - origin) / width))
        if b != prev:
            starts[nb] = j
            centres[nb] = origin + (b + 0.5) * width
            nb += 1
            prev = b
    starts[nb] = n
    return starts[: nb + 1], centres[:nb]


@njit(cache=True)
def _fgt(y, x, q, sigma, radius, p):
    """Fast Gauss transform: Hermite expansions of source boxes translated to Taylor
    expansions about target-box centres (Greengard-Strain), boxes of width sigma."""
    nk, ns = q.shape
    nt = y.shape[0]
    scale = 1.0 / (math.sqrt(2.0) * sigma)  # kernel = exp(-(Y - X)^2) in scaled units
    # Boxes and offsets live in the original units: x - c, y - c and c_t - c_s are exact
    # differences of nearby numbers, so no precision is lost when sigma << |x|.
    reach = radius + sigma
    origin = min(x[0], y[0])
    s_starts, s_centres = _boxes(x, origin, sigma)
    t_starts, t_centres = _boxes(y, origin, sigma)
    nbs = s_centres.shape[0]
    # Hermite moments A[b, n, k] = sum_j q_kj (X_j - C_b)^n / n!
    A = np.zeros((nbs, p, nk))
    for b in range(nbs):
        for j in range(s_starts[b], s_starts[b + 1]):
            u = (x[j] - s_centres[b]) * scale
            c = 1.0
            for n in range(p):
                for k in range(nk):
                    A[b, n, k] += c * q[k, j]
                c *= u / (n + 1)
    out = np.zeros((nk, nt))
    h = np.empty(2 * p)
    B = np.empty((p, nk))
    inv_fact = np.empty(p)
    inv_fact[0] = 1.0
    for m in range(1, p):
        inv_fact[m] = inv_fact[m - 1] / m
    lo = 0
    for tb in range(t_centres.shape[0]):
        ct = t_centres[tb]
        while lo < nbs and s_centres[lo] < ct - reach:
            lo += 1
        B[:, :] = 0.0
        sb = lo
        t_lo, t_hi = t_starts[tb], t_starts[tb + 1]
        while sb < nbs and s_centres[sb] <= ct + reach:
            s_lo, s_hi = s_starts[sb], s_starts[sb + 1]
            if (s_hi - s_lo) * (t_hi - t_lo) * (8 + nk) <= p * p * nk:
                # sparse box pair: exact pairwise sum is cheaper than a translation
                for i in range(t_lo, t_hi):
                    for j in range(s_lo, s_hi):
                        d = (y[i] - x[j]) * scale
                        g = math.exp(-d * d)
                        for k in range(nk):
                            out[k, i] += g * q[k, j]
                sb += 1
                continue
            t0 = (ct - s_centres[sb]) * scale
            h[0] = math.exp(-t0 * t0)
            h[1] = 2.0 * t0 * h[0]
            for kk in range(1, 2 * p - 1):
                h[kk + 1] = 2.0 * t0 * h[kk] - 2.0 * kk * h[kk - 1]
            for m in range(p):
                for n in range(p):
                    hn = h[n + m]
                    for k in range(nk):
                        B[m, k] += A[sb, n, k] * hn
            sb += 1
        for m in range(p):
            f = inv_fact[m] if m % 2 == 0 else -inv_fact[m]
            for k in range(nk):
                B[m, k] *= f
        for i in range(t_lo, t_hi):
            w = (y[i] - ct) * scale
            for k in range(nk):
                acc = B[p - 1, k]
                for m in range(p - 2, -1, -1):
                    acc = acc * w + B[m, k]
                out[k, i] += acc
    return out


def neighbour_count(y: np.ndarray, x: np.ndarray, radius: float) -> float:
    """Mean number of sources within ``radius`` of a target (sorted inputs)."""
    if y.size == 0 or x.size == 0:
        return 0.0
    hi = np.searchsorted(x, y + radius, side="right")
    lo = np.searchsorted(x, y - radius, side="left")
    return float(np.mean(hi - lo))


def choose_method(y, x, sigma, truncation) -> str:
    """Pick ``direct`` or ``fgt`` for this transform (see module docstring)."""
    if truncation is not None:
        return "direct"
    if neighbour_count(y, x, CUTOFF_SIGMAS * sigma) <= DIRECT_MAX_NEIGHBOURS:
        return "direct"
    return "fgt"


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
    same = y is x
    y = np.ascontiguousarray(y, dtype=np.float64)
    x = y if same else np.ascontiguousarray(x, dtype=np.float64)
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
    if method == "direct" and same and not skip_self:
        out = _direct_symmetric(x, q2, float(sigma), float(radius))
    elif method == "direct":
        out = _direct(y, x, q2, float(sigma), float(radius), bool(skip_self))
    elif method == "fgt":
        if truncation is not None:
            raise ValueError("the fgt method evaluates the untruncated kernel only")
        if skip_self:
            raise ValueError("skip_self is only supported by the direct method")
        if x.size == 0 or y.size == 0:
            out = np.zeros((q2.shape[0], y.size))
        else:
            out = _fgt(y, x, q2, float(sigma), float(radius), FGT_TERMS)
    elif method == "taylor":
        if truncation is not None:
            raise ValueError("the taylor method evaluates the untruncated kernel only")
        if skip_self:
            raise ValueError("skip_self is only supported by the direct method")
        if x.size == 0:
            out = np.zeros((q2.shape[0], y.size))
        else:
            centres, A = _taylor_moments(x, q2, float(sigma), float(x[0]), P_TERMS)
            out = _taylor_eval(y, centres, A, float(sigma), float(radius))
    else:
        raise ValueError(f"method must be 'auto', 'direct', 'fgt' or 'taylor', got {method!r}")
    return out[0] if squeeze else out
