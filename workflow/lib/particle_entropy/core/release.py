"""The exact plume of a continuous release (issue 53, point 2): a source of core/sources.py (1-D) or
core/sources2d.py (2-D) that lets out mass at the rate q per unit time from ``start`` until ``end``
(open: until the observation), in uniform flow v with uniform dispersion D on the infinite line or
plane. The equation is linear, so the plume at time t sums the instantaneous plumes of unit mass
(core/reference.py, core/reference2d.py), G(x, s) after an age s = t - tau, over the release:

    c(x, t) = q integral G(x, s) ds over s in [s_lo, s_hi],   s_lo = (t - end)^+,   s_hi = t - start,

and holds the mass M(t) = q (s_hi - s_lo). G is the kind's own exact density, so every source kind of
either dimension serves.

The age integral (``age_rule``) is Gauss-Legendre quadrature, 10 nodes a panel, on panels graded
geometrically toward the youngest age s_lo (each ends at most 3 times as far from s_lo as it starts:
equal panels in ln(s - s_lo)) down to 1e-12 of the span, 1e-20 for a point source, and toward the
oldest age down to 1e-6 of it. Near s_lo, G tends to the source: for a point source, at a point r
away, it is exp(-r^2 / (4 D s)) / s^(d/2), a step in ln s at s ~ r^2 / (4 D) of the same shape on
every scale, which equal panels in ln s resolve for every r alike (down to r ~ 1e-10 of the plume's
width); at r = 0 it is s^(-1/2) in 1-D, made smooth by s = f u^2 on the first panel [0, f], and 1/s
in 2-D (c = inf there). Near s_hi, G of a point beyond the plume's front rises steeply to its oldest
value. In between, a fast flow makes G a narrow bump in s at the age r / |v| of the water at the
point, sqrt(s / (2 kappa)) wide, kappa = v^T D^-1 v / 4: panels are at most 2 sqrt(s / kappa) wide.
Against the closed forms (tests/test_release_reference.py) the density is within 1.3e-11 relative in
1-D (continuous point source, Pe from 0 to 1e4, at the source and in tails 1e-80 below the peak; box
and Gaussian sources against quadrature of the closed form, 3e-13) and within 3e-11 in 2-D (Wilson
and Miller, along, across and 1e-8 from the source).

The spatial integrals (the mass, ``total``, and H_I = -integral p ln p of p = c / M) use composite
Gauss-Legendre rules over the plume's span (the source carried to every age, plus 10 sd of its
spread). Each axis is split where the youngest plume (the source carried by v s_lo) jumps: a point's
position, a box's edges; and graded toward there from 1e-6 of the plume's width on, panels at most 3
times their distance from there and at most 2 sqrt(2 lambda a) wide, a the age of the water there
(distance / |v_i|) and lambda D's smallest eigenvalue: that resolves the kink at a source, the log
singularity of a 2-D point source (c ~ ln(1/r), integrable in p ln p) and a fast flow's front. In 1-D
each panel is then halved until its integrals of p and -p ln p settle to 1e-13 (a kind's own fine
structure, e.g. a narrow lobe of two_gaussians, is found so). In 2-D the rule is a tensor product
along x and y (along D's principal axes for a point source), where each age's plume is a product of
its two marginals and the sum over ages a matrix product; a Gaussian in an oblique flow is summed
point by point (seconds) and a box in an oblique flow is refused (hours). The masses are within
1e-14 of M(t); H_I within 4e-15 nats of scipy's quad of the 1-D closed form and within 4e-14 of a
radial quadrature of the 2-D point source at v = 0, whose density is q E1(r^2 / (4 D t)) / (4 pi D).

Closed forms of the continuous point source: ``point_release`` (1-D, any v, with erfc, derived in its
docstring), ``steady_point_release`` (1-D, t -> infinity), ``point_release_2d`` (Wilson and Miller
1978, through Hantush's leaky-aquifer well function ``hantush_w``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .reference import Reference
from .reference2d import Reference2D
from .sources import Source, SourceError
from .sources2d import Source2D

_NODES = 10  # Gauss-Legendre nodes per panel, in age and in space
_RATIO = 3.0  # a graded panel ends at most 3 times as far from its origin as it starts
_AGE_FLOOR = 1e-12  # the age rule grades down to this fraction of the release's span of ages ...
_POINT_FLOOR = 1e-20  # ... (of a point source, whose G ~ s^-d/2 near it: c near the point needs it) ...
_AGE_TOP = 1e-6  # ... and toward the oldest age down to this fraction (a far point's G rises to it) ...
_AGE_CAP = 2.0  # ... with panels at most 2 sqrt(s / kappa) wide (a fast flow's bump in s)
_SPACE_FLOOR = 1e-6  # the spatial rule grades down to this fraction of the plume's width ...
_SPACE_CAP = 2.0  # ... with panels at most 2 sqrt(2 lambda a) wide (a the water's age there)
_TOL = 1e-13  # the 1-D rule halves a panel until its integrals of p and -p ln p change by less ...
_HALVINGS = 30  # ... or it has been halved this many times
_REACH = 10.0  # the span: 10 sd beyond the source carried to every age (exp(-50) ~ 2e-22 beyond)
_ZERO = 40.0  # beyond 40 sd of an age's plume its density is 0 in floats (exp(-800), ndtr(-40)): skipped


class ReleaseError(SourceError):
    """A release parameter out of its range: ``param`` the field (rate, start, end) or the observation
    time t, its ``value`` and ``allowed``, the message."""


_KEYS = {"start": "from", "end": "until"}  # a config's key of each field it renames


def _finite(value) -> bool:
    """Whether ``value`` is a finite real number (not a bool)."""
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    return ok and math.isfinite(value)


@dataclass(frozen=True)
class Release:
    """Mass ``rate`` per unit time let out from ``start`` until ``end`` (None: until the observation) [M/T, T].

    A config writes {rate: q, from: t0, until: t1} (``from_spec``)."""

    rate: float
    start: float = 0.0
    end: float | None = None

    def __post_init__(self):
        if not (_finite(self.rate) and self.rate > 0):
            raise ReleaseError("rate", self.rate, f"rate: a number > 0 and finite [M/T], got {self.rate!r}")
        if not _finite(self.start):
            raise ReleaseError("start", self.start, f"start: a finite time [T], got {self.start!r}")
        if self.end is not None and not (_finite(self.end) and self.end > self.start):
            raise ReleaseError(
                "end",
                self.end,
                f"end: a finite time after the release's start {self.start!r} [T], or None (open), got {self.end!r}",
            )

    @staticmethod
    def from_spec(spec: Mapping) -> Release:
        """The release a config writes: {rate: q, from: t0 (default 0), until: t1 (default open)}."""
        extra = sorted(set(spec) - {"rate", "from", "until"})
        if extra:
            raise ReleaseError(extra[0], spec[extra[0]], f"{extra[0]}: not a key of a release (rate, from, until)")
        try:
            return Release(spec.get("rate"), spec.get("from", 0.0), spec.get("until"))
        except ReleaseError as error:  # named by the config's keys
            key = _KEYS.get(error.param, error.param)
            raise ReleaseError(key, error.value, f"{key}{error.allowed.removeprefix(error.param)}") from None

    def check(self, t: float) -> None:
        """ReleaseError unless the observation time t is finite and after ``start``."""
        if not (_finite(t) and t > self.start):
            raise ReleaseError("t", t, f"t: a finite time > the release's start {self.start!r} [T], got {t!r}")

    def ages(self, t: float) -> tuple[float, float]:
        """(s_lo, s_hi): the youngest and oldest age t - tau of the mass released by t [T]."""
        self.check(t)
        return (0.0 if self.end is None else max(t - self.end, 0.0)), t - self.start

    def mass(self, t: float) -> float:
        """M(t) = q (min(end, t) - start)^+ [M] (0 before the start)."""
        stop = t if self.end is None else min(self.end, t)
        return self.rate * max(stop - self.start, 0.0)


# ------------------------------------------------------------------------ quadrature rules
@functools.cache
def _unit_panel() -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [0, 1]."""
    nodes, weights = np.polynomial.legendre.leggauss(_NODES)
    return 0.5 * (nodes + 1.0), 0.5 * weights


