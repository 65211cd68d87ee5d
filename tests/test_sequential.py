"""The authors' sequential pairwise transfer (sequential.py), by its documented behaviour: particle i
exchanges dm = beta (m_i - m_j) W_ij / r_i with each partner j > i in reach, in random order, r_i the
row sum of W over i's neighbours (itself included), masses clipped at zero. Hand-computed exchanges,
non-negativity, conservation when no clipping is needed, the cut-off, and determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.numerics.sequential import sequential_transfer


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


# ---------------------------------------------------------------- the authors' storage order
def _stored_loop(x, m, label, sigma, beta, partner_orders):
    """The documented loop written plainly: particles visited in storage order (``label``),
    partners later in storage within the cut-off in the given orders, r_i over all neighbours."""
    m = list(m)
    n = len(x)
    at = {int(label[p]): p for p in range(n)}
    for i in range(n):
        p = at[i]
        r = sum(W(x[p] - x[q], sigma) for q in range(n))
        for q in partner_orders[i]:
            dm = beta * (m[p] - m[q]) * W(x[p] - x[q], sigma) / r
            m[p], m[q] = max(0.0, m[p] - dm), max(0.0, m[q] + dm)
    return np.array(m)


def test_storage_order_visits_particles_as_stored_with_partners_on_both_sides():
    sigma, beta = 0.5, 0.9
    x, m = np.array([-0.1, 0.05, 0.3]), np.array([0.6, 0.1, 0.3])
    label = np.array([2, 0, 1])  # the middle particle is stored first, the left one last
    # stored first (x = 0.05) has partners on both sides (sorted 2 and 0), then x = 0.3 has sorted 0
    refs = [_stored_loop(x, m, label, sigma, beta, {0: order, 1: [0], 2: []}) for order in ([2, 0], [0, 2])]
    assert np.max(np.abs(refs[0] - refs[1])) > 1e-6
    by_position = sequential_transfer(x, m, sigma, beta, None, np.random.default_rng(0))  # the sorted variant
    assert min(np.max(np.abs(by_position - ref)) for ref in refs) > 1e-6  # the order is a real difference
    seen = set()
    for seed in range(12):
        out = sequential_transfer(x, m, sigma, beta, None, np.random.default_rng(seed), label=label)
        match = [k for k, ref in enumerate(refs) if np.allclose(out, ref, rtol=1e-13, atol=1e-16)]
        assert len(match) == 1, out
        seen.add(match[0])
    assert seen == {0, 1}


def test_row_sum_includes_neighbours_visited_earlier():
    # stored order: right, left, middle. When the middle particle is visited last it has no
    # partners; the left one (visited second) must count the right one, visited before it, in r.
    sigma, beta = 0.4, 0.5
    x, m = np.array([0.0, 0.2, 0.5]), np.array([0.2, 0.5, 0.3])
    label = np.array([1, 2, 0])
    ref = [_stored_loop(x, m, label, sigma, beta, {0: order, 1: [1], 2: []}) for order in ([0, 1], [1, 0])]
    out = sequential_transfer(x, m, sigma, beta, None, np.random.default_rng(1), label=label)
    assert min(np.max(np.abs(out - r)) for r in ref) < 1e-15


def test_symmetric_pair_weight_variant():
    sigma, beta, d = 0.3, 0.5, 0.2
    x, m = np.array([0.0, d, 0.5]), np.array([0.7, 0.1, 0.0])  # r_0, r_1 and r_2 all differ
    r = [sum(W(x[i] - x[j], sigma) for j in range(3)) for i in range(3)]

    def ref(order):
        mm = list(m)
        for i, j in [(0, order[0]), (0, order[1]), (1, 2)]:
            dm = beta * (mm[i] - mm[j]) * W(x[i] - x[j], sigma) * 0.5 * (1 / r[i] + 1 / r[j])
            mm[i], mm[j] = mm[i] - dm, mm[j] + dm
        return np.array(mm)

    refs = [ref((1, 2)), ref((2, 1))]
    row_only = sequential_transfer(x, m, sigma, beta, 9.0, np.random.default_rng(0))
    assert min(np.max(np.abs(row_only - r_)) for r_ in refs) > 1e-6  # the weights are a real difference
    out = sequential_transfer(x, m, sigma, beta, 9.0, np.random.default_rng(0), symnorm=True)
    assert min(np.max(np.abs(out - r_)) for r_ in refs) < 1e-15


def test_without_clipping_masses_go_negative_and_mass_is_conserved():
    rng = np.random.default_rng(1)
    x = np.sort(rng.uniform(-1, 1, 40))  # about one particle per kernel width: W_ij / r_i up to ~1/2
    m = rng.exponential(1.0, 40) * (rng.random(40) < 0.3)
    out = sequential_transfer(x, m, 0.02, 3.0, 3.0, np.random.default_rng(2), clip=False)
    assert out.min() < -1e-6  # beta = 3 overshoots
    assert abs(out.sum() - m.sum()) <= 1e-12 * m.sum()
    clipped = sequential_transfer(x, m, 0.02, 3.0, 3.0, np.random.default_rng(2))
    assert clipped.min() >= 0.0 and clipped.sum() > m.sum() + 1e-6  # clipping creates mass


def _centre_of_mass_after_steps(label_of, seeds, steps=10):
    """Centre of mass of a unit mass at the middle of an even grid (one particle a kernel width)."""
    x = np.linspace(-1.0, 1.0, 201)
    shifts = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        m = np.zeros(x.size)
        m[100] = 1.0
        label = label_of(rng, x.size)
        for _ in range(steps):
            m = sequential_transfer(x, m, 0.01, 0.5, 3.0, rng, label=label)
        shifts.append(float(np.sum(m * x) / m.sum()))
    return np.array(shifts)


def test_position_order_moves_the_centre_of_mass_storage_order_does_not():
    # left to right, a particle's left neighbours take their share of its mass before it gives
    # to its right ones: a drift to the left. Random storage order has no direction.
    seeds = range(30)
    se = lambda a: a.std(ddof=1) / math.sqrt(a.size)
    by_position = _centre_of_mass_after_steps(lambda rng, n: None, seeds)
    stored = _centre_of_mass_after_steps(lambda rng, n: rng.permutation(n), seeds)
    assert by_position.mean() < -4 * se(by_position)
    assert abs(stored.mean()) < 3 * se(stored)
