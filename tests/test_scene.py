"""A scene from config (scenes/scene.py): defaults, domains, identity, ladders and refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.core.timegrid import MAX_STEPS
from particle_entropy.scenes.scene import Scene, scenes

FD = {"method": "fd", "kernel": "implicit", "n_range": [16, 1000]}
MTPT = {"method": "mtpt", "kernel": "collision", "n_range": [30, 3000]}
PT = {"method": "pt", "kernel": "adaptive"}


def spec(**over):
    out = {"v": 0.01, "t_final": 50.0, "target": {"value": 0.02}, "candidates": [FD, MTPT]}
    out.update(over)
    return out


def test_defaults_and_domains_from_the_margin():
    scene = Scene.from_config("s", spec(source={"kind": "box", "a": -0.5, "b": 0.5}))
    spread = math.sqrt(2 * 1e-3 * 50.0)
    assert scene.omega == pytest.approx(2 * (0.5 + 6 * spread))  # the box's half width + 6 sd either side
    assert scene.fd_length == scene.omega
    assert (scene.D, scene.measure, scene.realisations) == (1e-3, "rmse", 8)
    assert (scene.max_realisations, scene.blocks) == (32, 4)  # default: 4 blocks of realisations
    mine = Scene.from_config("s", spec(realisations=20, max_realisations=20))
    assert (mine.max_realisations, mine.blocks) == (20, 1)  # no refinement
    cfg = scene.run_config(scene.candidates[0], 100)
    lo, length = cfg.fd_span()
    assert length == pytest.approx(scene.fd_length + 0.01 * 50.0)  # the window plus the path v t
    assert lo == pytest.approx(-scene.fd_length / 2)
    assert scene.peclet == pytest.approx(0.01 * scene.fd_length / 1e-3)


@pytest.mark.parametrize("a", [0.0, 1000.0])
def test_a_box_one_float_wide_scores_as_the_point_source(a):
    """Issue 39: a box narrower than ~1e-15 got a wrong exact entropy. The narrowest box a float
    holds at its position is the point source at its centre: an FD run of it has the point's exact
    H_C, entropy and SSE (the same grid, the same masses)."""
    from particle_entropy.models.simulate import run

    b = math.nextafter(a, math.inf) if a else 5e-324
    box = Scene.from_config("s", spec(source={"kind": "box", "a": a, "b": b}, candidates=[FD]))
    point = Scene.from_config("p", spec(source={"kind": "point", "x0": box.source.centre}, candidates=[FD]))
    rows = [run(s.run_config(s.candidates[0], 64))[0].iloc[-1] for s in (box, point)]
    for column in ("H_C_analytic", "E_analytic", "SSE", "SSE_points", "H_C"):
        assert rows[0][column] == pytest.approx(rows[1][column], rel=1e-10), column


def test_identity_is_the_physics_only():
    base = Scene.from_config("a", spec())
    other_target = Scene.from_config("b", spec(target={"value": 1e-4, "measure": "entropy"}))
    other_v = Scene.from_config("c", spec(v=0.02))
    fd, mtpt = base.candidates
    assert base.identity(fd) == other_target.identity(other_target.candidates[0])  # a shared run
    assert base.identity(fd) != other_v.identity(other_v.candidates[0])
    assert base.identity(fd) != base.identity(mtpt)  # FD's step is part of its runs
    central = Scene.from_config("d", spec(candidates=[{**FD, "advection": "central"}]))
    assert central.identity(central.candidates[0]) != base.identity(fd)


def test_ladders_rise_by_about_two_and_fd_takes_even_grids():
    fd, mtpt = Scene.from_config("s", spec()).candidates
    assert fd.ladder()[0] == 16 and fd.ladder()[-1] == 1000 and all(n % 2 == 0 for n in fd.ladder())
    assert mtpt.ladder()[0] == 30 and mtpt.ladder()[-1] == 3000
    for ladder in (fd.ladder(), mtpt.ladder()):
        ratios = [b / a for a, b in zip(ladder, ladder[1:])]
        assert all(1.6 < r <= 2.05 for r in ratios), ratios


@pytest.mark.parametrize(
    "over, key",
    [
        ({"v": math.inf}, "scenes.s.v"),
        ({"D": 0.0}, "scenes.s.D"),
        ({"t_final": -1.0}, "scenes.s.t_final"),
        ({"realisations": 1}, "scenes.s.realisations"),
        ({"max_realisations": 4}, "scenes.s.max_realisations"),  # below realisations (8)
        ({"max_realisations": 12}, "scenes.s.max_realisations"),  # not a multiple of it
        ({"realisations": 4, "max_realisations": 10}, "scenes.s.max_realisations"),
        ({"max_realisations": 8.0}, "scenes.s.max_realisations"),
        ({"source": {"kind": "gaussian", "x0": 0.0, "sd": 0.0}}, "scenes.s.source.sd"),
        ({"source": {"kind": "box", "a": 1.0, "b": 1.0}}, "scenes.s.source.b"),
        ({"source": {"kind": "line"}}, "scenes.s.source.kind"),
        ({"source": {"kind": "point", "sd": 1.0}}, "scenes.s.source.sd"),
        ({"target": {"value": 0.0}}, "scenes.s.target.value"),
        ({"target": {"value": 1.0, "measure": "mae"}}, "scenes.s.target.measure"),
        ({"candidates": []}, "scenes.s.candidates"),
        ({"candidates": [{**FD, "n_range": [5, 5]}]}, "scenes.s.candidates[0].n_range"),
        ({"candidates": [MTPT, {**MTPT, "advection": "upwind"}]}, "scenes.s.candidates[1].advection"),
        ({"candidates": [{**FD, "advection": "lax"}]}, "scenes.s.candidates[0].advection"),
        ({"candidates": [{**MTPT, "eta": 2.0}]}, "scenes.s.candidates[0].eta"),
        ({"candidates": [FD, FD]}, "scenes.s.candidates[1]"),
        ({"omega": 0.1, "source": {"kind": "gaussian", "x0": 0.0, "sd": 1.0}}, "scenes.s.omega"),
        ({"fd_length": 0.1, "source": {"kind": "gaussian", "x0": 0.0, "sd": 1.0}}, "scenes.s.fd_length"),
        ({"cost": {"fd": [1.0]}}, "scenes.s.cost.fd"),
        ({"budget": 0.0}, "scenes.s.budget"),
        ({"budget": "cheap"}, "scenes.s.budget"),
        ({"candidates": [{**MTPT, "ladder": [30, 100]}]}, "scenes.s.candidates[0].ladder"),  # and n_range
        ({"candidates": [{**PT, "ladder": [100, 30]}]}, "scenes.s.candidates[0].ladder"),
        ({"candidates": [{**PT, "ladder": [30]}]}, "scenes.s.candidates[0].ladder"),
        ({"candidates": [{"method": "fd", "kernel": "implicit", "ladder": [16, 33]}]}, "scenes.s.candidates[0].ladder"),
    ],
)
def test_a_bad_value_is_refused_naming_its_key_path(over, key):
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", spec(**over))
    assert err.value.name == key


def test_a_plume_carried_100_windows_fits_the_fd_grid_and_moves_the_particles():
    """v large enough for the plume to travel 100 window lengths: the grid holds the path."""
    scene = Scene.from_config("far", spec(v=100 * 3.0 / 50.0, fd_length=3.0, omega=3.0, t_final=50.0))
    cfg = scene.run_config(scene.candidates[0], 1000)
    lo, length = cfg.fd_span()
    assert length == pytest.approx(3.0 + 300.0) and lo == pytest.approx(-1.5)
    assert scene.reference.centre == pytest.approx(300.0)
    assert abs(cfg.points(50.0) - 300.0).max() < 1.5  # the sensors moved with the plume, within the window


def test_every_scene_of_a_config():
    got = scenes({"scenes": {"one": spec(), "two": spec(v=0.0), "bad": spec(v=math.nan)}})
    assert list(got) == ["one", "two", "bad"] and got["two"].v == 0.0
    fd = got["one"].candidates[0]
    assert got.settings(got["one"].identity(fd)) == got["one"].settings(fd)
    with pytest.raises(SettingError, match="scenes.bad.v"):  # checked when used
        got["bad"]
    assert len(scenes({})) == 0


def test_a_job_finds_its_settings_in_an_index_digested_once(monkeypatch):
    """Scenes.settings(identity): each candidate's identity, and each half-step twin's, digested once
    however many jobs look one up; a lookup builds the scenes only up to its owner's."""
    got = scenes({"scenes": {"one": spec(), "two": spec(v=0.0), "bad": spec(v=math.nan)}})
    one = got["one"]
    own = [one.identity(c) for c in one.candidates]
    digested = []
    identity = Scene.identity
    monkeypatch.setattr(Scene, "identity", lambda self, c: digested.append(self.name) or identity(self, c))
    for _ in range(3):  # as many jobs of the same runs
        assert [got.settings(i) for i in own] == [one.settings(c) for c in one.candidates]
    assert digested == ["one"] * len(one.candidates)  # once each; "two" and "bad" never needed

    good = scenes({"scenes": {"one": spec(), "two": spec(v=0.0)}})
    two = good["two"]
    # FD's half step, which only "two" has (MTPT's is one's too: particle runs are computed at rest)
    half = two.half_step(two.candidates[0])
    assert good.settings(identity(two, half)) == two.settings(half) != two.settings(two.candidates[0])
    digested.clear()
    for _ in range(2):
        with pytest.raises(KeyError, match="no scene candidate has runs keyed '000000000000'"):
            good.settings("000000000000")
    assert digested == []  # every part already indexed by the half-step lookup: nothing digested again


