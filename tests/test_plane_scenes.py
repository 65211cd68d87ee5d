"""2-D scenes as data (issue 52 point 1): the keys, and every refusal before any job by its key path."""

import math

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.pipeline.configcheck import load_yaml
from particle_entropy.scenes.scene import Scene, scenes

BASE = {
    "v": [0.5, 0.0],
    "D": {"L": 1e-2, "T": 1e-3},
    "t_final": 4.0,
    "source": {"kind": "point", "x0": [0.0, 0.0]},
    "target": {"measure": "rmse", "value": 0.025},
    "candidates": [
        {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [32, 256]},
        {"method": "pt", "kernel": "adaptive", "n_range": [1000, 8000]},
    ],
}


def test_a_2d_scene_s_tensor_follows_its_flow():
    """D = D_T I + (D_L - D_T) v v^T / |v|^2, written here from the formula: at 30 degrees."""
    th = math.radians(30.0)
    scene = Scene.from_config("s", {**BASE, "v": [math.cos(th), math.sin(th)]})
    u = np.array([math.cos(th), math.sin(th)])
    assert np.allclose(scene.D, 1e-3 * np.eye(2) + 9e-3 * np.outer(u, u), rtol=1e-14, atol=0)
    assert scene.dim == 2 and scene.n_points == 225


@pytest.mark.parametrize(
    "change, key",
    [
        ({"v": [1.0, 0.0, 0.0]}, "scenes.s.v"),  # three components
        ({"D": {"L": 0.0, "T": 1e-3}}, "scenes.s.D.L"),
        ({"D": {"L": 1e-2, "T": -1.0}}, "scenes.s.D.T"),
        ({"D": {"L": math.nan, "T": 1e-3}}, "scenes.s.D.L"),
        ({"D": {"L": 1e-2}}, "scenes.s.D.T"),  # half a pair
        ({"D": {"L": 1e-2, "T": 1e-3, "x": 1e-3}}, "scenes.s.D.x"),  # both pairs
        ({"D": 1e-3}, "scenes.s.D"),  # 1-D and 2-D keys mixed
        ({"v": 0.5}, "scenes.s.v"),
        ({"source": {"kind": "gaussian", "x0": 0.0, "sd": 0.1}}, "scenes.s.source"),
        ({"source": {"kind": "gaussian", "x0": [0.0, 0.0], "sd": [0.1, -0.1]}}, "scenes.s.source.sd[1]"),
        ({"v": [0.0, 0.0]}, "scenes.s.D.L"),  # along and across no flow: give {x, y}
        ({"reaction": {"kind": "decay", "rate": 0.1}}, "scenes.s.reaction"),
        ({"fd_length": 0.5}, "scenes.s.fd_length"),
    ],
)
def test_a_bad_2d_scene_is_refused_by_its_key_path(change, key):
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", {**BASE, **change})
    assert err.value.name == key


def test_an_fd_rung_past_the_memory_bound_names_the_rung_its_grid_and_its_bytes():
    cands = [{"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [32, 4096]}]
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", {**BASE, "candidates": cands})
    assert err.value.name == "scenes.s.candidates[0].n_range"
    assert "4,096 x 4,096" in err.value.allowed and "bytes" in err.value.allowed


def test_the_shipped_2d_scenes_are_a_flow_along_and_at_45_degrees_to_the_grid():
    table = scenes(load_yaml("config.yaml"))
    along, oblique = table["plume2d"], table["oblique"]
    assert along.dim == oblique.dim == 2
    assert along.v[1] == 0.0 and math.isclose(oblique.v[0], oblique.v[1], rel_tol=1e-15)
    assert math.isclose(along.speed, oblique.speed, rel_tol=1e-15)
    assert np.allclose(np.linalg.eigvalsh(np.asarray(along.D)), np.linalg.eigvalsh(np.asarray(oblique.D)))


def test_a_2d_scene_is_priced_by_the_plane_s_cost_model_unless_it_writes_its_own():
    """The workflow's schema fills in the 1-D default `cost`; a 2-D scene reads that as unset and takes
    settings.PLANE_COST (MTPT's 2-D step costs ~20 times the 1-D default's), but keeps one written."""
    from particle_entropy.core.settings import PLANE_COST, SCENE, defaults

    filled = Scene.from_config("s", {**BASE, "cost": defaults(SCENE)["cost"]})
    assert dict(filled.cost) == {m: tuple(p) for m, p in PLANE_COST.items()}
    own = {"fd": [1.0, 2.0], "pt": [3.0, 4.0], "mtpt": [5.0, 6.0]}
    assert dict(Scene.from_config("s", {**BASE, "cost": own}).cost) == {m: tuple(p) for m, p in own.items()}
