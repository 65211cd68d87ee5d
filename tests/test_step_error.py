"""analysis.step_error: the mean's t interval and the observed order of a step error, on errors of
known order (first, second, none) with and without seed noise."""

import math

import numpy as np
import pytest
from scipy import stats

from particle_entropy.analysis.step_error import mean_interval, observed_order


def test_mean_interval_is_the_t_interval():
    v = np.array([1.0, 2.0, 4.0, 7.0])
    mean, half = mean_interval(v)
    assert mean == pytest.approx(3.5)
    assert half == pytest.approx(stats.t.ppf(0.975, 3) * v.std(ddof=1) / 2.0)
    assert math.isnan(mean_interval([0.3])[1])


@pytest.mark.parametrize("order", [1.0, 2.0])
def test_observed_order_of_a_power_error(order):
    h = np.array([0.4, 0.2, 0.1])
    rng = np.random.default_rng(1)
    seed_offset = rng.normal(0.0, 0.05, 24)  # a seed's own error, the same at every step: paired away
    e = 0.01 + 0.3 * h[:, None] ** order + seed_offset + rng.normal(0.0, 1e-4, (3, 24))
    got = observed_order(*e)
    assert got.p == pytest.approx(order, abs=0.05)
    assert got.lo < order < got.hi and got.hi - got.lo < 0.3
    det = observed_order(*(0.3 * h[:, None] ** order))  # one deterministic run: no interval
    assert det.p == pytest.approx(order) and math.isnan(det.lo) and math.isnan(det.hi)


def test_a_drift_that_does_not_shrink_has_order_near_zero_and_a_sign_change_none():
    h = np.array([0.4, 0.2, 0.1])
    assert observed_order(*(0.01 * np.log(h)[:, None])).p == pytest.approx(0.0, abs=1e-12)
    bent = observed_order(np.array([0.0]), np.array([-1.0]), np.array([0.5]))  # down, then up
    assert math.isnan(bent.p)
    ratio = observed_order(*(h[:, None] ** 1.0 * np.array([[1.0, 1.1]])), ratio=2.0)
    assert ratio.p == pytest.approx(1.0)


def test_observed_order_refuses_unpaired_or_bad_input():
    with pytest.raises(ValueError, match="same seeds"):
        observed_order(np.zeros(3), np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match="ratio"):
        observed_order(np.zeros(3), np.ones(3), np.full(3, 1.5), ratio=1.0)
