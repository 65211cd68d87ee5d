"""Appendix B shear flow (Fig. 10): random walks with and without the div D drift, and mass transfer.

Sizes: the random-walk tests run the paper's full case (N = 20,000, t = 500; about 1 s each).
The mass-transfer run is shortened in x only (length 60 instead of 400, strip 20-40, N = 3,000):
that keeps the paper's particle density (50 per unit x, so the same ~35 kernel neighbours per
particle and ~1,000 particles in the strip) and all the y physics, which is what these tests
are about; the x-periodic domain only wraps the sheared plume onto itself, and the lateral
marginal is an integral over x that does not depend on the domain length.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from conftest import no_runtime_warnings

from particle_entropy.core.records import TIMING_COLUMNS
from particle_entropy.core.runconfig import SettingError
from particle_entropy.core.settings import SHEAR_MAX_N as MAX_N
from particle_entropy.models.shear2d import (
    ShearConfig,
    kernel_cutoff,
    run_shear,
    transfer_step,
    velocity,
)

N_FULL = 20_000
UNIFORM_WALL = 0.1  # fraction of a uniform y distribution within 0.05 of either wall
SE_FULL = math.sqrt(UNIFORM_WALL * (1 - UNIFORM_WALL) / N_FULL)  # binomial standard error
SMALL_MT = dict(case="mt", length=60.0, strip_lo=20.0, strip_hi=40.0, n=3_000)


@pytest.fixture(scope="module")
def rw_runs():
    return {case: run_shear(ShearConfig(case=case, seed=3)) for case in ("rw_nodrift", "rw_drift")}


@pytest.fixture(scope="module")
def mt_run():
    cfg = ShearConfig(seed=3, **SMALL_MT)
    steps, state = run_shear(cfg)
    return cfg, steps, state


# ---------------------------------------------------------------- random walks


def test_no_drift_piles_particles_at_the_walls(rw_runs):
    """Without div D the walk migrates to low D: > 3x the uniform share sits within 0.05 of a wall."""
    steps, state = rw_runs["rw_nodrift"]
    final = steps["wall_fraction"].iloc[-1]
    assert final > 3 * UNIFORM_WALL  # measured ~0.52; uniform is 0.1 +- 0.002
    assert final > UNIFORM_WALL + 50 * SE_FULL
    # the mass-carrying walkers pile up as well (the paper's Fig. 10a)
    carry = state[state["mass"] > 0]
    near = ((carry["y"] < 0.05) | (carry["y"] > 0.95)).mean()
    assert near > 2 * UNIFORM_WALL


def test_drift_keeps_particles_uniform_in_y(rw_runs):
    """With the drift the wall fraction stays 0.1 within 4 binomial standard errors sqrt(0.1*0.9/N).

    The stationary density of dy = div D dt + sqrt(2 D) dW is uniform, and the initial positions
    are uniform, so at every step the count near the walls is Binomial(N, 0.1) (to the accuracy
    of the Euler scheme). Checked at t = 500 and for the average over t = 250..500, whose
    variance is at most the single-step variance.
    """
    steps, _ = rw_runs["rw_drift"]
    wf = steps["wall_fraction"].to_numpy()
    assert abs(wf[-1] - UNIFORM_WALL) < 4 * SE_FULL
    assert abs(wf[250:].mean() - UNIFORM_WALL) < 4 * SE_FULL


def test_random_walks_conserve_mass_and_stay_in_domain(rw_runs):
    for steps, state in rw_runs.values():
        assert np.all(np.abs(steps["mass_total"] - 1.0) < 1e-12)
        assert state["y"].between(0.0, 1.0).all()
        assert ((state["x"] >= 0.0) & (state["x"] < 400.0)).all()
        assert len(steps) == 501 and steps["time"].iloc[-1] == 500.0


# ---------------------------------------------------------------- mass transfer


def test_mt_conserves_mass_and_stays_non_negative(mt_run):
    _, steps, state = mt_run
    assert np.all(np.abs(steps["mass_total"] - 1.0) <= 1e-12)
    assert steps["mass_min"].min() >= 0.0
    assert (state["mass"] >= 0).all()
    # the positivity condition beta * sum_{j != i} P_ij <= 1 holds in every (sub)step
    assert np.all(steps["max_offdiag_beta"].iloc[1:] / steps["substeps"].iloc[1:] <= 1.0)
    assert (steps["substeps"].iloc[1:] >= 1).all()
    # particles only move along x in MT
    assert np.isfinite(state[["x", "y", "mass"]].to_numpy()).all()


def test_mt_has_no_lateral_bias(mt_run):
    """Mass-weighted mean y stays at 0.5 and the near-wall mass stays at its uniform share.

    The marginal c(y) obeys dc/dt = d/dy(alpha_T v dc/dy) with no-flux walls; its mean relaxes
    towards 0.5 and a uniform c(y) is stationary. So the only departures are the sampling error
    of the initial strip, N_s uniform y values: 4 SE = 4 sqrt(1/12 / N_s) for the mean, and
    4 sqrt(0.1*0.9 / N_s) for the near-wall share.
    """
    cfg, steps, _ = mt_run
    rng = cfg.rng()
    x0 = rng.uniform(0.0, cfg.length, cfg.n)  # the run's own initial positions
    n_strip = int(((x0 > cfg.strip_lo) & (x0 < cfg.strip_hi)).sum())
    assert 800 < n_strip < 1200
    tol_mean = 4 * math.sqrt(1 / 12 / n_strip)
    tol_wall = 4 * math.sqrt(0.09 / n_strip)
    assert np.all(np.abs(steps["mean_y"] - 0.5) < tol_mean)
    assert np.all(np.abs(steps["wall_fraction"] - UNIFORM_WALL) < tol_wall)


def test_mt_mirror_symmetric_case_keeps_mean_y_exactly():
    """Particles mirrored about y = 0.5 with equal masses stay mirrored: mean y = 0.5 to round-off."""
    cfg = ShearConfig(case="mt", length=20.0, strip_lo=5.0, strip_hi=10.0, n=1200, t_final=100.0)
    rng = np.random.default_rng(7)
    x = rng.uniform(0, cfg.length, 600)
    y = rng.uniform(0, 0.5, 600)
    m = np.where((x > 5) & (x < 10), 1.0, 0.0)
    m /= 2 * m.sum()
    steps, state = run_shear(cfg, init=(np.r_[x, x], np.r_[y, 1 - y], np.r_[m, m]))
    assert np.all(np.abs(steps["mean_y"] - 0.5) < 1e-12)
    mass = state["mass"].to_numpy()
    assert np.allclose(mass[:600], mass[600:], rtol=1e-9, atol=1e-15)
    assert mass.max() < m.max()  # something did mix


def test_mt_alpha_T_zero_moves_no_mass_across_y():
    """With alpha_T = 0 the kernel is a delta in y: mass placed on the particles of one line
    y = 0.3 spreads along x on that line and is exactly 0 on the particles of every other line
    (lines 0.05 apart, and on 200 particles at random y) after 200 steps."""
    cfg = ShearConfig(case="mt", alpha_T=0.0, length=40.0, strip_lo=10.0, strip_hi=20.0, n=1000, t_final=200.0)
    rng = np.random.default_rng(11)
    lines = np.array([0.25, 0.3, 0.35, 0.5])
    y = np.r_[np.repeat(lines, 200), rng.uniform(0, 1, 200)]
    x = rng.uniform(0, cfg.length, y.size)
    on_line = y == 0.3
    m = np.where(on_line & (x > 10) & (x < 20), 1.0, 0.0)
    m /= m.sum()
    steps, state = run_shear(cfg, init=(x, y, m))
    mass = state["mass"].to_numpy()
    assert np.all(mass[~on_line] == 0.0)
    assert abs(mass[on_line].sum() - 1.0) < 1e-12
    assert (mass[on_line] > 1e-6).sum() > (m > 0).sum()  # it did spread along the line


def test_mt_exchanges_across_the_periodic_boundary():
    """Two particles straddling x = 400 exchange exactly as the same pair in mid-domain does."""
    cfg = ShearConfig(case="mt", t_final=1.0)
    y = np.array([0.5, 0.5])  # both advected by 0.25: 399.95 and 0.25 after the step
    out = []
    for x in (np.array([399.7, 0.0]), np.array([199.7, 200.0])):
        _, state = run_shear(cfg, init=(x, y, np.array([1.0, 0.0])))
        out.append(state["mass"].to_numpy())
    wrap, mid = out
    assert wrap[1] > 1e-3  # real exchange across the boundary (pair 0.3 apart across x = 400)
    assert np.allclose(wrap, mid, rtol=1e-10, atol=0.0)
    assert abs(wrap.sum() - 1.0) < 1e-15


def test_mt_matches_dense_untruncated_reference():
    """The cut-off kernel on a sparse pair list equals the full Eq. 17 transfer (dense, no cut-off, with
    the prefactor 1/sqrt(det(8 pi D_ij dt))) for 300 particles: the neglected weights are < 1e-16."""
    cfg = ShearConfig(case="mt", length=6.0, strip_lo=2.0, strip_hi=3.0, n=300)
    rng = np.random.default_rng(5)
    x, y = rng.uniform(0, cfg.length, 300), rng.uniform(0, 1, 300)
    m = rng.uniform(0, 1, 300) * (x < 3)
    m /= m.sum()
    got, substeps, _, n_pairs = transfer_step(np.column_stack([x, y]), m, cfg)
    assert n_pairs < 300 * 299 / 2  # the cut-off did drop pairs

    dx = np.abs(x[:, None] - x[None, :])
    dx = np.minimum(dx, cfg.length - dx)
    dy = y[:, None] - y[None, :]
    vbar = 0.5 * (velocity(y)[:, None] + velocity(y)[None, :])
    DL, DT = cfg.alpha_L * vbar, cfg.alpha_T * vbar
    W = np.exp(-(dx**2 / DL + dy**2 / DT) / (8 * cfg.dt)) / np.sqrt(64 * np.pi**2 * DL * DT * cfg.dt**2)
    P = 0.5 * (W / W.sum(1)[:, None] + W / W.sum(0)[None, :])
    np.fill_diagonal(P, 0.0)
    assert cfg.beta * P.sum(1).max() <= 1.0 and substeps == 1
    want = m + cfg.beta * (P @ m - m * P.sum(1))
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-15)
    assert kernel_cutoff(cfg) == pytest.approx(math.sqrt(2 * math.log(2e16)))


# ---------------------------------------------------------------- the tables before the shared steps

# From the code at commit 5399db0, before the walk (models/walk.py) and the transfer
# (numerics/pair_transfer.py) were shared: run_shear(ShearConfig(case, n=2000, t_final=50, seed=0))
# for the walks, and SMALL_HOLD for mt; floats as repr printed them.
OLD_WALKS = {
    "rw_nodrift": dict(
        wall_fraction=0.173,
        mean_y=0.5130552063816076,
        x=[365.86174256528494, 266.42052578867384, 276.1878440788135],
        y=[0.2010972944823712, 0.5239392016637888, 0.20500426560536017],
        sum_x=402289.503498457,
        sum_y=1026.1104127632152,
    ),
    "rw_drift": dict(
        wall_fraction=0.089,
        mean_y=0.49677880631059024,
        x=[215.08534830180554, 210.93737896126908, 158.694529624494],
        y=[0.03284340107873654, 0.770341720844198, 0.27564366346891933],
        sum_x=391519.863940686,
        sum_y=993.5576126211805,
    ),
}
SMALL_HOLD = dict(case="mt", n=1500, t_final=30.0, seed=3, length=60.0, strip_lo=20.0, strip_hi=40.0)
OLD_MT = dict(
    wall_fraction=0.1015011440245978,
    mean_y=0.5099792086566362,
    max_offdiag_beta=0.3972440867453919,
    mass_max=0.0020366598778004093,
    sum_m2=0.002002796960500083,
    sum_mx=35.23102604147818,
)


@pytest.mark.parametrize("case", sorted(OLD_WALKS))
def test_random_walks_are_the_tables_before_the_shared_walk_to_the_bit(case):
    """The shared walk draws (2, N) normals, x's row first, and adds in the old order: same bits."""
    steps, state = run_shear(ShearConfig(case=case, n=2000, t_final=50.0, seed=0))
    old = OLD_WALKS[case]
    last = steps.iloc[-1]
    assert last["wall_fraction"] == old["wall_fraction"] and last["mean_y"] == old["mean_y"]
    assert state["x"].iloc[:3].tolist() == old["x"] and state["y"].iloc[:3].tolist() == old["y"]
    assert state["x"].sum() == old["sum_x"] and state["y"].sum() == old["sum_y"]


