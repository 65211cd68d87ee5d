"""Reactions on particles (models/reaction_step.py, the species rows of numerics/mass_transfer.py, the
runner's steps as experiments/segregation.py runs them on its domains): MTPT decay against the
conservative run, convergence of MTPT and PT to the well-mixed law C0 / (1 + k C0 t) as N grows,
PT's statistics against the exact laws, and the mass bookkeeping of every step."""

import math

import numpy as np
import pytest

from particle_entropy.core.reactions import Bimolecular, Decay, well_mixed
from particle_entropy.core.timegrid import steps_growing_with_time
from particle_entropy.experiments import segregation as S
from particle_entropy.models import pt
from particle_entropy.models import reaction_step as R
from particle_entropy.models.conservation import MassError
from particle_entropy.numerics.mass_transfer import mass_transfer

KERNELS = [None, 0.005]  # the collision kernel; SPH of width h: beta = 2 eta D dt / h^2 up to 2: substeps


def _pulse(n, rng):
    """N particles on [0, 1) with a Gaussian pulse of A (unit mass) and no B or C."""
    x = np.sort(rng.random(n))
    masses = np.zeros((3, n))
    masses[R.A] = np.exp(-0.5 * ((x - 0.5) / 0.05) ** 2)
    masses[R.A] /= masses[R.A].sum()
    return x, masses


def test_species_rows_move_each_species_as_one_species_does():
    rng = np.random.default_rng(0)
    x = np.sort(rng.random(300))
    m = rng.random((3, 300))
    res = mass_transfer(x, m, 0.01, 0.5)
    for i in range(3):
        np.testing.assert_allclose(res.mass[i], mass_transfer(x, m[i], 0.01, 0.5).mass, rtol=1e-14, atol=1e-16)


@pytest.mark.parametrize("kernel", KERNELS, ids=["collision", "sph"])
def test_mtpt_decay_is_the_conservative_run_times_the_exponential(kernel):
    lam, D, eta, dts = 3.0, 1e-3, 0.5, steps_growing_with_time(0.5, 0.025)
    runs = {}
    for rate in (0.0, lam):
        rng = np.random.default_rng(7)
        x, masses = _pulse(400, rng)
        _, ca, _, x, masses = S.run_mtpt(x, masses, Decay(rate), 1 / 400, D, eta, dts, rng, kernel, (0.0, 1.0))
        runs[rate] = (x, masses, ca)
    (x0, m0, _), (x1, m1, _) = runs[0.0], runs[lam]
    np.testing.assert_array_equal(x0, x1)  # the same walks: reactions draw no random numbers
    f = math.exp(-lam * dts.sum())
    assert np.max(np.abs(m1[R.A] - f * m0[R.A])) <= 1e-14 * m0[R.A].max()
    assert np.max(np.abs(m1[R.C] - (1 - f) * m0[R.A])) <= 1e-14 * m0[R.A].max()
    assert abs(m1[R.A].sum() - f) < 1e-14


def test_mtpt_uniform_equal_masses_follow_the_well_mixed_law_to_round_off():
    # every particle at c0: the exchange moves nothing and each particle is the well-mixed ODE
    rng = np.random.default_rng(3)
    n, c0, k = 200, 2.0, 1.5
    x = np.sort(rng.random(n))
    masses = np.zeros((3, n))
    masses[R.A] = masses[R.B] = c0 / n
    t, ca, cb, _, _ = S.run_mtpt(x, masses, Bimolecular(k), 1 / n, 1e-3, 0.5, steps_growing_with_time(1.0, 0.1), rng)
    np.testing.assert_allclose(ca, c0 / (1 + k * c0 * t), rtol=1e-13)
    np.testing.assert_allclose(cb, ca, rtol=1e-13)


def _bias(run, ns, seeds):
    """Mean and standard error over seeds of c_A(t_final) - C0 / (1 + k C0 t_final), per N."""
    out = []
    for n in ns:
        e = np.array([run(n, s) for s in range(seeds)])
        out.append((e.mean(), e.std(ddof=1) / math.sqrt(seeds)))
    return out


def _assert_decreasing(errors):
    for (e1, s1), (e2, s2) in zip(errors, errors[1:], strict=False):
        assert e1 - e2 > 3.0 * math.hypot(s1, s2), errors


T_FINAL, K, D_MIX = 2.0, 1.0, 1e-4
WELL_MIXED = float(well_mixed(1.0, 1.0, K, T_FINAL)[0])


def test_mtpt_converges_to_the_well_mixed_law_as_n_grows():
    # noise of N: each particle starts with only A or only B (mtpt_uniform_labels)
    def run(n, seed):
        rng = np.random.default_rng(seed)
        x, m = S.mtpt_uniform_labels(n, 1.0, 1.0, rng)
        dts = steps_growing_with_time(T_FINAL, 0.02)
        _, ca, _, _, _ = S.run_mtpt(x, m, Bimolecular(K), 1 / n, D_MIX, 0.5, dts, rng, domain=(0.0, 1.0))
        return ca[-1] - WELL_MIXED

    errors = _bias(run, (100, 400, 1600), 8)
    _assert_decreasing(errors)
    assert errors[-1][0] < 0.06 * WELL_MIXED


