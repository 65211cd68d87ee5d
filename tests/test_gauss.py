"""gauss_transform (direct, taylor, auto) against a dense numpy reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.gauss import CUTOFF_SIGMAS, gauss_transform

from conftest import dense_kernel

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
@pytest.mark.parametrize("method", ["direct", "taylor", "auto"])
def test_sources_as_targets_match_dense(rng, n, width, method):
    x = _sources(rng, n)
    sigma = SIGMA_FACTORS[width] * 10.0 / n
    q = _weights(rng, n)
    out = gauss_transform(x, x, q, sigma, method=method)
    _assert_matches(out, x, x, q, sigma)


@pytest.mark.parametrize("n", [10, 300, 2000])
@pytest.mark.parametrize("width", list(SIGMA_FACTORS))
@pytest.mark.parametrize("method", ["direct", "taylor", "auto"])
def test_other_targets_match_dense(rng, n, width, method):
    """Kernel-reconstruction use: targets on a grid wider than the sources."""
    x = _sources(rng, n)
    y = np.linspace(-6.5, 6.5, 777)
    sigma = SIGMA_FACTORS[width] * 10.0 / n
    q = _weights(rng, n)
    out = gauss_transform(y, x, q, sigma, method=method)
    _assert_matches(out, y, x, q, sigma)


@pytest.mark.parametrize("method", ["direct", "taylor", "auto"])
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
