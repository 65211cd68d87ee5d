"""A target its reference cannot judge (scenes/defined.py, issue 50): refused before any job where
the reference is a closed form, else every candidate stopped with the reason and nothing recommended."""

import numpy as np
import pytest

from particle_entropy.analysis import scene_search as S
from particle_entropy.core.case import SettingError
from particle_entropy.scenes.defined import undefined
from particle_entropy.scenes.scene import Scene

PTS = np.linspace(-1.0, 1.0, 15)


def _ref(product=0.5, product_error=1e-6, a=1.0, c=1.0, err=1e-6):
    return {
        "product_mass": product,
        "product_error": product_error,
        "a_points": a * np.exp(-PTS * PTS),
        "a_error": np.full(15, err),
        "c_points": c * np.exp(-PTS * PTS),
        "c_error": np.full(15, err),
    }


@pytest.mark.parametrize(
    "measure, value, ref, why",
    [
        ("product", 0.02, _ref(product=0.0), "makes no product"),
        ("product", 0.02, _ref(product=None, product_error=None), "makes no product"),
        ("product", 0.02, _ref(product=1e-3, product_error=1e-4), "own error"),  # 10 % of it > 2 %
        ("rmse", 0.05, _ref(a=1e-3), "field of zeros"),
        ("product_rmse", 0.05, _ref(c=0.0), "field of zeros"),
        ("rmse", 0.05, _ref(err=0.1), "own error"),
    ],
)
def test_each_measure_s_undefined_target_is_named(measure, value, ref, why):
    assert why in undefined(measure, value, ref)


@pytest.mark.parametrize("measure", ["product", "rmse", "product_rmse"])
def test_a_target_the_reference_resolves_is_defined(measure):
    assert undefined(measure, 0.02, _ref()) == ""


def _scene(reaction, measure="product", value=0.02, fd=(64, 256), mtpt=(100, 400)):
    spec = {
        "D": 1e-4,
        "t_final": 20.0,
        "source": {"kind": "gaussian", "x0": 0.0, "sd": 0.05},
        "reaction": reaction,
        "target": {"measure": measure, "value": value},
        "candidates": [
            {"method": "fd", "kernel": "implicit", "fd_dt": 0.5, "n_range": list(fd)},
            {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": list(mtpt)},
        ],
    }
    if reaction is None:  # a conservative scene
        del spec["reaction"]
    return Scene.from_config("r", spec)


def test_a_decay_that_leaves_no_a_is_refused_before_any_job_naming_the_reaction():
    # rate 1e300: C_A is 0 everywhere at t_final, so RMSE <= 0.05 is met by a field of zeros
    with pytest.raises(SettingError) as err:
        _scene({"kind": "decay", "rate": 1e300}, measure="rmse", value=0.05)
    assert err.value.name == "scenes.r.target" and "'rate': 1e+300" in err.value.allowed
    assert "field of zeros" in err.value.allowed
    _scene({"kind": "decay", "rate": 0.01}, measure="rmse", value=0.05)  # A left to judge: accepted


def test_a_b_plume_that_never_meets_a_stops_every_candidate_and_recommends_nothing():
    # issue 50: B at [100, 101], A at 0, t_final 20: the reference makes no product, every error was
    # NaN and every candidate read "not met within n_range"
    far = {"kind": "bimolecular", "k": 1.0, "B": {"source": {"kind": "box", "a": 100.0, "b": 101.0}}}
    scene = _scene(far, fd=(1024, 4096), mtpt=(1000, 4000))  # grids fine enough for a 200-wide window
    search = S.SceneSearch(scene, _ref(product=0.0, product_error=0.0))
    plan = search.first_plan(0)
    assert plan.empty and plan["done"].all()  # no job runs
    out = S.result(scene, S.judged(scene, S.read_runs(plan, [])), search.undefined)
    assert len(out) == 2 and not out["recommended"].any() and not out["meets"].any()
    assert out["stopped"].str.startswith("target undefined: the reference makes no product").all()
    assert out["unscored"].str.startswith("not run: target undefined").all()
    assert S.SceneSearch(scene, _ref()).first_plan(0)["n"].tolist() == [1024, 1000]  # defined: it runs


def test_a_run_whose_error_is_not_finite_is_unscored_not_failed():
    scene = _scene({"kind": "decay", "rate": 0.01})
    row = {"candidate": 0, "negative_step": -1, "mass_total": 1.0, "mass_lost_BC": 0.0, "product_error": np.nan}
    assert S.unscored(scene, row) == "its product error is not finite"


def test_a_conservative_rmse_target_a_field_of_zeros_meets_is_refused_naming_its_plume_s_rms():
    """A Gaussian plume at rest: sd^2 = 0.05^2 + 2 D t; its 15 points span +- REACH sqrt(2 sd^2)
    (Scene.points_span), where the exact density's RMS is what a field of zeros scores. A target at
    or above it is refused by scenes.<name>.target before any job; just below it is accepted."""
    from particle_entropy.core import measures as M
    from particle_entropy.core.settings import SCENE_REACH

    sd = np.sqrt(0.05**2 + 2.0 * 1e-4 * 20.0)
    x = M.measurement_points(2.0 * SCENE_REACH * np.sqrt(2.0) * sd)
    rms = float(np.sqrt(np.mean((np.exp(-0.5 * (x / sd) ** 2) / (sd * np.sqrt(2.0 * np.pi))) ** 2)))
    with pytest.raises(SettingError) as err:
        _scene(None, measure="rmse", value=1.001 * rms)
    assert err.value.name == "scenes.r.target" and f"{rms:.3g}" in err.value.allowed
    _scene(None, measure="rmse", value=0.999 * rms)  # a plume still above its target somewhere: accepted