def test_check_config_refuses_a_bad_scene_and_accepts_the_shipped_ones():
    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import check_config, load_yaml

    config = dict(load_yaml(ROOT / "config.yaml"))
    check_config(config)  # the shipped scenes are valid
    shipped = {
        "paper",
        "carried",
        "spill",
        "narrow",
        "front",
        "well_mixed",
        "carried_reaction",
        "plume2d",
        "oblique",
        "mt3dms_p03",
        "mt3dms_p04",
    }
    assert set(config["scenes"]) == shipped
    config["scenes"] = {**config["scenes"], "carried": {**config["scenes"]["carried"], "margin": 0.5}}
    with pytest.raises(SettingError) as err:
        check_config(config)
    assert err.value.name == "scenes.carried.margin"


def test_the_peclet_sweep_makes_one_scene_a_velocity():
    base = spec()
    del base["v"]
    got = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01, 0.1]}})
    assert list(got) == list(got.sweep) == ["peclet-0", "peclet-1", "peclet-2"]
    assert [got[n].v for n in got] == [0.0, 0.01, 0.1]
    assert got["peclet-2"].peclet == pytest.approx(0.1 * got["peclet-2"].fd_length / 1e-3)
    for bad, key in (
        ({"base": spec(), "v": [0.0, 1.0]}, "scenes_peclet.base.v"),
        ({"base": base, "v": [1.0, 0.5]}, "scenes_peclet.v"),
    ):
        with pytest.raises(SettingError) as err:
            scenes({"scenes_peclet": bad})
        assert err.value.name == key


PLANE_BASE = {
    "D": {"L": 1e-2, "T": 1e-3},
    "t_final": 4.0,
    "source": {"kind": "point", "x0": [0.0, 0.0]},
    "target": {"measure": "rmse", "value": 0.1},
    "candidates": [
        {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [32, 128]},
        {"method": "pt", "kernel": "adaptive", "n_range": [1000, 4000]},
    ],
}


def test_the_2d_peclet_sweep_makes_one_scene_a_speed_along_its_angle():
    """scenes_peclet2d: each speed of v along `angle` is a 2-D scene peclet2d-<k>, D_L along its flow."""
    got = scenes({"scenes_peclet2d": {"base": PLANE_BASE, "v": [0.5, 2.0], "angle": 45}})
    assert list(got) == list(got.sweep) == ["peclet2d-0", "peclet2d-1"]
    fast = got["peclet2d-1"]
    assert fast.dim == 2 and fast.v == (2.0 * math.sqrt(0.5), 2.0 * math.sqrt(0.5))
    eigenvalues, vectors = np.linalg.eigh(np.asarray(fast.D))
    assert eigenvalues == pytest.approx([1e-3, 1e-2], rel=1e-12)
    assert abs(vectors[:, 1] @ np.array(fast.v)) / fast.speed == pytest.approx(1.0, rel=1e-12)  # D_L along v
    assert fast.peclet == pytest.approx(2.0 * fast.fd_length / 1e-2, rel=1e-12)
    along = scenes({"scenes_peclet2d": {"base": PLANE_BASE, "v": [0.5, 2.0]}})
    assert along["peclet2d-0"].v == (0.5, 0.0)  # angle 0 by default: exactly along x
    written = Scene.from_config("mine", {**PLANE_BASE, "v": [0.5, 0.0]})
    sweep = along["peclet2d-0"]
    assert [sweep.identity(c) for c in sweep.candidates] == [written.identity(c) for c in written.candidates]


def test_both_sweeps_side_by_side_keep_their_names_and_dimensions():
    base = spec()
    del base["v"]
    both = {"scenes_peclet": {"base": base, "v": [0.0, 0.01]}, "scenes_peclet2d": {"base": PLANE_BASE, "v": [0.5, 1.0]}}
    got = scenes(both)
    assert list(got.sweep) == ["peclet-0", "peclet-1", "peclet2d-0", "peclet2d-1"]
    assert [got[n].dim for n in got.sweep] == [1, 1, 2, 2]


