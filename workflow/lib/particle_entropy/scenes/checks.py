"""The rules between a scene's parts (scenes/scene.py): its FD window against its sources'
extent, its candidates against each other, its plume's path against the reach of a double, a
reactive scene's reference against its cost cap and PT's pair probability against its particle
numbers. Each part checks its own values where it is declared: a section's keys by its model
(core/typed.py), a source's and a reaction's parameters by their classes (core/sources.py,
core/reactions.py), a candidate's runs by ``Candidate``. Each refusal is a SettingError naming the
key path the user wrote: ``key(k)`` for a scene not yet built (scene.key_path), ``scene.key(k)``
for a built one."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable

import numpy as np

from ..core.case import SettingError
from ..core.released import singular
from ..core.runconfig import check_plume_width
from ..core.settings import SCENE_REACH

REACH = SCENE_REACH  # how far beyond its sources the FD window reaches, in sqrt(4 D t_final) (scene.REACH)
# Half the digits of a double: a plume whose centre lies further than its width over this from x = 0
# has positions (particles', nodes', points') rounded to more than this fraction of the width.
HALF_DIGITS = math.sqrt(sys.float_info.epsilon)


def check_window(key: Callable[[str], str], fd_length: float, extent: float, D: float, t_final: float) -> None:
    """SettingError naming scenes.<name>.fd_length (``key("fd_length")``) unless the window reaches
    REACH sqrt(4 D t_final) beyond the sources' extent (``extent``: the half width around A's centre
    holding A's source and B's plume, as scene.py's _extent gives it) on either side, as the paper's [-6, 6] at
    t = 1000: its zero ends then absorb at most 2 erfc(3) = 4.4e-5 of each species' mass by t_final
    (an upper bound: a flow only lowers it); a window of +- 1 sqrt(2 D t_final) lost a third."""
    need = 2.0 * (extent + REACH * math.sqrt(4.0 * D * t_final))
    if fd_length < need * (1.0 - 1e-12):  # the paper's own 12 is the bound at its D, t_final
        extent_text = f"the sources' extent {2.0 * extent:.6g} + " if extent else ""
        raise SettingError(
            key("fd_length"),
            fd_length,
            f"a window >= {extent_text}2 x {REACH:g} sqrt(4 D t_final) = {need:.6g} for D = {D:g}, t_final = "
            f"{t_final:g} (the paper's [-6, 6] at t = 1000, whose zero ends absorb 2 erfc(3) = 4.4e-5 of the mass "
            "by then): a narrower window loses the plume through its ends",
        )


def check_distinct(key: Callable[[str], str], candidates) -> None:
    """SettingError naming the second of two candidates that are the same model (Candidate.model)."""
    seen: dict[tuple, int] = {}
    for i, c in enumerate(candidates):
        if c.model in seen:
            j = seen[c.model]
            raise SettingError(
                key(f"candidates[{i}]"), c.label, f"a model other than candidates[{j}] ({c.label}): each once"
            )
        seen[c.model] = i


def check_reach(scene) -> None:
    """SettingError unless the plume fits a grid at t_final (runconfig.check_plume_width) and its
    centre then, x0 + v t_final, lies within its spread sqrt(2 D t_final) / HALF_DIGITS of x = 0:
    further out a double rounds every position (particles, FD nodes, measurement points) by more
    than HALF_DIGITS of the plume's width, and FD's grid, which spans the path, overflows (v = 1e300)."""
    try:
        check_plume_width(scene)
    except SettingError as e:
        raise SettingError(scene.key(e.name), e.value, e.allowed) from None
    D, v, t_final, source = scene.D, scene.v, scene.t_final, scene.source
    spread = math.sqrt(2.0 * D * t_final)
    reach = spread / HALF_DIGITS
    x0 = source.centre
    if abs(x0 + v * t_final) <= reach:
        return
    why = (
        f"the plume's centre x0 + v t_final within sqrt(2 D t_final) / sqrt(eps) = {reach:.3g} of x = 0 "
        f"(D = {D:g}, t_final = {t_final:g}, eps = {sys.float_info.epsilon:.3g}), where a double holds the "
        "plume's width to half its digits"
    )
    if v != 0.0:
        lo, hi = (-reach - x0) / t_final, (reach - x0) / t_final
        raise SettingError(scene.key("v"), v, f"a number in [{lo:.6g}, {hi:.6g}] [L/T]: {why}")
    key = source.POSITION  # the parameter that places the source
    raise SettingError(
        scene.key(f"source.{key}"), getattr(source, key), f"a number in [{-reach:.6g}, {reach:.6g}]: {why}"
    )


# How near a 2-D point source, in standard deviations of the released plume (the Mahalanobis distance by
# its covariance), a measurement point counts as on it: the exact plume's quadrature (core/release.py)
# holds the density to its closed form down to ~1e-10 of the plume's width from the source, and the
# density is infinite on it.
AT_SOURCE = 1e-10


def check_release_points(scene) -> None:
    """SettingError naming scenes.<name>.target.measure where an rmse target would need the concentration
    at a 2-D point source that is still releasing at t_final: it is infinite there (c grows as ln(1/r)
    toward the point). The RMSE is taken at the 15 x 15 lattice over the released plume (its centre x0 +
    v a, a the puffs' mean age, along its principal axes); a lattice point within AT_SOURCE sd of the
    source is on it: always at v = 0 (the lattice's centre is the source), in a flow where the source
    falls on a tick. H_C and E integrate c ln c and c over the plume, finite (the singularity is
    integrable), and a release that ends before t_final, or a source with an extent, has a finite
    concentration everywhere: those are not refused."""
    if scene.release is None or scene.measure != "rmse" or not singular(scene.source, scene.release, scene.t_final):
        return
    plume = scene.reference
    points = np.asarray(scene.points, dtype=np.float64)
    offset = points - np.asarray(scene.source.centre, dtype=np.float64)
    inverse = np.linalg.inv(np.asarray(plume.covariance, dtype=np.float64))
    sds = np.sqrt(np.einsum("ij,jk,ik->i", offset, inverse, offset))
    i = int(np.argmin(sds))
    if sds[i] > AT_SOURCE:
        return
    n = round(math.sqrt(len(points)))
    where = (
        "its centre: at v = 0 the lattice is centred on the source"
        if scene.speed == 0.0
        else (
            f"point ({i // n}, {i % n}), {sds[i]:.3g} sd from it: the flow has carried the lattice's centre a whole "
            "number of its steps from the source"
        )
    )
    raise SettingError(
        scene.key("target.measure"),
        scene.measure,
        "entropy or dilution (integrals over the plume, finite), or rmse at points away from the source: a 2-D "
        "point source still releasing at t_final (release without until, or until >= t_final) has an infinite "
        f"concentration where it stands, and the {n} x {n} measurement lattice has a point on it, {where}; "
        "rmse is allowed where no point is (another v), for a release that ends before t_final, or for a "
        "source with an extent (a gaussian or a box)",
    )


def check_reactive(scene) -> None:
    """SettingError where a reactive scene's parts cannot carry its reaction: its reference past the
    cost cap (check_reference_cost), a PT candidate whose pair probability exceeds 1
    (check_pair_probability), a candidate of a model that moves one species (Candidate.check_reactive)."""
    if scene.reaction is None:
        return
    check_reference_cost(scene)
    for i, c in enumerate(scene.candidates):
        if c.case.method == "pt" and scene.reaction.kinetics.CONSUMES_B:  # PT reacts A with B by pairs
            check_pair_probability(scene, i, c)
        c.check_reactive(scene.key, i)


def check_pair_probability(scene, i: int, c) -> None:
    """SettingError naming a PT candidate's resolutions where Benson & Meerschaert's pair probability
    k m_p dt v(0) (m_p = 1 / N, v(0) = 1 / sqrt(8 pi D dt)) exceeds 1 at its largest step: it holds
    from N >= k sqrt(dt / (8 pi D)) on (models/reaction_step.max_pair_probability)."""
    from ..core.timegrid import time_steps
    from ..models.reaction_step import max_pair_probability

    k = scene.reaction.kinetics.k
    for n in (c.n_lo, *c.rungs):
        cfg = scene.run_config(c, n)
        dt = float(time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, cfg.time_grid).max())  # the runner's grid
        if max_pair_probability(k, 1.0 / n, scene.D, dt) > 1.0:
            least = math.ceil(k * math.sqrt(dt / (8.0 * math.pi * scene.D)))
            key = "ladder" if c.rungs else "n_range"
            raise SettingError(
                scene.key(f"candidates[{i}].{key}"),
                list(c.rungs) if c.rungs else [c.n_lo, c.n_hi],
                f"particle numbers >= {least:,}: PT's pair probability k dt v(0) / N (Benson & Meerschaert "
                f"2008) exceeds 1 below that at its largest step dt = {dt:.4g}",
            )


def check_reference_cost(scene) -> None:
    """SettingError naming scenes.<name>.reaction.k where the scene's reference (scenes/reference.py)
    would take more than numerics/reaction_diffusion's MAX_WORK: its plan, known before any job, and
    its estimate in the message. The kinetic rule's steps are capped at that bound; what is refused
    is a reference whose diffusion rule (r <= 1/4 on the coarsest grid) alone exceeds it."""
    from ..numerics.reaction_diffusion import MAX_WORK, SECONDS_PER_CELL_STEP
    from .reference import physics, plan

    how = plan(physics(scene))
    if how is None or how.work <= MAX_WORK:
        return
    raise SettingError(
        scene.key("reaction.k"),
        scene.reaction.kinetics.k,
        f"a reaction whose reference takes at most {MAX_WORK:.3g} cell-steps (~{MAX_WORK * SECONDS_PER_CELL_STEP:.3g} "
        f"s); this one's would take {how.describe()}",
    )
