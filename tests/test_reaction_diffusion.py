"""The reaction-diffusion reference (numerics/reaction_diffusion.py) against exact solutions: the
well-mixed law for uniform fields, the decaying Gaussian, the conserved totals, and Richardson's
estimates on plumes that meet."""

import math

import numpy as np
import pytest

from particle_entropy.core.reactions import Bimolecular, Decay
from particle_entropy.core.sources import Source
from particle_entropy.numerics import reaction_diffusion as RD

D, T = 0.1, 2.0


def test_uniform_equal_species_follow_the_well_mixed_law():
    c0, k, steps = 2.0, 0.5, 400
    x, dx = RD.cell_centres(0.0, 1.0, 64)
    times = T * np.arange(0, steps + 1, 50) / steps
    f = RD.solve(x, np.full(x.size, c0), c0, D, Bimolecular(k), T, steps, times)
    exact = c0 / (1.0 + k * c0 * T)
    np.testing.assert_allclose(f.a, exact, rtol=1e-12)
    np.testing.assert_allclose(f.b, exact, rtol=1e-12)
    np.testing.assert_allclose(f.c, c0 - exact, rtol=1e-12)
    np.testing.assert_allclose(f.masses[:, 0], c0 / (1.0 + k * c0 * times), rtol=1e-12)


def test_richardson_recovers_a_second_order_sequence():
    h = np.array([0.4, 0.2, 0.1])
    r = RD.richardson(*(1.5 + 3.0 * h**2))
    assert r.order == pytest.approx(2.0, rel=1e-12)
    assert r.value == pytest.approx(1.5, rel=1e-14)
    assert r.error == pytest.approx(3.0 * 0.1**2, rel=1e-12)
    wobble = RD.richardson(1.0, 1.1, 1.05)  # no asymptotic convergence: no order, the largest change
    assert math.isnan(wobble.order) and wobble.value == 1.05 and wobble.error == pytest.approx(0.1)


def test_cubic_interpolation_is_exact_for_cubics():
    x, _ = RD.cell_centres(-1.0, 1.0, 40)
    p = np.array([-0.99, -0.3, 0.013, 0.7, 0.98])
    cubic = lambda z: 2.0 - z + 3.0 * z**2 - 0.5 * z**3
    np.testing.assert_allclose(RD.at_points(p, x, cubic(x)), cubic(p), rtol=1e-13)


def test_decaying_gaussian_matches_the_exact_solution_at_second_order():
    lam, v = 0.7, 0.3
    source = Source.of("gaussian", x0=0.0, sd=0.5)
    points = np.array([-1.5, -0.3, 0.0, 0.4, 1.5]) + v * T  # lab frame, away from the inflections
    ref = RD.reference(source, 0.0, D, Decay(lam), T, points, v=v, n_cells=128)
    exact = source.density(points, D, v, T) * math.exp(-lam * T)
    fine_error = np.abs(ref.a_points.values[2] - exact)
    assert np.all((ref.a_points.order > 1.9) & (ref.a_points.order < 2.1))
    assert np.all(fine_error <= 1.5 * ref.a_points.error)  # the estimate is the error's size ...
    assert np.all(fine_error >= 0.5 * ref.a_points.error)  # ... not a loose bound
    assert np.all(np.abs(ref.a_points.value - exact) < 0.05 * fine_error)
    # decay commutes with diffusion: the product mass is exact to round-off on every grid
    assert ref.product_mass.values[0] == pytest.approx(-math.expm1(-lam * T), rel=1e-12)


class _Watched:
    """Bimolecular kinetics that record the smallest concentration they are handed (every half step)."""

    def __init__(self, k):
        self.kinetics, self.smallest = Bimolecular(k), math.inf
        self.CONSUMES_B = True

    def react(self, a, b, dt):
        self.smallest = min(self.smallest, float(a.min()), float(b.min()))
        return self.kinetics.react(a, b, dt)


def _boxes(n):
    x, dx = RD.cell_centres(-8.0, 8.0, n)
    a0 = Source.of("box", a=-1.0, b=0.0).masses(x, dx) / dx
    b0 = 0.8 * Source.of("box", a=-0.5, b=1.0).masses(x, dx) / dx
    return x, a0, b0


def test_totals_are_conserved_and_nothing_goes_negative_every_step():
    x, a0, b0 = _boxes(256)
    steps = 200
    watched = _Watched(3.0)
    f = RD.solve(x, a0, b0, D, watched, T, steps, T * np.arange(steps + 1) / steps)
    m_a, m_b, m_c = f.masses.T
    np.testing.assert_allclose(m_a + m_c, 1.0, rtol=1e-13, atol=0)
    np.testing.assert_allclose(m_b + m_c, 0.8, rtol=1e-13, atol=0)
    assert np.all(np.diff(m_c) > 0) and m_c[-1] > 0.1  # the boxes overlap and keep reacting
    assert watched.smallest >= 0.0
    assert min(f.a.min(), f.b.min(), f.c.min()) >= 0.0


def test_a_step_that_loses_mass_is_refused():
    class Leaky:
        CONSUMES_B = True

        def react(self, a, b, dt):
            a_new, b_new, made = Bimolecular(1.0).react(a, b, dt)
            return a_new, b_new, 0.999 * made

    x, a0, b0 = _boxes(64)
    with pytest.raises(ArithmeticError, match="changed the total"):
        RD.solve(x, a0, b0, D, Leaky(), T, 20)


