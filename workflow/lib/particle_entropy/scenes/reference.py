"""A reactive scene's reference (config ``scenes.<name>.reaction``): what every candidate's runs are
judged against at t_final, with its own error stated.

- A decay is exact: the conservative plume (core/reference.py) times exp(-lambda t), and the
  product's mass 1 - exp(-lambda t), computed as -expm1(-lambda t); its error is zero.
- A + B -> C is solved once on a fine grid in the frame moving with v, where the problem is pure
  reaction-diffusion with no numerical dispersion from advection (numerics/reaction_diffusion.py:
  Strang splitting of the closed-form kinetics around Crank-Nicolson), on three grids refined by 2
  in space and time; each quantity is Richardson-extrapolated and its error estimated from the
  three, or, where the observed order is far from 2 (``*_asymptotic`` false), the finest grid's
  value with a conservative error. Where A and B start uniform and equal, this is also the
  well-mixed C0 / (1 + k C0 t). Its cost is known before it runs (``plan``), and scene
  validation refuses a reference past numerics/reaction_diffusion's MAX_WORK.

The rule scene_reference passes the code hash of its script's imports (pipeline/codeversion.py:
this module and numerics/reaction_diffusion.py, lazy imports included), so an edit reruns it.

The reference is keyed by a digest of the physics it depends on (``digest``), as runs are, so two
scenes of the same physics share one file (REFERENCE_PATTERN). The file carries the SHA-256 of its
own canonical content (``sha256``), as a table carries one beside it: ``read`` uses it only when that
holds and its digest is both its file's name and its physics' (``problem``), so a file damaged, cut
short or copied from another scene is refused in one line, and the workflow sets it aside before a
run and rebuilds it (pipeline/preflight.py).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..core.io import write_bytes_atomically
from ..core.reactions import Reaction
from ..core.reference_file import (  # noqa: F401  (re-exported: the reference's file, where it was)
    ReferenceFileError,
    content_sha256,
    key,
    problem,
    read,
)

REFERENCE_PATTERN = "results/scenes/references/{digest}.json"
SERIES = 40  # the product's mass is recorded at this many equal times in (0, t_final] (the scene figure)


def points(scene) -> np.ndarray:
    """The scene's measurement points at t_final, common to every candidate (RunConfig.points) [L]."""
    return scene.run_config(scene.candidates[0], scene.candidates[0].n_lo).points(scene.t_final)


def physics(scene) -> dict:
    """What the reference depends on: the source, D, v, t_final, the reaction and the points."""
    return {
        "source": scene.source.record(),
        "D": scene.D,
        "v": scene.v,
        "t_final": scene.t_final,
        "reaction": scene.reaction.record(),
        "points": [float(p).hex() for p in points(scene)],
    }


def digest(scene) -> str:
    """The key of a reactive scene's reference (``key`` of its ``physics``)."""
    return key(physics(scene))


def path(scene) -> str:
    """The file of a reactive scene's reference (REFERENCE_PATTERN)."""
    return REFERENCE_PATTERN.format(digest=digest(scene))


def _inputs(physics: dict):
    """(reaction, source, D, v, t_final, points) of a reference's ``physics``."""
    from ..core.sources import Source

    pts = np.array([float.fromhex(p) for p in physics["points"]])
    reaction, source = Reaction.of(physics["reaction"]), Source.of(**physics["source"])
    return reaction, source, physics["D"], physics["v"], physics["t_final"], pts


def _b(reaction):
    """B as numerics/reaction_diffusion takes it: C0, or (its source, its mass)."""
    return reaction.b_uniform if reaction.b_source is None else (reaction.b_source, reaction.b_mass)


def plan(physics: dict):
    """What computing the reference of ``physics`` will take, before it runs (a
    reaction_diffusion.Plan: cells, steps, work, estimated seconds), or None for a decay's closed form."""
    reaction, source, D, _, t, _ = _inputs(physics)
    if reaction.closed_form(t) is not None:
        return None
    from ..numerics.reaction_diffusion import plan as rd_plan

    return rd_plan(source, _b(reaction), D, reaction.kinetics, t)


def compute(physics: dict) -> dict:
    """The reference of a reactive scene at t_final from its ``physics`` (what ``digest`` covers, so
    that nothing else, a target or a candidate, can change it): the product's mass and A's and C's
    concentrations at the measurement points, each with its error estimate, observed order and
    whether that order is the scheme's (``*_asymptotic``: else the finest grid's value, its error
    stated conservatively, reaction_diffusion.richardson), and the product's mass over time (SERIES
    times) -> a JSON-ready mapping."""
    reaction, source, D, v, t, pts = _inputs(physics)
    times = t * np.arange(1, SERIES + 1) / SERIES
    form = reaction.closed_form(t)
    if form is not None:  # the conservative plume times each species' share (a decay's product as -expm1)
        left, made = form
        plume = source.density(pts, D, v, t)
        zero = [0.0] * pts.size
        return {
            "method": f"closed form: the conservative plume times the {reaction.kind}'s shares of A and C",
            "product_mass": made,
            "product_error": 0.0,
            "product_order": math.nan,
            "product_asymptotic": True,
            "points": pts.tolist(),
            "a_points": (plume * left).tolist(),
            "a_error": zero,
            "a_asymptotic": [True] * pts.size,
            "c_points": (plume * made).tolist(),
            "c_error": zero,
            "c_asymptotic": [True] * pts.size,
            "times": times.tolist(),
            "product_series": [reaction.closed_form(s)[1] for s in times],
            "seconds": [0.0],
        }
    from ..numerics.reaction_diffusion import reference

    ref = reference(source, _b(reaction), D, reaction.kinetics, t, pts, v=v, times_per_run=SERIES)
    fine, how = ref.fine, ref.plan
    return {
        "method": "Richardson extrapolation of Strang-split Crank-Nicolson on three grids, moving with v",
        "product_mass": float(ref.product_mass.value),
        "product_error": float(ref.product_mass.error),
        "product_order": float(ref.product_mass.order),
        "product_asymptotic": bool(ref.product_mass.asymptotic),
        "points": pts.tolist(),
        "a_points": np.asarray(ref.a_points.value, dtype=float).tolist(),
        "a_error": np.asarray(ref.a_points.error, dtype=float).tolist(),
        "a_asymptotic": np.asarray(ref.a_points.asymptotic, dtype=bool).tolist(),
        "c_points": np.asarray(ref.c_points.value, dtype=float).tolist(),
        "c_error": np.asarray(ref.c_points.error, dtype=float).tolist(),
        "c_asymptotic": np.asarray(ref.c_points.asymptotic, dtype=bool).tolist(),
        "times": fine.times.tolist(),
        "product_series": fine.masses[:, 2].tolist(),
        "cells": int(fine.x.size),
        "steps": int(fine.n_steps),
        "window": [how.lo, how.hi],
        "edges_on_faces": how.aligned,
        "kinetic_steps_capped": how.capped,
        "estimated_seconds": how.seconds,
        "seconds": list(ref.seconds),
    }


def write(physics: dict, out_path: str) -> None:
    """The reference of ``physics`` (a scene's: ``physics(scene)``) as JSON at ``out_path``, NaN as
    null, with the SHA-256 of its content (``content_sha256``); written whole or not at all."""
    out = compute(physics)
    out = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}
    ref = {"digest": key(physics), "physics": physics, **out}
    ref = {"digest": ref["digest"], "sha256": content_sha256(ref), **ref}
    write_bytes_atomically(json.dumps(ref, indent=1).encode(), Path(out_path))
