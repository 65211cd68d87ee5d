"""Noise-driven segregation of A + B -> C in 1-D: one seeded run of PT or MTPT from A and B well
mixed but for the noise of finite particle numbers, whose mean c_A follows the well-mixed
C0 / (1 + k C0 t) early and c_A ~ t^(-1/4) late (Ovchinnikov & Zeldovich 1978; Toussaint & Wilczek
1983; Paster, Bolster & Benson 2014, J. Comput. Phys. 263, 91). Shared by
benchmarks/segregation.py and tests/test_segregation.py; the slope and its interval over seeds
are in analysis/segregation.py.

- pt: na = nb = n0 L particles of mass m_p = C0 / n0 at independent uniform positions on the
  periodic domain [0, L) (as Benson & Meerschaert 2008 and Paster et al. 2014 start them);
- mtpt: 2 n0 L particles uniform on [0, L) with reflecting walls, half of them (at random)
  carrying only A, half only B, at mass 2 C0 dV = m_p (so the noise of A - B per length, 2 m_p
  C0, is PT's); c_A is taken over the interior, a wall's reach (3 sqrt(8 D t_end)) in from each end.

Steps: dt0 while growth t < dt0, then dt = growth t (core/timegrid.steps_growing_with_time). The
steps are the runner's own (models/mtpt.walk, numerics/mass_transfer, models/pt.step and the
reaction operator of models/reaction_step); only the domains (periodic, reflecting) are this experiment's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.reactions import Bimolecular
from ..core.timegrid import steps_growing_with_time

METHODS = ("pt", "mtpt")


@dataclass(frozen=True)
class Segregation:
    """One segregation setup: ``method`` (pt or mtpt), n0 particles of each species per length,
    domain length, D, k, C0, MTPT's share eta of D by mass transfer, and the steps to t_end."""

    method: str = "pt"
    n0: float = 10.0
    length: float = 11_000.0
    D: float = 1.0
    k: float = 1.0
    c0: float = 1.0
    eta: float = 0.5
    dt0: float = 0.01
    growth: float = 0.01
    t_end: float = 1e4

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {self.method!r}")

    @property
    def m_p(self) -> float:
        """A PT particle's mass, C0 / n0 (MTPT's A or B particle carries the same) [M]."""
        return self.c0 / self.n0

    def steps(self) -> np.ndarray:
        """The step sizes to t_end: dt0, then growth t (timegrid.steps_growing_with_time)."""
        return steps_growing_with_time(self.t_end, self.dt0, self.growth)

    def wall_reach(self) -> float:
        """How far in from a reflecting wall MTPT's c_A is not taken: 3 sqrt(8 D t_end) [L]."""
        return 3.0 * math.sqrt(8.0 * self.D * self.t_end)


def crossover_time(m_p: float, c0: float, D: float, k: float) -> float:
    """t* where the well-mixed 1 / (k t) meets the segregated law_late: (sqrt(pi / (m_p C0))
    (8 pi D)^(1/4) / k)^(4/3) [T]."""
    return (math.sqrt(math.pi / (m_p * c0)) * (8.0 * math.pi * D) ** 0.25 / k) ** (4.0 / 3.0)


def late_law(t, m_p: float, c0: float, D: float):
    """The segregated c_A ~ sqrt(m_p C0 / pi) (8 pi D t)^(-1/4): E|U| / 2 of the diffused white-noise
    difference U = A - B of strength 2 m_p C0 (Ovchinnikov & Zeldovich 1978) [M/L]."""
    return math.sqrt(m_p * c0 / math.pi) * (8.0 * math.pi * D * np.asarray(t)) ** -0.25


