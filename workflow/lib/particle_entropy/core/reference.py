"""The exact solution of 1-D advection-dispersion with uniform v and D from a point, Gaussian or box
source: the reference that SSE, COMIC, H_C and the dilution index of a scene are measured against.

A point source at x0 spreads into the Gaussian of variance 2 D t centred at x0 + v t (the paper's
Eq. 2 carried by v); a Gaussian source of standard deviation sd into the Gaussian of variance
sd^2 + 2 D t; a box of uniform concentration on [a, b] into

    c(x, t) = [erf((x - a - v t) / s) - erf((x - b - v t) / s)] / (2 (b - a)),   s = sqrt(4 D t),

the Gaussian's mean over the box, computed without the erf difference's cancellation (``box_mean``)
for any width a float holds, down to the spacing of floats at the box's position.

The differential entropy H_I = -integral c ln c dx of a Gaussian is ln sqrt(2 pi e variance)
(Eq. 14); the box's has no closed form for t > 0 and is computed by Gauss-Legendre quadrature of
the exact density (``box_entropy``), ln(b - a) at t = 0. The dilution index is E = exp(H_I) (Eq. 8
with dV = 1). Every quantity is unit mass: the source carries mass 1.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from . import measures as M

SOURCE_KINDS = ("point", "gaussian", "box")
_GL_NODES = 16  # Gauss-Legendre nodes per panel of box_entropy ...
_PANEL = 2.0  # ... on panels 2 s wide (s = sqrt(4 D t)): converged to round-off
_TAIL_WIDTHS = 8.0  # box_entropy integrates to 8 s beyond each edge: erfc(8) ~ 1e-29
_FAR = 12.0  # a box wider than 24 s: its edges spread apart, erfc(12) ~ 1e-64 (box_entropy's closed form)
_MEAN_NODES = 5  # Gauss-Legendre nodes of box_mean where the erf difference would cancel ...
_NARROW = 0.05  # ... there: 4 |u| h below this ...
_WIDE = 0.1  # ... and h below this


@dataclass(frozen=True)
class Source:
    """The initial condition of a scene, unit mass: a point at x0, a Gaussian (mean x0, standard
    deviation sd) or a box of uniform concentration on [a, b] [L]."""

    kind: str = "point"
    x0: float = 0.0
    sd: float = 0.0
    a: float = 0.0
    b: float = 0.0

    def __post_init__(self):
        if self.kind not in SOURCE_KINDS:
            raise ValueError(f"source kind {self.kind!r}: one of {', '.join(SOURCE_KINDS)}")
        if self.kind == "gaussian" and not (self.sd > 0 and math.isfinite(self.sd)):
            raise ValueError(f"a Gaussian source needs sd > 0 and finite, got {self.sd!r}")
        if self.kind == "box" and not (self.b > self.a and math.isfinite(self.b - self.a)):
            raise ValueError(f"a box source needs a < b, both finite, got [{self.a!r}, {self.b!r}]")

    @property
    def centre(self) -> float:
        """The source's centre of mass [L]."""
        return 0.5 * (self.a + self.b) if self.kind == "box" else self.x0

    @property
    def variance(self) -> float:
        """The source's own variance: 0, sd^2 or (b - a)^2 / 12 [L^2]."""
        if self.kind == "gaussian":
            return self.sd * self.sd
        if self.kind == "box":
            return (self.b - self.a) ** 2 / 12.0
        return 0.0

    @property
    def half_width(self) -> float:
        """Half the source's extent where it holds all but ~1e-9 of its mass: 0, 6 sd, (b - a) / 2 [L]."""
        return {"point": 0.0, "gaussian": 6.0 * self.sd, "box": 0.5 * (self.b - self.a)}[self.kind]

    def positions(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n particle positions drawn from the source (random walkers' starting points) [L]."""
        if self.kind == "gaussian":
            return self.x0 + self.sd * rng.standard_normal(n)
        if self.kind == "box":
            return rng.uniform(self.a, self.b, n)
        return np.full(n, float(self.x0))

    def masses(self, x: np.ndarray, dV: float) -> np.ndarray:
        """Unit mass spread over particles or nodes at ``x`` with spacing dV: the point on
        the one nearest x0, the Gaussian and box by their density (a box narrower than dV on the
        one nearest its centre), normalised to sum 1."""
        x = np.asarray(x, dtype=np.float64)
        if self.kind == "gaussian":
            z = (x - self.x0) / self.sd
            m = np.exp(-0.5 * z * z)
        elif self.kind == "box":
            m = np.clip(np.minimum(x + 0.5 * dV, self.b) - np.maximum(x - 0.5 * dV, self.a), 0.0, None)
        else:
            m = np.zeros_like(x)
        if not m.sum() > 0:  # a point, or a source narrower than the spacing
            m = np.zeros_like(x)
            m[np.argmin(np.abs(x - self.centre))] = 1.0
        return m / m.sum()


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
    def centre(self) -> float:
        """The plume's centre of mass, the source's plus v t [L]."""
        return self.source.centre + self.shift

    def density(self, x: np.ndarray) -> np.ndarray:
        """c(x, t) [1/L] (a point source at t = 0 has none: ValueError)."""
        x = np.asarray(x, dtype=np.float64)
        s = self.source
        if s.kind == "box":
            if self.spread == 0.0:
                return np.where((x >= s.a + self.shift) & (x <= s.b + self.shift), 1.0 / (s.b - s.a), 0.0)
            w = math.sqrt(2.0 * self.spread)  # sqrt(4 D t)
            return box_mean((x - self.centre) / w, 0.5 * (s.b - s.a) / w) / w
        var = self.variance
        if not var > 0:
            raise ValueError("a point source has no density at t = 0 (a delta)")
        if s.kind == "point":  # the paper's Gaussian (Eq. 2), moved: its very bits at x0 = v = 0
            return M.gaussian_density(x - self.centre, self.D, self.t)
        z = x - self.centre
        return np.exp(-0.5 * z * z / var) / math.sqrt(2.0 * math.pi * var)

    def entropy(self) -> float:
        """H_I = -integral c ln c dx [nats, dV = 1] (Eq. 14 for a Gaussian; -inf for a point at t = 0)."""
        s = self.source
        if s.kind == "box":
            return box_entropy(s.b - s.a, self.D * max(self.t, 0.0))
        if s.kind == "point":
            return M.analytic_h_i(self.D, self.t)
        var = self.variance
        return 0.5 * math.log(2.0 * math.pi * math.e * var) if var > 0 else -math.inf

    def dilution(self) -> float:
        """E = exp(H_I) (Eq. 8) [L]."""
        if self.source.kind == "point":
            return M.analytic_dilution(self.D, self.t)
        h = self.entropy()
        return math.exp(h) if h > -math.inf else 0.0

    def h_c(self, dV: float) -> float:
        """H_C = H_I - ln dV (Eqs. 6-7)."""
        return self.entropy() - math.log(dV)

    def sampled(self, x: np.ndarray, dV: float) -> np.ndarray:
        """c sampled at sorted ``x`` and scaled to sum c dV = 1, as analytic_sampled does for the
        paper's Gaussian; where the plume is narrower than the sampling (no sample sees it), all
        its mass goes on the sample nearest its centre."""
        x = np.asarray(x, dtype=np.float64)
        if self.source.kind == "point":
            return M.analytic_sampled(x - self.centre, self.D, self.t, dV)
        if self.variance > 0:
            if self.source.kind == "box":  # at t = 0 its indicator: 1 / width may overflow
                g = self.density(x) if self.spread > 0 else self.density(x) > 0
            else:  # in log space: a plume narrower than the spacing keeps its peak
                z = x - self.centre
                logg = -0.5 * z * z / self.variance
                g = np.exp(logg - logg.max())
            total = g.sum()
            if total > 0:
                return g / (total * dV)
        g = np.zeros_like(x)
        g[np.argmin(np.abs(x - self.centre))] = 1.0
        return g / dV

    def points(self, length: float | None = None) -> np.ndarray:
        """The measurement points common to every model (measures.measurement_points: 15 points on
        [-L/2, L/2], L the paper's fd_length or ``length``, a scene's span), carried with the
        plume by x0 + v t: sensors that follow the plume, so that a scene measures it where it is [L]."""
        points = M.measurement_points() if length is None else M.measurement_points(length)
        move = self.source.x0 + self.shift if self.source.kind != "box" else self.centre
        return points if move == 0.0 else points + move

    def sse_points(self, points: np.ndarray, x: np.ndarray, c: np.ndarray, dV: float) -> float:
        """SSE at ``points`` of the model concentration c at sorted x against c(points, t), as
        measures.sse_points (whose very bits a point source at rest gets); where the plume has no
        density (a point at t = 0), against its delta on the model point nearest the centre."""
        if self.source.kind == "point":
            move = self.centre
            if move == 0.0:
                return M.sse_points(points, x, c, self.D, self.t, dV)
            return M.sse_points(points - move, x - move, c, self.D, self.t, dV)
        return M.sse(M.at_points(points, x, c), self.density(points))

    def extent(self, widths: float = 6.0) -> tuple[float, float]:
        """[lo, hi] around the plume: the source's extent carried by v t plus ``widths`` standard
        deviations of the dispersion 2 D t [L]."""
        reach = self.source.half_width + widths * math.sqrt(self.spread)
        return self.centre - reach, self.centre + reach


@functools.lru_cache(maxsize=256)
def box_entropy(width: float, dt: float) -> float:
    """H_I of a unit-mass box of ``width`` after dispersion D t = ``dt`` [nats]; ln(width) for dt = 0.

    In u = x / s (s = sqrt(4 D t)) the density is box_mean(u, h) / s with h = width / (2 s), so one
    rule in u serves every step. By symmetry only u >= 0 is summed: farther than 8 s inside the
    edge c is 1 / width to 1e-29, a term known exactly; from there to 8 s beyond the edge,
    Gauss-Legendre quadrature of -c ln c = entr(b) + b ln s per du (b = box_mean) on panels at most
    2 s wide. Where h >= 12 the edges spread apart and the entropy is ln(width) + K / (2 h), K that
    of one spread edge (``_edge_entropy``): exact also where the box is so many s wide that floats
    at its edge cannot resolve s."""
    if not width > 0:
        raise ValueError(f"box width must be > 0, got {width!r}")
    if dt <= 0:
        return math.log(width)
    from scipy.special import entr

    s = math.sqrt(4.0 * dt)
    h = 0.5 * width / s
    if h >= _FAR:
        return math.log(width) + _edge_entropy() / (2.0 * h)
    start = max(0.0, h - _TAIL_WIDTHS)
    span = h + _TAIL_WIDTHS - start
    nodes, weights = _unit_rule(math.ceil(span / _PANEL))
    u = start + span * nodes
    b = box_mean(u, h)
    flat = start * s * math.log(width) / width  # -c ln c = ln(width) / width on [0, start s]
    return float(2.0 * (flat + span * (np.dot(weights, entr(b)) + math.log(s) * np.dot(weights, b))))


@functools.lru_cache(maxsize=64)
def _unit_rule(panels: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of composite Gauss-Legendre quadrature on [0, 1]: ``panels`` equal panels,
    _GL_NODES nodes each."""
    nodes, weights = np.polynomial.legendre.leggauss(_GL_NODES)
    mid = (np.arange(panels) + 0.5) / panels
    return (mid[:, None] + (0.5 / panels) * nodes[None, :]).ravel(), np.tile((0.5 / panels) * weights, panels)


@functools.cache
def _edge_entropy() -> float:
    """K = integral of -erfc(v) ln erfc(v) + 2 ln 2 [v < 0] dv over the real line: (s / width) K is
    what dispersion adds to the entropy ln(width) of a box whose two edges spread apart [-]."""
    from scipy.special import entr, erfc

    span = 2.0 * _TAIL_WIDTHS
    nodes, weights = _unit_rule(math.ceil(span / _PANEL))
    return float(span * np.dot(weights, entr(erfc(span * nodes - _TAIL_WIDTHS)))) + span * math.log(2.0)


def warm_up(source: Source) -> None:
    """Import what the exact solution of ``source`` is computed with and build box_entropy's rules
    before a run's timed steps (scipy.special: ~30 ms once per process)."""
    if source.kind == "box":
        _edge_entropy()
        for panels in range(1, math.ceil(2.0 * _TAIL_WIDTHS / _PANEL) + 1):  # every span up to 16 s
            _unit_rule(panels)
        box_mean(np.zeros(1), 1.0)


def box_mean(u: np.ndarray, h: float) -> np.ndarray:
    """The mean of exp(-z^2) / sqrt(pi) over [u - h, u + h], (erf(u + h) - erf(u - h)) / (4 h), to
    round-off for every h >= 0 (h = 0: the density at u itself).

    The erf difference cancels when both ends lie on one side of 0 and the interval is narrow: its
    relative error is ~ eps / (1 - exp(-4 |u| h)), all of it for h below ~1e-16 (a box 1e-16 wide
    at 4 D t = 0.2 had an entropy 0.36 too low). Where 4 |u| h < 1/20 and h < 1/10, the mean is
    exp(-u^2) times that of exp(-2 u h z - h^2 z^2) over z in [-1, 1], a function within 4 % of 1
    whose 5-node Gauss-Legendre quadrature is exact to round-off. Elsewhere the ends lie on one side
    of 0 with 4 |u| h >= 1/20 (erfc(|u| - h) - erfc(|u| + h), which loses at most a factor 20 of
    round-off to the difference) or straddle 0 with h >= 1/10 (erf(|u| + h) + erf(h - |u|): no
    cancellation). Where h >= 1/10 (most calls: every step of a box's run) the erfc difference serves
    every point, in the fewest array operations: it loses at most a factor 25 where the ends lie on
    one side of 0 (4 |u| h >= 1/25) and 1 / erf(h) < 9 where they straddle it."""
    from scipy.special import erf

    u = np.asarray(u, dtype=np.float64)
    h = float(h)
    if not h >= 0:
        raise ValueError(f"half width must be >= 0, got {h!r}")
    a = np.abs(u)  # by symmetry
    if h >= _WIDE:  # one form, the fewest array operations: most calls (every step of a box's run)
        return _erfc_mean(a, h)
    out = np.empty_like(u)
    if h > 0:
        side = a >= h
        out[side] = _erfc_mean(a[side], h)
        straddle = ~side
        near = a[straddle]
        out[straddle] = (erf(near + h) + erf(h - near)) / (4.0 * h)
    narrow = 4.0 * a * h < _NARROW  # every point at h = 0
    if narrow.any():
        nodes, weights = _mean_rule()
        z = a[narrow][..., None] + h * nodes
        out[narrow] = (0.5 / math.sqrt(math.pi)) * (np.exp(-z * z) @ weights)
    return out


def _erfc_mean(a: np.ndarray, h: float) -> np.ndarray:
    """box_mean at |u| = a >= 0 as (erfc(a - h) - erfc(a + h)) / (4 h), h > 0 (its bounds on round-off:
    box_mean)."""
    from scipy.special import erfc

    return (erfc(a - h) - erfc(a + h)) / (4.0 * h)


@functools.cache
def _mean_rule() -> tuple[np.ndarray, np.ndarray]:
    return np.polynomial.legendre.leggauss(_MEAN_NODES)