@pytest.mark.parametrize(
    "bad, key",
    [
        ({"base": {**PLANE_BASE, "v": [1.0, 0.0]}, "v": [0.5, 1.0]}, "scenes_peclet2d.base.v"),
        ({"base": PLANE_BASE, "v": [1.0, 0.5]}, "scenes_peclet2d.v"),
        ({"base": PLANE_BASE, "v": [0.0, 0.5]}, "scenes_peclet2d.v[0]"),  # D {L, T} needs a flow
        ({"base": PLANE_BASE, "v": [0.5, 1.0], "angle": 181.0}, "scenes_peclet2d.angle"),
        ({"base": PLANE_BASE, "v": [0.5]}, "scenes_peclet2d.v"),
    ],
)
def test_a_bad_2d_sweep_is_refused_naming_its_key(bad, key):
    with pytest.raises(SettingError) as err:
        scenes({"scenes_peclet2d": bad})
    assert err.value.name == key


def test_a_2d_sweep_scene_s_refusals_name_the_2d_sweep_s_keys():
    base = {**PLANE_BASE, "candidates": [PLANE_BASE["candidates"][0], PLANE_BASE["candidates"][0]]}
    every = scenes({"scenes_peclet2d": {"base": base, "v": [0.5, 1.0]}})
    with pytest.raises(SettingError) as err:
        every["peclet2d-1"]
    assert err.value.name == "scenes_peclet2d.base.candidates[1]"


def test_at_rest_fd_candidates_that_differ_only_in_advection_are_one():
    at_rest = Scene.from_config("s", spec(v=0.0, candidates=[FD, {**FD, "advection": "central"}, MTPT]))
    labels = ["fd implicit dt=0.05", "fd implicit dt=0.05", "mtpt collision eta=1"]
    assert [c.label for c in at_rest.candidates] == labels  # one model, each at the index written
    fd, central, _ = at_rest.candidates
    assert at_rest.same_as(1) == 0 and at_rest.identity(central) == at_rest.identity(fd)


def test_a_scene_at_rest_measures_over_its_own_window_and_the_paper_over_its_own():
    """A point at 0 with no flow is the paper's physics, but a scene's points span its FD window."""
    from particle_entropy.core import measures as M

    scene = Scene.from_config("s", spec(v=0.0))
    cfg = scene.run_config(scene.candidates[1], 300)
    assert cfg.at_rest and abs(cfg.points(50.0)).max() <= scene.fd_length / 2
    paper = Scene.from_config("p", spec(v=0.0, fd_length=12.0, omega=10.0, t_final=1000.0))
    pts = paper.run_config(paper.candidates[1], 300).points(1000.0)
    assert pts.tobytes() == M.measurement_points().tobytes()  # the paper's window: the paper's points


def test_a_scene_whose_top_job_cannot_fit_in_memory_is_refused():
    from particle_entropy.pipeline.crosschecks import check_scene_memory

    scene = Scene.from_config("s", spec())
    check_scene_memory(scene, available=24e9)  # fits
    with pytest.raises(SettingError) as err:
        check_scene_memory(scene, available=1e6)  # 1 MB: no job fits
    assert err.value.name == "scenes.s.candidates[0].n_range" and "GB" in err.value.allowed
    guarded = scenes({"scenes": {"s": spec()}}, check=lambda sc: check_scene_memory(sc, available=1e6))
    with pytest.raises(SettingError, match="scenes.s.candidates"):
        guarded["s"]


def test_a_ladder_written_out_is_the_search_s_rungs():
    pt = {"method": "pt", "kernel": "adaptive", "ladder": [30, 100, 300, 1000]}
    (cand,) = Scene.from_config("s", spec(candidates=[pt])).candidates
    assert cand.ladder() == [30, 100, 300, 1000] and (cand.n_lo, cand.n_hi) == (30, 1000)


PAPER = {  # the paper's problem, as config.yaml's scene `paper` writes it
    "D": 1.0e-3,
    "t_final": 1000.0,
    "omega": 10.0,
    "fd_length": 12.0,
    "target": {"value": 1e-3},
    "candidates": [
        {"method": "fd", "kernel": "implicit", "fd_dt": 0.05, "ladder": [8, 16, 30]},
        {"method": "mtpt", "kernel": "collision", "ladder": [30, 100]},
        {"method": "pt", "kernel": "adaptive", "ladder": [30, 100]},
    ],
}


def _with_paper(spec_, config=None):
    from functools import partial

    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import load_yaml
    from particle_entropy.pipeline.sweeps import RUN_PATTERN, run_config

    config = config or dict(load_yaml(ROOT / "config.yaml"))
    return scenes({"scenes": {"p": spec_}}, paper=(RUN_PATTERN, partial(run_config, config=config)))["p"], config


def test_the_paper_scene_runs_are_the_paper_run_s_own_files():
    from particle_entropy.analysis.scene_search import run_path

    scene, _ = _with_paper(PAPER)
    assert scene.paper_runs == {0, 1, 2}
    fd, mtpt, _pt = scene.candidates
    assert run_path(scene, mtpt, 100, 0, 19) == (
        "results/runs/mtpt/collision/n~100/eta~1/trunc~none/growth~1.05/scheme~symmetric/grid~exact/seeds~0-19.parquet"
    )
    assert run_path(scene, fd, 30, 0, 0).startswith("results/runs/fd/implicit/n~30/")
    # any difference of physics, step or points keeps a scene's runs its own
    for over in ({"D": 5e-4}, {"fd_length": 14.0}, {"source": {"kind": "point", "x0": 0.5}}):
        other, _ = _with_paper({**PAPER, **over})
        assert other.paper_runs == frozenset(), over
        assert run_path(other, other.candidates[1], 100, 0, 19).startswith("results/scenes/")
    # carried: FD's runs are its own, the particles' are computed at rest (Scene.runs_at_rest), the paper's
    carried, _ = _with_paper({**PAPER, "v": 1e-4})
    assert carried.paper_runs == {1, 2}
    assert run_path(carried, carried.candidates[0], 30, 0, 0).startswith("results/scenes/")
    assert run_path(carried, carried.candidates[1], 100, 0, 19) == run_path(scene, mtpt, 100, 0, 19)
    other, _ = _with_paper({**PAPER, "candidates": [{**PAPER["candidates"][0], "fd_dt": 0.1}, PAPER["candidates"][1]]})
    assert other.paper_runs == {1}  # FD at another step is not the paper's FD


