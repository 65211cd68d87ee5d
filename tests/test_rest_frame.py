"""Particle runs computed at rest (scenes/scene.py, Scene.runs_at_rest): a particle plume in a uniform
flow is the plume at rest carried by v t (Galilean invariance), so a conservative scene's PT and MTPT
runs are computed at v = 0, shared by scenes that differ only in v, and carried back where a consumer
needs the plume where it is (figures/scene_maps.py).

The run tables agree to relative 1e-9 on every float column, with an absolute floor where a relative
bound means nothing: 1e-8 nats for the columns on a log scale (H_*, AIC, COMIC, COMIC_points), which
cross zero (COMIC = 2 ln(SSE / n) - ln dV: its error twice the SSE's relative one); 1e-13 for masses (of
the unit total; the smallest particle mass is subnormal in MTPT's far tail). The two runs differ only by
the round-off of x + v t: at v t = 100 a position carries ulp(100) = 1.4e-14 against the plume's width
sqrt(2 D t) = 0.14, 1e-13 relative, which the measures' sums carry through. Measured: the errors SSE
and SSE_points within 3.5e-10 relative, the logs within 6.9e-10 nats and masses within 6.7e-15, over
54 of the shipped sweep's, carried's and spill's particle run files (N = 30 to 16,000, up to 2,024 steps,
the old code's runs at v against this code's at rest); in 2-D (plume2d and oblique, N = 1,000 to 16,000)
within 5e-14 relative.
"""

from __future__ import annotations

import math
from dataclasses import replace

import matplotlib
import numpy as np
import pandas as pd
import pytest
from conftest import ROOT

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402

from particle_entropy.core.records import TIMING_COLUMNS  # noqa: E402
from particle_entropy.core.reference2d import Reference2D  # noqa: E402
from particle_entropy.figures import scene_maps as SM  # noqa: E402
from particle_entropy.models.simulate import run_seeds_arrow  # noqa: E402
from particle_entropy.pipeline.configcheck import load_yaml  # noqa: E402
from particle_entropy.scenes.scene import Scene, peclet_scenes, scenes  # noqa: E402

REL = 1e-9  # the tables' agreement (module docstring: round-off of x + v t, measured at most 3.5e-10)
LOG_ATOL = 1e-8  # nats, where a column on a log scale crosses zero (measured at most 6.9e-10)
MASS_ATOL = 1e-13  # of the unit total mass (measured at most 6.7e-15)
CONFIG = dict(load_yaml(ROOT / "config.yaml"))
MTPT = {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [300, 8000]}
PT = {"method": "pt", "kernel": "adaptive", "n_range": [300, 64000]}
PLUME2D = {
    "v": [0.5, 0.0],
    "D": {"L": 1.0e-2, "T": 1.0e-3},
    "t_final": 4.0,
    "source": {"kind": "point", "x0": [0.0, 0.0]},
    "target": {"measure": "rmse", "value": 0.025},
    "candidates": [MTPT, PT],
}


def _sweep_base_at(v: float) -> dict:
    """The shipped Peclet sweep's scene (config.yaml's scenes_peclet) at velocity v, as written."""
    return next(s for s in peclet_scenes(CONFIG).values() if s["v"] == v)


def _atol(col: str) -> float:
    """The absolute floor of a column's agreement (module docstring): logs and masses; 0 for the rest."""
    if col.startswith(("H_", "AIC", "COMIC")):
        return LOG_ATOL
    return MASS_ATOL if col.startswith("mass_") else 0.0


def _agree(rest: pd.DataFrame, moving: pd.DataFrame) -> None:
    """Every column of two run tables equal, the floats to REL (and _atol; NaN and inf where the other
    has them), the measured wall times and memory aside."""
    assert list(rest.columns) == list(moving.columns)
    for col in rest.columns:
        if col in TIMING_COLUMNS:
            continue
        a, b = rest[col], moving[col]
        if a.dtype.kind != "f":
            assert a.equals(b), col
            continue
        a, b = a.to_numpy(), b.to_numpy()
        np.testing.assert_allclose(a, b, rtol=REL, atol=_atol(col), equal_nan=True, err_msg=col)


