"""Today's (before issue 20) authors' loop, kept verbatim as the reference the fast loop must
match bit for bit: sequential._sweep as of commit 0c6f3df, with gauss._exp_neg's table form."""

from __future__ import annotations

import numpy as np
from numba import njit

# exp(-a) for the windowed sums, 0 <= a: inline arithmetic that compilers vectorise (a libm
# call per pair does not). 2^-k from a table, e^r by a degree-13 Taylor polynomial on
# |r| <= ln(2) / 2 (truncation < 5e-18 relative), ln 2 split in two for exact reduction.
_LN2_HI = 0.693147180369123816490  # 32 significant bits: k * _LN2_HI is exact
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.4426950408889634
_EXP_MAX_K = 1100  # beyond this exp(-a) is 0 in double precision
_POW2_NEG = np.array([2.0**-k for k in range(_EXP_MAX_K + 1)])


@njit(cache=True, inline="always")
def _exp_neg(a):
    """exp(-a) for a >= 0, to about 1 ulp."""
    k = min(int(a * _INV_LN2 + 0.5), _EXP_MAX_K)  # 2^-_EXP_MAX_K is 0.0: exp underflows
    r = (k * _LN2_HI - a) + k * _LN2_LO  # -a + k ln 2, |r| <= ln(2) / 2
    return _taylor_exp13(r) * _POW2_NEG[k]


@njit(cache=True, inline="always")
def _taylor_exp13(r):
    """sum_(n <= 13) r^n / n! (Horner, literal coefficients so the loop vectorises)."""
    return (
        (
            (
                (
                    (
                        (
                            (
                                (
                                    (
                                        (
                                            (
                                                ((1.6059043836821613e-10) * r + 2.08767569878681e-09) * r
                                                + 2.505210838544172e-08
                                            )
                                            * r
                                            + 2.755731922398589e-07
                                        )
                                        * r
                                        + 2.7557319223985893e-06
                                    )
                                    * r
                                    + 2.48015873015873e-05
                                )
                                * r
                                + 0.0001984126984126984
                            )
                            * r
                            + 0.001388888888888889
                        )
                        * r
                        + 0.008333333333333333
                    )
                    * r
                    + 0.041666666666666664
                )
                * r
                + 0.16666666666666666
            )
            * r
            + 0.5
        )
        * r
        + 1.0
    ) * r + 1.0


@njit(cache=True, inline="always")
def _splitmix(state):
    """Next state and 64-bit output of SplitMix64."""
    state = state + np.uint64(0x9E3779B97F4A7C15)
    z = state
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return state, z ^ (z >> np.uint64(31))


@njit(cache=True, fastmath={"contract"})
def _kernel(u, out, cnt):
    """out[k] = exp(-u[k]) for k < cnt, by gauss._exp_neg (arithmetic that vectorises)."""
    for k in range(cnt):
        out[k] = _exp_neg(u[k])


@njit(cache=True)
def _row_sums(x, radius, inv2s2):
    """r_i = sum of W_ij over |x_i - x_j| <= radius, i included (x sorted)."""
    n = x.shape[0]
    r = np.empty(n)
    u = np.empty(n)
    w = np.empty(n)
    for p in range(n):
        lo = np.searchsorted(x, x[p] - radius, side="left")
        hi = np.searchsorted(x, x[p] + radius, side="right")
        for k in range(lo, hi):
            d = x[p] - x[k]
            u[k - lo] = d * d * inv2s2
        _kernel(u, w, hi - lo)
        r[p] = w[: hi - lo].sum()
    return r


@njit(cache=True, fastmath={"contract"})
def _sweep(x, m, label, sigma, radius, beta, seed, symnorm, clip):
    """One step of the loop on positions ``x`` sorted, ``label`` the storage index of each."""
    n = x.shape[0]
    inv2s2 = 0.5 / (sigma * sigma)
    where = np.empty(n, np.int64)  # sorted index of the particle stored at i
    for p in range(n):
        where[label[p]] = p
    r_full = _row_sums(x, radius, inv2s2) if symnorm else np.zeros(n)
    # The particles not yet visited, in position order: positions, sorted indices, labels, masses,
    # row sums so far (and whole row sums). Only they exchange mass from here on: a visited
    # particle is final, written back when the arrays are compacted every `chunk` visits.
    xs = x.copy()
    ps = np.arange(n)
    ls = label.copy()
    ms = m.copy()
    rs = np.zeros(n)
    rf = r_full.copy()
    left = n
    chunk = max(64, n // 32)
    part = np.empty(n, np.int64)
    u = np.empty(n)
    c = np.empty(n)
    state = np.uint64(seed)
    for i in range(n):
        if i % chunk == 0 and i > 0:
            k2 = 0
            for k in range(left):
                if ls[k] >= i:
                    xs[k2] = xs[k]
                    ps[k2] = ps[k]
                    ls[k2] = ls[k]
                    ms[k2] = ms[k]
                    rs[k2] = rs[k]
                    rf[k2] = rf[k]
                    k2 += 1
                else:
                    m[ps[k]] = ms[k]
            left = k2
        xp = x[where[i]]
        lo = np.searchsorted(xs[:left], xp - radius, side="left")
        hi = np.searchsorted(xs[:left], xp + radius, side="right")
        me = np.searchsorted(xs[:left], xp, side="left")  # i itself
        while ls[me] != i:
            me += 1
        cnt = 0
        for k in range(lo, hi):  # partners: later in storage (branch-free compaction)
            d = xp - xs[k]
            part[cnt] = k
            u[cnt] = d * d * inv2s2
            cnt += ls[k] > i
        if cnt == 0:
            continue
        _kernel(u, c, cnt)
        s = 0.0
        for k in range(cnt):
            s += c[k]
            rs[part[k]] += c[k]
        inv_r = 1.0 / (rf[me] if symnorm else rs[me] + 1.0 + s)
        if symnorm:  # c = beta W_ij / r_i (symnorm: the mean of 1/r_i and 1/r_j)
            for k in range(cnt):
                c[k] *= beta * 0.5 * (inv_r + 1.0 / rf[part[k]])
        else:
            b = beta * inv_r
            for k in range(cnt):
                c[k] *= b
        mi = ms[me]
        z = np.uint64(0)
        for k in range(cnt):
            # Fisher-Yates as we go: the k-th partner is uniform among those left; 32 random
            # bits a draw, two draws from each 64-bit output
            if k % 2 == 0:
                state, z = _splitmix(state)
                bits = z >> np.uint64(32)
            else:
                bits = z & np.uint64(0xFFFFFFFF)
            j = k + np.int64((bits * np.uint64(cnt - k)) >> np.uint64(32))
            q = part[j]
            cj = c[j]
            part[j] = part[k]
            c[j] = c[k]
            mj = ms[q]
            dm = cj * (mi - mj)  # beta (m_i - m_j) W_ij / r_i
            if clip:
                mi = max(0.0, mi - dm)
                ms[q] = max(0.0, mj + dm)
            else:
                mi = mi - dm
                ms[q] = mj + dm
        ms[me] = mi
    for k in range(left):
        m[ps[k]] = ms[k]
    return m
