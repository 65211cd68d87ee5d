"""A scene whose source keeps releasing (issue 53, point 1): the keys, their refusals, the release
reaching every run, the runs' identity and frame, and where a 2-D point source's infinite
concentration at the source keeps an rmse target from being judged."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.core.measures import measurement_points
from particle_entropy.core.release import Release
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.scenes.scene import Scene, scenes

FD = {"method": "fd", "kernel": "implicit", "n_range": [16, 256]}
MTPT = {"method": "mtpt", "kernel": "collision", "n_range": [30, 300]}
PT = {"method": "pt", "kernel": "adaptive", "n_range": [30, 300]}
POINT = {"kind": "point", "x0": 0.0}


def spec(release=None, source=POINT, **over):
    """A 1-D scene in a flow (D 1e-3, v 0.01, t_final 50) whose source has ``release``."""
    src = dict(source) if release is None else {**source, "release": release}
    out = {"v": 0.01, "t_final": 50.0, "source": src, "target": {"value": 0.002}, "candidates": [FD, MTPT, PT]}
    out.update(over)
    return out


PLANE_FD = {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [32, 64]}
PLANE_PT = {"method": "pt", "kernel": "adaptive", "n_range": [1000, 2000]}
PLANE_MTPT = {"method": "mtpt", "kernel": "collision", "n_range": [500, 1000]}


def plane(release=None, source=None, v=(0.5, 0.0), measure="rmse", **over):
    """A 2-D scene (D_L 1e-2, D_T 1e-3 along a flow v, t_final 4) whose source has ``release``."""
    src = dict(source or {"kind": "point", "x0": [0.0, 0.0]})
    if release is not None:
        src["release"] = release
    D = {"L": 1e-2, "T": 1e-3} if any(v) else {"x": 1e-2, "y": 1e-3}
    out = {
        "D": D,
        "v": list(v),
        "t_final": 4.0,
        "source": src,
        "target": {"measure": measure, "value": 0.1},
        "candidates": [PLANE_FD, PLANE_PT, PLANE_MTPT],
    }
    out.update(over)
    return out


def refused(name, config) -> SettingError:
    with pytest.raises(SettingError) as err:
        Scene.from_config(name, config)
    return err.value


# ------------------------------------------------------------------------ refusals, by key path
@pytest.mark.parametrize(
    "release, key, says",
    [
        ({"rate": 0.0}, "rate", "> 0"),
        ({"rate": -1.0}, "rate", "> 0"),
        ({"rate": math.nan}, "rate", "> 0 and finite"),
        ({"rate": math.inf}, "rate", "> 0 and finite"),
        ({"rate": -math.inf}, "rate", "> 0 and finite"),
        ({"rate": True}, "rate", "> 0"),
        ({"from": 1.0}, "rate", "a required key"),
        ({"rate": 1.0, "from": -1.0}, "from", ">= 0"),
        ({"rate": 1.0, "from": math.nan}, "from", "finite"),
        ({"rate": 1.0, "from": 10.0, "until": 10.0}, "until", "> from = 10"),
        ({"rate": 1.0, "from": 10.0, "until": 5.0}, "until", "> from = 10"),
        ({"rate": 1.0, "until": 0.0}, "until", "> from = 0"),  # from's default is 0
        ({"rate": 1.0, "until": math.inf}, "until", "finite"),
        ({"rate": 1.0, "from": 50.0}, "from", "[0, t_final = 50)"),
        ({"rate": 1.0, "from": 80.0, "until": 90.0}, "from", "[0, t_final = 50)"),
        ({"rate": 1.0, "frm": 1.0}, "frm", "did you mean from"),
    ],
)
def test_a_bad_release_is_refused_naming_its_key_and_range(release, key, says):
    err = refused("s", spec(release))
    assert err.name == f"scenes.s.source.release.{key}", err
    assert says in err.allowed, err


def test_a_2d_source_s_release_is_refused_by_the_same_keys():
    err = refused("p", plane({"rate": 0.0}))
    assert err.name == "scenes.p.source.release.rate" and "> 0" in err.allowed
    err = refused("p", plane({"rate": 1.0, "from": 4.0}))
    assert err.name == "scenes.p.source.release.from" and "t_final = 4" in err.allowed


def test_a_reactive_scene_refuses_a_release():
    """The reactive runs start from the source's unit mass at t = 0 (core/runconfig.py refuses a reactive
    run with a release): the scene says so before any job, naming the release."""
    decay = {"kind": "decay", "rate": 0.01}
    err = refused("r", spec({"rate": 1.0}, reaction=decay, candidates=[FD]))
    assert err.name == "scenes.r.source.release" and "reactive" in err.allowed
    Scene.from_config("r", spec(reaction=decay, candidates=[FD]))  # the same scene without it: taken


def test_the_workflow_refuses_a_release_as_the_scene_does_and_its_schema_takes_an_open_until():
    """One declaration: the workflow's parse names the same key in the same words, and the generated
    schema (which Snakemake validates the config with) takes `until: null` and refuses rate 0."""
    import jsonschema
    from conftest import ROOT

    from particle_entropy.pipeline.configcheck import check_config, load_schema, load_yaml

    config = dict(load_yaml(ROOT / "config.yaml"))
    carried = config["scenes"]["carried"]
    source = {"kind": "point", "x0": 0.0}
    bad = {**carried, "source": {**source, "release": {"rate": 1.0, "from": 2.0, "until": 1.0}}}
    with pytest.raises(SettingError) as alone:
        Scene.from_config("carried", bad, config["case_defaults"])
    with pytest.raises(SettingError) as workflow:
        check_config({**config, "scenes": {**config["scenes"], "carried": bad}})
    assert alone.value.name == "scenes.carried.source.release.until"
    assert str(alone.value) == str(workflow.value)
    schema = load_schema()
    good = {**carried, "source": {**source, "release": {"rate": 1.0, "from": 0.0, "until": None}}}
    jsonschema.validate({**config, "scenes": {"carried": good}}, schema)
    zero = {**carried, "source": {**source, "release": {"rate": 0.0}}}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({**config, "scenes": {"carried": zero}}, schema)


def test_a_peclet_base_may_release_and_its_refusals_name_the_base():
    """A sweep's scenes are ordinary scenes at their own v: each carries the base's release (their particle
    runs are then no longer shared across v: runs_at_rest), and a bad release names the base's key."""
    base = {k: v for k, v in spec({"rate": 0.5, "from": 5.0}).items() if k != "v"}
    every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
    assert [every[name].release for name in every.sweep] == [Release(0.5, 5.0, None)] * 2
    base["source"] = {**base["source"], "release": {"rate": -0.5}}
    with pytest.raises(SettingError) as err:  # the sweep's model parses its base: at once
        every = scenes({"scenes_peclet": {"base": base, "v": [0.0, 0.01]}})
        every[every.sweep[1]]
    assert err.value.name == "scenes_peclet.base.source.release.rate"


