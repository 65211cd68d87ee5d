"""Source kinds of a 2-D scene, unit mass, one class per kind, each axis-aligned (the flow may point
anywhere): a point {kind: point, x0: [x0, y0]}, a Gaussian {kind: gaussian, x0: [x0, y0], sd: [sx, sy]}
and a box of uniform concentration {kind: box, x: [a, b], y: [c, d]}, the 1-D forms (core/sources.py)
with pairs. A kind checks its parameters and gives its centre and covariance, draws particle positions
and puts its mass on the cells of a tensor grid by exact integrals. ``SOURCES2D`` lists the kinds once.

The dispersion of a 2-D scene is a tensor: ``dispersion_tensor`` builds it from a config's
{L: D_L, T: D_T} (along and across the flow) or {x: Dx, y: Dy}.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import ClassVar

import numpy as np

from .sources import SourceError


def _positive(key: str, value) -> float:
    """``value`` as a float > 0 and finite, or ValueError naming ``key`` and the range."""
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    if not (ok and math.isfinite(value) and value > 0):
        raise ValueError(f"{key}: a number > 0 and finite [L^2/T], got {value!r}")
    return float(value)


def dispersion_tensor(v, D: Mapping) -> np.ndarray:
    """The 2 x 2 dispersion tensor [L^2/T]: D = D_T I + (D_L - D_T) v v^T / |v|^2 from {L: D_L, T: D_T}
    (v != 0: D_L along the flow, D_T across it), or diag(Dx, Dy) from {x: Dx, y: Dy} (any v)."""
    v = np.asarray(v, dtype=np.float64)
    if v.shape != (2,) or not np.all(np.isfinite(v)):
        raise ValueError(f"v: two finite components [vx, vy] [L/T], got {v.tolist()!r}")
    if not isinstance(D, Mapping):
        raise ValueError(f"D: a mapping {{L: D_L, T: D_T}} or {{x: Dx, y: Dy}} [L^2/T], got {D!r}")
    keys = set(D)
    if keys == {"x", "y"}:
        return np.diag([_positive("D.x", D["x"]), _positive("D.y", D["y"])])
    if keys != {"L", "T"}:
        raise ValueError(f"D: the keys {{L, T}} (along and across the flow) or {{x, y}}, got {sorted(map(str, keys))}")
    d_l, d_t = _positive("D.L", D["L"]), _positive("D.T", D["T"])
    speed2 = float(v @ v)
    if not speed2 > 0:
        raise ValueError("D.L: D_L and D_T act along and across the flow, which needs v != 0; at v = 0 give D: {x, y}")
    return d_t * np.eye(2) + (d_l - d_t) * np.outer(v, v) / speed2


def normal_mass(lo, hi):
    """Phi(hi) - Phi(lo) for standard-normal bounds lo <= hi, from the nearer tail: no cancellation
    where both bounds lie far out on one side."""
    from scipy.special import ndtr  # imported when used: a job that runs no 2-D source never loads scipy

    lo, hi = np.broadcast_arrays(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64))
    right = lo > 0  # both bounds in the right tail: Phi(-lo) - Phi(-hi)
    return ndtr(np.where(right, -lo, hi)) - ndtr(np.where(right, -hi, lo))


def _pair(name: str, value) -> tuple[float, float]:
    """``value`` as two finite floats, or SourceError naming ``name``."""
    try:
        pair = tuple(float(u) for u in value)
    except (TypeError, ValueError):
        pair = ()
    if len(pair) != 2 or not all(math.isfinite(u) for u in pair):
        raise SourceError(name, value, f"{name}: a pair of finite numbers [L], got {value!r}")
    return pair


def _cell_index(x: float, centres: np.ndarray, width: float, name: str) -> int:
    """The cell of centres ``centres`` and width ``width`` holding x (the first where it lies on an edge)."""
    i = int(np.argmin(np.abs(centres - x)))
    if abs(centres[i] - x) > 0.5 * width:
        raise ValueError(f"{name} = {x!r} lies outside the grid [{centres[0] - width / 2}, {centres[-1] + width / 2}]")
    return i


class Source2D:
    """The initial plume of a 2-D scene, unit mass (a kind's class holds its parameters as fields)."""

    KIND: ClassVar[str]

    def __post_init__(self):
        for f in fields(self):
            object.__setattr__(self, f.name, _pair(f.name, getattr(self, f.name)))
        self._argcheck()

    def _argcheck(self) -> None:
        """SourceError naming the first parameter out of its range (none by default)."""

    @property
    def kind(self) -> str:
        return self.KIND

    @staticmethod
    def of(kind: str = "point", **params) -> Source2D:
        """The source of ``kind`` with ``params`` in the config's pair form; SourceError for an unknown
        kind, a key not of the kind or a parameter out of range."""
        if kind not in SOURCES2D:
            raise SourceError("kind", kind, f"kind: one of {', '.join(SOURCES2D)}, got {kind!r}")
        cls = SOURCES2D[kind]
        names = {f.name for f in fields(cls)}
        extra = sorted(set(params) - names)
        if extra:
            raise SourceError(extra[0], params[extra[0]], f"{extra[0]}: not a key of a 2-D {kind} source")
        return cls(**params)

    def record(self) -> dict:
        """{kind, its parameters as pairs [u, w]}: what a config writes; ``Source2D.of(**record)`` reads it back."""
        return {"kind": self.KIND, **{f.name: list(getattr(self, f.name)) for f in fields(self)}}

    @property
    def centre(self) -> np.ndarray:
        """The source's centre of mass (2,) [L]."""
        raise NotImplementedError

    @property
    def covariance(self) -> np.ndarray:
        """The source's own covariance (2, 2) [L^2]."""
        raise NotImplementedError

    def positions(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n particle positions (n, 2) drawn from the source [L]."""
        raise NotImplementedError

    def _axis_masses(self, axis: int, centres: np.ndarray, width: float) -> np.ndarray:
        """The source's mass in each cell [centre - width/2, centre + width/2] of one axis (its marginal)."""
        raise NotImplementedError

    def cell_masses(self, xc, yc, dx: float, dy: float) -> np.ndarray:
        """The source's mass in each cell of the tensor grid of cell centres xc (nx,) and yc (ny,), cells
        dx by dy -> (nx, ny), normalised to sum 1 (exact integrals: the kinds are products of their x and
        y marginals; what lies beyond the grid is put back in proportion)."""
        xc, yc = np.asarray(xc, dtype=np.float64), np.asarray(yc, dtype=np.float64)
        m = np.outer(self._axis_masses(0, xc, dx), self._axis_masses(1, yc, dy))
        total = m.sum()
        if not total > 0:
            raise ValueError(f"the grid holds none of the {self.KIND} source's mass")
        return m / total


@dataclass(frozen=True)
class Point2D(Source2D):
    """A point (delta) at x0 = [x0, y0]."""

    KIND: ClassVar[str] = "point"
    x0: tuple[float, float] = (0.0, 0.0)

    @property
    def centre(self):
        return np.array(self.x0)

    @property
    def covariance(self):
        return np.zeros((2, 2))

    def positions(self, n, rng):
        return np.tile(np.array(self.x0), (n, 1))

    def _axis_masses(self, axis, centres, width):
        m = np.zeros(len(centres))
        m[_cell_index(self.x0[axis], centres, width, f"x0[{axis}]")] = 1.0
        return m


@dataclass(frozen=True)
class Gaussian2D(Source2D):
    """Independent Gaussians along x and y: mean x0 = [x0, y0], standard deviations sd = [sx, sy] > 0."""

    KIND: ClassVar[str] = "gaussian"
    x0: tuple[float, float] = (0.0, 0.0)
    sd: tuple[float, float] = (math.nan, math.nan)

    def _argcheck(self):
        if not min(self.sd) > 0:
            raise SourceError("sd", list(self.sd), f"sd: a pair of finite numbers > 0 [L], got {list(self.sd)!r}")

    @property
    def centre(self):
        return np.array(self.x0)

    @property
    def covariance(self):
        """diag(sx^2, sy^2)."""
        return np.diag(np.square(self.sd))

    def positions(self, n, rng):
        return np.array(self.x0) + np.array(self.sd) * rng.standard_normal((n, 2))

    def _axis_masses(self, axis, centres, width):
        """Phi((x + dx/2 - x0) / sd) - Phi((x - dx/2 - x0) / sd)."""
        z = (centres - self.x0[axis]) / self.sd[axis]
        h = 0.5 * width / self.sd[axis]
        return normal_mass(z - h, z + h)


@dataclass(frozen=True)
class Box2D(Source2D):
    """Uniform concentration on the rectangle [a, b] x [c, d]: x = [a, b], y = [c, d], a < b, c < d."""

    KIND: ClassVar[str] = "box"
    x: tuple[float, float] = (math.nan, math.nan)
    y: tuple[float, float] = (math.nan, math.nan)

    def _argcheck(self):
        for name, (lo, hi) in (("x", self.x), ("y", self.y)):
            if not (hi > lo and math.isfinite(hi - lo)):
                raise SourceError(name, [lo, hi], f"{name}: [lo, hi] with lo < hi, both finite [L], got {[lo, hi]!r}")

    @property
    def area(self) -> float:
        """(b - a)(d - c) [L^2]."""
        return (self.x[1] - self.x[0]) * (self.y[1] - self.y[0])

    @property
    def centre(self):
        return np.array([0.5 * (self.x[0] + self.x[1]), 0.5 * (self.y[0] + self.y[1])])

    @property
    def covariance(self):
        """diag((b - a)^2 / 12, (d - c)^2 / 12)."""
        return np.diag([(self.x[1] - self.x[0]) ** 2 / 12.0, (self.y[1] - self.y[0]) ** 2 / 12.0])

    def positions(self, n, rng):
        lo = np.array([self.x[0], self.y[0]])
        hi = np.array([self.x[1], self.y[1]])
        return rng.uniform(lo, hi, (n, 2))

    def _axis_masses(self, axis, centres, width):
        """The overlap of each cell with the box's side, over the side's length."""
        lo, hi = (self.x, self.y)[axis]
        overlap = np.minimum(centres + 0.5 * width, hi) - np.maximum(centres - 0.5 * width, lo)
        return np.clip(overlap, 0.0, None) / (hi - lo)


# The kinds, each once.
SOURCES2D: dict[str, type[Source2D]] = {cls.KIND: cls for cls in (Point2D, Gaussian2D, Box2D)}


def pair_shape(**bounds) -> dict:
    """The JSON schema of a pair [u, w] of numbers (``bounds`` on each: exclusiveMinimum, ...)."""
    return {"type": "array", "items": {"type": "number", **bounds}, "minItems": 2, "maxItems": 2}


def with_pairs(shape: dict) -> dict:
    """A source's JSON schema (core/sources.source_shape) that also takes the 2-D kinds: their pair
    keys, a key both take being a number or a pair."""
    properties = {k: dict(v) for k, v in shape["properties"].items()}
    properties["kind"] = {"type": "string", "enum": list(dict.fromkeys([*properties["kind"]["enum"], *SOURCES2D]))}
    for cls in SOURCES2D.values():
        for f in fields(cls):
            pair = pair_shape(**({"exclusiveMinimum": 0} if f.name == "sd" else {}))
            one = properties.get(f.name)
            if one is None:
                properties[f.name] = pair
            elif "oneOf" not in one:
                properties[f.name] = {"oneOf": [one, pair]}
    return {**shape, "properties": properties}


_PAIR_WORDS = {"x0": "x0, y0", "sd": "sx, sy", "x": "a, b", "y": "c, d"}  # how the docs write each pair


def source_forms_2d() -> str:
    """'{kind: point, x0: [x0, y0]}, ...': what a 2-D scene's config writes for each kind."""
    return ", ".join(
        f"{{kind: {k}, {', '.join(f'{f.name}: [{_PAIR_WORDS[f.name]}]' for f in fields(cls))}}}"
        for k, cls in SOURCES2D.items()
    )
