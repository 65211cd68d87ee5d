"""A scene (config `scenes.<name>`, declared by settings.SCENE): a problem of the user's own (D, a
uniform v, a source, the observation time, the domains) with the candidate models to compare and the
accuracy they must reach. A scene knows each candidate's runs: their settings, their identity and
the ladder of resolutions its search may visit (analysis/scene_search.py). Each part checks its own
values (a candidate here, its source and reaction in core/); the rules between the parts are in
scenes/checks.py."""

from __future__ import annotations

import copy
import functools
import math
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass, replace

import numpy as np

from ..core import plane
from ..core.case import CASE_DIR, Case, SettingError
from ..core.io import digest
from ..core.reactions import Reaction, ReactionError
from ..core.reference import Reference
from ..core.reference2d import Reference2D
from ..core.registry import DEFAULT_ADVECTION, MEASUREMENT_POINTS
from ..core.release import Release, ReleaseError
from ..core.released import ReleasedPlume, ReleasedPlume2D, released_span
from ..core.runconfig import RunConfig
from ..core.runcost import StepWork, Tally
from ..core.settings import MAX_REALISATIONS, PAPER, PLANE_COST, REACTIVE_COST, SCENE, SCENE_REACH, defaults
from ..core.sources import Source, SourceError
from ..core.sources2d import Source2D, dispersion_tensor
from ..core.timegrid import MAX_STEPS, max_first_step
from ..core.typed import FD_ONLY, PARTICLE_ONLY, shared, validate
from ..core.typed import key_path as typed_key_path
from . import checks as scene_checks
from . import defined

SCENE_RUN_PATTERN = "results/scenes/{scene_id}/{kind}/" + CASE_DIR + "/seeds~{first}-{last}.parquet"
LADDER_RATIO = 2.0  # neighbouring resolutions of a candidate's ladder
# A straddling particle rung's seed blocks by default (max_realisations = this x realisations): four
# blocks halve the bound's half-width, t_0.95 s / sqrt(R), and cost what the rung two above costs at
# one block on a ratio-2 ladder, so a refined rung is never dearer than the climb it may save.
MAX_BLOCKS = 4
# The 15 measurement points common to every model span the plume at t_final, its mean +- REACH
# sqrt(2 variance) (+- 3 sqrt(4 D t) for a point: 4.24 standard deviations), as the paper's span
# [-6, 6] its plume at t = 1000; they move with the plume and never depend on the FD window, which
# must reach as far beyond the source (settings.SCENE_REACH).
REACH = SCENE_REACH
_DEFAULTS = defaults(SCENE)
SPEC = shared().Scene  # a scene's model: its keys, their ranges and the rules between them (core/typed.py)


# The Peclet sweeps by the prefix of their scenes' names (peclet-0, peclet2d-1, ...: a '-' no user
# scene's name has): their config section and the dimension of their scenes.
SWEEPS = {"peclet-": ("scenes_peclet", 1), "peclet2d-": ("scenes_peclet2d", 2)}
SWEEP_NAME = "|".join(f"{prefix}[0-9]+" for prefix in SWEEPS)  # a sweep scene's name, as a pattern
USER_NAME = re.compile(r"[A-Za-z0-9_]+")  # a scene's name in config `scenes` (the schema's pattern)
# what a candidate of a reactive scene may be: the models that carry a reaction (models/simulate.py)
REACTIVE_SCHEMES = ("symmetric",)  # MTPT's transfer matrix of Eqs. 16-21, which moves every species at once
_CASE_DIMS = ("eta", "truncation", "dt_growth", "scheme", "time_grid")


def sweep_of(name: str) -> tuple[str, int, int] | None:
    """A Peclet sweep's scene (SWEEPS) -> (its config section, its dimension, its index k); None for
    a scene of config `scenes`."""
    for prefix, (section, dim) in SWEEPS.items():
        if name.startswith(prefix) and name[len(prefix) :].isdigit():
            return section, dim, int(name[len(prefix) :])
    return None


def key_path(name: str, key: str) -> str:
    """The config key of ``key`` in scene ``name``: scenes.<name>.<key>; in a scene of a Peclet
    sweep (peclet-<k>, peclet2d-<k>) its base's key, and its v: <section>.v[k]."""
    sweep = sweep_of(name)
    if sweep is not None:
        section, _, k = sweep
        return f"{section}.v[{k}]" if key == "v" else f"{section}.base.{key}"
    return f"scenes.{name}.{key}"


def _number(x: float) -> str:
    """A number as short as it reads back exactly: 0.05, 1.1, 0.30000000000000004."""
    return f"{x:g}" if float(f"{x:g}") == x else repr(x)


