"""Reaction kinetics in closed form: first-order decay and the irreversible bimolecular reaction
A + B -> C at rate k C_A C_B, over one time step at fixed local concentrations.

Every model that carries a reaction (FD on its nodes, MTPT on its particles after each exchange,
the reference grid) advances the kinetics by these exact solutions of the local rate equations, so
that no step makes a mass negative or loses one to round-off beyond the last digit:

- decay, dC/dt = -lambda C: C(t + dt) = C(t) exp(-lambda dt);
- A + B -> C, dA/dt = dB/dt = -k A B: with p = max(A, B), q = min(A, B) and the conserved excess
  d = p - q >= 0, the amount that reacts in dt is

      r = p q k dt g / (1 + q k dt g),   g = (1 - exp(-x)) / x,   x = k d dt  (g(0) = 1),

  which tends to q as dt grows (the scarcer species runs out) and to p q k dt as dt shrinks. For
  equal uniform concentrations C0 it is the well-mixed solution C(t) = C0 / (1 + k C0 t), which
  also solves the reaction-diffusion PDE exactly for uniform initial conditions.

A reaction kind is a class (``Decay``, ``Bimolecular``, listed once in ``REACTIONS``) whose ``react``
advances nodes or particles by these solutions and returns the product made.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

# below this |x| the series 1 - x/2 + x^2/6 is g(x) to round-off (its next term x^3/24 < eps x)
_SERIES = 1e-5


def decay_factor(rate: float, dt: float) -> float:
    """exp(-lambda dt): what a first-order decay leaves of a mass over a step dt [-]."""
    return float(np.exp(-rate * dt))


def _g(x: np.ndarray) -> np.ndarray:
    """(1 - exp(-x)) / x for x >= 0, with g(0) = 1, without cancellation (expm1, and its series near 0)."""
    x = np.asarray(x, dtype=np.float64)
    small = x < _SERIES
    safe, tiny = np.where(small, 1.0, x), np.where(small, x, 0.0)  # each branch on its own x: no overflow
    return np.where(small, 1.0 - tiny / 2.0 + tiny * tiny / 6.0, -np.expm1(-safe) / safe)


def _ordered(a, b, k: float, dt):
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    p, q = np.maximum(a, b), np.minimum(a, b)
    kt = k * np.asarray(dt, dtype=np.float64)
    x = kt * (p - q)
    return a, b, p, q, x, kt * _g(x)


def bimolecular_reacted(a, b, k: float, dt) -> np.ndarray:
    """The concentration of A (and of B) that reacts in dt by A + B -> C at rate k a b, the exact
    solution of dA/dt = dB/dt = -k A B from (a, b) >= 0, never more than min(a, b)."""
    _, _, p, q, _, e = _ordered(a, b, k, dt)
    return np.minimum(p * q * e / (1.0 + q * e), q)


def bimolecular_step(a, b, k: float, dt) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) after dt of A + B -> C from (a, b) >= 0, each left amount computed without subtracting
    (the abundant species keeps p / (1 + q k dt g), the scarce one q exp(-x) / (1 + q k dt g)), so that
    late-time concentrations keep their digits; never negative."""
    a, b, p, q, x, e = _ordered(a, b, k, dt)
    rich, scarce = p / (1.0 + q * e), q * np.exp(-x) / (1.0 + q * e)
    return np.where(a >= b, rich, scarce), np.where(a >= b, scarce, rich)