@pytest.mark.parametrize("which", [0, 1, 2])
def test_a_shared_run_is_the_paper_run_to_the_bit(which):
    """The claim that lets the paper scene read the paper's files: its RunConfig's table equals the
    paper's own (measured wall times aside), so no answer depends on which job made the file."""
    from particle_entropy.models.simulate import run_seeds_arrow
    from particle_entropy.pipeline.sweeps import run_config

    scene, config = _with_paper(PAPER)
    cand = scene.candidates[which]
    n = cand.ladder()[0]
    mine = run_seeds_arrow(scene.run_config(cand, n, seed=3), [3]).to_pandas()
    from dataclasses import replace as _replace

    theirs = run_seeds_arrow(run_config(_replace(cand.case, n=n), config, seed=3), [3]).to_pandas()
    timing = [c for c in mine.columns if c.startswith(("wall_", "peak_rss", "core_s"))]
    assert list(mine.columns) == list(theirs.columns)
    assert mine.drop(columns=timing).equals(theirs.drop(columns=timing))


# --- issue 39: scenes at their edges --------------------------------------------------------------
S_FD = {"method": "fd", "kernel": "implicit", "fd_dt": 0.5, "n_range": [16, 256]}
S_PT = {"method": "pt", "kernel": "adaptive", "n_range": [30, 480]}


def small(**over):
    """The issue's small scene S: D 1e-3, v 0.01, t_final 50, FD implicit and PT adaptive, rmse 0.1."""
    out = {"D": 1e-3, "v": 0.01, "t_final": 50.0, "target": {"value": 0.1}, "candidates": [S_FD, S_PT]}
    out.update(over)
    return out


def _refused(spec_, name="s"):
    with pytest.raises(SettingError) as err:
        Scene.from_config(name, spec_)
    return err.value


def test_the_sweep_s_scenes_cannot_take_a_user_scene_s_name():
    """Point 6: scenes.peclet_0, peclet_mine and peclet stay the user's; the sweep's names are its own."""
    import re

    base = {k: v for k, v in small().items() if k != "v"}
    user = {"peclet_0": small(v=0.02), "peclet_mine": small(), "peclet": small(v=0.03)}
    got = scenes({"scenes": user, "scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
    assert got["peclet_0"].v == 0.02 and got["peclet"].v == 0.03  # not replaced by the sweep's
    assert set(user) < set(got) and len(got) == len(user) + 2
    assert len(got.sweep) == 2 and not set(got.sweep) & set(user)
    assert [got[n].v for n in got.sweep] == [0.0, 0.01]
    for name in got.sweep:  # a name no user scene can have (the schema's pattern)
        assert not re.fullmatch(r"[A-Za-z0-9_]+", name)


def test_a_user_scene_named_like_the_sweep_is_refused():
    base = {k: v for k, v in small().items() if k != "v"}
    sweep = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}}).sweep
    with pytest.raises(SettingError) as err:
        scenes({"scenes": {sweep[0]: small()}, "scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
    assert err.value.name == f"scenes.{sweep[0]}"


@pytest.mark.parametrize(
    "typo, key, near",
    [
        ({"t_finall": 50.0}, "t_finall", "t_final"),
        ({"budjet": 1.0}, "budjet", "budget"),
        ({"target": {"value": 0.1, "valeu": 0.2}}, "target.valeu", "value"),
    ],
)
def test_typos_under_the_peclet_base_are_refused_with_did_you_mean(typo, key, near):
    """Point 7: the schema and the scene itself refuse them, naming scenes_peclet.base.<key>."""
    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import check_config, check_schema, load_schema, load_yaml

    base = {**{k: v for k, v in small().items() if k != "v"}, **typo}
    with pytest.raises(SettingError) as err:
        every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
        every[every.sweep[0]]
    assert err.value.name == f"scenes_peclet.base.{key}" and f"did you mean {near}" in err.value.allowed
    with pytest.raises(SettingError) as err:  # the same typo under scenes.<name>, by the scene itself
        Scene.from_config("s", {**small(), **typo})
    assert err.value.name == f"scenes.s.{key}" and f"did you mean {near}" in err.value.allowed
    config = dict(load_yaml(ROOT / "config.yaml"))
    config["scenes_peclet"] = {"base": base, "v": [0.0, 0.01]}
    for check in (lambda: check_schema(config, load_schema()), lambda: check_config(config)):  # at the parse
        with pytest.raises(SettingError) as err:
            check()
        assert err.value.name == f"scenes_peclet.base.{key}" and f"did you mean {near}" in err.value.allowed


def test_at_rest_fd_candidates_keep_the_user_s_indexes():
    """Point 9b: at v = 0 two FD candidates that differ only in advection share their runs, but every
    candidate keeps the index the user wrote, and a refusal names that index."""
    at_rest = Scene.from_config("s", small(v=0.0, candidates=[S_FD, {**S_FD, "advection": "central"}, S_PT]))
    assert [c.case.method for c in at_rest.candidates] == ["fd", "fd", "pt"]
    assert at_rest.same_as(1) == 0 and at_rest.same_as(0) == 0 and at_rest.same_as(2) == 2
    bad = _refused(small(v=0.0, candidates=[S_FD, {**S_FD, "advection": "central"}, {**S_FD, "fd_dt": 1e-9}]))
    assert bad.name == "scenes.s.candidates[2].fd_dt"


def test_a_velocity_that_carries_the_plume_beyond_double_precision_is_refused():
    """Point 13: v = 1e300 overflowed FD's jobs (and v = 1e30 left no digit of a particle's position
    within the plume): |x0 + v t_final| must keep the plume's width in half the digits of a double."""
    err = _refused(small(v=1.0e300))
    assert err.name == "scenes.s.v" and err.value == 1.0e300
    assert "sqrt(2 D t_final)" in err.allowed and "[-" in err.allowed
    err = _refused(small(v=-1.0e30))
    assert err.name == "scenes.s.v"
    Scene.from_config("s", small(v=1.0e4))  # the plume 500 window lengths away: still resolved
    base = {k: v for k, v in small().items() if k != "v"}
    every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 1.0e300]}})
    with pytest.raises(SettingError) as e:
        every[every.sweep[1]]
    assert e.value.name == "scenes_peclet.v[1]"


def test_a_gaussian_too_narrow_for_its_variance_is_refused():
    """Point 13: sd = 1e-300 has sd^2 = 0, a point source whose density FD's jobs could not take."""
    err = _refused(small(source={"kind": "gaussian", "x0": 0.0, "sd": 1.0e-300}))
    assert err.name == "scenes.s.source.sd" and "point" in err.allowed and "e-154" in err.allowed
    Scene.from_config("s", small(source={"kind": "gaussian", "x0": 0.0, "sd": 1.0e-10}))


