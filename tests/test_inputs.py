"""pipeline/inputs.py: what the rules read from the config (the default target, a section's tables
and cases, a job's case from its wildcards) and the crate's parameters from the rules."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
import yaml
from conftest import ROOT

from particle_entropy.pipeline.configcheck import parse
from particle_entropy.pipeline.inputs import (
    Inputs,
    beyond_default_target,
    coded_rules,
    default_targets,
    in_config,
    plotted_figures,
)
from particle_entropy.pipeline.sweeps import RUN_PATTERN, SUMMARY_PATTERN


@pytest.fixture
def config() -> dict:
    return yaml.safe_load((ROOT / "config.yaml").read_text())


class Wildcards(dict):
    """Snakemake's wildcards: a mapping whose values are attributes too."""

    __getattr__ = dict.__getitem__


def _run_wildcards(**changes) -> Wildcards:
    w = dict(kind="runs", method="mtpt", kernel="collision", n="1000", eta="1", trunc="none", growth="1.05")
    return Wildcards(w | dict(scheme="symmetric", grid="exact", first="0", last="3") | changes)


def test_in_config_follows_a_dotted_key(config):
    cfg = parse(config)
    assert in_config(cfg, "figures.fig3") and in_config(cfg, "shear")
    assert not in_config(cfg, "figures.nosuch") and not in_config(cfg, "base_seed.x")


def test_the_default_target_follows_the_config_s_sections(config):
    targets = default_targets(parse(config))
    assert {"figures/fig3.png", "figures/fig10.pdf", "results/tables/tradeoff.parquet"} <= set(targets)
    assert targets[-4:] == [
        "results/tables/comic.parquet",
        "results/tables/comic_minima.parquet",
        "results/tables/paper_claims.parquet",
        "results/paper_claims.md",
    ]
    del config["shear"], config["tradeoff"], config["figures"]["fig3"]
    fewer = default_targets(parse(config))
    assert not any("fig10" in t or "tradeoff" in t or "fig3." in t for t in fewer)
    assert "fig3" not in plotted_figures(parse(config)) and "fig4" in plotted_figures(parse(config))


def test_a_section_reads_its_tables_in_the_order_of_its_cases(config):
    inputs = Inputs(config)
    assert inputs.section_inputs("fig9") == [
        f"results/tables/fig9/{t}.parquet" for t in ("comic", "comic_minima", "comic_argmin")
    ]
    summaries = inputs.section_inputs("fig3")
    assert summaries == inputs.summaries_of("fig3") and all(s.startswith("results/tables/cases/") for s in summaries)
    assert len(inputs.section_cases("fig3")) == len(summaries)
    runs = inputs.runs_of("fig3", "fig3")
    assert runs and len(runs) == len(set(runs))  # each once


def test_the_fd_report_times_end_at_t_final_on_the_fd_grid(config):
    times = Inputs(config).fd_report_times()
    dt = float(config["time"]["fd_dt"])
    assert len(times) == 20 and times[-1] == pytest.approx(float(config["physics"]["t_final"]))
    assert all(abs(t / dt - round(t / dt)) < 1e-9 for t in times)


def test_a_job_s_case_and_resources_come_from_its_wildcards(config):
    inputs = Inputs(config)
    w = _run_wildcards()
    assert inputs.target_case(w, RUN_PATTERN).n == 1000
    assert inputs.sim_runtime_min(w) == 4 * 2 and inputs.sim_mem_mb(w) > 0 and inputs.sim_priority(w) > 0
    assert inputs.sim_settings(w)


@pytest.mark.parametrize(
    "changes,expected",
    [({"first": "5", "last": "2"}, "seeds~5-2: first <= last"), ({"n": "1"}, "n=1 is not allowed")],
)
def test_a_path_that_names_no_valid_run_raises_the_given_error(config, changes, expected):
    class Refused(Exception):
        pass

    with pytest.raises(Refused, match="a table path names no valid run") as e:
        Inputs(config, Refused).target_case(_run_wildcards(**changes), RUN_PATTERN)
    assert expected in str(e.value) and "expected results/{kind}/" in str(e.value)
    summary = Wildcards({k: v for k, v in _run_wildcards().items() if k not in ("kind", "first", "last")}, nreal="0")
    with pytest.raises(Refused, match="r~0: an ensemble of at least 1"):
        Inputs(config, Refused).summary_runs(summary)
    assert "r~{nreal}" in SUMMARY_PATTERN


def test_the_crate_s_rules_and_targets_beyond_the_default_one():
    def rule(name, params=(), input=(), output=()):
        return SimpleNamespace(name=name, params={p: 1 for p in params}, input=list(input), output=list(output))

    rules = [
        rule("simulate", ["code", "settings"]),
        rule("all"),
        rule("optimum", input=["results/optimum/a.parquet"]),
        rule("plot_fig9_mechanism", ["code"], output=["figures/fig9_mechanism.png"]),
    ]
    assert coded_rules(rules) == ["plot_fig9_mechanism", "simulate"]
    assert beyond_default_target(rules) == ["results/optimum/a.parquet", "figures/fig9_mechanism.png"]
