"""The maps of a 2-D scene's figure (issue 52): the exact concentration at t_final beside a model's,
on one grid over the plume (MAP_REACH sd of the exact covariance each way along x and y, MAP_NODES
a side), with the same filled-contour levels and colour scale and the exact one's contour lines
drawn over both, so that a reader sees where the model departs from it.

The model is the recommended candidate at its recommended rung, run once more on the scene's first
seed (base_seed) for its final state (``model_run``: the scene's runs keep no state); when nothing
is recommended, the cheapest candidate's best rung (``map_row``), its panel saying so. Its
concentration on the grid is the one its run is scored with (``concentration``, models/plane.at_points): FD's nodes
bilinearly interpolated (models/plane.bilinear), MTPT's m / dV on its particles' triangles
(particles2d.mtpt_concentration_2d), PT's kernel estimate with H = N^(-1/3) Sigma (models/plane.pt_bandwidth).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from .style import BLACK, VERMILLION

MAP_NODES = 200  # grid points a side
MAP_REACH = 4.0  # the grid spans the exact plume's centre +- 4 sd along x and y
LEVELS = 10  # filled-contour bands, at most (MaxNLocator's round numbers from 0 to the larger peak)
DECADES = 3  # a plume infinite at its source: bands 1 and 3 times each power of ten, this many decades down
CMAP = "YlGnBu"  # light where nothing is: the plume stands out on white


@dataclass(frozen=True)
class ModelRun:
    """A model's final state, the map's model panel: the table row it comes from (label, n, ...),
    whether the scene recommends it, the run's settings and state (models/simulate.run_arrow; the
    state in the scene's frame, where its plume is, also for a run computed at rest: model_run), its
    seed and the wall time the plot job spent on it [s]."""

    row: pd.Series
    recommended: bool
    cfg: object  # RunConfig
    state: pd.DataFrame
    seed: int = 0
    wall_s: float = math.nan


@dataclass(frozen=True)
class Maps:
    """What the map panels drew: the grid's ticks, the exact and model concentrations on it (x along
    the first axis), the shared levels, the filled contours (exact, model; model None without a run)
    and the exact contour lines over each, the model's RMSE at the scene's points."""

    x: np.ndarray
    y: np.ndarray
    exact: np.ndarray
    model: np.ndarray | None
    levels: np.ndarray
    filled: tuple
    lines: tuple
    rmse: float


def best_rungs(table: pd.DataFrame) -> pd.DataFrame:
    """Every candidate's best rung: its scored run of least mean error (the cheaper on a tie), one row a
    candidate that has one, in the table's candidate order."""
    err = table["error_mean"].astype(float)
    ran = table[np.isfinite(err) & (table["unscored"] == "")]
    best = ran.sort_values(["error_mean", "cost_s"]).groupby("candidate", sort=False).head(1)
    return best.sort_values("candidate")


def map_row(table: pd.DataFrame) -> tuple[pd.Series | None, bool]:
    """The rung the model panel draws, and whether it is the recommended one: the recommended row;
    else, of every candidate's best rung (``best_rungs``), the cheapest (least counted cost); (None,
    False) if no rung has an error."""
    best = table[table["recommended"]]
    if len(best):
        return best.iloc[0], True
    per_candidate = best_rungs(table)
    if not len(per_candidate):
        return None, False
    return per_candidate.sort_values(["cost_s", "error_mean"]).iloc[0], False


def model_run(scene, table: pd.DataFrame, base_seed: int) -> ModelRun | None:
    """The final state of the rung ``map_row`` picks, run once on the scene's first seed; None if none."""
    row, recommended = map_row(table)
    return None if row is None else run_row(scene, row, recommended, base_seed)


def run_row(scene, row: pd.Series, recommended: bool, base_seed: int) -> ModelRun:
    """The final state of the table ``row``'s rung (its candidate and n), run once on the scene's first seed."""
    from ..models.simulate import run

    candidate = scene.candidates[int(row["candidate"])]
    cfg = scene.run_config(candidate, int(row["n"]), seed=int(base_seed))
    start = time.perf_counter()
    _, state = run(cfg, want_state=True)
    wall = time.perf_counter() - start
    # where the scene's plume is: a particle run computed at rest, carried by v t_final (Scene.runs_at_rest)
    dx, dy = scene.frame_shift(candidate, scene.t_final)
    state = state.assign(x=state["x"] + dx, y=state["y"] + dy)
    return ModelRun(row, recommended, cfg, state, int(base_seed), wall)


def map_grid(reference, nodes: int = MAP_NODES) -> tuple[np.ndarray, np.ndarray]:
    """The ticks along x and y of the map: the exact plume's centre +- MAP_REACH sd of its covariance."""
    sd = np.sqrt(np.diag(reference.covariance))
    return tuple(np.linspace(c - MAP_REACH * s, c + MAP_REACH * s, nodes) for c, s in zip(reference.centre, sd))


