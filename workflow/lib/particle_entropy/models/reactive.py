"""Reactions on particles in 1-D: first-order decay A -> C and the irreversible A + B -> C, by
mass-transfer particle tracking (MTPT, particles carrying every species) and by random-walk particle
tracking (PT, one species per particle, reaction by probabilistic particle killing).

MTPT (Benson & Bolster 2016, Water Resour. Res. 52, 9190, "Arbitrarily complex chemical reactions on
particles"; Schmidt, Pankavich & Benson 2017, J. Comput. Phys., arXiv:1610.02412): every particle
carries masses m_A, m_B, m_C and stands for the volume dV = Omega / N. A step random-walks the
particles with (1 - eta) D, exchanges every species with eta D by one symmetric transfer matrix P
(Eq. 19 of the paper; numerics.species_transfer.mass_transfer_species), then reacts each particle on
its own for dt at its concentrations c = m / dV by the closed-form kinetics of core.reactions,
moving the reacted mass into C.

PT (Benson & Meerschaert 2008, Water Resour. Res. 44, W12201): A and B particles of equal mass m_p
each random-walk with D; a pair at separation s reacts in dt with probability

    P = k m_p dt v(s),   v(s) = exp(-s^2 / (8 D dt)) / sqrt(8 pi D dt),

v the density of the two particles' co-location, the convolution of their two location densities
(each Gaussian with variance 2 D dt), i.e. the separation's density (variance 4 D dt) at 0
(Benson & Meerschaert 2008; Paster, Bolster & Benson 2014, J. Comput. Phys. 263, 91, 1-D). A
reacted pair is removed and a C particle is put at its midpoint. Decay: each A particle becomes a
C particle with probability 1 - exp(-lambda dt).

Every step checks its bookkeeping: A + C and B + C (decay: A + C and B) keep their totals to
round-off and no mass is negative (check_species_mass raises models.conservation.MassError otherwise).

Units: lengths [L], times [T], concentrations and masses per length in 1-D [M/L] and [M], k [L/(M T)].
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from ..core.reactions import Bimolecular, Decay, decay_factor  # noqa: F401  (the kinetics, re-exported)
from ..numerics.kernels import beta_sph, collision_sigma
from .conservation import MassError
from .walk import walk

A, B, C = 0, 1, 2  # rows of an MTPT particle's masses
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


# -------------------------------------------------------------------------------- reactions


def particle_reaction(reaction, xa, xb, m_p: float, D: float, dt: float, length: float, rng):
    """(A kept, B kept, new C positions) of one PT step's reaction on particles of mass m_p: a decay
    keeps each A with probability exp(-lambda dt) (its C where it was); A + B -> C is Benson &
    Meerschaert's pair rule on the periodic domain [0, length) (``pair_reactions``)."""
    if reaction.KIND == "decay":  # decays with probability -expm1(-lambda dt): > 0 however small lambda dt
        keep = rng.random(xa.size) >= -math.expm1(-reaction.rate * dt)
        return keep, np.ones(xb.size, dtype=bool), xa[~keep]
    return pair_reactions(xa, xb, reaction.k, m_p, D, dt, length, rng)


# ---------------------------------------------------------------------------------- kernels


@dataclass(frozen=True)
class CollisionKernel:
    """The collision kernel of MTPT, variance 4 eta D dt, beta = 1/2 (Eq. 17)."""

    def width_and_beta(self, eta: float, D: float, dt: float) -> tuple[float, float]:
        return collision_sigma(eta, D, dt), 0.5


@dataclass(frozen=True)
class SPHKernel:
    """An SPH kernel of fixed width ``h`` [L] with beta = 2 eta D dt / h^2 (Eqs. 20, 21)."""

    h: float

    def __post_init__(self):
        if not (self.h > 0.0 and math.isfinite(self.h)):
            raise ValueError(f"SPH width h must be positive and finite, got {self.h!r}")

    def width_and_beta(self, eta: float, D: float, dt: float) -> tuple[float, float]:
        return self.h, beta_sph(eta, D, dt, self.h)


# ------------------------------------------------------------------------------------- MTPT


