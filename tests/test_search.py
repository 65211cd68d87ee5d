"""The adaptive-search engine (analysis/search.py): plans, seed blocks, rounds and what each round
reads, for its two kinds (the COMIC optimum, a scene's cheapest model) and a toy third kind; the
kinds' plans on fixed synthetic runs are those of the code before the engine (digests below)."""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pandas as pd
import pytest

from particle_entropy.analysis import scene_search as S
from particle_entropy.analysis import search as E
from particle_entropy.analysis.optimum import MAX_ROUNDS, PLAN_COLUMNS, REASONS, Search
from particle_entropy.core.case import Case
from particle_entropy.core.io import write_parquet
from particle_entropy.scenes.scene import Scene

MTPT = Case("mtpt", "collision", None)


def _digest(plan: pd.DataFrame) -> str:
    """A plan's content, column order and dtypes, hashed."""
    return hashlib.sha256((plan.to_csv(index=False) + str(list(plan.dtypes))).encode()).hexdigest()[:16]


def _comic(x, seed, noise, star, over):
    """A COMIC curve quadratic in the search's u (log N, log(dt_growth - 1)), minimum at ``star``, plus noise."""
    rng = np.random.default_rng([int(round(x * 1000)), int(seed)])
    u, s = (math.log(x - 1.0), math.log(star - 1.0)) if over == "dt_growth" else (math.log(x), math.log(star))
    return 2.0 * (u - s) ** 2 + noise * rng.standard_normal()


def _values(search: Search, plan: pd.DataFrame, noise: float, star: float) -> pd.DataFrame:
    rows = [
        (int(b.n), float(b.dt_growth), s, _comic(getattr(b, search.over), s, noise, star, search.over))
        for b in plan.itertuples()
        for s in range(int(b.first), int(b.last) + 1)
    ]
    return pd.DataFrame(rows, columns=["n", "dt_growth", "seed", "COMIC"])


def _optimum_plan(search: Search, noise: float, star: float, base_seed: int) -> tuple[pd.DataFrame, int]:
    """Every round of an optimum search through the engine's kind -> (final plan, plans written)."""
    plan, written = search.first_plan(base_seed), 1
    while not plan["done"].any():
        plan = search.next_plan(plan, _values(search, plan, noise, star), base_seed)
        written += 1
    return plan, written


def _mtpt(**kw) -> Search:
    return Search(name="t", model=MTPT, time=1000.0, lo=30, hi=30000, **kw)


# name: (search, noise, true optimum, base seed, its final plan's rows, last round, reason, digest of
# that plan as the code before the engine wrote it)
OPTIMUM = {
    "fd": (
        Search(name="t", model=Case("fd", "implicit", None), time=250.0, lo=30, hi=30000, width=1.5, budget_runs=40),
        *(0.0, 1000.0, 0, 11, 5, REASONS[0], "17d71640f1fadb78"),
    ),
    "noisy": (_mtpt(width=3.0, budget_runs=300), *(0.3, 1000.0, 5, 11, 4, REASONS[0], "1921015f35bcb78d")),
    "cost": (
        _mtpt(width=2.0, budget_core_s=200.0, cost=((30.0, 0.03), (30000.0, 30.0))),
        *(0.1, 1000.0, 0, 7, 3, REASONS[0], "78b1429b275f6bfd"),
    ),
    "edge": (_mtpt(width=1.5, budget_runs=2000), *(0.05, 25000.0, 0, 7, 4, REASONS[4], "9966e849e5002b7a")),
    "round_limit": (
        _mtpt(width=1.12, budget_runs=100000, max_realisations=512),
        *(2.0, 1000.0, 0, 82, MAX_ROUNDS, REASONS[3], "071bc82dc2255432"),
    ),
    "nothing_left": (
        _mtpt(width=1.15, budget_runs=100000, max_realisations=64),
        *(0.5, 1000.0, 0, 48, 13, REASONS[2], "5aeb3a7d3780e10f"),
    ),
    "budget": (_mtpt(width=1.2, budget_runs=25), *(0.3, 1000.0, 0, 6, 3, REASONS[1], "57198b71c39df379")),
    "growth": (
        Search(
            name="g",
            model=Case("mtpt", "collision", 60),
            time=20.0,
            lo=1.01,
            hi=1.6,
            over="dt_growth",
            width=3.0,
            budget_runs=200,
            initial_realisations=2,
            max_realisations=12,
        ),
        *(0.1, 1.1, 0, 5, 2, REASONS[0], "4105213070cd84ca"),
    ),
}