def grid_points(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The (len(x) len(y), 2) points of the grid, x along the first axis (reshape (len(x), len(y)))."""
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


def concentration(cfg, state: pd.DataFrame, points: np.ndarray) -> np.ndarray:
    """A 2-D run's concentration at ``points`` (M, 2) from its final ``state``, as its run scores it
    (models/plane.at_points)."""
    from ..models.plane import at_points

    return at_points(cfg, state)(points)


def draw_maps(axes, cax, scene, run: ModelRun | None, nodes: int = MAP_NODES) -> Maps:
    """Draw the exact map in axes[0] and ``run``'s in axes[1] (a note where there is none), one colour
    bar in ``cax``; -> what was drawn (Maps)."""
    exact_ref = scene.reference
    x, y = map_grid(exact_ref, nodes)
    points = grid_points(x, y)
    exact = exact_ref.density(points).reshape(len(x), len(y))
    model = rmse = None
    if run is not None:
        model = concentration(run.cfg, run.state, points).reshape(len(x), len(y))
        at = scene.points
        rmse = float(np.sqrt(np.mean((concentration(run.cfg, run.state, at) - exact_ref.density(at)) ** 2)))
    top = max(float(np.nanmax(exact)), float(np.nanmax(model)) if model is not None else 0.0)
    singular = bool(getattr(exact_ref, "singular", False))  # a 2-D point still releasing: c ~ ln(1/r) at it
    levels = decade_levels(top) if singular else even_levels(top)
    below = model is not None and float(np.nanmin(model)) < 0.0  # a model's negative values: the under colour
    style = {"levels": levels, **_colours(levels), "extend": "min" if below else "neither"}
    lines_at = levels[1:-1]
    filled, lines = [], []
    for ax, c in zip(axes, (exact, model)):
        ax.set_aspect("equal")
        filled.append(None if c is None else ax.contourf(x, y, c.T, **style))
        lines.append(ax.contour(x, y, exact.T, levels=lines_at, colors=BLACK, linewidths=0.7))
        ax.set_xlim(x[0], x[-1])
        ax.set_ylim(y[0], y[-1])
        ax.set_xlabel("x [L]")
    axes[0].set_ylabel("y [L]")
    axes[0].set_title(f"(c) the exact concentration\nat t_final = {scene.t_final:g}", loc="left", fontsize=10)
    axes[1].set_title(_model_title(run, rmse), loc="left", fontsize=10)
    if run is None:
        axes[1].text(0.5, 0.5, "no model to draw", transform=axes[1].transAxes, ha="center", color="0.3")
    else:
        key = [Line2D([], [], color=BLACK, lw=0.7), Patch(facecolor=style["cmap"](0.75), edgecolor="none")]
        axes[1].legend(key, ["exact", "model"], loc="upper right", fontsize=8, framealpha=0.9)
    cbar = axes[0].figure.colorbar(filled[0], cax=cax)
    cbar.set_label(concentration_label(scene))
    return Maps(x, y, exact, model, levels, tuple(filled), tuple(lines), math.nan if rmse is None else rmse)


def even_levels(top: float) -> np.ndarray:
    """At most LEVELS bands of round, even width from 0 to at least ``top`` (MaxNLocator)."""
    levels = MaxNLocator(nbins=LEVELS).tick_values(0.0, top)
    levels = levels[levels >= 0.0]
    if levels[-1] < top:
        levels = np.append(levels, levels[-1] + (levels[1] - levels[0]))
    return levels


def decade_levels(top: float) -> np.ndarray:
    """0, then 1 and 3 times each power of ten from DECADES decades below ``top`` up to the first at or above
    it: a plume whose concentration is infinite at its source (a 2-D point still releasing) has its body
    DECADES decades below its peak on any grid near the source, where even bands would leave it blank (the
    MT3DMS manual contours its wells' plumes so, at 0.1, 1, 10, 50 mg/L)."""
    low = math.floor(math.log10(top)) - DECADES
    steps = [m * 10.0**k for k in range(low, low + DECADES + 2) for m in (1.0, 3.0)]
    steps = [x for x in steps if x >= top * 10.0**-DECADES]
    cut = next(i for i, x in enumerate(steps) if x >= top)
    return np.array([0.0, *steps[: cut + 1]])


def concentration_label(scene) -> str:
    """The axis label of a 2-D scene's concentration: of its unit mass [1/L^2], or of a release's mass [M/L^2]."""
    return r"concentration $c$ [M/L$^2$]" if scene.release is not None else r"concentration $c$ [1/L$^2$]"


def _colours(levels: np.ndarray) -> dict:
    """contourf's colours and norm for the bands between ``levels``: white below the first level above 0,
    then CMAP's from light to dark, one a band whatever its width; a value below 0 (a model's undershoot)
    in VERMILLION."""
    bands = len(levels) - 1
    shades = matplotlib.colormaps[CMAP](np.linspace(0.12, 1.0, max(bands - 1, 1)))
    cmap = ListedColormap(np.vstack([[1.0, 1.0, 1.0, 1.0], shades])[:bands]).with_extremes(under=VERMILLION)
    return {"cmap": cmap, "norm": BoundaryNorm(levels, bands)}


def _model_title(run: ModelRun | None, rmse: float | None) -> str:
    """The model panel's title: its label, n and RMSE at the points; says when it is not recommended."""
    if run is None:
        return "(d) none recommended\nand no rung has an error"
    r = run.row
    what = f"{r['label']}\nn = {int(r['n']):,}, RMSE at the points {rmse:.3g}"
    if run.recommended:
        return f"(d) recommended: {what}"
    return f"(d) none recommended; the cheapest best rung: {what}"