def test_pt_converges_to_the_well_mixed_law_as_n_grows():
    def run(n, seed):
        _, ca, _ = S.run_pt(
            n, n, Bimolecular(K), 1.0, D_MIX, 1.0, steps_growing_with_time(T_FINAL, 0.02), np.random.default_rng(seed)
        )
        return ca[-1] - WELL_MIXED

    errors = _bias(run, (100, 400, 1600), 32)
    _assert_decreasing(errors)


def test_pt_decay_matches_the_exponential_in_the_mean():
    lam, t_end, n, seeds = 2.0, 0.5, 20_000, 20
    ends = []
    for s in range(seeds):
        _, ca, _ = S.run_pt(
            n, 0, Decay(lam), 1.0, 1e-3, 1.0, steps_growing_with_time(t_end, 0.05), np.random.default_rng(s)
        )
        ends.append(ca[-1])
    mean, se = np.mean(ends), np.std(ends, ddof=1) / math.sqrt(seeds)
    assert abs(mean - math.exp(-lam * t_end)) < 3 * se
    assert se < 5e-3 * math.exp(-lam * t_end)  # not a vacuous bound


def test_pt_bimolecular_follows_the_well_mixed_law_at_early_time():
    # many particles, k C0 t = 1/4: the reaction has had no time to segregate A from B
    n, t_end, seeds = 5000, 0.25, 10
    ends = []
    for s in range(seeds):
        dts = steps_growing_with_time(t_end, 5e-3)
        _, ca, _ = S.run_pt(n, n, Bimolecular(K), 1.0, 1e-4, 1.0, dts, np.random.default_rng(100 + s))
        ends.append(ca[-1])
    wm = float(well_mixed(1.0, 1.0, K, t_end)[0])
    mean, se = np.mean(ends), np.std(ends, ddof=1) / math.sqrt(seeds)
    assert abs(mean - wm) < 3 * se
    assert se < 0.005 * wm
    assert 1.0 - mean > 0.9 * (1.0 - wm)  # it reacted about as much as it must


@pytest.mark.parametrize("kernel", KERNELS, ids=["collision", "sph"])
def test_mtpt_keeps_a_plus_c_and_b_plus_c_and_no_mass_negative(kernel):
    rng = np.random.default_rng(11)
    n = 600
    x, m = S.mtpt_uniform_labels(n, 1.0, 1.0, rng)
    a0, b0 = m[R.A].sum(), m[R.B].sum()
    substeps = []
    for i, dt in enumerate(steps_growing_with_time(1.0, 0.05)):
        x, m, s = S.mtpt_step(x, m, Bimolecular(5.0), 1 / n, 1e-3, 0.5, dt, rng, kernel, (0.0, 1.0), t=i)
        substeps.append(s)
    assert abs(m[R.A].sum() + m[R.C].sum() - a0) < 1e-13 * a0
    assert abs(m[R.B].sum() + m[R.C].sum() - b0) < 1e-13 * b0
    assert m.min() >= 0.0
    assert m[R.C].sum() > 0.3 * a0  # the reaction ran
    if kernel is not None:
        assert max(substeps) > 1  # the split exchange was exercised


def test_a_step_that_loses_reacted_mass_raises():
    class Leaky(Bimolecular):
        def on_masses(self, ma, mb, dV, dt):
            na, nb, gained = super().on_masses(ma, mb, dV, dt)
            return na, nb, 0.5 * gained

    rng = np.random.default_rng(0)
    x, m = S.mtpt_uniform_labels(100, 1.0, 1.0, rng)
    m[R.A] = m[R.B] = 0.01
    with pytest.raises(MassError, match="did not conserve A \\+ C"):
        S.mtpt_step(x, m, Leaky(1.0), 0.01, 1e-3, 0.5, 0.1, rng)


def test_pt_keeps_counts_and_puts_c_between_the_pair():
    rng = np.random.default_rng(5)
    xa, xb, xc = rng.random(3000), rng.random(3000), np.empty(0)
    for _ in range(20):
        moved = pt.step([xa, xb, xc], 1e-4, 0.05, rng, period=1.0)
        xa, xb, xc = R.react_particles(Bimolecular(1.0), moved, 1 / 3000, 1e-4, 0.05, 1.0, rng)
    assert xa.size + xc.size == 3000 and xb.size + xc.size == 3000
    assert 0 < xc.size and np.all((xc >= 0) & (xc < 1))


def test_pt_refuses_a_step_whose_probability_exceeds_one():
    m_p, k, D = 0.1, 10.0, 1e-3
    dt_max = R.largest_pt_dt(k, m_p, D)
    assert R.max_pair_probability(k, m_p, D, dt_max) == pytest.approx(1.0)
    xa = xb = np.array([0.5])
    with pytest.raises(ValueError, match=f"dt = {1.01 * dt_max:.6g}"):
        R.pair_reactions(xa, xb, k, m_p, D, 1.01 * dt_max, 1.0, np.random.default_rng(0))


def test_colocation_density_is_the_separation_density_at_zero():
    # v(s) integrates to 1 over s: the density of X_A - X_B (variance 4 D dt) at 0 shifted by s
    s = np.linspace(-1.0, 1.0, 20001)
    v = R.colocation_density(s, 0.5, 0.01)
    assert np.trapezoid(v, s) == pytest.approx(1.0, rel=1e-9)
    assert v[10000] == pytest.approx(1 / math.sqrt(8 * math.pi * 0.5 * 0.01))
