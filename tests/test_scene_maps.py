"""The maps of a 2-D scene's figure (figures/scene_maps.py, issue 52 point 6): the exact panel is the
exact solution on the map's grid, the model panel a run's concentration as its run scores it, both at
the same levels; a table with no recommended rung still draws, the cheapest candidate's best rung."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pandas as pd
import pytest

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402

from particle_entropy.analysis import scene_search as S  # noqa: E402
from particle_entropy.figures import scene_maps as SM  # noqa: E402
from particle_entropy.figures.scene import scene as draw  # noqa: E402
from particle_entropy.figures.style import save_figure  # noqa: E402
from particle_entropy.models.plane import bilinear, fd_grid  # noqa: E402
from particle_entropy.scenes.scene import Scene  # noqa: E402

FD = {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [16, 64]}
PT = {"method": "pt", "kernel": "adaptive", "n_range": [200, 800]}


_SPEC = {
    "v": [0.5, 0.0],
    "D": {"L": 1.0e-2, "T": 1.0e-3},
    "t_final": 4.0,
    "source": {"kind": "point", "x0": [0.0, 0.0]},
    "target": {"measure": "rmse", "value": 0.05},
}


@pytest.fixture(scope="module")
def plane():
    """A small 2-D scene: a point carried along x, D_T = D_L / 10."""
    return Scene.from_config("plane", {**_SPEC, "candidates": [FD, PT]})


def _fd_state(scene, n: int = 16):
    """A synthetic FD final state on the run's own nodes (x, y, c in the runner's order) and its RunConfig."""
    cfg = scene.run_config(scene.candidates[0], n)
    g = fd_grid(cfg)
    x, y = g.nodes()
    gx, gy = np.meshgrid(x, y, indexing="ij")
    c = np.exp(-((gx - 2.0) ** 2) / 0.2 - gy**2 / 0.02) * 7.0 + 0.3 * np.sin(3.0 * gx)  # not the exact one
    state = pd.DataFrame({"x": gx.ravel(), "y": gy.ravel(), "c": c.ravel()})
    return cfg, g, c, state


def _table(scene, law, value):
    """The finished table of ``scene``'s search on synthetic runs of RMSE law(candidate, n), judged at ``value``."""
    from dataclasses import replace

    scene = replace(scene, value=value)

    def runs(plan):
        rows = []
        for r in plan.itertuples():
            for seed in range(int(r.first), int(r.last) + 1):
                e = law(r.candidate, r.n)
                rows.append(
                    {
                        "candidate": r.candidate,
                        "n": r.n,
                        "half_step": getattr(r, "half_step", False),
                        "seed": seed,
                        "SSE_points": scene.n_points * e * e,
                        "COMIC_points": math.log(e),
                        **{"H_C": 0.0, "H_C_analytic": 0.0, "E": 1.0, "E_analytic": 1.0, "mass_min": 0.0},
                        **{"negative_step": -1, "negative_t": math.nan, "negative_dt": math.nan},
                        **{"mass_total": 1.0, "dV": 0.1, "work": 100.0 * r.n, "steps": 100.0, "core_s": 0.01},
                    }
                )
        return pd.DataFrame(rows)

    plan = S.next_plan(scene, None, None, base_seed=0)
    while not plan["done"].all():
        plan = S.next_plan(scene, plan, runs(plan), base_seed=0)
    return S.result(scene, S.judged(scene, runs(plan)))


def _maps(scene, run):
    fig = Figure(layout="constrained")
    cx, dx, cax = fig.subplots(1, 3, width_ratios=[1, 1, 0.05])
    return SM.draw_maps((cx, dx), cax, scene, run, nodes=60), (cx, dx)


def test_the_exact_panel_is_the_exact_solution_and_the_model_panel_the_fd_nodes_interpolated(plane):
    cfg, g, c, state = _fd_state(plane)
    row = pd.Series({"label": plane.candidates[0].label, "n": 16, "candidate": 0})
    maps, _ = _maps(plane, SM.ModelRun(row, True, cfg, state))
    points = SM.grid_points(maps.x, maps.y)
    ref = plane.reference
    sd = np.sqrt(np.diag(ref.covariance))
    assert maps.x[[0, -1]] == pytest.approx(ref.centre[0] + np.array([-4, 4]) * sd[0])
    assert maps.y[[0, -1]] == pytest.approx(ref.centre[1] + np.array([-4, 4]) * sd[1])
    np.testing.assert_array_equal(maps.exact, ref.density(points).reshape(60, 60))
    np.testing.assert_array_equal(maps.model, bilinear(g, c, points).reshape(60, 60))
    at = plane.points  # the title's RMSE: at the scene's points, as the run is scored
    assert maps.rmse == pytest.approx(np.sqrt(np.mean((bilinear(g, c, at) - ref.density(at)) ** 2)))


