"""Extreme settings: each gives the right answer (against an analytic value) or a clear error."""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest
from conftest import ROOT

from particle_entropy.core import measures as M
from particle_entropy.core.runconfig import RunConfig, SettingError
from particle_entropy.models.simulate import run
from particle_entropy.numerics.mass_transfer import mass_transfer


def finite_after_start(table):
    """No NaN anywhere; after t = 0 everything finite, except ln(SSE) = -inf where SSE is exactly 0
    (likewise COMIC_points where SSE_points is: a delta, or a plume too narrow to reach a point)."""
    num = table.select_dtypes(include=[np.number]).drop(columns=["truncation"])
    assert not num.isna().any().any(), num.columns[num.isna().any()].tolist()
    later = num.iloc[1:]
    logs = {"SSE": ["AIC", "COMIC"], "SSE_points": ["COMIC_points"]}
    logs = {sse: cols for sse, cols in logs.items() if sse in later}
    for sse, cols in logs.items():
        exact = later[sse] == 0.0
        assert (later.loc[exact, cols] == -np.inf).all().all()
        assert np.isfinite(later.loc[~exact, cols].to_numpy()).all()
    rest = later.drop(columns=[c for cols in logs.values() for c in cols])
    bad = ~np.isfinite(rest.to_numpy()).all(axis=0)
    assert not bad.any(), rest.columns[bad].tolist()


@pytest.mark.parametrize("n", [2, 3, 10])
@pytest.mark.parametrize(
    "method,kernel", [("pt", "bins"), ("pt", "fixed"), ("pt", "adaptive"), ("mtpt", "collision"), ("mtpt", "sph")]
)
def test_tiny_particle_numbers(n, method, kernel):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tab, state = run(RunConfig.of(method=method, kernel=kernel, n=n, t_final=50.0, seed=3), want_state=True)
    finite_after_start(tab)
    assert np.allclose(tab["mass_total"], 1.0, rtol=0, atol=1e-14)
    assert (tab["mass_min"] >= 0).all()
    if method == "mtpt":
        assert tab["H_D"].iloc[0] == 0.0
    else:
        assert np.allclose(tab["H_D"], math.log(n))


@pytest.mark.parametrize("method,kernel", [("pt", "bins"), ("mtpt", "collision"), ("mtpt", "sph")])
def test_one_particle_is_refused_it_would_score_a_perfect_comic(method, kernel):
    """One particle holds the whole mass at its own position: its SSE against the normalised
    Gaussian at that position is 0 and COMIC -inf, which would win every Fig. 9 panel."""
    with pytest.raises(SettingError, match=r"n=1 is not allowed: an integer >= 2"):
        RunConfig.of(method=method, kernel=kernel, n=1, t_final=10.0)


def test_one_particle_and_a_huge_growth_are_refused_by_the_config_and_the_cli(tmp_path):
    import copy

    import yaml

    from particle_entropy.cli import main
    from particle_entropy.pipeline.configcheck import check_config

    base = yaml.safe_load((ROOT / "config.yaml").read_text())
    one = copy.deepcopy(base)
    one["figures"]["fig9"]["n"] = [1, 100]
    with pytest.raises(SettingError, match=r"figures.fig9.n\[0\]=1 is not allowed"):
        check_config(one)
    huge = copy.deepcopy(base)
    huge["case_defaults"]["dt_growth"] = 1e308  # an OverflowError naming no key, before
    with pytest.raises(SettingError, match=r"case_defaults.dt_growth=1e\+308 is not allowed: .*10"):
        check_config(huge)
    out = tmp_path / "t.parquet"
    for option in (["--n", "1"], ["--dt-growth", "1e308"]):
        with pytest.raises(SystemExit):
            main(["simulate", "--method", "mtpt", "--kernel", "collision", *option, "--out", str(out)])
    assert not out.exists()


def test_one_step_with_300k_particles():
    rng = np.random.default_rng(5)
    x = np.sort(rng.uniform(-5, 5, 300_000))
    m = np.exp(-x * x) * rng.random(x.size)
    m /= m.sum()
    for sigma in (0.0063, 0.44):
        res = mass_transfer(x, m, sigma, 0.5)
        assert abs(res.mass.sum() - 1.0) < 1e-12
        assert res.mass.min() >= 0.0
    # the fast path against the exact windowed sum, early width (cheap for the direct sum)
    fast = mass_transfer(x, m, 0.002, 0.5, method="fgt").mass
    exact = mass_transfer(x, m, 0.002, 0.5, method="direct").mass
    assert np.max(np.abs(fast - exact)) < 1e-12 * m.max()