def test_mt_is_the_table_before_the_shared_transfer_to_round_off():
    """Not to the bit (shear2d's docstring says why): the pair tensor is now (D_i + D_j)/2 of each
    particle's D, not alpha (v_i + v_j)/2, and the weights keep the factor 1/sqrt(alpha_L alpha_T).
    The positions take no random draws after the start, so the tables agree to round-off; the same
    pairs and substeps to the count."""
    steps, state = run_shear(ShearConfig(**SMALL_HOLD))
    last = steps.iloc[-1]
    m, x = state["mass"].to_numpy(), state["x"].to_numpy()
    assert int(last["n_pairs"]) == 12249 and int(steps["n_pairs"].sum()) == 366667
    assert int(steps["substeps"].sum()) == 30 and int(m.argmax()) == 246
    got = dict(
        wall_fraction=last["wall_fraction"],
        mean_y=last["mean_y"],
        max_offdiag_beta=last["max_offdiag_beta"],
        mass_max=m.max(),
        sum_m2=np.dot(m, m),
        sum_mx=np.dot(m, x),
    )
    for key, want in OLD_MT.items():
        assert got[key] == pytest.approx(want, rel=1e-12, abs=0.0), key


# ---------------------------------------------------------------- walls, D = 0, settings


@pytest.mark.parametrize("case", ["rw_nodrift", "rw_drift", "mt"])
def test_particles_on_the_walls_give_no_nan(case):
    """D = 0 on y = 0 and y = 1: walks, drift, Cholesky factor and kernel stay finite, no warnings."""
    cfg = ShearConfig(case=case, length=20.0, strip_lo=5.0, strip_hi=10.0, n=400, t_final=20.0)
    rng = np.random.default_rng(2)
    x = rng.uniform(0, 20, 400)
    y = np.r_[np.zeros(100), np.ones(100), rng.uniform(0, 1, 200)]
    m = np.where((x > 5) & (x < 10), 1.0, 0.0)
    m /= m.sum()
    with no_runtime_warnings():
        steps, state = run_shear(cfg, init=(x, y, m))
    assert np.isfinite(steps.drop(columns=["case"]).select_dtypes("number").to_numpy()).all()
    assert np.isfinite(state[["x", "y", "mass"]].to_numpy()).all()
    assert np.all(np.abs(steps["mass_total"] - 1.0) < 1e-12) and steps["mass_min"].min() >= 0


