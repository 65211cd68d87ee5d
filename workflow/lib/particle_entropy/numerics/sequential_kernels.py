"""The numba kernels of the authors' sequential loop (sequential.py states what it computes and
why): ``_sweep``, bit for bit the loop before issue 20, and ``_sweep_fma``, the default fast form.
Both are exported through compiled.py (compiled.EXPORTS), so that a job calls them compiled ahead
of time, or through numba's JIT where there is no such module."""

from __future__ import annotations

import numpy as np
from llvmlite import binding as llvm
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .fastexp import EXP_NEAR_MAX, exp_neg, exp_neg_near, wide_vectors

# vector compress in _compact: a vpcompressd where the CPU has AVX-512 (the JIT and the ahead-of-time
# build, compiled.py, target this CPU), LLVM's scalar expansion elsewhere, slower than a loop
_VECTOR_COMPRESS = "+avx512f" in llvm.get_host_cpu_features().flatten()
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


@njit(cache=True, inline="always")
def _drop_visited(i, left, xs, ps, ls, ms, rs, rf, m):
    """Keep the particles not yet visited (storage label >= i) at the front of the compact arrays,
    in position order, and write the visited ones' masses back to m -> how many are kept."""
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
    return k2


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
            left = _drop_visited(i, left, xs, ps, ls, ms, rs, rf, m)
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


# ------------------------------------------------------------------ the fast form (round-off)
# The same loop (every fact above: the same visits, partners, partner orders and random stream),
# with two sums rounded differently: r_i's partner sum is vectorised, and the chain through m_i is
# one fused multiply-add, m_i <- m_i (1 - c) + c m_j, whose latency is half of m_i - c (m_i - m_j)'s.
# Its passes over a window are vectorised (512-bit vectors where the CPU has them), the random
# draws of a visit are made all at once before its exchanges, and two consecutive visits whose
# windows are disjoint exchange interleaved, two independent chains through m_i. Where an exchange
# could overshoot (beta > 1.9) or masses are negative with clipping, it keeps _sweep's arithmetic.


@intrinsic
def _fma(typingctx, a, b, c):
    """a b + c rounded once (llvm.fma)."""
    if not all(isinstance(t, types.Float) for t in (a, b, c)):
        return None

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.DoubleType(), [ir.DoubleType()] * 3)
        return builder.call(cgutils.get_or_insert_function(builder.module, fnty, "llvm.fma.f64"), args)

    return types.float64(types.float64, types.float64, types.float64), codegen


@njit(cache=True, fastmath={"contract", "reassoc"})
def _window_pass(i, xp, xw, lw, rw, inv2s2, near, w):
    """W_ij over a window (positions xw, labels lw, row sums so far rw) into w, added to the
    partners' row sums -> the sum of the partners' W (vectorised, in another order of rounding)."""
    wide_vectors()
    s = 0.0
    if near:
        for k in range(xw.shape[0]):
            d = xp - xw[k]
            wk = exp_neg_near(d * d * inv2s2)
            w[k] = wk
            wk = wk if lw[k] > i else 0.0
            rw[k] += wk
            s += wk
    else:
        for k in range(xw.shape[0]):
            d = xp - xw[k]
            wk = exp_neg(d * d * inv2s2)
            w[k] = wk
            wk = wk if lw[k] > i else 0.0
            rw[k] += wk
            s += wk
    return s


