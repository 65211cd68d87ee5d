"""The concentration along the plume's axis in a 2-D release scene's figure (issue 53 point 4), drawn as
the MT3DMS manual compares its schemes with Wilson and Miller's solution: the exact plume
(core/released.py) and, on the same line, the recommended model and each FD candidate's best rung
(scene_maps.best_rungs), each read as its run is scored (scene_maps.concentration).

The axis runs through the source along the flow v (along x at v = 0) over the measurement lattice's
extent along it, the released plume's centre +- LATTICE_SDS sd (core/reference2d.lattice). A point source
still releasing is infinite where it stands and grows as ln(1/r) toward it (Wilson and Miller's W(u,
beta) as beta = r |v| / (2 D_L) -> 0): within B = 2 D_L / |v| of it no grid and no particle cloud can
follow it. ``Profile.max_error`` is therefore taken beyond B, and the panel's height is set by the exact
plume and the models beyond B.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..core.reference2d import LATTICE_SDS  # the axis spans the lattice's extent along it
from .scene_maps import ModelRun, best_rungs, concentration, concentration_label, run_row
from .style import BLACK, style_axes

AXIS_NODES = 401  # points along the axis


@dataclass(frozen=True)
class Profile:
    """What the profile panel drew: the distance s from the source along the axis [L], the exact
    concentration there (NaN on a source that is infinite), each drawn model's by its legend label, and
    B = 2 D_L / |v| [L], the distance from the source within which ``max_error`` does not look."""

    s: np.ndarray
    exact: np.ndarray
    models: dict[str, np.ndarray]
    near: float

    def max_error(self, label: str) -> float:
        """The largest |c_model - c_exact| along the axis beyond ``near`` of the source [M/L^2]."""
        far = np.abs(self.s) >= self.near
        return float(np.nanmax(np.abs(self.models[label] - self.exact)[far]))


def direction(scene) -> np.ndarray:
    """The axis' unit vector: along v, or along x at v = 0."""
    v = np.asarray(scene.v, dtype=np.float64)
    speed = float(np.hypot(*v))
    return v / speed if speed > 0 else np.array([1.0, 0.0])


def near_length(scene) -> float:
    """B = 2 D_L / |v|, Wilson and Miller's length, within which the plume of a point still releasing
    grows as ln(1/r) toward it (core/release.point_release_2d); 0 at v = 0 [L]."""
    return 2.0 * scene.d_along / scene.speed if scene.speed > 0 else 0.0


def axis(scene, nodes: int = AXIS_NODES) -> tuple[np.ndarray, np.ndarray]:
    """(s, points): the distances from the source along ``direction`` and the points (nodes, 2) there,
    over the released plume's centre +- LATTICE_SDS sd along the axis [L]."""
    ref = scene.reference
    e = direction(scene)
    source = np.asarray(scene.source.centre, dtype=np.float64)
    middle = float(e @ (np.asarray(ref.centre, dtype=np.float64) - source))
    sd = math.sqrt(float(e @ np.asarray(ref.covariance, dtype=np.float64) @ e))
    s = np.linspace(middle - LATTICE_SDS * sd, middle + LATTICE_SDS * sd, nodes)
    return s, source + s[:, None] * e


def profile_rows(table: pd.DataFrame) -> list[tuple[pd.Series, bool]]:
    """The rungs the panel draws, each with whether it is the recommended one: the recommended rung,
    then every FD candidate's best rung (scene_maps.best_rungs), each once."""
    out, seen = [], set()
    for _, row in table[table["recommended"]].iterrows():
        out.append((row, True))
        seen.add((int(row["candidate"]), int(row["n"])))
    best = best_rungs(table)
    for _, row in best[best["method"] == "fd"].iterrows():
        if (int(row["candidate"]), int(row["n"])) not in seen:
            out.append((row, False))
            seen.add((int(row["candidate"]), int(row["n"])))
    return out


def profile_runs(scene, table: pd.DataFrame, base_seed: int, known: list[ModelRun] = ()) -> list[ModelRun]:
    """The final states of ``profile_rows``' rungs on the scene's first seed; a rung among ``known`` (the
    map's run) is not run again."""
    have = {(int(r.row["candidate"]), int(r.row["n"])): r for r in known if r is not None}
    out = []
    for row, recommended in profile_rows(table):
        key = (int(row["candidate"]), int(row["n"]))
        out.append(have[key] if key in have else run_row(scene, row, recommended, base_seed))
    return out


def legend_label(run: ModelRun) -> str:
    """A drawn model's legend entry: its label and n, and whether it is recommended."""
    tail = " (recommended)" if run.recommended else ""
    return f"{run.row['label']}, n = {int(run.row['n']):,}{tail}"


def draw_profile(ax, scene, runs: list[ModelRun], colours: dict[str, str], nodes: int = AXIS_NODES) -> Profile:
    """Draw the exact concentration along the axis and each run's in its candidate's colour (``colours``
    by candidate label), the source marked; -> what was drawn (Profile)."""
    s, points = axis(scene, nodes)
    exact = np.asarray(scene.reference.density(points), dtype=np.float64)
    near = near_length(scene)
    ax.plot(s, exact, color=BLACK, lw=2.2, label="exact (Wilson & Miller 1978)" if near > 0 else "exact")
    models = {}
    for run in runs:
        label = legend_label(run)
        models[label] = concentration(run.cfg, run.state, points)
    profile = Profile(s, exact, models, near)
    for run in runs:
        label = legend_label(run)
        ax.plot(
            s,
            models[label],
            color=colours.get(run.row["label"], "0.4"),
            lw=1.3,
            ls="-" if run.recommended else "--",
            label=f"{label}: max |error| {profile.max_error(label):.3g} beyond B",
        )
    far = np.abs(s) >= near
    tops = [float(np.nanmax(c[far])) for c in (exact, *models.values())]  # near the source, c -> inf
    ax.set_ylim(min(0.0, *(float(np.nanmin(c)) for c in models.values())), 1.1 * max(tops))
    ax.set_xlim(s[0], s[-1])
    ax.axvline(0.0, color="0.5", lw=0.8, ls=":", label=f"the source; B = 2 D_L / |v| = {near:.3g}")
    style_axes(
        ax,
        "b",
        f"along the plume's axis at t_final = {scene.t_final:g}",
        concentration_label(scene),
        "distance from the source along the flow [L]",
        logx=False,
    )
    return profile
