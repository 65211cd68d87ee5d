"""FD's tvd advection (models/fd.py: Leonard's ULTIMATE-QUICKEST, split from backward-Euler
dispersion): total variation, extrema, the exact shift at Courant 1, the mass balance, the order
of convergence and a carried box, against the implicit upwind and central schemes."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.sources import Source
from particle_entropy.models import fd, simulate
from particle_entropy.models.conservation import MassError

EPS = np.finfo(np.float64).eps
BOX = Source.of("box", a=-1.0, b=-0.6)  # 1 / width = 2.5


def _box_nodes(m: int = 200, lo: int = 60, hi: int = 90) -> np.ndarray:
    c = np.zeros(m)
    c[lo:hi] = 1.0
    return c


def _tv(c: np.ndarray) -> float:
    """Total variation of the interior between the zero end nodes."""
    return float(np.abs(np.diff(np.concatenate([[0.0], c, [0.0]]))).sum())


def _config(n, scheme, D=1e-5, v=1.0, t_final=1.0, courant=0.5, source=BOX, fd_length=4.0) -> RunConfig:
    return RunConfig.of(
        method="fd",
        kernel="implicit",
        n=n,
        D=D,
        t_final=t_final,
        fd_length=fd_length,
        source=source,
        v=v,
        advection=scheme,
        courant=courant,
    ).resolved()


def _final(cfg: RunConfig):
    """(nodes, c at t_final, exact c there, dx): the run's solver stepped to t_final."""
    x, dx = fd.grid(cfg)
    c = fd.initial_concentration(cfg)
    steps = round(cfg.t_final / cfg.dt0)
    assert steps * cfg.dt0 == pytest.approx(cfg.t_final, rel=1e-12)
    solve = fd.solver(cfg, cfg.dt0, dx).solve
    for _ in range(steps):
        c[1:-1] = solve(c[1:-1])
    return x, c, cfg.reference(cfg.t_final).density(x), dx


@pytest.mark.parametrize("p", [0.1, 0.37, 0.5, 0.83, 1.0, -0.37, -0.83])
def test_pure_advection_of_a_box_never_grows_its_variation_nor_an_extremum(p):
    """The advection substep alone (no dispersion), 150 steps carrying a box and a ragged stretch
    (uniform noise in [0, 1]) to and through an end: TV never grows, and nothing falls below 0 or
    rises above the initial 1, to round-off."""
    c = _box_nodes()
    c[120:150] = np.random.default_rng(7).random(30)
    tv = _tv(c)
    for _ in range(150):
        c, _ = fd.advect_tvd(c, p)
        assert _tv(c) <= tv * (1.0 + 16 * EPS)
        assert c.min() >= -16 * EPS and c.max() <= 1.0 + 16 * EPS
        tv = _tv(c)


def test_the_split_step_keeps_variation_and_bounds_with_dispersion_too():
    """Backward-Euler dispersion is monotone as well: the whole TVDSolver step keeps them."""
    solver = fd.TVDSolver(200, r=0.3, p=0.6)
    c = _box_nodes()
    tv = _tv(c)
    for _ in range(100):
        c = solver.solve(c)
        assert _tv(c) <= tv * (1.0 + 16 * EPS)
        assert c.min() >= -16 * EPS and c.max() <= 1.0 + 16 * EPS
        tv = _tv(c)


@pytest.mark.parametrize("p", [1.0, -1.0])
def test_at_courant_1_pure_advection_is_a_shift_of_one_cell(p):
    rng = np.random.default_rng(40)
    c = rng.random(64)
    out, outflow = fd.advect_tvd(c, p)
    shifted = np.concatenate([[0.0], c[:-1]]) if p > 0 else np.concatenate([c[1:], [0.0]])
    assert np.abs(out - shifted).max() <= 2 * EPS
    assert outflow == pytest.approx(c[-1] if p > 0 else c[0], rel=4 * EPS)


def test_a_courant_1_run_steps_at_exactly_1():
    """dt = courant dx / |v| read back as |v| dt / dx is 1 to an ulp: the solver takes it as 1,
    and the carried box reaches t_final as the exact shift (its shape unchanged but for D)."""
    cfg = _config(100, "tvd", courant=1.0)
    _, dx = fd.grid(cfg)
    assert fd.solver(cfg, cfg.dt0, dx).p == 1.0
    assert cfg.courant_number() == pytest.approx(1.0, rel=1e-15)


def test_mass_balances_every_step_and_the_outflow_is_what_crosses_the_end():
    """A box carried past the right end: every substep passes check_balance (else MassError) and
    the mass lost equals the summed flux through the end faces."""
    solver = fd.TVDSolver(120, r=0.0, p=0.7)
    c = _box_nodes(120, 80, 110)
    start, out = c.sum(), 0.0
    for _ in range(60):
        new, flux = fd.advect_tvd(c, 0.7)
        c = solver.advect(c)
        assert np.array_equal(c, new)
        out += flux
    assert c.sum() < 0.1 * start  # most of it left
    assert start - c.sum() == pytest.approx(out, rel=1e-13)


def test_a_broken_flux_raises_mass_error(monkeypatch):
    """A face whose flux differs for the two cells it joins, or an outflow left uncounted, is a
    mass error of the step, not a score."""
    honest = fd.advect_tvd
    c = _box_nodes(120, 80, 110)
    solver = fd.TVDSolver(120, r=0.1, p=0.7)

    def leaky(values, p):
        out, outflow = honest(values, p)
        out[85] += 1e-9  # one cell gains what its neighbour did not lose
        return out, outflow

    monkeypatch.setattr(fd, "advect_tvd", leaky)
    with pytest.raises(MassError, match="mass error"):
        solver.solve(c)

    def uncounted(values, p):
        return honest(values, p)[0], 0.0

    monkeypatch.setattr(fd, "advect_tvd", uncounted)
    c = _box_nodes(120, 100, 120)  # at the end: mass leaves in the first step
    with pytest.raises(MassError):
        solver.solve(c)


