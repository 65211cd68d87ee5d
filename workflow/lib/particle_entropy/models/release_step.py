"""What a continuous release (RunConfig.release, core/release.py) adds to each model's step (issue 53):
the mass q overlap([t_n, t_n+1], [t0, t1]) released during a step, and where it enters. A run with a
release starts empty (its source holds the mass back), and models/simulate.py's runners call these
around the same transport steps as an instantaneous run; without a release none is called.

- FD (``NodeSource``): the step's released mass spread on the nodes as the instantaneous start spreads
  its unit mass (fd.initial_concentration, plane.fd_start: a point's on its node), with the window's end
  nodes or ring left out and the rest normalised to one. Half of it is added before the step's transport
  and half after: the trapezoidal rule of the source integral int_0^dt S(dt - s) q ds, S the step's
  transport, whose local error is O(dt^3), so that the release costs no order in time. Adding it all
  before (backward Euler's own source term, S (c + q dt)) errs by (dt / 2) L q dt a step, first order:
  measured on a 1-D release with tvd at Courant 0.5, its order in space fell from 1.9 to 0.8 (12 times
  the error at n = 768). The first half enters the step's solve, so that the step's mass balance
  (fd.check_balance) counts it with the mass the step starts with; the second half is added to the
  solved state.
- MTPT (``ParticleSource``): its N particles are the instantaneous run's, uniform on Omega from t = 0,
  with no mass: the release brings mass, never particles, so that every particle keeps its volume
  dV = Omega / N and m / dV stays its concentration (particles entering at the source would crowd there,
  and the equal-volume transfer of Eq. 18, which drives neighbours to equal masses, would then make
  m / dV understate the concentration). At the end of each step, after its transfer, the mass released
  during the step enters the particles as the exact plume it has become by then (``step_plume``: the
  source's instantaneous plumes over the ages the step's release has reached, by Gauss-Legendre
  quadrature in age), its density at each particle times dV, normalised to the step's mass, as the
  instantaneous start puts a Gaussian's mass on them (Source.weighted_particles). Put on the particle
  nearest a point source instead, each step's mass would stay a spike there: the collision transfer's
  beta = 1/2 keeps half of a lone mass on its particle each step (2^-k after k steps), and a release
  adds a fresh one every step, of q dt / dV: on a 1-D release in a flow (N = 8,000, dt = 0.25, 4 seeds)
  the RMSE at 13 points was 0.075 so, 0.0049 as the step's plume (0.0092 for PT at that N).
- PT (``Batches``): the ladder's N is the number of particles released over [t0, t_e], t_e =
  min(t1, t_final) (t1 None: t_final), each of mass q (t_e - t0) / N, released at the midpoints
  tau_i = t0 + (i + 1/2) (t_e - t0) / N (not drawn: the midpoint rule's error in time, O(N^-2), lies
  far below the walk's noise, O(N^-1/2)). A step's batch is the particles whose tau_i lies in
  (t_n, t_n+1]: drawn from the source's positions, then carried by v and walked with D over
  t_n+1 - tau_i, exactly (a Gaussian step of any length is the walk's own). The mass held is m_p times
  the number released: within m_p / 2 of M(t) (the midpoints), and M(t) itself from t_e on.
"""

from __future__ import annotations

import numpy as np

from ..core.released import released_span
from .walk import walk

# Gauss-Legendre nodes of step_plume's quadrature in s, the age being a_lo + (a_hi - a_lo) s^2: the
# substitution takes out a point source's a^(-1/2) (1-D) and gives the youngest, narrowest plumes
# little weight (the first node: 1.4e-4 of the step's mass)
AGE_NODES = 16


def released(release, t_a: float, t_b: float) -> float:
    """The mass ``release`` lets out between t_a and t_b, M(t_b) - M(t_a) (Release.mass) [M]: zero, exactly,
    before its start and after its end."""
    return release.mass(t_b) - release.mass(t_a)


class NodeSource:
    """FD's release: ``per_mass`` the interior's concentration per unit mass released (summing, times the
    cell, to one); ``add`` puts half a step's released mass on it."""

    def __init__(self, cfg, per_mass: np.ndarray):
        self.release, self.per_mass = cfg.release, per_mass

    def add(self, interior: np.ndarray, t_a: float, t_b: float) -> np.ndarray:
        """``interior`` with half the mass released in [t_a, t_b] added (itself when none is)."""
        half = 0.5 * released(self.release, t_a, t_b)
        return interior if half == 0.0 else interior + half * self.per_mass


