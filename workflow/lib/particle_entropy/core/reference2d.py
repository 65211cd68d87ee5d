"""The exact solution of 2-D advection-dispersion with uniform v and a uniform dispersion tensor D from
a source of core/sources2d.py: the source convolved with the Gaussian of covariance S = 2 D t and
carried by v t. Unit mass.

A point or Gaussian source spreads into the normal density N(centre + v t, Sigma), Sigma the source's
covariance plus S, whose differential entropy is H_I = ln(2 pi e sqrt(det Sigma)) and dilution index
E = exp(H_I). A box [a, b] x [c, d] spreads into

    c(p, t) = P(p - v t - Z in [a, b] x [c, d]) / ((b - a)(d - c)),   Z ~ N(0, S),

a bivariate normal rectangle probability. With S diagonal it is a product of two erf differences; in
an oblique flow S is not, and the probability is computed by conditioning Z_y on Z_x: for fixed Z_x = z
the Z_y-integral is an erf difference with mean (S_xy / S_xx) z and variance det S / S_xx, which
leaves a 1-D integral over z (``rectangle_probability``). The box's H_I has no closed form; it is
computed by tensor Gauss-Legendre quadrature of -c ln c (``box_entropy2d``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .sources2d import Box2D, Source2D, normal_mass

_NODES = 8  # Gauss-Legendre nodes per panel of rectangle_probability ...
_REACH = 10.0  # ... which integrates Z_x over +-10 sd: 2 Phi(-10) ~ 1.5e-23 left out
_STEP = 2.0  # ... on panels at most 2 sd wide, and at most 2 widths wide around an erf's step
_STEP_REACH = 10.0  # ... out to 10 widths each side of the step (beyond, the erf is flat to 1e-23)
_CHUNK = 4096  # points per block of rectangle_probability (memory: _CHUNK x 34 x 8 doubles per array)
_H_REACH = 8.0  # box_entropy2d integrates to 8 sd of S beyond each edge (c < e^-32 / area beyond) ...
_H_STEP = 2.0  # ... on panels at most 2 marginal sd wide within 8 sd of an edge (one over the flat inside) ...
_H_MIN_STEP = 6.0  # ... and at most 6 sd of S's minor axis (an oblique S's corners vary on that scale) ...
_H_NODES = 12  # ... each with 12 Gauss-Legendre nodes

LATTICE_N, LATTICE_SDS = 15, 3.0  # the measurement lattice: n x n points, +- sds standard deviations along each axis


def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1]."""
    return np.polynomial.legendre.leggauss(n)


def rectangle_probability(lo, hi, S) -> np.ndarray:
    """P(lo <= Z <= hi) for Z ~ N(0, S) in 2-D, lo and hi (M, 2), S (2, 2) positive definite.

    Diagonal S: the product of the two axes' Phi differences. Otherwise
    P = integral phi(u) [Phi((hi_y - k u) / s) - Phi((lo_y - k u) / s)] du over u = Z_x / sqrt(S_xx) in
    [lo_x, hi_x] / sqrt(S_xx), with k = S_xy / sqrt(S_xx) and s^2 = det S / S_xx (Z_y given Z_x), by
    8-node Gauss-Legendre panels broken at most 2 apart over |u| <= 10 and at most 2 s / |k| apart
    within 10 s / |k| of each erf's step. Against dblquad (tests/test_reference2d.py) within 1e-13 at
    D_L / D_T = 10 to 1000, dblquad's own tolerance; the rule leaves out 2 Phi(-10) ~ 1.5e-23."""
    lo = np.atleast_2d(np.asarray(lo, dtype=np.float64))
    hi = np.atleast_2d(np.asarray(hi, dtype=np.float64))
    S = np.asarray(S, dtype=np.float64)
    sx, sy = math.sqrt(S[0, 0]), math.sqrt(S[1, 1])
    if S[0, 1] == 0.0:
        return normal_mass(lo[:, 0] / sx, hi[:, 0] / sx) * normal_mass(lo[:, 1] / sy, hi[:, 1] / sy)
    k = S[0, 1] / sx
    s = math.sqrt(np.linalg.det(S) / S[0, 0])
    width = s / abs(k)  # the u-width of each erf's step
    grid = np.arange(-_REACH, _REACH + 0.5 * _STEP, _STEP)
    steps = np.arange(-_STEP_REACH, _STEP_REACH + 0.5 * _STEP, _STEP) * width
    nodes, weights = _gauss_legendre(_NODES)
    out = np.empty(len(lo))
    for start in range(0, len(lo), _CHUNK):
        part = slice(start, start + _CHUNK)
        ylo, yhi = lo[part, 1], hi[part, 1]
        u_lo = np.clip(lo[part, 0] / sx, -_REACH, _REACH)[:, None]
        u_hi = np.clip(hi[part, 0] / sx, -_REACH, _REACH)[:, None]
        breaks = np.concatenate(
            [
                u_lo,
                u_hi,
                np.broadcast_to(grid, (len(u_lo), len(grid))),
                (ylo / k)[:, None] + steps,
                (yhi / k)[:, None] + steps,
            ],
            axis=1,
        )
        breaks = np.sort(np.clip(np.nan_to_num(breaks, nan=-_REACH), u_lo, u_hi), axis=1)
        mid = 0.5 * (breaks[:, 1:] + breaks[:, :-1])
        half = 0.5 * (breaks[:, 1:] - breaks[:, :-1])
        u = mid[..., None] + half[..., None] * nodes  # (m, panels, nodes)
        mean = k * u
        inner = normal_mass((ylo[:, None, None] - mean) / s, (yhi[:, None, None] - mean) / s)
        phi = np.exp(-0.5 * u * u) / math.sqrt(2.0 * math.pi)
        out[part] = np.einsum("mpn,mp,n->m", phi * inner, half, weights)
    return out


