"""The adaptive COMIC optimum search (optimum.py) on synthetic COMIC curves with a known minimum:
it brackets the true optimum, respects its budget, refines near the minimum only, replicates
where neighbours are not resolved, and (FD) needs one run per N."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from particle_entropy.analysis.optimum import (
    PLAN_COLUMNS,
    REASONS,
    RESULT_COLUMNS,
    Search,
    initial_plan,
    next_plan,
    result_table,
    runs_in,
)
from particle_entropy.core.case import Case, SettingError

N_STAR = 1000.0  # the synthetic curve's minimum


def comic(n, seed, noise):
    """A smooth COMIC curve in log N with its minimum at N_STAR, plus per-seed noise."""
    rng = np.random.default_rng([int(n), int(seed)])
    return 2.0 * (math.log(n) - math.log(N_STAR)) ** 2 + noise * rng.standard_normal()


def realisations_of(plan, noise):
    rows = [
        (n, s, comic(n, s, noise))
        for _, b in plan.iterrows()
        for n in [int(b["n"])]
        for s in range(b["first"], b["last"] + 1)
    ]
    return pd.DataFrame(rows, columns=["n", "seed", "COMIC"])


def costs_of(table, power=1.0):
    """Synthetic measured costs: 1e-3 N^power core-seconds a run."""
    return table.assign(core_s=1e-3 * table["n"].astype(float) ** power)[["n", "seed", "core_s"]]


LINEAR_COST = ((30.0, 0.03), (30000.0, 30.0))  # a calibrated cost model of 1e-3 N s a run


def run_search(search, noise, base_seed=0):
    plan = initial_plan(search, base_seed)
    while not plan["done"].any():
        table = realisations_of(plan, noise)
        plan = next_plan(search, plan, table)
        assert (plan["last"] >= plan["first"]).all(), "an empty seed block"
    return plan


def grid(lo, hi, count, fd=False):
    """Search.grid of an N search over [lo, hi] (FD: even N)."""
    model = Case("fd", "implicit", None) if fd else Case("mtpt", "collision", None)
    return Search(name="g", model=model, time=1.0, lo=lo, hi=hi).grid(count)


def mtpt(**kw):
    return Search(name="t", model=Case("mtpt", "collision", None), time=1000.0, lo=30, hi=30000, **kw)


def fd(**kw):
    return Search(name="t", model=Case("fd", "implicit", None), time=250.0, lo=30, hi=30000, **kw)


def test_grid_is_geometric_with_both_ends_and_even_for_fd():
    assert grid(30, 30000, 4) == [30, 300, 3000, 30000]
    assert all(n % 2 == 0 for n in grid(31, 3001, 7, fd=True))
    assert grid(10, 12, 5) == [10, 11, 12]  # rounding merges points: each N once


def test_first_round_is_the_cheap_end_of_the_coarse_grid_with_the_first_seeds():
    plan = initial_plan(mtpt(initial_points=4, start_points=3, initial_realisations=3), base_seed=7)
    assert list(plan.columns) == PLAN_COLUMNS
    assert plan["n"].tolist() == [30, 300, 3000]  # 30,000 only if the minimum may lie there
    assert (plan["first"] == 7).all() and (plan["last"] == 9).all() and runs_in(plan) == 9


def test_fd_brackets_the_minimum_within_the_width_with_one_run_per_n():
    search = fd(width=1.5, budget_runs=40)
    plan = run_search(search, noise=0.0)
    assert plan["reason"].iloc[-1] == "bracket narrow enough"
    assert (plan["last"] == plan["first"]).all()  # deterministic: one run per N
    table = realisations_of(plan, 0.0)
    _, n_opt, lo, hi = _bracket(search, plan, table)
    assert lo <= N_STAR <= hi and hi / lo <= 1.5
    assert runs_in(plan) <= 40


def _bracket(search, plan, table):
    out = result_table(search, plan, table, costs_of(table))
    row = out.iloc[0]
    return out, int(row["optimum"]), int(row["bracket_lo"]), int(row["bracket_hi"])


@pytest.mark.parametrize("noise", [0.05, 0.3])
def test_noisy_search_brackets_the_true_minimum_within_budget(noise):
    search = mtpt(width=3.0, budget_runs=300)
    plan = run_search(search, noise)
    table = realisations_of(plan, noise)
    out, n_opt, lo, hi = _bracket(search, plan, table)
    assert lo <= N_STAR <= hi
    assert runs_in(plan) <= 300
    assert plan["reason"].iloc[-1] in REASONS
    if plan["reason"].iloc[-1] == "bracket narrow enough":
        assert hi / lo <= 3.0
    # refinement concentrates near the minimum: every N added after round 0 lies within a decade of it
    added = plan.loc[plan["round"] > 0, "n"]
    assert len(added) and (abs(np.log10(added / N_STAR)) <= 1.0).all()
    new_per_round = plan.groupby("n")["round"].min().value_counts()
    assert (new_per_round.drop(0, errors="ignore") <= 2).all()  # beside the lowest mean and the fit only
    assert list(out.columns) == RESULT_COLUMNS


def test_unresolved_neighbours_get_more_realisations():
    search = mtpt(width=1.2, budget_runs=1000, max_realisations=32)
    plan = run_search(search, noise=1.0)  # noise comparable to the curve near its minimum
    counts = plan.assign(r=plan["last"] - plan["first"] + 1).groupby("n")["r"].sum()
    assert counts.max() > search.initial_realisations  # some N were replicated
    assert counts.max() <= search.max_realisations
    # seeds of one N are consecutive blocks: base, base + 4, base + 8, ... never reused
    for _, g in plan.groupby("n"):
        g = g.sort_values("first")
        assert (g["first"].iloc[1:].to_numpy() == g["last"].iloc[:-1].to_numpy() + 1).all()


def test_a_small_budget_stops_the_search_and_is_never_exceeded():
    search = mtpt(width=1.2, budget_runs=30)
    plan = run_search(search, noise=0.3)
    assert plan["reason"].iloc[-1] == "budget spent"
    assert runs_in(plan) <= 30


def test_full_sweep_estimate_is_a_grid_giving_the_same_bracket():
    search = fd(width=1.5, budget_runs=40)
    plan = run_search(search, noise=0.0)
    table = realisations_of(plan, 0.0)
    out, _, lo, hi = _bracket(search, plan, table)
    step = math.sqrt(hi / lo)  # a grid of this step brackets its minimum as narrowly
    sweep = grid(30, 30000, math.ceil(math.log(1000) / math.log(step)) + 1, fd=True)
    # the cost per run is 1e-3 N exactly, so the interpolated estimate is exact
    assert out["full_sweep_core_s"].iloc[0] == pytest.approx(1e-3 * sum(sweep), rel=1e-9)
    assert out["core_s_spent"].iloc[0] < out["full_sweep_core_s"].iloc[0] / 3


@pytest.mark.parametrize(
    "spec,key",
    [
        ({"n_range": [100, 100]}, "n_range"),
        ({"n_range": [300, 30]}, "n_range"),
        ({"budget_runs": 10}, "budget_runs"),
        ({"time": 5000}, "time"),
        ({"width": 1.0}, "width"),
        ({"width": 1001.0}, "width"),  # wider than the range 30-30,000: round 0 would stop on any bracket
        ({"initial_points": 2}, "initial_points"),
        ({"initial_points": 4, "start_points": 5}, "start_points"),
        ({"budget_core_s": 0, "cost": [[30, 1]]}, "budget_core_s"),
        ({"budget_core_s": 60}, "cost"),  # a core-second budget needs a cost model
        ({"budget_core_s": 60, "cost": [[30, 1], [30, 2]]}, "cost"),
        ({"budget_core_s": 60, "cost": [[30, 0]]}, "cost[0][1]"),  # the item, as the workflow names it
        ({"budget_core_s": 60, "cost": [[0.5, 1]]}, "cost"),
        ({"case": {"method": "pt", "kernel": "sph"}}, "case.kernel"),
    ],
)
def test_bad_searches_are_refused_naming_the_key(spec, key):
    config = {"physics": {"t_final": 1000}}
    base = {"case": {"method": "mtpt", "kernel": "collision"}, "time": 1000, "n_range": [30, 30000], "budget_runs": 100}
    with pytest.raises(SettingError) as err:
        Search.from_config("s", {**base, **spec}, config)
    assert err.value.name == f"optimum.s.{key}"


def test_the_error_convention_can_move_the_optimum():
    """Mean of per-run COMIC (a mean of logs) against COMIC of the mean SSE (the log of a mean):
    rare large errors weigh little in the first and much in the second."""
    from particle_entropy.analysis.optimum import evaluate

    sse = {100: [1.0, 1.0, 1.0, 1.0], 300: [0.01, 0.01, 0.01, 10.0], 1000: [2.0, 2.0, 2.0, 2.0]}
    rows = [
        (n, s, v, 2 * math.log(v / 50.0) - math.log(0.1), 50, 0.1) for n, vs in sse.items() for s, v in enumerate(vs)
    ]
    table = pd.DataFrame(rows, columns=["n", "seed", "SSE", "COMIC", "n_sse", "dV"])
    _, by_comic = evaluate(mtpt(), table)
    _, by_sse = evaluate(mtpt(convention="COMIC_of_mean_SSE"), table)
    assert by_comic["best"] == 300 and by_sse["best"] == 100


def test_a_minimum_at_the_end_of_the_range_is_said_so():
    search = Search(name="t", model=Case("fd", "implicit", None), time=250.0, lo=30, hi=600, width=3.0, budget_runs=40)
    plan = run_search(search, noise=0.0)  # N_STAR = 1000 lies beyond the range
    assert plan["reason"].iloc[-1] == "minimum at an end of the range"


def test_fitted_minimum_recovers_the_vertex_of_a_quadratic_in_log_n():
    from particle_entropy.analysis.optimum import fitted_minimum

    u = np.log([100.0, 300.0, 1000.0, 3000.0, 10000.0])
    values = 2.0 * (u - math.log(1500.0)) ** 2  # vertex between grid points
    got = fitted_minimum(u, values, np.ones(5))
    assert math.exp(got[0]) == pytest.approx(1500.0, rel=1e-9)
    # the lowest point at an end of the grid: that end, no extrapolation
    assert fitted_minimum(u, -u, np.ones(5))[0] == u[-1]
    # several columns at once (the bootstrap's resamples), each with its own lowest point
    two = np.stack([values, 2.0 * (u - math.log(400.0)) ** 2], axis=1)
    assert np.exp(fitted_minimum(u, two, np.ones(5))) == pytest.approx([1500.0, 400.0], rel=1e-9)


def test_the_fit_beats_the_lowest_mean_on_noisy_curves():
    """Winner's curse: on a flat noisy minimum the visited N with the lowest mean is often a
    lucky neighbour; the weighted quadratic through its neighbours lands nearer the truth."""
    from particle_entropy.analysis.optimum import evaluate

    ns = [300, 450, 700, 1000, 1500, 2200, 3300]
    err_fit, err_best = [], []
    for rep in range(60):
        rows = [(n, s, comic(n, 1000 * rep + s, 0.8)) for n in ns for s in range(8)]
        _, opt = evaluate(mtpt(), pd.DataFrame(rows, columns=["n", "seed", "COMIC"]))
        err_fit.append(math.log(opt["optimum"] / N_STAR) ** 2)
        err_best.append(math.log(opt["best"] / N_STAR) ** 2)
    assert np.mean(err_fit) < 0.8 * np.mean(err_best)


def test_the_search_walks_up_only_as_far_as_the_minimum_needs():
    """The expensive end of the range is never run when the minimum lies well below it."""
    for search in (fd(width=1.5, budget_runs=40), mtpt(width=3.0, budget_runs=400)):
        plan = run_search(search, noise=0.0 if search.fd else 0.05)
        assert plan["n"].max() < 10_000  # N_STAR = 1000; the range goes to 30,000
        assert plan["n"].max() > N_STAR  # but far enough to see the curve turn up
        for k in range(1, int(plan["round"].max()) + 1):  # a round that walks does nothing else
            before, added = plan[plan["round"] < k], plan[plan["round"] == k]
            if added["n"].max() > before["n"].max():
                assert (added["n"] > before["n"].max()).all() and (added["first"] == 0).all()


def test_a_minimum_high_in_the_range_is_reached_by_walking():
    global N_STAR
    saved, N_STAR = N_STAR, 20_000.0
    try:
        plan = run_search(fd(width=1.5, budget_runs=40), noise=0.0)
        table = realisations_of(plan, 0.0)
        _, n_opt, lo, hi = _bracket(fd(width=1.5, budget_runs=40), plan, table)
        assert lo <= 20_000 <= hi
    finally:
        N_STAR = saved


def test_cost_model_is_exact_for_a_power_law_and_extrapolates_its_slope():
    from particle_entropy.analysis.optimum import cost_model

    costs = pd.DataFrame({"n": [100, 1000, 10000], "seed": 0, "core_s": [1e-3 * n**1.5 for n in (100, 1000, 10000)]})
    predict = cost_model(costs)
    for n in (30, 300, 5000, 50000):
        assert predict(n) == pytest.approx(1e-3 * n**1.5, rel=1e-9)
    single = cost_model(costs.iloc[:1])
    assert single(400) == pytest.approx(4 * single(100), rel=1e-12)  # one N: cost proportional to N


def test_a_core_seconds_budget_is_never_exceeded_and_stops_the_search():
    search = mtpt(width=1.2, budget_runs=10_000, budget_core_s=60.0, cost=LINEAR_COST)  # 1e-3 N s a run
    plan = run_search(search, noise=0.5)
    table = realisations_of(plan, 0.5)
    assert plan["reason"].iloc[-1] == "budget spent"
    assert costs_of(table)["core_s"].sum() <= 60.0
    out = result_table(search, plan, table, costs_of(table, power=2.0))  # measured: other timings
    assert out["cost_s_spent"].iloc[0] == pytest.approx(costs_of(table)["core_s"].sum(), rel=1e-9)
    assert out["cost_s"].sum() == pytest.approx(out["cost_s_spent"].iloc[0], rel=1e-9)
    assert out["core_s_spent"].iloc[0] == pytest.approx(costs_of(table, power=2.0)["core_s"].sum(), rel=1e-9)


def test_replication_goes_to_the_cheapest_unresolved_n_first():
    """Three N tie within their noise; the core-seconds left pay for one doubling: the cheapest."""
    ns = [100, 300, 1000, 3000, 10000]
    spread = [-2.0, -0.5, 0.5, 2.0]
    rows = [(n, s, (10.0 if n in (100, 10000) else 0.0) + d) for n in ns for s, d in enumerate(spread)]
    table = pd.DataFrame(rows, columns=["n", "seed", "COMIC"])
    plan = pd.DataFrame([(0, n, 1.05, 0, 3, False, "") for n in ns], columns=PLAN_COLUMNS)
    spent = 4 * 1e-3 * sum(ns)  # costs 1e-3 N s a run
    search = Search(
        name="t", model=Case("mtpt", "collision", None), time=1.0, lo=100, hi=10000,
        width=1.5, min_step=4.0, budget_core_s=spent + 1.5,  # no midpoints; 1.5 s pays 300's doubling only
        cost=LINEAR_COST,
    )  # fmt: skip
    out = next_plan(search, plan, table)
    added = out[out["round"] == 1]
    assert added[["n", "first", "last"]].values.tolist() == [[300, 4, 7]]
    roomy = next_plan(replace(search, budget_core_s=1e9), plan, table)
    assert sorted(roomy.loc[roomy["round"] == 1, "n"]) == [300, 1000, 3000]  # all three when affordable


def test_the_time_step_in_the_sampling_volume_shifts_every_n_alike():
    """Section 6, point 3: with dt in the sampling volume COMIC drops by ln(mean dt); every N of a
    model shares its time grid, so the curve shifts by a constant and the optimum stays put."""
    from particle_entropy.analysis.optimum import evaluate

    config = {"physics": {"t_final": 1000}, "time": {"dt0": 0.01, "fd_dt": 0.05, "fixed_dt": 1.0}}
    spec = {"case": {"method": "mtpt", "kernel": "collision", "dt_growth": 1.05}, "time": 1000, "n_range": [30, 30000]}
    plain = Search.from_config("s", {**spec, "budget_runs": 100}, config)
    with_dt = Search.from_config("s", {**spec, "budget_runs": 100, "time_volume": True}, config)
    rows = [(n, s, comic(n, s, 0.3), 1000.0, 10.0 / n, 1.05) for n in (100, 300, 1000, 3000, 10000) for s in range(6)]
    table = pd.DataFrame(rows, columns=["n", "seed", "COMIC", "time_step", "dV", "dt_growth"])
    a, opt_a = evaluate(plain, table)
    b, opt_b = evaluate(with_dt, table)
    steps = math.ceil(math.log(1 + 1000 * 0.05 / 0.01) / math.log(1.05))  # dt0 1.05^k summed to 1000
    assert steps == 175
    assert (b["COMIC_mean"] - a["COMIC_mean"]).to_numpy() == pytest.approx(-math.log(1000 / steps), abs=1e-12)
    assert opt_a == opt_b
    fd_spec = {"case": {"method": "fd", "kernel": "implicit"}, "time": 250, "n_range": [30, 3000], "budget_runs": 9}
    fd_search = Search.from_config("f", {**fd_spec, "initial_points": 5, "time_volume": True}, config)
    assert fd_search.steps["fd_dt"] == 0.05 and fd_search.time_volume


def test_the_common_measurement_points_replace_the_models_own():
    """measure: points judges SSE and COMIC at the 15 common points (columns SSE_points, COMIC_points)."""
    from particle_entropy.analysis.optimum import evaluate

    rows = [
        (n, s, comic(n, s, 0.1), comic(n * 10, s, 0.1), 1.0) for n in (100, 300, 1000, 3000, 10000) for s in range(6)
    ]  # the points' curve has its minimum at N_STAR / 10
    table = pd.DataFrame(rows, columns=["n", "seed", "COMIC", "COMIC_points", "SSE_points"])
    assert evaluate(mtpt(), table)[1]["best"] == 1000
    assert evaluate(mtpt(measure="points"), table)[1]["best"] == 100
    with pytest.raises(SettingError, match="measure"):
        mtpt(measure="nodes").check("optimum.s", 1000.0)


G_STAR = 1.03  # the synthetic growth curve's minimum


def growth_comic(g, seed, noise):
    rng = np.random.default_rng([int(round(g * 1e6)), int(seed)])
    return 2.0 * (math.log(g - 1.0) - math.log(G_STAR - 1.0)) ** 2 + noise * rng.standard_normal()


def test_a_search_over_the_dt_growth_finds_its_minimum():
    """over dt_growth: the same machinery on log(dt_growth - 1) at a fixed N, starting at the
    cheap end (large growth, few steps) and walking towards small growth only as needed."""
    config = {"physics": {"t_final": 1000}}
    spec = {
        "case": {"method": "mtpt", "kernel": "collision"},
        "n": 1000,
        "time": 1000,
        "growth_range": [1.001, 1.5],
        "budget_runs": 400,
        "width": 2.0,
    }
    search = Search.from_config("g", spec, config)
    assert search.over == "dt_growth" and search.model.n == 1000
    plan = initial_plan(search, 0)
    assert (plan["n"] == 1000).all() and plan["dt_growth"].min() > 1.05  # the cheap end first
    while not plan["done"].any():
        rows = [
            (1000, g, s, growth_comic(g, s, 0.05))
            for _, b in plan.iterrows()
            for g in [float(b["dt_growth"])]
            for s in range(b["first"], b["last"] + 1)
        ]
        table = pd.DataFrame(rows, columns=["n", "dt_growth", "seed", "COMIC"])
        costs = table.assign(core_s=1.0 / (table["dt_growth"] - 1.0))[["n", "dt_growth", "seed", "core_s"]]
        plan = next_plan(search, plan, table)
    out = result_table(search, plan, table, costs)
    row = out.iloc[0]
    assert row["bracket_lo"] <= G_STAR <= row["bracket_hi"]
    assert abs(math.log((row["optimum"] - 1) / (G_STAR - 1))) < math.log(1.5)
    assert plan["dt_growth"].min() > 1.005  # the most expensive end of the range was never run
    assert (out["n"] == 1000).all() and row["over"] == "dt_growth"


@pytest.mark.parametrize(
    "spec,key",
    [
        ({"growth_range": [1.0, 1.2]}, "growth_range[0]"),  # 1 = a fixed step
        ({"growth_range": [1.2, 1.1]}, "growth_range"),
        ({"growth_range": [1.01, 1.2], "n_range": [30, 300]}, "n_range"),
        ({"growth_range": [1.01, 1.2], "n": None}, "n"),
        ({"growth_range": [1.01, 1.2], "case": {"method": "fd", "kernel": "implicit"}}, "growth_range"),
    ],
)
def test_bad_growth_searches_are_refused_naming_the_key(spec, key):
    base = {"case": {"method": "mtpt", "kernel": "collision"}, "time": 1000, "n": 300, "budget_runs": 100}
    spec = {k: v for k, v in {**base, **spec}.items() if v is not None}
    with pytest.raises(SettingError) as err:
        Search.from_config("s", spec, {"physics": {"t_final": 1000}})
    assert err.value.name == f"optimum.s.{key}"


@pytest.mark.parametrize("measure,time_volume", [("own", False), ("points", True)])
def test_the_figure_names_the_options_it_was_judged_with(measure, time_volume):
    import matplotlib.pyplot as plt

    from particle_entropy.figures.optimum import optimum_figure

    search = fd(width=1.5, budget_runs=40)
    plan = run_search(search, noise=0.0)
    out = result_table(search, plan, realisations_of(plan, 0.0), costs_of(realisations_of(plan, 0.0)))
    fig = optimum_figure(out.assign(measure=measure, time_volume=time_volume))
    title = fig.axes[0].get_title(loc="left")
    plt.close(fig)
    assert ("15 common points" in title) == (measure == "points")
    assert ("dt in dV" in title) == time_volume
    assert "\n" in title  # two lines: a long search name does not push the judging settings off


def test_an_end_point_within_the_noise_is_replicated_not_walked_past():
    """The lowest mean at 95; 300 is within its noise. Walking to 949 would cost ~3x a doubling at
    300 and, on a flat curve, would walk to the range end: 300 gets more realisations instead."""
    spread = [-1.5, -0.5, 0.5, 1.5]
    level = {30: 5.0, 95: 0.0, 300: 0.3}
    rows = [(n, s, level[n] + d) for n in level for s, d in enumerate(spread)]
    table = pd.DataFrame(rows, columns=["n", "seed", "COMIC"])
    plan = pd.DataFrame([(0, n, 1.05, 0, 3, False, "") for n in level], columns=PLAN_COLUMNS)
    out = next_plan(mtpt(width=1.5, budget_runs=1000), plan, table)
    added = out[out["round"] == 1]
    assert added["n"].max() <= 300  # no walk beyond the visited N
    assert 300 in added.loc[added["first"] == 4, "n"].tolist()  # the end point is replicated
    # once doubled and still within the noise, the search walks on (a flat start must not stop it)
    eight = [(n, s, level[n] + spread[s % 4] * (1.0 if s < 4 else 0.9)) for n in level for s in range(8)]
    plan8 = pd.DataFrame(
        [(0, n, 1.05, 0, 3, False, "") for n in level] + [(1, 300, 1.05, 4, 7, False, "")], columns=PLAN_COLUMNS
    )
    table8 = pd.DataFrame([r for r in eight if r[0] == 300 or r[1] < 4], columns=table.columns)
    later = next_plan(mtpt(width=1.5, budget_runs=1000), plan8, table8)
    walked_to = later.loc[later["round"] == 2, "n"].tolist()
    assert len(walked_to) == 1 and 300 < walked_to[0] <= 949  # half a step: the fit turns up below 300
    # while the lowest mean itself sits at the end, the search does walk
    level[300] = -3.0
    rows = [(n, s, level[n] + d) for n in level for s, d in enumerate(spread)]
    walked = next_plan(mtpt(width=1.5, budget_runs=1000), plan, pd.DataFrame(rows, columns=table.columns))
    assert walked.loc[walked["round"] == 1, "n"].tolist() == [949]


def test_a_lucky_new_point_is_replicated_before_it_wins():
    """Winner's curse: a midpoint with 4 realisations beats neighbours with 16 by luck. The search
    does not stop on it (the bracket is narrow enough) but doubles it first."""
    spread = [-1.5, -0.5, 0.5, 1.5]
    level = {300: 0.0, 400: -1.0, 533: 0.2}  # 400 lowest, but within 2 combined s.e. of 300
    count = {300: 16, 400: 4, 533: 16}
    rows = [(n, s, level[n] + spread[s % 4]) for n in level for s in range(count[n])]
    table = pd.DataFrame(rows, columns=["n", "seed", "COMIC"])
    plan = pd.DataFrame(
        [(0, n, 1.05, 0, count[n] - 1, False, "") for n in level], columns=PLAN_COLUMNS
    )  # fmt: skip
    search = Search(name="t", model=Case("mtpt", "collision", None), time=1.0, lo=300, hi=533, width=10.0)
    out = next_plan(search, plan, table)
    assert not out["done"].any()
    added = out[out["round"] == 1]
    assert [400, 4, 7] in added[["n", "first", "last"]].values.tolist()
    # and its interval spans the rivals within noise, where the bootstrap alone trusts the lucky mean
    from particle_entropy.analysis.optimum import evaluate

    _, opt = evaluate(search, table)
    assert opt["best"] == 400 and opt["ci_lo"] == 300 and opt["ci_hi"] == 533


def test_a_coarse_grid_finer_than_the_stopping_width_is_refused():
    """optimum.*.initial_points had no upper bound: 1,000,000 points over 30-30,000 put round 0's
    three lowest points within 30-32, whose bracket is 'narrow enough' at once (the search reported
    64 where the optimum is ~600). Two coarse steps must span at least `width`: 1 + 2 ln(1000) /
    ln(10) = 7 points over 30-30,000 at width 10, the shipped default."""
    config = {"physics": {"t_final": 1000}, "time": {"dt0": 0.01, "fd_dt": 0.05, "fixed_dt": 1.0}}
    spec = {"case": {"method": "fd", "kernel": "implicit"}, "time": 250, "n_range": [30, 30000], "budget_runs": 50}
    assert Search.from_config("s", {**spec, "initial_points": 7}, config).max_initial_points == 7
    for points in (8, 50, 1_000_000):
        with pytest.raises(SettingError, match=r"optimum.s.initial_points=\d+ is not allowed: an integer in \[3, 7\]"):
            Search.from_config("s", {**spec, "initial_points": points}, config)
    wide = Search.from_config("s", {**spec, "initial_points": 13, "width": math.sqrt(10)}, config)
    assert wide.max_initial_points == 13  # a narrower stopping width allows a finer grid


_SPEC = {"case": {"method": "fd", "kernel": "implicit"}, "time": 250, "n_range": [30, 30000], "budget_runs": 50}


@pytest.mark.parametrize(
    "change, key",
    [
        ({"n_range": [30]}, "n_range"),
        ({"n_range": "abc"}, "n_range"),
        ({"n_range": [30.5, 300]}, "n_range[0]"),
        ({"time": None}, "time"),
        ({"time": "x"}, "time"),
        ({"case": None}, "case"),
        ({"case": "fd"}, "case"),
        ({"width": "w"}, "width"),
        ({"budget_runs": "a"}, "budget_runs"),
        ({"realisations": 0}, "realisations"),
        ({"initial_points": 4.5}, "initial_points"),
        ({"n_range": None, "growth_range": [1.1], "n": 300}, "growth_range"),
        ({"n_range": None, "growth_range": [1.01, 1.5], "n": "a"}, "n"),
        ({"cost": [[30]], "budget_core_s": 10}, "cost[0]"),
        ({"budget_core_s": "x"}, "budget_core_s"),
        ({"time_volume": "yes"}, "time_volume"),
        ({"budjet_runs": 3}, "budjet_runs"),
    ],
)
def test_every_bad_search_value_is_named_by_its_key_path(change, key):
    """Round 4: a search's messages named no key path where a value was missing or of the wrong type
    (KeyError 'time', 'not enough values to unpack', 'invalid literal for int()'): each is now a
    SettingError naming optimum.<name>.<key>, its value and what is allowed, whoever calls."""
    config = {"physics": {"t_final": 1000}, "time": {"dt0": 0.01, "fd_dt": 0.05, "fixed_dt": 1.0}}
    spec = {k: v for k, v in {**_SPEC, **change}.items() if v is not None}
    with pytest.raises(SettingError) as refused:
        Search.from_config("s", spec, config)
    assert refused.value.name == f"optimum.s.{key}"
    assert str(refused.value).startswith(f"optimum.s.{key}=") and "is not allowed: " in str(refused.value)


def test_a_search_whose_seeds_overflow_names_its_max_realisations():
    """Seeds run to base_seed + max_realisations - 1: the refusal names the search's key."""
    from particle_entropy.core.runconfig import MAX_SEED
    from particle_entropy.pipeline.crosschecks import check_search

    config = {
        "base_seed": MAX_SEED - 10,
        "physics": {"t_final": 1000, "D": 1e-3, "omega": 10.0, "fd_length": 12.0},
        "time": {"dt0": 0.01, "fd_dt": 0.05, "fixed_dt": 1.0},
        "optimum": {"s": {**_SPEC, "case": {"method": "mtpt", "kernel": "sph", "eta": 1}, "max_realisations": 64}},
    }
    with pytest.raises(SettingError) as refused:
        check_search("s", config)
    assert refused.value.name == "optimum.s.max_realisations" and refused.value.value == 64
    assert "an integer <= 11 with base_seed = " in refused.value.allowed


