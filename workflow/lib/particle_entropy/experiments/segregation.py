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

Steps: dt0 while growth t < dt0, then dt = growth t (models.reactive.time_steps).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..models import reactive as R

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
        """The step sizes to t_end: dt0, then growth t (models.reactive.time_steps)."""
        return R.time_steps(self.t_end, self.dt0, self.growth)

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
    reaction = R.Bimolecular(setup.k)
    if setup.method == "pt":
        n = round(setup.n0 * setup.length)
        t, ca, _ = R.run_pt(n, n, reaction, setup.c0, setup.D, setup.length, dts, rng)
        return t, ca
    n = 2 * round(setup.n0 * setup.length)
    x, m = R.mtpt_uniform_labels(n, setup.length, setup.c0, rng)
    wall = setup.wall_reach()
    if not 2.0 * wall < setup.length:
        raise ValueError(f"MTPT's wall reach {wall:.4g} leaves no interior of the length {setup.length:.4g}")
    t, ca, _, _, _ = R.run_mtpt(
        x, m, reaction, setup.length / n, setup.D, setup.eta, dts, rng, domain=(0.0, setup.length),
        window=(wall, setup.length - wall),
    )  # fmt: skip
    return t, ca


def run_seeds(setup: Segregation, seeds) -> tuple[np.ndarray, np.ndarray]:
    """(times, c_A of every seed, shape (seeds, times)) of ``run_seed`` over ``seeds``, one after another."""
    runs = [run_seed(setup, s) for s in seeds]
    return runs[0][0], np.array([c for _, c in runs])
