"""The cheapest-model search of a scene (analysis/scene_search.py) on synthetic runs whose errors are
known: the path, the answer, the confidence bound and the recommendation."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from particle_entropy.analysis import scene_search as S
from particle_entropy.experiments.scene import Scene

FD = {"method": "fd", "kernel": "implicit", "n_range": [16, 4096]}
MTPT = {"method": "mtpt", "kernel": "collision", "n_range": [32, 8192]}


def _scene(value=0.01, candidates=(FD, MTPT)):
    return Scene.from_config(
        "s", {"v": 0.01, "t_final": 50.0, "target": {"value": value}, "candidates": list(candidates)}
    )


def _runs(plan: pd.DataFrame, law, negative=lambda ci, n: False) -> pd.DataFrame:
    """The runs a plan would make, each with RMSE law(candidate, n, seed) (SSE_points = 15 rmse^2)."""
    rows = []
    for r in plan.itertuples():
        for seed in range(int(r.first), int(r.last) + 1):
            e = law(r.candidate, r.n, seed)
            rows.append(
                {
                    "candidate": r.candidate,
                    "n": r.n,
                    "seed": seed,
                    "SSE_points": 15 * e * e,
                    "COMIC_points": math.log(e),
                    "H_C": 0.0,
                    "H_C_analytic": 0.0,
                    "E": 1.0,
                    "E_analytic": 1.0,
                    "mass_min": -0.1 if negative(r.candidate, r.n) else 0.0,
                    "negative_step": 3 if negative(r.candidate, r.n) else -1,
                    "negative_t": 3.0 if negative(r.candidate, r.n) else math.nan,
                    "negative_dt": 1.0 if negative(r.candidate, r.n) else math.nan,
                    "mass_total": 1.0,
                    "dV": 0.1,
                    "work": 100.0 * r.n,
                    "steps": 100.0,
                    "core_s": 0.01,
                }
            )
    return pd.DataFrame(rows)


def _search(scene, law, negative=lambda ci, n: False):
    """Every round until done -> (final plan, judged table, rounds)."""
    plan = S.next_plan(scene, None, None, base_seed=0)
    rounds = 1
    while not plan["done"].all():
        plan = S.next_plan(scene, plan, _runs(plan, law, negative), base_seed=0)
        rounds += 1
        assert rounds < 50
    return plan, S.judged(scene, _runs(plan, law, negative)), rounds


def test_the_search_finds_the_smallest_passing_rung_without_visiting_the_ladder():
    scene = _scene(value=0.01)
    law = lambda ci, n, seed: 1.0 / n  # noqa: E731  deterministic: passes from n >= 100
    plan, table, rounds = _search(scene, law)
    for ci, cand in enumerate(scene.candidates):
        ladder = cand.ladder()
        answer = min(n for n in ladder if 1.0 / n <= 0.01)
        mine = table[(table["candidate"] == ci) & table["meets"]]["n"].min()
        assert mine == answer
        below = max(n for n in ladder if n < answer)
        assert below in set(table[table["candidate"] == ci]["n"])  # bracketed by the rung below
        assert len(table[table["candidate"] == ci]) < len(ladder)  # not a sweep
    assert rounds <= 6


def test_the_path_depends_on_the_errors_only():
    scene = _scene(value=0.01)
    law = lambda ci, n, seed: 1.0 / n * (1 + 0.05 * math.sin(seed + n))  # noqa: E731
    a = _search(scene, law)[0]
    b = _search(scene, law)[0]
    assert a.equals(b)


def test_the_upper_bound_is_students_one_sided_95_percent():
    errors = np.array([1.0, 2.0, 3.0])  # mean 2, sd 1, t_0.95 with 2 degrees of freedom = 2.919986 (tables)
    assert S.upper_bound(errors) == pytest.approx(2.0 + 2.919986 / math.sqrt(3), rel=1e-6)
    assert S.upper_bound(np.array([0.5])) == 0.5  # FD: one deterministic run


def test_noise_keeps_a_rung_from_passing_until_its_bound_does():
    """Mean error below the target but the 95 % bound above it: not met."""
    scene = _scene(value=0.01, candidates=(MTPT,))
    noisy = lambda ci, n, seed: 0.009 + (0.004 if seed % 2 else -0.004) if n < 1000 else 0.001  # noqa: E731
    _, table, _ = _search(scene, noisy)
    low = table[table["n"] < 1000]
    assert (low["error_mean"] < 0.01).all() and not low["meets"].any()
    assert table[table["meets"]]["n"].min() >= 1000


def test_the_recommendation_is_the_cheapest_first_passing_rung_and_unscored_runs_never_win():
    scene = _scene(value=0.01)
    law = lambda ci, n, seed: 1.0 / n  # noqa: E731
    negative = lambda ci, n: ci == 0  # noqa: E731  every FD run has negative concentrations
    _, table, _ = _search(scene, law, negative)
    out = S.result(scene, table)
    assert out["recommended"].sum() == 1
    best = out[out["recommended"]].iloc[0]
    assert best["method"] == "mtpt"
    assert (out[out["candidate"] == 0]["unscored"].str.startswith("negative concentrations from step 3")).all()
    assert not out[out["candidate"] == 0]["meets"].any()
    assert out[out["comic_best"]].iloc[0]["method"] == "mtpt"
    assert out.loc[out["candidate"] == 0, "stopped"].iloc[0] == "not met within n_range"


def test_the_cheaper_candidate_is_recommended_by_counted_cost():
    scene = _scene(value=0.01)
    law = lambda ci, n, seed: 1.0 / n  # noqa: E731
    _, table, _ = _search(scene, law)
    out = S.result(scene, table)
    firsts = out[out["meets"]].sort_values("n").groupby("candidate").head(1)
    cheapest = firsts.loc[firsts["cost_s"].idxmin()]
    assert out[out["recommended"]].index.tolist() == [cheapest.name]
    fd = scene.cost_s("fd", 100.0, 100.0 * 100)
    assert fd == pytest.approx(3.85e-5 * 100 + 1.72e-8 * 1e4)  # the shipped cost model: a step, a unit of work


def test_nothing_recommended_when_no_candidate_meets_the_target():
    scene = _scene(value=1e-9)
    _, table, _ = _search(scene, lambda ci, n, seed: 1.0 / n)
    out = S.result(scene, table)
    assert not out["recommended"].any()
    assert set(out["stopped"]) == {"not met within n_range"}
    assert out.groupby("candidate")["n"].max().tolist() == [c.n_hi for c in scene.candidates]


def _answer(scene: str, peclet: float, fd_cost: float | None, particle_cost: float | None) -> pd.DataFrame:
    """A scene table holding one FD and one PT candidate, each meeting at n = 200 (below it 100) or never."""
    rows = []
    for ci, (method, label, cost) in enumerate(
        [("fd", "fd implicit upwind dt=1", fd_cost), ("pt", "pt adaptive", particle_cost)]
    ):
        for n, meets in ((100, False), (200, cost is not None)):
            rows.append(
                {
                    "scene": scene,
                    "peclet": peclet,
                    "candidate": ci,
                    "method": method,
                    "label": label,
                    "n": n,
                    "meets": meets,
                    "cost_s": (cost or 1.0) * n / 200,
                    "n_below": 100.0 if n == 200 else np.nan,
                }
            )
    return pd.DataFrame(rows)


def test_the_peclet_table_and_its_crossover():
    tables = [
        _answer("peclet_0", 0.0, 0.01, 0.5),
        _answer("peclet_1", 50.0, 0.1, 0.4),
        _answer("peclet_2", 500.0, 1.0, 0.3),  # particles cheaper from here
        _answer("peclet_3", 5000.0, None, 0.3),  # the grid never meets it
    ]
    table = S.peclet_table(tables)
    grid = table[table["family"] == S.FAMILIES["fd"]].set_index("peclet")
    assert (
        grid.loc[0.0, "cost_s"] == 0.01 and grid.loc[0.0, "cost_lo"] == 0.005 and np.isnan(grid.loc[5000.0, "cost_s"])
    )
    assert table.drop_duplicates("peclet")["particles_cheaper"].tolist() == [False, False, True, True]
    assert S.crossover(table) == (50.0, 500.0)
    assert S.crossover(S.peclet_table(tables[:2])) is None  # the grid wins throughout


def test_the_counted_cost_of_a_run_is_known_before_it_runs():
    """Scene.run_cost from the time grid alone equals the cost counted from the run's own table
    (steps, particle- or node-steps) for PT and FD, which have no substeps."""
    from particle_entropy.models.simulate import run_seeds_arrow

    scene = _scene(
        candidates=(
            {"method": "fd", "kernel": "implicit", "fd_dt": 1.0, "n_range": [16, 64]},
            {"method": "pt", "kernel": "adaptive", "n_range": [30, 300]},
        )
    )
    for cand, n in zip(scene.candidates, (16, 30)):
        table = run_seeds_arrow(scene.run_config(cand, n), [0]).to_pandas()
        last = table.loc[table["step"].idxmax()]
        counted = scene.cost_s(cand.case.method, float(last["step"]), float(last["work"]))
        assert scene.run_cost(cand, n) == pytest.approx(counted, rel=1e-12)
        size = n + 1 if cand.case.method == "fd" else n
        assert last["work"] == last["step"] * size


def test_a_budget_stops_the_climb_and_says_so():
    scene = _scene(value=1e-9)  # never met
    dear = scene.candidates[1]
    ladder = dear.ladder()
    budget = scene.run_cost(dear, ladder[3]) * 1.0001  # rungs 0..3 of MTPT are affordable
    capped = Scene.from_config(
        "s", {"v": 0.01, "t_final": 50.0, "budget": budget, "target": {"value": 1e-9}, "candidates": [FD, MTPT]}
    )
    assert S.affordable(capped, capped.candidates[1]) == ladder[:4]
    plan, table, _ = _search(capped, lambda ci, n, seed: 1.0 / n)
    mtpt = table[table["candidate"] == 1]
    assert mtpt["n"].max() == ladder[3] and mtpt["cost_s"].max() <= budget
    reasons = S.stop_reasons(capped, table)
    assert reasons[1] == f"not met within the budget (n <= {ladder[3]:,})"
    out = S.result(capped, table)
    assert (out["budget"] == budget).all() and not out["recommended"].any()
    # a budget below the cheapest rung: nothing run, and the reason names the rung's cost
    tiny = Scene.from_config(
        "s", {"v": 0.01, "t_final": 50.0, "budget": 1e-9, "target": {"value": 0.1}, "candidates": [MTPT]}
    )
    assert S.next_plan(tiny, None, None, 0)["done"].all()
    nothing = pd.DataFrame({"candidate": [], "n": [], "meets": []})
    assert S.stop_reasons(tiny, nothing)[0].startswith("over budget: n = 32 costs")


def test_the_result_columns_are_the_documented_ones():
    scene = _scene(value=0.01)
    _, table, _ = _search(scene, lambda ci, n, seed: 1.0 / n)
    assert list(S.result(scene, table).columns) == list(S.RESULT_COLUMN_DOCS)


def test_a_budget_below_every_first_rung_answers_over_budget():
    """Issue 39, point 13: the table of a scene that ran nothing was a KeyError; docs/scenes.md
    promises each candidate's "over budget"."""
    tiny = Scene.from_config(
        "s", {"v": 0.01, "t_final": 50.0, "budget": 1e-9, "target": {"value": 0.1}, "candidates": [FD, MTPT]}
    )
    plan = S.next_plan(tiny, None, None, 0)
    assert plan["done"].all() and plan.empty
    out = S.result(tiny, S.judged(tiny, S.read_runs(plan, [])))
    assert list(out.columns) == list(S.RESULT_COLUMN_DOCS)
    assert out["candidate"].tolist() == [0, 1] and (out["realisations"] == 0).all()
    assert out["stopped"].str.startswith("over budget: n = ").all()
    assert not out["meets"].any() and not out["recommended"].any() and not out["comic_best"].any()
    assert out["cost_s"].tolist() == [tiny.run_cost(c, c.ladder()[0]) for c in tiny.candidates]
    from particle_entropy.figures.scene import scene as draw

    draw(out)  # the figure says so rather than failing