def test_a_gaussian_into_uniform_b_converges_within_its_bounds():
    k, c0 = 2.0, 0.5
    ref = RD.reference(Source.of("gaussian", x0=0.0, sd=0.5), c0, D, Bimolecular(k), T, [0.0, 0.5], n_cells=128)
    m = ref.product_mass
    assert m.error < abs(m.values[0] - m.values[2])
    assert 1.9 < m.order < 2.1
    # B <= C0 everywhere (B_t <= D B_xx), so dM_A/dt >= -k C0 M_A: at most 1 - exp(-k C0 T) of A reacts
    assert 0.0 < m.value <= -math.expm1(-k * c0 * T)
    assert np.all(ref.c_points.error < np.abs(ref.c_points.values[0] - ref.c_points.values[2]))


def test_two_boxes_that_meet_converge_within_their_bounds():
    k = 2.0
    a, b = Source.of("box", a=-1.0, b=0.0), Source.of("box", a=0.0, b=1.0)
    # bounds and cells put the boxes' edges on cell faces of every grid: second order from the start
    ref = RD.reference(a, (b, 0.8), D, Bimolecular(k), T, [-0.3, 0.0, 0.4], bounds=(-8.0, 8.0), n_cells=128)
    m = ref.product_mass
    assert m.error < abs(m.values[0] - m.values[2])
    assert 1.9 < m.order < 2.1
    assert 0.0 < m.value <= 0.8  # the scarcer species' mass
    assert np.all(ref.c_points.error < np.abs(ref.c_points.values[0] - ref.c_points.values[2]))


def test_richardson_extrapolates_only_near_the_scheme_s_order():
    h = np.array([0.4, 0.2, 0.1])
    second = RD.richardson(*(1.5 + h**2))
    assert second.asymptotic and second.value == pytest.approx(1.5, rel=1e-14)
    # order 1 (a kink) or 5 (a lucky cancellation): the finest grid's value, its error at least |f3 - f2|
    first, fifth = RD.richardson(*(1.5 + h)), RD.richardson(*(1.5 + h**5))
    assert not first.asymptotic and first.value == 1.6 and first.error == pytest.approx(0.1, rel=1e-12)
    assert not fifth.asymptotic and fifth.value == 1.5 + 0.1**5 and fifth.error == pytest.approx(0.2**5 - 0.1**5)
    assert fifth.error >= abs(fifth.value - 1.5)  # the truth within the stated error, where p = 5 would not be
    same = RD.richardson(0.25, 0.25, 0.25)  # every grid agrees (a decay's mass): exact
    assert same.asymptotic and same.error == 0.0
    mixed = RD.richardson([1.9, 1.51024], [1.7, 1.50032], [1.6, 1.50001])
    assert mixed.asymptotic.tolist() == [False, False]


def test_the_default_grid_puts_every_box_edge_on_a_face_of_all_three_grids():
    a, b = Source.of("box", a=-0.7, b=0.3), Source.of("box", a=0.3, b=1.1)
    lo, hi, n = RD.aligned_grid([a, b], 1e-3, 20.0)
    wlo, whi = RD.window([a, b], 1e-3, 20.0)
    assert lo <= wlo and hi >= whi and RD.COARSE_CELLS <= n <= RD.ALIGN_SLACK * RD.COARSE_CELLS
    for level in range(3):
        dx = (hi - lo) / (n * 2**level)
        faces = (np.array([-0.7, 0.3, 1.1]) - lo) / dx
        np.testing.assert_allclose(faces, faces.round(), rtol=0, atol=1e-8)
    smooth = Source.of("gaussian", x0=0.0, sd=0.5)
    assert RD.aligned_grid([smooth], D, T) == (*RD.window([smooth], D, T), RD.COARSE_CELLS)


def test_a_decaying_box_s_extrapolation_is_far_inside_its_stated_error():
    # the box's edges on faces (the default grid): order 2 at every point, the fine grid's error the
    # estimate's size, the extrapolated value 1e-3 of it from the exact one. With the edges inside
    # cells (the plain window) the extrapolation kept 2 to 8 % of the error
    lam, box = 0.7, Source.of("box", a=-1.0, b=1.0)
    points = np.array([-1.6, -1.2, -0.5, 0.0, 0.7, 1.3, 2.0])
    exact = box.density(points, D, 0.0, T) * math.exp(-lam * T)
    ref = RD.reference(box, 0.0, D, Decay(lam), T, points)
    a = ref.a_points
    assert ref.plan.aligned and np.all(a.asymptotic) and np.all(np.abs(a.order - 2.0) < 0.01)
    np.testing.assert_allclose(np.abs(a.values[2] - exact) / a.error, 1.0, atol=0.01)
    assert np.all(np.abs(a.value - exact) < 0.01 * a.error)


def test_a_fast_reaction_s_steps_are_capped_and_its_plan_is_known_before_it_runs():
    # the kinetics are exact within a step: k C0 t = 1e9 plans no more work than MAX_WORK, where the
    # kinetic rule asked for 2.5e8 steps on the coarsest grid
    box = Source.of("box", a=-1.0, b=1.0)
    for k in (1e-7, 1e8):
        how = RD.plan(box, 0.5, 1e-5, Bimolecular(k), 20.0)
        assert how.work <= RD.MAX_WORK and how.aligned
        assert how.capped == (k > 1.0) and how.n_steps >= how.by_r
    assert how.by_kinetics == pytest.approx(0.5 * 1e8 * 20.0 / RD.COARSE_KINETIC)
    small = RD.plan(box, 0.5, 1e-5, Bimolecular(1e8), 20.0, max_work=1e6)
    assert small.n_steps < how.n_steps and small.work <= 1e6
    with pytest.raises(RD.CostError, match="above the bound of 1e\\+03 cell-steps"):
        RD.reference(box, 0.5, 1e-5, Bimolecular(1e8), 20.0, max_work=1e3)