@pytest.mark.parametrize(
    "over, key",
    [
        ({"t_final": 1.0e308}, "scenes.s.t_final"),
        ({"candidates": [{**S_FD, "n_range": [15, 64]}]}, "scenes.s.candidates[0].n_range"),
        ({"candidates": [{**S_FD, "n_range": [16, 17]}]}, "scenes.s.candidates[0].n_range"),
        ({"candidates": [S_FD, {**S_FD, "fd_dt": 1.0e-9}]}, "scenes.s.candidates[1].fd_dt"),
        ({"D": 1e-6, "t_final": 1.0e6, "candidates": [{**S_FD, "fd_dt": 0.05}]}, "scenes.s.candidates[0].fd_dt"),
        (
            {"D": 1e-6, "t_final": 1.0e6, "candidates": [{k: v for k, v in S_FD.items() if k != "fd_dt"}]},
            "scenes.s.t_final",
        ),
        ({"candidates": [S_PT, {"method": "fd", "kernel": "implicit", "ladder": [2, 64]}]}, None),
        ({"candidates": [S_FD, S_PT, S_PT]}, "scenes.s.candidates[2]"),
    ],
)
def test_every_refusal_names_a_key_the_user_wrote(over, key):
    """Point 14: no candidates[0].dt0, no candidates[0].n, no message without a key."""
    spec_ = small(**over)
    if key is None:  # an FD rung of 2 intervals (fewer than its stencil needs): the ladder
        key = "scenes.s.candidates[1].ladder"
    err = _refused(spec_)
    assert err.name == key, err


def test_pt_candidates_that_differ_only_in_dt_growth_are_two_models():
    """Point 14: they were refused as identical; their labels and runs differ."""
    got = Scene.from_config("s", small(candidates=[S_PT, {**S_PT, "dt_growth": 1.1}]))
    a, b = got.candidates
    assert a.case != b.case and a.label != b.label


def test_a_peclet_scene_s_refusals_name_the_sweep_s_keys():
    """Point 14: scenes.peclet_0.candidates does not exist; scenes_peclet.base.candidates does."""
    base = {k: v for k, v in small().items() if k != "v"}
    base["candidates"] = [S_FD, S_FD]
    every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
    with pytest.raises(SettingError) as err:
        every[every.sweep[1]]
    assert err.value.name == "scenes_peclet.base.candidates[1]"
    from particle_entropy.pipeline.crosschecks import check_scene_memory

    base["candidates"] = [S_FD]
    every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
    with pytest.raises(SettingError) as err:
        check_scene_memory(every[every.sweep[0]], available=1e6)
    assert err.value.name == "scenes_peclet.base.candidates[0].n_range"
    base["candidates"] = [{"method": "pt", "kernel": "adaptive", "ladder": [30, 100]}]
    every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
    with pytest.raises(SettingError) as err:
        check_scene_memory(every[every.sweep[0]], available=1e3)
    assert err.value.name == "scenes_peclet.base.candidates[0].ladder"


def test_a_scene_runs_on_the_exact_time_grid_whatever_case_defaults_say():
    """case_defaults' time_grid (the paper figures') would move particle runs past t_final, where a
    scene is judged: the authors' whole growing steps end at t = 51.6 for t_final = 50."""
    from particle_entropy.core.timegrid import time_steps
    from particle_entropy.models.simulate import run_seeds_arrow

    pt = {**PT, "n_range": [30, 480]}
    scene = Scene.from_config("s", spec(candidates=[FD, pt]), {"time_grid": "authors", "dt_growth": 1.1})
    cfg = scene.run_config(scene.candidates[1], 30)
    assert cfg.time_grid == "exact" and cfg.dt_growth == 1.1  # the other case_defaults still apply
    assert time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, "authors").sum() > 51.0  # what it would do
    last = run_seeds_arrow(cfg, [0]).to_pandas()["time"].iloc[-1]
    assert last == pytest.approx(50.0, rel=1e-12)
    with pytest.raises(SettingError) as err:  # a candidate's own time_grid: refused, not ignored
        Scene.from_config("s", spec(candidates=[FD, {**pt, "time_grid": "authors"}]))
    assert err.value.name == "scenes.s.candidates[1].time_grid" and "t_final" in err.value.allowed


def test_explicit_fd_in_a_flow_is_refused_not_run_implicit():
    """Explicit FD has no advection term: at v != 0 it ran the implicit scheme under its own label
    (tables bit-identical to the implicit candidate's). It is refused by key path; at rest it runs."""
    from particle_entropy.core.runconfig import RunConfig

    explicit = {"method": "fd", "kernel": "explicit", "fd_dt": 0.5, "n_range": [16, 256]}
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", spec(candidates=[MTPT, explicit]))
    assert err.value.name == "scenes.s.candidates[1].kernel" and err.value.value == "explicit"
    assert "implicit when v != 0" in err.value.allowed
    with pytest.raises(SettingError, match="kernel"):  # the CLI's runs too
        RunConfig.of(method="fd", kernel="explicit", n=16, v=0.01, dt0=0.5, fd_length=4.0).resolved()
    stable = {**explicit, "n_range": [16, 64]}  # r = D dt / dx^2 < 1/2 up to its ladder's top
    at_rest = Scene.from_config("s", spec(v=0.0, candidates=[MTPT, stable]))
    assert at_rest.candidates[1].label == "fd explicit dt=0.5"


S_SMALL = {  # the small scene S
    "D": 1e-3,
    "v": 0.01,
    "t_final": 50.0,
    "target": {"measure": "rmse", "value": 0.1},
    "candidates": [
        {"method": "fd", "kernel": "implicit", "fd_dt": 0.5, "n_range": [16, 256]},
        {"method": "pt", "kernel": "adaptive", "n_range": [30, 480]},
    ],
}


def test_the_measurement_points_sample_the_plume_whatever_the_window():
    """The 15 points span the plume's mean +- 3 sqrt(4 D t_final), never the FD window: at
    fd_length 1e6 they spanned the window, none was near the plume, and every model scored 0."""
    from particle_entropy.analysis.scene_search import error
    from particle_entropy.core import measures as M
    from particle_entropy.models.simulate import run_seeds_arrow

    wide = Scene.from_config("s", {**S_SMALL, "fd_length": 1.0e6})
    default = Scene.from_config("s", S_SMALL)
    fd, pt = wide.candidates
    assert wide.frame_shift(pt, 50.0) == 0.5  # PT runs at rest (Scene.runs_at_rest): its points, carried by v t
    pts = wide.run_config(pt, 30).points(50.0) + wide.frame_shift(pt, 50.0)
    assert pts.tobytes() == (default.run_config(default.candidates[1], 30).points(50.0) + 0.5).tobytes()
    reach = 3.0 * math.sqrt(4e-3 * 50.0)  # 1.342: +- 4.24 standard deviations around x = v t = 0.5
    assert np.allclose(pts, M.measurement_points(2 * reach) + 0.5, rtol=0, atol=1e-12)
    assert 0.5 - reach <= pts.min() and pts.max() <= 0.5 + reach
    for scene in (wide, default):  # FD and particles measure at the same points
        assert scene.run_config(scene.candidates[0], 16).points(50.0).tobytes() == pts.tobytes()
    # FD on the 1e6 window puts the plume on one node: its error is the exact plume's own RMSE there
    exact = wide.reference.density(pts)
    table = run_seeds_arrow(wide.run_config(fd, 16), [0]).to_pandas()
    last = table.iloc[-1]
    assert error(wide, last) == pytest.approx(math.sqrt(np.mean(exact**2)), rel=1e-3)
    assert error(wide, last) > 0.5  # before: 5e-6, "met" at rmse 0.1
    # at rest with particles only, too: PT n = 30 is judged against the plume, not 0
    rest = Scene.from_config("r", {**S_SMALL, "v": 0.0, "fd_length": 1.0e6, "candidates": [S_SMALL["candidates"][1]]})
    runs = run_seeds_arrow(rest.run_config(rest.candidates[0], 30, seed=0), range(3)).to_pandas()
    errors = [error(rest, g.iloc[-1]) for _, g in runs.groupby("seed")]
    assert min(errors) > 0.01
    assert np.allclose(
        rest.run_config(rest.candidates[0], 30).points(50.0), M.measurement_points(2 * reach), atol=1e-12
    )