def test_both_maps_share_their_levels_and_the_exact_lines(plane):
    cfg, _, _, state = _fd_state(plane)
    row = pd.Series({"label": plane.candidates[0].label, "n": 16, "candidate": 0})
    maps, (cx, dx) = _maps(plane, SM.ModelRun(row, True, cfg, state))
    exact, model = maps.filled
    np.testing.assert_array_equal(exact.levels, maps.levels)
    np.testing.assert_array_equal(model.levels, maps.levels)
    assert exact.get_cmap() is model.get_cmap() and exact.norm.vmax == model.norm.vmax
    assert maps.levels[0] == 0.0 and maps.levels[-1] >= max(maps.exact.max(), maps.model.max())
    assert model.extend == exact.extend == "min"  # the synthetic model dips below 0: the under colour on both
    for ax, lines in zip((cx, dx), maps.lines):  # the exact solution's lines over each map, at the inner levels
        assert lines.axes is ax
        np.testing.assert_array_equal(lines.levels, maps.levels[1:-1])
    assert "recommended" in dx.get_title(loc="left") and "n = 16" in dx.get_title(loc="left")


def test_a_particle_state_is_drawn_as_its_run_scores_it(plane):
    from particle_entropy.models.plane import pt_bandwidth
    from particle_entropy.numerics.particles2d import kde_2d

    cfg = plane.run_config(plane.candidates[1], 200)
    x = plane.reference.centre + np.random.default_rng(1).multivariate_normal([0, 0], plane.reference.covariance, 200)
    state = pd.DataFrame({"x": x[:, 0], "y": x[:, 1], "mass": np.full(200, 1 / 200)})
    points = np.array([[2.0, 0.0], [2.1, 0.05]])
    got = SM.concentration(cfg, state, points)
    np.testing.assert_array_equal(got, kde_2d(points, x, pt_bandwidth(cfg, plane.t_final)))


def test_an_mtpt_state_is_its_masses_over_dv_on_its_triangles(plane):
    from particle_entropy.numerics.particles2d import mtpt_concentration_2d

    mtpt = Scene.from_config(
        "m", {**_SPEC, "candidates": [{"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [1000, 2000]}]}
    )
    cfg = mtpt.run_config(mtpt.candidates[0], 1000)
    x = np.random.default_rng(2).uniform(-1.0, 3.0, (1000, 2))
    m = np.random.default_rng(3).random(1000) / 1000
    state = pd.DataFrame({"x": x[:, 0], "y": x[:, 1], "mass": m, "c": m / cfg.dV})
    points = np.array([[2.0, 0.0], [0.5, 0.5]])
    np.testing.assert_array_equal(SM.concentration(cfg, state, points), mtpt_concentration_2d(points, x, m, cfg.dV))


def test_a_table_with_no_recommended_rung_still_draws_the_cheapest_best_rung(plane, tmp_path):
    # never met: FD's error falls with n, PT's is flat; each candidate's best rung is its least error
    # (the cheaper on a tie), and of those the cheaper is drawn
    table = _table(plane, lambda ci, n: 1.0 / n if ci == 0 else 0.5, value=1e-9)
    assert not table["recommended"].any()
    row, recommended = SM.map_row(table)
    assert not recommended
    best = {ci: g.loc[g["error_mean"].idxmin()] for ci, g in table.groupby("candidate")}
    cheapest = min(best.values(), key=lambda r: r["cost_s"])
    assert (row["candidate"], row["n"]) == (cheapest["candidate"], cheapest["n"])
    cfg, _, _, state = _fd_state(plane)
    fake = SM.ModelRun(pd.Series({"label": "fd", "n": 16, "candidate": 0}), False, cfg, state)
    fig = draw(table, (plane, fake))
    save_figure(fig, tmp_path / "none.png", tmp_path / "none.pdf")
    titles = [ax.get_title(loc="left") for ax in fig.axes]
    assert any("none recommended" in t for t in titles)
    fig = draw(table, (plane, None))  # no rung with an error: the exact map alone
    fig.canvas.draw()
    assert any("no rung has an error" in ax.get_title(loc="left") for ax in fig.axes)


def test_the_plot_job_runs_the_recommended_rung_on_the_first_seed(plane):
    table = _table(plane, lambda ci, n: 0.01 if (ci, n) == (0, 16) else 1.0, value=0.05)
    assert table.loc[table["recommended"], ["candidate", "n"]].values.tolist() == [[0, 16]]
    run = SM.model_run(plane, table, base_seed=3)
    assert run.recommended and run.seed == 3 and run.cfg.n == 16 and run.cfg.method == "fd"
    assert len(run.state) == 17 * 17 and {"x", "y", "c"} <= set(run.state)


def test_a_point_still_releasing_is_mapped_in_decades():
    """A 2-D point source still releasing is infinite at its point: the map's levels are 1 and 3 times the
    powers of ten from three decades below its peak, where even bands would leave the plume's body blank."""
    np.testing.assert_allclose(SM.decade_levels(54.0), [0.0, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0], rtol=1e-12)
    source = {"kind": "point", "x0": [0.0, 0.0], "release": {"rate": 1.0}}
    well = Scene.from_config("well", {**_SPEC, "source": source, "candidates": [FD]})
    maps, (cx, _) = _maps(well, None)
    top = float(np.nanmax(maps.exact))
    assert maps.levels[0] == 0.0 and maps.levels[-2] < top <= maps.levels[-1]
    assert top * 1e-3 <= maps.levels[1] < top * 3e-3
    exact = maps.filled[0]
    assert exact.norm(maps.levels[1:-1]).tolist() == list(range(1, len(maps.levels) - 1))  # a colour a band
    assert "M/L" in cx.figure.axes[-1].get_ylabel()  # a release's mass, not a unit mass