@intrinsic
def _compress16(typingctx, part, cnt, lw, k, i):
    """part[cnt:cnt + 16] <- the offsets k + t (t < 16) with lw[k + t] > i, packed in order, and
    garbage after them (vector compress: one vpcompressd with AVX-512) -> cnt + how many. Needs
    cnt + 16 <= len(part) and k + 16 <= len(lw); lw is C-contiguous int64, part uint32."""
    if not (isinstance(lw, types.Array) and lw.dtype == types.int64 and lw.layout == "C"):
        return None
    if not (isinstance(part, types.Array) and part.dtype == types.uint32 and part.layout == "C"):
        return None

    def codegen(context, builder, signature, args):
        part_a, cnt_v, lw_a, k_v, i_v = args
        i32, i64 = ir.IntType(32), ir.IntType(64)
        v64, v32, mask_t = ir.VectorType(i64, 16), ir.VectorType(i32, 16), ir.VectorType(ir.IntType(1), 16)
        zeros = ir.Constant(v32, [0] * 16)

        def splat(vec_t, value):
            one = builder.insert_element(ir.Constant(vec_t, ir.Undefined), value, ir.Constant(i32, 0))
            return builder.shuffle_vector(one, ir.Constant(vec_t, ir.Undefined), zeros)

        labels_at = builder.gep(context.make_array(signature.args[2])(context, builder, lw_a).data, [k_v])
        labels = builder.load(builder.bitcast(labels_at, v64.as_pointer()), align=8)
        mask = builder.icmp_signed(">", labels, splat(v64, i_v))
        offsets = builder.add(splat(v32, builder.trunc(k_v, i32)), ir.Constant(v32, list(range(16))))
        compress = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(v32, [v32, mask_t, v32]), "llvm.experimental.vector.compress.v16i32"
        )
        packed = builder.call(compress, [offsets, mask, ir.Constant(v32, ir.Undefined)])
        out_at = builder.gep(context.make_array(signature.args[0])(context, builder, part_a).data, [cnt_v])
        builder.store(packed, builder.bitcast(out_at, v32.as_pointer()), align=4)
        popcount = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.IntType(16), [ir.IntType(16)]), "llvm.ctpop.i16"
        )
        taken = builder.call(popcount, [builder.bitcast(mask, ir.IntType(16))])
        return builder.add(cnt_v, builder.zext(taken, i64))

    return types.int64(part, types.int64, lw, types.int64, types.int64), codegen


@njit(cache=True)
def _compact(i, ls, lo, hi, part):
    """part[:cnt] <- the window offsets (from lo) of i's partners in ls[lo:hi] (later in storage),
    in window order -> cnt. Blocks of 16 by vector compress where the CPU has AVX-512; the scalar
    loop elsewhere (LLVM would lower the compress to scalar stores)."""
    cnt = 0
    start = 0
    if _VECTOR_COMPRESS:
        while start + 16 <= hi - lo:
            cnt = _compress16(part, cnt, ls[lo:], start, i)
            start += 16
    for k in range(start, hi - lo):
        part[cnt] = k
        cnt += ls[lo + k] > i
    return cnt


@njit(cache=True)
def _draws(cnt, state, zz, jd):
    """jd[k] <- the k-th draw of _draw for k < cnt, all at once (vectorised) -> the stream's state
    after them (SplitMix64's state after t outputs is s + t G)."""
    wide_vectors()
    h = (cnt + 1) // 2
    for t in range(h):
        _, z = _splitmix(state + np.uint64(t) * _GOLDEN)
        zz[t] = (z << np.uint64(32)) | (z >> np.uint64(32))  # halves swapped: draw 2t's bits first
    bits = zz.view(np.uint32)
    for k in range(cnt):
        jd[k] = np.uint64(k) + ((np.uint64(bits[k]) * np.uint64(np.uint32(cnt - k))) >> np.uint64(32))
    return state + np.uint64(h) * _GOLDEN


@njit(cache=True, inline="always")
def _weight(wq, b, hb, irf, p):
    """c = beta W_ij / r_i (b = beta / r_i, hb = 0), or symnorm's beta W_ij (1/r_i + 1/r_j) / 2
    (b = 1/r_i, hb = beta / 2, 1/r_j = irf[p]), as _sweep computes it."""
    if hb == 0.0:
        return wq * b
    return wq * (hb * (b + irf[p]))


@njit(cache=True, inline="always")
def _step_fma(k, mi, part, jd, w, b, hb, irf, ms, lo):
    """The visit's k-th exchange, unclipped: m_j <- m_j + c (m_i - m_j) and m_i <- m_i (1 - c) +
    c m_j, one rounding on the chain through m_i -> m_i."""
    j = jd[k]
    q = part[j]
    part[j] = part[k]
    c = _weight(w[q], b, hb, irf, lo + q)
    mj = ms[lo + q]
    ms[lo + q] = _fma(c, mi - mj, mj)
    return _fma(mi, 1.0 - c, c * mj)