def test_a_window_that_cannot_hold_the_plume_is_refused():
    """margin 1 (+- 1 sqrt(2 D t_final)) was accepted and its FD runs lost a third of the mass. The
    window must reach 3 sqrt(4 D t_final) beyond the source, as the paper's [-6, 6] at t = 1000."""
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", {**S_SMALL, "margin": 1.0})
    assert err.value.name == "scenes.s.margin" and err.value.value == 1.0
    assert "4.24264, 100]" in err.value.allowed
    need = 2 * 3 * math.sqrt(4e-3 * 50.0)  # 2.683
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", {**S_SMALL, "fd_length": 0.99 * need})
    assert err.value.name == "scenes.s.fd_length" and f"{need:.6g}" in err.value.allowed
    box = {"kind": "box", "a": -0.5, "b": 0.5}
    with pytest.raises(SettingError, match=r"scenes.s.fd_length=3.6 .*extent 1 \+"):
        Scene.from_config("s", {**S_SMALL, "source": box, "fd_length": 3.6})  # < 1 + 2.683
    assert Scene.from_config("s", {**S_SMALL, "source": box, "fd_length": 3.7}).fd_length == 3.7
    assert Scene.from_config("s", {**S_SMALL, "margin": 3 * math.sqrt(2)}).fd_length == pytest.approx(need)
    # the paper's own window is the bound at its D and t_final
    paper = Scene.from_config("p", {**PAPER, "candidates": PAPER["candidates"][:1]})
    assert paper.fd_length == 12.0


def test_the_smallest_window_loses_what_the_paper_s_does():
    """At rest, FD on the smallest window (ends 3 sqrt(4 D t_final) from the point) loses the
    exact 2 erfc(3) = 4.4e-5 by t_final, within MASS_LOSS_MAX; the search still scores it."""
    from particle_entropy.analysis.scene_search import MASS_LOSS_MAX
    from particle_entropy.models.simulate import run_seeds_arrow

    fine = {**S_SMALL["candidates"][0], "fd_dt": 0.01}  # backward Euler's tails converge with dt and dx
    scene = Scene.from_config("s", {**S_SMALL, "v": 0.0, "margin": 3 * math.sqrt(2), "candidates": [fine]})
    last = run_seeds_arrow(scene.run_config(scene.candidates[0], 256), [0]).to_pandas().iloc[-1]
    lost = 1.0 - last["mass_total"]
    assert lost == pytest.approx(math.erfc(3.0) * 2, rel=0.03)  # 4.51e-5
    coarse = Scene.from_config("s", {**S_SMALL, "v": 0.0, "margin": 3 * math.sqrt(2)})  # fd_dt 0.5, n = 16
    last = run_seeds_arrow(coarse.run_config(coarse.candidates[0], 16), [0]).to_pandas().iloc[-1]
    assert lost < 1.0 - last["mass_total"] < MASS_LOSS_MAX  # its own discretisation on top: still judged


def test_a_run_that_lost_mass_is_unscored(tmp_path):
    """H_C and E are computed on the mass left: a run that lost more than MASS_LOSS_MAX of its mass
    is never judged (nor chosen), whatever its error. At v = 0.05, S's upwind grid n = 32 spreads the
    plume by numerical dispersion (v dx / 2 = 5 D) through the window's ends."""
    import pandas as pd

    from particle_entropy.analysis import scene_search as S
    from particle_entropy.core.io import write_parquet
    from particle_entropy.models.simulate import run_seeds_arrow

    scene = Scene.from_config("s", {**S_SMALL, "v": 0.05, "target": {"measure": "entropy", "value": 1.0}})
    plan = pd.DataFrame([{"candidate": 0, "label": "", "n": 32, "first": 0, "last": 0, "round": 0}])
    path = tmp_path / "fd32.parquet"
    write_parquet(run_seeds_arrow(scene.run_config(scene.candidates[0], 32), [0]), path)
    runs = S.read_runs(plan, [str(path)])
    lost = 1.0 - runs["mass_total"].iloc[0]
    assert 0.01 < lost < 0.05  # 0.023
    row = S.judged(scene, runs).iloc[0]
    assert S.error(scene, runs.iloc[0]) < 1.0  # its entropy of what is left would meet the target (0.85)
    assert row["unscored"].startswith("mass lost") and not row["meets"] and math.isnan(row["COMIC_points"])
    kept = runs.assign(mass_total=1.0 - 0.5 * S.MASS_LOSS_MAX)  # within the window's allowance: judged
    assert S.judged(scene, kept).iloc[0]["meets"]
    gained = S.judged(scene, runs.assign(mass_total=1.01)).iloc[0]  # mass from nowhere: not judged either
    assert gained["unscored"].startswith("mass gained: 0.01") and not gained["meets"]


def test_a_wide_box_s_points_stay_on_its_plume_and_inside_the_window():
    """A box's variance (b - a)^2 / 12 overstates its reach: [-5, 5] at D = 1e-3, t_final = 50 put its
    points out to +- 12.3, 6 of 15 outside the FD grid, where every model scores 0 error."""
    box = {**S_SMALL, "v": 0.0, "source": {"kind": "box", "a": -5.0, "b": 5.0}, "candidates": [S_FD]}
    box["target"] = {"value": 0.01}  # below the plume's own RMS at the points (0.086), which a field of zeros scores
    scene = Scene.from_config("b", box)
    pts = scene.run_config(scene.candidates[0], 16).points(50.0)
    reach = 5.0 + 3.0 * math.sqrt(4e-3 * 50.0)  # the box's edge plus 3 sqrt(4 D t_final)
    from particle_entropy.core import measures as M

    assert np.allclose(pts, M.measurement_points(2 * reach), rtol=0, atol=1e-12)  # the paper's 15, on that span
    assert np.all(np.abs(pts) <= scene.fd_length / 2)  # every point on the FD grid
    exact = scene.reference.density(pts)
    assert exact.min() > 1e-6 * exact.max()  # and on the plume