@dataclass(frozen=True)
class Candidate:
    """One model a scene compares: a case without N, its resolution range, and FD's advection scheme
    and time step: fixed (fd_dt) or following the grid (courant: dt = courant dx / |v|, in a flow)."""

    case: Case
    n_lo: int
    n_hi: int
    advection: str = DEFAULT_ADVECTION  # "none" in a scene without flow
    fd_dt: float = PAPER["fd_dt"]
    rungs: tuple[int, ...] = ()  # a ladder written out (config `ladder`) instead of n_range's
    courant: float | None = None  # FD in a flow: the step's Courant number instead of fd_dt
    dt0: float | None = None  # particles: their first step instead of time.dt0 (growth 1: a fixed step)

    @property
    def label(self) -> str:
        """The candidate's name in tables and legends."""
        c = self.case
        if c.method == "fd":
            scheme = "" if self.advection == "none" else f" {self.advection}"
            step = f"dt={_number(self.fd_dt)}" if self.courant is None else f"Cr={_number(self.courant)}"
            return f"fd {c.kernel}{scheme} {step}"
        words = [c.method, c.kernel]
        if c.method == "mtpt":
            words.append(f"eta={_number(c.eta)}")
            if c.truncation is not None:
                words.append(f"cut={_number(c.truncation)}")
            if c.scheme != "symmetric":
                words.append(c.scheme)
        if self.dt0 is not None:
            words.append(f"dt0={_number(self.dt0)}")
        if c.dt_growth != PAPER["dt_growth"]:  # every dimension that tells two models apart
            words.append(f"growth={_number(c.dt_growth)}")
        if c.time_grid != PAPER["time_grid"]:
            words.append(f"grid={c.time_grid}")
        return " ".join(words)

    @property
    def model(self) -> tuple:
        """What makes two candidates the same model: the case, FD's scheme and step, particles' first step."""
        return (self.case, self.advection, self.fd_dt, self.courant, self.dt0)

    def ladder(self) -> list[int]:
        """The resolutions the search may visit: n_lo, n_lo r, n_lo r^2, ... up to n_hi (r = LADDER_RATIO,
        rounded; FD: even numbers of intervals), each once; or the candidate's own ``rungs``."""
        if self.rungs:
            return list(self.rungs)
        steps = max(1, math.ceil(math.log(self.n_hi / self.n_lo) / math.log(LADDER_RATIO) - 1e-9))
        out = []
        for k in range(steps + 1):
            n = self.n_lo * (self.n_hi / self.n_lo) ** (k / steps)
            n = 2 * round(n / 2) if self.case.method == "fd" else round(n)
            if not out or n > out[-1]:
                out.append(int(n))
        return out

    @classmethod
    def from_spec(cls, spec, case_defaults: Mapping, key) -> Candidate:
        """The candidate of its parsed model ``spec`` (its keys' rules held there, core/typed.py): its
        case built with case_defaults (not their time_grid: a scene's runs end at t_final, where they
        are judged), else SettingError naming ``key(k)``, the candidate's key k in its scene."""
        dims = spec.model_dump(exclude_unset=True, exclude={*FD_ONLY, *PARTICLE_ONLY, "n_range", "ladder"})
        case_defaults = {k: v for k, v in case_defaults.items() if k != "time_grid"}
        try:
            case = Case.from_spec(dims, None, case_defaults)
        except SettingError as e:
            raise SettingError(key(e.name), e.value, e.allowed) from None
        rungs = tuple(spec.ladder or ())
        lo, hi = (rungs[0], rungs[-1]) if rungs else spec.n_range
        advection = spec.advection or DEFAULT_ADVECTION
        fd_dt = PAPER["fd_dt"] if spec.fd_dt is None else spec.fd_dt
        return cls(case, lo, hi, advection, fd_dt, rungs, spec.courant, spec.dt0)

    def check_runs(self, scene: Scene, i: int, written) -> None:
        """SettingError unless this candidate's runs (candidate i of ``scene``) fit their domains and
        steps at both ends of its ladder, named by the key the user wrote (run_error; ``written``:
        the keys its config sets)."""
        for n in dict.fromkeys((self.n_lo, self.ladder()[-1])):
            try:
                scene.run_config(self, n)
                if scene.runs_at_rest(self):  # and the carried run it stands for, as the scene states it
                    scene.run_config(self, n, carried=True)
            except SettingError as e:
                raise self.run_error(scene, i, written, e) from None

    def run_error(self, scene: Scene, i: int, written, e: SettingError) -> SettingError:
        """A SettingError of this candidate's run (candidate i of ``scene``), named by the key the user
        wrote (``written``): its n_range or ladder for a resolution, its fd_dt or else the scene's
        t_final for a step count, its own dimension or else case_defaults' for a case dimension, the
        scene's key for the physics."""
        where = f"candidates[{i}]"
        if e.name == "n":
            key = "ladder" if self.rungs else "n_range"
            value = list(self.rungs) if self.rungs else [self.n_lo, self.n_hi]
            return SettingError(scene.key(f"{where}.{key}"), value, e.allowed)
        if e.name == "courant":
            return SettingError(scene.key(f"{where}.courant"), e.value, e.allowed)
        if e.name == "dt0" and self.case.method == "fd" and "fd_dt" in written:
            return SettingError(scene.key(f"{where}.fd_dt"), e.value, e.allowed)
        if e.name == "dt0" and self.dt0 is not None:  # a particle step of its own: too many steps to t_final
            least = max_first_step(scene.t_final, self.case.dt_growth)
            return SettingError(
                scene.key(f"{where}.dt0"),
                self.dt0,
                f"a number >= {least:.3g} [T]: a first step that reaches t_final = {scene.t_final:g} in at most "
                f"{MAX_STEPS:,} steps",
            )
        if e.name == "dt0":  # a step the scene does not set: the time it must reach is the key
            g = self.case.dt_growth
            try:
                most = e.value * MAX_STEPS if g == 1.0 else e.value * (g**MAX_STEPS - 1.0) / (g - 1.0)
            except OverflowError:
                most = math.inf
            fd = self.case.method == "fd"
            hint = f"; or give {where} an fd_dt >= {max_first_step(scene.t_final, g):.3g}" if fd else ""
            return SettingError(
                scene.key("t_final"),
                scene.t_final,
                f"a number in (0, {most:.6g}] [T]: what {self.label} ({where}) reaches in at most {MAX_STEPS:,} "
                f"steps of its first step {e.value:g}{hint}",
            )
        if e.name in _CASE_DIMS:
            key = scene.key(f"{where}.{e.name}") if e.name in written else f"case_defaults.{e.name}"
            return SettingError(key, e.value, e.allowed)
        if e.name in ("kernel", "advection", "fd_dt", "ladder"):
            return SettingError(scene.key(f"{where}.{e.name}"), e.value, e.allowed)
        return SettingError(scene.key(e.name), e.value, e.allowed)

    def check_reactive(self, key, i: int) -> None:
        """SettingError naming candidate i's scheme (``key``: the scene's key path) unless it can carry a
        reaction: MTPT's symmetric transfer (REACTIVE_SCHEMES), not the authors' loop, which moves one
        species."""
        if self.case.method == "mtpt" and self.case.scheme not in REACTIVE_SCHEMES:
            raise SettingError(
                key(f"candidates[{i}].scheme"),
                self.case.scheme,
                f"{', '.join(REACTIVE_SCHEMES)} in a reactive scene: the transfer moves every species by one matrix",
            )