# ------------------------------------------------------------------------ what the runs get
@pytest.mark.parametrize(
    "source",
    [
        POINT,
        {"kind": "gaussian", "x0": 0.1, "sd": 0.05},
        {"kind": "box", "a": -0.1, "b": 0.1},
        {"kind": "two_gaussians", "x1": -0.1, "sd1": 0.02, "x2": 0.1, "sd2": 0.05, "fraction": 0.3},
    ],
)
def test_every_1d_kind_takes_a_release_and_every_run_carries_it(source):
    scene = Scene.from_config("s", spec({"rate": 0.02, "from": 5.0, "until": 40.0}, source=source))
    want = Release(0.02, 5.0, 40.0)
    assert scene.release == want
    for c in scene.candidates:
        for n in (c.n_lo, c.ladder()[-1]):
            assert scene.run_config(c, n).release == want
        # a job's route: its settings by the run's identity, read back as simulate.py reads them
        job = RunConfig.for_case(replace(c.case, n=c.n_lo), **scene.settings(c))
        assert job.release == want and job.source == scene.source


@pytest.mark.parametrize(
    "source, v",
    [
        ({"kind": "point", "x0": [0.0, 0.0]}, (0.5, 0.0)),
        ({"kind": "gaussian", "x0": [0.0, 0.1], "sd": [0.05, 0.02]}, (0.3, 0.3)),
        ({"kind": "box", "x": [-0.1, 0.1], "y": [-0.05, 0.05]}, (0.0, 0.0)),
    ],
)
def test_every_2d_kind_takes_a_release_and_every_run_carries_it(source, v):
    scene = Scene.from_config("p", plane({"rate": 2.0, "until": 3.0}, source=source, v=v))
    assert scene.dim == 2 and scene.release == Release(2.0, 0.0, 3.0)
    for c in scene.candidates:
        cfg = scene.run_config(c, c.n_lo)
        assert cfg.release == scene.release and cfg.dim == 2
        assert cfg.mass(scene.t_final) == pytest.approx(2.0 * 3.0)  # q (t1 - t0) released by t_final