@njit(cache=True, inline="always")
def _exchange_fma(mi, cnt, part, jd, w, b, hb, irf, ms, lo):
    """The visit's exchanges in the drawn order, fused, two a link of the chain through m_i:
    m_i after exchanges k and k + 1 is m_i (1 - c_k)(1 - c_k+1) + (c_k m_k (1 - c_k+1) + c_k+1
    m_k+1), whose factors need no m_i, so the chain waits for one fused multiply-add every two
    partners; m_i between them feeds only partner k + 1's update -> m_i."""
    k = 0
    while k + 1 < cnt:
        j = jd[k]
        q = part[j]
        part[j] = part[k]
        j1 = jd[k + 1]
        q1 = part[j1]
        part[j1] = part[k + 1]
        c = _weight(w[q], b, hb, irf, lo + q)
        c1 = _weight(w[q1], b, hb, irf, lo + q1)
        mj = ms[lo + q]
        mj1 = ms[lo + q1]
        ms[lo + q] = _fma(c, mi - mj, mj)
        mid = _fma(mi, 1.0 - c, c * mj)  # m_i after exchange k
        ms[lo + q1] = _fma(c1, mid - mj1, mj1)
        mi = _fma(mi, (1.0 - c) * (1.0 - c1), _fma(c * mj, 1.0 - c1, c1 * mj1))
        k += 2
    if k < cnt:
        mi = _step_fma(k, mi, part, jd, w, b, hb, irf, ms, lo)
    return mi


@njit(cache=True, inline="always")
def _exchange_fma_two(ma, cna, pa, ja, wa, ba, loa, mb, cnb, pb, jb, wb, bb, lob, hb, irf, ms):
    """Two visits with disjoint windows, fused and interleaved: two independent chains -> (m_a,
    m_b)."""
    both = min(cna, cnb)
    for k in range(both):
        ma = _step_fma(k, ma, pa, ja, wa, ba, hb, irf, ms, loa)
        mb = _step_fma(k, mb, pb, jb, wb, bb, hb, irf, ms, lob)
    for k in range(both, cna):  # the longer visit's rest
        ma = _step_fma(k, ma, pa, ja, wa, ba, hb, irf, ms, loa)
    for k in range(both, cnb):
        mb = _step_fma(k, mb, pb, jb, wb, bb, hb, irf, ms, lob)
    return ma, mb


@njit(cache=True, inline="always")
def _exchange_plain(mi, cnt, part, w, b, hb, irf, ms, lo, state, clip):
    """The visit's exchanges in random order in _sweep's arithmetic, clipped or not -> (m_i,
    state)."""
    z = np.uint64(0)
    for k in range(cnt):
        j, state, z = _draw(k, cnt, state, z)
        q = part[j]
        part[j] = part[k]
        mj = ms[lo + q]
        dm = _weight(w[q], b, hb, irf, lo + q) * (mi - mj)
        if clip:
            mi = max(0.0, mi - dm)
            ms[lo + q] = max(0.0, mj + dm)
        else:
            mi = mi - dm
            ms[lo + q] = mj + dm
    return mi, state


@njit(cache=True, inline="always")
def _find(i, xp, xs, ls, left, radius):
    """i's window [lo, hi) in the compact arrays and its own place me in it -> (lo, hi, me)."""
    lo = np.searchsorted(xs[:left], xp - radius, side="left")
    hi = np.searchsorted(xs[:left], xp + radius, side="right")
    me = lo + np.searchsorted(xs[lo:hi], xp, side="left")
    while ls[me] != i:
        me += 1
    return lo, hi, me


