"""Noise-driven segregation of A + B -> C in 1-D, by PT (Benson & Meerschaert 2008) and MTPT (the
closed-form bimolecular step on mass-transfer particles): from A and B well mixed but for the noise
of finite particle numbers, the mean c_A follows the well-mixed C0 / (1 + k C0 t) while k C0 t <= 1
and decays as t^(-1/4) late (Ovchinnikov & Zeldovich 1978; Toussaint & Wilczek 1983; Paster, Bolster
& Benson 2014, J. Comput. Phys. 263, 91), not as the well-mixed t^-1.

Slow (minutes on one core), so not run by default: ``pytest -m slow tests/test_segregation.py``.
The runs are experiments/segregation.py's and the slope's interval analysis/segregation.py's, as
benchmarks/segregation.py uses them, at smaller sizes and steps of dt = 0.02 t (the benchmark's
default is 0.01 t); seeds are fixed, so the test is deterministic. D = k = C0 = 1, m_p = 0.1:
t* ~ 29, the late window is 10 t* .. t_end. Measured (4.6 min wall, 3.7 min CPU, one process):
MTPT -0.244 [-0.281, -0.219] (8 seeds), PT -0.288 [-0.312, -0.267] (16 seeds); early deviations
1.9 % (MTPT) and 1.0 % (PT).
"""

from __future__ import annotations

import numpy as np
import pytest

from particle_entropy.analysis.segregation import slope_interval, well_mixed_ratio
from particle_entropy.experiments.segregation import Segregation, crossover_time, run_seeds

MTPT = Segregation("mtpt", length=3500.0, t_end=3000.0, growth=0.02)
MTPT_SEEDS = range(8)
PT = Segregation("pt", length=4000.0, t_end=3000.0, growth=0.02)
PT_SEEDS = range(16)

SEGREGATED = -0.25  # the late exponent of c_A in 1-D (Ovchinnikov & Zeldovich; Toussaint & Wilczek)
# A late interval must lie inside (STEEPEST, SHALLOWEST): far from the well-mixed -1 (and from 2-D's
# segregated -1/2) and from 0 (no decay)
STEEPEST, SHALLOWEST = -0.5, -0.1
# |<c_A> / (C0 / (1 + k C0 t)) - 1| while k C0 t <= 1. PT reacts pairs by their co-location density,
# the mean-field rate for independent uniform particles: within 2 % (measured 1.0 %, segregation's
# first traces and noise). MTPT's particles start as pure A or pure B and react only as the mass
# transfer mixes neighbours: slower, by 1.9 % near t = 1 / (k C0) (measured), so within 4 %.
PT_EARLY_TOLERANCE = 0.02
MTPT_EARLY_TOLERANCE = 0.04


def late_window(setup: Segregation) -> tuple[float, float]:
    """10 t* .. t_end: past the crossover from the well-mixed t^-1 to the segregated t^(-1/4)."""
    return 10.0 * crossover_time(setup.m_p, setup.c0, setup.D, setup.k), setup.t_end


def early_deviation(setup: Segregation, t: np.ndarray, c: np.ndarray) -> float:
    """The largest |<c_A> / well-mixed - 1| while k C0 t <= 1."""
    early = setup.k * setup.c0 * t <= 1.0
    return float(np.max(np.abs(well_mixed_ratio(t, c, setup.c0, setup.k)[early] - 1.0)))


@pytest.fixture(scope="module")
def mtpt_runs():
    return run_seeds(MTPT, MTPT_SEEDS)


@pytest.fixture(scope="module")
def pt_runs():
    return run_seeds(PT, PT_SEEDS)


@pytest.mark.slow
def test_mtpt_decays_late_as_the_segregated_quarter_power(mtpt_runs):
    """MTPT's late slope: its 95 % interval holds -1/4 and lies far from -1 and 0."""
    fit = slope_interval(*mtpt_runs, *late_window(MTPT))
    print(f"MTPT late slope {fit}")
    assert fit.low <= SEGREGATED <= fit.high, fit
    assert STEEPEST < fit.low and fit.high < SHALLOWEST, fit


@pytest.mark.slow
def test_mtpt_follows_the_well_mixed_law_early(mtpt_runs):
    """MTPT's <c_A> is C0 / (1 + k C0 t) while k C0 t <= 1, within MTPT_EARLY_TOLERANCE."""
    dev = early_deviation(MTPT, *mtpt_runs)
    print(f"MTPT early deviation {dev:.4f}")
    assert dev <= MTPT_EARLY_TOLERANCE


@pytest.mark.slow
def test_pt_decays_late_far_from_well_mixed_and_from_none(pt_runs):
    """PT's late slope: its 95 % interval lies far from -1 and 0. It need not hold -1/4: PT is
    measured slightly steeper in this window (-0.28 [-0.29, -0.27] at L = 11000, t_end = 1e4, 24
    seeds; equal A/B counts on a periodic domain explain part of it), so this shows segregation,
    not its exponent."""
    fit = slope_interval(*pt_runs, *late_window(PT))
    print(f"PT late slope {fit}")
    assert STEEPEST < fit.low and fit.high < SHALLOWEST, fit


@pytest.mark.slow
def test_pt_follows_the_well_mixed_law_early(pt_runs):
    """PT's <c_A> is C0 / (1 + k C0 t) while k C0 t <= 1, within PT_EARLY_TOLERANCE."""
    dev = early_deviation(PT, *pt_runs)
    print(f"PT early deviation {dev:.4f}")
    assert dev <= PT_EARLY_TOLERANCE
