"""core/runcost.py: the one run cost model. The step-work kind against runs counted by hand, the
tabulated curve at and between its knots in log-log, and one interface, RunCost.seconds, behind
the jobs' order, the scenes' counted costs and the optimum searches' budgets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.analysis import search as E
from particle_entropy.analysis.optimum import Search, calibrated_cost, planned_cost_s
from particle_entropy.analysis.scene_search import SceneSearch
from particle_entropy.core.case import Case
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.runcost import RunCost, StepWork, Tabulated, Tally, run_steps, units_per_step
from particle_entropy.pipeline.jobcost import JOB_COST, PAIR_S, STEP_S, UNIT_S, estimated_seconds
from particle_entropy.scenes.scene import Scene


def _pt(n=10, **kw):
    """A PT run of 4 fixed steps of 0.25 to t_final = 1."""
    return RunConfig.of(method="pt", kernel="bins", n=n, dt_growth=1.0, t_final=1.0, dt0=0.25, **kw).resolved()


def _fd(n=10):
    """An FD run of 4 fixed steps of 0.25 on n intervals (n + 1 nodes)."""
    return RunConfig.of(
        method="fd", kernel="implicit", n=n, dt_growth=1.0, t_final=1.0, dt0=0.25, fd_length=1.0
    ).resolved()


def test_step_work_counts_a_tiny_run_by_hand():
    """4 steps of 10 particles: 4 x 2 s + 40 particle-steps x 0.5 s = 28 s; FD: 11 nodes a step."""
    model = StepWork(2.0, 0.5)
    assert run_steps(_pt()).tolist() == [0.25] * 4
    assert model.tally(_pt()) == Tally(4, 40)
    assert model.seconds(_pt()) == 4 * 2.0 + 40 * 0.5 == 28.0
    assert units_per_step(_fd()) == 11 and model.seconds(_fd()) == 4 * 2.0 + 44 * 0.5
    by_n = StepWork(2.0, 0.5, per="n")  # the jobs' constants are per N: FD's 10 intervals
    assert by_n.seconds(_fd()) == 4 * 2.0 + 40 * 0.5 and by_n.seconds(_pt()) == model.seconds(_pt())
    with pytest.raises(ValueError, match="per='nodes'"):
        StepWork(1.0, 1.0, per="nodes").seconds(_pt())


def test_growing_steps_are_counted_on_the_runs_grid():
    """dt0 = 0.25 doubling to t_final = 1: 0.25, 0.5 and a last step shortened to 0.25: 3 steps."""
    cfg = RunConfig.of(method="pt", kernel="bins", n=7, dt_growth=2.0, t_final=1.0, dt0=0.25).resolved()
    assert run_steps(cfg).tolist() == [0.25, 0.5, 0.25]
    assert StepWork(1.0, 1.0).seconds(cfg) == 3 + 21


def test_pairs_are_priced_step_by_step():
    """A pair counter's pairs join each step: sum over steps of (a + b N + c pairs)."""
    seen = []

    def pairs(cfg, dt, t_end):
        seen.append((dt.tolist(), t_end.tolist()))
        return np.array([1.0, 2.0, 3.0, 4.0])

    model = StepWork(2.0, 0.5, 0.25, pairs=pairs)
    assert model.seconds(_pt()) == 4 * (2.0 + 0.5 * 10) + 0.25 * (1 + 2 + 3 + 4)
    assert seen == [([0.25] * 4, [0.25, 0.5, 0.75, 1.0])]  # the steps and when each ends
    tally = model.tally(_pt())
    assert np.array_equal(tally.steps, np.ones(4)) and np.array_equal(tally.work, np.full(4, 10.0))


def test_totals_and_steps_give_the_same_seconds():
    model = StepWork(3.85e-5, 1.72e-8, 5e-9)
    per_step = Tally(np.ones(175), np.full(175, 3001.0), np.linspace(0.0, 1e5, 175))
    totals = Tally(175, 175 * 3001, float(per_step.pairs.sum()))
    assert model.counted(per_step) == pytest.approx(model.counted(totals), rel=1e-12)