def _panel_nodes(lo: float, hi: float, sd: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights over [lo - 8 sd, hi + 8 sd]: equal panels at most ``step`` wide
    within 8 sd of either end, and one panel over the flat middle farther than 8 sd from both."""
    reach = _H_REACH * sd
    if hi - lo <= 2.0 * reach:
        breaks = np.linspace(lo - reach, hi + reach, math.ceil((hi - lo + 2.0 * reach) / step) + 1)
    else:
        edge = np.linspace(-reach, reach, math.ceil(2.0 * reach / step) + 1)
        breaks = np.concatenate([lo + edge, hi + edge])
    nodes, weights = _gauss_legendre(_H_NODES)
    mid, half = 0.5 * (breaks[1:] + breaks[:-1]), 0.5 * (breaks[1:] - breaks[:-1])
    return (mid[:, None] + half[:, None] * nodes).ravel(), (half[:, None] * weights).ravel()


def box_entropy2d(box: Box2D, S) -> float:
    """H_I = -integral c ln c dA of the box convolved with N(0, S) [nats, dA = 1], S (2, 2) positive
    definite: a tensor product of 12-node Gauss-Legendre rules in x and y over the box widened by 8
    marginal sd of S (sqrt(S_xx), sqrt(S_yy)) each side, on panels at most 2 marginal sd and 6 minor-axis
    sd wide within 8 sd of an edge. Measured within 1e-13 nats of sums of 1-D entropies (diagonal S, by
    scipy's quad), of a fine trapezoid rule (D_L / D_T = 10 to 100 at 20 to 60 degrees) and of the
    Gaussian limit of a small box; its cost grows with D_L / D_T (~0.4 s at 10, ~1.6 s at 100)."""
    S = np.asarray(S, dtype=np.float64)
    sx, sy, s_min = math.sqrt(S[0, 0]), math.sqrt(S[1, 1]), math.sqrt(np.linalg.eigvalsh(S)[0])
    x, wx = _panel_nodes(*box.x, sx, min(_H_STEP * sx, _H_MIN_STEP * s_min))
    y, wy = _panel_nodes(*box.y, sy, min(_H_STEP * sy, _H_MIN_STEP * s_min))
    X, Y = np.meshgrid(x, y, indexing="ij")
    points = np.stack([X.ravel(), Y.ravel()], axis=1)
    corner_hi = np.array([box.x[1], box.y[1]])
    corner_lo = np.array([box.x[0], box.y[0]])
    c = rectangle_probability(points - corner_hi, points - corner_lo, S) / box.area
    safe = np.where(c > 0, c, 1.0)
    return float(np.outer(wx, wy).ravel() @ (-c * np.log(safe)))


@dataclass(frozen=True, eq=False)
class Reference2D:
    """The exact concentration of ``source`` after time t under uniform velocity v (2,) and dispersion
    tensor D (2, 2), symmetric positive definite."""

    source: Source2D
    D: np.ndarray
    v: np.ndarray
    t: float

    def __post_init__(self):
        D = np.array(self.D, dtype=np.float64)
        v = np.array(self.v, dtype=np.float64)
        if v.shape != (2,) or not np.all(np.isfinite(v)):
            raise ValueError(f"v: two finite components [L/T], got {v.tolist()!r}")
        if D.shape != (2, 2) or not np.all(np.isfinite(D)) or D[0, 1] != D[1, 0]:
            raise ValueError(f"D: a finite symmetric 2 x 2 tensor [L^2/T], got {D.tolist()!r}")
        if not (D[0, 0] > 0 and np.linalg.det(D) > 0):
            raise ValueError(f"D: a positive definite tensor [L^2/T], got {D.tolist()!r}")
        if not (math.isfinite(self.t) and self.t >= 0):
            raise ValueError(f"t: a finite time >= 0 [T], got {self.t!r}")
        D.setflags(write=False)
        v.setflags(write=False)
        object.__setattr__(self, "D", D)
        object.__setattr__(self, "v", v)

    @property
    def spread(self) -> np.ndarray:
        """The covariance added by dispersion, S = 2 D t [L^2]."""
        return 2.0 * self.t * self.D

    @property
    def centre(self) -> np.ndarray:
        """The plume's centre of mass, the source's plus v t [L]."""
        return self.source.centre + self.v * self.t

    @property
    def covariance(self) -> np.ndarray:
        """Sigma = the source's covariance + 2 D t [L^2]."""
        return self.source.covariance + self.spread

    @property
    def kernel_covariance(self) -> np.ndarray:
        """The covariance PT's bandwidth rule reads (particles2d.plume_bandwidth_2d): the plume's [L^2]."""
        return self.covariance

    def density(self, points) -> np.ndarray:
        """c(p, t) at points (M, 2) [1/L^2] (a point source at t = 0, a delta, has none: ValueError)."""
        p = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if isinstance(self.source, Box2D):
            return self._box_density(p)
        sigma = self.covariance
        det = float(np.linalg.det(sigma))
        if not det > 0:
            raise ValueError("a point source has no density at t = 0 (a delta)")
        z = p - self.centre
        quad = np.einsum("mi,ij,mj->m", z, np.linalg.inv(sigma), z)
        return np.exp(-0.5 * quad) / (2.0 * math.pi * math.sqrt(det))

    def _box_density(self, p: np.ndarray) -> np.ndarray:
        """The box convolved with N(0, 2 D t), carried by v t: its rectangle probability over its area."""
        box = self.source
        q = p - self.v * self.t
        lo = np.array([box.x[0], box.y[0]])
        hi = np.array([box.x[1], box.y[1]])
        if self.t == 0:
            inside = np.all((q >= lo) & (q <= hi), axis=1)
            return np.where(inside, 1.0 / box.area, 0.0)
        return rectangle_probability(q - hi, q - lo, self.spread) / box.area

    def h_i(self) -> float:
        """H_I = -integral c ln c dA [nats, dA = 1]: ln(2 pi e sqrt(det Sigma)) for a point or Gaussian
        (-inf for a point at t = 0); for a box ln((b - a)(d - c)) at t = 0, else box_entropy2d."""
        if isinstance(self.source, Box2D):
            return math.log(self.source.area) if self.t == 0 else box_entropy2d(self.source, self.spread)
        det = float(np.linalg.det(self.covariance))
        return math.log(2.0 * math.pi * math.e * math.sqrt(det)) if det > 0 else -math.inf

    def dilution(self) -> float:
        """E = exp(H_I) [L^2]."""
        h = self.h_i()
        return math.exp(h) if h > -math.inf else 0.0

    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """(standard deviations (2,), principal axes as columns (2, 2)) of the plume's covariance
        (principal_axes)."""
        return principal_axes(self.covariance, self.v)

    def points(self, n: int = LATTICE_N, sds: float = LATTICE_SDS) -> np.ndarray:
        """The measurement points (n * n, 2) over the plume (lattice), carried with it [L]."""
        return lattice(self.centre, self.covariance, self.v, n, sds)


def principal_axes(covariance, v) -> tuple[np.ndarray, np.ndarray]:
    """(standard deviations (2,), principal axes as columns (2, 2)) of a plume's ``covariance``, the
    larger first; the first axis points along v (along +x at v = 0 or across v), the second a
    quarter turn anticlockwise from it; where the two are equal, along and across v (x and y at v = 0)."""
    values, vectors = np.linalg.eigh(covariance)
    values, vectors = values[::-1], vectors[:, ::-1]
    speed = math.hypot(*v)
    toward = v / speed if speed > 0 else np.array([1.0, 0.0])
    if values[0] - values[1] <= 1e-12 * values[0]:
        first = toward
    else:
        first = vectors[:, 0]
        along = first @ toward
        if along < 0 or (along == 0 and first[0] + first[1] < 0):
            first = -first
    axes = np.column_stack([first, [-first[1], first[0]]])
    return np.sqrt(np.clip(values, 0.0, None)), axes


def lattice(centre, covariance, v, n: int = LATTICE_N, sds: float = LATTICE_SDS) -> np.ndarray:
    """The measurement points (n * n, 2): an n x n lattice along the principal axes of the plume's
    ``covariance`` (principal_axes), +- ``sds`` standard deviations along each, centred on the plume's
    ``centre`` (carried with it), the first axis's index the slower; independent of any model's window [L]."""
    sd, axes = principal_axes(covariance, v)
    if not sd[1] > 0:
        raise ValueError("a point source at t = 0 has no spread to lay the measurement lattice over")
    ticks = np.linspace(-sds, sds, n)
    a, b = np.meshgrid(ticks * sd[0], ticks * sd[1], indexing="ij")
    return centre + np.outer(a.ravel(), axes[:, 0]) + np.outer(b.ravel(), axes[:, 1])
