"""Nothing degenerate scores (issue 33, item 1): a run whose sampling volume cannot resolve the plume,
whose domain cannot hold it, an FD grid too coarse for its stencil or explicit FD at r >= 1/2 is
refused before it runs, naming the key, its value and the allowed range; shear dispersivities whose
step reaches across the channel are refused; an FD step that loses mass beyond its boundary outflow
raises. The bounds are derived here from the physics, not read from the code under test."""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import pytest
import yaml
from conftest import ROOT, TINY

from particle_entropy.cli import main
from particle_entropy.core.case import SettingError
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.experiments.fd_domain import grid_intervals
from particle_entropy.pipeline.configcheck import check_config

D, T = 1e-3, 1000.0  # the paper's physics
E_FINAL = math.sqrt(4.0 * math.pi * math.e * D * T)  # the plume's dilution index at t_final (Eq. 14 into 8)
WIDTH = 2.0 * math.sqrt(2.0 * D * T)  # the plume's width, +-1 standard deviation
BASE = yaml.safe_load((ROOT / "config.yaml").read_text())


def _simulate(tmp_path, capsys, *args):
    """Exit code and the error line of `simulate` with ``args``."""
    with pytest.raises(SystemExit) as e:
        main(["simulate", *args, "--out", str(tmp_path / "run.parquet"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert not (tmp_path / "run.parquet").exists()
    return e.value.code, err[-1]


# ------------------------------------------------------------------ case 1: resolution and domain


@pytest.mark.parametrize(
    "args,option,bound",
    [
        (["--method", "fd", "--fd-length", "1e6"], "--fd-length", f"{300 * E_FINAL:.6g}"),  # dx = 3333 vs E = 5.8
        (["--t-final", "1e12"], "--omega", f"{2 * math.sqrt(2 * D * 1e12):.6g}"),  # plume 9e4 wide, Omega 10
        (["--omega", "1e-6"], "--omega", f"{WIDTH:.6g}"),  # a domain a millionth of the plume
    ],
    ids=["fd-length 1e6", "t-final 1e12", "omega 1e-6"],
)
def test_tester_runs_that_scored_extreme_comic_are_refused_naming_option_and_range(
    tmp_path, capsys, args, option, bound
):
    code, line = _simulate(tmp_path, capsys, *args)
    assert code == 2
    assert f"error: {option}:" in line and "is not allowed" in line
    assert bound in line, line


def test_grid_spacing_is_bounded_by_the_plumes_dilution_index_at_t_final():
    # dx = L / n just below and just above E(t_final): the settling time dV^2 / (4 pi e D) of Section 3
    n = 300
    RunConfig.of(method="fd", n=n, fd_length=0.999 * n * E_FINAL).resolved()
    with pytest.raises(SettingError) as e:
        RunConfig.of(method="fd", n=n, fd_length=1.001 * n * E_FINAL).resolved()
    assert e.value.name == "fd_length"
    assert f"[{WIDTH:.6g}, {n * E_FINAL:.6g}]" in e.value.allowed


def test_mtpt_domain_at_rest_must_hold_the_plume():
    RunConfig.of(method="mtpt", n=300, omega=1.001 * WIDTH).resolved()
    with pytest.raises(SettingError) as e:
        RunConfig.of(method="mtpt", n=300, omega=0.999 * WIDTH).resolved()
    assert e.value.name == "omega" and f"{WIDTH:.6g}" in e.value.allowed


def test_a_config_drawing_fig8_on_a_million_long_domain_is_refused():
    cfg = copy.deepcopy(BASE)
    cfg["physics"]["fd_length"] = 1.0e6
    with pytest.raises(SettingError) as e:
        check_config(cfg)
    assert str(e.value).startswith("physics.fd_length=1000000.0 is not allowed")
    assert f"{30 * E_FINAL:.6g}" in str(e.value)  # Fig. 8's coarsest grid, n = 30


@pytest.mark.parametrize("path", [ROOT / "config.yaml", TINY], ids=["config.yaml", "tiny"])
def test_shipped_configs_still_pass(path, capsys):
    assert main(["check-config", str(path)]) == 0
    captured = capsys.readouterr()
    assert "accepted" in captured.out + captured.err


def test_paper_runs_at_their_coarsest_settings_stay_valid():
    # Fig. 8's coarsest grid, Fig. 9's fewest particles, the fd_domain experiment's grids and lengths
    RunConfig.of(method="fd", kernel="implicit", n=30).resolved()
    RunConfig.of(method="mtpt", kernel="collision", n=30).resolved()
    for n in (1000, 3000, 10000):
        for length in (12.0, 24.0):
            m = grid_intervals(n, length, 12.0)
            RunConfig.of(method="fd", kernel="implicit", n=m, fd_length=length).resolved()


# ------------------------------------------------------------------ case 2: shear dispersivities


def test_shear_alpha_t_whose_step_crosses_the_channel_is_refused():
    from particle_entropy.models.shear2d import ShearConfig

    # a step's sd sqrt(2 alpha_T v_max dt), v_max = 1/4, at most a tenth of the width 1: alpha_T dt <= 0.02
    ShearConfig(case="rw_nodrift", alpha_T=0.0199)
    for case in ("rw_nodrift", "rw_drift", "mt"):
        with pytest.raises(SettingError) as e:
            ShearConfig(case=case, alpha_T=0.0201)
        assert e.value.name == "alpha_T" and "[0, 0.02]" in e.value.allowed
    with pytest.raises(SettingError) as e:
        ShearConfig(case="rw_drift", alpha_T=0.0101, dt=2.0)
    assert "[0, 0.01]" in e.value.allowed


def test_shear_alpha_l_whose_step_wraps_the_domain_is_refused():
    from particle_entropy.models.shear2d import ShearConfig

    limit = (0.1 * 400.0) ** 2 / (2 * 0.25 * 1.0)  # sd <= length / 10
    ShearConfig(case="rw_nodrift", alpha_L=0.99 * limit)
    with pytest.raises(SettingError) as e:
        ShearConfig(case="rw_nodrift", alpha_L=1e300)
    assert e.value.name == "alpha_L" and f"{limit:g}" in e.value.allowed


def test_a_config_with_shear_alpha_t_1e300_is_refused(capsys):
    cfg = copy.deepcopy(BASE)
    cfg["shear"]["alpha_T"] = 1.0e300
    with pytest.raises(SettingError) as e:
        check_config(cfg)
    assert str(e.value).startswith("shear.alpha_T=1e+300 is not allowed: a number in [0, 0.02]")


# ------------------------------------------------------------------ case 3: FD that loses or invents


def test_fd_with_two_intervals_is_refused(tmp_path, capsys):
    code, line = _simulate(tmp_path, capsys, "--method", "fd", "--n", "2")
    assert code == 2 and "error: --n: n=2 is not allowed" in line and ">= 4" in line
    with pytest.raises(SettingError, match="fits an even whole number"):
        grid_intervals(2, 12.0, 12.0)


def test_explicit_fd_at_r_one_half_is_refused_and_just_below_runs(tmp_path, capsys):
    # n = 300 on 12: dx = 0.04; r = D dt / dx^2 = 1/2 at dt = 0.8 (checkerboard factor 1 - 4 r = -1)
    code, line = _simulate(tmp_path, capsys, "--method", "fd", "--kernel", "explicit", "--n", "300", "--dt0", "0.8")
    assert code == 2 and "error: --dt0: dt0=0.8 is not allowed" in line and "r = D dt / dx^2 < 1/2" in line
    RunConfig.of(method="fd", kernel="explicit", n=300, dt0=0.79).resolved()


def test_coarse_fd_conserves_mass_up_to_its_boundary_outflow():
    from particle_entropy.models import fd
    from particle_entropy.models.simulate import run

    cfg = RunConfig.of(method="fd", n=4, fd_length=4.0, t_final=100.0)
    table = run(cfg)[0]
    x, dx = fd.grid(cfg.resolved())
    # mass leaves only through the zero ends: check it by the flux r (c_1 + c_M) of each step
    assert table["mass_total"].iloc[-1] < 1.0
    assert np.all(np.diff(table["mass_total"]) <= 0.0)
    assert dx == 1.0 and x.size == 5


def test_an_fd_step_that_loses_mass_raises_naming_the_mass_error(monkeypatch):
    from particle_entropy.models import fd
    from particle_entropy.models.simulate import run

    real = fd.kernels()

    class Leaky:  # the compiled solve, losing a millionth of each step's mass
        def __getattr__(self, name):
            return getattr(real, name)

        def thomas_solve(self, *args):
            return real.thomas_solve(*args) * (1.0 - 1e-6)

    monkeypatch.setattr(fd, "kernels", lambda: Leaky())
    cfg = RunConfig.of(method="fd", kernel="implicit", n=30, t_final=100.0)
    with pytest.raises(fd.MassError, match=r"^fd step lost mass: mass error [-0-9.e]+ .* beyond round-off"):
        run(cfg)


def test_explicit_step_balance_detects_a_lost_mass():
    from particle_entropy.models import fd

    c = np.exp(-(np.linspace(-3, 3, 29) ** 2))
    r = 0.4
    good = fd.ExplicitSolver(c.size, r).solve(c)  # balances: no raise
    outflow = r * (c[0] + c[-1])
    assert abs(c.sum() - good.sum() - outflow) < 1e-13  # the sums of 29 terms near 8, to round-off
    with pytest.raises(fd.MassError, match="mass error"):
        fd.check_balance(c, good * (1.0 - 1e-9), outflow, 1.0 + 4.0 * r)


@pytest.mark.parametrize("scheme", ["symmetric", "sequential"])
def test_a_particle_transfer_that_loses_mass_is_a_failure_not_a_score(monkeypatch, scheme):
    """MTPT's total mass is checked at every step: a transfer that loses 0.1 % raises MassError
    naming the error, whichever scheme (the matrix, or the authors' loop with its clipping)."""
    from particle_entropy.models import simulate
    from particle_entropy.models.conservation import PARTICLE_MASS_TOLERANCE, MassError
    from particle_entropy.numerics import mass_transfer, sequential

    cfg = RunConfig.of("mtpt", "collision", 100, scheme=scheme, truncation=3.0, t_final=5.0).resolved()
    simulate.run(cfg)  # as written: the mass holds to round-off
    if scheme == "symmetric":
        real = mass_transfer.mass_transfer

        def leaky(*args, **kwargs):
            res = real(*args, **kwargs)
            return dataclasses.replace(res, mass=res.mass * 0.999)

        monkeypatch.setattr(mass_transfer, "mass_transfer", leaky)
    else:
        real_seq = sequential.sequential_transfer
        monkeypatch.setattr(sequential, "sequential_transfer", lambda *a, **k: real_seq(*a, **k) * 0.999)
    with pytest.raises(MassError, match=r"^mtpt lost mass: total 0\.99[0-9]+ at t = [0-9.e-]+, an error of -0\.00"):
        simulate.run(cfg)
    assert PARTICLE_MASS_TOLERANCE < 1e-3 * 1e-3  # far below the 0.1 % lost here