def test_the_tabulated_curve_is_exact_at_its_knots_and_log_log_between():
    xs, s = np.array([10.0, 100.0, 1000.0]), np.array([1.0, 4.0, 8.0])
    curve = Tabulated(xs, s)
    for x, y in zip(xs, s):
        assert curve.seconds(x) == pytest.approx(y, rel=1e-12)
    assert curve.seconds(math.sqrt(10.0 * 100.0)) == pytest.approx(2.0, rel=1e-12)  # geometric mean halfway in log
    assert curve.seconds(10.0**1.25) == pytest.approx(1.0 * 4.0**0.25, rel=1e-12)
    assert curve.seconds(1.0) == pytest.approx(4.0 ** (-1.0), rel=1e-12)  # slope log 4 / log 10 below
    assert curve.seconds(1e4) == pytest.approx(16.0, rel=1e-12)  # slope log 2 / log 10 above


def test_the_tabulated_curve_extrapolates_with_clipped_slopes_and_one_knot_alone():
    steep = Tabulated(np.array([10.0, 100.0]), np.array([1.0, 1e4]))  # slope 4 in log-log, kept at 2
    assert steep.seconds(1000.0) == pytest.approx(1e4 * 100.0, rel=1e-12)
    assert steep.seconds(1.0) == pytest.approx(1e-2, rel=1e-12)
    alone = Tabulated(np.array([100.0]), np.array([3.0]))
    assert alone.seconds(400.0) == pytest.approx(12.0, rel=1e-12)  # proportional to N
    growth = Tabulated(np.array([1.05]), np.array([2.0]), lambda g: np.log(np.asarray(g) - 1.0), -1.0)
    assert growth.seconds(1.1) == pytest.approx(1.0, rel=1e-12)  # twice dt_growth - 1: half the steps


def test_one_interface_for_the_jobs_the_scenes_and_the_searches():
    """Every cost model is a RunCost and answers seconds(point); each search kind asks through run_seconds."""
    cfg = RunConfig.of(method="mtpt", kernel="collision", n=300).resolved()
    job = JOB_COST["mtpt"]
    assert isinstance(job, RunCost) and job == StepWork(
        STEP_S["mtpt"], UNIT_S["mtpt"], PAIR_S, per="n", pairs=job.pairs
    )
    assert estimated_seconds(cfg, 3) == 3 * job.seconds(cfg)

    scene = Scene.from_config(
        "s",
        {
            "t_final": 50.0,
            "target": {"value": 0.01},
            "candidates": [{"method": "pt", "kernel": "bins", "n_range": [30, 240]}],
        },
    )
    cand = scene.candidates[0]
    model = scene.cost_model("pt")
    assert isinstance(model, RunCost) and model == StepWork(*dict(scene.cost)["pt"])
    run = scene.run_config(cand, 60)
    assert (
        scene.run_cost(cand, 60)
        == model.seconds(run)
        == scene.cost_s("pt", run_steps(run).size, 60 * run_steps(run).size)
    )
    kind = SceneSearch(scene)
    assert [kind.run_seconds((0, n)) for n in cand.ladder()] == [scene.run_cost(cand, n) for n in cand.ladder()]

    optimum = Search(
        name="t", model=Case("mtpt", "collision", None), time=1.0, lo=30, hi=3000, cost=((30.0, 0.03), (3000.0, 3.0))
    )
    curve = calibrated_cost(optimum)
    assert isinstance(curve, Tabulated) and optimum.cost_curve.seconds(300.0) == curve.seconds(300.0)
    assert optimum.run_seconds(300) == pytest.approx(0.3, rel=1e-12)
    assert math.isnan(
        Search(name="u", model=Case("mtpt", "collision", None), time=1.0, lo=30, hi=3000).run_seconds(300)
    )
    plan = optimum.first_plan(0)
    counts = plan["last"] - plan["first"] + 1
    expected = sum(int(c) * optimum.run_seconds(x) for x, c in zip(plan["n"], counts))
    assert planned_cost_s(optimum, plan) == E.counted_seconds(optimum, plan["n"], counts) == pytest.approx(expected)


def test_a_kind_without_a_cost_model_counts_nan():
    class Bare(E.AdaptiveSearch):
        title, max_plans = "bare", 1

        def first_plan(self, base_seed):
            return E.new_plan([], ["round", "first", "last", "done"])

        def next_plan(self, plan, runs, base_seed):
            return plan

        def read_runs(self, plan, paths):
            return None

    assert math.isnan(Bare().run_seconds(100))