def reflect(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Positions folded back into [lo, hi] by reflection at both walls (any number of crossings)."""
    span = hi - lo
    y = np.mod(x - lo, 2.0 * span)
    return lo + np.where(y > span, 2.0 * span - y, y)


def mtpt_uniform_labels(n: int, length: float, c0: float, rng: np.random.Generator):
    """N particles uniform on [0, length), sorted, half of them (at random) carrying only A and
    half only B at mass 2 c0 dV, dV = length / N: mean concentrations c0 each, with the noise of
    N one-species particles -> (x, masses (3, N))."""
    if n % 2:
        raise ValueError(f"an equal A/B split needs an even N, got {n}")
    x = np.sort(rng.random(n) * length)
    is_a = np.zeros(n, dtype=bool)
    is_a[rng.permutation(n)[: n // 2]] = True
    masses = np.zeros((3, n))
    m = 2.0 * c0 * length / n
    masses[A, is_a] = m
    masses[B, ~is_a] = m
    return x, masses


def mtpt_step(
    x: np.ndarray,
    masses: np.ndarray,
    reaction,
    dV: float,
    D: float,
    eta: float,
    dt: float,
    rng: np.random.Generator,
    kernel=CollisionKernel(),
    domain: tuple[float, float] | None = None,
    truncation: float | None = None,
    t: float = 0.0,
):
    """One MTPT step of reactive transport -> (x sorted, masses (3, N), substeps): random walk with
    (1 - eta) D (reflected into ``domain`` when given), re-sort, exchange of A, B and C with eta D
    by one P (Eq. 19, ``kernel``: CollisionKernel or SPHKernel), then ``reaction`` (Decay or
    Bimolecular) on every particle at c = m / dV for dt. Raises MassError when a total the reaction
    conserves (A + C, and B + C or B) changed beyond round-off or a mass went negative; ``t``
    names the step's end in that message."""
    from ..numerics.species_transfer import mass_transfer_species  # numba: loaded by the steps

    before = _conserved(reaction, masses)
    d_walk = (1.0 - eta) * D
    if d_walk > 0.0:
        x = walk(x, d_walk, dt, rng)
        if domain is not None:
            x = reflect(x, *domain)
        order = np.argsort(x, kind="stable")
        x, masses = x[order], masses[:, order]
    substeps = 1
    if eta * D > 0.0:
        sigma, beta = kernel.width_and_beta(eta, D, dt)
        res = mass_transfer_species(x, masses, sigma, beta, truncation)
        masses, substeps = res.mass, res.substeps
    else:
        masses = masses.copy()
    masses[A], masses[B], gained = reaction.on_masses(masses[A], masses[B], dV, dt)
    masses[C] = masses[C] + gained
    check_species_mass(before, _conserved(reaction, masses), float(masses.min()), t, "reactive mtpt", masses.size)
    return x, masses, substeps


def _conserved(reaction, masses) -> dict[str, float]:
    tot = masses.sum(axis=1)
    return reaction.conserved(float(tot[A]), float(tot[B]), float(tot[C]))


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


def pt_step(xa, xb, xc, reaction, m_p: float, D: float, dt: float, length: float, rng, t: float = 0.0):
    """One PT step on the periodic domain [0, length): A, B and C particles walk with D, then
    ``reaction`` (Decay or Bimolecular) removes the reacted ones and adds C particles
    -> (xa, xb, xc). Raises MassError when a count the reaction conserves (A + C, and B + C or B) changed."""
    before = reaction.conserved(float(xa.size), float(xb.size), float(xc.size))
    xa = np.mod(walk(xa, D, dt, rng), length)
    xb = np.mod(walk(xb, D, dt, rng), length)
    xc = np.mod(walk(xc, D, dt, rng), length)
    keep_a, keep_b, new_c = particle_reaction(reaction, xa, xb, m_p, D, dt, length, rng)
    xa, xb, xc = xa[keep_a], xb[keep_b], np.concatenate([xc, new_c])
    after = reaction.conserved(float(xa.size), float(xb.size), float(xc.size))
    check_species_mass(before, after, m_p, t, "reactive pt")
    return xa, xb, xc


# ------------------------------------------------------------------------------------- runs


def time_steps(t_end: float, dt0: float, growth: float = 0.0, dt_max: float = math.inf) -> np.ndarray:
    """Step sizes reaching t_end exactly: dt0 while growth * t < dt0, then growth * t (geometric
    steps, as the segregation runs need), never above dt_max; the last one cut to land on t_end."""
    out, t = [], 0.0
    while t < t_end * (1.0 - 1e-12):
        dt = min(max(dt0, growth * t), dt_max, t_end - t)
        out.append(dt)
        t += dt
    return np.array(out)


def run_mtpt(x, masses, reaction, dV, D, eta, dts, rng, kernel=CollisionKernel(), domain=None, window=None):
    """MTPT steps of sizes ``dts`` from (x, masses) -> (times, mean c_A, mean c_B, final x, masses):
    the mass of the particles inside ``window`` (lo, hi) over its length, or without a window all
    the mass over the particles' volume N dV."""
    t, times, ca, cb = 0.0, [], [], []
    for dt in dts:
        t += dt
        x, masses, _ = mtpt_step(x, masses, reaction, dV, D, eta, dt, rng, kernel, domain, t=t)
        if window is None:
            inside, volume = slice(None), x.size * dV
        else:
            inside, volume = (x >= window[0]) & (x <= window[1]), window[1] - window[0]
        times.append(t)
        ca.append(masses[A, inside].sum() / volume)
        cb.append(masses[B, inside].sum() / volume)
    return np.array(times), np.array(ca), np.array(cb), x, masses


def run_pt(na, nb, reaction, c0: float, D: float, length: float, dts, rng):
    """PT from na A and nb B particles at independent uniform positions on the periodic [0, length),
    particle mass m_p = c0 length / na -> (times, c_A, c_B): the counts times m_p over length."""
    m_p = c0 * length / na
    xa, xb, xc = rng.random(na) * length, rng.random(nb) * length, np.empty(0)
    t, times, ca, cb = 0.0, [], [], []
    for dt in dts:
        t += dt
        xa, xb, xc = pt_step(xa, xb, xc, reaction, m_p, D, dt, length, rng, t=t)
        times.append(t)
        ca.append(xa.size * m_p / length)
        cb.append(xb.size * m_p / length)
    return np.array(times), np.array(ca), np.array(cb)
