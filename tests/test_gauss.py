"""gauss_transform (direct, taylor, auto) against a dense numpy reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import dense_kernel

from particle_entropy.numerics import fastexp, gauss, gauss_kernels
from particle_entropy.numerics.bandwidths import CUTOFF_SIGMAS
from particle_entropy.numerics.gauss import gauss_transform

# Both methods drop pairs farther apart than CUTOFF_SIGMAS sigma (documented); each dropped
# term is below exp(-CUTOFF_SIGMAS^2 / 2) |q_j|. The error bound used below is therefore
#   |out - ref| <= RTOL * (K |q|)  +  exp(-CUTOFF^2/2) * sum |q|
# i.e. relative error < RTOL against the sum of absolute contributions, plus the documented
# cut-off (which is < 3e-18 of the total weight and so is below 1e-12 anyway).
RTOL = 1e-12
CUT = math.exp(-0.5 * CUTOFF_SIGMAS**2)


def _sources(rng, n):
    return np.sort(rng.uniform(-5.0, 5.0, n))


def _weights(rng, n):
    """Three right-hand sides: ones, positive, signed (|q| in [0.5, 1.5])."""
    signs = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    return np.vstack([np.ones(n), rng.uniform(0.5, 1.5, n), signs * rng.uniform(0.5, 1.5, n)])


def _assert_matches(out, y, x, q, sigma, rtol=RTOL, truncation=None, cut=CUT):
    K = dense_kernel(y, x, sigma, truncation)
    ref = q @ K.T
    ref_abs = np.abs(q) @ K.T
    assert out.shape == ref.shape
    assert np.all(np.isfinite(out))
    bound = rtol * ref_abs + cut * np.abs(q).sum(axis=-1, keepdims=q.ndim == 2)
    err = np.abs(out - ref)
    worst = np.max(err / np.where(bound > 0, bound, 1.0))
    assert np.all(err <= bound), f"error exceeds bound by factor {worst:.3g}"
    # and the plain normwise relative error, per right-hand side
    scale = np.max(ref_abs, axis=-1)
    assert np.all(np.max(err, axis=-1) <= rtol * scale)


SIGMA_FACTORS = {  # sigma in units of the mean source spacing 10 / N
    "tiny": 1e-3,
    "comparable": 1.0,
    "many-neighbours": 40.0,
    "huge": 1e5,  # far wider than the whole source range
}


@pytest.mark.parametrize("n", [10, 100, 2000])
@pytest.mark.parametrize("width", list(SIGMA_FACTORS))
@pytest.mark.parametrize("method", ["direct", "fgt", "taylor", "auto"])
def test_sources_as_targets_match_dense(rng, n, width, method):
    x = _sources(rng, n)
    sigma = SIGMA_FACTORS[width] * 10.0 / n
    q = _weights(rng, n)
    out = gauss_transform(x, x, q, sigma, method=method)
    _assert_matches(out, x, x, q, sigma)


@pytest.mark.parametrize("n", [10, 300, 2000])
@pytest.mark.parametrize("width", list(SIGMA_FACTORS))
@pytest.mark.parametrize("method", ["direct", "fgt", "taylor", "auto"])
def test_other_targets_match_dense(rng, n, width, method):
    """Kernel-reconstruction use: targets on a grid wider than the sources."""
    x = _sources(rng, n)
    y = np.linspace(-6.5, 6.5, 777)
    sigma = SIGMA_FACTORS[width] * 10.0 / n
    q = _weights(rng, n)
    out = gauss_transform(y, x, q, sigma, method=method)
    _assert_matches(out, y, x, q, sigma)


@pytest.mark.parametrize("method", ["direct", "fgt", "taylor", "auto"])
def test_single_rhs_shape_and_clustered_sources(rng, method):
    """1-D weights give a 1-D result; repeated positions and tight clusters are handled."""
    x = np.sort(np.concatenate([np.zeros(50), rng.normal(0, 1e-3, 400), rng.uniform(-3, 3, 300)]))
    q = rng.uniform(0.5, 1.5, x.size)
    for sigma in (1e-4, 0.05, 2.0):
        out = gauss_transform(x, x, q, sigma, method=method)
        assert out.ndim == 1 and out.shape == x.shape
        _assert_matches(out[None, :], x, x, q[None, :], sigma)


@pytest.mark.parametrize("truncation", [0.5, 1.0, 3.0, 5.5])
@pytest.mark.parametrize("width", [0.3, 1.0, 10.0])
@pytest.mark.parametrize("method", ["direct", "auto"])
def test_truncated_kernel_equals_zeroed_dense(rng, truncation, width, method):
    """Truncated kernels keep exactly the pairs with |y - x| <= truncation * sigma."""
    n = 800
    x = _sources(rng, n)
    sigma = width * 10.0 / n
    q = _weights(rng, n)
    out = gauss_transform(x, x, q, sigma, truncation=truncation, method=method)
    _assert_matches(out, x, x, q, sigma, rtol=1e-13, truncation=truncation, cut=0.0)
    y = np.linspace(-5.2, 5.2, 501)
    out = gauss_transform(y, x, q, sigma, truncation=truncation, method=method)
    _assert_matches(out, y, x, q, sigma, rtol=1e-13, truncation=truncation, cut=0.0)


def test_truncation_boundary_pairs_are_kept():
    """On an integer lattice with sigma = 1, truncation = 3 keeps the pairs at distance exactly 3."""
    x = np.arange(-50.0, 51.0)
    out = gauss_transform(x, x, np.ones_like(x), 1.0, truncation=3.0, method="direct")
    interior = 1.0 + 2.0 * sum(math.exp(-0.5 * k * k) for k in (1, 2, 3))
    np.testing.assert_allclose(out[10:-10], interior, rtol=1e-14, atol=0)
    # end particle: itself and three right neighbours
    assert out[0] == pytest.approx(1.0 + sum(math.exp(-0.5 * k * k) for k in (1, 2, 3)), rel=1e-14)


def test_skip_self_drops_only_the_diagonal(rng):
    x = _sources(rng, 500)
    q = _weights(rng, 500)
    sigma = 0.05
    K = np.exp(-0.5 * ((x[:, None] - x[None, :]) / sigma) ** 2)
    np.fill_diagonal(K, 0.0)
    ref = q @ K.T
    out = gauss_transform(x, x, q, sigma, method="direct", skip_self=True)
    scale = np.abs(q) @ K.T + np.abs(q)
    assert np.all(np.abs(out - ref) <= 1e-12 * scale)


@pytest.mark.parametrize("sigma", [0.0, -1.0, math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("method", ["direct", "taylor", "auto"])
def test_bad_sigma_raises(sigma, method):
    x = np.linspace(-1, 1, 20)
    with pytest.raises(ValueError):
        gauss_transform(x, x, np.ones_like(x), sigma, method=method)


@pytest.mark.parametrize("truncation", [1.0, 3.0])
def test_taylor_with_truncation_raises(truncation):
    x = np.linspace(-1, 1, 20)
    with pytest.raises(ValueError):
        gauss_transform(x, x, np.ones_like(x), 0.1, truncation=truncation, method="taylor")


def test_other_documented_errors():
    x = np.linspace(-1, 1, 20)
    with pytest.raises(ValueError):  # weights not matching the sources
        gauss_transform(x, x, np.ones(19), 0.1)
    with pytest.raises(ValueError):  # unknown method
        gauss_transform(x, x, np.ones_like(x), 0.1, method="fmm")
    with pytest.raises(ValueError):  # skip_self is direct-only
        gauss_transform(x, x, np.ones_like(x), 0.1, method="taylor", skip_self=True)


@pytest.mark.parametrize("ratio", [0.5, 1.0, 1.5, 2.5, 3.0])
@pytest.mark.parametrize("density", [0.5, 30.0, 400.0])  # sources per sigma
def test_fgt_box_widths_match_dense(rng, ratio, density):
    """Boxes from 0.5 to 2.5 sigma wide, with their default term count, are exact to 1e-12,
    both where box pairs are summed exactly (sparse) and where they are translated (dense)."""
    n = 1500
    x = _sources(rng, n)
    sigma = density * 10.0 / n
    q = _weights(rng, n)
    width = 2.0 ** math.floor(math.log2(ratio * sigma))  # exact box geometry: a power of two
    terms = gauss.fgt_offset_terms(sigma, CUTOFF_SIGMAS * sigma, width)
    out = gauss_kernels.fgt(x, x, q, sigma, width, terms)
    _assert_matches(out, x, x, q, sigma)


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("tolerance", [1e-3, 1e-6, 1e-10, 1e-17])
def test_fgt_term_count_is_the_fewest_meeting_the_bound(ratio, tolerance):
    p = gauss.fgt_terms(ratio, tolerance)
    assert gauss.fgt_error_bound(ratio, p) <= tolerance
    assert p == 1 or gauss.fgt_error_bound(ratio, p - 1) > tolerance


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.25, 3.0])
def test_fgt_error_bound_dominates_the_dropped_terms(ratio):
    """The bound against a brute-force sum of the dropped terms of the double series
    exp(-(t + v - u)^2) = sum h_{n+m}(t) u^n (-v)^m / (n! m!), worst case over u, v, t."""
    a = ratio / math.sqrt(2)
    for p in (4, 8, 16):
        worst = 0.0
        for t in np.linspace(0.0, 4.0, 9):
            h = [math.exp(-t * t), 2 * t * math.exp(-t * t)]  # Hermite functions h_k(t)
            for k in range(1, 160):
                h.append(2 * t * h[k] - 2 * k * h[k - 1])
            for u in (-a / 2, a / 2):
                for v in (-a / 2, a / 2):
                    kept = sum(
                        h[n + m] * u**n * (-v) ** m / (math.factorial(n) * math.factorial(m))
                        for n in range(p)
                        for m in range(p)
                    )
                    worst = max(worst, abs(math.exp(-((t + v - u) ** 2)) - kept))
        assert worst <= gauss.fgt_error_bound(ratio, p)


@pytest.mark.parametrize("sigma", [0.02, 0.05, 0.5])  # 8 to 200 sources per sigma
def test_fgt_tolerance_bounds_the_error(rng, sigma):
    """A looser tolerance keeps the documented bound |error_i| <= tolerance * sum_j |q_j| (over
    sources within the cut-off) and is really used: the error grows with the tolerance."""
    n = 4000
    x = _sources(rng, n)
    q = _weights(rng, n)
    ref = q @ dense_kernel(x, x, sigma, None).T
    near = np.abs(q) @ (np.abs(x[:, None] - x[None, :]) <= CUTOFF_SIGMAS * sigma).T
    worst = []
    for tolerance in (1e-4, 1e-8, 1e-12):
        err = np.abs(gauss_transform(x, x, q, sigma, method="fgt", tolerance=tolerance) - ref)
        assert np.all(err <= tolerance * near + CUT * np.abs(q).sum(axis=-1, keepdims=True))
        worst.append(err.max())
    assert worst[0] > worst[2]


def test_fgt_plan_narrow_boxes_for_dense_sources_wide_for_sparse():
    """Many sources per sigma: per-particle terms dominate, so narrow boxes (fewer terms);
    few per sigma: translations dominate, so wide boxes. Widths are exact k 2^e."""
    x = np.linspace(-5.0, 5.0, 30000)  # 1300 sources per sigma = 0.44, 19 per sigma = 0.0063
    w_dense, p_dense = gauss.fgt_plan(x, x, 0.44, CUTOFF_SIGMAS * 0.44, 1)
    w_sparse, p_sparse = gauss.fgt_plan(x, x, 0.0063, CUTOFF_SIGMAS * 0.0063, 1)
    p_dense, p_sparse = p_dense[0], p_sparse[0]
    assert w_dense / 0.44 < w_sparse / 0.0063 and p_dense < p_sparse
    for w in (w_dense, w_sparse):
        mantissa = w / 2.0 ** math.floor(math.log2(w) - 2)
        assert mantissa in (4.0, 5.0, 6.0, 7.0)
    assert gauss.fgt_error_bound(w_dense / 0.44, p_dense) <= gauss.FGT_TOLERANCE


@pytest.mark.parametrize("tolerance", [0.0, -1e-10, 0.5, math.nan])
def test_bad_tolerance_raises(tolerance):
    x = np.linspace(-1, 1, 20)
    with pytest.raises(ValueError, match="tolerance"):
        gauss_transform(x, x, np.ones_like(x), 0.1, method="fgt", tolerance=tolerance)


def test_inline_exp_matches_libm_to_an_ulp():
    """The windowed sums' exp(-a) (vectorisable polynomial) against numpy's exp."""
    from numba import njit

    @njit
    def evaluate(a):
        out = np.empty_like(a)
        for i in range(a.size):
            out[i] = fastexp.exp_neg(a[i])
        return out

    a = np.concatenate([np.linspace(0.0, 50.0, 200001), np.linspace(50.0, 760.0, 20001)])
    got, ref = evaluate(a), np.exp(-a)
    normal = ref > np.finfo(float).tiny
    assert np.all(np.abs(got[normal] - ref[normal]) <= 2.3e-16 * ref[normal])
    assert np.all(got[a > 746.0] == 0.0) and got[0] == 1.0


def test_distant_box_pairs_get_fewer_terms_within_the_bound():
    """terms[d] for pairs d boxes apart: the most at d = 0, never more farther out, and each
    meets the tolerance once the bound's exp(-t^2 / 2) at centre offset t is applied."""
    sigma, width = 0.01, 0.025
    terms = gauss.fgt_offset_terms(sigma, CUTOFF_SIGMAS * sigma, width)
    assert len(terms) == math.ceil(CUTOFF_SIGMAS * sigma / width) + 2
    assert np.all(np.diff(terms) <= 0) and terms[-1] < terms[0]
    ratio = math.ceil(width / sigma * 64) / 64
    for d, p in enumerate(terms):
        t = d * math.floor(width / sigma * 64) / 64 / math.sqrt(2)
        assert math.exp(-t * t / 2) * gauss.fgt_error_bound(ratio, int(p)) <= gauss.FGT_TOLERANCE