def test_the_round_cap_follows_the_longest_ladder():
    """Issue 39, point 13: a written-out ladder of 101 rungs, never met, stopped on "no finished plan
    after 41 rounds"; the cap is the rounds its search can take."""
    pt = {"method": "pt", "kernel": "adaptive", "ladder": list(range(30, 131))}  # 101 rungs

    def rounds(scene, law):
        plan, k = S.next_plan(scene, None, None, 0), 1
        while not plan["done"].all():
            plan = S.next_plan(scene, plan, _runs(plan, law), 0)
            k += 1
            assert k <= S.max_rounds(scene)
        return k

    never = _scene(value=1e-9, candidates=(FD, pt))
    assert 41 < rounds(never, lambda ci, n, seed: 1.0 / n) == S.max_rounds(never) - 1  # the climb and the stop
    at_top = _scene(value=0.5, candidates=(pt,))  # met at the top rung only: one bisection round more
    assert rounds(at_top, lambda ci, n, seed: 0.1 if n == 130 else 1.0) == S.max_rounds(at_top)


def test_at_rest_twin_candidates_run_once_and_keep_their_index():
    """Issue 39, point 9b: at v = 0, FD upwind and central are one model; the second runs nothing, and
    its rows are the first's under its own index, saying so."""
    fd_central = {**FD, "advection": "central"}
    scene = Scene.from_config(
        "s", {"v": 0.0, "t_final": 50.0, "target": {"value": 0.01}, "candidates": [FD, fd_central, MTPT]}
    )
    plan, table, _ = _search(scene, lambda ci, n, seed: 1.0 / n)
    assert set(plan["candidate"]) == {0, 2}  # the twin plans no run of its own
    out = S.result(scene, table)
    assert sorted(set(out["candidate"])) == [0, 1, 2]
    first, twin = out[out["candidate"] == 0], out[out["candidate"] == 1]
    assert twin["n"].tolist() == first["n"].tolist()
    assert twin["error_mean"].tolist() == first["error_mean"].tolist()
    assert (twin["stopped"] == "the same runs as candidates[0]: at v = 0 advection moves nothing").all()
    assert out["recommended"].sum() == 1 and out.loc[out["recommended"], "candidate"].iloc[0] != 1
    assert (out[out["candidate"] == 2]["method"] == "mtpt").all()


