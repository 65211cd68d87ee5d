"""The profile panel of a 2-D release scene's figure (figures/scene_profile.py, issue 53 point 4): the
exact line is Wilson and Miller's plume along the axis, the models' lines are their runs read as they are
scored, and the panel draws the recommended rung and each FD candidate's best rung."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from test_scene_maps import _table  # noqa: E402  (a finished search on synthetic errors)

from particle_entropy.core.release import point_release_2d  # noqa: E402
from particle_entropy.figures import scene_maps as SM  # noqa: E402
from particle_entropy.figures import scene_profile as SP  # noqa: E402
from particle_entropy.figures.scene import scene as draw  # noqa: E402
from particle_entropy.figures.style import save_figure  # noqa: E402
from particle_entropy.scenes.scene import Scene  # noqa: E402

V, D_L, D_T, RATE, T = (0.4, 0.3), 1e-2, 1e-3, 2.0, 4.0  # a well in a flow at 37 degrees to the grid
UPWIND = {"method": "fd", "kernel": "implicit", "advection": "upwind", "courant": 0.75, "n_range": [16, 32]}
TVD = {**UPWIND, "advection": "tvd"}
PT = {"method": "pt", "kernel": "adaptive", "n_range": [200, 400]}


@pytest.fixture(scope="module")
def well():
    """A 2-D point source at (0.1, -0.2) releasing RATE from t = 0 on, judged at T by the RMSE at its lattice,
    none of whose points is on the source (the synthetic tables below give the errors)."""
    spec = {
        "v": list(V),
        "D": {"L": D_L, "T": D_T},
        "t_final": T,
        "source": {"kind": "point", "x0": [0.1, -0.2], "release": {"rate": RATE}},
        "target": {"measure": "rmse", "value": 0.05},
        "candidates": [UPWIND, TVD, PT],
    }
    return Scene.from_config("well", spec)


@pytest.fixture(scope="module")
def drawn(well, tmp_path_factory):
    """The figure of a search where PT at N = 200 is recommended and FD's errors fall with n."""
    table = _table(well, lambda ci, n: 0.01 if ci == 2 else 4.0 / n, value=0.05)
    assert table.loc[table["recommended"], ["candidate", "n"]].values.tolist() == [[2, 200]]
    run = SM.model_run(well, table, base_seed=0)
    runs = SP.profile_runs(well, table, 0, [run])
    fig = draw(table, (well, run), runs)
    out = tmp_path_factory.mktemp("profile")
    save_figure(fig, out / "well.png", out / "well.pdf")
    return table, run, runs, fig


def test_the_panel_draws_the_recommended_rung_and_each_fd_scheme_s_best(drawn):
    table, run, runs, fig = drawn
    assert [(int(r.row["candidate"]), int(r.row["n"]), r.recommended) for r in runs] == [
        (2, 200, True),
        (0, 32, False),  # FD's least errors: its finest rungs
        (1, 32, False),
    ]
    assert runs[0] is run  # the map's run is not run again
    panel = next(ax for ax in fig.axes if "along the plume's axis" in ax.get_title(loc="left"))
    assert panel.get_title(loc="left").startswith("(b)")
    exact, *models = [line for line in panel.get_lines() if len(line.get_xdata()) == SP.AXIS_NODES]
    np.testing.assert_array_equal(exact.get_ydata(), fig.profile.exact)
    assert len(models) == 3 and all("max |error|" in m.get_label() for m in models)
    assert "(recommended)" in models[0].get_label()


def test_the_exact_line_is_wilson_and_miller_s_plume_along_the_flow(well, drawn):
    """Along the flow through the source, the drawn exact line equals the closed form (Hantush's W) at
    points upstream and downstream, away from the source, where it is infinite (drawn as a gap)."""
    profile = drawn[3].profile
    s, points = SP.axis(well)
    np.testing.assert_array_equal(s, profile.s)
    e = np.array(V) / math.hypot(*V)
    np.testing.assert_allclose(points - np.array([0.1, -0.2]), s[:, None] * e, atol=1e-15)
    picks = [i for i in np.linspace(0, len(s) - 1, 9).astype(int) if abs(s[i]) > 0.02]
    closed = point_release_2d(points[picks], T, RATE, D_L, D_T, V, x0=(0.1, -0.2))
    assert np.all(closed[len(closed) // 2 :] > 0)
    np.testing.assert_allclose(profile.exact[picks], closed, rtol=1e-8)
    centre = well.reference.centre  # the axis spans the lattice's +- 3 sd along the flow
    sd = math.sqrt(e @ np.asarray(well.reference.covariance) @ e)
    assert s[[0, -1]] == pytest.approx(e @ (centre - np.array([0.1, -0.2])) + np.array([-3, 3]) * sd)


def test_each_model_line_is_its_run_read_as_scored_and_its_error_is_taken_beyond_b(well, drawn):
    _, _, runs, fig = drawn
    profile = fig.profile
    _, points = SP.axis(well)
    for r in runs:
        label = SP.legend_label(r)
        np.testing.assert_array_equal(profile.models[label], SM.concentration(r.cfg, r.state, points))
        far = np.abs(profile.s) >= 2.0 * D_L / math.hypot(*V)
        assert profile.max_error(label) == np.nanmax(np.abs(profile.models[label] - profile.exact)[far])


def test_a_scene_without_a_release_keeps_its_comic_panel(tmp_path):
    """Only a release scene swaps panel b for the profile."""
    plain = Scene.from_config(
        "plain",
        {
            "v": list(V),
            "D": {"L": D_L, "T": D_T},
            "t_final": T,
            "source": {"kind": "point", "x0": [0.0, 0.0]},
            "target": {"measure": "rmse", "value": 0.05},
            "candidates": [TVD],
        },
    )
    table = _table(plain, lambda ci, n: 1.0 / n, value=0.05)
    fig = draw(table, (plain, None))
    assert any("COMIC" in ax.get_title(loc="left") for ax in fig.axes)
    assert not hasattr(fig, "profile")
