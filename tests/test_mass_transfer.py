"""MTPT mass transfer (Eqs. 16-21) against a dense transfer matrix built in the tests."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import dense_kernel, dense_mass_update, dense_transfer_matrix

from particle_entropy.numerics.mass_transfer import mass_transfer, transfer_matrix_dense


def _positions(rng, n):
    return np.sort(rng.uniform(-5.0, 5.0, n))


def _masses(rng, n, kind):
    if kind == "delta":  # the paper's initial condition: one unit mass, all others zero
        m = np.zeros(n)
        m[n // 2] = 1.0
        return m
    m = rng.exponential(1.0, n)
    m[rng.random(n) < 0.3] = 0.0  # many empty particles
    return m / m.sum()


# --------------------------------------------------------------------------- the dense matrix
@pytest.mark.parametrize("truncation", [None, 3.0])
def test_transfer_matrix_dense_is_symmetric_and_matches_definition(rng, truncation):
    x = _positions(rng, 300)
    sigma = 0.07
    P = transfer_matrix_dense(x, sigma, truncation)
    assert np.array_equal(P, P.T)  # average of row- and column-normalised symmetric W
    # exp of a large negative argument carries a relative error ~ |arg| eps, hence rtol 1e-12
    np.testing.assert_allclose(P, dense_transfer_matrix(x, sigma, truncation), rtol=1e-12, atol=1e-16)
    if truncation is not None:
        far = np.abs(x[:, None] - x[None, :]) > truncation * sigma
        assert far.any() and np.all(P[far] == 0.0)


@pytest.mark.parametrize("truncation", [None, 3.0])
@pytest.mark.parametrize("sigma", [0.005, 0.05, 0.5])
def test_row_sums_identity(rng, sigma, truncation):
    """Row sums of the symmetrised matrix are 0.5 (1 + sum_j W_ij / r_j), not 1 in general."""
    x = _positions(rng, 250)
    P = transfer_matrix_dense(x, sigma, truncation)
    W = dense_kernel(x, x, sigma, truncation)
    r = W.sum(axis=1)
    expected = 0.5 * (1.0 + W @ (1.0 / r))
    np.testing.assert_allclose(P.sum(axis=1), expected, rtol=1e-13, atol=0)
    # random spacings: rows do not sum to one (the identity above is not trivially 1)
    assert np.max(np.abs(P.sum(axis=1) - 1.0)) > 1e-3


@pytest.mark.parametrize("truncation", [None, 3.0])
def test_interior_rows_sum_to_one_on_a_lattice(truncation):
    """Equally spaced particles: r_j is the same for every particle away from the ends, so
    interior rows sum to 1. W is below 1e-17 beyond 8.9 sigma, so with spacing 1 and
    sigma = 2, r_j is at its interior value 18 particles in and rows 36 in sum to 1."""
    x = np.arange(400, dtype=np.float64)
    P = transfer_matrix_dense(x, 2.0, truncation)
    rows = P.sum(axis=1)
    np.testing.assert_allclose(rows[50:-50], 1.0, rtol=0, atol=1e-12)
    assert abs(rows[0] - 1.0) > 1e-3  # the ends do not


# --------------------------------------------------------------------------- one transfer step
CASES = [
    # (n, sigma): sigma from well below to well above the mean spacing 10 / n
    (50, 0.05),
    (50, 1.0),
    (200, 0.02),
    (200, 0.3),
    (400, 0.01),
    (400, 0.4),  # > 150 neighbours within 9 sigma: auto takes the taylor path
]


@pytest.mark.parametrize("n,sigma", CASES)
@pytest.mark.parametrize("method", ["auto", "direct", "taylor"])
@pytest.mark.parametrize("truncation", [None, 3.0])
@pytest.mark.parametrize("kind", ["delta", "random"])
def test_mass_transfer_equals_dense_update(rng, n, sigma, method, truncation, kind):
    if method == "taylor" and truncation is not None:
        pytest.raises(ValueError, mass_transfer, np.linspace(0, 1, 10), np.ones(10), 0.1, 0.5, truncation, "taylor")
        return
    x = _positions(rng, n)
    m = _masses(rng, n, kind)
    beta = 0.5  # collision kernel (Eq. 16)
    P = dense_transfer_matrix(x, sigma, truncation)
    offdiag = P.sum(axis=1) - np.diag(P)
    assert beta * offdiag.max() < 1.0  # single step expected
    ref = dense_mass_update(P, m, beta)
    res = mass_transfer(x, m.copy(), sigma, beta, truncation, method)
    total = m.sum()
    assert res.substeps == 1
    assert np.max(np.abs(res.mass - ref)) <= 1e-12 * total
    assert abs(res.mass.sum() - total) <= 1e-13 * total
    assert res.mass.min() >= 0.0
    # the positivity guard is over particles holding mass (empty ones only receive)
    assert res.max_offdiag_beta == pytest.approx(beta * offdiag[m != 0].max(), rel=1e-12)


@pytest.mark.parametrize("method", ["auto", "direct", "taylor"])
def test_untruncated_transfer_equals_full_dense_gaussian(rng, method):
    """truncation=None means the whole Gaussian (no cut-off visible at 1e-12)."""
    n, sigma = 300, 0.6  # kernel wider than 1/16 of the domain: many long-range pairs
    x = _positions(rng, n)
    m = _masses(rng, n, "random")
    d = x[:, None] - x[None, :]
    W = np.exp(-d * d / (2 * sigma * sigma))  # no truncation, no cut-off at all
    r = W.sum(axis=1)
    P = 0.5 * (W / r[:, None] + W / r[None, :])
    ref = m + 0.5 * (P @ m - m * P.sum(axis=1))
    res = mass_transfer(x, m, sigma, 0.5, None, method)
    assert np.max(np.abs(res.mass - ref)) <= 1e-12 * m.sum()


@pytest.mark.parametrize("truncation", [None, 3.0])
def test_uniform_masses_are_a_fixed_point(rng, truncation):
    """A symmetric P leaves equal masses unchanged (well-mixed state is stationary)."""
    x = _positions(rng, 300)
    m = np.full(300, 1.0 / 300)
    res = mass_transfer(x, m, 0.1, 0.5, truncation)
    np.testing.assert_allclose(res.mass, m, rtol=1e-13, atol=0)


@pytest.mark.parametrize("beta", [5.0, 50.0])
@pytest.mark.parametrize("truncation", [None, 3.0])
@pytest.mark.parametrize("kind", ["delta", "random"])
def test_large_beta_substeps_keep_masses_non_negative(rng, beta, truncation, kind):
    n, sigma = 200, 0.08
    x = _positions(rng, n)
    m = _masses(rng, n, kind)
    P = dense_transfer_matrix(x, sigma, truncation)
    c_max = beta * np.max(P.sum(axis=1) - np.diag(P))
    expected_substeps = math.ceil(c_max)
    assert expected_substeps > 1
    res = mass_transfer(x, m.copy(), sigma, beta, truncation)
    assert res.substeps == expected_substeps
    assert res.max_offdiag_beta == pytest.approx(c_max, rel=1e-12)
    assert res.mass.min() >= 0.0
    assert abs(res.mass.sum() - m.sum()) <= 1e-13 * m.sum()
    ref = dense_mass_update(P, m, beta, expected_substeps)
    assert np.max(np.abs(res.mass - ref)) <= 1e-12 * m.sum()


def test_single_explicit_step_with_large_beta_would_go_negative(rng):
    """Why substeps are needed: the plain explicit update with beta = 5 makes masses negative."""
    x = _positions(rng, 200)
    m = _masses(rng, 200, "delta")
    P = dense_transfer_matrix(x, 0.08)
    assert dense_mass_update(P, m, 5.0).min() < 0.0
    assert mass_transfer(x, m, 0.08, 5.0).mass.min() >= 0.0


def test_trivial_cases_return_a_copy():
    m = np.array([1.0])
    res = mass_transfer(np.array([0.0]), m, 0.1, 0.5)
    assert res.substeps == 1 and np.array_equal(res.mass, m) and res.mass is not m
    x = np.linspace(-1, 1, 5)
    m = np.array([0, 0, 1.0, 0, 0])
    res = mass_transfer(x, m, 0.1, 0.0)
    assert np.array_equal(res.mass, m)


@pytest.mark.parametrize("truncation", [None, 5.0])
@pytest.mark.parametrize("method", ["auto", "direct"])
def test_transfer_on_a_lattice_adds_variance_beta_sigma2(truncation, method):
    """Eq. 19 is diffusive: on an equally spaced lattice (far from its ends) P_ij = W_ij / r with
    sum_j P_ij (x_j - x_i)^2 = sigma^2 (Poisson summation, error ~ exp(-2 pi^2 sigma^2) for the
    whole Gaussian), so one step keeps the mean and adds beta sigma^2 to the second moment:
    for the collision kernel 0.5 * 4 eta D dt = 2 eta D dt."""
    x = np.arange(-300.0, 301.0)
    sigma, beta = 3.0, 0.5
    m = np.exp(-0.5 * (x / 20.0) ** 2)
    m /= m.sum()
    res = mass_transfer(x, m, sigma, beta, truncation, method)
    assert abs(np.sum(res.mass * x) - np.sum(m * x)) <= 1e-12
    dvar = np.sum(res.mass * x * x) - np.sum(m * x * x)
    if truncation is None:
        assert dvar == pytest.approx(beta * sigma**2, rel=1e-10)
    else:  # truncated at 5 sigma: the lattice second moment of the cut kernel, summed in the test
        k = np.arange(-15, 16)
        w = np.exp(-0.5 * (k / sigma) ** 2)
        assert dvar == pytest.approx(beta * np.sum(w * k * k) / np.sum(w), rel=1e-10)


@pytest.mark.parametrize("method", ["direct", "fgt"])
@pytest.mark.parametrize("holders", [1, 5])
def test_step_near_mass_equals_the_whole_step(rng, method, holders):
    """Early MTPT states (a few mass holders among many empty particles) are computed on the
    particles within reach of mass only: same result as the dense update, mass to round-off,
    and particles out of reach stay exactly empty."""
    n, sigma = 4000, 0.004  # ~70 neighbours within 9 sigma; reach covers a few % of [-5, 5]
    x = _positions(rng, n)
    m = np.zeros(n)
    m[rng.choice(np.flatnonzero(np.abs(x) < 0.5), holders, replace=False)] = rng.uniform(0.5, 1.5, holders)
    res = mass_transfer(x, m, sigma, 0.5, None, method)
    near = np.abs(x) < 0.6
    sub = np.flatnonzero(np.abs(x) < 1.0)  # dense reference on a window that holds all reach
    P = dense_transfer_matrix(x[sub], sigma, None)
    # rows of P near the mass need r over all particles; the window is 0.4 wider than reach
    ref = dense_mass_update(P, m[sub], 0.5)
    assert np.max(np.abs(res.mass[sub] - ref)) <= 1e-12 * m.sum()
    assert abs(res.mass.sum() - m.sum()) <= 1e-13 * m.sum()
    assert np.all(res.mass[~near] == 0.0)
    assert res.mass.min() >= 0.0 and np.count_nonzero(res.mass) > holders


def test_positivity_guard_counts_only_mass_holders():
    """beta = 1.5 with a crowded cluster: the cluster's empty particles would need a split, a
    lone mass holder does not; once the cluster holds mass the step is split."""
    cluster = np.linspace(2.0, 2.001, 200)
    lone = np.array([-3.0])
    x = np.concatenate([lone, cluster])
    m = np.zeros(x.size)
    m[0] = 1.0
    res = mass_transfer(x, m, 0.01, 1.5)
    assert res.substeps == 1
    np.testing.assert_array_equal(res.mass, m)  # nothing within reach of the lone particle
    m[100] = 1.0
    res = mass_transfer(x, m, 0.01, 1.5)
    assert res.substeps >= 2 and res.mass.min() >= 0.0
    assert res.mass.sum() == pytest.approx(2.0, rel=1e-13)


def _variance_added(scheme_sigma, truncation, beta=0.5, sigma=0.05):
    """Variance a transfer step adds to a smooth Gaussian of masses on a dense even grid."""
    x = np.linspace(-3.0, 3.0, 6001)
    m = np.exp(-0.5 * (x / 0.5) ** 2)
    m /= m.sum()
    out = mass_transfer(x, m, scheme_sigma(sigma), beta, truncation, "direct").mass
    var = lambda w: np.sum(w * x * x) / w.sum() - (np.sum(w * x) / w.sum()) ** 2
    return (var(out) - var(m)) / (beta * sigma**2)


def test_truncation_loses_the_cut_variance_and_widening_restores_it():
    # a step of Eq. 19 adds beta x (kernel variance); a kernel cut at 3 widths has 0.9733 of it
    from particle_entropy.numerics.bandwidths import truncated_variance_fraction as f

    whole = _variance_added(lambda s: s, None)
    cut = _variance_added(lambda s: s, 3.0)
    widened = _variance_added(lambda s: s / math.sqrt(f(3.0)), 3.0)
    assert whole == pytest.approx(1.0, abs=2e-3)
    assert cut == pytest.approx(f(3.0), abs=2e-3) and cut < 0.98
    assert widened == pytest.approx(1.0, abs=2e-3)
