"""Source kinds: the initial condition of a scene, unit mass, one class per kind (as scipy.stats gives
each distribution a class whose ``_argcheck`` sits beside its ``_pdf`` and ``_entropy``).

A kind declares its parameters (``PARAMS``: key, unit, default, schema) and their checks
(``_argcheck``, and ``_speccheck`` for a config's stricter ones), and computes what the runs and
their exact reference need: the source's centre, variance and extent, the particles' initial
positions and the masses of particles or FD nodes, and the exact solution of 1-D advection-dispersion
with uniform v and D after time t: the density c(x, t), its differential entropy
H_I = -integral c ln c dx (Eq. 14 for a Gaussian), the dilution index E = exp(H_I) (Eq. 8, dV = 1)
and the sampled reference. ``SOURCES`` lists the kinds once: the config schema's fragment
(``source_shape``), the scene's checks (``Source.from_spec``) and the texts that name the kinds
derive from it, so that a new kind is one class here.

A point source at x0 spreads into the Gaussian of variance 2 D t centred at x0 + v t (the paper's
Eq. 2 carried by v); a Gaussian source of standard deviation sd into the Gaussian of variance
sd^2 + 2 D t; a box of uniform concentration on [a, b] into

    c(x, t) = [erf((x - a - v t) / s) - erf((x - b - v t) / s)] / (2 (b - a)),   s = sqrt(4 D t),

the Gaussian's mean over the box, computed without the erf difference's cancellation (``box_mean``)
for any width a float holds, down to the spacing of floats at the box's position. The box's entropy
has no closed form for t > 0 and is computed by Gauss-Legendre quadrature of the exact density
(``box_entropy``), ln(b - a) at t = 0.
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from . import measures as M

MIN_SD = math.sqrt(sys.float_info.min)  # a Gaussian source's sd whose variance sd^2 is a normal float
# The fields every source's record carried before kinds were classes (one dataclass for all kinds):
# the kinds of then keep them all, 0.0 where not theirs, so that the digests of their runs stay.
LEGACY_FIELDS = ("x0", "sd", "a", "b")
_GL_NODES = 16  # Gauss-Legendre nodes per panel of box_entropy ...
_PANEL = 2.0  # ... on panels 2 s wide (s = sqrt(4 D t)): converged to round-off
_TAIL_WIDTHS = 8.0  # box_entropy integrates to 8 s beyond each edge: erfc(8) ~ 1e-29
_FAR = 12.0  # a box wider than 24 s: its edges spread apart, erfc(12) ~ 1e-64 (box_entropy's closed form)
_MEAN_NODES = 5  # Gauss-Legendre nodes of box_mean where the erf difference would cancel ...
_NARROW = 0.05  # ... there: 4 |u| h below this ...
_WIDE = 0.1  # ... and h below this


class SourceError(ValueError):
    """A source parameter out of its range: ``param`` its key in the source (kind, x0, sd, ...), its
    ``value`` and ``allowed``, the message (a scene names the key path: scenes.<name>.source.<param>)."""

    def __init__(self, param: str, value, allowed: str):
        super().__init__(allowed)
        self.param, self.value, self.allowed = param, value, allowed


@dataclass(frozen=True)
class Param:
    """One parameter of a source kind: its key, meaning, unit, default (None: required) and the JSON
    schema of its value."""

    name: str
    meaning: str
    unit: str = "L"
    default: float | None = None
    schema: tuple = (("type", "number"),)


def _or(words) -> str:
    """'a, b or c'."""
    words = list(words)
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} or {words[-1]}"


class Source:
    """The initial plume of a scene, unit mass (a kind's class holds its parameters as fields).

    A kind sets KIND, PARAMS, SUMMARY (its parameters and their ranges, in words), POSITION (the
    parameter that places it, named when its position is out of range) and LEGACY (its record keeps
    LEGACY_FIELDS), checks its parameters in ``_argcheck`` and gives its centre, variance, half_width,
    positions, density and entropy."""

    KIND: ClassVar[str]
    PARAMS: ClassVar[tuple[Param, ...]]
    SUMMARY: ClassVar[str]
    POSITION: ClassVar[str]
    LEGACY: ClassVar[bool] = False

    def __post_init__(self):
        self._argcheck()

    # ---------------------------------------------------------------- parameters and their checks
    def _argcheck(self) -> None:
        """SourceError naming the first parameter out of its range (none by default)."""

    @classmethod
    def _speccheck(cls, values: dict) -> None:
        """SourceError for a config's value that the class takes but a scene refuses (none by default)."""

    @property
    def kind(self) -> str:
        return self.KIND

    @staticmethod
    def of(kind: str = "point", **params) -> Source:
        """The source of ``kind`` with ``params`` (a record's LEGACY_FIELDS at 0.0 that are not the
        kind's own are dropped); SourceError for an unknown kind or a parameter out of range."""
        if kind not in SOURCES:
            raise SourceError("kind", kind, f"source kind {kind!r}: one of {', '.join(SOURCES)}")
        cls = SOURCES[kind]
        own = {p.name for p in cls.PARAMS}
        if cls.LEGACY:
            params = {k: v for k, v in params.items() if k in own or not (k in LEGACY_FIELDS and v == 0.0)}
        return cls(**params)

    @staticmethod
    def from_spec(spec: Mapping) -> Source:
        """The source a config writes ({kind: ..., its parameters}); SourceError naming the first bad
        parameter: an unknown kind, a key not of the kind, a value not a finite number, a value out
        of its kind's range."""
        kind = spec.get("kind")
        if kind not in SOURCES:
            raise SourceError("kind", kind, f"one of {', '.join(SOURCES)}")
        cls = SOURCES[kind]
        names = [p.name for p in cls.PARAMS]
        extra = sorted(set(spec) - {"kind", *names})
        if extra:
            raise SourceError(extra[0], spec[extra[0]], f"not a key of a {kind} source")
        values = {}
        for p in cls.PARAMS:
            value = spec.get(p.name, p.default)
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)):
                raise SourceError(p.name, value, f"a finite number [{p.unit}]")
            values[p.name] = float(value)
        cls._speccheck(values)
        return cls(**values)

    def record(self) -> dict:
        """The source as a run's settings carry it and its identity digests it: kind and parameters
        (a LEGACY kind: all of LEGACY_FIELDS, 0.0 where not its own); ``Source.of(**record)`` reads it back."""
        own = {p.name: getattr(self, p.name) for p in self.PARAMS}
        if self.LEGACY:
            return {"kind": self.KIND, **{k: own.get(k, 0.0) for k in LEGACY_FIELDS}}
        return {"kind": self.KIND, **own}

    # ---------------------------------------------------------------- the source itself
    @property
    def centre(self) -> float:
        """The source's centre of mass [L]."""
        raise NotImplementedError

    @property
    def variance(self) -> float:
        """The source's own variance [L^2]."""
        raise NotImplementedError

    @property
    def half_width(self) -> float:
        """Half the source's extent where it holds all but ~1e-9 of its mass [L]."""
        raise NotImplementedError

    def positions(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n particle positions drawn from the source (random walkers' starting points) [L]."""
        raise NotImplementedError

    def _weights(self, x: np.ndarray, dV: float) -> np.ndarray:
        """Unnormalised mass of particles or nodes at x with spacing dV (all 0: the one nearest the centre)."""
        return np.zeros_like(x)

    def masses(self, x: np.ndarray, dV: float) -> np.ndarray:
        """Unit mass spread over particles or nodes at ``x`` with spacing dV by the source's density,
        normalised to sum 1; where the source is narrower than the spacing (a point), on the one
        nearest its centre."""
        x = np.asarray(x, dtype=np.float64)
        m = self._weights(x, dV)
        if not m.sum() > 0:  # a point, or a source narrower than the spacing
            m = np.zeros_like(x)
            m[np.argmin(np.abs(x - self.centre))] = 1.0
        return m / m.sum()

    def weighted_particles(self, n: int, omega: float, dV: float, rng: np.random.Generator):
        """MTPT's initial particles: n uniform on the domain omega around the centre, the source's
        mass on them by its density (masses) -> (positions, masses), unsorted."""
        lo, hi = self.centre - omega / 2.0, self.centre + omega / 2.0
        x = rng.uniform(lo, hi, n)
        return x, self.masses(x, dV)

    # ---------------------------------------------------------------- the exact solution at time t
    def plume(self, D: float, v: float, t: float) -> tuple[float, float, float]:
        """(centre, variance, spread) of the plume after time t: the source's centre plus v t, its
        variance plus the spread 2 D t [L, L^2, L^2]."""
        spread = 2.0 * D * max(t, 0.0)
        return self.centre + v * t, self.variance + spread, spread

    def density(self, x: np.ndarray, D: float, v: float, t: float) -> np.ndarray:
        """c(x, t) [1/L]."""
        raise NotImplementedError

    def entropy(self, D: float, t: float) -> float:
        """H_I = -integral c ln c dx after time t [nats, dV = 1]."""
        raise NotImplementedError

    def dilution(self, D: float, t: float) -> float:
        """E = exp(H_I) (Eq. 8) [L]."""
        h = self.entropy(D, t)
        return math.exp(h) if h > -math.inf else 0.0

    def _sample_weights(self, x: np.ndarray, D: float, v: float, t: float) -> np.ndarray:
        """c(x, t) up to a factor, for ``sampled`` (default: the density)."""
        return self.density(x, D, v, t)

    def sampled(self, x: np.ndarray, dV: float, D: float, v: float, t: float) -> np.ndarray:
        """c(x, t) sampled at sorted ``x`` and scaled to sum c dV = 1, as measures.analytic_sampled
        does for the paper's Gaussian; where the plume is narrower than the sampling (no sample sees
        it), all its mass goes on the sample nearest its centre."""
        x = np.asarray(x, dtype=np.float64)
        centre, variance, _ = self.plume(D, v, t)
        if variance > 0:
            g = self._sample_weights(x, D, v, t)
            total = g.sum()
            if total > 0:
                return g / (total * dV)
        g = np.zeros_like(x)
        g[np.argmin(np.abs(x - centre))] = 1.0
        return g / dV

    def sse_points(self, points, x, c, dV: float, D: float, v: float, t: float) -> float:
        """SSE at ``points`` of the model concentration c at sorted x against c(points, t)."""
        return M.sse(M.at_points(points, x, c), self.density(points, D, v, t))

    def warm_up(self) -> None:
        """Import and build what the exact solution is computed with before a run's timed steps."""


def _gaussian(x: np.ndarray, centre: float, variance: float) -> np.ndarray:
    """The normal density of mean ``centre`` and ``variance`` > 0 at x [1/L]."""
    z = x - centre
    return np.exp(-0.5 * z * z / variance) / math.sqrt(2.0 * math.pi * variance)


@dataclass(frozen=True)
class Point(Source):
    """A point (delta) at x0: the paper's source at x0 = 0."""

    KIND: ClassVar[str] = "point"
    PARAMS: ClassVar[tuple[Param, ...]] = (Param("x0", "position", default=0.0),)
    SUMMARY: ClassVar[str] = "a point (x0)"
    POSITION: ClassVar[str] = "x0"
    LEGACY: ClassVar[bool] = True

    x0: float = 0.0

    @property
    def centre(self) -> float:
        return self.x0

    @property
    def variance(self) -> float:
        return 0.0

    @property
    def half_width(self) -> float:
        return 0.0

    def positions(self, n: int, rng: np.random.Generator) -> np.ndarray:
        return np.full(n, float(self.x0))

    def weighted_particles(self, n: int, omega: float, dV: float, rng: np.random.Generator):
        """One unit mass on the point, stored first, and n - 1 zero-mass particles uniform on the
        domain omega around it."""
        lo, hi = self.centre - omega / 2.0, self.centre + omega / 2.0
        x = np.concatenate([[self.x0], rng.uniform(lo, hi, n - 1)])
        m = np.zeros(n)
        m[0] = 1.0
        return x, m

    def density(self, x, D, v, t):
        """The paper's Gaussian of variance 2 D t (Eq. 2), moved to x0 + v t: its very bits at x0 = v = 0
        (at t = 0 a delta, with no density: ValueError)."""
        x = np.asarray(x, dtype=np.float64)
        centre, variance, _ = self.plume(D, v, t)
        if not variance > 0:
            raise ValueError("a point source has no density at t = 0 (a delta)")
        return M.gaussian_density(x - centre, D, t)

    def entropy(self, D, t):
        """ln sqrt(4 pi e D t) (Eq. 14); -inf at t = 0."""
        return M.analytic_h_i(D, t)

    def dilution(self, D, t):
        return M.analytic_dilution(D, t)

    def sampled(self, x, dV, D, v, t):
        x = np.asarray(x, dtype=np.float64)
        return M.analytic_sampled(x - self.plume(D, v, t)[0], D, t, dV)

    def sse_points(self, points, x, c, dV, D, v, t):
        """measures.sse_points moved with the plume (its very bits for a point at rest); at t = 0
        against the delta on the model point nearest the centre."""
        move = self.plume(D, v, t)[0]
        if move == 0.0:
            return M.sse_points(points, x, c, D, t, dV)
        return M.sse_points(points - move, x - move, c, D, t, dV)


@dataclass(frozen=True)
class Gaussian(Source):
    """A Gaussian of mean x0 and standard deviation sd: at time t the Gaussian of variance sd^2 + 2 D t."""

    KIND: ClassVar[str] = "gaussian"
    PARAMS: ClassVar[tuple[Param, ...]] = (
        Param("x0", "mean", default=0.0),
        Param("sd", "standard deviation", schema=(("type", "number"), ("exclusiveMinimum", 0))),
    )
    SUMMARY: ClassVar[str] = "a Gaussian (x0, sd > 0)"
    POSITION: ClassVar[str] = "x0"
    LEGACY: ClassVar[bool] = True

    x0: float = 0.0
    sd: float = 0.0

    def _argcheck(self):
        if not (self.sd > 0 and math.isfinite(self.sd)):
            raise SourceError("sd", self.sd, f"a Gaussian source needs sd > 0 and finite, got {self.sd!r}")

    @classmethod
    def _speccheck(cls, values):
        if 0 < values["sd"] < MIN_SD:
            raise SourceError(
                "sd",
                values["sd"],
                f"a number >= {MIN_SD:.3g} [L]: its variance sd^2 a normal float (below, sd^2 rounds to 0 and the "
                "Gaussian is a delta); for a narrower source write {kind: point, x0}",
            )

    @property
    def centre(self) -> float:
        return self.x0

    @property
    def variance(self) -> float:
        return self.sd * self.sd

    @property
    def half_width(self) -> float:
        """6 sd."""
        return 6.0 * self.sd

    def positions(self, n, rng):
        return self.x0 + self.sd * rng.standard_normal(n)

    def _weights(self, x, dV):
        z = (x - self.x0) / self.sd
        return np.exp(-0.5 * z * z)

    def density(self, x, D, v, t):
        x = np.asarray(x, dtype=np.float64)
        centre, variance, _ = self.plume(D, v, t)
        if not variance > 0:
            raise ValueError("a point source has no density at t = 0 (a delta)")
        return _gaussian(x, centre, variance)

    def entropy(self, D, t):
        """ln sqrt(2 pi e variance) (Eq. 14)."""
        variance = self.plume(D, 0.0, t)[1]
        return 0.5 * math.log(2.0 * math.pi * math.e * variance) if variance > 0 else -math.inf

    def _sample_weights(self, x, D, v, t):
        """In log space: a plume narrower than the spacing keeps its peak."""
        centre, variance, _ = self.plume(D, v, t)
        z = x - centre
        logg = -0.5 * z * z / variance
        return np.exp(logg - logg.max())


@dataclass(frozen=True)
class Box(Source):
    """Uniform concentration on [a, b]: at time t the Gaussian's mean over the box (box_mean)."""

    KIND: ClassVar[str] = "box"
    PARAMS: ClassVar[tuple[Param, ...]] = (Param("a", "left end"), Param("b", "right end"))
    SUMMARY: ClassVar[str] = "a box (a < b)"
    POSITION: ClassVar[str] = "a"
    LEGACY: ClassVar[bool] = True

    a: float = 0.0
    b: float = 0.0

    def _argcheck(self):
        if not (self.b > self.a and math.isfinite(self.b - self.a)):
            raise SourceError("b", self.b, f"a box source needs a < b, both finite, got [{self.a!r}, {self.b!r}]")

    @property
    def centre(self) -> float:
        return 0.5 * (self.a + self.b)

    @property
    def variance(self) -> float:
        """(b - a)^2 / 12."""
        return (self.b - self.a) ** 2 / 12.0

    @property
    def half_width(self) -> float:
        """(b - a) / 2."""
        return 0.5 * (self.b - self.a)

    def positions(self, n, rng):
        return rng.uniform(self.a, self.b, n)

    def _weights(self, x, dV):
        """The box's overlap with each cell [x - dV/2, x + dV/2] (a box narrower than dV: on the one
        nearest its centre)."""
        return np.clip(np.minimum(x + 0.5 * dV, self.b) - np.maximum(x - 0.5 * dV, self.a), 0.0, None)

    def density(self, x, D, v, t):
        x = np.asarray(x, dtype=np.float64)
        centre, _, spread = self.plume(D, v, t)
        if spread == 0.0:
            shift = v * t
            return np.where((x >= self.a + shift) & (x <= self.b + shift), 1.0 / (self.b - self.a), 0.0)
        w = math.sqrt(2.0 * spread)  # sqrt(4 D t)
        return box_mean((x - centre) / w, 0.5 * (self.b - self.a) / w) / w

    def entropy(self, D, t):
        return box_entropy(self.b - self.a, D * max(t, 0.0))

    def _sample_weights(self, x, D, v, t):
        """At t = 0 its indicator: 1 / width may overflow."""
        spread = self.plume(D, v, t)[2]
        return self.density(x, D, v, t) if spread > 0 else self.density(x, D, v, t) > 0

    def warm_up(self):
        """box_entropy's rules and scipy.special (~30 ms once per process)."""
        _edge_entropy()
        for panels in range(1, math.ceil(2.0 * _TAIL_WIDTHS / _PANEL) + 1):  # every span up to 16 s
            _unit_rule(panels)
        box_mean(np.zeros(1), 1.0)


@dataclass(frozen=True)
class TwoGaussians(Source):
    """A sum of two Gaussians: mass ``fraction`` in the one of mean x1 and standard deviation sd1, the
    rest in the one of mean x2 and sd2 (a plume with two lobes, or a tail). Each lobe spreads as a
    Gaussian source does, to variance sd^2 + 2 D t; the entropy of their sum has no closed form and is
    computed by Gauss-Legendre quadrature of -c ln c (``entropy``)."""

    KIND: ClassVar[str] = "two_gaussians"
    PARAMS: ClassVar[tuple[Param, ...]] = (
        Param("x1", "first lobe's mean"),
        Param("sd1", "first lobe's standard deviation", schema=(("type", "number"), ("exclusiveMinimum", 0))),
        Param("x2", "second lobe's mean"),
        Param("sd2", "second lobe's standard deviation", schema=(("type", "number"), ("exclusiveMinimum", 0))),
        Param(
            "fraction",
            "the first lobe's share of the unit mass",
            unit="-",
            schema=(("type", "number"), ("exclusiveMinimum", 0), ("exclusiveMaximum", 1)),
        ),
    )
    SUMMARY: ClassVar[str] = "two Gaussians (x1, sd1 > 0, x2, sd2 > 0, the first's mass 0 < fraction < 1)"
    POSITION: ClassVar[str] = "x1"
    _STEP: ClassVar[float] = 0.25  # entropy's panels: at most this many of a lobe's sd wide ...
    _REACH: ClassVar[float] = 12.0  # ... out to this many sd each side of each lobe (exp(-72) beyond)

    x1: float = 0.0
    sd1: float = 0.0
    x2: float = 0.0
    sd2: float = 0.0
    fraction: float = 0.5

    def _argcheck(self):
        for name in ("sd1", "sd2"):
            sd = getattr(self, name)
            if not (sd > 0 and math.isfinite(sd)):
                raise SourceError(name, sd, f"a two_gaussians source needs {name} > 0 and finite, got {sd!r}")
        if not (0.0 < self.fraction < 1.0):
            raise SourceError(
                "fraction",
                self.fraction,
                f"a number in (0, 1): the first lobe's share of the mass, got {self.fraction!r}",
            )

    @classmethod
    def _speccheck(cls, values):
        for name in ("sd1", "sd2"):
            if 0 < values[name] < MIN_SD:
                raise SourceError(
                    name,
                    values[name],
                    f"a number >= {MIN_SD:.3g} [L]: its variance {name}^2 a normal float (below, it rounds to 0)",
                )

    def _lobes(self, D: float, v: float, t: float):
        """((weight, mean, variance) of each lobe after time t)."""
        spread = 2.0 * D * max(t, 0.0)
        f = self.fraction
        return ((f, self.x1 + v * t, self.sd1**2 + spread), (1.0 - f, self.x2 + v * t, self.sd2**2 + spread))

    @property
    def centre(self) -> float:
        """fraction x1 + (1 - fraction) x2."""
        return self.fraction * self.x1 + (1.0 - self.fraction) * self.x2

    @property
    def variance(self) -> float:
        """The lobes' variances and their means' spread about the centre, weighted by their masses."""
        c = self.centre
        return sum(w * (var + (m - c) ** 2) for w, m, var in self._lobes(0.0, 0.0, 0.0))

    @property
    def half_width(self) -> float:
        """From the centre to the farther lobe's mean + 6 of its sd."""
        c = self.centre
        return max(abs(self.x1 - c) + 6.0 * self.sd1, abs(self.x2 - c) + 6.0 * self.sd2)

    def positions(self, n, rng):
        """Each particle in the first lobe with probability fraction, then drawn from its lobe."""
        first = rng.random(n) < self.fraction
        z = rng.standard_normal(n)
        return np.where(first, self.x1 + self.sd1 * z, self.x2 + self.sd2 * z)

    def _weights(self, x, dV):
        return self.density(x, 0.0, 0.0, 0.0)

    def density(self, x, D, v, t):
        x = np.asarray(x, dtype=np.float64)
        return sum(w * _gaussian(x, m, var) for w, m, var in self._lobes(D, v, t))

    def entropy(self, D, t):
        """-integral c ln c dx by 16-node Gauss-Legendre panels that break every _STEP sd of each lobe
        out to _REACH sd, so that each lobe, however narrow or far from the other, is resolved."""
        lobes = self._lobes(D, 0.0, t)
        k = np.arange(-self._REACH, self._REACH + self._STEP / 2, self._STEP)
        edges = np.unique(np.concatenate([m + math.sqrt(var) * k for _, m, var in lobes]))
        nodes, weights = np.polynomial.legendre.leggauss(_GL_NODES)
        mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * (edges[1:] - edges[:-1])
        x = (mid[:, None] + half[:, None] * nodes).ravel()
        c = self.density(x, D, 0.0, t)
        safe = np.where(c > 0, c, 1.0)
        return float(np.dot((half[:, None] * weights).ravel(), -c * np.log(safe)))


# The kinds, each once, in the order the schema and the messages list them.
SOURCES: dict[str, type[Source]] = {cls.KIND: cls for cls in (Point, Gaussian, Box, TwoGaussians)}


def source_shape() -> dict:
    """The JSON schema of a config's source: kind one of SOURCES, each kind's parameters."""
    properties: dict = {"kind": {"type": "string", "enum": list(SOURCES)}}
    for cls in SOURCES.values():
        for p in cls.PARAMS:
            properties.setdefault(p.name, dict(p.schema))
    return {"type": "object", "additionalProperties": False, "required": ["kind"], "properties": properties}


def source_forms() -> str:
    """'{kind: point, x0}, {kind: gaussian, x0, sd} or ...': what a config writes for each kind."""
    return _or(f"{{kind: {k}, {', '.join(p.name for p in cls.PARAMS)}}}" for k, cls in SOURCES.items())


def source_ranges() -> str:
    """'a point (x0), a Gaussian (x0, sd > 0) or ...': each kind's parameters and ranges, in words."""
    return _or(cls.SUMMARY for cls in SOURCES.values())


def source_names() -> str:
    """'point, gaussian or box'."""
    return _or(SOURCES)


# ------------------------------------------------------------------------ the box's numerics
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
