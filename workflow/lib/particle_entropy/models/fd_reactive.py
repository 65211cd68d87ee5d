"""Finite differences carrying a reaction (issue 42): species A, B and their product C on one FD grid
and time step, each carried by the existing transport step (models/fd.py: a solver of the interior
nodes), then every node reacted over dt by the closed-form kinetics of core/reactions (decay A -> C,
or A + B -> C) on its masses, the balance checked every step.

Sequential non-iterative operator splitting, Lie's order: transport over dt, then reaction over dt,
first order in dt (Valocchi & Malmstead 1992, Water Resour. Res. 28: 1471-1476), as RT3D reacts the
nodes after each step of the MT3D transport it reuses (Clement 1997, RT3D, report PNNL-11720). The
kinetics within a node are exact, so the splitting is the only error of the reaction's coupling; for
a decay, which commutes with linear transport, there is none: the run is the conservative run times
exp(-lambda t) to round-off.

``steps`` is the one loop: the scene runs (models/reactive_run.py) and ``run_reactive`` (a fixed step,
concentrations in and out) both iterate it."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ReactiveRun:
    """An FD run with a reaction: node concentrations a, b, c after the last step, and the product
    mass made, integral of R dt dx, after each step (``made[0]`` = 0) [M]."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    made: np.ndarray


def transport_step(transport, c: np.ndarray) -> np.ndarray:
    """The nodes c after one FD transport step: the interior by ``transport.solve`` (an fd solver),
    the end nodes held as they are (the zero boundary of models/fd)."""
    out = c.copy()
    out[1:-1] = transport.solve(c[1:-1])
    return out


def react(kinetics, a: np.ndarray, b: np.ndarray, dx: float, dt: float, t: float, made: float):
    """The node masses a, b after dt of the kinetics at their concentrations m / dx (on_masses), with
    ``made`` the product so far -> (a, b, the mass each node turned into C); MassError unless A + C and
    B + C (a decay: A + C and B) keep their totals to round-off and no mass is negative
    (models/reactive.check_species_mass)."""
    from .reactive import check_species_mass

    before = kinetics.conserved(float(a.sum()), float(b.sum()), made)
    a_new, b_new, step = kinetics.on_masses(a, b, dx, dt)
    after = kinetics.conserved(float(a_new.sum()), float(b_new.sum()), made + float(step.sum()))
    # what the reaction made negative: a node's mass less what its transport had already left below 0
    # (a scheme's undershoot is the transport's, judged by the search, never a failed run)
    made_negative = min((a_new - np.minimum(a, 0.0)).min(), (b_new - np.minimum(b, 0.0)).min())
    check_species_mass(before, after, float(made_negative), t, "reactive fd", 2 * a.size)
    return a_new, b_new, step


def steps(
    solver: Callable[[float], object],
    masses: np.ndarray,
    kinetics,
    dx: float,
    dts: Sequence[float],
    ts: Sequence[float],
    background: float = 0.0,
) -> Iterator[tuple[int, float, float, np.ndarray, float]]:
    """Each step k = 1.. of c^{k} = K_dt(T_dt c^{k-1}) for the node masses (A, B, C) (``masses``, 3 x
    (N + 1), changed in place): T_dt the FD transport of each species by ``solver(dt)`` (its interior;
    the ends held), K_dt the closed-form kinetics at every node (Lie splitting) -> (k, t, dt, masses,
    the product made so far). B is carried as its departure from ``background`` (a uniform B's node
    mass C0 dx; its ends held there), which every scheme, the TVD limiter included, leaves unchanged."""
    a, b, c = masses
    made = 0.0
    for k, dt in enumerate(dts, start=1):
        transport = solver(dt)
        a[:] = transport_step(transport, a / dx) * dx
        b[:] = transport_step(transport, (b - background) / dx) * dx + background
        c[:] = transport_step(transport, c / dx) * dx
        a[:], b[:], step = react(kinetics, a, b, dx, dt, ts[k], made)
        c += step
        made += float(step.sum())
        yield k, ts[k], dt, masses, made


def run_reactive(transport, a0, b0, reaction, dt: float, n_steps: int, dx: float) -> ReactiveRun:
    """n_steps of ``steps`` at the fixed dt with the solver ``transport`` (built for this dt and dx by
    models/fd), from node concentrations a0 and b0 (B's ends held as given), C = 0 at the start."""
    a = np.array(a0, dtype=np.float64)
    masses = np.vstack([a, np.array(b0, dtype=np.float64) * np.ones_like(a), np.zeros_like(a)]) * dx
    made = np.zeros(n_steps + 1)
    ts = dt * np.arange(n_steps + 1)
    for k, _, _, _, total in steps(lambda _: transport, masses, reaction, dx, [dt] * n_steps, ts):
        made[k] = total
    a, b, c = masses / dx
    return ReactiveRun(a, b, c, made)
