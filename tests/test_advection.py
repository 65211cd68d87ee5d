"""Advection in every model (a scene's uniform v): FD's upwind and central schemes against the exact
solution, and particles carried by v t exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.core.records import TIMING_COLUMNS
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.sources import Source
from particle_entropy.models import fd, simulate

SMOOTH = Source.of("gaussian", x0=-0.5, sd=0.2)


def _fd_final(n: int, scheme: str, D: float, v: float, t_final: float, dt: float, source=SMOOTH):
    """(nodes, c at t_final, exact c there, dx) of an implicit FD run with advection."""
    cfg = RunConfig.of(
        method="fd",
        kernel="implicit",
        n=n,
        D=D,
        t_final=t_final,
        dt0=dt,
        fd_length=4.0,
        source=source,
        v=v,
        advection=scheme,
    ).resolved()
    x, dx = fd.grid(cfg)
    c = fd.initial_concentration(cfg)
    steps = round(t_final / dt)
    solve = fd.solver(cfg, dt, dx).solve
    for _ in range(steps):
        c[1:-1] = solve(c[1:-1])
    return x, c, cfg.reference(t_final).density(x), dx


def _l2(n, scheme):
    D, v, T = 0.01, 1.0, 1.0
    dx = (4.0 + v * T) / n
    x, c, exact, dx = _fd_final(n, scheme, D, v, T, dt=T / round(T / (0.5 * dx * dx)))  # dt ~ dx^2 / 2
    return math.sqrt(np.sum((c - exact) ** 2) * dx)


@pytest.mark.parametrize("scheme, order", [("upwind", 1.0), ("central", 2.0)])
def test_fd_advection_converges_at_the_schemes_order(scheme, order):
    errors = [_l2(n, scheme) for n in (160, 320, 640)]
    rates = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert all(abs(r - order) < 0.2 for r in rates), (errors, rates)


def test_upwind_adds_the_numerical_dispersion_v_dx_over_2():
    """The plume's variance grows as 2 (D + v dx / 2 + v^2 dt / 2) t under implicit upwind."""
    D, v, T, n, dt = 1e-3, 1.0, 1.0, 250, 1e-3
    x, c, _, dx = _fd_final(n, "upwind", D, v, T, dt)
    mass = c.sum() * dx
    mean = (x * c).sum() * dx / mass
    var = ((x - mean) ** 2 * c).sum() * dx / mass
    d_eff = (var - SMOOTH.sd**2) / (2 * T)
    assert d_eff == pytest.approx(D + v * dx / 2 + v * v * dt / 2, rel=0.03)
    assert d_eff > 5 * D  # the grid's dispersion, not D, spreads this plume
    assert mass == pytest.approx(1.0, abs=1e-12)
    assert mean == pytest.approx(SMOOTH.x0 + v * T, abs=1e-3)


def test_central_oscillates_past_grid_peclet_2_and_upwind_stays_monotone():
    D, v, n, T, dt = 1e-4, 1.0, 100, 1.0, 0.01
    box = Source.of("box", a=-1.0, b=-0.6)
    dx = (4.0 + v * T) / n
    assert fd.grid_peclet(v, dx, D) == pytest.approx(500.0)
    _, central, _, _ = _fd_final(n, "central", D, v, T, dt, box)
    _, upwind, _, _ = _fd_final(n, "upwind", D, v, T, dt, box)
    assert central.min() < -1e-3 * central.max()
    assert upwind.min() >= 0.0
    gentle = fd.grid_peclet(v, 5.0 / 4000, 1e-3)
    assert gentle == pytest.approx(1.25)
    _, calm, _, _ = _fd_final(4000, "central", 1e-3, v, T, dt, box)
    assert calm.min() > -1e-6 * calm.max()


@pytest.mark.parametrize(
    "method, kernel, eta",
    [("mtpt", "collision", 1.0), ("mtpt", "collision", 0.5), ("mtpt", "sph", 1.0), ("pt", "fixed", 1.0)],
)
def test_particles_are_carried_by_v_t_and_the_transfer_is_unchanged(method, kernel, eta):
    settings = dict(method=method, kernel=kernel, n=300, D=1e-3, t_final=50.0, seed=4)
    if method == "mtpt":
        settings["eta"] = eta
    v = 0.013
    at_rest = RunConfig.of(**settings, source=Source.of("point", x0=0.25))
    carried = RunConfig.of(**settings, source=Source.of("point", x0=0.25), v=v)
    _, still = simulate.run(at_rest, want_state=True)
    table, moved = simulate.run(carried, want_state=True)
    shift = np.asarray(moved["x"]) - np.asarray(still["x"])
    assert np.allclose(shift, v * 50.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(moved["mass"], still["mass"], rtol=0, atol=1e-14)
    # measured against the carried reference: the same fit as the run at rest
    rest_table = simulate.run(at_rest)[0]
    np.testing.assert_allclose(table["SSE_points"], rest_table["SSE_points"], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(table["H_C"], rest_table["H_C"], rtol=0, atol=1e-10)


def test_a_paper_run_is_untouched_by_the_scene_fields():
    """v = 0 and a point at 0 are the paper's scene: the same bits as a run that names neither."""
    plain = RunConfig.of(method="mtpt", kernel="collision", n=200, seed=3, t_final=20.0)
    named = RunConfig.of(
        method="mtpt", kernel="collision", n=200, seed=3, t_final=20.0, source=Source.of("point"), v=0.0
    )
    a, b = simulate.run(plain)[0], simulate.run(named)[0]
    cols = [c for c in a.columns if c not in TIMING_COLUMNS]
    assert a[cols].equals(b[cols])


@pytest.mark.parametrize(
    "settings, key",
    [
        (dict(method="fd", kernel="implicit", n=100, fd_length=1.0, source=Source.of("gaussian", sd=2.0)), "fd_length"),
        (dict(method="mtpt", n=100, omega=1.0, source=Source.of("box", a=-3.0, b=3.0)), "omega"),
        (dict(method="pt", n=100, v=math.inf), "v"),
        (dict(method="fd", kernel="implicit", n=100, v=1.0, advection="lax"), "advection"),
    ],
)
def test_a_scene_that_does_not_fit_is_refused_naming_the_key(settings, key):
    with pytest.raises(SettingError) as err:
        RunConfig.of(**settings).resolved()
    assert err.value.name == key