def fd_source(cfg, start: np.ndarray, cell: float) -> NodeSource:
    """FD's: ``start`` the instantaneous run's initial concentration (unit mass over ``cell``, dx or dx dy),
    its end nodes or ring left out and the rest normalised to one."""
    inner = (slice(1, -1),) * start.ndim
    w = np.asarray(start[inner], dtype=np.float64) * cell
    return NodeSource(cfg, w / (w.sum() * cell))


class ParticleSource:
    """MTPT's release: at the end of each step the mass released during it, spread on the particles as
    the exact plume it has become (step_plume)."""

    def __init__(self, cfg):
        self.cfg = cfg

    def add(self, m: np.ndarray, x: np.ndarray, t_a: float, t_b: float) -> np.ndarray:
        """Masses ``m`` of particles at ``x`` at t_b with the mass released in [t_a, t_b] added."""
        mass = released(self.cfg.release, t_a, t_b)
        if mass == 0.0:
            return m
        return m + mass * self.weights(x, t_a, t_b)

    def weights(self, x: np.ndarray, t_a: float, t_b: float) -> np.ndarray:
        """The fractions of the step's released mass on particles at ``x``: step_plume's density there,
        normalised to one; where the plume is narrower than the particles' spacing (no particle sees
        it), all on the particle nearest its centre."""
        cfg = self.cfg
        rho, centre = step_plume(cfg, x, t_a, t_b)
        total = rho.sum()
        if total > 0 and np.isfinite(total):
            return rho / total
        w = np.zeros(len(x))
        w[np.argmin(np.sum(np.reshape((x - centre) ** 2, (len(x), -1)), axis=1))] = 1.0
        return w


def step_plume(cfg, x: np.ndarray, t_a: float, t_b: float) -> tuple[np.ndarray, object]:
    """The concentration at t_b, at ``x``, of unit mass released uniformly over the release's part of
    [t_a, t_b] (the mixture of the source's plumes of ages a in [t_b - min(t_b, t_e), t_b - max(t_a, t0)]),
    by AGE_NODES-point Gauss-Legendre quadrature in s, a = a_lo + (a_hi - a_lo) s^2 -> (density, its
    centre: the source's carried by v times the mean age)."""
    first, last = released_span(cfg.release, cfg.t_final, t_b)
    first = max(first, t_a)
    a_lo, a_hi = t_b - last, t_b - first
    xi, omega = np.polynomial.legendre.leggauss(AGE_NODES)
    s = 0.5 * (xi + 1.0)  # on [0, 1]: the mean over ages is int_0^1 f(a(s)) 2 s ds
    w = omega * s  # the nodes' weights, times the Jacobian 2 s over the 2 of [-1, 1]: summing to one
    ages = a_lo + (a_hi - a_lo) * s * s
    if cfg.dim == 1:
        rho = sum(wj * cfg.source.density(x, cfg.D, cfg.v, a) for wj, a in zip(w, ages))
        return rho, cfg.source.centre + cfg.v * 0.5 * (a_lo + a_hi)
    from ..core.reference2d import Reference2D

    rho = sum(wj * Reference2D(cfg.source, cfg.D, cfg.v, a).density(x) for wj, a in zip(w, ages))
    return rho, cfg.source.centre + np.asarray(cfg.v) * 0.5 * (a_lo + a_hi)


class Batches:
    """PT's release: N particles of mass m_p at the midpoint release times tau_i over [t0, t_e]."""

    def __init__(self, cfg):
        self.cfg = cfg
        t0, t_e = released_span(cfg.release, cfg.t_final, cfg.t_final)
        n = cfg.n
        self.mass = cfg.release.rate * (t_e - t0) / n  # m_p
        self.times = t0 + (np.arange(n) + 0.5) * ((t_e - t0) / n)  # tau_i

    def count(self, t: float) -> int:
        """The number of particles released by t (tau_i <= t)."""
        return int(np.searchsorted(self.times, t, side="right"))

    def enter(self, t_a: float, t_b: float, rng: np.random.Generator) -> np.ndarray:
        """The positions at t_b of the particles released in (t_a, t_b]: drawn from the source, carried
        by v and walked with D over t_b - tau_i ((k,) on the line, (k, 2) in the plane)."""
        cfg = self.cfg
        ages = t_b - self.times[self.count(t_a) : self.count(t_b)]
        if not ages.size:
            return np.empty((0,) if cfg.dim == 1 else (0, 2))
        x = cfg.source.positions(ages.size, rng)
        if cfg.dim == 1:
            return walk(x, cfg.D * ages, 1.0, rng, cfg.v * ages)
        D, v = np.asarray(cfg.D), np.asarray(cfg.v)
        return walk(x, ages[:, None, None] * D[None], 1.0, rng, ages[:, None] * v[None])
