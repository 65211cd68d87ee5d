"""The compiled loops of the discrete Gauss transforms (numerics/gauss.py states the methods and
chooses among them): the windowed direct sums, the Taylor cross-check and the fast Gauss
transform. Only numba-compiled code lives here, so that gauss.py imports without numba: a job
that runs them ahead-of-time compiled (numerics/compiled.py) never starts numba's JIT."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .fastexp import EXP_NEAR_MAX, exp_neg, exp_neg_near, wide_vectors


@njit(cache=True, inline="always")
def _window_weights(yi, x, lo, hi, inv2s2, near, buf):
    """buf[j - lo] <- exp(-(yi - x_j)^2 / (2 sigma^2)) for lo <= j < hi; exp_neg_near (the same
    bits, cheaper) where the window's largest argument allows it."""
    if near:
        for j in range(lo, hi):
            d = yi - x[j]
            buf[j - lo] = exp_neg_near(d * d * inv2s2)
    else:
        for j in range(lo, hi):
            d = yi - x[j]
            buf[j - lo] = exp_neg(d * d * inv2s2)


@njit(cache=True, fastmath={"reassoc", "contract"})
def direct(y, x, q, sigma, radius, skip_self):
    """Windowed sum over sorted sources; the window's weights go to a buffer first, so the
    exp and the sums vectorise (512-bit vectors where the CPU has them)."""
    wide_vectors()
    nk, ns = q.shape
    nt = y.shape[0]
    out = np.zeros((nk, nt))
    buf = np.empty(ns)
    inv2s2 = 0.5 / (sigma * sigma)
    near = radius * radius * inv2s2 <= EXP_NEAR_MAX
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
        _window_weights(yi, x, lo, hi, inv2s2, near, buf)
        if skip_self and lo <= i < hi:
            buf[i - lo] = 0.0
        for k in range(nk):
            acc = 0.0
            for j in range(lo, hi):
                acc += buf[j - lo] * q[k, j]
            out[k, i] = acc
    return out


@njit(cache=True, fastmath={"reassoc", "contract"})
def direct_symmetric(x, q, sigma, radius):
    """Windowed sum with targets = sources: each pair's exp is evaluated once (into a
    buffer, so that the exp and the sums vectorise over a window, 512-bit where the CPU has it)."""
    wide_vectors()
    nk, n = q.shape
    out = q.copy()  # self terms, W_ii = 1
    inv2s2 = 0.5 / (sigma * sigma)
    near = radius * radius * inv2s2 <= EXP_NEAR_MAX
    buf = np.empty(n)
    hi = 0
    for i in range(n):
        if hi < i + 1:
            hi = i + 1
        while hi < n and x[hi] <= x[i] + radius:
            hi += 1
        lo = i + 1
        _window_weights(x[i], x, lo, hi, inv2s2, near, buf)
        for k in range(nk):
            qi = q[k, i]
            acc = 0.0
            for j in range(lo, hi):
                w = buf[j - lo]
                acc += w * q[k, j]
                out[k, j] += w * qi
            out[k, i] += acc
    return out


@njit(cache=True)
def taylor_moments(x, q, sigma, x0, p):
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
def taylor_eval(y, centres, A, sigma, radius):
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
    """Consecutive-box partition of sorted z: (box start indices incl. end, integer box ids)."""
    n = z.shape[0]
    starts = np.empty(n + 1, np.int64)
    ids = np.empty(n, np.int64)
    nb = 0
    prev = -(2**62)
    for j in range(n):
        b = int(math.floor((z[j] - origin) / width))
        if b != prev:
            starts[nb] = j
            ids[nb] = b
            nb += 1
            prev = b
    starts[nb] = n
    return starts[: nb + 1], ids[:nb]


@njit(cache=True)
def _hermite_table(kmax, step, p):
    """h_n(t) = exp(-t^2) H_n(t), n < 2p, at t = d * step for box offsets d = -kmax .. kmax."""
    H = np.empty((2 * kmax + 1, 2 * p))
    for d in range(-kmax, kmax + 1):
        t = d * step
        row = H[d + kmax]
        row[0] = math.exp(-t * t)
        row[1] = 2.0 * t * row[0]
        for n in range(1, 2 * p - 1):
            row[n + 1] = 2.0 * t * row[n] - 2.0 * n * row[n - 1]
    return H


@njit(cache=True, fastmath={"reassoc", "contract"})
def _hermite_moments(x, q, starts, ids, origin, width, scale, p):
    """A[b, k, n] = sum_{j in box b} q_kj u_j^n / n!, u_j = (x_j - c_b) scale (Hermite moments)."""
    nk = q.shape[0]
    nb = ids.shape[0]
    A = np.zeros((nb, nk, p))
    inv = np.empty(p)
    for n in range(p):
        inv[n] = 1.0 / (n + 1)
    maxc = 0
    for b in range(nb):
        maxc = max(maxc, starts[b + 1] - starts[b])
    u = np.empty(maxc)
    c = np.empty(maxc)
    for b in range(nb):
        lo = starts[b]
        cnt = starts[b + 1] - lo
        centre = origin + (ids[b] + 0.5) * width
        for jj in range(cnt):
            u[jj] = (x[lo + jj] - centre) * scale
        for k in range(nk):
            for jj in range(cnt):
                c[jj] = q[k, lo + jj]
            for n in range(p):
                s = 0.0
                for jj in range(cnt):
                    s += c[jj]
                A[b, k, n] = s
                for jj in range(cnt):
                    c[jj] *= u[jj] * inv[n]
    return A


