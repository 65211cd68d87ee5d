"""Mass conservation, checked as a model runs: a run that loses or invents mass beyond round-off
is a failure (MassError, one line naming the error), never a score."""

from __future__ import annotations

# MTPT's total mass (unit at the start) may drift from 1 by this much at most: 10^5 times the worst
# drift of the paper's runs (7.3e-14, N = 30,000 after 175 steps), and 10^3 times the round-off of
# summing 10^6 masses; any transfer that loses or makes mass does so by far more
PARTICLE_MASS_TOLERANCE = 1e-8


class MassError(ArithmeticError):
    """A model step that did not conserve mass beyond round-off (one line: the mass error)."""


def check_particle_mass(total: float, t: float, method: str = "mtpt", expected: float = 1.0) -> None:
    """MassError unless the particles' total mass ``total`` at time t is ``expected`` (the unit mass, or a
    release's mass released by t) to within PARTICLE_MASS_TOLERANCE times max(1, expected) (NaN fails too)."""
    if not abs(total - expected) <= PARTICLE_MASS_TOLERANCE * max(1.0, expected):
        raise MassError(
            f"{method} lost mass: total {total:.17g} at t = {t:.6g}, an error of {total - expected:.3g} beyond "
            f"round-off ({PARTICLE_MASS_TOLERANCE:g})"
        )
