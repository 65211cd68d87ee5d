"""The authors' sequential pairwise mass transfer, and variants of it that change one detail.

Facts about the authors' MATLAB script (repository dbenson5225/Particle_Entropy, file
RW_entropy_ens_GSM_COMIC.m), checked line by line against that script and implemented here:

1. Storage. Particles keep the order in which they were created: the unit mass at x = 0 first,
   then N - 1 positions uniform on [-Omega/2, Omega/2]. Storage order is random in space and
   never changes; random walks move particles, not their place in storage.
2. Visits. Each step visits particles i = 1 ... N in storage order. Particle i exchanges with
   every neighbour j within the cut-off that comes later in storage (j > i); these lie on both
   sides of i.
3. Partner order. The partners of i are taken in a random order, a fresh permutation for each i.
4. Weights. The weight of pair (i, j) is W_ij / r_i, where W_ij = exp(-(x_i - x_j)^2 / (2 h^2))
   (the kernel's prefactor cancels) and r_i sums W over all of i's neighbours within the cut-off,
   i itself included. Positions do not change during the transfer, so r_i is fixed for the step.
5. Cut-off. Neighbours are found by a range search of radius 3 h (|x_i - x_j| <= 3 h).
6. Update. dm = beta (m_i - m_j) W_ij / r_i, then m_i <- max(0, m_i - dm) and
   m_j <- max(0, m_j + dm). The clipping breaks mass conservation only when it acts, which
   needs beta W_ij / r_i > 1. With beta = 1/2 it never acts, because W_ij <= r_i.
7. Kernels. Collision: h = sqrt(4 eta D dt), beta = 1/2 (Eq. 17). SPH: h = 0.822 (2 D t)^(2/5)
   (Omega/N)^(1/5), with D (not eta D) and t the time at the end of the step; beta =
   2 eta D dt / h^2 (Eq. 20), used as it is even above 1 (no splitting).
8. Random walk. When eta < 1, the same particles first take a random walk with (1 - eta) D,
   then the transfer.
9. Time loop. The clock advances by dt before the step, and the loop runs while t < t_final;
   dt grows by 1.05 after each step. With dt0 = 0.01 and t_final = 1000 it ends after 175
   steps at t = 1021.1 (timegrid.time_steps with grid "authors").
10. Details kept as the paper has them (each a small difference): the script's SPH constant is
   0.822 where Eq. 26 has 0.82 (0.24 % in h, 0.5 % in beta), and both kernels' lines are in the
   script, the SPH ones overriding the collision ones (one is commented in or out by hand).
11. Error and COMIC. The script's SSE is sum_i (g_i - m_i/dV)^2 / N with g the Gaussian at the
   particles normalised so that sum_i g_i dV = 1 (measures.sse over N, the same). Its Fig. 9
   is the COMIC of the ensemble-mean SSE at the last step, 2 ln(mean SSE/N) - ln(Omega/N), with
   error bars ln(mean +- std) - ln(mean) of the SSE: not doubled, so on the COMIC scale they are
   half the +-1 std of the SSE (aggregate.comic_of_mean_sse draws them doubled); its variance is
   a running estimate, not the sample variance.

Variants for the controlled experiments (registry.SCHEMES) each change one detail:
- ``sorted``: visit particles left to right, partners to the right only (storage = position
  order);
- ``symnorm``: weight W_ij (1/r_i + 1/r_j) / 2, the pair weight of the symmetric matrix
  (Eq. 18);
- ``noclip``: no clipping.

r_i is built during the sweep. When i is visited, every neighbour stored before i has already
been visited and has added its W to i's sum, so each pair's kernel is evaluated once. A visited
particle never changes again within the step, so the sweep keeps the unvisited ones in compact
arrays in position order, and each window holds almost only partners. The random
permutations come from a SplitMix64 stream that is seeded for each step from the run's numpy
Generator.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .fastexp import EXP_NEAR_MAX, exp_neg, exp_neg_near
from .gauss import cutoff_radius

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)  # SplitMix64's increment: its state after k outputs is s + k G


@njit(cache=True, inline="always")
def _splitmix(state):
    """Next state and 64-bit output of SplitMix64."""
    state = state + _GOLDEN
    z = state
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return state, z ^ (z >> np.uint64(31))


@njit(cache=True, fastmath={"contract"})
def _kernel(u, out, cnt, near=False):
    """out[k] = exp(-u[k]) for k < cnt, by fastexp.exp_neg (arithmetic that vectorises); ``near``:
    every u[k] <= fastexp.EXP_NEAR_MAX, so the cheaper fastexp.exp_neg_near gives the same bits."""
    if near:
        for k in range(cnt):
            out[k] = exp_neg_near(u[k])
    else:
        for k in range(cnt):
            out[k] = exp_neg(u[k])


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


@njit(cache=True, inline="always")
def _partners(i, xp, xs, ls, rs, left, radius, inv2s2, near, part, u, w, c):
    """The visit to i: its window [lo, hi) of the compact arrays, its partners (later in storage)
    part[:cnt] and their W_ij c[:cnt] in window order, their W added to their row sums ->
    (lo, hi, me, cnt, sum of the partners' W in window order).

    W is evaluated over the whole window (a vectorised pass; the few visited particles not yet
    compacted and i itself get a W that is then not used). A non-partner adds +0.0 to the sum and
    to its row sum, which leaves both unchanged: the sums are those over partners alone."""
    lo = np.searchsorted(xs[:left], xp - radius, side="left")
    hi = np.searchsorted(xs[:left], xp + radius, side="right")
    me = lo + np.searchsorted(xs[lo:hi], xp, side="left")  # i itself
    while ls[me] != i:
        me += 1
    nw = hi - lo
    for k in range(nw):
        d = xp - xs[lo + k]
        u[k] = d * d * inv2s2
    _kernel(u, w, nw, near)
    cnt = 0
    s = 0.0
    for k in range(nw):  # branch-free compaction, row sums in the same pass
        later = ls[lo + k] > i
        wk = w[k] if later else 0.0
        s += wk
        rs[lo + k] += wk
        part[cnt] = lo + k
        c[cnt] = wk
        cnt += later
    return lo, hi, me, cnt, s


@njit(cache=True, inline="always")
def _weights(c, part, cnt, inv_r, rf, beta, symnorm):
    """c[:cnt] <- beta W_ij / r_i (symnorm: times the mean of 1/r_i and 1/r_j); returns max c."""
    cmax = 0.0
    if symnorm:
        for k in range(cnt):
            c[k] *= beta * 0.5 * (inv_r + 1.0 / rf[part[k]])
            cmax = max(cmax, c[k])
    else:
        b = beta * inv_r
        for k in range(cnt):
            c[k] *= b
            cmax = max(cmax, c[k])
    return cmax


@njit(cache=True, inline="always")
def _draw(k, cnt, state, z):
    """Fisher-Yates as we go: the k-th partner is uniform among the cnt - k left; 32 random bits a
    draw, two draws from each 64-bit output -> (index, state, z)."""
    if k % 2 == 0:
        state, z = _splitmix(state)
        bits = z >> np.uint64(32)
    else:
        bits = z & np.uint64(0xFFFFFFFF)
    return k + np.int64((bits * np.uint64(cnt - k)) >> np.uint64(32)), state, z


@njit(cache=True, inline="always")
def _take(k, j, part, c):
    """Swap the j-th partner into place k -> (its compact index, its weight)."""
    q = part[j]
    cj = c[j]
    part[j] = part[k]
    c[j] = c[k]
    return q, cj


@njit(cache=True, inline="always")
def _exchange_clipped(mi, cnt, part, c, ms, state):
    """The visit's exchanges in random order with the clipping m <- max(0, m) -> (m_i, state)."""
    z = np.uint64(0)
    for k in range(cnt):
        j, state, z = _draw(k, cnt, state, z)
        q, cj = _take(k, j, part, c)
        mj = ms[q]
        dm = cj * (mi - mj)  # beta (m_i - m_j) W_ij / r_i
        mi = max(0.0, mi - dm)
        ms[q] = max(0.0, mj + dm)
    return mi, state


@njit(cache=True, inline="always")
def _exchange(mi, k0, cnt, part, c, ms, state, z):
    """The visit's exchanges k0 .. cnt - 1 in random order, unclipped, from the stream's state and
    its last output z -> (m_i, state, z)."""
    for k in range(k0, cnt):
        j, state, z = _draw(k, cnt, state, z)
        q, cj = _take(k, j, part, c)
        mj = ms[q]
        dm = cj * (mi - mj)
        mi = mi - dm
        ms[q] = mj + dm
    return mi, state, z


@njit(cache=True, inline="always")
def _exchange_two(ma, cna, pa, ca, mb, cnb, pb, cb, ms, state):
    """Two visits with disjoint windows, unclipped, their exchanges interleaved: the same arithmetic
    on the same masses as one after the other (they share no particle), with two independent chains
    through m_i. The second visit's stream starts where the first's ends: SplitMix64's state after
    k outputs is s + k G -> (m_a, m_b, state at the end of both)."""
    sa = state
    sb = state + np.uint64((cna + 1) // 2) * _GOLDEN
    za = np.uint64(0)
    zb = np.uint64(0)
    both = min(cna, cnb)
    for k in range(both):
        ja, sa, za = _draw(k, cna, sa, za)
        jb, sb, zb = _draw(k, cnb, sb, zb)
        qa, cja = _take(k, ja, pa, ca)
        qb, cjb = _take(k, jb, pb, cb)
        mja = ms[qa]
        mjb = ms[qb]
        dma = cja * (ma - mja)
        dmb = cjb * (mb - mjb)
        ma = ma - dma
        mb = mb - dmb
        ms[qa] = mja + dma
        ms[qb] = mjb + dmb
    ma, sa, za = _exchange(ma, both, cna, pa, ca, ms, sa, za)  # the longer visit's rest
    mb, sb, zb = _exchange(mb, both, cnb, pb, cb, ms, sb, zb)
    return ma, mb, sb


@njit(cache=True, fastmath={"contract"})
def _sweep(x, m, label, sigma, radius, beta, seed, symnorm, clip):
    """One step of the loop on positions ``x`` sorted, ``label`` the storage index of each.

    Visits are found two at a time (i, i + 1): their windows, weights and row sums need only
    positions and the row sums so far. When the windows share no particle the two visits are
    independent and their exchanges run interleaved, the same operations in the same order on each
    value as one visit after the other. Clipping can act only when some m_i - dm or
    m_j + dm is negative; with all masses >= 0 and every c = beta W_ij / r_i <= 1 neither is (in
    floating point too: fl(m_i - m_j) <= m_i, fl(c t) <= t and rounding is monotone), so such visits
    skip it."""
    n = x.shape[0]
    inv2s2 = 0.5 / (sigma * sigma)
    # |x_i - x_j| <= radius in a window (up to rounding in xp - radius: the margin covers it)
    near = radius * radius * inv2s2 <= 0.99 * EXP_NEAR_MAX
    where = np.empty(n, np.int64)  # sorted index of the particle stored at i
    for p in range(n):
        where[label[p]] = p
    r_full = _row_sums(x, radius, inv2s2) if symnorm else np.zeros(n)
    # Clipping can act only if a mass is negative (or not finite) at the start; once all are >= 0,
    # every update keeps them so.
    safe = True
    for p in range(n):
        if not (m[p] >= 0.0 and m[p] < np.inf):
            safe = False
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
    pa = np.empty(n, np.int64)
    pb = np.empty(n, np.int64)
    u = np.empty(n)
    w = np.empty(n)
    ca = np.empty(n)
    cb = np.empty(n)
    state = np.uint64(seed)
    i = 0
    while i < n:
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
        lo, hi, me, cna, sa = _partners(i, x[where[i]], xs, ls, rs, left, radius, inv2s2, near, pa, u, w, ca)
        two = i + 1 < n and (i + 1) % chunk != 0  # no compaction between the two visits
        if two:  # i + 1's weights and row sums need only positions and i's row sums: found now
            lob, hib, meb, cnb, sb = _partners(
                i + 1, x[where[i + 1]], xs, ls, rs, left, radius, inv2s2, near, pb, u, w, cb
            )
        else:
            lob = hib = meb = cnb = 0
            sb = 0.0
        clipa = clipb = False
        if cna > 0:
            ra = rf[me] if symnorm else rs[me] + 1.0 + sa
            cmax = _weights(ca, pa, cna, 1.0 / ra, rf, beta, symnorm)
            clipa = clip and (cmax > 1.0 or not safe)
        if cnb > 0:
            rb = rf[meb] if symnorm else rs[meb] + 1.0 + sb
            cmax = _weights(cb, pb, cnb, 1.0 / rb, rf, beta, symnorm)
            clipb = clip and (cmax > 1.0 or not safe)
        if cna > 0 and cnb > 0 and not (clipa or clipb) and (hi <= lob or hib <= lo):
            # disjoint windows: neither visit touches the other's particles, so both at once
            ms[me], ms[meb], state = _exchange_two(ms[me], cna, pa, ca, ms[meb], cnb, pb, cb, ms, state)
        else:  # one after the other
            if cna > 0:
                ms[me], state = _visit_mass(ms[me], cna, pa, ca, ms, state, clipa)
            if cnb > 0:
                ms[meb], state = _visit_mass(ms[meb], cnb, pb, cb, ms, state, clipb)
        i += 2 if two else 1
    for k in range(left):
        m[ps[k]] = ms[k]
    return m


@njit(cache=True, inline="always")
def _visit_mass(mi, cnt, part, c, ms, state, clip):
    """One visit's exchanges, clipped or not -> (m_i, state)."""
    if clip:
        return _exchange_clipped(mi, cnt, part, c, ms, state)
    mi, state, _ = _exchange(mi, 0, cnt, part, c, ms, state, np.uint64(0))
    return mi, state


def sequential_transfer(
    x: np.ndarray,
    m: np.ndarray,
    sigma: float,
    beta: float,
    truncation: float | None,
    rng: np.random.Generator,
    label: np.ndarray | None = None,
    symnorm: bool = False,
    clip: bool = True,
) -> np.ndarray:
    """One step of the authors' loop on sorted positions ``x``; ``label`` is the storage index of
    each particle (None: storage order = position order, the ``sorted`` variant). ``rng`` seeds
    the partner permutations of this step. The input masses are not changed."""
    radius = cutoff_radius(sigma, truncation)
    if label is None:
        label = np.arange(x.size, dtype=np.int64)
    seed = int(rng.integers(0, 2**63))
    return _sweep(
        np.ascontiguousarray(x, dtype=np.float64),
        np.array(m, dtype=np.float64),
        np.ascontiguousarray(label, dtype=np.int64),
        float(sigma),
        float(radius),
        float(beta),
        np.uint64(seed),
        bool(symnorm),
        bool(clip),
    )


def warm_up() -> None:
    """Load the compiled loop (numba's on-disk cache) before the timed steps."""
    x = np.linspace(-1.0, 1.0, 8)
    sequential_transfer(x, np.ones(8), 0.5, 0.5, 3.0, np.random.default_rng(0), label=np.arange(8)[::-1].copy())
