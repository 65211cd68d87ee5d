"""A reaction kind added after the one runner (issue 51): first-order production A -> A + C, dC/dt =
lambda A. Its class (core/reactions.Production) is all the code it took; these are its tests.

Closed form: A is the conservative plume and C = lambda t A everywhere, because C made at time s is
carried by the same linear transport as A from then on. FD (every scheme is linear in its rows) and
MTPT (every species row walks and exchanges by the same P) hold it to round-off; PT's Poisson births
hold it in the mean."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.core.reactions import REACTIONS, Production, Reaction
from particle_entropy.models.simulate import run_arrow
from particle_entropy.scenes import reference as reactive
from particle_entropy.scenes.scene import Scene

RATE, T = 0.05, 20.0
CANDIDATES = [
    {"method": "fd", "kernel": "implicit", "advection": "upwind", "fd_dt": 0.5, "n_range": [64, 512]},
    {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [64, 512]},
    {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [100, 2000]},
    {"method": "mtpt", "kernel": "sph", "eta": 1, "n_range": [100, 2000]},
    {"method": "pt", "kernel": "adaptive", "n_range": [2000, 8000]},
]


def _scene(**over) -> Scene:
    spec = {
        "D": 1e-3,
        "v": 0.05,
        "t_final": T,
        "source": {"kind": "gaussian", "x0": 0.0, "sd": 0.2},
        "reaction": {"kind": "production", "rate": RATE},
        "target": {"measure": "product", "value": 0.01},
        "candidates": CANDIDATES,
    }
    return Scene.from_config("made", {**spec, **over})


def test_production_is_a_kind_of_its_own_and_reads_back():
    assert REACTIONS["production"] is Production
    reaction = Reaction.of({"kind": "production", "rate": 0.3})
    assert reaction.kinetics == Production(0.3) and reaction.record() == {"kind": "production", "rate": 0.3}
    assert reaction.closed_form(2.0) == (1.0, pytest.approx(0.6, rel=1e-15))
    with pytest.raises(ValueError):
        Production(-1.0)


@pytest.mark.parametrize(
    "reaction, key",
    [
        ({"kind": "production"}, "reaction.rate"),
        ({"kind": "production", "rate": 0.0}, "reaction.rate"),
        ({"kind": "production", "rate": 1.0, "B": {"uniform": 1.0}}, "reaction.B"),
        ({"kind": "production", "rate": 1.0, "k": 1.0}, "reaction.k"),
    ],
)
def test_bad_production_keys_are_refused_by_key_path(reaction, key):
    with pytest.raises(SettingError) as err:
        _scene(reaction=reaction)
    assert f"scenes.made.{key}" in str(err.value)


def test_the_reference_is_the_plume_and_lambda_t_of_it():
    scene = _scene()
    ref = reactive.compute(reactive.physics(scene))
    assert ref["product_mass"] == pytest.approx(RATE * T, rel=1e-15)
    plume = scene.source.density(np.asarray(ref["points"]), scene.D, scene.v, T)
    np.testing.assert_allclose(ref["a_points"], plume, rtol=1e-15)
    np.testing.assert_allclose(ref["c_points"], RATE * T * plume, rtol=1e-15)
    assert ref["product_series"][-1] == pytest.approx(RATE * T, rel=1e-15)


@pytest.mark.parametrize("ci", [0, 1, 2, 3])
def test_grids_and_mtpt_make_c_lambda_t_a_to_round_off(ci):
    scene = _scene()
    ref = {k: np.asarray(v) if isinstance(v, list) else v for k, v in reactive.compute(reactive.physics(scene)).items()}
    cand = scene.candidates[ci]
    table, _ = run_arrow(scene.run_config(cand, cand.n_lo * 2), reference=ref)
    t = table.to_pandas()
    # A is kept whole (the unit mass, less what an FD window's ends let out) and the C still held
    # (mass_total = A + C held) is lambda t_k of it at every step, to round-off
    held_c = t["mass_total"] - t["mass_A"]
    np.testing.assert_allclose(held_c.iloc[1:], (RATE * t["time"] * t["mass_A"]).iloc[1:], rtol=1e-12)
    assert (t["mass_C"] >= held_c - 1e-15).all()  # made: what is held and what left
    np.testing.assert_allclose(t["mass_B"], 0.0, atol=0.0)
    last = t.iloc[-1]
    # C's SSE at the points is A's times (lambda t)^2: C_C = lambda t C_A on every node or particle
    assert last["SSE_points_C"] == pytest.approx(last["SSE_points"] * (RATE * T) ** 2, rel=1e-9)
    assert last["product_error"] < 1e-3  # the unit mass is kept: only the window's ends lose any


def test_pt_births_match_lambda_t_in_the_mean():
    scene = _scene()
    ref = {k: np.asarray(v) if isinstance(v, list) else v for k, v in reactive.compute(reactive.physics(scene)).items()}
    cand = scene.candidates[4]
    made = []
    for seed in range(6):
        cfg = scene.run_config(cand, 2000, seed=seed)
        last = run_arrow(cfg, reference=ref)[0].to_pandas().iloc[-1]
        assert last["mass_A"] == 1.0  # A's particles are never taken
        made.append(last["mass_C"])
    # births are Poisson(lambda dt) per A per step: the count after t has mean lambda t N and variance lambda t N
    n, mean = 2000, RATE * T
    se = math.sqrt(mean / n / len(made))
    assert abs(np.mean(made) - mean) < 4 * se