def _panels(breaks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of composite Gauss-Legendre quadrature on the panels between sorted ``breaks``."""
    nodes, weights = _unit_panel()
    lo, width = breaks[:-1, None], np.diff(breaks)[:, None]
    return (lo + width * nodes).ravel(), (width * weights).ravel()


def _graded(length: float, first: float, cap) -> np.ndarray:
    """Breaks 0 < first < ... < length, each panel ending at most _RATIO times as far from 0 as it starts
    and at most cap(start) wide (cap: a function of the distance from 0)."""
    breaks = [0.0]
    w = min(first, length)
    while w < length:
        breaks.append(w)
        w = min(_RATIO * w, w + cap(w))
    breaks.append(length)
    return np.array(breaks)


def age_rule(s_lo: float, s_hi: float, kappa: float, floor: float = _AGE_FLOOR) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights in the age s over [s_lo, s_hi]: Gauss-Legendre panels graded geometrically
    toward s_lo down to ``floor`` of the span (the first, [s_lo, s_lo + f], in s = s_lo + f u^2) and
    toward s_hi down to _AGE_TOP of it, at most _AGE_CAP sqrt(s / kappa) wide, kappa = v^T D^-1 v / 4
    [1/T] (0: no flow, no cap)."""
    span = s_hi - s_lo
    if not span > 0:
        raise ValueError(f"an age span needs s_hi > s_lo, got [{s_lo!r}, {s_hi!r}]")
    if kappa > 0:
        young = lambda w: _AGE_CAP * math.sqrt((s_lo + w) / kappa)  # noqa: E731
        old = lambda w: _AGE_CAP * math.sqrt((s_lo + 0.5 * span) / kappa)  # noqa: E731
    else:
        young = old = lambda w: math.inf  # noqa: E731
    lower = _graded(0.5 * span, floor * span, young)
    upper = span - _graded(0.5 * span, _AGE_TOP * span, old)
    ages, weights = _panels(np.unique(np.concatenate([lower, upper])))
    nodes, unit = _unit_panel()  # the first panel [0, f] in s = f u^2: G ~ s^-1/2 there becomes smooth
    f = lower[1]
    ages[:_NODES], weights[:_NODES] = f * nodes * nodes, 2.0 * f * nodes * unit
    return s_lo + ages, weights


def _axis_breaks(lo: float, hi: float, edges, finest: float, speed: float, lam: float, s_lo: float, s_hi: float):
    """Panel breaks over [lo, hi] on one axis: split at ``edges`` and graded toward each from ``finest``
    on, panels at most _SPACE_CAP sqrt(2 lam a) wide, a = distance / |speed| clipped to [s_lo, s_hi]
    (s_hi where speed = 0)."""

    def cap(w):
        age = s_hi if speed == 0 else min(max(w / abs(speed), s_lo), s_hi)
        return _SPACE_CAP * math.sqrt(2.0 * lam * age) if age > 0 else 0.0

    edges = sorted({e for e in edges if lo < e < hi})
    ends = [lo, *edges, hi]
    pieces = []
    for i, (a, b) in enumerate(zip(ends[:-1], ends[1:])):
        from_a, from_b = i > 0, i < len(ends) - 2  # a, b an edge
        if not (from_a or from_b):  # no edge on the span: equal panels at the widest cap
            n = max(1, math.ceil((b - a) / max(cap(b - a), 1e-300)))
            pieces.append(np.linspace(a, b, n + 1))
            continue
        if from_a and from_b:
            mid = 0.5 * (a + b)
            pieces += [a + _graded(mid - a, finest, cap), b - _graded(b - mid, finest, cap)]
        elif from_a:
            pieces.append(a + _graded(b - a, finest, cap))
        else:
            pieces.append(b - _graded(b - a, finest, cap))
    return np.unique(np.concatenate(pieces))


def _halved(breaks: np.ndarray, density, mass: float):
    """Nodes, weights and c of composite Gauss-Legendre quadrature on the panels between ``breaks``,
    each halved until its integrals of p = c / mass and of -p ln p equal its halves' sums to _TOL (at
    most _HALVINGS times): an adaptive rule for a source whose fine structure no edge marks."""
    from scipy.special import entr

    nodes, unit = _unit_panel()

    def integrals(lo, width):
        x = lo[:, None] + width[:, None] * nodes
        w = width[:, None] * unit
        p = density(x.ravel()).reshape(x.shape) / mass
        return x, w, p, np.stack([(w * p).sum(axis=1), (w * entr(p)).sum(axis=1)], axis=1)

    lo, width = breaks[:-1], np.diff(breaks)
    whole = integrals(lo, width)[3]
    kept = []
    for rounds in range(_HALVINGS, -1, -1):
        half = 0.5 * width
        x, w, p, parts = integrals(np.concatenate([lo, lo + half]), np.concatenate([half, half]))
        n = len(lo)
        ok = np.abs(parts[:n] + parts[n:] - whole).max(axis=1) <= _TOL
        if rounds == 0:
            ok[:] = True
        both = np.concatenate([ok, ok])
        kept.append((x[both].ravel(), w[both].ravel(), p[both].ravel()))
        if ok.all():
            break
        lo = np.concatenate([lo[~ok], (lo + half)[~ok]])
        width = np.concatenate([half[~ok], half[~ok]])
        whole = np.concatenate([parts[:n][~ok], parts[n:][~ok]])
    x, w, p = (np.concatenate(a) for a in zip(*kept))
    return x, w, mass * p


def _span(centre: float, speed: float, var0: float, half: float, Dii: float, s_lo: float, s_hi: float):
    """[lo, hi] on one axis covering the plume of every age in [s_lo, s_hi]: the source's centre carried
    by v s, its half extent ``half`` and _REACH sd of its variance plus 2 D_ii s beyond."""
    s = s_lo + (s_hi - s_lo) * np.linspace(0.0, 1.0, 1025) ** 2
    reach = half + _REACH * np.sqrt(var0 + 2.0 * Dii * s)
    return float(np.min(centre + speed * s - reach)), float(np.max(centre + speed * s + reach))


def _entropy(c: np.ndarray, weights: np.ndarray, mass: float) -> float:
    """-integral p ln p of p = c / mass by the rule's ``weights`` [nats]."""
    from scipy.special import entr

    return float(weights @ entr(c / mass))


# ------------------------------------------------------------------------ the references
class _Released:
    """What both references read off their release at their time t: the ages and the mass."""

    @property
    def ages(self) -> tuple[float, float]:
        """(s_lo, s_hi): the ages of the mass released by t [T]."""
        return self.release.ages(self.t)

    @property
    def mass(self) -> float:
        """M(t) = q (min(t1, t) - t0) [M]."""
        return self.release.mass(self.t)


@dataclass(frozen=True)
class ReleaseReference(_Released):
    """The exact concentration at time t of ``release`` from ``source`` under uniform velocity v and
    dispersion D on the line."""

    source: Source
    release: Release
    D: float
    v: float
    t: float

    def __post_init__(self):
        if not (_finite(self.D) and self.D > 0):
            raise ValueError(f"D: a number > 0 and finite [L^2/T], got {self.D!r}")
        if not _finite(self.v):
            raise ValueError(f"v: a finite velocity [L/T], got {self.v!r}")
        self.release.check(self.t)

    def age_rule(self) -> tuple[np.ndarray, np.ndarray]:
        """The ages and weights of the release's age integral (age_rule; kappa = v^2 / (4 D), graded
        down to _POINT_FLOOR for a point source) [T]."""
        floor = _POINT_FLOOR if self.source.variance == 0 else _AGE_FLOOR
        return age_rule(*self.ages, self.v * self.v / (4.0 * self.D), floor)

    def density(self, x) -> np.ndarray:
        """c(x, t) = q integral G(x, s) ds over the ages (age_rule), G the Reference's density [M/L]."""
        x = np.asarray(x, dtype=np.float64)
        c = np.zeros(x.shape)
        for s, w in zip(*self.age_rule()):
            c += w * Reference(self.source, self.D, self.v, float(s)).density(x)
        return self.release.rate * c

    @functools.cached_property
    def _on_rule(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(nodes, weights, c there) of the adaptive spatial rule (computed once)."""
        s_lo, s_hi = self.ages
        source = self.source
        lo, hi = _span(source.centre, self.v, source.variance, source.half_width, self.D, s_lo, s_hi)
        edges = [source.centre + sign * source.half_width + self.v * s_lo for sign in (-1.0, 1.0)]
        width = math.sqrt(source.variance + 2.0 * self.D * s_hi)
        breaks = _axis_breaks(lo, hi, edges, _SPACE_FLOOR * width, self.v, self.D, s_lo, s_hi)
        return _halved(breaks, self.density, self.mass)

    def spatial_rule(self) -> tuple[np.ndarray, np.ndarray]:
        """Nodes and weights over the plume's span: panels graded toward the youngest plume's edges (the
        source's extent, centre -+ half_width, carried by v s_lo: a point's position, a box's edges), each
        halved until the integrals of p and -p ln p on it settle (an adaptive rule: a kind's own fine
        structure, e.g. a narrow lobe, is found by it) [L]."""
        return self._on_rule[:2]

    def density_on_rule(self) -> np.ndarray:
        """c at spatial_rule's nodes [M/L]."""
        return self._on_rule[2]

    def total(self) -> float:
        """integral c dx by the spatial rule: M(t) to its accuracy [M]."""
        _, w, c = self._on_rule
        return float(w @ c)

    def entropy(self) -> float:
        """H_I = -integral p ln p dx of p = c / M [nats, dV = 1] (spatial_rule)."""
        _, w, c = self._on_rule
        return _entropy(c, w, self.mass)

    def dilution(self) -> float:
        """E = exp(H_I) [L]."""
        return math.exp(self.entropy())


@dataclass(frozen=True, eq=False)
class ReleaseReference2D(_Released):
    """The exact concentration at time t of ``release`` from ``source`` under uniform velocity v (2,)
    and dispersion tensor D (2, 2), symmetric positive definite, on the plane."""

    source: Source2D
    release: Release
    D: np.ndarray
    v: np.ndarray
    t: float

    def __post_init__(self):
        checked = Reference2D(self.source, self.D, self.v, 0.0)  # D and v checked and frozen there
        object.__setattr__(self, "D", checked.D)
        object.__setattr__(self, "v", checked.v)
        self.release.check(self.t)

    @property
    def kappa(self) -> float:
        """v^T D^-1 v / 4 [1/T]: a fast flow's bump in age is sqrt(s / (2 kappa)) wide."""
        return float(self.v @ np.linalg.solve(self.D, self.v)) / 4.0

    def age_rule(self) -> tuple[np.ndarray, np.ndarray]:
        """The ages and weights of the release's age integral (age_rule, graded down to _POINT_FLOOR for
        a point source) [T]."""
        floor = _POINT_FLOOR if not np.any(self.source.covariance) else _AGE_FLOOR
        return age_rule(*self.ages, self.kappa, floor)

    def _reach(self, plume: Reference2D, sds: float = _ZERO) -> np.ndarray:
        """How far from its centre an age's plume reaches along x and y: the source's half extent
        (sqrt(3 var)) and ``sds`` marginal sd (_ZERO: where its density is 0 in floats) [L]."""
        return np.sqrt(3.0 * np.diag(self.source.covariance)) + sds * np.sqrt(np.diag(plume.covariance))

    def density(self, points) -> np.ndarray:
        """c(p, t) = q integral G(p, s) ds over the ages (age_rule), G the Reference2D's density, at
        points (M, 2) [M/L^2]; inf on a point source still releasing (c ~ ln(1/r) near it). Each age's
        plume is evaluated only at the points it reaches (``_reach``): a young plume, at few of them."""
        p = np.atleast_2d(np.asarray(points, dtype=np.float64))
        c = np.zeros(len(p))
        for s, w in zip(*self.age_rule()):
            plume = Reference2D(self.source, self.D, self.v, float(s))
            near = np.all(np.abs(p - plume.centre) <= self._reach(plume), axis=1)
            if near.any():
                c[near] += w * plume.density(p[near])
        c *= self.release.rate
        if self.ages[0] == 0.0 and not np.any(self.source.covariance):  # a point, still releasing
            c[np.all(p == self.source.centre, axis=1)] = math.inf
        return c

    @functools.cached_property
    def _frame(self) -> np.ndarray:
        """The tensor rule's axes, the columns of a rotation: x and y, or D's principal axes for a point
        source in an oblique flow (along them its plume is a product of two marginals)."""
        if self.D[0, 1] != 0.0 and not np.any(self.source.covariance):
            return np.linalg.eigh(self.D)[1]
        return np.eye(2)

    def _jumps(self, axis: int, at: float, step: float) -> bool:
        """Whether the source's marginal along x (axis 0) or y (1) jumps at ``at``: its masses in the
        cells of width ``step`` either side differ by more than a factor 2 (a box's edge; not a
        Gaussian's smooth flank)."""
        centres = np.array([at - 0.5 * step, at + 0.5 * step])
        across = np.array([self.source.centre[1 - axis]])
        big = 1e6 * (1.0 + math.sqrt(float(np.trace(self.source.covariance))))
        pair = (centres, across, step, big) if axis == 0 else (across, centres, big, step)
        m = self.source.cell_masses(*pair).ravel()
        return bool(m.min() < 0.5 * m.max())

    def _has_edges(self, i: int) -> bool:
        """Whether the source jumps along the rule's axis i: a point (no variance: D's axes hold only a
        point) or a box (``_jumps`` at sqrt(3 var) from its centre), not a Gaussian."""
        e = self._frame[:, i]
        var0 = float(e @ self.source.covariance @ e)
        if var0 == 0.0:
            return True
        half = math.sqrt(3.0 * var0)
        return self._jumps(i, float(self.source.centre[i]) + half, 1e-9 * half)

    def _axis(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Nodes and weights along the rule's axis i: its span, graded toward the youngest plume's edges
        where the source jumps (a point's position; a box's edges, a side of variance var being
        sqrt(3 var) from the centre) down to _SPACE_FLOOR of the plume's width, else toward its centre
        down to a quarter of its sd; never finer than a quarter of the dispersion's sqrt(2 lambda s_lo)."""
        s_lo, s_hi = self.ages
        e = self._frame[:, i]
        centre, speed = float(e @ self.source.centre), float(e @ self.v)
        var0, Dii = float(e @ self.source.covariance @ e), float(e @ self.D @ e)
        lam = float(np.linalg.eigvalsh(self.D)[0])
        half = math.sqrt(3.0 * var0)
        lo, hi = _span(centre, speed, var0, half, Dii, s_lo, s_hi)
        width = math.sqrt(var0 + 2.0 * Dii * s_hi)
        carried = centre + speed * s_lo
        if self._has_edges(i):
            origins, finest = [carried - half, carried + half], _SPACE_FLOOR * width
        else:
            origins, finest = [carried], 0.25 * math.sqrt(var0)
        finest = max(finest, 0.25 * math.sqrt(2.0 * lam * s_lo))
        return _panels(_axis_breaks(lo, hi, origins, finest, speed, lam, s_lo, s_hi))

    @functools.cached_property
    def _on_grid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, wx, wy, c on the grid x by y) of the tensor rule, x and y along its axes (``_frame``),
        computed once.

        Where D is diagonal along the axes every kind's plume is the product of its two marginals,
        G(x, y) = G(x, y0) G(x0, y) / G(x0, y0) with (x0, y0) its centre, so each age costs two lines of
        the grid and the sum over ages is one matrix product. Otherwise (a Gaussian or a box in an
        oblique flow) each age's plume is added only on the part of the grid within _REACH marginal sd
        (``_reach``: beyond, less than 1e-22 of its mass)."""
        (x, wx), (y, wy) = self._axis(0), self._axis(1)
        R = self._frame
        ages, weights = self.age_rule()
        if self.D[0, 1] == 0.0 or not np.any(self.source.covariance):
            gx, gy = np.empty((len(ages), len(x))), np.empty((len(ages), len(y)))
            for k, (s, w) in enumerate(zip(ages, weights)):
                plume = Reference2D(self.source, self.D, self.v, float(s))
                x0, y0 = R.T @ plume.centre
                lines = [np.stack([x, np.full_like(x, y0)], 1), np.stack([np.full_like(y, x0), y], 1), [[x0, y0]]]
                g = plume.density(np.concatenate(lines) @ R.T)
                gx[k], gy[k] = g[: len(x)] * (w / g[-1]), g[len(x) : -1]
            return x, y, wx, wy, self.release.rate * (gx.T @ gy)
        if self._has_edges(0) or self._has_edges(1):
            raise ValueError(
                "H_I of a box in an oblique flow: Reference2D's density of it is a quadrature per point and age "
                "(~70 us), and the tensor rule needs ~1e8 of them (hours); give D diagonal (a flow along x or y) "
                "or measure the density at points"
            )
        c = np.zeros((len(x), len(y)))
        for s, w in zip(ages, weights):
            plume = Reference2D(self.source, self.D, self.v, float(s))
            (x0, y0), reach = plume.centre, self._reach(plume, _REACH)
            i0, i1 = np.searchsorted(x, [x0 - reach[0], x0 + reach[0]])
            j0, j1 = np.searchsorted(y, [y0 - reach[1], y0 + reach[1]])
            if i1 > i0 and j1 > j0:
                X, Y = np.meshgrid(x[i0:i1], y[j0:j1], indexing="ij")
                g = plume.density(np.stack([X.ravel(), Y.ravel()], axis=1))
                c[i0:i1, j0:j1] += w * g.reshape(X.shape)
        return x, y, wx, wy, self.release.rate * c

    def spatial_rule(self) -> tuple[np.ndarray, np.ndarray]:
        """Nodes (M, 2) and weights (M,) of the tensor rule over the plume's span (``_axis``) [L^2]."""
        x, y, wx, wy, _ = self._on_grid
        X, Y = np.meshgrid(x, y, indexing="ij")
        return np.stack([X.ravel(), Y.ravel()], axis=1) @ self._frame.T, np.outer(wx, wy).ravel()

    def density_on_rule(self) -> np.ndarray:
        """c at spatial_rule's nodes, summed as a grid (``_on_grid``) [M/L^2]."""
        return self._on_grid[4].ravel()

    def total(self) -> float:
        """integral c dA by the tensor rule: M(t) to its accuracy [M]."""
        _, _, wx, wy, c = self._on_grid
        return float(wx @ c @ wy)

    def h_i(self) -> float:
        """H_I = -integral p ln p dA of p = c / M [nats, dA = 1] (the tensor rule)."""
        _, _, wx, wy, c = self._on_grid
        return _entropy(c.ravel(), np.outer(wx, wy).ravel(), self.mass)

    def dilution(self) -> float:
        """E = exp(H_I) [L^2]."""
        return math.exp(self.h_i())


# ------------------------------------------------------------------------ closed forms
def point_release(x, t: float, rate: float, D: float, v: float, x0: float = 0.0, start: float = 0.0) -> np.ndarray:
    """c(x, t) of a point at x0 releasing ``rate`` from ``start`` on, on the infinite line [M/L].

    With r = x - x0 and T = t - start, c = q integral_0^T exp(-(r - v s)^2 / (4 D s)) / sqrt(4 pi D s) ds.
    The exponent is r^2 / (4 D s) + b s - r v / (2 D) with b = v^2 / (4 D), and
    integral_0^T s^-1/2 exp(-a / s - b s) ds = sqrt(pi / b) / 2 [e^-2sqrt(ab) erfc(z1) - e^2sqrt(ab) erfc(z2)]
    (a = r^2 / (4 D); its T-derivative is the integrand), z1,2 = (|r| -+ |v| T) / sqrt(4 D T), so

        c = q / (2 |v|) [e^-k erfc(z1) - e^(-k - z1^2) erfcx(z2)],   k = (|r v| - r v) / (2 D),

    the second term through erfcx (e^(|rv|/D) erfc(z2) = e^(-z1^2) erfcx(z2)), and where z1 >= 0 as
    q / (2 |v|) e^(-k - z1^2) [erfcx(z1) - erfcx(z2)], with no overflow nor underflow of either
    factor. At v = 0 (b -> 0): c = q sqrt(T / (pi D)) e^-z^2 [1 - sqrt(pi) z erfcx(z)], z = |r| / sqrt(4 D T)."""
    from scipy.special import erfc, erfcx

    r = np.asarray(x, dtype=np.float64) - x0
    T = t - start
    if not T > 0:
        raise ValueError(f"t: a time > start = {start!r}, got {t!r}")
    root = math.sqrt(4.0 * D * T)
    if v == 0:
        z = np.abs(r) / root
        return rate * math.sqrt(T / (math.pi * D)) * np.exp(-z * z) * (1.0 - math.sqrt(math.pi) * z * erfcx(z))
    z1, z2 = (np.abs(r) - abs(v) * T) / root, (np.abs(r) + abs(v) * T) / root
    k = (np.abs(r * v) - r * v) / (2.0 * D)
    ahead = z1 >= 0
    z1a = np.where(ahead, z1, 0.0)  # erfcx(z1) only where it cannot overflow
    both = np.exp(-k - z1 * z1) * (erfcx(z1a) - erfcx(z2))
    split = np.exp(-k) * erfc(z1) - np.exp(-k - z1 * z1) * erfcx(z2)
    return rate / (2.0 * abs(v)) * np.where(ahead, both, split)


def steady_point_release(x, rate: float, D: float, v: float, x0: float = 0.0) -> np.ndarray:
    """The steady state of ``point_release`` (v != 0, t -> infinity), D c'' - v c' = -q delta(x - x0):
    q / |v| downstream, (q / |v|) exp(-|v (x - x0)| / D) upstream [M/L]."""
    r = np.asarray(x, dtype=np.float64) - x0
    return rate / abs(v) * np.exp(-(np.abs(r * v) - r * v) / (2.0 * D))


def hantush_w(u, beta) -> np.ndarray:
    """Hantush's leaky-aquifer well function W(u, beta) = integral_u^inf exp(-y - beta^2 / (4 y)) / y dy,
    by scipy's quad in z = ln y (a smooth bump), split at its peak y = beta / 2 and cut where the
    integrand is e^-80 of its peak; inf at u = beta = 0. W(u, 0) is Theis's E1(u), W(0, beta) = 2 K0(beta)."""
    from scipy.integrate import quad

    def one(u: float, beta: float) -> float:
        if u == 0 and beta == 0:
            return math.inf
        b2 = 0.25 * beta * beta
        f = lambda z: math.exp(-math.exp(z) - b2 * math.exp(-z))  # noqa: E731
        top = max(u, 0.5 * beta)  # -y - b2 / y falls by 80 beyond y = top + 80 ...
        lo = math.log(u) if u > 0 else math.log(b2 / (beta + 80.0))  # ... and below y = b2 / (beta + 80)
        cuts = sorted({lo, max(lo, math.log(0.5 * beta)) if beta > 0 else lo, math.log(top + 80.0)})
        return sum(quad(f, a, b, epsabs=0.0, epsrel=1e-13, limit=200)[0] for a, b in zip(cuts[:-1], cuts[1:]))

    u, beta = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(beta, dtype=np.float64))
    return np.vectorize(one, otypes=[np.float64])(u, beta)


def point_release_2d(points, t: float, rate: float, D_L: float, D_T: float, v, x0=(0.0, 0.0), start: float = 0.0):
    """c(p, t) of a point at x0 releasing ``rate`` from ``start`` on, on the infinite plane, flow v (2,) != 0
    with dispersion D_L along it and D_T across (Wilson and Miller 1978) [M/L^2]:

        c = q / (4 pi sqrt(D_L D_T)) exp(x v / (2 D_L)) W(u, r / B),
        r = sqrt(x^2 + y^2 D_L / D_T),   u = r^2 / (4 D_L T),   B = 2 D_L / |v|,   T = t - start,

    x along the flow and y across it from x0, W Hantush's well function (``hantush_w``). From
    c = integral_0^T q / (4 pi s sqrt(D_L D_T)) exp(-(x - v s)^2 / (4 D_L s) - y^2 / (4 D_T s)) ds: the
    exponent is x v / (2 D_L) - r^2 / (4 D_L s) - v^2 s / (4 D_L), and y = r^2 / (4 D_L s) turns ds / s
    into dy / y and v^2 s / (4 D_L) into beta^2 / (4 y), beta = r v / (2 D_L), over y from u to inf."""
    v = np.asarray(v, dtype=np.float64)
    speed = math.hypot(*v)
    if not speed > 0:
        raise ValueError("v: a flow v != 0, along which D_L acts")
    T = t - start
    if not T > 0:
        raise ValueError(f"t: a time > start = {start!r}, got {t!r}")
    along_unit = v / speed
    z = np.atleast_2d(np.asarray(points, dtype=np.float64)) - np.asarray(x0, dtype=np.float64)
    x = z @ along_unit
    y = z @ np.array([-along_unit[1], along_unit[0]])
    r = np.sqrt(x * x + y * y * (D_L / D_T))
    w = hantush_w(r * r / (4.0 * D_L * T), r * speed / (2.0 * D_L))
    return rate / (4.0 * math.pi * math.sqrt(D_L * D_T)) * np.exp(x * speed / (2.0 * D_L)) * w