def test_without_a_release_every_run_is_instantaneous_as_before():
    scene = Scene.from_config("s", spec())
    assert scene.release is None
    assert all(scene.run_config(c, c.n_lo).release is None for c in scene.candidates)
    assert all("release" not in scene.settings(c) for c in scene.candidates)  # the runs keep their identity


def test_a_release_makes_runs_of_their_own():
    """The identity digests the release: no run is shared with the instantaneous scene, nor between two
    rates or two starts; an until at or past t_final is the open release (same plume by t_final)."""
    ids = {}
    for name, release in [
        ("none", None),
        ("open", {"rate": 0.02}),
        ("faster", {"rate": 0.04}),
        ("later", {"rate": 0.02, "from": 5.0}),
        ("ends", {"rate": 0.02, "until": 40.0}),
        ("at_t_final", {"rate": 0.02, "until": 50.0}),
        ("past_t_final", {"rate": 0.02, "until": 80.0}),
        ("null", {"rate": 0.02, "until": None}),
    ]:
        scene = Scene.from_config(name, spec(release))
        ids[name] = [scene.identity(c) for c in scene.candidates]
    distinct = ["none", "open", "faster", "later", "ends"]
    for i, a in enumerate(distinct):
        for b in distinct[i + 1 :]:
            assert not set(ids[a]) & set(ids[b]), (a, b)
    assert ids["at_t_final"] == ids["past_t_final"] == ids["null"] == ids["open"]


def test_a_release_in_a_flow_does_not_run_at_rest():
    """A conservative 1-D scene in a flow runs its particles at rest (shared across v); with a release its
    source stays put while the flow carries what it let out, so no one shift maps the run at rest onto
    the carried plume: its runs are made at the scene's v."""
    plain = Scene.from_config("s", spec())
    leaking = Scene.from_config("s", spec({"rate": 0.02}))
    for c, d in zip(plain.candidates, leaking.candidates):
        if c.case.method != "fd":
            assert plain.runs_at_rest(c)  # the control: the same candidate without a release
            assert plain.settings(c)["v"] == 0.0
        assert not leaking.runs_at_rest(d)
        assert leaking.settings(d)["v"] == 0.01
        assert leaking.frame_shift(d, 50.0) == 0.0


def test_the_particles_domain_holds_the_source_the_flow_leaves_behind():
    """MTPT's particles move with v while a release's source stays: by the release's end t_e the source
    lies |v| t_e behind their centre. The domain from `margin` adds that path; one written too small is
    refused by its key."""
    fast = spec({"rate": 0.02, "until": 30.0}, v=0.05, candidates=[MTPT])
    scene = Scene.from_config("s", fast)
    still = Scene.from_config("s", spec(v=0.05, candidates=[MTPT]))
    assert scene.omega == pytest.approx(still.omega + 2 * 0.05 * 30.0)
    # 2 (|v| t_e + sqrt(2 D t_final)) = 3.63 with the release; 2 sqrt(2 D t_final) = 0.63 without
    Scene.from_config("s", spec(v=0.05, candidates=[MTPT], omega=3.0))
    err = refused("s", {**fast, "omega": 3.0})
    assert err.name == "scenes.s.omega" and "release" in err.allowed


