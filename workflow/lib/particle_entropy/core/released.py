"""The plume of a continuous release as a run reads it (issue 53): its moments, exact, and no density.

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

Its exact density and entropy are core/release.py's ReleaseReference (ReleaseReference2D), which the
runs' scores do not read yet: here every score against the exact plume (density, sampled, SSE at
points, H_C and E) is NaN, so that a release run's table carries its model's own measures and masses.
RunConfig.reference returns a ReleasedPlume (ReleasedPlume2D in 2-D) for a run with a release; scoring
a release run is making these methods that reference's (a per-step quadrature in age: its cost per row
is the open question).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import measures as M
from .reference2d import lattice
from .release import Release


def released_span(release: Release, t_final: float, t: float) -> tuple[float, float]:
    """(t0, min(t, t_e)): the times over which mass has been released by time t, t_e = min(end, t_final)
    (end None: t_final); the two equal while nothing is released [T]."""
    end = t_final if release.end is None else min(release.end, t_final)
    last = min(t, end)
    return (release.start, last) if last > release.start else (release.start, release.start)


@dataclass(frozen=True, eq=False)
class _Released:
    """What a released plume of either dimension shares: the puffs' ages at time t."""

    source: object
    D: object
    v: object
    t: float
    release: Release
    t_final: float

    def ages(self) -> tuple[float, float]:
        """(mean age a, duration A) of the mass released by t; (0, 0) while none is [T]."""
        first, last = released_span(self.release, self.t_final, self.t)
        if last == first:
            return 0.0, 0.0
        return self.t - 0.5 * (first + last), last - first

    def mass(self) -> float:
        """M(t), the mass released by t [M]."""
        return self.release.mass(self.t)

    # the scores against the exact released plume: core/release.py's reference, not here
    def h_c(self, dV: float) -> float:
        return math.nan

    def entropy(self) -> float:
        return math.nan

    def h_i(self) -> float:
        return math.nan

    def dilution(self) -> float:
        return math.nan


class ReleasedPlume(_Released):
    """A 1-D release's plume at time t: centre, variance and kernel variance exact, scores NaN."""

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
        return np.full(np.shape(x), math.nan)

    def sampled(self, x, dV: float) -> np.ndarray:
        return np.full(np.shape(x), math.nan)

    def sse_points(self, points, x, c, dV: float) -> float:
        return math.nan

    def points(self, length: float | None = None) -> np.ndarray:
        """The 15 measurement points (Reference.points) carried to the released plume's centre [L]."""
        points = M.measurement_points() if length is None else M.measurement_points(length)
        return points + self.centre


class ReleasedPlume2D(_Released):
    """A 2-D release's plume at time t: centre, covariance and kernel covariance exact, scores NaN."""

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
        return np.full(len(np.atleast_2d(points)), math.nan)

    def points(self, n: int = 15, sds: float = 3.0) -> np.ndarray:
        """The n x n lattice over the released plume (reference2d.lattice) [L]."""
        return lattice(self.centre, self.covariance, np.asarray(self.v, dtype=np.float64), n, sds)
