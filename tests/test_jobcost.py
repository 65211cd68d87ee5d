"""pipeline/jobcost.py: the estimated seconds that order the simulation jobs (Snakemake priority).
The pair count is checked against pairs counted on particles; the order against the paper run's
measured job times; the rule against a dry run."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from conftest import ROOT, run_snakemake

from particle_entropy.core.case import Case
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.pipeline.config import build
from particle_entropy.pipeline.jobcost import estimated_seconds, pairs_per_step, shear_seconds
from particle_entropy.pipeline.sweeps import run_config

CONFIG = yaml.safe_load((ROOT / "config.yaml").read_text())


def _authors(kernel, eta, n):
    return Case.from_spec(
        {"method": "mtpt", "kernel": kernel, "eta": eta, "preset": "authors"}, n, CONFIG["case_defaults"]
    )


def test_pairs_per_step_counts_the_pairs_inside_the_cut_off():
    """N uniform particles on [-Omega/2, Omega/2]: pairs with |x_i - x_j| <= r number about N^2 r / Omega
    (fewer by the edges, r / Omega of them), counted here by sorting."""
    cfg = RunConfig.of(method="mtpt", kernel="collision", n=4000, truncation=3.0, scheme="sequential").resolved()
    dt = np.array([0.5, 5.0])
    estimate = pairs_per_step(cfg, dt, np.cumsum(dt))
    x = np.sort(np.random.default_rng(1).uniform(-cfg.omega / 2, cfg.omega / 2, cfg.n))
    for d, e in zip(dt, estimate):
        r = 3.0 * np.sqrt(4.0 * cfg.eta * cfg.D * d)  # 3 collision widths (Eq. 17)
        counted = int((np.searchsorted(x, x + r, side="right") - np.arange(cfg.n) - 1).sum())
        assert counted == pytest.approx(e, rel=0.05 + r / cfg.omega)


def test_the_symmetric_transfer_counts_no_pairs():
    cfg = RunConfig.of(method="mtpt", kernel="collision", n=3000).resolved()
    dt = np.array([1.0, 2.0])
    assert not pairs_per_step(cfg, dt, np.cumsum(dt)).any()


def test_the_paper_run_s_longest_jobs_come_first_in_its_order():
    """The paper run of 2026-12-03 measured its authors'-algorithm jobs at N = 30,000 (4 seeds):
    collision eta = 1 128 s, collision eta = 0.5 87 s, SPH 78 s; the next longest, collision
    eta = 1 at N = 10,000 (6 seeds), 23 s; symmetric collision at N = 30,000, 4 seeds: 4 s."""
    est = {
        name: estimated_seconds(run_config(case, CONFIG), seeds)
        for name, case, seeds in [
            ("collision 1", _authors("collision", 1, 30000), 4),
            ("collision 0.5", _authors("collision", 0.5, 30000), 4),
            ("sph", _authors("sph", 1, 30000), 4),
            ("collision 1 at 10,000", _authors("collision", 1, 10000), 6),
            ("symmetric", Case("mtpt", "collision", 30000), 4),
        ]
    }
    assert list(est) == sorted(est, key=est.get, reverse=True)
    assert 60 < est["collision 1"] < 250  # seconds, as measured to a factor of 2


def test_the_shear_estimate_puts_mass_transfer_first():
    shear = build().Shear(**CONFIG["shear"])
    assert shear_seconds("mt", shear) > 5 and shear_seconds("mt", shear) > 20 * shear_seconds("rw_drift", shear)


def test_the_simulate_rule_gives_each_job_its_estimate_as_priority(tmp_path):
    proc = run_snakemake(tmp_path, "figures/fig9.png", dry_run=True, configfile=ROOT / "config.yaml")
    out = proc.stdout + proc.stderr
    blocks = out.split("\nrule simulate:")
    long = next(
        b for b in blocks if "collision/n~30000/eta~1/trunc~3/growth~1.05/scheme~authors" in b.split("reason:")[0]
    )
    expected = estimated_seconds(run_config(_authors("collision", 1, 30000), CONFIG), 4)
    assert f"priority: {expected}" in long