def test_mt_wall_particle_without_partners_is_isolated():
    """Two D = 0 particles on the wall (D_ij = 0) and no other partner within the cut-off: no exchange."""
    cfg = ShearConfig(case="mt", t_final=3.0)
    x, y, m = np.array([100.0, 100.1, 300.0]), np.array([0.0, 0.0, 0.5]), np.array([0.7, 0.0, 0.3])
    with no_runtime_warnings():
        _, state = run_shear(cfg, init=(x, y, m))
    np.testing.assert_array_equal(state["mass"].to_numpy(), m)


def test_determinism_per_seed():
    for case, n, t in (("rw_drift", 2000, 50.0), ("mt", 1000, 20.0)):
        kw = dict(case=case, n=n, t_final=t, length=20.0, strip_lo=5.0, strip_hi=10.0)
        a_steps, a = run_shear(ShearConfig(seed=4, **kw))
        b_steps, b = run_shear(ShearConfig(seed=4, **kw))
        _, c = run_shear(ShearConfig(seed=5, **kw))
        pd.testing.assert_frame_equal(a, b)
        timing = list(TIMING_COLUMNS)
        pd.testing.assert_frame_equal(a_steps.drop(columns=timing), b_steps.drop(columns=timing))
        assert not np.array_equal(a["x"].to_numpy(), c["x"].to_numpy())