def test_a_search_takes_the_same_path_under_different_timings(tmp_path):
    """Issue 23: a core-second budget decided from measured wall times, so one config gave
    different optima on different machines. Real runs, written as run tables twice: as on a fast
    machine and as on one 1,000 times slower (wall_s scaled, with jitter). The search reads them
    as the workflow does (advance, result_table) and must take the same path to the same table;
    only the measured columns differ."""
    from particle_entropy.analysis.optimum import advance, read_runs
    from particle_entropy.core.io import write_parquet
    from particle_entropy.core.runconfig import RunConfig
    from particle_entropy.models.simulate import run_seeds_arrow
    from particle_entropy.pipeline.sweeps import run_settings

    config = {"physics": {"t_final": 20.0}, "time": {"dt0": 0.1, "fd_dt": 0.05, "fixed_dt": 1.0}}
    search = Search(
        name="t", model=Case("mtpt", "collision", None), time=20.0, lo=30, hi=3000,
        width=1.2, budget_core_s=3.0, cost=LINEAR_COST, max_realisations=16,
    )  # fmt: skip
    tables = {}

    def block(n, first, last):
        if (n, first, last) not in tables:
            case = search.model.at(int(n))
            cfg = RunConfig.for_case(case, **run_settings(case, config)).resolved()
            tables[n, first, last] = run_seeds_arrow(cfg, range(first, last + 1)).to_pandas()
        return tables[n, first, last]

    def machine(slowdown):
        rng, folder = np.random.default_rng(int(slowdown)), tmp_path / f"x{slowdown}"
        folder.mkdir()

        def paths(plan):
            out = []
            for r in plan.itertuples():
                path = folder / f"n{r.n}_{r.first}-{r.last}.parquet"
                if not path.exists():
                    t = block(r.n, int(r.first), int(r.last))
                    write_parquet(t.assign(wall_s=t["wall_s"] * slowdown * rng.uniform(0.5, 2.0, len(t))), str(path))
                out.append(str(path))
            return out

        plan = initial_plan(search, 0)
        while not plan["done"].any():
            plan = advance(search, plan, paths(plan))
        realisations, costs = read_runs(paths(plan), search.time)
        return plan, result_table(search, plan, realisations, costs)

    fast, slow = machine(1), machine(1000)
    pd.testing.assert_frame_equal(fast[0], slow[0])
    assert fast[0]["reason"].iloc[-1] == "budget spent" and fast[0]["round"].max() >= 2
    measured = ["core_s", "core_s_spent", "full_sweep_core_s"]
    pd.testing.assert_frame_equal(fast[1].drop(columns=measured), slow[1].drop(columns=measured))
    assert (slow[1]["core_s_spent"] > 100 * fast[1]["core_s_spent"]).all()  # the timings did differ
    assert fast[1]["cost_s_spent"].iloc[0] <= search.budget_core_s