@dataclass(frozen=True)
class Scene:
    """A scene's physics, target and candidates (defaults: settings.SCENE)."""

    name: str
    D: float
    v: float
    t_final: float
    source: Source
    omega: float
    fd_length: float
    measure: str
    value: float
    realisations: int
    candidates: tuple[Candidate, ...]
    cost: tuple = ()  # ((method, (seconds a step, seconds a unit of work)), ...)
    budget: float = math.inf  # the most counted cost of one run [s]
    paper_runs: frozenset = frozenset()  # candidates whose runs are the paper run's own (Scenes)
    paper_pattern: str = ""  # the paper run's table pattern, for those
    max_realisations: int = 0  # the most realisations of a particle rung, in blocks of ``realisations`` (0: 4 x)
    reaction: Reaction | None = None  # A -> C or A + B -> C (core/reactions.py); None: conservative
    # the source's mass let out at a rate over time (core/release.py; end None: up to t_final, also where the
    # config's until is t_final or later); None: all of it at t = 0
    release: Release | None = None

    @property
    def blocks(self) -> int:
        """The most seed blocks of ``realisations`` a particle rung may run (scene_search.seeds)."""
        return self.max_realisations // self.realisations if self.max_realisations else MAX_BLOCKS

    def cost_model(self, method: str) -> StepWork:
        """The scene's cost model of a method's runs (``cost``: seconds a step, seconds a unit of work;
        core/runcost.StepWork, units as the run tables' `work` counts them); in a reactive scene each
        times its method's factor of settings.REACTIVE_COST (what the reaction adds to the transport)."""
        per_step, per_work = dict(self.cost)[method]
        if self.reaction is not None:
            on_step, on_work = REACTIVE_COST.get(method, (1.0, 1.0))
            per_step, per_work = per_step * on_step, per_work * on_work
        return StepWork(per_step, per_work)

    def cost_s(self, method: str, steps: float, work: float) -> float:
        """A run's counted cost: steps and work times the scene's unit costs [s]."""
        return self.cost_model(method).counted(Tally(steps, work))

    def run_cost(self, candidate: Candidate, n: int) -> float:
        """The counted cost of one run of ``candidate`` at resolution n, known before it runs: its time
        steps and work (particles, or FD's n + 1 nodes, times steps; MTPT's substeps, if any, come on
        top in the run's own count) times the scene's unit costs (cost_model: a reactive scene's with
        its reaction's factors) [s]."""
        cfg = self.run_config(candidate, n)
        return self.cost_model(cfg.method).seconds(cfg)

    def key(self, key: str) -> str:
        """The config key path of ``key`` in this scene (key_path)."""
        return key_path(self.name, key)

    def same_as(self, i: int) -> int:
        """The index of the first candidate equal to candidate i (i itself, unless at v = 0 two FD
        candidates differ only in their advection scheme: their runs are one)."""
        return self.candidates.index(self.candidates[i])

    @property
    def dim(self) -> int:
        """The scene's dimensions: 2 with a 2-D source (core/plane.py), else 1."""
        return 2 if plane.is_plane(self.source) else 1

    @property
    def n_points(self) -> int:
        """The measurement points a run's SSE_points sums over: 15 on the line, a 15 x 15 lattice in 2-D."""
        return MEASUREMENT_POINTS**self.dim

    @property
    def reference(self):
        """The exact solution at the observation time (2-D: core/reference2d.Reference2D); with a release,
        what its runs are measured against (RunConfig.reference: core/released.py's plume, whose moments
        place the measurement points)."""
        if self.release is not None:
            kind = ReleasedPlume2D if self.dim == 2 else ReleasedPlume
            return kind(self.source, self.D, self.v, self.t_final, self.release, self.t_final)
        if self.dim == 2:
            return Reference2D(self.source, self.D, self.v, self.t_final)
        return Reference(self.source, self.D, self.v, self.t_final)

    @property
    def points(self):
        """The measurement points at t_final, as a run at the scene's v has them (RunConfig.points; a run
        computed at rest has them less frame_shift): a span on the line, the plume's 15 x 15 lattice in
        2-D [L]."""
        exact = self.reference
        return exact.points() if self.dim == 2 else exact.points(self.points_span)

    @property
    def speed(self) -> float:
        """|v| [L/T]."""
        return math.hypot(*self.v) if self.dim == 2 else abs(self.v)

    @property
    def d_along(self) -> float:
        """The dispersion the grid Peclet number divides by: D, or in 2-D the tensor's largest
        eigenvalue (D_L in a flow) [L^2/T]."""
        return plane.major(self.D) if self.dim == 2 else self.D

    @property
    def points_span(self) -> float:
        """The width the measurement points span, whatever the FD window: 2 REACH sqrt(2 variance)
        of the exact plume at t_final (the paper's 12 at its t = 1000), or the source's extent
        widened by REACH sqrt(4 D t_final) each side where that is less (a wide box, whose variance
        overstates its reach); a release's streak of puffs, |v| A long after A of releasing, adds half its
        length to the extent [L]."""
        exact = self.reference
        by_variance = REACH * math.sqrt(2.0 * exact.variance)
        streak = 0.0 if self.release is None else 0.5 * abs(self.v) * exact.ages()[1]
        by_extent = self.source.half_width + streak + REACH * math.sqrt(4.0 * self.D * self.t_final)
        return 2.0 * min(by_variance, by_extent)

    @property
    def peclet(self) -> float:
        """v L / D with L the FD window: how far advection outruns dispersion over the scene [-]."""
        return self.speed * self.fd_length / self.d_along

    def runs_at_rest(self, candidate: Candidate) -> bool:
        """Whether a candidate's runs are computed at rest (v = 0) and stand for the scene's carried
        plume. Galilean invariance: in a uniform flow each particle's step is its step at rest plus
        v dt (PT's and MTPT's walks alike; MTPT's transfer depends on separations only), and the
        measurement points and the exact plume are carried by v t with the particles, so every error
        and measure of a run at v is that of the run at rest, to the round-off of x + v t
        (tests/test_rest_frame.py).
        Scenes that differ only in v thus share their particle runs (the identity digests settings).
        Not FD, whose grid and advection scheme the flow sets; not a reactive scene, whose B need not
        move with A; not a scene with a release, whose source stays where it is while the flow carries
        what it has let out (at rest every puff would start at the source's place, in the flow each
        starts there too but its elders have moved on: no one shift maps the two); not a 2-D scene whose
        measurement lattice turns with v (an isotropic plume's axes are along v: Reference2D.axes),
        whose points at rest would be others."""
        if candidate.case.method == "fd" or self.reaction is not None or self.speed == 0.0:
            return False
        if self.release is not None:
            return False
        if self.dim == 1:
            return True
        # the axes at rest and in the flow: one lattice (up to a common sign, which only reorders it)
        rest = Reference2D(self.source, self.D, (0.0, 0.0), self.t_final).axes()[1]
        moving = self.reference.axes()[1]
        return bool(np.array_equal(rest, moving) or np.array_equal(rest, -moving))

    def frame_shift(self, candidate: Candidate, t: float):
        """What the scene's frame adds to a position in a candidate's runs at time t: v t where they are
        computed at rest (runs_at_rest), else 0; a pair in 2-D [L]. A run's state (particle positions)
        plus this is where the scene's plume is."""
        if not self.runs_at_rest(candidate):
            return np.zeros(2) if self.dim == 2 else 0.0
        return np.asarray(self.v, dtype=np.float64) * t if self.dim == 2 else self.v * t

    def settings(self, candidate: Candidate) -> dict:
        """The run settings of a candidate's runs (RunConfig's fields besides case and seed): a particle
        candidate's at rest where runs_at_rest says so."""
        still = self.runs_at_rest(candidate)
        out = {
            "D": self.D,
            "t_final": self.t_final,
            "omega": self.omega,
            "fd_length": self.fd_length,
            "source": self.source.record(),
            "v": 0.0 if still else self.v,
        }
        if self.dim == 2:  # the tensor and v as lists; the points are the plume's lattice, not a span
            out.update(D=[list(row) for row in self.D], v=[0.0, 0.0] if still else list(self.v))
        else:
            out["window"] = self.points_span  # the measurement points span the plume, at rest too
        if self.reaction is not None:  # only then: a conservative scene's runs keep their identity
            out["reaction"] = self.reaction.record()
        if self.release is not None:  # likewise: {rate, start, end}, as RunConfig reads it back
            out["release"] = asdict(self.release)
        if candidate.case.method == "fd":
            if candidate.courant is None:
                out["dt0"] = candidate.fd_dt
            else:  # only when set: the runs of a candidate without it keep their identity
                out["courant"] = candidate.courant
            if self.v != 0.0:
                out["advection"] = candidate.advection
        elif candidate.dt0 is not None:  # only when set, as courant
            out["dt0"] = candidate.dt0
        return out

    def identity(self, candidate: Candidate) -> str:
        """What a run's file is keyed by besides its case and seeds: a digest of its settings, so that
        two scenes share a run only when their physics (and FD's scheme and step) are equal."""
        return digest(self.settings(candidate))

    def run_config(self, candidate: Candidate, n: int, seed: int = 0, carried: bool = False) -> RunConfig:
        """The checked run of a candidate at resolution n, as its jobs run it (settings); ``carried``:
        at the scene's own v, the run that one at rest stands for (runs_at_rest), as the checks judge it."""
        settings = self.settings(candidate)
        settings["source"], settings["reaction"], settings["release"] = self.source, self.reaction, self.release
        if carried:
            settings["v"] = self.v
        return RunConfig.for_case(replace(candidate.case, n=n), seed=seed, **settings).resolved()

    def half_step(self, candidate: Candidate) -> Candidate:
        """The candidate at half its time step at every time: FD's fd_dt or Courant number halved; a
        particle's dt_n = dt0 g^n is dt0 + (g - 1) t at time t, so dt0 and g - 1 halved (a fixed step
        halved). Its runs are of their own identity: the check that an answer holds at a finer step."""
        if candidate.case.method == "fd":
            if candidate.courant is not None:
                return replace(candidate, courant=candidate.courant / 2.0)
            return replace(candidate, fd_dt=candidate.fd_dt / 2.0)
        dt0 = self.run_config(candidate, candidate.n_lo).dt0  # its own, or the time section's
        growth = 1.0 + (candidate.case.dt_growth - 1.0) / 2.0
        return replace(candidate, dt0=dt0 / 2.0, case=replace(candidate.case, dt_growth=growth))

    @classmethod
    def from_config(cls, name: str, spec, case_defaults: Mapping | None = None) -> Scene:
        """The scene at config key scenes.<name>: ``spec`` as written (parsed here by the scene's model,
        core/typed.py, as the workflow parses it) or that model parsed; SettingError naming the key
        path of a bad value, also for the rules that need the built scene and its runs."""
        s = spec if isinstance(spec, SPEC) else validate(SPEC, spec, functools.partial(_where, name))
        key = functools.partial(key_path, name)
        s, release = _release(key, s)  # the source's keys apart from its release's
        if _plane_keys(s):
            return cls._in_plane(name, s, key, case_defaults, release)
        D, v, t_final, r = s.D, s.v, s.t_final, s.realisations
        source = _source(key, s.source)
        reaction = _reaction(key, s.reaction)
        extent = _extent(source, reaction)  # the domains hold a second species' plume too
        span = 2.0 * (extent + s.margin * math.sqrt(2.0 * D * t_final))
        omega = span + 2.0 * abs(v) * _released_for(release, t_final) if s.omega is None else s.omega
        fd_length = span if s.fd_length is None else s.fd_length
        if s.fd_length is not None:  # from the margin it holds the plume by the margin's range
            scene_checks.check_window(key, fd_length, extent, D, t_final)
        if reaction is not None:  # B's plume, if any, within the domains
            try:
                reaction.check_b_within(source.centre, min(omega, fd_length), REACH * math.sqrt(4.0 * D * t_final))
            except ReactionError as e:
                raise SettingError(key(f"reaction.{e.param}"), e.value, e.allowed) from None
        cands = tuple(
            Candidate.from_spec(c, case_defaults or {}, lambda k, i=i: key(f"candidates[{i}].{k}"))
            for i, c in enumerate(s.candidates)
        )
        scene_checks.check_distinct(key, cands)
        if v == 0:  # nothing to advect: FD's scheme and Courant number are no part of the runs (the step is
            # fd_dt, its own or the default); twins keep their index (same_as)
            cands = tuple(replace(c, advection="none", courant=None) for c in cands)
        cost = tuple((m, tuple(pair)) for m, pair in sorted({**_DEFAULTS["cost"], **s.cost}.items()))
        budget = math.inf if s.budget is None else s.budget
        most = s.max_realisations or min(MAX_BLOCKS, MAX_REALISATIONS // r) * r
        scene = cls(name, D, v, t_final, source, omega, fd_length, s.target.measure, s.target.value, r, cands, cost)
        scene = replace(scene, budget=budget, max_realisations=most, reaction=reaction, release=release)
        scene_checks.check_reach(scene)
        for i, c in enumerate(cands):  # every candidate's runs must fit their domains, at both ends
            c.check_runs(scene, i, s.candidates[i].model_fields_set)
        scene_checks.check_reactive(scene)  # after the runs: the reference's points are a run's
        defined.check(scene, defined.closed_form(scene))  # a target its closed-form reference can judge
        return scene

    @classmethod
    def _in_plane(cls, name: str, s, key, case_defaults: Mapping | None, release: Release | None = None) -> Scene:
        """A 2-D scene (issue 52): v [vx, vy], D {L, T} or {x, y}, a 2-D source (and its ``release``); its
        domains the source's extent plus ``margin`` sd of 2 D t_final along each axis (core/plane.source_reach;
        the particles' also the path |v| t_e a release's first puffs travel while the source stays), every
        candidate's runs checked at both ends of its ladder (core/plane.check)."""
        _check_plane_keys(s, key)
        if s.reaction is not None:
            raise SettingError(
                key("reaction"),
                s.reaction.model_dump(exclude_unset=True),
                "absent in a 2-D scene: 2-D reactions do not exist yet",
            )
        v = tuple(float(u) for u in s.v) if isinstance(s.v, list) else (0.0, 0.0)
        origin = s.source == _DEFAULTS["source"]  # the default, a point at the origin, in the plane
        source = _source2d(key, {"kind": "point", "x0": [0.0, 0.0]} if origin else s.source)
        try:
            D = plane.tensor(dispersion_tensor(v, s.D.tensor_spec()))
        except ValueError as e:
            where = str(e).split(":", 1)[0]
            raise SettingError(key(where if where.startswith("D") else "D"), s.D.tensor_spec(), str(e)) from None
        t_final, r = s.t_final, s.realisations
        sd = np.sqrt(np.diag(2.0 * np.asarray(D) * t_final))  # of 2 D t_final along each axis
        span = 2.0 * float(np.max(plane.source_reach(source) + s.margin * sd))
        path = np.abs(np.asarray(v)) * _released_for(release, t_final)  # 0 without a release
        omega = 2.0 * float(np.max(plane.source_reach(source) + s.margin * sd + path)) if s.omega is None else s.omega
        fd_length = span if s.fd_length is None else s.fd_length
        cands = tuple(
            Candidate.from_spec(c, case_defaults or {}, lambda k, i=i: key(f"candidates[{i}].{k}"))
            for i, c in enumerate(s.candidates)
        )
        scene_checks.check_distinct(key, cands)
        if not any(v):  # nothing to advect: as on the line, FD's scheme and Courant number are no part of the runs
            cands = tuple(replace(c, advection="none", courant=None) for c in cands)
        # the 1-D default (as the workflow's schema fills it in) is no cost a user wrote: the plane's is
        written = {} if _same_cost(s.cost, _DEFAULTS["cost"]) else s.cost
        cost = tuple((m, tuple(pair)) for m, pair in sorted({**dict(PLANE_COST), **written}.items()))
        budget = math.inf if s.budget is None else s.budget
        most = s.max_realisations or min(MAX_BLOCKS, MAX_REALISATIONS // r) * r
        scene = cls(name, D, v, t_final, source, omega, fd_length, s.target.measure, s.target.value, r, cands, cost)
        scene = replace(scene, budget=budget, max_realisations=most, release=release)
        for i, c in enumerate(cands):  # every candidate's runs must fit their domains, at both ends
            c.check_runs(scene, i, s.candidates[i].model_fields_set)
        scene_checks.check_release_points(scene)  # no measurement point where the exact plume is infinite
        defined.check(scene, defined.closed_form(scene))
        return scene


def _same_cost(a: Mapping, b: Mapping) -> bool:
    """Whether two cost models give every method the same two unit costs."""
    return {m: tuple(map(float, p)) for m, p in a.items()} == {m: tuple(map(float, p)) for m, p in b.items()}


def _plane_keys(s) -> bool:
    """Whether the parsed scene ``s`` writes any 2-D key: v a pair, D a mapping, a source with pairs."""
    source = s.source if isinstance(s.source, Mapping) else {}
    return isinstance(s.v, list) or not isinstance(s.D, (int, float)) or plane.source_of(source) is not None


def _check_plane_keys(s, key) -> None:
    """SettingError naming the first key written in its 1-D form in a scene that writes 2-D ones (v = 0
    and the default source, a point at the origin, read the same in either form)."""
    if not isinstance(s.v, list) and s.v != 0.0:
        raise SettingError(
            key("v"), s.v, "a pair [vx, vy] in a 2-D scene (its D or source is 2-D): 1-D and 2-D keys mixed"
        )
    if isinstance(s.D, (int, float)):
        raise SettingError(key("D"), s.D, "{L: D_L, T: D_T} or {x: Dx, y: Dy} in a 2-D scene: 1-D and 2-D keys mixed")
    if s.source != _DEFAULTS["source"] and plane.source_of(s.source) is None:
        raise SettingError(
            key("source"), s.source, "a 2-D source (x0 a pair, or x and y) in a 2-D scene: 1-D and 2-D keys mixed"
        )


def _source2d(key, spec):
    """The 2-D source at scenes.<name>.source, else SettingError naming its key path."""
    try:
        return Source2D.of(**spec)
    except SourceError as e:
        raise SettingError(key(f"source.{e.param}"), e.value, e.allowed) from None


def _release(key, s):
    """(the parsed scene ``s`` with its source's keys only, the Release at scenes.<name>.source.release or
    None); a release still on at t_final (until >= t_final) is the open one, whose runs it shares.
    SettingError names the key path (the model, core/typed.py, has held every key to its range)."""
    spec = s.source.get("release") if isinstance(s.source, Mapping) else None
    if spec is None:
        return s, None
    try:
        release = Release.from_spec(spec)
    except ReleaseError as e:
        raise SettingError(key(f"source.release.{e.param}"), e.value, e.allowed) from None
    if release.end is not None and release.end >= s.t_final:
        release = replace(release, end=None)
    source = {k: value for k, value in s.source.items() if k != "release"}
    return s.model_copy(update={"source": source}), release


def _released_for(release: Release | None, t_final: float) -> float:
    """t_e = min(until, t_final), when a release stops letting mass out by t_final (0 without one) [T]: the
    particles' domain, carried by the flow from the source since t = 0, has left the source |v| t_e behind
    by then (RunConfig's MTPT check of a release holds omega to it)."""
    if release is None:
        return 0.0
    return released_span(release, t_final, t_final)[1]


def _where(name: str, path: list) -> str:
    """The config key of the key ``path`` (keys and indexes) within scene ``name`` (key_path)."""
    return key_path(name, typed_key_path(path)) if path else key_path(name, "")[:-1]


def _extent(source: Source, reaction: Reaction | None) -> float:
    """The half width around A's centre that the domains must hold at t = 0: A's source, and B's
    plume where A + B -> C has one (both domains are centred on A's source) [L]."""
    if reaction is None or reaction.b_source is None:
        return source.half_width
    b = reaction.b_source
    return max(source.half_width, abs(b.centre - source.centre) + b.half_width)


def _source(key, spec) -> Source:
    """The source at scenes.<name>.source (Source.from_spec), else SettingError naming its key path
    (``key``: a key's path in the scene)."""
    try:
        return Source.from_spec(spec)
    except SourceError as e:
        raise SettingError(key(f"source.{e.param}"), e.value, e.allowed) from None


def _reaction(key, spec) -> Reaction | None:
    """The reaction at scenes.<name>.reaction (Reaction.from_spec), else SettingError naming its key path."""
    if spec is None:
        return None
    try:
        return Reaction.from_spec(spec.model_dump(exclude_unset=True, warnings=False))
    except ReactionError as e:
        raise SettingError(key(f"reaction.{e.param}"), e.value, e.allowed) from None


class Scenes(Mapping):
    """The scenes of config `scenes` by name, each built and checked when a requested target first
    needs it (as the optimum searches are), so that a run that draws no scene is never blocked by
    one; a bad value is still refused before any of its jobs, naming its key path."""

    def __init__(self, config: Mapping, check=None, paper=None):
        user, sweep = dict(config.get("scenes") or {}), peclet_scenes(config)
        for name in user:
            if not (isinstance(name, str) and USER_NAME.fullmatch(name)):
                raise SettingError(
                    f"scenes.{name}",
                    "(a scene)",
                    "a name of letters, digits and _ (peclet-<k> and peclet2d-<k> name the sweeps' scenes)",
                )
        self._specs = {**user, **sweep}
        self.sweep = tuple(sweep)  # the Peclet sweeps' scenes (figures/scenes_peclet.png draws these only)
        self._defaults = config.get("case_defaults", {})
        self._check = check  # a further check of each built scene (the workflow's memory check)
        self._paper = paper  # (the paper run's table pattern, its RunConfig of a Case at seed 0)
        self._built: dict[str, Scene] = {}
        # The jobs' lookups by digest, each filled once, a scene at a time as lookups reach it (_find):
        self._runs: dict[str, tuple[Scene, Candidate]] = {}  # identity -> the scene and runs it keys
        self._references: dict[str, dict] = {}  # a reference's key -> its physics
        self._indexed: set[tuple] = set()  # the parts of scenes already in these

    def __getitem__(self, name: str) -> Scene:
        if name not in self._built:
            scene = Scene.from_config(name, self._specs[name], self._defaults)
            if self._check is not None:
                self._check(scene)
            if self._paper is not None:
                scene = shares_paper_runs(scene, *self._paper)
            self._built[name] = scene
        return self._built[name]

    def __iter__(self):
        return iter(self._specs)

    def __len__(self) -> int:
        return len(self._specs)

    def spec(self, name: str) -> dict:
        """The config of scene ``name`` as written (a Peclet scene: its base with its v)."""
        return self._specs[name]

    def _find(self, index: dict, key: str, parts, add):
        """``index[key]``, adding the scenes' ``parts`` to ``index`` in their order, each once in the
        life of this mapping (``add(part)``), until it holds ``key``; None if no part has it. A lookup
        thus builds the scenes only up to the one it needs (a bad scene after it blocks none of its
        jobs), and no identity is digested twice however many jobs look one up."""
        for part in parts:
            if key in index:
                break
            if part not in self._indexed:
                add(part)
                self._indexed.add(part)
        return index.get(key)

    def _add_runs(self, part: tuple) -> None:
        """The identities of one scene's candidates' runs (their half-step twins' if ``halved``); the
        first scene and candidate of an identity keep it (equal identities: equal settings)."""
        _, name, halved = part
        scene = self[name]
        for candidate in scene.candidates:
            runs = scene.half_step(candidate) if halved else candidate
            self._runs.setdefault(scene.identity(runs), (scene, runs))

    def _owner(self, identity: str) -> tuple[Scene, Candidate]:
        # every scene's own runs first; only then those at half a step (an answer's check), whose
        # candidates a particle's resolved first step must be built for
        parts = (("runs", name, halved) for halved in (False, True) for name in self)
        found = self._find(self._runs, identity, parts, self._add_runs)
        if found is None:
            raise KeyError(f"no scene candidate has runs keyed {identity!r}")
        return found

    def settings(self, identity: str) -> dict:
        """The run settings of the candidate runs keyed by ``identity`` (Scene.identity)."""
        scene, candidate = self._owner(identity)
        return scene.settings(candidate)

    def reference_path(self, identity: str) -> str:
        """The reference file that the reactive runs keyed by ``identity`` are judged against."""
        from .reference import path

        return path(self._owner(identity)[0])

    def reference_physics(self, key: str) -> dict:
        """The physics of the reference keyed ``key`` (reference.digest): all that its file depends on,
        the params of rule scene_reference, so that editing a target or a candidate reruns nothing."""
        from . import reference

        def add(part: tuple) -> None:
            scene = self[part[1]]
            if scene.reaction is not None:
                physics = reference.physics(scene)
                self._references.setdefault(reference.key(physics), physics)

        found = self._find(self._references, key, (("reference", name) for name in self), add)
        if found is None:
            raise KeyError(f"no reactive scene has a reference keyed {key!r}")
        return copy.deepcopy(found)  # the index's own stays as built


def shares_paper_runs(scene: Scene, pattern: str, paper_run) -> Scene:
    """``scene`` with its candidates whose runs are the paper run's own marked (``paper_runs``): the
    same RunConfig as ``paper_run(case)`` gives (the paper's physics, first step and numerics) and
    the same measurement points. Their tables are the paper's (``pattern``): the paper scene
    recomputes none of the paper's runs, and a rung it adds is one more file of the paper run. A
    particle candidate of a carried scene of the paper's physics shares them too: its runs are
    computed at rest (Scene.runs_at_rest), with the paper's RunConfig and points exactly."""
    shared = set()
    if scene.reaction is not None or scene.dim == 2 or scene.release is not None:  # none of their runs is the paper's
        return replace(scene, paper_pattern=pattern)
    for ci, cand in enumerate(scene.candidates):
        mine = scene.run_config(cand, cand.n_lo)
        try:
            theirs = paper_run(replace(cand.case, n=cand.n_lo))
        except (SettingError, ValueError):
            continue
        same_points = all(
            mine.points(t).tobytes() == theirs.points(t).tobytes() for t in (0.0, scene.t_final)
        )  # a run at rest: its points do not move; FD's in a flow would, and then v differs anyway
        if replace(mine, window=None) == theirs and same_points:
            shared.add(ci)
    return replace(scene, paper_runs=frozenset(shared), paper_pattern=pattern)


def peclet_scenes(config: Mapping) -> dict[str, dict]:
    """The scenes of the Peclet sweeps (SWEEPS: config `scenes_peclet`, `scenes_peclet2d`) as written:
    each base at each velocity, named <prefix><k>, a name no scene of config `scenes` can have. A 2-D
    sweep's v is a speed along its `angle`. Each sweep is parsed by its model (core/typed.py: a base
    without v, velocities ascending); SettingError names the key."""
    out = {}
    for prefix, (section, dim) in SWEEPS.items():
        sweep = config.get(section)
        if not sweep:
            continue
        model = shared().ScenesPeclet if dim == 1 else shared().ScenesPeclet2D
        parsed = validate(model, sweep, lambda path, section=section: typed_key_path([section, *path]))
        for k, speed in enumerate(parsed.v):
            out[f"{prefix}{k}"] = {**sweep["base"], "v": speed if dim == 1 else _along(speed, parsed.angle)}
    return out


def has_sweep(config: Mapping) -> bool:
    """Whether the config sets a Peclet sweep (figures/scenes_peclet.png draws them)."""
    return any(config.get(section) for section, _ in SWEEPS.values())


def _along(speed: float, angle: float) -> list[float]:
    """The velocity of ``speed`` at ``angle`` degrees from the x axis; exact along an axis or a diagonal
    (cos 45 = sin 45 as Python's math gives them, as a user writes 0.7071067811865476)."""
    a = math.radians(angle)
    c, s = math.cos(a), math.sin(a)
    if angle % 90 == 0:
        c, s = float(round(c)), float(round(s))
    elif angle % 45 == 0:
        c, s = math.copysign(math.sqrt(0.5), c), math.copysign(math.sqrt(0.5), s)
    return [speed * c, speed * s]


def scenes(config: Mapping, check=None, paper=None) -> Scenes:
    """Every scene of a config by name, each checked when first used (Scenes; ``check``: a further
    check of each, given the Scene; ``paper``: the paper run's table pattern and RunConfig of a case,
    whose runs the scenes of the paper's physics share: shares_paper_runs)."""
    return Scenes(config, check, paper)