@pytest.mark.parametrize("name", OPTIMUM)
def test_optimum_plans_are_those_of_the_code_before_the_engine(name):
    search, noise, star, seed, rows, last, reason, digest = OPTIMUM[name]
    plan, written = _optimum_plan(search, noise, star, seed)
    assert (len(plan), int(plan["round"].max()), plan["reason"].iloc[-1]) == (rows, last, reason)
    assert list(plan.columns) == PLAN_COLUMNS and plan["done"].all()
    assert written <= search.max_plans  # final_inputs looks far enough
    assert _digest(plan) == digest


def test_the_round_limit_stops_a_search_after_max_rounds():
    search = OPTIMUM["round_limit"][0]
    plan = search.first_plan(0)
    plan["round"] = MAX_ROUNDS  # a plan of round MAX_ROUNDS: the next round would be past the limit
    out = search.next_plan(plan, _values(search, plan, 2.0, 1000.0), 0)
    assert out["done"].all() and (out["reason"] == "round limit").all()
    assert out.drop(columns=["done", "reason"]).equals(plan.drop(columns=["done", "reason"]))  # nothing added
    assert search.max_plans == MAX_ROUNDS + 2


def _law(ci, n, seed):
    rng = np.random.default_rng([int(ci), int(n), int(seed)])
    return 2.0 / n ** (0.5 if ci == 1 else 1.0) * (1.0 + (0.3 if ci == 1 else 0.0) * rng.standard_normal() ** 2)


def _scene_runs(plan: pd.DataFrame) -> pd.DataFrame:
    """The runs of a scene's plan as read_runs gives them: a row per seed (a half step's error: the same law)."""
    rows = []
    for r in plan.itertuples():
        for seed in range(int(r.first), int(r.last) + 1):
            e = _law(r.candidate, r.n, seed)
            rows.append(
                {
                    **{"candidate": r.candidate, "n": r.n, "half_step": r.half_step, "seed": seed},
                    "SSE_points": 15 * e * e,
                    **{"COMIC_points": math.log(e), "H_C": 0.0, "H_C_analytic": 0.0, "E": 1.0, "E_analytic": 1.0},
                    **{"mass_min": 0.0, "negative_step": -1, "negative_t": math.nan, "negative_dt": math.nan},
                    **{"mass_total": 1.0, "dV": 0.1, "work": 100.0 * r.n, "steps": 100.0, "core_s": 0.01},
                }
            )
    return pd.DataFrame(rows)


def _scene(value: float) -> Scene:
    candidates = [
        {"method": "fd", "kernel": "implicit", "n_range": [16, 4096]},
        {"method": "mtpt", "kernel": "collision", "n_range": [32, 8192]},
    ]
    return Scene.from_config("s", {"v": 0.01, "t_final": 50.0, "target": {"value": value}, "candidates": candidates})


@pytest.mark.parametrize(
    "value, seed, rows, last, digest",
    [(0.01, 0, 14, 5, "97aa8e6fc5beaff3"), (0.002, 3, 16, 5, "247692b46caea620"), (0.03, 0, 18, 7, "6add29fd08eccf64")],
)
def test_scene_plans_are_those_of_the_code_before_the_engine(value, seed, rows, last, digest):
    """The plan's own rungs are the frozen plan of the code before the engine; the answer's check at half
    its step (added since) is one more row per answer, the answer's rung on its own seed blocks."""
    search = S.SceneSearch(_scene(value))
    plan, written = search.first_plan(seed), 1
    while not plan["done"].all():
        assert written < search.max_plans, "the search did not stop within max_plans"
        previous = plan
        plan = search.next_plan(plan, _scene_runs(plan), seed)
        written += 1
        # a plan continues the one before: its rows first, unchanged, then the new round's
        assert plan.iloc[: len(previous)].drop(columns="done").equals(previous.drop(columns="done"))
        assert (plan.iloc[len(previous) :]["round"] == E.next_round(previous)).all()
    own, checks = plan[~plan["half_step"]], plan[plan["half_step"]]
    frozen = own.drop(columns="half_step")
    assert (len(frozen), int(frozen["round"].max()), _digest(frozen)) == (rows, last, digest)
    table = S.judged(search.scene, _scene_runs(own))
    for ci, cand in enumerate(search.scene.candidates):
        passing = table[(table["candidate"] == ci) & table["meets"]]
        mine = checks[checks["candidate"] == ci]
        if passing.empty:
            assert mine.empty
            continue
        answer = own[(own["candidate"] == ci) & (own["n"] == passing["n"].min())]
        assert mine[["n", "first", "last"]].values.tolist() == answer[["n", "first", "last"]].values.tolist()
        assert (mine["label"] == search.scene.half_step(cand).label).all()
    assert len(checks) >= 1
    assert written <= search.max_plans == S.max_rounds(search.scene)
    assert list(plan.columns) == S.PLAN_COLUMNS