# --- issue 40: tvd advection and a step that follows the grid (courant) -----------------------------
S_TVD = {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.5, "n_range": [16, 256]}


def test_identities_of_candidates_without_courant_are_unchanged():
    """Digests of spec()'s candidates taken at 77a862f, before courant existed: frozen, since a run's
    file is keyed by them."""
    moving = Scene.from_config("s", spec(candidates=[FD, {**FD, "advection": "central", "fd_dt": 0.1}, MTPT]))
    # MTPT's runs in the flow are its runs at rest (Scene.runs_at_rest): at-rest's digest, no longer 1f90db7bbccc
    assert [moving.identity(c) for c in moving.candidates] == ["c7b20328ac6c", "d3855894c74e", "39998f06084d"]
    at_rest = Scene.from_config("s", spec(v=0.0))
    assert [at_rest.identity(c) for c in at_rest.candidates] == ["a61c6cc525bb", "39998f06084d"]
    assert all("courant" not in moving.settings(c) for c in moving.candidates)


def test_a_courant_candidate_steps_with_its_grid():
    got = Scene.from_config("s", small(candidates=[S_TVD, {**S_FD, "courant": 4.0}, S_FD]))
    tvd, upwind, fixed = got.candidates
    assert tvd.label == "fd implicit tvd Cr=0.5" and upwind.label == "fd implicit upwind Cr=4"
    assert fixed.label == "fd implicit upwind dt=0.5"
    assert got.settings(tvd)["courant"] == 0.5 and "dt0" not in got.settings(tvd)
    assert len({got.identity(c) for c in got.candidates}) == 3
    for n in (16, 32):
        cfg = got.run_config(tvd, n)
        assert cfg.dt0 == pytest.approx(0.5 * cfg.fd_span()[1] / n / 0.01)
        assert cfg.courant_number() == pytest.approx(0.5)
    # twice the intervals, twice the steps, four times the node-steps (fd cost: 3.85e-5 s a step, 1.72e-8 a node)
    a, b = got.run_cost(tvd, 16), got.run_cost(tvd, 32)
    steps = lambda n: math.ceil(50.0 / got.run_config(tvd, n).dt0 - 1e-9)  # noqa: E731
    assert a == pytest.approx(3.85e-5 * steps(16) + 1.72e-8 * steps(16) * 17)
    assert steps(32) == 2 * steps(16) and b > 1.9 * a


def test_at_rest_a_courant_candidate_is_its_fd_dt_twin():
    """Nothing to advect: courant is dropped, the step is fd_dt (its own or the default)."""
    got = Scene.from_config("s", small(v=0.0, candidates=[S_FD, {**S_TVD, "fd_dt": 0.5}, {**S_TVD}]))
    fd, tvd, default_step = got.candidates
    assert tvd.courant is None and got.same_as(1) == 0 and got.identity(tvd) == got.identity(fd)
    assert default_step.fd_dt == 0.05 and got.same_as(2) == 2 and default_step.label == "fd implicit dt=0.05"


@pytest.mark.parametrize(
    "candidate, key, says",
    [
        ({**S_PT, "courant": 0.5}, "scenes.s.candidates[0].courant", "fd candidates only"),
        ({**S_TVD, "courant": 0.0}, "scenes.s.candidates[0].courant", "> 0"),
        ({**S_FD, "courant": -1.0}, "scenes.s.candidates[0].courant", "> 0"),
        ({**S_TVD, "courant": 1.01}, "scenes.s.candidates[0].courant", "<= 1 for advection tvd"),
        ({**S_FD, "courant": 1e-9}, "scenes.s.candidates[0].courant", "10,000,000 steps"),
        # fd_dt 0.5 at v 0.01: Cr = 0.005 / dx, above 1 once dx < 0.005, i.e. on the top rung of 1024
        ({**S_FD, "advection": "tvd", "n_range": [16, 1024]}, "scenes.s.candidates[0].fd_dt", "at n = 1024"),
        (
            {k: v for k, v in S_TVD.items() if k != "courant"} | {"n_range": [16, 16384]},  # fd_dt 0.05
            "scenes.s.candidates[0].fd_dt",
            "<= 1",
        ),
    ],
)
def test_a_courant_number_a_candidate_cannot_take_is_refused_by_its_key(candidate, key, says):
    err = _refused(small(candidates=[candidate]))
    assert err.name == key and says in err.allowed, err


def test_tvd_with_a_step_fixed_in_time_is_taken_while_its_courant_number_is_at_most_1():
    got = Scene.from_config("s", small(candidates=[{**S_FD, "advection": "tvd", "n_range": [16, 512]}]))
    top = got.run_config(got.candidates[0], 512)
    assert 0.5 < top.courant_number() <= 1.0


def test_seeds_past_int64_are_refused_naming_max_realisations():
    """A scene's seeds run to base_seed + max_realisations - 1, stored as int64 (2^63 - 1)."""
    from particle_entropy.pipeline.crosschecks import check_scene

    scene = Scene.from_config("s", spec(realisations=4, max_realisations=16))
    check_scene(scene, 2**63 - 16, None)  # the last seed is 2^63 - 1
    with pytest.raises(SettingError) as e:
        check_scene(scene, 2**63 - 15, None)
    assert e.value.name == "scenes.s.max_realisations" and "<= 15 with base_seed" in e.value.allowed


@pytest.mark.parametrize(
    "key, value",
    [
        ("target", 0.1),  # a number where a section goes: a TypeError before scenes parsed by their model
        ("target", ["value", 0.1]),
        ("D", "1e-3"),
        ("v", math.inf),
        ("max_realisations", 12),
        ("cost", {"fd": [1.0, -1.0]}),
        ("source", {"kind": ["point"]}),
        ("candidates", [{"method": "pt", "kernel": "adaptive", "n_range": [30, 300], "eta": None}]),
        ("candidates", [{"method": "pt", "kernel": "adaptive", "n_range": [300, 30]}]),
        ("candidates", [{"method": "pt", "kernel": "adaptive", "ladder": [30, 100], "n_range": [30, 100]}]),
        ("candidates", [{"method": "pt", "kernel": "adaptive", "n_range": [30, 300], "courant": 0.5}]),
        ("candidates", [{"method": "fd", "kernel": "implicit", "advection": "tvd", "n_range": [16, 64], "courant": 2}]),
    ],
)
def test_a_scene_and_the_workflow_refuse_a_value_in_the_same_words(key, value):
    """One check: Scene.from_config on a scene as written (a notebook, a job script) parses it by the
    model the workflow's config is made of (core/typed.py), so both name the same key and value, and
    say the same."""
    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import check_config, load_yaml

    config = dict(load_yaml(ROOT / "config.yaml"))
    bad = {**config["scenes"]["carried"], key: value}
    with pytest.raises(SettingError) as alone:
        Scene.from_config("carried", bad, config["case_defaults"])
    with pytest.raises(SettingError) as workflow:
        check_config({**config, "scenes": {**config["scenes"], "carried": bad}})
    assert alone.value.name.startswith(f"scenes.carried.{key}")
    assert str(alone.value) == str(workflow.value)