def test_the_points_are_the_runs_and_span_the_released_plume():
    """The scene's measurement points are those its runs are measured at, over the released plume: the
    puffs' mean age t_final - (t0 + t1) / 2 carries their centre."""
    scene = Scene.from_config("s", spec({"rate": 0.02, "from": 10.0, "until": 30.0}))
    for c in scene.candidates:
        assert np.array_equal(scene.points, scene.run_config(c, c.n_lo).points(scene.t_final))
    centre = 0.01 * (50.0 - 20.0)  # x0 + v a, a = 50 - (10 + 30) / 2
    shift = scene.points - measurement_points(scene.points_span)  # the 15 points, each carried alike
    assert shift == pytest.approx(np.full(15, centre), abs=1e-12)


def test_an_rmse_target_is_judged_against_the_release_s_own_plume():
    """The target check (scenes/defined.py) reads the release's exact plume: its concentration is q times
    the unit release's, so a rate 1e4 times smaller makes a field of zeros meet the same target."""
    Scene.from_config("s", spec({"rate": 0.02}))
    err = refused("s", spec({"rate": 2e-6}))
    assert err.name == "scenes.s.target" and "field of zeros" in err.allowed


# ------------------------------------------------------------------------ a 2-D point source's singularity
def test_rmse_at_a_2d_point_source_still_releasing_at_rest_is_refused():
    """At v = 0 the lattice is centred on the source, where a 2-D point source still releasing has an
    infinite concentration: rmse there has no value. Named by the measure."""
    err = refused("p", plane({"rate": 1.0}, v=(0.0, 0.0)))
    assert err.name == "scenes.p.target.measure" and err.value == "rmse"
    assert "entropy or dilution" in err.allowed and "infinite" in err.allowed
    until = refused("p", plane({"rate": 1.0, "until": 4.0}, v=(0.0, 0.0)))  # until = t_final: still on
    assert until.name == "scenes.p.target.measure"


@pytest.mark.parametrize(
    "over",
    [
        {"measure": "entropy"},  # H_C and E integrate the plume: c ~ ln(1/r) is integrable
        {"measure": "dilution"},
        {"release": {"rate": 1.0, "until": 3.0}},  # stopped by t_final: finite everywhere
        {"source": {"kind": "gaussian", "x0": [0.0, 0.0], "sd": [0.02, 0.02]}},  # an extent: finite
    ],
)
def test_what_a_2d_point_release_at_rest_may_measure(over):
    args = {"release": {"rate": 1.0}, "v": (0.0, 0.0), **over}
    scene = Scene.from_config("p", plane(**args))
    assert scene.release is not None


def _on_a_tick(k: int, t: float, d_l: float) -> float:
    """The speed along x that puts the open release's point source on the lattice's tick k (of 15, from
    -3 to 3 sd along the flow) at time t. Its puffs' ages are uniform on [0, t]: mean t / 2, variance
    t^2 / 12, so the plume's centre is v t / 2 ahead of the source and its variance along the flow is
    2 D_L t / 2 + v^2 t^2 / 12; the source sits at (v t / 2) / sd = 3 - 6 k / 14 sd behind it."""
    z = 3.0 - 6.0 * k / 14.0
    return math.sqrt(z * z * d_l / (t * (0.25 - z * z / 12.0)))


def test_rmse_is_refused_where_the_flow_puts_a_lattice_point_on_the_source_and_taken_elsewhere():
    on = _on_a_tick(4, 4.0, 1e-2)
    err = refused("p", plane({"rate": 1.0}, v=(on, 0.0)))
    assert err.name == "scenes.p.target.measure" and "point (4, 7)" in err.allowed
    for speed in (0.9 * on, 1.1 * on, 0.5):  # the source between ticks: every point away from it
        scene = Scene.from_config("p", plane({"rate": 1.0}, v=(speed, 0.0)))
        sds = np.linalg.norm(scene.points - scene.source.centre, axis=1)
        assert sds.min() > 0.0


def test_a_2d_sweep_s_point_release_is_refused_only_at_the_speed_that_needs_the_source():
    base = {k: v for k, v in plane({"rate": 1.0}).items() if k != "v"}
    on = _on_a_tick(4, 4.0, 1e-2)
    every = scenes({"scenes_peclet2d": {"base": base, "v": [0.5 * on, on, 2.0 * on]}})
    every["peclet2d-0"], every["peclet2d-2"]
    with pytest.raises(SettingError) as err:
        every["peclet2d-1"]
    assert err.value.name == "scenes_peclet2d.base.target.measure"