def well_mixed(a0: float, b0: float, k: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The concentrations (A, B) at time t of a well-mixed A + B -> C from uniform a0, b0: with
    a0 = b0 = C0 the classical C0 / (1 + k C0 t)."""
    return bimolecular_step(a0, b0, k, t)


@dataclass(frozen=True)
class Decay:
    """First-order decay A -> C, dA/dt = -lambda A, at ``rate`` lambda [1/T]; B takes no part."""

    KIND: ClassVar[str] = "decay"
    CONSUMES_B: ClassVar[bool] = False  # conserved: A + C and B
    PARAMS: ClassVar[dict] = {"rate": "the first-order rate lambda of A -> C [1/T]"}
    rate: float

    def record(self) -> dict:
        return {"rate": self.rate}

    def closed_form(self, t: float) -> tuple[float, float]:
        """(A's, C's share of the conservative plume at time t): exp(-lambda t), -expm1(-lambda t)."""
        return math.exp(-self.rate * t), -math.expm1(-self.rate * t)

    def __post_init__(self):
        if not (self.rate >= 0 and math.isfinite(self.rate)):
            raise ValueError(f"decay rate must be >= 0 and finite, got {self.rate!r}")

    def react(self, a, b, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, the A turned into C) after dt: A exp(-lambda dt), B as it was, A (1 - exp(-lambda dt))."""
        a = np.asarray(a, dtype=np.float64)
        return a * decay_factor(self.rate, dt), np.asarray(b, dtype=np.float64), -a * math.expm1(-self.rate * dt)

    def fastest_rate(self, a, b) -> float:
        """lambda: the fastest local rate of the kinetics [1/T]."""
        return float(self.rate)

    def on_masses(self, ma, mb, dV: float, dt: float):
        """(m_A, m_B, mass moved into C) after dt on each particle or node: m_A exp(-lambda dt), and
        -m_A expm1(-lambda dt) moved, never m_A minus what is left (which cancels to 0 below lambda dt ~ eps)."""
        ma = np.asarray(ma, dtype=np.float64)
        return ma * decay_factor(self.rate, dt), mb, -ma * math.expm1(-self.rate * dt)

    def on_particles(self, xa, xb, m_p: float, D: float, dt: float, length: float, rng, pairs):
        """PT's rule (A kept, B kept, new C positions): each A particle stays with probability
        exp(-lambda dt), drawn against -expm1(-lambda dt) (> 0 however small lambda dt), its C where it was."""
        keep = rng.random(xa.size) >= -math.expm1(-self.rate * dt)
        return keep, np.ones(xb.size, dtype=bool), xa[~keep]

    @staticmethod
    def conserved(a: float, b: float, c: float) -> dict[str, float]:
        """The totals a decay keeps, from the totals of A, B and C: A + C and B."""
        return {"A + C": a + c, "B": b}


@dataclass(frozen=True)
class Bimolecular:
    """The irreversible A + B -> C, dA/dt = dB/dt = -k A B, at rate constant ``k`` [L/(M T) in 1-D]."""

    KIND: ClassVar[str] = "bimolecular"
    CONSUMES_B: ClassVar[bool] = True  # conserved: A + C and B + C
    PARAMS: ClassVar[dict] = {"k": "the rate constant k of A + B -> C at rate k C_A C_B [L/(M T)]"}
    k: float

    def record(self) -> dict:
        return {"k": self.k}

    def closed_form(self, t: float) -> None:
        """None: A + B -> C has no closed form where A and B are not uniform (a reference solves it)."""
        return None

    def __post_init__(self):
        if not (self.k >= 0 and math.isfinite(self.k)):
            raise ValueError(f"rate constant k must be >= 0 and finite, got {self.k!r}")

    def react(self, a, b, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, the C made) after dt, each by the exact step (bimolecular_step, bimolecular_reacted)."""
        a_new, b_new = bimolecular_step(a, b, self.k, dt)
        return a_new, b_new, bimolecular_reacted(a, b, self.k, dt)

    def fastest_rate(self, a, b) -> float:
        """k max(A, B): the fastest local rate of the kinetics from (a, b) [1/T]."""
        return float(self.k * max(np.max(a, initial=0.0), np.max(b, initial=0.0)))

    def on_masses(self, ma, mb, dV: float, dt: float):
        """(m_A, m_B, mass moved into C) after dt of the exact local kinetics at c = m / dV, solved for
        the masses, dm_A/dt = -(k / dV) m_A m_B, so that no mass goes through a division and back;
        C gains the reacted mass itself (bimolecular_reacted), never a difference of what A and B kept,
        which cancels to 0 where k dt m_B / dV is below eps (k = 1e-300). A negative round-off residue
        (an FD scheme carrying B as its departure from a background leaves -1e-18 where B is used up)
        takes no part: it reacts as 0 and is carried through unchanged."""
        ma, mb = np.asarray(ma, dtype=np.float64), np.asarray(mb, dtype=np.float64)
        pa, pb = np.maximum(ma, 0.0), np.maximum(mb, 0.0)
        na, nb = bimolecular_step(pa, pb, self.k / dV, dt)
        return na + (ma - pa), nb + (mb - pb), bimolecular_reacted(pa, pb, self.k / dV, dt)

    def on_particles(self, xa, xb, m_p: float, D: float, dt: float, length: float, rng, pairs):
        """PT's rule (A kept, B kept, new C positions): Benson & Meerschaert's pairs on the periodic
        [0, length), ``pairs`` (models/reaction_step.pair_reactions: the pair search is a model's)."""
        return pairs(xa, xb, self.k, m_p, D, dt, length, rng)

    @staticmethod
    def conserved(a: float, b: float, c: float) -> dict[str, float]:
        """The totals A + B -> C keeps, from the totals of A, B and C: A + C and B + C."""
        return {"A + C": a + c, "B + C": b + c}


@dataclass(frozen=True)
class Production:
    """First-order production A -> A + C, dC/dt = lambda A: A is kept and makes C at ``rate`` lambda
    [1/T] (a parent that releases a product without being used up); B takes no part."""

    KIND: ClassVar[str] = "production"
    CONSUMES_B: ClassVar[bool] = False  # conserved: A and B; C grows by lambda dt A a step
    PARAMS: ClassVar[dict] = {"rate": "the first-order rate lambda of A -> A + C [1/T]"}
    rate: float

    def __post_init__(self):
        if not (self.rate >= 0 and math.isfinite(self.rate)):
            raise ValueError(f"production rate must be >= 0 and finite, got {self.rate!r}")

    def record(self) -> dict:
        return {"rate": self.rate}

    def closed_form(self, t: float) -> tuple[float, float]:
        """(A's, C's share of the conservative plume at time t): 1 and lambda t, exactly, because C made at
        time s is carried by the same linear transport as A from s on."""
        return 1.0, self.rate * t

    def react(self, a, b, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, the C made) after dt: A and B as they were, lambda dt A made."""
        a = np.asarray(a, dtype=np.float64)
        return a, np.asarray(b, dtype=np.float64), a * (self.rate * dt)

    def fastest_rate(self, a, b) -> float:
        """lambda [1/T]."""
        return float(self.rate)

    def on_masses(self, ma, mb, dV: float, dt: float):
        """(m_A, m_B, mass made into C) after dt on each particle or node: m_A and m_B kept, lambda dt m_A made."""
        ma = np.asarray(ma, dtype=np.float64)
        return ma, mb, ma * (self.rate * dt)

    def on_particles(self, xa, xb, m_p: float, D: float, dt: float, length: float, rng, pairs):
        """PT's rule (A kept, B kept, new C positions): each A particle makes a Poisson(lambda dt) number of
        C particles where it is, lambda dt of them in the mean (exact in expectation at any dt)."""
        made = rng.poisson(self.rate * dt, xa.size)
        return np.ones(xa.size, dtype=bool), np.ones(xb.size, dtype=bool), np.repeat(xa, made)

    @staticmethod
    def conserved(a: float, b: float, c: float) -> dict[str, float]:
        """The totals production keeps, from the totals of A, B and C: A and B."""
        return {"A": a, "B": b}


# The reaction kinds, each once.
REACTIONS: dict[str, type] = {cls.KIND: cls for cls in (Decay, Bimolecular, Production)}


# ------------------------------------------------------------------------------ a scene's reaction
B_UNIFORM_MAX = 1e6  # a uniform B above this many units of mass per length is a typo [M/L]
# B's least concentration or plume mass (A's is 1): below it the products of A's and B's masses on the
# finest grids (cells of 1e-5, times k dt) reach the subnormal doubles, which the tridiagonal solvers
# flush to zero; at B = 1e-305 the reference's product was 10 % off, at 1e-300 1e-6, at 1e-200 exact
B_MIN = 1e-200
# the largest rate constant: the kinetics divide it by a particle's or node's dV (down to 1e-100 in
# any scene a grid can hold) and multiply by dt, and k / dV past 1e308 is inf, whose step is NaN; at
# k C0 t far below this bound a reaction is already instantaneous on every grid
K_MAX = 1e200


class ReactionError(ValueError):
    """A bad reaction parameter: ``param`` (its key within the reaction), the value, what is allowed."""

    def __init__(self, param: str, value, allowed: str):
        super().__init__(f"{param}={value!r}: {allowed}")
        self.param, self.value, self.allowed = param, value, allowed


@dataclass(frozen=True)
class Reaction:
    """A scene's reaction (config ``scenes.<name>.reaction``): its kinetics, and for A + B -> C the
    second species B's initial condition, a uniform background ``b_uniform`` [M/L] or a plume
    ``b_source`` of mass ``b_mass`` [M]. A is the scene's own source, of unit mass."""

    kinetics: Decay | Bimolecular
    b_uniform: float = 0.0
    b_source: object = None  # a core.sources.Source
    b_mass: float = 0.0

    @property
    def kind(self) -> str:
        return self.kinetics.KIND

    def record(self) -> dict:
        """The reaction as a run's settings carry it and its identity digests it."""
        out = {"kind": self.kind, **self.kinetics.record()}
        if self.kinetics.CONSUMES_B:
            out["B"] = (
                {"uniform": self.b_uniform}
                if self.b_source is None
                else {"source": self.b_source.record(), "mass": self.b_mass}
            )
        return out

    @staticmethod
    def from_spec(spec) -> Reaction:
        """The reaction a config writes ({kind, its kind's PARAMS} and, for a kind that consumes B, B:
        {uniform: C0} or {source: <a source>, mass}), its keys already typed (core/typed.py);
        ReactionError naming the first bad parameter of B's source."""
        from .sources import Source, SourceError

        def source(spec):
            try:
                return Source.from_spec(spec)
            except SourceError as e:
                raise ReactionError(f"B.source.{e.param}", e.value, e.allowed) from None

        return Reaction._built(spec, source)

    @staticmethod
    def of(record: dict | None) -> Reaction | None:
        """The reaction of a run's settings (``record``), or None."""
        from .sources import Source

        return None if record is None else Reaction._built(record, lambda spec: Source.of(**spec))

    @staticmethod
    def _built(mapping, source) -> Reaction:
        """The reaction of a config's or a record's ``mapping``, B's plume built by ``source``."""
        cls = REACTIONS[mapping["kind"]]
        kinetics = cls(**{key: mapping[key] for key in cls.PARAMS})
        if not cls.CONSUMES_B:
            return Reaction(kinetics)
        b = mapping["B"]
        if "uniform" in b:
            return Reaction(kinetics, b_uniform=b["uniform"])
        return Reaction(kinetics, b_source=source(b["source"]), b_mass=b.get("mass", 1.0))

    def closed_form(self, t: float) -> tuple[float, float] | None:
        """(A's, C's share of the conservative plume at t) where the kinetics have a closed form and B
        takes no part; None where a reference must be solved."""
        return None if self.kinetics.CONSUMES_B else self.kinetics.closed_form(t)

    @property
    def b_background(self) -> float:
        """B's uniform concentration C0, which a model's ends hold and its transport carries B's departure
        from; 0 for a plume of B or a decay [M/L]."""
        return self.b_uniform if self.b_source is None else 0.0

    def b_positions(self, m_p: float, length: float, lo: float, rng: np.random.Generator) -> np.ndarray:
        """PT's B particles of mass m_p on the periodic [0, length) that starts at ``lo``: C0 length / m_p
        uniform ones, or b_mass / m_p from B's plume; none for a decay."""
        if not self.kinetics.CONSUMES_B:
            return np.empty(0)
        if self.b_source is None:
            return rng.uniform(0.0, length, round(self.b_uniform * length / m_p))
        return np.mod(self.b_source.positions(round(self.b_mass / m_p), rng) - lo, length)

    def lost_bc(self, b_departure0: float, b_departure: float, c_total: float) -> float:
        """The fraction of B + C lost (through an FD window's ends) from B's initial departure from its
        background ``b_departure0``, its departure now and C's total: over B's mass for a plume of B, in
        units of A's unit mass for a uniform B (whose departure only the reaction makes); 0 where B is no
        reactant (a kind that keeps B, whatever leaves)."""
        if not self.kinetics.CONSUMES_B:
            return 0.0
        scale = self.b_mass if self.b_source is not None else 1.0
        return (b_departure0 - (b_departure + c_total)) / scale

    def b_masses(self, x: np.ndarray, dV: float) -> np.ndarray:
        """B's initial mass on particles or nodes at ``x`` with spacing dV [M]: C0 dV each, or the plume's
        mass spread by its density (Source.masses); zero for a decay."""
        x = np.asarray(x, dtype=np.float64)
        if not self.kinetics.CONSUMES_B:
            return np.zeros_like(x)
        if self.b_source is None:
            return np.full_like(x, self.b_uniform * dV)
        return self.b_mass * self.b_source.masses(x, dV)

    def check_b_within(self, centre: float, width: float, beyond: float) -> None:
        """ReactionError naming B.source unless B's plume and ``beyond`` past it (a scene's REACH
        sqrt(4 D t_final)) lie within ``width`` around ``centre`` (A's): the narrower of a scene's
        domains, outside which MTPT would put B's mass on the edge particle, FD on the edge node, PT
        would wrap it. A uniform B, or none, fits any domain."""
        b = self.b_source
        if b is None:
            return
        need = 2.0 * (abs(b.centre - centre) + b.half_width + beyond)
        if width < need * (1.0 - 1e-12):
            raise ReactionError(
                "B.source",
                b.record(),
                f"a plume within the scene's domains: omega and fd_length ({width:.6g} wide around A's centre) must "
                f"reach {need:.6g}, B's extent and 3 sqrt(4 D t_final) beyond it; widen them, or leave them to margin",
            )


def reaction_shape(source_shape: dict) -> dict:
    """The JSON schema of a scene's reaction: {kind: decay, rate} or {kind: bimolecular, k, B}, B a
    uniform background or a source with its mass (core/typed.py's Reaction and SpeciesB models hold
    the rules between these keys)."""
    b = {
        "type": "object",
        "x-model": "SpeciesB",
        "additionalProperties": False,
        "properties": {
            "uniform": {
                "type": "number",
                "minimum": B_MIN,
                "maximum": B_UNIFORM_MAX,
                "description": f"B's uniform initial concentration C0 [M/L]; a number in [{B_MIN:g}, "
                f"{B_UNIFORM_MAX:g}]",
            },
            "source": {**source_shape, "description": "B's initial plume: a source of the kinds scenes know"},
            "mass": {
                "type": "number",
                "minimum": B_MIN,
                "maximum": B_UNIFORM_MAX,
                "description": f"the mass of B's plume (A's is 1) [M]; a number in [{B_MIN:g}, {B_UNIFORM_MAX:g}] "
                "(default 1)",
            },
        },
    }
    return {
        "type": "object",
        "x-model": "Reaction",
        "additionalProperties": False,
        "required": ["kind"],
        "properties": {
            "kind": {"type": "string", "enum": list(REACTIONS), "description": f"one of {', '.join(REACTIONS)}"},
            **_param_shapes(),
            "B": {**b, "description": f"{_kinds_of('B')}: B's initial condition, {{uniform: C0}} or {{source, mass}}"},
        },
    }


def _kinds_of(key: str) -> str:
    """The kinds that take config key ``key`` (B: the kinds that consume B), joined."""
    if key == "B":
        return ", ".join(kind for kind, cls in REACTIONS.items() if cls.CONSUMES_B)
    return ", ".join(kind for kind, cls in REACTIONS.items() if key in cls.PARAMS)


# each rate parameter's upper bound (k: K_MAX, below the overflow of k / dV); a first-order rate has none
_MAXIMA = {"k": K_MAX}


def _param_shapes() -> dict:
    """The schema of every kind's rate parameters (PARAMS), each once, its meaning per kind."""
    shapes = {}
    for cls in REACTIONS.values():
        for key, meaning in cls.PARAMS.items():
            shape = shapes.setdefault(key, {"type": "number", "exclusiveMinimum": 0, "description": ""})
            if key in _MAXIMA:
                shape["maximum"] = _MAXIMA[key]
            shape["description"] += f"{cls.KIND}: {meaning}; "
    for key, shape in shapes.items():
        bound = f"a number in (0, {_MAXIMA[key]:g}]" if key in _MAXIMA else "a number > 0"
        shape["description"] += bound
    return shapes


def reaction_kinds_text() -> str:
    """Each kind's keys and meaning, for the config's docs: {kind: decay, rate} (its class's first
    docstring line), ... (B: {uniform: C0} or {source: <a source>, mass})."""
    parts = []
    for kind, cls in REACTIONS.items():
        keys = ", ".join([*cls.PARAMS, *(["B"] if cls.CONSUMES_B else [])])
        meaning = cls.__doc__.split(",")[0].strip()
        parts.append(f"{{kind: {kind}, {keys}}} ({meaning[0].lower()}{meaning[1:]})")
    return " or ".join(parts) + " (B: {uniform: C0} or {source: <a source>, mass})"


def reaction_ranges_text() -> str:
    """The allowed values of each kind's keys, for the config's docs."""
    parts = []
    for kind, cls in REACTIONS.items():
        keys = ", ".join(
            [
                *(f"{k} > 0" for k in cls.PARAMS),
                *(["B: {uniform: C0 > 0} or {source, mass > 0}"] if cls.CONSUMES_B else []),
            ]
        )
        parts.append(f"{{kind: {kind}, {keys}}}")
    return " or ".join(parts)