def test_all_particles_at_one_point_mix_to_the_mean():
    """W is all ones, so P = 1/N and m_i <- m_i + beta (mean(m) - m_i) exactly."""
    m = np.random.default_rng(2).random(500)
    for method in ("direct", "fgt"):
        out = mass_transfer(np.zeros(500), m, 0.1, 0.5, method=method).mass
        np.testing.assert_allclose(out, m + 0.5 * (m.mean() - m), rtol=1e-12)


@pytest.mark.parametrize("method,kernel", [("pt", "bins"), ("mtpt", "collision"), ("mtpt", "sph"), ("fd", "implicit")])
def test_zero_diffusion_is_refused_as_the_config_refuses_it(method, kernel):
    """D = 0 leaves a delta whose analytic reference is a delta too: SSE 0 and COMIC -inf would
    score as perfect. The run refuses it as the config's schema does (settings.SETTINGS)."""
    with pytest.raises(SettingError, match=r"D=0.0 is not allowed: a number > 0"):
        run(RunConfig.of(method=method, kernel=kernel, n=200, D=0.0, t_final=10.0))


@pytest.mark.parametrize("method,kernel", [("pt", "bins"), ("mtpt", "collision"), ("fd", "implicit")])
def test_tiny_diffusion_keeps_the_mass(method, kernel):
    grid = {"fd_length": 0.002} if method == "fd" else {}  # dx = 1e-5 resolves the plume (E = 1.8e-5)
    tab, _ = run(RunConfig.of(method=method, kernel=kernel, n=200, D=1e-12, t_final=10.0, **grid))
    assert tab["mass_total"].iloc[-1] == pytest.approx(1.0, abs=1e-13)


def test_eta_zero_is_a_pure_random_walk_and_eta_one_never_moves():
    walk, s0 = run(RunConfig.of(method="mtpt", n=300, eta=0.0, t_final=100.0, seed=4), want_state=True)
    assert (walk["H_D"] == 0.0).all() and (walk["beta"] == 0.0).all()
    still, s1 = run(RunConfig.of(method="mtpt", n=300, eta=1.0, t_final=100.0, seed=4), want_state=True)
    init = run(RunConfig.of(method="mtpt", n=300, eta=1.0, t_final=1e-9, seed=4), want_state=True)[1]
    np.testing.assert_array_equal(s1["x"].to_numpy(), init["x"].to_numpy())
    assert not np.array_equal(s0["x"].to_numpy(), init["x"].to_numpy())


@pytest.mark.parametrize(
    "dt0,growth,t_final", [(1e-6, 1.5, 1.0), (1e3, 1.05, 10.0), (1e3, 1.0, 3000.0), (0.5, 1.0, 0.2)]
)
def test_time_steps_from_tiny_to_huge(dt0, growth, t_final):
    tab = run(RunConfig.of(method="mtpt", kernel="collision", n=500, dt0=dt0, dt_growth=growth, t_final=t_final))[0]
    assert tab["time"].iloc[-1] == t_final
    assert abs(tab["mass_total"].iloc[-1] - 1.0) < 1e-12 and (tab["mass_min"] >= 0).all()
    finite_after_start(tab)
    if dt0 >= t_final:  # t_final shorter than one step: exactly one (shortened) step
        assert len(tab) == 2 and tab["dt"].iloc[1] == t_final


def test_forced_huge_sph_beta_stays_positive_and_conservative():
    """Omega = 0.005 packs N = 2000 particles so densely that beta = 2 D dt / h^2 >> 1 (t_final short
    enough that the plume, 2 sqrt(2 D t_final) = 0.0049 wide, fits Omega)."""
    tab = run(RunConfig.of(method="mtpt", kernel="sph", n=2000, omega=0.005, t_final=3e-3, seed=1))[0]
    assert tab["beta"].max() > 20
    assert tab["substeps"].max() > 10
    assert (tab["mass_min"] >= 0).all()
    assert np.max(np.abs(tab["mass_total"] - 1.0)) < 1e-12