def _scene_run_and_carried(scene: Scene, ci: int, n: int, seeds) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The scene's run of candidate ci (its jobs' RunConfig, at rest) and the same run computed at the
    scene's v by the models directly."""
    cand = scene.candidates[ci]
    rest = scene.run_config(cand, n, seed=seeds[0])
    moving = replace(rest, v=scene.v)
    assert rest.v in (0.0, (0.0, 0.0)) and moving.v == scene.v and any(np.atleast_1d(moving.v))
    assert moving == scene.run_config(cand, n, seed=seeds[0], carried=True)
    return run_seeds_arrow(rest, seeds).to_pandas(), run_seeds_arrow(moving, seeds).to_pandas()


@pytest.mark.parametrize("method", ["mtpt", "pt"])
def test_a_particle_run_at_rest_is_the_carried_run_on_the_line(method):
    """The sweep's base at v = 1 (its plume carried 100, some 700 of its widths sqrt(2 D t_final) =
    0.14, by t_final = 100): the scene's run at rest and the run at v agree on every column."""
    scene = Scene.from_config("peclet-4", _sweep_base_at(1.0))
    ci = next(i for i, c in enumerate(scene.candidates) if c.case.method == method)
    assert scene.runs_at_rest(scene.candidates[ci]) and scene.frame_shift(scene.candidates[ci], 100.0) == 100.0
    rest, moving = _scene_run_and_carried(scene, ci, 300, [7, 8])
    last = rest.groupby("seed").tail(1)
    assert np.all(last["SSE_points"] > 0) and np.all(np.isfinite(last["COMIC_points"]))  # a plume was measured
    _agree(rest, moving)


@pytest.mark.parametrize("ci", [0, 1], ids=["mtpt", "pt"])
@pytest.mark.parametrize(
    "v", [[0.5, 0.0], [-0.5, 0.0], [0.3535533905932738, 0.3535533905932738]], ids=["along-x", "back", "oblique"]
)
def test_a_particle_run_at_rest_is_the_carried_run_in_the_plane(v, ci):
    """A plume2d-like scene (D_L = 10 D_T along v, t_final = 4): the run at rest and at v agree; back
    along -x the lattice's axes turn by half a turn (Reference2D.axes), which only reorders its points."""
    scene = Scene.from_config("plane", {**PLUME2D, "v": v})
    assert scene.runs_at_rest(scene.candidates[ci])
    rest, moving = _scene_run_and_carried(scene, ci, 500, [3])
    assert rest["SSE_points"].iloc[-1] > 0
    _agree(rest, moving)


def test_the_sweep_s_particle_runs_have_one_identity_across_v():
    """The shipped Peclet sweep: its particle candidates' runs (and their half-step twins') have one
    identity at every v, so its scenes share their files; FD's differ at every v."""
    got = scenes({"scenes_peclet": CONFIG["scenes_peclet"]})
    sweep = [got[name] for name in got.sweep]
    assert len({s.v for s in sweep}) == len(sweep) >= 3 and sweep[0].v == 0.0
    methods = [c.case.method for c in sweep[0].candidates]
    assert {"fd", "pt", "mtpt"} <= set(methods)
    for i, method in enumerate(methods):
        ids = {s.identity(s.candidates[i]) for s in sweep}
        halves = {s.identity(s.half_step(s.candidates[i])) for s in sweep}
        if method == "fd":
            assert len(ids) == len(halves) == len(sweep), i
        else:
            assert len(ids) == len(halves) == 1, i
            assert all(s.settings(s.candidates[i])["v"] == 0.0 for s in sweep)


def test_a_reactive_scene_s_particle_runs_keep_their_v():
    """A reaction's B need not move with A: a reactive scene's particle runs are computed at its v."""
    spec = CONFIG["scenes"]["carried_reaction"]
    a, b = (Scene.from_config("r", {**spec, "v": v}) for v in (0.5, 0.25))
    particles = [i for i, c in enumerate(a.candidates) if c.case.method != "fd"]
    assert particles
    for i in particles:
        assert not a.runs_at_rest(a.candidates[i]) and a.frame_shift(a.candidates[i], 50.0) == 0.0
        assert a.settings(a.candidates[i])["v"] == 0.5 and a.run_config(a.candidates[i], 300).v == 0.5
        assert a.identity(a.candidates[i]) != b.identity(b.candidates[i])


