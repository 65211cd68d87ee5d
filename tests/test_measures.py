"""Entropy, dilution and fitness measures (Sections 2, 3, 5.4, Appendix A)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from conftest import gaussian, no_runtime_warnings

from particle_entropy.core import measures as M


# --------------------------------------------------------------------------- discrete entropy
@pytest.mark.parametrize("n", [1, 2, 10, 300, 30000])
def test_uniform_pmf_has_entropy_ln_n(n):
    assert M.entropy_discrete(np.full(n, 1.0 / n)) == pytest.approx(math.log(n), rel=1e-13, abs=1e-15)


def test_delta_pmf_has_zero_entropy():
    p = np.zeros(100)
    p[37] = 1.0
    with no_runtime_warnings():  # 0 ln 0 must be skipped, not evaluated
        assert M.entropy_discrete(p) == 0.0


def test_discrete_entropy_two_point_and_zeros_ignored():
    p = np.array([0.0, 0.25, 0.0, 0.75, 0.0])
    expected = -(0.25 * math.log(0.25) + 0.75 * math.log(0.75))
    assert M.entropy_discrete(p) == pytest.approx(expected, rel=1e-14)


# --------------------------------------------------------------------------- Gaussian (Eq. 14)
@pytest.mark.parametrize("D,t", [(1e-3, 1000.0), (1e-3, 1.0), (0.5, 3.0)])
def test_sampled_gaussian_entropy_matches_analytic_h_i(D, t):
    """-integral f ln f of N(0, 2Dt) by a fine Riemann sum equals ln sqrt(4 pi D t) + 1/2."""
    s = math.sqrt(2 * D * t)
    dx = s / 200.0
    x = np.arange(-40 * s, 40 * s + dx / 2, dx)
    f = gaussian(x, D, t)
    h_i = M.entropy_inconsistent(f, dx)
    assert h_i == pytest.approx(math.log(math.sqrt(4 * math.pi * D * t)) + 0.5, abs=1e-10)
    assert M.analytic_h_i(D, t) == pytest.approx(h_i, abs=1e-10)


@pytest.mark.parametrize("D,t,dV", [(1e-3, 1000.0, 10 / 300), (1e-3, 250.0, 0.004), (2.0, 0.5, 0.7)])
def test_analytic_h_c_is_eq14(D, t, dV):
    eq14 = -math.log(dV) + math.log(math.sqrt(4 * math.pi * D * t)) + 0.5
    assert M.analytic_h_c(D, t, dV) == pytest.approx(eq14, rel=1e-14)
    # consistent entropy of a finely sampled Gaussian: H_C = -ln dV + H_I (Eqs. 6-7) ...
    h_i = M.analytic_h_i(D, t)
    assert M.entropy_consistent(h_i, dV) == pytest.approx(eq14, rel=1e-14)


def test_analytic_h_c_equals_discrete_entropy_of_binned_gaussian():
    """H_D of the probabilities p_i = g(x_i) dV on a grid of spacing dV (well settled) is H_C."""
    D, t, dV = 1e-3, 1000.0, 10.0 / 3000
    x = np.arange(-12.0, 12.0 + dV / 2, dV)  # +-8.5 sd: tails negligible
    p = gaussian(x, D, t) * dV
    assert M.entropy_discrete(p / p.sum()) == pytest.approx(M.analytic_h_c(D, t, dV), abs=1e-9)


@pytest.mark.parametrize("D,t", [(1e-3, 1000.0), (1e-3, 0.01), (3.0, 7.0)])
@pytest.mark.parametrize("dV", [1e-4, 10 / 300, 1.0, 12.5])
def test_analytic_dilution(D, t, dV):
    E = math.sqrt(4 * math.pi * math.e * D * t)
    assert M.analytic_dilution(D, t) == pytest.approx(E, rel=1e-14)
    # E = dV exp(H_C) (Eq. 8), independent of the sampling volume
    assert dV * math.exp(M.analytic_h_c(D, t, dV)) == pytest.approx(E, rel=1e-13)
    assert M.dilution_index(M.analytic_h_c(D, t, dV), dV) == pytest.approx(E, rel=1e-13)


def test_paper_numbers_at_t_1000():
    """D = 1e-3, t = 1000: E = sqrt(4 pi e) = 5.844565..., H_C(dV = 10/300) = ln(300 E / 10)."""
    E = math.sqrt(4 * math.pi * math.e)
    assert M.analytic_dilution(1e-3, 1000.0) == pytest.approx(E, rel=1e-14)
    assert E == pytest.approx(5.844565, abs=1e-6)
    assert M.analytic_h_c(1e-3, 1000.0, 10 / 300) == pytest.approx(math.log(30 * E), rel=1e-14)


def test_t_zero_is_minus_infinity_without_warnings():
    with no_runtime_warnings():
        assert M.analytic_h_i(1e-3, 0.0) == -math.inf
        assert M.analytic_h_c(1e-3, 0.0, 0.01) == -math.inf
        assert M.analytic_dilution(1e-3, 0.0) == 0.0
        assert M.dilution_index(-math.inf, 0.01) == 0.0
        assert M.entropy_consistent(-math.inf, 0.01) == -math.inf
        assert M.entropy_inconsistent(np.zeros(5), 0.1) == -math.inf


def test_settling_time_is_where_h_c_crosses_zero():
    """t_s = dV^2 / (4 pi e D): there E = dV, so H_C = 0 (Section 3)."""
    D, dV = 1e-3, 10 / 300
    ts = M.settling_time(dV, D)
    assert ts == pytest.approx(dV**2 / (4 * math.pi * math.e * D), rel=1e-14)
    assert M.analytic_h_c(D, ts, dV) == pytest.approx(0.0, abs=1e-13)
    assert M.analytic_dilution(D, ts) == pytest.approx(dV, rel=1e-13)


def test_entropy_pmf():
    assert M.entropy_pmf(3.0, 10.0, 300) == pytest.approx(3.0 + math.log(10 / 300), rel=1e-14)
    # uniform masses over N particles on Omega: H_PMF = ln Omega
    assert M.entropy_pmf(math.log(300), 10.0, 300) == pytest.approx(math.log(10.0), rel=1e-13)


# --------------------------------------------------------------------------- SSE, AIC, COMIC
def test_sse_and_information_criteria_eq43():
    model = np.array([1.0, 2.0, 3.0, 4.0])
    ref = np.array([1.5, 2.0, 2.0, 4.25])
    sse = 0.25 + 0.0 + 1.0 + 0.0625
    assert M.sse(model, ref) == pytest.approx(sse, rel=1e-15)
    n, dV = 4, 0.04
    # Eq. 43: COMIC = 2 ln(SSE / n) - ln(dV), by hand: SSE/n = 0.328125
    assert M.comic(sse, n, dV) == pytest.approx(2 * math.log(0.328125) - math.log(0.04), rel=1e-14)
    assert M.comic(sse, n, dV) == pytest.approx(2 * -1.114360645 + 3.218875825, abs=1e-8)
    # AIC with k = 0 (Eq. 41) and with k parameters
    assert M.aic(sse, n) == pytest.approx(2 * math.log(0.328125), rel=1e-14)
    assert M.aic(sse, n, k=3) == pytest.approx(2 * math.log(0.328125) + 6, rel=1e-14)
    # COMIC - AIC = -ln dV: the computational penalty
    assert M.comic(sse, n, dV) - M.aic(sse, n) == pytest.approx(-math.log(dV), rel=1e-13)


def test_zero_sse_gives_minus_infinity_without_warnings():
    with no_runtime_warnings():
        assert M.aic(0.0, 10) == -math.inf
        assert M.comic(0.0, 10, 0.1) == -math.inf


# --------------------------------------------------------------------------- analytic_sampled
@pytest.mark.parametrize("t", [0.0, 1e-300, 1e-12, 1e-6, 0.01, 1.0, 1000.0])
@pytest.mark.parametrize("offset", [0.0, 0.3])
def test_analytic_sampled_normalised_and_finite(t, offset):
    D, dV = 1e-3, 10 / 300
    x = (np.arange(300) - 150 + offset) * dV  # offset = 0.3: no sample at x = 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = M.analytic_sampled(x, D, t, dV)
    assert np.all(np.isfinite(g)) and np.all(g >= 0)
    assert g.sum() * dV == pytest.approx(1.0, rel=1e-13)
    if 2 * D * t < (0.01 * dV) ** 2:  # far narrower than the spacing: all on the nearest sample
        k = int(np.argmin(np.abs(x)))
        assert g[k] * dV == pytest.approx(1.0, rel=1e-13)


def test_analytic_sampled_is_the_normalised_gaussian():
    D, t = 1e-3, 100.0
    x = np.sort(np.random.default_rng(1).uniform(-5, 5, 500))
    dV = 0.02
    g = M.analytic_sampled(x, D, t, dV)
    ref = gaussian(x, D, t)
    ref = ref / (ref.sum() * dV)
    np.testing.assert_allclose(g, ref, rtol=1e-12, atol=0)


# --------------------------------------------------------------------------- measurement points
def test_measurement_points_are_fixed_sorted_and_in_the_fd_domain():
    """Section 6, point 1: 15 points common to all simulations, uniform on [-6, 6] (the paper's FD
    domain), drawn once from the registry's seed."""
    from particle_entropy.core.registry import MEASUREMENT_POINTS, MEASUREMENT_SEED
    from particle_entropy.core.settings import PAPER

    p = M.measurement_points()
    assert p.shape == (MEASUREMENT_POINTS,) == (15,)
    assert PAPER["fd_length"] == 12.0
    assert np.all(np.diff(p) > 0) and np.all(np.abs(p) < 6.0)
    want = np.sort(np.random.default_rng(MEASUREMENT_SEED).uniform(-6.0, 6.0, 15))
    np.testing.assert_array_equal(p, want)
    np.testing.assert_array_equal(M.measurement_points(12.0), p)
    assert M.measurement_points() is p and not p.flags.writeable  # one shared array nobody can change


