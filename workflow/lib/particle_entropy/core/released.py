"""The plume of a continuous release as a run reads it (issue 53): its moments, and its scores against
the exact plume.

A release (core/release.py) of rate q from t0 to t_e = min(t1, t_final) (t1 None: t_final) has put, by
time t, the mass M(t) = q A, A = max(0, min(t, t_e) - t0), into puffs: the mass released at tau has
spread as the source's instantaneous plume of age t - tau. The ages are uniform on
[t - min(t, t_e), t - t0], of mean a = t - (t0 + min(t, t_e)) / 2 and variance A^2 / 12, so the
released plume (normalised to unit mass: the mixture of the source's plumes over those ages) has

- centre: the source's centre + v a;
- covariance: the source's + 2 D a + v v^T A^2 / 12 (the puffs' mean spread, and their centres'
  spread along the flow), which sets the plume's extent (PT's estimate grid in 2-D, the points);
- kernel covariance: the puffs' mean, the source's + 2 D a, which the particles' bandwidth rules read
  (pt.reconstruction_width, mtpt.kernel_for_step, plane.pt_bandwidth): in a flow a release is a
  streak of puffs, whose variance grows with its length v A while its concentration varies on the
  puffs' scale. At v = 0 the two are equal. Before any mass is released (A = 0) both are the source's.

The scores are core/release.py's exact plume (ReleaseReference, ReleaseReference2D: Gauss-Legendre
quadrature in age, ~1e-11 relative), read as the instantaneous references are read:

- density(x): the concentration c(x, t) of the mass released so far [M/L^d], in the units the models'
  concentrations carry (FD's nodes, MTPT's m / dV, PT's estimate times its particles' mass); the SSEs
  at the points and over a model's own points are of it [M^2/L^2d] (divided by M(t)^2: the normalised
  plume's);
- sampled(x, dV) (1-D): c sampled at the model's points and scaled to sum c dV = M(t), as
  Source.sampled scales the instantaneous plume to its unit mass (point values, not cell means);
- H_I (``entropy``, ``h_i``), H_C = H_I - ln dV and E = exp(H_I): of the plume normalised to unit
  mass, p = c / M(t), as the models' entropies normalise their masses.

While nothing is released (t <= t0) every score is NaN: there is no plume to normalise.

Cost. The exact plume at one t costs 10-40 ms in 1-D (its entropy's adaptive rule: ~600 ages by
~800-3,000 nodes) and 0.1-2 s in 2-D (the tensor rule), against ~0.07 ms for an FD step of 200 nodes
on the line (benchmarks/release_scores.py). So a run is scored against it at its last row only, t_final, the time a
scene judges (RunConfig.reference passes ``scored`` False before: those rows' exact columns are NaN,
as the plane's are before its last row for every run), and models/simulate.warm_up builds that plume
before the timed steps (its H_I, its density at the measurement points and at a 1-D FD run's nodes,
kept by ``exact_plume``'s cache), so that the rows' wall times stay the model's. A ReleasedPlume made
directly scores at any t.

Infinite values. A 2-D point source still releasing at t (t <= t1) has an infinite concentration at its
point (c ~ ln(1/r) near it: Wilson and Miller's W(u, beta) as r -> 0); ``density`` gives NaN there, so a
measure that reads it (SSE_points, COMIC_points: a lattice point on the source, as at v = 0, where the
lattice's centre is the source) is NaN, while H_I and E stay finite (p ln p ~ ln(1/r) ln ln(1/r) is
integrable in the plane). ``measure_finite`` tells, for a measure, a source, D, a release, t and
points, whether the value is finite. On the line the plume is finite everywhere: at a point source the age
integral of its s^-1/2 converges.

Not computed. H_I (so H_C and E) of a 2-D box in an oblique flow (D with D_xy != 0) is NaN:
ReleaseReference2D refuses it (its tensor rule would need ~1e8 rectangle probabilities, hours);
``measure_finite`` says so too. Its density at points is computed (~1.6 s at the 225 lattice points).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from . import measures as M
from . import plane
from .reference2d import LATTICE_N, LATTICE_SDS, lattice
from .release import Release, ReleaseReference, ReleaseReference2D

# the measures a run reads off the exact plume's value at points (its own or the measurement points; a
# scene's rmse is SSE_points'), and those it reads off its integrals (H_I, E; a scene's entropy, dilution)
POINTWISE = ("SSE", "AIC", "COMIC", "SSE_points", "COMIC_points", "rmse")
INTEGRALS = ("H_C_analytic", "E_analytic", "entropy", "dilution")
_MEMO = 4  # densities an exact plume keeps, by their points: the measurement points, FD's nodes, ...
_MEMO_POINTS = 100_000  # ... of sets up to this size (a particle cloud's, asked once, is not kept)


def released_span(release: Release, t_final: float, t: float) -> tuple[float, float]:
    """(t0, min(t, t_e)): the times over which mass has been released by time t, t_e = min(end, t_final)
    (end None: t_final); the two equal while nothing is released [T]."""
    end = t_final if release.end is None else min(release.end, t_final)
    last = min(t, end)
    return (release.start, last) if last > release.start else (release.start, release.start)


def singular(source, release: Release, t: float) -> bool:
    """Whether the exact plume at t has an infinite concentration: a 2-D point source still releasing
    (t0 < t <= t1, t1 None: open), c ~ ln(1/r) at its point (Wilson and Miller 1978)."""
    if not (plane.is_plane(source) and source.kind == "point" and t > release.start):
        return False
    return release.end is None or release.end >= t


def uncomputed_entropy(source, D) -> bool:
    """Whether the exact plume's H_I is left NaN: a 2-D box under an oblique D (D_xy != 0), whose tensor
    rule ReleaseReference2D refuses (hours)."""
    return plane.is_plane(source) and source.kind == "box" and np.asarray(D, dtype=np.float64)[0, 1] != 0.0


def measure_finite(measure: str, source, D, release: Release, t: float, points=None) -> bool:
    """Whether ``measure`` (a run's column in POINTWISE or INTEGRALS, or a scene's rmse, entropy,
    dilution) of the exact plume of ``release`` from ``source`` under dispersion D at time t is finite:
    the integrals unless ``uncomputed_entropy``; a pointwise measure unless the plume is ``singular``
    and one of ``points`` (M, 2) lies on the source (``points`` None: anywhere, so it may)."""
    if measure in INTEGRALS:
        return not uncomputed_entropy(source, D)
    if measure not in POINTWISE:
        raise ValueError(f"measure: one of {', '.join(POINTWISE + INTEGRALS)}, got {measure!r}")
    if not singular(source, release, t):
        return True
    if points is None:
        return False
    p = np.atleast_2d(np.asarray(points, dtype=np.float64))
    return not bool(np.any(np.all(p == source.centre, axis=1)))


class ExactPlume:
    """The exact plume of a release at one t (ReleaseReference or ReleaseReference2D, ``reference``) and
    the densities asked of it, kept by their points (the last _MEMO sets of up to _MEMO_POINTS)."""

    def __init__(self, reference):
        self.reference = reference
        self._densities: dict = {}

    def density(self, points) -> np.ndarray:
        """c at ``points`` (the reference's density, computed once per set of points) [M/L^d]."""
        p = np.asarray(points, dtype=np.float64)
        if len(p) > _MEMO_POINTS:
            return self.reference.density(p)
        key = (p.shape, p.tobytes())
        if key not in self._densities:
            if len(self._densities) >= _MEMO:
                self._densities.pop(next(iter(self._densities)))
            c = self.reference.density(p)
            c.setflags(write=False)
            self._densities[key] = c
        return self._densities[key]

    @functools.cached_property
    def h_i(self) -> float:
        """H_I of the plume normalised to unit mass [nats, dV = 1]; NaN where ``uncomputed_entropy``."""
        ref = self.reference
        if not isinstance(ref, ReleaseReference2D):
            return ref.entropy()
        return math.nan if uncomputed_entropy(ref.source, ref.D) else ref.h_i()


@functools.lru_cache(maxsize=8)
def exact_plume(source, D, v, release: Release, t: float) -> ExactPlume:
    """The exact plume of ``release`` from ``source`` at time t (> its start), cached by the physics and t
    (D, v: floats on the line, plane.tensor and plane.pair in the plane), so that a run's calls at one t,
    and the warm-up's, share one."""
    if plane.is_plane(source):
        return ExactPlume(ReleaseReference2D(source, release, np.array(D), np.array(v), t))
    return ExactPlume(ReleaseReference(source, release, D, v, t))


@dataclass(frozen=True, eq=False)
class _Released:
    """What a released plume of either dimension shares: the puffs' ages at time t, the mass, and the
    scores against the exact plume (NaN while nothing is released, or where ``scored`` is False)."""

    source: object
    D: object
    v: object
    t: float
    release: Release
    t_final: float
    scored: bool = True

    def ages(self) -> tuple[float, float]:
        """(mean age a, duration A) of the mass released by t; (0, 0) while none is [T]."""
        first, last = released_span(self.release, self.t_final, self.t)
        if last == first:
            return 0.0, 0.0
        return self.t - 0.5 * (first + last), last - first

    def mass(self) -> float:
        """M(t), the mass released by t [M]."""
        return self.release.mass(self.t)

    @property
    def singular(self) -> bool:
        """Whether the exact plume is infinite at the source (``singular``: a 2-D point still releasing)."""
        return singular(self.source, self.release, self.t)

    def exact(self) -> ExactPlume | None:
        """The exact plume at t (``exact_plume``), None where it is not read: ``scored`` False, or nothing
        released yet."""
        if not (self.scored and self.mass() > 0):
            return None
        if plane.is_plane(self.source):
            return exact_plume(self.source, plane.tensor(self.D), plane.pair(self.v), self.release, self.t)
        return exact_plume(self.source, float(self.D), float(self.v), self.release, self.t)

    def entropy(self) -> float:
        """H_I = -integral p ln p of p = c / M(t) [nats, dV = 1]; NaN unscored."""
        plume = self.exact()
        return math.nan if plume is None else plume.h_i

    def h_i(self) -> float:
        """H_I, as Reference2D names it."""
        return self.entropy()

    def h_c(self, dV: float) -> float:
        """H_C = H_I - ln dV (Eqs. 6-7); NaN unscored."""
        return self.entropy() - math.log(dV)

    def dilution(self) -> float:
        """E = exp(H_I) (Eq. 8) [L^d]; NaN unscored."""
        return math.exp(self.entropy())

    def _density(self, points, count: int) -> np.ndarray:
        """The exact c at ``points`` (``count`` of them), NaN where it is infinite or unscored [M/L^d]."""
        plume = self.exact()
        if plume is None:
            return np.full(count, math.nan)
        c = plume.density(points)
        return np.where(np.isinf(c), math.nan, c) if self.singular else c.copy()


class ReleasedPlume(_Released):
    """A 1-D release's plume at time t: centre, variance and kernel variance, and its exact scores."""

    @property
    def centre(self) -> float:
        """The source's centre + v a [L]."""
        return self.source.centre + self.v * self.ages()[0]

    @property
    def kernel_variance(self) -> float:
        """The puffs' mean variance, the source's + 2 D a [L^2]."""
        return self.source.variance + 2.0 * self.D * self.ages()[0]

    @property
    def variance(self) -> float:
        """The released plume's variance, the puffs' mean + v^2 A^2 / 12 [L^2]."""
        duration = self.ages()[1]
        return self.kernel_variance + self.v * self.v * duration * duration / 12.0

    def density(self, x) -> np.ndarray:
        """c(x, t) of the mass released by t (ReleaseReference.density) [M/L]; NaN unscored."""
        x = np.asarray(x, dtype=np.float64)
        return self._density(x.ravel(), x.size).reshape(x.shape)

    def sampled(self, x, dV: float) -> np.ndarray:
        """c at sorted ``x`` scaled to sum c dV = M(t), as Source.sampled scales the instantaneous plume to
        its unit mass; where no sample sees the plume, all of it on the sample nearest its centre [M/L]."""
        x = np.asarray(x, dtype=np.float64)
        g = self.density(x)
        mass = self.mass()
        if np.isnan(g).any():
            return g
        total = g.sum()
        if total > 0:
            return g * (mass / (total * dV))
        g = np.zeros_like(x)
        g[np.argmin(np.abs(x - self.centre))] = mass / dV
        return g

    def sse_points(self, points, x, c, dV: float) -> float:
        """SSE at ``points`` of the model concentration c at sorted x (measures.at_points) against the
        exact c there (Eq. 44) [M^2/L^2]; NaN unscored."""
        return M.sse(M.at_points(points, x, c), self.density(points))

    def points(self, length: float | None = None) -> np.ndarray:
        """The 15 measurement points (Reference.points) carried to the released plume's centre [L]."""
        points = M.measurement_points() if length is None else M.measurement_points(length)
        return points + self.centre


class ReleasedPlume2D(_Released):
    """A 2-D release's plume at time t: centre, covariance and kernel covariance, and its exact scores."""

    @property
    def centre(self) -> np.ndarray:
        """The source's centre + v a (2,) [L]."""
        return self.source.centre + np.asarray(self.v) * self.ages()[0]

    @property
    def kernel_covariance(self) -> np.ndarray:
        """The puffs' mean covariance, the source's + 2 D a (2, 2) [L^2]."""
        return self.source.covariance + 2.0 * self.ages()[0] * np.asarray(self.D)

    @property
    def covariance(self) -> np.ndarray:
        """The released plume's covariance, the puffs' mean + v v^T A^2 / 12 (2, 2) [L^2]."""
        v = np.asarray(self.v)
        duration = self.ages()[1]
        return self.kernel_covariance + np.outer(v, v) * (duration * duration / 12.0)

    def density(self, points) -> np.ndarray:
        """c(p, t) of the mass released by t at points (M, 2) (ReleaseReference2D.density) [M/L^2]; NaN on
        a point source still releasing (``singular``: c = inf there) and unscored."""
        p = np.atleast_2d(np.asarray(points, dtype=np.float64))
        return self._density(p, len(p))

    def points(self, n: int = LATTICE_N, sds: float = LATTICE_SDS) -> np.ndarray:
        """The n x n lattice over the released plume (reference2d.lattice) [L]."""
        return lattice(self.centre, self.covariance, np.asarray(self.v, dtype=np.float64), n, sds)