def test_a_run_negative_mid_way_is_unscored_though_it_ends_positive(tmp_path):
    """FD central at grid Peclet 2.75 (v 0.03, D 1e-4, n 512 on the Peclet sweep's window) goes
    negative at its first step (-0.030 of the mass) and has smoothed it out by t_final (-3e-38): the
    last step alone would score it. Caught at every step, it is unscored, naming the first step, the
    minimum, the grid Peclet and Courant numbers."""
    from particle_entropy.core.io import write_parquet
    from particle_entropy.models.simulate import run

    central = {"method": "fd", "kernel": "implicit", "advection": "central", "fd_dt": 1.0, "n_range": [64, 65536]}
    spec = {"D": 1e-4, "v": 0.03, "t_final": 100.0, "target": {"value": 0.05}, "candidates": [central]}
    scene = Scene.from_config("s", spec)
    cfg = scene.run_config(scene.candidates[0], 512)
    table, _ = run(cfg)
    assert table["mass_min"].iloc[-1] > -S.NEGATIVE_TOLERANCE  # t_final alone looks clean
    path = tmp_path / "runs.parquet"
    write_parquet(table, path)
    plan = pd.DataFrame([{"candidate": 0, "label": "", "n": 512, "first": 0, "last": 0, "round": 0}])
    runs = S.read_runs(plan, [str(path)])
    row = runs.iloc[0]
    assert row["negative_step"] == 1 and row["negative_t"] == 1.0 and row["mass_min"] < -0.01
    judged = S.judged(scene, runs).iloc[0]
    assert not judged["meets"]
    dx = cfg.fd_span()[1] / 512
    assert judged["unscored"] == (
        f"negative concentrations from step 1 (t = 1): minimum {row['mass_min']:.3g} of the total; "
        f"grid Peclet {0.03 * dx / 1e-4:.3g} > 2, Courant {0.03 * 1.0 / dx:.3g}"
    )


def test_a_run_that_never_goes_negative_has_no_negative_step():
    table = pd.DataFrame(
        {"step": [0, 1, 2], "time": [0.0, 1.0, 2.0], "dt": [0.0, 1.0, 1.0], "mass_min": [0.0, -1e-13, 0.0]}
    ).assign(mass_total=1.0)
    assert S.negative_steps(table) == (
        -1,
        pytest.approx(math.nan, nan_ok=True),
        pytest.approx(math.nan, nan_ok=True),
        -1e-13,
    )
    table.loc[2, "mass_min"] = -2e-12
    assert S.negative_steps(table)[:3] == (2, 2.0, 1.0)