def test_at_points_interpolates_linearly_and_is_zero_outside():
    x = np.array([-1.0, 0.0, 2.0])
    c = np.array([4.0, 2.0, 6.0])
    got = M.at_points(np.array([-3.0, -1.0, -0.5, 1.5, 2.0, 2.5]), x, c)
    np.testing.assert_array_equal(got, [0.0, 4.0, 3.0, 5.0, 6.0, 0.0])


def test_gaussian_density_is_the_exact_solution():
    x = np.linspace(-3, 3, 41)
    np.testing.assert_allclose(M.gaussian_density(x, 0.5, 2.0), gaussian(x, 0.5, 2.0), rtol=1e-14)


def test_sse_points_of_the_exact_gaussian_is_zero():
    """A model whose concentration is the exact Gaussian at every point it carries, the
    measurement points among them, scores 0 to round-off."""
    D, t = 1e-3, 250.0
    p = M.measurement_points()
    assert M.sse_points(p, p, M.gaussian_density(p, D, t), D, t, 0.1) == 0.0
    x = np.union1d(np.linspace(-6, 6, 101), p)  # a grid with the points on it
    assert M.sse_points(p, x, gaussian(x, D, t), D, t, 0.12) <= 1e-28


def test_sse_points_by_hand_on_a_tiny_grid():
    """Three points on a four-node grid: interpolation weights and the Gaussian written out."""
    x = np.array([-1.0, 0.0, 1.0, 2.0])
    c = np.array([0.0, 2.0, 1.0, 0.0])
    p = np.array([-0.5, 0.25, 1.5])
    D, t = 0.5, 1.0  # variance 2 D t = 1
    model = [0.5 * 0.0 + 0.5 * 2.0, 0.75 * 2.0 + 0.25 * 1.0, 0.5 * 1.0 + 0.5 * 0.0]
    exact = [math.exp(-(v**2) / 2) / math.sqrt(2 * math.pi) for v in p]
    want = sum((a - b) ** 2 for a, b in zip(model, exact, strict=True))
    assert M.sse_points(p, x, c, D, t, 1.0) == pytest.approx(want, rel=1e-14)


def test_sse_points_at_t_zero_compares_with_the_models_own_delta():
    """At t = 0, as SSE does, the reference is the delta on the model point nearest 0 (height
    1 / dV): the model's own discrete delta scores 0, a displaced one does not."""
    x = np.linspace(-1.0, 1.0, 5)  # spacing 0.5, node 2 at 0
    p = np.array([-0.2, 0.1, 0.6])
    delta = np.array([0.0, 0.0, 2.0, 0.0, 0.0])
    assert M.sse_points(p, x, delta, 1e-3, 0.0, 0.5) == 0.0
    moved = np.roll(delta, 1)  # 2 at x = 0.5: the model is 0, 0.4, 1.6; the reference 1.2, 1.6, 0
    assert M.sse_points(p, x, moved, 1e-3, 0.0, 0.5) == pytest.approx(1.2**2 + 1.2**2 + 1.6**2, rel=1e-14)