def test_explicit_fd_past_its_limit_is_refused_with_the_safe_range():
    cfg = RunConfig.of(method="fd", kernel="explicit", n=3000, dt0=0.05)  # r = 1e-3 * 0.05 / 0.004^2 = 3.1
    with pytest.raises(SettingError) as err:
        cfg.resolved()
    msg = str(err.value)
    assert "dt0" in msg and "r = D dt / dx^2 < 1/2" in msg and "0.008" in msg  # dt0 < 0.5 dx^2 / D


def test_explicit_fd_within_its_limit_matches_implicit():
    kw = dict(method="fd", n=300, dt0=0.05, t_final=200.0)  # r = 0.03
    ex = run(RunConfig.of(kernel="explicit", **kw))[0].iloc[-1]
    im = run(RunConfig.of(kernel="implicit", **kw))[0].iloc[-1]
    assert ex["H_C"] == pytest.approx(im["H_C"], abs=1e-3)
    assert ex["H_C"] == pytest.approx(ex["H_C_analytic"], abs=2e-3)


def test_cli_refuses_explicit_fd_past_limit(tmp_path):
    out = tmp_path / "x.parquet"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "particle_entropy",
            "simulate",
            "--method",
            "fd",
            "--kernel",
            "explicit",
            "--n",
            "3000",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2 and "--dt0" in proc.stderr and not out.exists()


def test_implicit_fd_with_a_million_nodes_in_bounded_memory():
    code = (
        "import resource\n"
        "from particle_entropy.models.simulate import run\n"
        "from particle_entropy.core.runconfig import RunConfig\n"
        "t = run(RunConfig.of(method='fd', n=1_200_000, t_final=0.15))[0]\n"  # dx = 1e-5
        "print(t['mass_total'].iloc[-1], t['mass_min'].min(), t['H_C'].iloc[-1], t['H_C_analytic'].iloc[-1],"
        " resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    mass, mass_min, h_c, h_c_an, rss_mb = map(float, out)
    # r = D dt / dx^2 = 5e5: the LU solve's round-off grows with the condition number ~ r
    assert abs(mass - 1.0) < 1e-9 and mass_min >= 0.0
    assert abs(h_c - h_c_an) < 0.2  # 3 backward-Euler steps from a delta: dt error ~ dt / t
    assert rss_mb < 1500


def test_entropy_before_the_settling_time_is_flagged_not_nan():
    tab = run(RunConfig.of(method="mtpt", n=30, t_final=1.0))[0]
    t_settle = M.settling_time(10.0 / 30, 1e-3)
    early = tab[(tab["time"] > 0) & (tab["time"] <= t_settle)]
    assert len(early) > 0 and not early["settled"].any()
    assert tab[tab["time"] > t_settle]["settled"].all()
    assert (early["H_C_analytic"] < 0).all() and np.isfinite(early["H_C_analytic"]).all()
    finite_after_start(tab)


def test_a_plume_that_overflows_or_outgrows_the_fd_grid_is_refused_by_its_setting():
    """D = 1e300 wrote FD tables with -inf entropy and zero mass; fd_length = 1e-300 NaN tables.
    sqrt(2 D t_final) = sqrt(2) at the paper's settings: the FD domain must be >= 2 sqrt(2)."""
    with pytest.raises(SettingError, match=r"D=1e\+306 is not allowed: a number with 2 D t_final finite"):
        RunConfig.of(method="mtpt", kernel="collision", n=100, D=1e306).resolved()
    for length in (1e-300, 2.8):
        with pytest.raises(
            SettingError, match=rf"fd_length={length:g} is not allowed: a domain >= 2 sqrt\(2 D t_final\) = 2\.82843"
        ):
            RunConfig.of(method="fd", kernel="implicit", n=100, fd_length=length).resolved()
    assert (
        RunConfig.of(method="fd", kernel="implicit", n=100, fd_length=2.9).resolved().fd_length == 2.9
    )  # holds the plume
    with pytest.raises(SettingError, match=r"fd_length=12.0 is not allowed: .* = 89\.4427 for D = 1, t_final = 1000"):
        RunConfig.of(method="fd", kernel="implicit", n=100, D=1.0).resolved()  # D 1e300 in the issue: the same rule