def test_a_particle_candidate_takes_a_first_step_of_its_own():
    """dt0 on a particle candidate: its runs step from it (growth 1: a fixed step), its label and run
    identity say so, and a candidate without it keeps its identity; FD refuses it (fd_dt is FD's)."""
    own = {**MTPT, "dt0": 0.5, "dt_growth": 1.0}
    scene = Scene.from_config("s", spec(candidates=[{**MTPT, "dt_growth": 1.0}, own]))
    plain, fixed = scene.candidates
    cfg = scene.run_config(fixed, 100)
    assert (cfg.dt0, cfg.dt_growth) == (0.5, 1.0) and scene.run_config(plain, 100).dt0 != 0.5
    assert fixed.label.endswith("dt0=0.5 growth=1") and "dt0" not in plain.label
    assert scene.settings(fixed)["dt0"] == 0.5 and "dt0" not in scene.settings(plain)
    assert scene.identity(fixed) != scene.identity(plain) and scene.same_as(1) == 1
    alone = Scene.from_config("s", spec(candidates=[{**MTPT, "dt_growth": 1.0}]))
    assert alone.identity(alone.candidates[0]) == scene.identity(plain)
    err = _refused(spec(candidates=[{**FD, "dt0": 0.5}]))
    assert err.name == "scenes.s.candidates[0].dt0" and "particle candidates only" in err.allowed
    err = _refused(spec(candidates=[FD, {**MTPT, "dt0": 1e-9, "dt_growth": 1.0}]))
    assert err.name == "scenes.s.candidates[1].dt0" and err.value == 1e-9
    least = float(err.allowed.split(">= ")[1].split(" ")[0])
    assert least == pytest.approx(50.0 / MAX_STEPS, rel=1e-2)  # t_final / the most steps


def _transport_s(scene: Scene, cand, n: int) -> tuple[float, float]:
    """A run's counted step part and work part under the scene's `cost` alone, by StepWork's formula
    written out: seconds a step x steps, seconds a unit x steps x units (particles, FD's n + 1 nodes)."""
    from particle_entropy.core.runcost import run_steps

    cfg = scene.run_config(cand, n)
    per_step, per_unit = dict(scene.cost)[cfg.method]
    steps = run_steps(cfg).size
    units = n + 1 if cfg.method == "fd" else n
    return per_step * steps, per_unit * (steps * units)


def test_a_conservative_scene_s_counted_cost_is_its_transport_s_to_the_bit():
    """No reaction, no factor: every rung of the shipped conservative scenes costs what `cost` counts
    for its steps and work (settings.REACTIVE_COST prices reactive runs only)."""
    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import load_yaml

    table = scenes(dict(load_yaml(ROOT / "config.yaml")))
    for name in ("carried", "spill", "narrow"):
        scene = table[name]
        assert scene.reaction is None
        for cand in scene.candidates:
            for n in cand.ladder()[:3]:
                step_s, work_s = _transport_s(scene, cand, n)
                assert scene.run_cost(cand, n) == step_s + work_s


def test_a_reactive_rung_costs_its_transport_times_the_reaction_s_factors():
    """A reactive scene's run costs its transport's step part and work part, each times its method's
    factor of settings.REACTIVE_COST (benchmarks/reactive_cost.py): every method more at its top rung,
    where the work dominates (a small particle rung's steps may cost less: the reactive run draws no
    entropy or exact density a step)."""
    from particle_entropy.core.settings import REACTIVE_COST

    mixed = {"kind": "bimolecular", "k": 2.0, "B": {"source": {"kind": "box", "a": -1.0, "b": 1.0}, "mass": 1.0}}
    cands = [FD, MTPT, {**PT, "n_range": [300, 3000]}]
    box = {"kind": "box", "a": -1.0, "b": 1.0}
    reactive = Scene.from_config("r", spec(source=box, reaction=mixed, target={"value": 0.02}, candidates=cands))
    for cand in reactive.candidates:
        method = cand.case.method
        for n in (cand.n_lo, cand.ladder()[-1]):
            step_s, work_s = _transport_s(reactive, cand, n)
            on_step, on_work = REACTIVE_COST.get(method, (1.0, 1.0))
            got = reactive.run_cost(cand, n)
            assert got == pytest.approx(on_step * step_s + on_work * work_s, rel=1e-12)
            if n == cand.ladder()[-1]:
                assert got > step_s + work_s
    assert set(REACTIVE_COST) == {"fd", "mtpt", "pt"} and all(w > 1.0 for _, w in REACTIVE_COST.values())


def test_half_step_halves_every_candidate_s_step_at_every_time():
    """issue 50: an answer is checked at half its step. A particle's dt_n = dt0 g^n is dt0 + (g - 1) t at
    time t, so halving dt0 and g - 1 halves it all the way; FD halves fd_dt or its Courant number."""
    from particle_entropy.core.timegrid import time_steps

    spec = {
        **S_SMALL,
        "v": 0.01,
        "candidates": [
            {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.5, "n_range": [64, 256]},
            {"method": "fd", "kernel": "implicit", "fd_dt": 0.5, "n_range": [64, 256]},
            {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [100, 400]},
            {"method": "pt", "kernel": "adaptive", "dt_growth": 1.0, "dt0": 0.2, "n_range": [100, 400]},
        ],
    }
    scene = Scene.from_config("s", spec)
    for cand in scene.candidates:
        half = scene.half_step(cand)
        assert scene.identity(half) != scene.identity(cand) and half.label != cand.label
        full, fine = (scene.run_config(c, 64 if c.case.method == "fd" else 100) for c in (cand, half))
        steps = [time_steps(c.t_final, c.dt0, c.dt_growth, "exact") for c in (full, fine)]
        ends = [np.cumsum(d) for d in steps]
        # the step in force at times away from the last (cut) step: half, to a step's growth
        t = np.linspace(0.1, 0.8, 8) * full.t_final
        ratio = [np.interp(t, e, d) for e, d in zip(ends, steps)]
        np.testing.assert_allclose(ratio[1] / ratio[0], 0.5, rtol=0.06)