@pytest.mark.parametrize(
    "kw, name",
    [
        (dict(case="walk"), "case"),
        (dict(n=0), "n"),
        (dict(n=MAX_N + 1), "n"),
        (dict(alpha_L=0.0), "alpha_L"),
        (dict(alpha_T=-1e-3), "alpha_T"),
        (dict(dt=0.0), "dt"),
        (dict(t_final=10.5), "t_final"),
        (dict(beta=1.5), "beta"),
        (dict(seed=-1), "seed"),
        (dict(strip_lo=120.0), "strip_hi"),
        (dict(length=1.0, strip_lo=0.2, strip_hi=0.4), "length"),
    ],
)
def test_bad_settings_name_the_setting(kw, name):
    with pytest.raises(SettingError) as err:
        ShearConfig(**kw)
    assert err.value.name == name


def test_shear_memory_estimate_is_above_a_measured_peak():
    """The mt shear job at 4x the paper's N, two steps: memory.shear_memory_mb must bound the
    peak resident memory a fresh process reaches (its pairs grow as N^2). The peak is the child's
    own VmHWM: ru_maxrss would also count the pages a forked child shares with this (large) test
    process before it execs."""
    import subprocess
    import sys

    import yaml

    from particle_entropy.pipeline.config import build
    from particle_entropy.pipeline.memory import shear_memory_mb

    shear = {**yaml.safe_load(open("config.yaml"))["shear"], "n": 80_000, "t_final": 2, "cases": ["mt"]}
    code = (
        "from particle_entropy.models.shear2d import ShearConfig, run_shear; "
        f"run_shear(ShearConfig(case='mt', **{ {k: v for k, v in shear.items() if k != 'cases'}!r})); "
        "print(next(line.split()[1] for line in open('/proc/self/status') if line.startswith('VmHWM:')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    peak = int(out.stdout.split()[-1]) * 1024  # kB
    estimate = shear_memory_mb(build().Shear(**shear)) * 2**20
    assert peak > 350e6  # the pairs do cost memory: the check is not vacuous
    assert peak < estimate < 3 * peak