def test_a_scene_search_refuses_runs_that_would_make_it_repeat_itself():
    """Runs that hide which are half-step checks would replan the same check every round: refused."""
    search = S.SceneSearch(_scene(0.01))
    plan = search.first_plan(0)
    while not plan["half_step"].any():
        plan = search.next_plan(plan, _scene_runs(plan), 0)
    with pytest.raises(ValueError, match="'half_step' column"):
        search.next_plan(plan, _scene_runs(plan).drop(columns="half_step"), 0)
    hidden = _scene_runs(plan).assign(half_step=False)  # the checks read as the rung's own runs
    with pytest.raises(RuntimeError, match=r"would run fd implicit upwind dt=0.025 at n = 256 on seeds 0-0 again"):
        search.next_plan(plan, hidden, 0)


def test_seed_blocks_follow_the_runs_a_point_has():
    assert E.seed_block(7, 0, 3) == (7, 9) and E.seed_block(7, 3, 3) == (10, 12) and E.seed_block(0, 4, 4) == (4, 7)
    with pytest.raises(ValueError):
        E.seed_block(0, 0, 0)
    scene = _scene(0.01)
    fd, mtpt = scene.candidates
    assert S.seeds(scene, fd, 5) == (5, 5)  # FD: one run
    count = scene.realisations
    assert S.seeds(scene, mtpt, 5, block=2) == (5 + 2 * count, 5 + 3 * count - 1)


def test_plan_columns_hold_the_engines_once():
    assert E.check_plan_columns(["x", "round", "first", "last", "done"]) == ["x", "round", "first", "last", "done"]
    for bad in (["round", "first", "last"], ["round", "first", "last", "done", "first"]):
        with pytest.raises(ValueError, match="each of round, first, last, done once"):
            E.check_plan_columns(bad)


class _Halving(E.AdaptiveSearch):
    """A toy third kind: one point a round, halving N until a run's value is below 1 (runs: N / 100)."""

    title, max_plans = "toy search", 5
    columns = E.check_plan_columns(["round", "n", "first", "last", "done"])

    def first_plan(self, base_seed):
        return E.new_plan([(0, 400, *E.seed_block(base_seed, 0, 2), False)], self.columns)

    def next_plan(self, plan, runs, base_seed):
        if runs[-1] < 1.0:
            return E.stopped(plan)
        n = int(plan["n"].iloc[-1]) // 2
        return E.extended(plan, [(E.next_round(plan), n, *E.seed_block(base_seed, 0, 2), False)], self.columns)

    def read_runs(self, plan, paths):
        return [float(pd.read_parquet(p)["value"].iloc[0]) for p in paths]


def test_a_third_kind_needs_only_its_rule_and_the_engine_runs_its_rounds(tmp_path):
    toy = _Halving()

    def plan_paths(plan):  # the run table of each row; made here as a simulation job would
        paths = []
        for r in plan.itertuples():
            path = tmp_path / f"runs/n{r.n}-{r.first}-{r.last}.parquet"
            if not path.exists():
                path.parent.mkdir(exist_ok=True)
                write_parquet(pd.DataFrame({"value": [r.n / 100.0]}), path)
            paths.append(str(path))
        return paths

    def plan_at(k):
        return str(tmp_path / f"round~{k}.parquet")

    assert toy.round_inputs(0, plan_at, plan_paths) == {}
    plan, k = toy.round(None, [], 3), 0
    write_parquet(plan, plan_at(0))
    while not plan["done"].any():
        k += 1
        inputs = toy.round_inputs(k, plan_at, plan_paths)
        assert inputs["plan"] == plan_at(k - 1) and len(inputs["runs"]) == len(plan)
        plan = toy.round(pd.read_parquet(inputs["plan"]), inputs["runs"], 3)
        write_parquet(plan, plan_at(k))
    assert plan["n"].tolist() == [400, 200, 100, 50] and k == 4 and (plan["first"] == 3).all()
    assert E.runs_in(plan) == 8
    with pytest.raises(ValueError, match="toy search stopped at round 4: there is no round 5"):
        toy.round_inputs(5, plan_at, plan_paths)
    final = toy.final_inputs(plan_at, plan_paths)
    assert final["plan"] == plan_at(4) and len(final["runs"]) == 4
    toy.max_plans = 4  # the finished plan is round 4: past the most plans the kind writes
    with pytest.raises(ValueError, match="toy search: no finished plan after 4 rounds"):
        toy.final_inputs(plan_at, plan_paths)


