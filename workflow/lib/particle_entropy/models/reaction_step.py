"""The reaction operator of a run (RunConfig.reaction), applied after every transport step (Lie
splitting): first-order decay A -> C and the irreversible A + B -> C, each kind's own rules in
core/reactions.py (``on_masses`` for nodes and MTPT particles, ``on_particles`` for PT).

- Masses (FD nodes, MTPT particles: rows A, B, C of a (species, n) array; Benson & Bolster 2016,
  Water Resour. Res. 52, 9190; Schmidt, Pankavich & Benson 2017, J. Comput. Phys., arXiv:1610.02412):
  every node or particle is reacted on its own for dt at its concentrations c = m / dV by the
  closed-form kinetics, the reacted mass moved into C (``react_masses``).
- PT (Benson & Meerschaert 2008, Water Resour. Res. 44, W12201): A and B particles of equal mass m_p;
  a pair at separation s reacts in dt with probability

      P = k m_p dt v(s),   v(s) = exp(-s^2 / (8 D dt)) / sqrt(8 pi D dt),

  v the density of the two particles' co-location, the convolution of their two location densities
  (each Gaussian with variance 2 D dt), i.e. the separation's density (variance 4 D dt) at 0
  (Benson & Meerschaert 2008; Paster, Bolster & Benson 2014, J. Comput. Phys. 263, 91, 1-D). A
  reacted pair is removed and a C particle is put at its midpoint (``pair_reactions``). Decay: each A
  particle becomes a C particle with probability 1 - exp(-lambda dt) (``react_particles``).

Every reaction checks its bookkeeping: A + C and B + C (decay: A + C and B) keep their totals to
round-off and the reaction made no mass negative (check_species_mass raises
models.conservation.MassError otherwise).

Units: lengths [L], times [T], concentrations and masses per length in 1-D [M/L] and [M], k [L/(M T)].
"""

from __future__ import annotations

import math
import sys

import numpy as np

from .conservation import MassError

A, B, C = 0, 1, 2  # the species' rows of a reactive run's masses
# PT pairs farther apart than this many standard deviations of their separation (sqrt(4 D dt)) are
# not tested: the Gaussian tail beyond it holds 6e-7 of v's mass, far below the sampling noise
PAIR_REACH_SIGMAS = 5.0
# A reactive step's conserved totals (A + C, B + C or B) may move by this much relative to their size:
# one step's round-off on N particles is a few eps per particle (the exchange sums, the closed-form
# kinetics, the mass moved into C), far below it; a lost or doubled reacted mass is far above.
SPECIES_MASS_TOLERANCE = 1e-12


def species_tolerance(totals, count: int) -> float:
    """The round-off bound of a reactive step on ``count`` particles or nodes whose conserved totals are
    ``totals`` [M]: SPECIES_MASS_TOLERANCE of the largest, and the least normal double per value (the
    FD solver flushes subnormal values to zero: each loses less than that)."""
    size = max((abs(t) for t in totals), default=0.0)
    return SPECIES_MASS_TOLERANCE * size + count * sys.float_info.min


def check_species_mass(
    before: dict[str, float], after: dict[str, float], smallest: float, t: float, method: str, count: int = 1
) -> None:
    """MassError (models.conservation) unless every conserved total of a reactive step (``before`` and
    ``after``, by name, e.g. "A + C") agrees within its round-off bound (species_tolerance of the two
    totals over ``count`` values), and the reaction made no mass negative beyond the bound of the
    largest total (``smallest``: the least of all species' masses the reaction left, each less what
    was negative before it; NaN fails too)."""
    for name, b in before.items():
        a = after[name]
        tol = species_tolerance((a, b), count)
        if not abs(a - b) <= tol:
            raise MassError(
                f"{method} did not conserve {name}: {b:.17g} -> {a:.17g} at t = {t:.6g}, an error of "
                f"{a - b:.3g} beyond round-off ({tol:.3g}: {SPECIES_MASS_TOLERANCE:g} relative)"
            )
    tol = species_tolerance([*before.values(), *after.values()], count)
    if not smallest >= -tol:
        raise MassError(f"{method} made a negative mass: {smallest:.3g} at t = {t:.6g}, beyond round-off {tol:.3g}")


# --------------------------------------------------------------------------------------- PT


def colocation_density(s, D: float, dt: float):
    """v(s) = exp(-s^2 / (8 D dt)) / sqrt(8 pi D dt) [1/L]: the density that two particles at
    separation s, each walking with D for dt, meet (Benson & Meerschaert 2008)."""
    var = 4.0 * D * dt
    return np.exp(-0.5 * np.square(s) / var) / math.sqrt(2.0 * math.pi * var)


def max_pair_probability(k: float, m_p: float, D: float, dt: float) -> float:
    """The largest reaction probability of a pair, P(0) = k m_p dt v(0) [-]."""
    return k * m_p * dt / math.sqrt(8.0 * math.pi * D * dt)


def largest_pt_dt(k: float, m_p: float, D: float, p_max: float = 1.0) -> float:
    """The largest dt at which no pair's probability exceeds ``p_max``: 8 pi D (p_max / (k m_p))^2."""
    return 8.0 * math.pi * D * (p_max / (k * m_p)) ** 2