def run_seed(setup: Segregation, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(times, mean c_A) of one run of ``setup`` from np.random.default_rng(seed)."""
    rng = np.random.default_rng(seed)
    dts = setup.steps()
    reaction = Bimolecular(setup.k)
    if setup.method == "pt":
        n = round(setup.n0 * setup.length)
        t, ca, _ = run_pt(n, n, reaction, setup.c0, setup.D, setup.length, dts, rng)
        return t, ca
    n = 2 * round(setup.n0 * setup.length)
    x, m = mtpt_uniform_labels(n, setup.length, setup.c0, rng)
    wall = setup.wall_reach()
    if not 2.0 * wall < setup.length:
        raise ValueError(f"MTPT's wall reach {wall:.4g} leaves no interior of the length {setup.length:.4g}")
    t, ca, _, _, _ = run_mtpt(
        x, m, reaction, setup.length / n, setup.D, setup.eta, dts, rng, domain=(0.0, setup.length),
        window=(wall, setup.length - wall),
    )  # fmt: skip
    return t, ca


def run_seeds(setup: Segregation, seeds) -> tuple[np.ndarray, np.ndarray]:
    """(times, c_A of every seed, shape (seeds, times)) of ``run_seed`` over ``seeds``, one after another."""
    runs = [run_seed(setup, s) for s in seeds]
    return runs[0][0], np.array([c for _, c in runs])


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
    masses[0, is_a] = m
    masses[1, ~is_a] = m
    return x, masses


def mtpt_step(x, masses, kinetics, dV, D, eta, dt, rng, h=None, domain=None, t: float = 0.0):
    """One reactive MTPT step of the runner's parts -> (x, masses, substeps): the walk with (1 - eta) D
    (models/mtpt.walk, reflected into ``domain``), every species exchanged with eta D (mass_transfer;
    models/mtpt.kernel: the collision kernel, or ``h`` a fixed SPH width), then every particle reacted
    (reaction_step.react_masses)."""
    from ..models.mtpt import kernel, walk
    from ..models.reaction_step import react_masses
    from ..numerics.mass_transfer import mass_transfer

    if h is not None and not (h > 0.0 and math.isfinite(h)):
        raise ValueError(f"SPH width h must be positive and finite, got {h!r}")
    x, masses, _ = walk(x, masses, None, (1.0 - eta) * D, dt, rng, domain)
    substeps = 1
    if eta * D > 0.0:
        res = mass_transfer(x, masses, *kernel(eta, D, dt, h))
        masses, substeps = res.mass, res.substeps
    else:
        masses = masses.copy()
    react_masses(kinetics, masses, dV, dt, t, "mtpt")
    return x, masses, substeps


def run_mtpt(x, masses, kinetics, dV, D, eta, dts, rng, h=None, domain=None, window=None):
    """MTPT steps of sizes ``dts`` from (x, masses) -> (times, mean c_A, mean c_B, final x, masses):
    the mass of the particles inside ``window`` (lo, hi) over its length, or without a window all
    the mass over the particles' volume N dV."""
    t, times, ca, cb = 0.0, [], [], []
    for dt in dts:
        t += dt
        x, masses, _ = mtpt_step(x, masses, kinetics, dV, D, eta, dt, rng, h, domain, t=t)
        if window is None:
            inside, volume = slice(None), x.size * dV
        else:
            inside, volume = (x >= window[0]) & (x <= window[1]), window[1] - window[0]
        times.append(t)
        ca.append(masses[0, inside].sum() / volume)
        cb.append(masses[1, inside].sum() / volume)
    return np.array(times), np.array(ca), np.array(cb), x, masses


def run_pt(na, nb, kinetics, c0: float, D: float, length: float, dts, rng):
    """PT from na A and nb B particles at independent uniform positions on the periodic [0, length),
    particle mass m_p = c0 length / na -> (times, c_A, c_B): the counts times m_p over length."""
    from ..models.pt import step
    from ..models.reaction_step import react_particles

    m_p = c0 * length / na
    xs = [rng.random(na) * length, rng.random(nb) * length, np.empty(0)]
    t, times, ca, cb = 0.0, [], [], []
    for dt in dts:
        t += dt
        xs = react_particles(kinetics, step(xs, D, dt, rng, period=length), m_p, D, dt, length, rng, t)
        times.append(t)
        ca.append(xs[0].size * m_p / length)
        cb.append(xs[1].size * m_p / length)
    return np.array(times), np.array(ca), np.array(cb)
