"""Whether a scene's target asks a question its reference can answer (issue 50): a relative error of
a zero product is undefined, an RMSE that a field of zeros already meets says nothing about a model,
and a reference whose own error reaches the target cannot judge one. A scene so posed is refused by
its key path before any job where its reference is a closed form (``check``: a conservative plume,
whose RMSE target must lie below the plume's own RMS at the points; a decay), and otherwise, once the
reference is solved, every candidate stops with the reason and nothing is recommended
(analysis/scene_search.py reads ``undefined``)."""

from __future__ import annotations

import math

import numpy as np

from ..core.case import SettingError

# the measures judged at the points: (measure, the reference's values there, their error, the field)
_AT_POINTS = {"rmse": ("a_points", "a_error", "C_A"), "product_rmse": ("c_points", "c_error", "C_C")}


def _rms(values) -> float:
    """The root mean square of ``values``: the RMSE a field of zeros scores against them."""
    values = np.asarray(values, dtype=np.float64)
    return float(np.sqrt(np.mean(values * values))) if values.size else 0.0


def undefined(measure: str, value: float, ref: dict) -> str:
    """Why the target ``measure`` <= ``value`` cannot be judged against the reference ``ref`` (keys as
    core/reference_file.read gives them; a conservative scene's a_points and a_error), '' if it can."""
    if measure == "product":
        m, err = ref["product_mass"], ref["product_error"]
        if not (m is not None and m > 0.0 and math.isfinite(m)):
            return f"the reference makes no product by t_final (M_C = {m}): its relative error is undefined"
        if not (err is not None and err < value * m):
            return (
                f"the reference's own error {err:.3g} is not below the target's {value:g} of its M_C = {m:.3g}: "
                "it cannot judge a model to that accuracy"
            )
        return ""
    if measure not in _AT_POINTS:  # entropy and dilution: of a conservative plume, never zero
        return ""
    values, errors, field = _AT_POINTS[measure]
    zero = _rms(ref[values])
    if not zero > value:
        return (
            f"a field of zeros scores RMSE {zero:.3g} <= {value:g} against the reference's {field} at the points, "
            "so meeting the target says nothing about a model (lower it below that)"
        )
    own = _rms(ref[errors])
    if not own < value:
        return f"the reference's own error at the points (RMS {own:.3g}) is not below the target {value:g}"
    return ""


def check(scene, ref: dict | None) -> None:
    """SettingError naming scenes.<name>.target when its question is undefined (``undefined``) against
    the closed-form reference ``ref`` known before any job (None: solved later, judged by the search)."""
    if ref is None:
        return
    why = undefined(scene.measure, scene.value, ref)
    if why:
        reaction = f" with the reaction {scene.reaction.record()}" if scene.reaction is not None else ""
        raise SettingError(
            scene.key("target"),
            {"measure": scene.measure, "value": scene.value},
            f"a target the reference can judge{reaction}: {why}",
        )


def closed_form(scene) -> dict | None:
    """A scene's reference when it is a closed form known before any job, as ``undefined`` reads it: a
    conservative plume's exact values at the scene's points (core/reference.py, no error of its own; a
    release's by its quadrature in age, core/release.py, to ~1e-10), or a reaction without B
    (scenes/reference.compute); None for A + B -> C, solved by a job."""
    if scene.reaction is None and scene.release is not None:
        values = _released(scene).density(scene.points)
        return {"a_points": values.tolist(), "a_error": np.zeros_like(values).tolist()}
    if scene.reaction is None:
        values = scene.reference.density(scene.points)
        return {"a_points": values.tolist(), "a_error": np.zeros_like(values).tolist()}
    from . import reference

    if scene.reaction.closed_form(scene.t_final) is not None:
        return reference.compute(reference.physics(scene))
    return None


def _released(scene):
    """The exact plume of the scene's release at t_final (core/release.py): c at any point, by quadrature
    in the puffs' ages."""
    from ..core.release import ReleaseReference, ReleaseReference2D

    if scene.dim == 2:
        D, v = np.asarray(scene.D, dtype=np.float64), np.asarray(scene.v, dtype=np.float64)
        return ReleaseReference2D(scene.source, scene.release, D, v, scene.t_final)
    return ReleaseReference(scene.source, scene.release, scene.D, scene.v, scene.t_final)