def test_the_result_says_when_the_optimum_sits_at_a_visited_end():
    """A search stopped by its budget while walking up has its lowest mean at the highest visited
    N, not at the range's end: the table says so (at_end), and so does the figure's text."""
    import matplotlib.pyplot as plt

    from particle_entropy.figures.optimum import optimum_figure

    search = fd(width=1.5, budget_runs=4, start_points=3)  # walks up one step, then the budget is spent
    global N_STAR
    saved, N_STAR = N_STAR, 20000.0
    try:
        plan = run_search(search, noise=0.0)
        table = realisations_of(plan, 0.0)
    finally:
        N_STAR = saved
    out = result_table(search, plan, table, costs_of(table))
    assert plan["reason"].iloc[-1] == "budget spent"
    assert out["best"].iloc[0] == out["n"].max() < search.hi
    assert (out["at_end"] == "high").all()
    fig = optimum_figure(out)
    text = " ".join(t.get_text() for t in fig.texts)
    left, bottom, width, height = fig.get_layout_engine().get()["rect"]  # two lines below: the title still fits
    assert bottom >= 0.08 and bottom + height <= 1.0
    plt.close(fig)
    assert "lowest mean at the highest visited N: the minimum may lie above it" in text
    bracketed = fd(width=1.5, budget_runs=40)
    plan = run_search(bracketed, noise=0.0)
    table = realisations_of(plan, 0.0)
    assert (result_table(bracketed, plan, table, costs_of(table))["at_end"] == "").all()