@njit(cache=True, inline="always")
def _prepare(i, xs, ls, rs, irf, lo, hi, me, inv2s2, near, beta, hb, part, w):
    """The visit to i up to its weights: W over its window, the row sums, its partners
    part[:cnt] -> (cnt, b: beta / r_i, or 1 / r_i for symnorm)."""
    s = _window_pass(i, xs[me], xs[lo:hi], ls[lo:hi], rs[lo:hi], inv2s2, near, w)
    cnt = _compact(i, ls, lo, hi, part)
    return cnt, (irf[me] if hb != 0.0 else beta * (1.0 / (rs[me] + 1.0 + s)))


@njit(cache=True, fastmath={"contract"})
def _sweep_fma(x, m, label, sigma, radius, beta, seed, symnorm, clip):
    """One step of the loop as _sweep does it, in the fast form (equal to it to round-off). Visits
    go two at a time as in _sweep, interleaved when their windows are disjoint."""
    n = x.shape[0]
    inv2s2 = 0.5 / (sigma * sigma)
    near = radius * radius * inv2s2 <= 0.99 * EXP_NEAR_MAX  # as in _sweep
    where = np.empty(n, np.int64)  # sorted index of the particle stored at i
    for p in range(n):
        where[label[p]] = p
    safe = True
    for p in range(n):
        if not (m[p] >= 0.0 and m[p] < np.inf):
            safe = False
    # c <= beta / 2, as r_i >= 1 + W_ij (symnorm: r_j too): up to beta = 1.9 (room for rounding)
    # an exchange leaves each mass a weighted mean of m_i and m_j, so the clipping cannot act on
    # masses >= 0 and the fused chain's rounding errors do not grow. Beyond, _sweep's arithmetic.
    fused = beta <= 1.9 and (safe or not clip)
    xs = x.copy()
    ps = np.arange(n)
    ls = label.copy()
    ms = m.copy()
    rs = np.zeros(n)
    irf = 1.0 / _row_sums(x, radius, inv2s2) if symnorm else np.zeros(n)
    hb = beta * 0.5 if symnorm else 0.0  # beta > 0: hb != 0 marks symnorm
    left = n
    chunk = max(64, n // 32)
    pa = np.empty(n, np.uint32)
    pb = np.empty(n, np.uint32)
    ja = np.empty(n + 1, np.uint32)
    jb = np.empty(n + 1, np.uint32)
    zz = np.empty(n // 2 + 1, np.uint64)
    wa = np.empty(n)
    wb = np.empty(n)
    state = np.uint64(seed)
    i = 0
    while i < n:
        if i % chunk == 0 and i > 0:
            left = _drop_visited(i, left, xs, ps, ls, ms, rs, irf, m)
        lo, hi, me = _find(i, x[where[i]], xs, ls, left, radius)
        cna, ba = _prepare(i, xs, ls, rs, irf, lo, hi, me, inv2s2, near, beta, hb, pa, wa)
        ulo = np.uint64(lo)
        if not fused:
            ms[me], state = _exchange_plain(ms[me], cna, pa, wa, ba, hb, irf, ms, ulo, state, clip)
            i += 1
            continue
        state = _draws(cna, state, zz, ja)
        two = i + 1 < n and (i + 1) % chunk != 0  # no compaction between the two visits
        cnb = 0
        if two:
            lob, hib, meb = _find(i + 1, x[where[i + 1]], xs, ls, left, radius)
            cnb, bb = _prepare(i + 1, xs, ls, rs, irf, lob, hib, meb, inv2s2, near, beta, hb, pb, wb)
            state = _draws(cnb, state, zz, jb)
        if cnb > 0 and (hi <= lob or hib <= lo):  # disjoint windows: both at once
            ms[me], ms[meb] = _exchange_fma_two(
                ms[me], cna, pa, ja, wa, ba, ulo, ms[meb], cnb, pb, jb, wb, bb, np.uint64(lob), hb, irf, ms
            )
        else:  # one after the other
            ms[me] = _exchange_fma(ms[me], cna, pa, ja, wa, ba, hb, irf, ms, ulo)
            if cnb > 0:
                ms[meb] = _exchange_fma(ms[meb], cnb, pb, jb, wb, bb, hb, irf, ms, np.uint64(lob))
        i += 2 if two else 1
    for k in range(left):
        m[ps[k]] = ms[k]
    return m