def test_an_isotropic_plume_in_an_oblique_flow_keeps_its_v():
    """An isotropic plume's measurement lattice is laid along v (Reference2D.axes): at rest it would lie
    along x, other points, so its particle runs keep v; along x the lattice is one and they run at rest."""
    iso = {**PLUME2D, "D": {"x": 1.0e-2, "y": 1.0e-2}}
    oblique = Scene.from_config("o", {**iso, "v": [0.3, 0.4]})
    pt = oblique.candidates[1]
    assert not oblique.runs_at_rest(pt) and oblique.settings(pt)["v"] == [0.3, 0.4]
    assert np.all(oblique.frame_shift(pt, 4.0) == 0.0)
    rest = Reference2D(oblique.source, oblique.D, (0.0, 0.0), oblique.t_final).points() + np.array([0.3, 0.4]) * 4.0
    assert np.max(np.abs(rest - oblique.points)) > 0.1  # the reason: another lattice
    along = Scene.from_config("x", {**iso, "v": [0.5, 0.0]})
    assert along.runs_at_rest(along.candidates[1]) and along.settings(along.candidates[1])["v"] == [0.0, 0.0]
    assert list(along.frame_shift(along.candidates[1], 4.0)) == [2.0, 0.0]


@pytest.mark.parametrize("ci", [0, 1], ids=["mtpt", "pt"])
def test_the_map_of_a_carried_particle_answer_is_where_the_plume_is(ci):
    """figures/scene_maps: a particle answer run at rest is drawn carried by v t_final: the map holds its
    mass, its centre lies within one spacing along v of the measurement lattice of the exact one's (2 away,
    off the map, without the shift), and its RMSE at the scene's points is the one its run was scored
    with."""
    from particle_entropy.models.simulate import run

    scene = Scene.from_config("plane", PLUME2D)
    cand = scene.candidates[ci]
    table = pd.DataFrame([{"candidate": ci, "n": 2000, "label": cand.label, "recommended": True}])
    model = SM.model_run(scene, table, base_seed=3)
    assert model.cfg.v == (0.0, 0.0)  # computed at rest
    fig = Figure(layout="constrained")
    cx, dx, cax = fig.subplots(1, 3, width_ratios=[1, 1, 0.05])
    maps = SM.draw_maps((cx, dx), cax, scene, model, nodes=200)
    cell = (maps.x[1] - maps.x[0]) * (maps.y[1] - maps.y[0])
    gx, gy = np.meshgrid(maps.x, maps.y, indexing="ij")
    mass = [float(m.sum() * cell) for m in (maps.exact, maps.model)]
    assert mass[1] == pytest.approx(mass[0], rel=0.25)  # the model's plume on the map (0 without the shift)
    (ex, ey), (mx, my) = (
        (float((m * gx).sum() / m.sum()), float((m * gy).sum() / m.sum())) for m in (maps.exact, maps.model)
    )
    sd, _ = scene.reference.axes()
    spacing = 6.0 * sd[0] / 14.0  # the 15 x 15 lattice's spacing along v (+- 3 sd): 0.12
    assert math.hypot(mx - ex, my - ey) <= spacing  # the model's centre where the exact one's is
    scored, _ = run(model.cfg)
    assert maps.rmse == pytest.approx(math.sqrt(scored["SSE_points"].iloc[-1] / scene.n_points), rel=REL)


def test_a_scene_s_checks_judge_its_particle_runs_at_its_v():
    """A run at rest stands for the scene's carried run, and the checks judge that one: PT's particle
    domain must hold a carried plume (at rest, the paper's PT at the origin is exempt), as before."""
    from particle_entropy.core.case import SettingError

    spec = {"D": 1e-4, "t_final": 100.0, "omega": 0.2, "target": {"value": 0.05}, "candidates": [PT]}
    with pytest.raises(SettingError, match=r"scenes\.s\.omega=0\.2 .* a domain >= 2 sqrt\(2 D t_final\)"):
        Scene.from_config("s", {**spec, "v": 1.0})
    Scene.from_config("s", {**spec, "v": 0.0})  # at rest it runs
