"""The authors' sequential pairwise transfer (sequential.py), by its documented behaviour: particle i
exchanges dm = beta (m_i - m_j) W_ij / r_i with each partner j > i in reach, in random order, r_i the
row sum of W over i's neighbours (itself included), masses clipped at zero. Hand-computed exchanges,
non-negativity, conservation when no clipping is needed, the cut-off, and determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.sequential import sequential_transfer


def W(d: float, sigma: float) -> float:
    return math.exp(-d * d / (2.0 * sigma * sigma))


def test_two_particles_one_hand_computed_exchange():
    sigma, beta, d = 0.3, 0.5, 0.2
    x, m = np.array([0.0, d]), np.array([0.7, 0.1])
    out = sequential_transfer(x, m, sigma, beta, None, np.random.default_rng(0))
    r0 = W(0.0, sigma) + W(d, sigma)  # row sum of particle 0 over its neighbours, itself included
    dm = beta * (0.7 - 0.1) * W(d, sigma) / r0
    np.testing.assert_allclose(out, [0.7 - dm, 0.1 + dm], rtol=1e-14, atol=0)
    np.testing.assert_array_equal(m, [0.7, 0.1])  # the input is not changed


def _three(order, x, m, sigma, beta):
    """The documented loop on three particles, i = 0's partners taken in ``order``."""
    m = list(m)
    r = [sum(W(x[i] - x[j], sigma) for j in range(3)) for i in range(3)]
    for j in order:
        dm = beta * (m[0] - m[j]) * W(x[0] - x[j], sigma) / r[0]
        m[0], m[j] = max(0.0, m[0] - dm), max(0.0, m[j] + dm)
    dm = beta * (m[1] - m[2]) * W(x[1] - x[2], sigma) / r[1]
    m[1], m[2] = max(0.0, m[1] - dm), max(0.0, m[2] + dm)
    return np.array(m)


def test_three_particles_follow_one_of_the_two_partner_orders():
    sigma, beta = 0.5, 0.9
    x, m = np.array([-0.1, 0.05, 0.3]), np.array([0.6, 0.1, 0.3])
    a, b = _three((1, 2), x, m, sigma, beta), _three((2, 1), x, m, sigma, beta)
    assert np.max(np.abs(a - b)) > 1e-6  # the order matters, so the check below is sharp
    seen = set()
    for seed in range(12):
        out = sequential_transfer(x, m, sigma, beta, None, np.random.default_rng(seed))
        match = [k for k, ref in enumerate((a, b)) if np.allclose(out, ref, rtol=1e-13, atol=1e-16)]
        assert len(match) == 1, out
        seen.add(match[0])
    assert seen == {0, 1}  # random order: both orders occur over a dozen seeds


def test_masses_stay_non_negative_under_strong_transfer():
    rng = np.random.default_rng(1)
    x = np.sort(rng.uniform(-1, 1, 400))
    m = rng.exponential(1.0, 400) * (rng.random(400) < 0.3)  # many zeros, a few large masses
    for beta in (0.5, 1.0, 3.0):  # beta > 1 overshoots and needs the clipping
        out = sequential_transfer(x, m, 0.05, beta, None, np.random.default_rng(2))
        assert out.shape == m.shape and np.all(out >= 0.0) and np.all(np.isfinite(out))
    strong = sequential_transfer(x, m, 0.05, 3.0, None, np.random.default_rng(2))
    assert not np.allclose(strong, m)


@pytest.mark.parametrize("truncation", [None, 3.0])
def test_mass_conserved_when_no_clipping_is_needed(truncation):
    x = np.linspace(-2, 2, 300)
    m = np.exp(-(x**2)) + 0.5  # smooth and positive
    m /= m.sum()
    out = sequential_transfer(x, m, 0.03, 0.1, truncation, np.random.default_rng(3))
    assert np.all(out > 0)
    assert abs(out.sum() - m.sum()) <= 1e-14
    assert np.max(np.abs(out - m)) > 1e-8  # mass moved


def test_particle_beyond_the_cut_off_receives_nothing():
    sigma = 0.1
    x = np.array([0.0, 0.05, 0.4])  # the last particle is 3.5 sigma from the middle one, 4 from the first
    m = np.array([0.5, 0.5, 0.0])
    cut = sequential_transfer(x, m, sigma, 1.0, 3.0, np.random.default_rng(4))
    assert cut[2] == 0.0
    assert cut[0] + cut[1] == pytest.approx(1.0, abs=1e-15)
    reach = sequential_transfer(x, m, sigma, 1.0, 5.0, np.random.default_rng(4))
    assert reach[2] > 0.0  # within 5 widths it does receive mass


def test_far_particle_is_untouched_with_the_whole_kernel():
    sigma = 0.1
    x = np.array([0.0, 0.05, 100.0])
    m = np.array([0.9, 0.1, 0.25])
    out = sequential_transfer(x, m, sigma, 1.0, None, np.random.default_rng(5))
    assert out[2] == 0.25
    assert out[0] + out[1] == pytest.approx(1.0, abs=1e-15) and out[0] < 0.9


def test_deterministic_for_a_fixed_seed():
    rng = np.random.default_rng(6)
    x = np.sort(rng.uniform(-1, 1, 200))
    m = rng.random(200)
    a = sequential_transfer(x, m, 0.1, 0.8, None, np.random.default_rng(42))
    b = sequential_transfer(x, m, 0.1, 0.8, None, np.random.default_rng(42))
    np.testing.assert_array_equal(a, b)
    c = sequential_transfer(x, m, 0.1, 0.8, None, np.random.default_rng(43))
    assert not np.array_equal(a, c)  # another seed, another partner order