def _l2(scheme: str, n: int) -> float:
    smooth = Source.of("gaussian", x0=-0.5, sd=0.2)
    x, c, exact, dx = _final(_config(n, scheme, D=1e-4, source=smooth))
    return math.sqrt(np.sum((c - exact) ** 2) * dx)


def test_tvd_converges_faster_than_upwind_and_central_at_fixed_courant():
    """A Gaussian (sd 0.2) carried 1 by v = 1 with D = 1e-4, Courant 0.5, n = 200, 400, 800. Measured
    L2 errors: tvd 2.6e-3, 4.8e-4, 8.7e-5 (orders 2.45, 2.45); implicit upwind 0.31, 0.19, 0.11
    (0.72, 0.83, rising to 1); implicit central 0.135, 0.073, 0.038 (0.89, 0.94: at fixed Courant
    the backward-Euler step, dt ~ dx, makes both first order)."""
    errors = {s: [_l2(s, n) for n in (200, 400, 800)] for s in ("tvd", "upwind", "central")}
    orders = {s: [math.log2(a / b) for a, b in zip(e, e[1:])] for s, e in errors.items()}
    assert min(orders["tvd"]) > 2.2, orders
    assert max(orders["upwind"]) < 1.1, orders
    assert max(orders["central"]) < 1.1, orders
    assert errors["tvd"][0] < errors["central"][-1] / 10  # tvd at 200 beats central at 800


def test_a_carried_box_stays_in_its_bounds_where_central_oscillates_and_upwind_smears():
    """The box [-1, -0.6] (height 2.5) carried 1 by v = 1, D = 1e-5, Courant 0.5, n = 100
    (dx = 0.05). Measured: tvd min 0, max 2.5 (the exact's), L2 error 0.24; implicit central min
    -0.056, max 2.006, L2 0.62; implicit upwind min 0 but its peak falls to 1.35 (by 46 %), L2 0.90."""
    height = 2.5
    got = {s: _final(_config(100, s)) for s in ("tvd", "central", "upwind")}
    _, tvd, exact, dx = got["tvd"]
    assert tvd.min() >= -4 * EPS * height and tvd.max() <= height * (1 + 4 * EPS)
    assert tvd.max() > 0.99 * height  # its top survives the trip
    central, upwind = got["central"][1], got["upwind"][1]
    assert central.min() < -0.02 * height
    assert upwind.min() >= 0.0 and upwind.max() < 0.6 * height
    l2 = {s: math.sqrt(np.sum((c - exact) ** 2) * dx) for s, (_, c, _, _) in got.items()}
    assert l2["tvd"] < 0.5 * l2["central"] < 0.5 * l2["upwind"], l2


def test_a_tvd_run_balances_its_mass_through_the_time_loop():
    """simulate.run steps a courant run to t_final on its exact grid; every step balances."""
    cfg = _config(64, "tvd", D=1e-3, courant=0.8, source=Source.of("gaussian", x0=-0.5, sd=0.2))
    table, state = simulate.run(cfg, want_state=True)
    assert table["time"].iloc[-1] == pytest.approx(1.0)
    assert table["mass_total"].iloc[-1] == pytest.approx(1.0, abs=1e-6)
    assert table["mass_min"].min() >= 0.0


@pytest.mark.parametrize(
    "settings, name, says",
    [
        ({"courant": 1.5}, "courant", "(0, 1]"),
        ({"courant": None, "dt0": 0.1}, "fd_dt", "at n = 100"),
        ({"courant": 0.0}, "courant", "> 0"),
        ({"courant": 0.5, "v": 0.0, "source": Source.of("gaussian", x0=0.1, sd=0.2)}, "courant", "v != 0"),
        ({"courant": 0.5, "method": "mtpt", "kernel": "collision"}, "courant", "fd in a flow"),
    ],
)
def test_a_courant_number_the_scheme_cannot_take_is_refused(settings, name, says):
    base = dict(method="fd", kernel="implicit", n=100, D=1e-4, t_final=1.0, fd_length=4.0, source=BOX, v=1.0)
    base.update(advection="tvd", courant=0.5)
    base.update(settings)
    with pytest.raises(SettingError, match=re.escape(says)) as e:
        RunConfig.of(**base).resolved()
    assert e.value.name == name


def test_the_implicit_schemes_take_any_courant_number():
    for scheme in ("upwind", "central"):
        cfg = _config(100, scheme, courant=7.5)
        assert cfg.courant_number() == pytest.approx(7.5)
        assert cfg.dt0 == pytest.approx(7.5 * (4.0 + 1.0) / 100)  # dx of the grid spanning the path


@pytest.mark.parametrize("p", [1.0, 0.83, 0.37, 0.1, 1e-9, -0.37, -1.0])
def test_the_compiled_step_gives_the_numpy_steps_bits(p):
    """advect_tvd (numerics/thomas.tvd_advect) against its readable numpy form on a box, a Gaussian,
    noise and a single node: the same bytes, faces, outflow and all."""
    rng = np.random.default_rng(5)
    x = np.linspace(-1.0, 1.0, 301)
    for c in (
        np.where(np.abs(x) < 0.3, 2.5, 0.0),
        np.exp(-(x**2) / 0.02),
        rng.random(301) * (np.abs(x) < 0.5),
        np.eye(1, 7, 3).ravel(),
    ):
        want, want_out = fd.advect_tvd_numpy(c, p)
        got, got_out = fd.advect_tvd(c, p)
        assert got.tobytes() == want.tobytes() and got_out == want_out