def pair_reactions(xa, xb, k: float, m_p: float, D: float, dt: float, length: float, rng):
    """Benson & Meerschaert's A + B -> C on the periodic domain [0, length): every A-B pair within
    PAIR_REACH_SIGMAS sqrt(4 D dt) passes with probability P = k m_p dt v(s) (one uniform per pair);
    the A's are taken in a random order and each reacts with the passing, still unreacted B of
    largest P - u, if any. Pairs are found by sorting the B's (never an N x N matrix).
    -> (A kept, B kept, C positions at the reacted pairs' midpoints). ValueError when P(0) > 1."""
    p_max = max_pair_probability(k, m_p, D, dt)
    if p_max > 1.0:
        raise ValueError(
            f"PT reaction probability k m_p dt v(0) = {p_max:.4g} > 1 at dt = {dt:.6g}: take "
            f"dt <= {largest_pt_dt(k, m_p, D):.6g} (8 pi D / (k m_p)^2)"
        )
    reach = PAIR_REACH_SIGMAS * math.sqrt(4.0 * D * dt)
    if 2.0 * reach >= length:
        raise ValueError(f"pair reach {reach:.4g} at dt = {dt:.6g} is not below half the domain {length:.4g}")
    keep_a, keep_b = np.ones(xa.size, dtype=bool), np.ones(xb.size, dtype=bool)
    if xa.size == 0 or xb.size == 0 or p_max == 0.0:
        return keep_a, keep_b, np.empty(0)
    from ..numerics.reaction_kernels import pair_reactions as loop  # numba: loaded by the steps

    ob = np.argsort(xb, kind="stable")
    xs = xb[ob]
    left = np.searchsorted(xs, reach, side="left")  # B's near 0 reappear beyond length
    right = np.searchsorted(xs, length - reach, side="right")  # and those near length before 0
    x_near = np.concatenate([xs[right:] - length, xs, xs[:left] + length])
    b_near = np.concatenate([ob[right:], ob, ob[:left]]).astype(np.int64)
    lo = np.searchsorted(x_near, xa - reach, side="left")
    hi = np.searchsorted(x_near, xa + reach, side="right")
    start = np.concatenate([[0], np.cumsum(hi - lo)[:-1]]).astype(np.int64)
    u = rng.random(int((hi - lo).sum()))
    order = rng.permutation(xa.size)
    partner = loop(xa, order, x_near, b_near, lo, hi, start, u, p_max, 1.0 / (8.0 * D * dt))
    hit = partner >= 0
    keep_a[hit] = False
    keep_b[b_near[partner[hit]]] = False
    xc = np.mod(0.5 * (xa[hit] + x_near[partner[hit]]), length)
    return keep_a, keep_b, xc


def react_masses(kinetics, masses: np.ndarray, dV: float, dt: float, t: float, method: str) -> float:
    """Every node's or particle's masses (rows A, B, C of ``masses``, changed in place) after dt of
    ``kinetics`` at their concentrations m / dV (its on_masses), the reacted mass moved into C -> the
    mass made. MassError (check_species_mass) unless A + C and B + C (a decay: A + C and B) keep their
    totals and the reaction made no mass negative: a value's mass less what the transport had already
    left below 0 (a scheme's undershoot is the transport's, judged by a scene's search, never a failed run)."""
    a, b, c = masses[A], masses[B], masses[C]
    before = kinetics.conserved(float(a.sum()), float(b.sum()), float(c.sum()))
    a_new, b_new, step = kinetics.on_masses(a, b, dV, dt)
    made = float(step.sum())
    after = kinetics.conserved(float(a_new.sum()), float(b_new.sum()), float(c.sum()) + made)
    made_negative = min((a_new - np.minimum(a, 0.0)).min(), (b_new - np.minimum(b, 0.0)).min())
    check_species_mass(before, after, float(made_negative), t, f"reactive {method}", masses.size)
    masses[A], masses[B] = a_new, b_new
    masses[C] = c + step
    return made


def react_particles(kinetics, xs: list, m_p: float, D: float, dt: float, length: float, rng, t: float = 0.0):
    """PT's A, B and C particles (``xs``: their positions on the periodic [0, length)) after ``kinetics``'
    particle rule for dt (on_particles: a decay's survival draw, A + B -> C by ``pair_reactions``)
    -> [A, B, C]. MassError when a count the reaction conserves (A + C, and B + C or B) changed."""
    xa, xb, xc = xs
    before = kinetics.conserved(float(xa.size), float(xb.size), float(xc.size))
    keep_a, keep_b, new_c = kinetics.on_particles(xa, xb, m_p, D, dt, length, rng, pair_reactions)
    xa, xb, xc = xa[keep_a], xb[keep_b], np.concatenate([xc, new_c])
    after = kinetics.conserved(float(xa.size), float(xb.size), float(xc.size))
    check_species_mass(before, after, m_p, t, "reactive pt")
    return [xa, xb, xc]
