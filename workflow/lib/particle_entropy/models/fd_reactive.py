"""Finite differences carrying a reaction (issue 42): species A, B and their product C on one FD grid
and time step, each carried by the existing transport step (models/fd.py: a solver of the interior
nodes, its mass balance checked), then every node reacted over dt by the closed-form kinetics of
core/reactions (decay A -> C, or A + B -> C).

Sequential non-iterative operator splitting, Lie's order: transport over dt, then reaction over dt,
first order in dt (Valocchi & Malmstead 1992, Water Resour. Res. 28: 1471-1476), as RT3D reacts the
nodes after each step of the MT3D transport it reuses (Clement 1997, RT3D, report PNNL-11720). The
kinetics within a node are exact, so the splitting is the only error of the reaction's coupling; for
a decay, which commutes with linear transport, there is none: the run is the conservative run times
exp(-lambda t) to round-off."""

from __future__ import annotations

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


def run_reactive(transport, a0, b0, reaction, dt: float, n_steps: int, dx: float) -> ReactiveRun:
    """n_steps of c^{n+1} = K_dt(T_dt c^n) for (A, B, C), C = 0 at the start: T_dt the FD transport
    step of each species (``transport``, built for this dt and dx by models/fd), K_dt the closed-form
    kinetics ``reaction.react`` at every node (Lie splitting)."""
    a = np.array(a0, dtype=np.float64)
    b = np.array(b0, dtype=np.float64) * np.ones_like(a)
    c = np.zeros_like(a)
    made = np.zeros(n_steps + 1)
    for step in range(1, n_steps + 1):
        a, b, c = transport_step(transport, a), transport_step(transport, b), transport_step(transport, c)
        a, b, reacted = reaction.react(a, b, dt)
        c = c + reacted
        made[step] = made[step - 1] + float(reacted.sum()) * dx
    return ReactiveRun(a, b, c, made)