def test_the_searches_code_hashes_include_the_engine():
    from particle_entropy.pipeline.codeversion import closure

    for entry in ("analysis.optimum", "analysis.scene_search"):
        assert "analysis.search" in closure([entry])


def test_a_runs_measured_core_seconds_are_its_steps_wall_times_summed():
    steps = pd.DataFrame({"n": [10, 10, 10, 20], "seed": [0, 0, 1, 0], "wall_s": [0.5, 0.25, 1.0, 2.0]})
    out = E.measured_core_s(steps, ["n", "seed"])
    assert out.to_dict("records") == [
        {"n": 10, "seed": 0, "core_s": 0.75},
        {"n": 10, "seed": 1, "core_s": 1.0},
        {"n": 20, "seed": 0, "core_s": 2.0},
    ]
    assert list(E.measured_core_s(steps.iloc[:0], ["seed"]).columns) == ["seed", "core_s"]


def _run_table(r, seeds) -> pd.DataFrame:
    """A per-step run table of plan row ``r`` (three steps a seed) whose last step's error is _law's."""
    rows = []
    for seed in seeds:
        e = _law(r.candidate, r.n, seed)
        for step in (1, 2, 3):
            rows.append(
                {
                    **{"seed": seed, "step": step, "time": 0.5 * step, "dt": 0.5, "mass_min": 0.0, "wall_s": 0.002},
                    **{"SSE_points": 15 * e * e * (4 - step), "COMIC_points": math.log(e), "H_C": 0.1, "E": 1.5},
                    **{"H_C_analytic": 0.1, "E_analytic": 1.5, "mass_total": 1.0, "dV": 0.1, "work": 10.0 * r.n},
                }
            )
    return pd.DataFrame(rows)


def test_a_round_reads_only_the_runs_its_last_round_added_and_gets_what_a_full_read_gets(tmp_path):
    """A scene's round k reads what round k-1 read (its table, written and read back as the workflow
    does) and only the run tables of the rows round k-1 added: the table equals reading every run
    again, and the older run tables are not opened (they are moved away before the round reads)."""
    from particle_entropy.core.io import read_parquet

    search = S.SceneSearch(_scene(0.01))
    assert search.KEEPS_READS
    plan, earlier, rounds = search.first_plan(0), None, 0
    while not plan["done"].all():
        paths = []
        for i, r in enumerate(plan.itertuples()):
            path = tmp_path / f"row{i}.parquet"
            if not path.exists():
                write_parquet(_run_table(r, range(int(r.first), int(r.last) + 1)), path)
            paths.append(str(path))
        full = search.read_runs(plan, paths)
        hidden = tmp_path / "hidden"
        hidden.mkdir(exist_ok=True)
        old = [p for p, k in zip(paths, plan["round"]) if k < plan["round"].max()]
        for p in old:
            (tmp_path / p).rename(hidden / (tmp_path / p).name)
        got = search.runs_since(plan, paths, earlier)
        for p in old:
            (hidden / (tmp_path / p).name).rename(p)
        pd.testing.assert_frame_equal(got, full)
        if earlier is not None:
            assert len(earlier) < len(got)
        write_parquet(got, tmp_path / "read.parquet")
        earlier = read_parquet(tmp_path / "read.parquet")
        plan = search.next_plan(plan, got, 0)
        rounds += 1
    assert rounds >= 4


def test_the_round_s_read_table_lies_beside_its_plan():
    from particle_entropy.analysis.rounds import read_path

    assert read_path("results/scenes/a/round~3.parquet") == "results/scenes/a/round~3.read.parquet"
    with pytest.raises(ValueError, match="ends in .parquet"):
        read_path("results/scenes/a/round~3")
