"""The exact solution of 1-D advection-dispersion with uniform v and D from a source (core/sources.py:
a point, Gaussian, box ...): the reference that SSE, COMIC, H_C and the dilution index of a scene are
measured against. The source's kind computes the solution; a Reference fixes D, v and t and adds what
every kind shares: the plume's centre and variance, H_C, the measurement points and the extent.
Every quantity is unit mass: the source carries mass 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import measures as M
from .sources import Source


@dataclass(frozen=True)
class Reference:
    """The exact concentration of ``source`` after time t under uniform velocity v and dispersion D."""

    source: Source
    D: float
    v: float
    t: float

    @property
    def shift(self) -> float:
        """How far the plume has been carried, v t [L]."""
        return self.v * self.t

    @property
    def spread(self) -> float:
        """The variance added by dispersion, 2 D t [L^2]."""
        return 2.0 * self.D * max(self.t, 0.0)

    @property
    def variance(self) -> float:
        """The plume's variance: the source's plus 2 D t [L^2]."""
        return self.source.variance + self.spread

    @property
    def kernel_variance(self) -> float:
        """The variance the particles' bandwidth rules read (h_DE, Eq. 23; h_SPH, Eq. 26): the plume's [L^2]."""
        return self.variance

    @property
    def centre(self) -> float:
        """The plume's centre of mass, the source's plus v t [L]."""
        return self.source.centre + self.shift

    def density(self, x: np.ndarray) -> np.ndarray:
        """c(x, t) [1/L] (a point source at t = 0 has none: ValueError)."""
        return self.source.density(x, self.D, self.v, self.t)

    def entropy(self) -> float:
        """H_I = -integral c ln c dx [nats, dV = 1] (Eq. 14 for a Gaussian; -inf for a point at t = 0)."""
        return self.source.entropy(self.D, self.t)

    def dilution(self) -> float:
        """E = exp(H_I) (Eq. 8) [L]."""
        return self.source.dilution(self.D, self.t)

    def h_c(self, dV: float) -> float:
        """H_C = H_I - ln dV (Eqs. 6-7)."""
        return self.entropy() - math.log(dV)

    def sampled(self, x: np.ndarray, dV: float) -> np.ndarray:
        """c sampled at sorted ``x`` and scaled to sum c dV = 1 (Source.sampled)."""
        return self.source.sampled(x, dV, self.D, self.v, self.t)

    def points(self, length: float | None = None) -> np.ndarray:
        """The measurement points common to every model (measures.measurement_points: 15 points on
        [-L/2, L/2], L the paper's fd_length or ``length``, a scene's span), carried with the
        plume to its centre: sensors that follow the plume, so that a scene measures it where it is [L]."""
        points = M.measurement_points() if length is None else M.measurement_points(length)
        move = self.centre
        return points if move == 0.0 else points + move

    def sse_points(self, points: np.ndarray, x: np.ndarray, c: np.ndarray, dV: float) -> float:
        """SSE at ``points`` of the model concentration c at sorted x against c(points, t) (Source.sse_points:
        a point source at rest gets the very bits of measures.sse_points)."""
        return self.source.sse_points(points, x, c, dV, self.D, self.v, self.t)

    def extent(self, widths: float = 6.0) -> tuple[float, float]:
        """[lo, hi] around the plume: the source's extent carried by v t plus ``widths`` standard
        deviations of the dispersion 2 D t [L]."""
        reach = self.source.half_width + widths * math.sqrt(self.spread)
        return self.centre - reach, self.centre + reach
