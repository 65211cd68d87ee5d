"""Time grid: dt0 = 0.01 growing by 1.05 to t_final (175 steps for the paper's runs)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.core.timegrid import MAX_STEPS, time_steps, times


def test_paper_grid():
    dt = time_steps(1000.0, 0.01, 1.05)
    # smallest n with 0.01 (1.05^n - 1) / 0.05 >= 1000: n >= ln(5001) / ln(1.05) = 174.57
    assert len(dt) == 175
    assert math.ceil(math.log(5001) / math.log(1.05)) == 175
    assert dt[0] == 0.01
    np.testing.assert_allclose(dt[1:-1] / dt[:-2], 1.05, rtol=1e-13)
    # the last step is shortened: the full one would overshoot 1000
    full_last = 0.01 * 1.05**174
    assert 0 < dt[-1] < full_last
    assert dt[:-1].sum() < 1000.0 < dt[:-1].sum() + full_last
    t = times(dt)
    assert t[0] == 0.0 and len(t) == 176
    assert t[-1] == 1000.0
    assert np.all(np.diff(t) > 0)
    # the simulations accumulate t += dt: that also ends exactly at t_final
    acc = 0.0
    for d in dt:
        acc += d
    assert acc == 1000.0


def test_fixed_step():
    dt = time_steps(250.0, 0.05, 1.0)
    assert len(dt) == 5000
    np.testing.assert_allclose(dt, 0.05, rtol=1e-8)
    assert times(dt)[-1] == pytest.approx(250.0, rel=1e-15)
    dt = time_steps(1.0, 0.3, 1.0)  # 1 / 0.3 = 3.33: three full steps and a short one
    assert len(dt) == 4
    np.testing.assert_allclose(dt[:3], 0.3, rtol=1e-15)
    assert dt[3] == pytest.approx(0.1, rel=1e-12)


@pytest.mark.parametrize("growth", [1.0, 1.05])
@pytest.mark.parametrize("t_final", [0.005, 0.01 * (1 - 1e-12), 1e-9])
def test_t_final_shorter_than_dt0_is_one_step(growth, t_final):
    dt = time_steps(t_final, 0.01, growth)
    assert len(dt) == 1 and dt[0] == t_final


def test_t_final_equal_to_dt0_is_one_full_step():
    for growth in (1.0, 1.05):
        dt = time_steps(0.01, 0.01, growth)
        assert len(dt) == 1 and dt[0] == 0.01


@pytest.mark.parametrize(
    "t_final,dt0,growth",
    [
        (1000.0, 0.01, 1.05),  # the paper's grid
        (250.0, 0.05, 1.0),  # the paper's FD grid at t = 250 (Fig. 8c)
        (250.0, 0.01, 1.05),  # the particle grid stopped at t = 250
        (500.0, 0.01, 1.05),
        (0.3, 0.1, 1.0),
        (7.7, 0.003, 1.1),
    ],
)
def test_grid_ends_exactly_at_t_final(t_final, dt0, growth):
    """Documented: 'the last one shortened to end exactly at t_final'."""
    dt = time_steps(t_final, dt0, growth)
    assert times(dt)[-1] == t_final


@pytest.mark.parametrize(
    "args",
    [
        (0.0, 0.01, 1.05),
        (-1.0, 0.01, 1.05),
        (math.nan, 0.01, 1.05),
        (math.inf, 0.01, 1.05),
        (1.0, 0.0, 1.05),
        (1.0, -0.01, 1.05),
        (1.0, math.nan, 1.05),
        (1.0, 0.01, 0.99),
        (1.0, 0.01, 0.0),
        (1.0, 0.01, math.nan),
        (1.0, 0.01, math.inf),
        (1e9, 1e-3, 1.0),  # 1e12 steps > MAX_STEPS
    ],
)
def test_bad_inputs_raise(args):
    with pytest.raises(ValueError):
        time_steps(*args)


def test_max_steps_boundary():
    assert MAX_STEPS >= 175
    dt = time_steps(1000.0, 1e-3, 1.0)  # 1e6 steps is allowed
    assert len(dt) == 1_000_000


def test_authors_grid_runs_whole_steps_past_t_final():
    # the authors' loop: t += dt; step; dt *= 1.05 while t < 1000, written out as a plain loop
    t, dt, ends = 0.0, 0.01, []
    while t < 1000.0:
        t += dt
        ends.append(t)
        dt *= 1.05
    assert len(ends) == 175 and round(ends[-1], 1) == 1021.1
    steps = time_steps(1000.0, 0.01, 1.05, grid="authors")
    assert steps.size == 175
    np.testing.assert_allclose(np.cumsum(steps), ends, rtol=1e-12)
    assert times(steps)[-1] == pytest.approx(1021.1, abs=0.05)


@pytest.mark.parametrize(("t_final", "dt0", "growth"), [(10.0, 1.0, 1.0), (10.0, 0.3, 1.0), (7.0, 0.01, 1.2)])
def test_authors_grid_last_step_starts_before_t_final_and_ends_at_or_after_it(t_final, dt0, growth):
    steps = time_steps(t_final, dt0, growth, grid="authors")
    ends = np.cumsum(steps)
    assert ends[-1] >= t_final - 1e-12 and ends[-1] - steps[-1] < t_final
    np.testing.assert_allclose(steps, dt0 * growth ** np.arange(steps.size), rtol=1e-12)  # no step shortened


def test_unknown_grid_is_refused():
    with pytest.raises(ValueError, match="exact, authors"):
        time_steps(10.0, 1.0, 1.0, grid="matlab")
