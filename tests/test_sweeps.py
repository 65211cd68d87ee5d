"""Expanding the config into ensembles, seed blocks, run paths and run settings (sweeps.py), and the
pre-flight checks of check_sweeps, on the shipped config, the tiny test config and small dicts."""

from __future__ import annotations

import copy

import pytest
import yaml
from conftest import ROOT

from particle_entropy.core.case import Case, SettingError
from particle_entropy.pipeline.config import build
from particle_entropy.pipeline.configcheck import parse
from particle_entropy.pipeline.crosschecks import check_sweeps
from particle_entropy.pipeline.sweeps import (
    Ensemble,
    case_run_paths,
    case_sections,
    figure_ensembles,
    realisations_for,
    run_config,
    run_path,
    run_settings,
    seed_blocks,
    spec_ensembles,
)

SHIPPED = yaml.safe_load((ROOT / "config.yaml").read_text())
TYPED = parse(SHIPPED)  # the planning helpers read the typed config (pipeline/config.py)
section = build().CaseSection  # a section of cases, typed
PAPER_DIR = "mtpt/collision/n~30/eta~1/trunc~none/growth~1.05/scheme~symmetric/grid~exact"


# --------------------------------------------------------------------------- seed blocks
@pytest.mark.parametrize("base", [0, 7])
@pytest.mark.parametrize("size", [1, 2, 3, 20])
@pytest.mark.parametrize("count", [1, 2, 5, 19, 20, 21, 60, 80])
def test_seed_blocks_are_aligned_and_cover_each_seed_once(base, size, count):
    config = parse({**SHIPPED, "base_seed": base, "seed_blocks": {"size": size, "max_n": 1000}})
    blocks = seed_blocks(Ensemble(Case("mtpt", "collision", 300), count), config)
    seeds = [s for a, b in blocks for s in range(a, b + 1)]
    assert seeds == list(range(base, base + count))  # exactly these, in order, none twice
    for k, (a, b) in enumerate(blocks):
        assert a <= b and b - a + 1 <= size
        assert (a - base) == k * size  # block k starts at realisation k * size
        if k < len(blocks) - 1:
            assert b - a + 1 == size  # only the last block may be short
    assert len(blocks) == -(-count // size)


@pytest.mark.parametrize("size", [1, 3, 20])
def test_smaller_ensembles_share_the_first_blocks_of_larger_ones(size):
    config = parse({**SHIPPED, "base_seed": 0, "seed_blocks": {"size": size, "max_n": 1000}})
    blocks = {r: seed_blocks(Ensemble(Case("pt", "bins", 30), r), config) for r in (20, 60, 80)}
    for small, large in ((20, 60), (60, 80), (20, 80)):
        full = [(a, b) for a, b in blocks[small] if b - a + 1 == size]  # a short last block cannot be shared
        assert len(full) == small // size
        assert blocks[large][: len(full)] == full


def test_one_seed_per_job_above_max_n():
    config = parse({**SHIPPED, "base_seed": 3, "seed_blocks": {"size": 20, "max_n": 1000}})
    assert seed_blocks(Ensemble(Case("mtpt", "sph", 1001), 4), config) == [(3, 3), (4, 4), (5, 5), (6, 6)]
    assert seed_blocks(Ensemble(Case("mtpt", "sph", 1000), 4), config) == [(3, 6)]


def test_case_run_paths_written_by_hand():
    ens = Ensemble(Case("mtpt", "collision", 30), 80)
    assert case_run_paths(ens, TYPED) == [
        f"results/runs/{PAPER_DIR}/seeds~{a}-{a + 19}.parquet" for a in (0, 20, 40, 60)
    ]
    big = Ensemble(Case("mtpt", "collision", 30000), 4)  # 30000 <= max_n: one block of 4
    assert case_run_paths(big, TYPED) == [f"results/runs/{PAPER_DIR.replace('n~30/', 'n~30000/')}/seeds~0-3.parquet"]
    assert (
        run_path(Case("mtpt", "collision", 30), 5, kind="snapshots")
        == f"results/snapshots/{PAPER_DIR}/seeds~5-5.parquet"
    )


def test_summary_path_and_ensemble_wildcards():
    ens = Ensemble(Case("mtpt", "collision", 30), 80)
    assert ens.summary_path() == f"results/tables/cases/{PAPER_DIR}/r~80.parquet"
    assert Ensemble.from_wildcards({**ens.case.wildcards(), "nreal": "80"}) == ens


# --------------------------------------------------------------------------- realisations
ENSEMBLE = {"cases": [{"method": "mtpt", "kernel": "collision"}], "n": [30, 10000], "realisations": "ensemble"}


def test_realisations_from_the_table_and_capped():
    # config.yaml: {n: 30, count: 80}, {n: 10000, count: 6}, {n: 30000, count: 4}
    assert realisations_for(section(**ENSEMBLE), 30, TYPED) == 80
    assert realisations_for(section(**ENSEMBLE), 10000, TYPED) == 6
    capped = section(**ENSEMBLE, max_realisations=20)
    assert realisations_for(capped, 30, TYPED) == 20
    assert realisations_for(capped, 10000, TYPED) == 6
    assert realisations_for(section(**{**ENSEMBLE, "realisations": 5}), 30, TYPED) == 5
    unset = section(cases=ENSEMBLE["cases"], n=[30])
    assert realisations_for(unset, 30, TYPED) == 1  # unset: one realisation
    with pytest.raises(SettingError):
        realisations_for(section(**ENSEMBLE), 31, TYPED)


def test_fd_gets_one_realisation():
    spec = {
        "cases": [{"method": "fd", "kernel": "implicit"}, {"method": "mtpt", "kernel": "sph"}],
        "n": [30, 100],
        "realisations": "ensemble",
    }
    got = {(e.case.method, e.case.n): e.realisations for e in spec_ensembles(section(**spec), TYPED)}
    assert got == {("fd", 30): 1, ("fd", 100): 1, ("mtpt", 30): 80, ("mtpt", 100): 80}


def test_shipped_fig9_expands_to_the_realisations_table():
    ens = figure_ensembles(TYPED, "fig9")
    # config.yaml: 6 cases (3 models: the equations and the authors' preset) x 7 N; counts 80, 80, 60,
    # 50, 20, 6, 4 for N = 30 ... 30000
    counts = {30: 80, 100: 80, 300: 60, 1000: 50, 3000: 20, 10000: 6, 30000: 4}
    assert len(ens) == 42
    for e in ens:
        assert e.realisations == counts[e.case.n]
    paper = [Case("mtpt", "collision"), Case("mtpt", "sph"), Case("mtpt", "collision", eta=0.5)]
    # the authors' algorithm as registry.PRESETS says it: loop and SPH constant, cut at 3, their grid
    authors = [Case(m.method, m.kernel, eta=m.eta, truncation=3, scheme="authors", time_grid="authors") for m in paper]
    assert {e.case.model for e in ens} == {*paper, *authors}


def test_shipped_fig3_is_capped_at_20():
    assert {(e.case.kernel, e.case.n): e.realisations for e in figure_ensembles(TYPED, "fig3")} == {
        ("adaptive", 300): 20,
        ("adaptive", 30000): 4,
        ("sph", 300): 20,
        ("sph", 30000): 4,
    }


def test_spec_ensembles_take_case_defaults_where_they_apply(tiny_config):
    config = {**tiny_config, "case_defaults": {"eta": 1, "truncation": "none", "dt_growth": 1.3}}
    spec = {
        "cases": [
            {"method": "fd", "kernel": "implicit"},
            {"method": "pt", "kernel": "bins"},
            {"method": "mtpt", "kernel": "collision", "dt_growth": 1.01},
        ],
        "n": [30],
    }
    growth = [e.case.dt_growth for e in spec_ensembles(section(**spec), parse(config))]
    assert growth == [1.0, 1.3, 1.01]


def test_case_sections_of_the_shipped_config():
    assert list(case_sections(TYPED)) == [f"figures.fig{k}" for k in range(1, 10)] + ["tradeoff"] + [
        f"mechanism.sweeps[{i}]" for i in range(3)
    ]
    assert "tradeoff" not in case_sections(parse({k: v for k, v in SHIPPED.items() if k != "tradeoff"}))


def test_mechanism_cases_shared_with_fig9_are_the_same_ensembles():
    from particle_entropy.pipeline.sweeps import mechanism_ensembles

    mech = set(mechanism_ensembles(TYPED))
    fig9 = set(figure_ensembles(TYPED, "fig9"))
    shared = mech & fig9
    # from N = 3,000 the same ensembles (same summaries); below, the mechanism's 20 seeds are the
    # first blocks of Fig. 9's larger ensemble: no run of the equations or the authors' loop is extra
    assert {(e.case.scheme, e.case.n) for e in shared} == {
        (s, n) for s in ("symmetric", "authors") for n in (3000, 10000, 30000)
    }
    fig9_runs = {p for e in fig9 for p in case_run_paths(e, TYPED)}
    for e in mech:
        if e.case.model in {f.case.model for f in fig9} and e.case.n <= 30000:
            assert set(case_run_paths(e, TYPED)) <= fig9_runs, e
    assert {e.case.n for e in mech - fig9} >= {100000, 300000}


def test_check_sweeps_refuses_a_bad_mechanism_case(tiny_config):
    config = tiny_config
    config["mechanism"]["sweeps"][0]["cases"].append({"method": "mtpt", "kernel": "collision", "scheme": "compensated"})
    msg = _refused(config)
    assert "mechanism.sweeps[0].cases[4].scheme" in msg and "needs a truncation" in msg


# --------------------------------------------------------------------------- run settings
SETTINGS = {
    "physics": {"D": 2e-3, "t_final": 50, "omega": 8, "fd_length": 10, "fixed_kernel_time": 2},
    "time": {"dt0": 0.02, "fd_dt": 0.3, "fixed_dt": 2.0},
    "numerics": {"transfer_method": "direct", "transfer_tolerance": 1e-10},
}


@pytest.mark.parametrize(
    "case,dt0",
    [
        (Case("fd", "implicit", 100), 0.3),
        (Case("pt", "bins", 100, dt_growth=1), 2.0),
        (Case("mtpt", "collision", 100, dt_growth=1), 2.0),
        (Case("mtpt", "collision", 100), 0.02),
        (Case("mtpt", "sph", 100, dt_growth=1.01), 0.02),
        (Case("pt", "adaptive", 100), 0.02),
    ],
)
def test_run_settings_first_step(case, dt0):
    s = run_settings(case, SETTINGS)
    assert s["dt0"] == dt0
    assert (s["D"], s["t_final"], s["omega"], s["fd_length"], s["fixed_kernel_time"]) == (2e-3, 50, 8, 10, 2)
    assert (s["transfer_method"], s["transfer_tolerance"]) == ("direct", 1e-10)


def test_run_settings_on_the_shipped_config():
    assert run_settings(Case("fd", "implicit", 100), SHIPPED)["dt0"] == 0.05
    assert run_settings(Case("mtpt", "collision", 100, dt_growth=1), SHIPPED)["dt0"] == 1.0
    assert run_settings(Case("pt", "bins", 100), SHIPPED)["dt0"] == 0.01


def test_run_config_is_the_case_at_the_seed():
    case = Case("mtpt", "sph", 60, eta=0.5, truncation=3, scheme="sequential")
    cfg = run_config(case, SETTINGS, seed=7)
    assert cfg.case == case and cfg.seed == 7
    assert (cfg.dt0, cfg.D, cfg.t_final, cfg.omega) == (0.02, 2e-3, 50, 8)


# --------------------------------------------------------------------------- check_sweeps
def test_check_sweeps_accepts_the_shipped_and_tiny_configs(tiny_config):
    check_sweeps(SHIPPED)
    check_sweeps(tiny_config)


def _refused(config) -> str:
    with pytest.raises(SettingError) as e:
        check_sweeps(config)
    return str(e.value)


def test_check_sweeps_refuses_a_kernel_of_another_method(tiny_config):
    config = tiny_config
    config["figures"]["fig1"]["cases"][0]["kernel"] = "collision"
    msg = _refused(config)
    assert "figures.fig1.cases[0].kernel" in msg and "collision" in msg


def test_check_sweeps_refuses_an_inapplicable_dimension_in_tradeoff(tiny_config):
    config = tiny_config
    config["tradeoff"]["cases"][1]["eta"] = 0.5  # pt adaptive
    msg = _refused(config)
    assert "tradeoff.cases[1].eta" in msg and "0.5" in msg


def test_check_sweeps_refuses_an_odd_fd_n(tiny_config):
    config = tiny_config
    config["figures"]["fig8"]["n"] = [30, 61]
    msg = _refused(config)
    assert "figures.fig8.cases[0].n" in msg and "61" in msg


def test_check_sweeps_refuses_explicit_fd_past_stability(tiny_config):
    config = tiny_config
    config["figures"]["fig8"]["cases"] = [{"method": "fd", "kernel": "explicit"}]
    config["figures"]["fig8"]["n"] = [30, 200]
    check_sweeps(config)  # n = 200: dx = 0.06, r = D dt / dx^2 = 1e-3 * 0.5 / 0.0036 = 0.14 <= 1/2
    config["figures"]["fig8"]["n"] = [30, 2000]  # dx = 0.006: r = 13.9 > 1/2
    msg = _refused(config)
    assert "figures.fig8.cases[0]" in msg and "explicit" in msg


def test_check_sweeps_refuses_a_missing_realisations_entry(tiny_config):
    config = tiny_config
    config["tradeoff"]["n"] = [30, 40]  # ensemble, and the table has no N = 40
    msg = _refused(config)
    assert "tradeoff.n" in msg and "40" in msg


@pytest.mark.parametrize("key", ["comic_times", "tradeoff.times"])
def test_check_sweeps_refuses_a_time_past_t_final(key, tiny_config):
    config = tiny_config  # t_final 20
    section = config["tradeoff"] if key == "tradeoff.times" else config
    section[key.split(".")[-1]] = [5, 25]
    msg = _refused(config)
    assert key in msg and "25" in msg


def test_fd_only_section_needs_no_realisations_entry(tiny_config):
    cfg = tiny_config
    cfg["figures"]["fig8"].update(realisations="ensemble", n=[30, 40])  # no realisations entry for n = 40
    check_sweeps(cfg)
    assert [e.realisations for e in figure_ensembles(parse(cfg), "fig8")] == [1, 1]


def test_physics_settings_from_config_reach_the_run(tiny_config):
    cfg = tiny_config
    cfg["physics"].update(fixed_kernel_time=2.5, D=2e-3)
    run = run_config(Case("pt", "fixed", 30), cfg)
    assert (run.fixed_kernel_time, run.D, run.t_final) == (2.5, 2e-3, cfg["physics"]["t_final"])


def test_a_case_listed_twice_is_one_ensemble(tiny_config):
    cfg = tiny_config
    once = len(figure_ensembles(parse(cfg), "fig9"))
    cases = cfg["figures"]["fig9"]["cases"]
    cases.append({**cases[0], "eta": 1.0, "scheme": "symmetric"})  # the first case again, written another way
    assert len(figure_ensembles(parse(cfg), "fig9")) == once


def test_lattice_cases_and_their_checks(tiny_config):
    from particle_entropy.pipeline.sweeps import lattice_cases

    cases = lattice_cases(TYPED)
    assert {c.n for c in cases} == {3001} and all(c.eta == 1.0 and c.method == "mtpt" for c in cases)
    assert any(c.dt_growth == 1.01 for c in cases) and len(cases) == len(set(cases))
    config = copy.deepcopy(tiny_config)
    config["mechanism"]["lattice"]["n"] = 60
    assert "mechanism.lattice.n" in _refused(config)
    config = tiny_config
    config["mechanism"]["lattice"]["cases"].append({"method": "mtpt", "kernel": "collision", "eta": 0.5})
    assert "eta = 1 only" in _refused(config)


@pytest.mark.parametrize(
    ("path", "value"),
    [
        (("physics", "D"), float("nan")),
        (("physics", "t_final"), float("inf")),
        (("time", "dt0"), float("nan")),
        (("physics", "omega"), -float("inf")),
        (("comic_times", 1), float("nan")),
        (("shear", "dt"), float("inf")),
    ],
)
def test_check_sweeps_refuses_nan_and_infinity_anywhere(path, value, tiny_config):
    config = tiny_config
    node = config
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    msg = _refused(config)
    where = path[0] + "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in path[1:])
    assert msg.startswith(f"{where}=") and "finite" in msg


def test_check_sweeps_refuses_a_realisations_entry_given_twice(tiny_config):
    config = tiny_config
    config["realisations"].append({"n": config["realisations"][0]["n"], "count": 99})
    last = len(config["realisations"]) - 1
    assert f"realisations[{last}].n" in _refused(config) and "also at realisations[0]" in _refused(config)


def test_check_sweeps_refuses_a_claims_range_written_high_to_low(tiny_config):
    config = tiny_config
    config["claims"]["collision_eta1_optimum"] = [10000, 1000]
    msg = _refused(config)
    assert msg.startswith("claims.collision_eta1_optimum=[10000, 1000]") and "low <= high" in msg