@njit(cache=True)
def _empty_boxes(q, starts):
    """empty[b, k]: every weight q_kj of box b is zero."""
    nk = q.shape[0]
    nb = starts.shape[0] - 1
    empty = np.ones((nb, nk), np.bool_)
    for b in range(nb):
        for k in range(nk):
            for j in range(starts[b], starts[b + 1]):
                if q[k, j] != 0.0:
                    empty[b, k] = False
                    break
    return empty


@njit(cache=True)
def fgt(y, x, q, sigma, width, terms):
    """Fast Gauss transform (Greengard-Strain): Hermite moments of source boxes translated to
    Taylor coefficients about target-box centres; boxes ``width`` (see fgt_box_width) wide on one
    grid, so a translation depends only on the box offset and is tabulated once."""
    nk = q.shape[0]
    scale = 1.0 / (math.sqrt(2.0) * sigma)  # kernel = exp(-(Y - X)^2) in scaled units
    # Box geometry is exact: width is k 2^e with a small integer k and origin a multiple of
    # it, so every centre (b + 1/2) width is a float and centre offsets are exactly
    # d * width. The Hermite table therefore matches the centres used for moments and
    # evaluation, even when sigma << |x| (offsets x - c, y - c are in the original units).
    origin = math.floor(min(x[0], y[0]) / width) * width
    s_starts, s_ids = _boxes(x, origin, width)
    t_starts, t_ids = _boxes(y, origin, width)
    kmax = terms.shape[0] - 1  # pairs within the cut-off radius are at most kmax boxes apart
    p = terms[0]  # terms[d]: Hermite / Taylor terms for box pairs d boxes apart (most at 0)
    H = _hermite_table(kmax, width * scale, p)
    A = _hermite_moments(x, q, s_starts, s_ids, origin, width, scale, p)
    empty = _empty_boxes(q, s_starts)
    sign = np.empty(p)  # Taylor coefficients carry (-1)^m / m!
    sign[0] = 1.0
    for m in range(1, p):
        sign[m] = -sign[m - 1] / m
    nbs = s_ids.shape[0]
    out = np.zeros((nk, y.shape[0]))
    B = np.empty((nk, p))
    maxc = 0
    for tb in range(t_ids.shape[0]):
        maxc = max(maxc, t_starts[tb + 1] - t_starts[tb])
    v = np.empty(maxc)
    acc = np.empty(maxc)
    lo = 0
    for tb in range(t_ids.shape[0]):
        bt = t_ids[tb]
        while lo < nbs and s_ids[lo] < bt - kmax:
            lo += 1
        t_lo, t_hi = t_starts[tb], t_starts[tb + 1]
        ct = origin + (bt + 0.5) * width
        B[:, :] = 0.0
        sb = lo
        while sb < nbs and s_ids[sb] <= bt + kmax:
            s_lo, s_hi = s_starts[sb], s_starts[sb + 1]
            if empty[sb].all():
                sb += 1
                continue
            pp = terms[abs(bt - s_ids[sb])]
            if (s_hi - s_lo) * (t_hi - t_lo) * (30 + nk) <= pp * pp * nk:
                # sparse box pair: the exact pairwise sum is cheaper than a translation
                for i in range(t_lo, t_hi):
                    for j in range(s_lo, s_hi):
                        d = (y[i] - x[j]) * scale
                        g = exp_neg(d * d)
                        for k in range(nk):
                            out[k, i] += g * q[k, j]
            else:
                h = H[bt - s_ids[sb] + kmax]
                for k in range(nk):
                    if empty[sb, k]:
                        continue  # all weights zero (empty particles at early MTPT times)
                    for n in range(pp):
                        a = A[sb, k, n]
                        for m in range(pp):
                            B[k, m] += a * h[n + m]
            sb += 1
        cnt = t_hi - t_lo
        for ii in range(cnt):
            v[ii] = (y[t_lo + ii] - ct) * scale
        for k in range(nk):
            if not B[k].any():
                continue
            for ii in range(cnt):
                acc[ii] = B[k, p - 1] * sign[p - 1]
            for m in range(p - 2, -1, -1):
                b = B[k, m] * sign[m]
                for ii in range(cnt):
                    acc[ii] = acc[ii] * v[ii] + b
            for ii in range(cnt):
                out[k, t_lo + ii] += acc[ii]
    return out