def test_an_unscored_point_is_never_the_optimum_and_none_scored_is_said():
    """N = 30 with SSE = 0 (COMIC NaN in the realisations table, aggregate.UNSCORED) must not win:
    before, its -inf was the search's minimum."""
    from particle_entropy.analysis.optimum import evaluate

    plan = pd.DataFrame([(0, n, 1.05, 0, 3, False, "") for n in (30, 95, 300)], columns=PLAN_COLUMNS)
    table = realisations_of(plan, 0.1)
    table.loc[table["n"] == 30, "COMIC"] = np.nan
    table["COMIC_reason"] = np.where(table["n"] == 30, "SSE = 0: ...", "")
    _, opt = evaluate(mtpt(budget_runs=100), table)
    assert opt["best"] == 300
    table["COMIC"] = np.nan
    none = r"search t: no visited point scores a COMIC \(SSE = 0: ...\); try a later optimum.t.time \(now 1000\)"
    with pytest.raises(ValueError, match=none):
        evaluate(mtpt(budget_runs=100), table)


@pytest.mark.parametrize(
    "key, value",
    [
        ("case", "mtpt"),  # not a mapping
        ("n_range", [30.5, 300]),
        ("cost", [[30, 0]]),
        ("realisations", 0),
        ("budjet_runs", 3),
    ],
)
def test_a_search_and_the_workflow_refuse_a_value_in_the_same_words(key, value):
    """One check: Search.from_config parses a search as written by the model the workflow's config
    is made of (core/typed.py), so both name the same key and value, and say the same."""
    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import check_config, load_yaml

    config = dict(load_yaml(ROOT / "config.yaml"))
    name = next(iter(config["optimum"]))
    bad = {**config["optimum"][name], key: value}
    with pytest.raises(SettingError) as alone:
        Search.from_config(name, bad, config)
    with pytest.raises(SettingError) as workflow:
        check_config({**config, "optimum": {**config["optimum"], name: bad}})
    assert alone.value.name.startswith(f"optimum.{name}.{key}")
    assert str(alone.value) == str(workflow.value)
