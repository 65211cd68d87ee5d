"""A small config layered over config.yaml from the repository root: sections the requested
targets do not use (config.yaml's optimum searches at t = 250, past the tiny t_final) cannot
block the run, and a bad value in a section a target uses is still refused before any job."""

from __future__ import annotations

import copy
import subprocess
from pathlib import Path

import pytest
import yaml
from conftest import ROOT, TINY, run_snakemake
from snakemake.utils import update_config

from particle_entropy.core.case import SettingError
from particle_entropy.pipeline.configcheck import check_config
from particle_entropy.pipeline.crosschecks import check_sweeps, optimum_searches


def _merged() -> dict:
    """config.yaml with the tiny config over it, as Snakemake merges --configfile."""
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    update_config(config, yaml.safe_load(TINY.read_text()))
    return config


def _dry_run(root: Path, *targets: str) -> subprocess.CompletedProcess:
    """`snakemake -j2 -n TARGETS --configfile tests/data/tiny_config.yaml` run in ``root``, as a
    user runs it there: no -s or -d, so Snakemake takes root's Snakefile and config.yaml."""
    configfile = TINY.relative_to(ROOT)
    return run_snakemake(None, *targets, snakefile=None, dry_run=True, configfile=configfile, cwd=root, check=False)


def test_the_merge_keeps_config_yamls_searches_past_the_tiny_t_final():
    """The situation itself: a merged config cannot delete config.yaml's searches."""
    config = _merged()
    assert "fd_t250" in config["optimum"] and config["optimum"]["fd_t250"]["time"] > config["physics"]["t_final"]


def test_unused_searches_do_not_block_the_case_sections(tiny_config):
    config = _merged()
    check_sweeps(config)  # the figures, the mechanism, the trade-off: all fine
    searches = optimum_searches(config)
    assert "fd_t250" in list(searches)  # named, not yet judged
    with pytest.raises(SettingError, match=r"optimum\.fd_t250\.time=250"):
        searches["fd_t250"]
    tiny_search = next(n for n in tiny_config["optimum"])
    assert searches[tiny_search].name == tiny_search  # the tiny config's own search is fine


def test_check_config_still_judges_every_search():
    """check-config does not know the targets: it judges every section, searches included."""
    with pytest.raises(SettingError, match=r"optimum\.fd_t250\.time"):
        check_config(_merged())


def test_a_bad_search_is_refused_when_it_is_used(tiny_config):
    config = copy.deepcopy(_merged())
    del config["optimum"]  # only the tiny config's searches, then break one of them
    config["optimum"] = tiny_config["optimum"]
    name = next(iter(config["optimum"]))
    config["optimum"][name]["time"] = 1e6
    with pytest.raises(SettingError, match=rf"optimum\.{name}\.time"):
        optimum_searches(config)[name]


def test_the_tiny_config_runs_from_the_repository_root(workflow_copy):
    root = workflow_copy  # the repository as a user clones it: config.yaml at the root, the tiny config beside
    proc = _dry_run(root)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout + proc.stderr
    assert "plot_fig1" in out and "optimum_round" not in out
    # the tiny sizes, not the paper's: no N above the tiny config's largest
    assert "n~30000" not in out and "n~100/" in out


def test_the_optimum_target_refuses_config_yamls_search_before_any_job(workflow_copy):
    root = workflow_copy
    proc = _dry_run(root, "optimum")
    assert proc.returncode != 0
    assert "optimum.fd_t250.time=250" in proc.stdout + proc.stderr
    assert not (root / "results").exists()  # nothing ran, nothing was written
