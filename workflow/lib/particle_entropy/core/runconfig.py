"""One simulation's settings (a Case plus physics and numerics), their defaults and checks."""

from __future__ import annotations

import math
import sys
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from . import plane
from .case import DEFAULT, Case, SettingError, check_range
from .measures import settling_time
from .reactions import Reaction
from .reference import Reference
from .registry import ADVECTION_SCHEMES, COURANT_LIMIT, COURANT_SLACK, DEFAULT_ADVECTION, DEFAULT_KERNEL
from .release import Release
from .run_settings import BY_NAME, MAX_SEED, PAPER, Setting
from .sources import Source, source_names
from .timegrid import MAX_STEPS, count_text, max_first_step, step_count

PAPER_SOURCE = Source.of("point", x0=0.0)  # the paper's delta at x = 0
# FD's fewest intervals: a node at the source's x = 0 (an even number) whose 3-point stencil reaches
# an interior node on either side. With 2 the one interior node's neighbours are both zero ends: its
# mass only drains into them (5 % by t = 1000 at the paper's settings) and never spreads (H_C stays 0).
FD_MIN_INTERVALS = 4


def check_setting(setting: Setting, value):
    """``value`` if ``setting`` allows it, else SettingError naming the setting and its range."""
    if setting.choices is not None:
        if value not in setting.choices:
            raise SettingError(setting.name, value, setting.allowed())
        return value
    if setting.none and value is None:
        return value
    if setting.kind == "integer":
        whole = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
        if not whole or not setting.low <= value <= setting.high:
            raise SettingError(setting.name, value, setting.allowed())
        return value
    return check_range(setting.name, value, setting.low, setting.high, open_low=setting.open_low)


# The widest reconstruction grid a run may build (models/pt.kernel_grid: spacing min(0.1, spread / 4,
# h / 2), the bins Omega / N), as MAX_STEPS bounds the steps: 800 MB an array; the plume a grid
# must hold is the source and PLUME_SIGMAS standard deviations either side of it.
MAX_GRID_POINTS = 100_000_000
GRID_SPACING = 0.1
PLUME_SIGMAS = 8.0


def plume_span(cfg: RunConfig) -> float:
    """The width a run's particles spread over by t_final: the source's extent plus PLUME_SIGMAS
    sqrt(2 D t_final) either side [L]."""
    return 2.0 * (cfg.source.half_width + PLUME_SIGMAS * math.sqrt(2.0 * cfg.D * cfg.t_final))


def check_arithmetic(cfg: RunConfig) -> None:
    """Refuse finite settings whose derived widths, variances or grids overflow or underflow, by
    name with the range allowed at the other settings: each variance 2 D t (t_final, dt0, and
    the fixed kernel's time) a normal float, the plume within a grid of MAX_GRID_POINTS at
    spacing GRID_SPACING (t_final), and the fixed kernel's grid within MAX_GRID_POINTS too."""
    tiny = sys.float_info.min
    times = ["t_final", "dt0"] + (["fixed_kernel_time"] if (cfg.method, cfg.kernel) == ("pt", "fixed") else [])
    for name in times:
        t = getattr(cfg, name)
        variance = 2.0 * cfg.D * t
        if not math.isfinite(4.0 * math.pi * math.e * variance):  # E = sqrt(2 pi e variance)
            raise SettingError("D", cfg.D, f"a number with 2 D {name} finite ({name} = {t:g})")
        if variance < tiny:  # a subnormal (or zero) variance: 1 / sqrt(variance) overflows
            raise SettingError(
                name,
                t,
                f"a number with 2 D {name} a normal float (>= {tiny:.3g}): >= {tiny / (2 * cfg.D):.3g} "
                f"for D = {cfg.D:g}",
            )
    check_plume_width(cfg)
    if (cfg.method, cfg.kernel) == ("pt", "fixed"):
        _check_kernel_grid(cfg, plume_span(cfg))


def check_plume_width(cfg) -> None:
    """Refuse a t_final whose plume (plume_span; ``cfg``: anything with D, t_final and source, a
    RunConfig or a scene) is wider than a grid of MAX_GRID_POINTS at spacing GRID_SPACING."""
    widest = MAX_GRID_POINTS * GRID_SPACING
    span = plume_span(cfg)
    if span > widest:
        room = (widest / 2.0 - cfg.source.half_width) / PLUME_SIGMAS
        raise SettingError(
            "t_final",
            cfg.t_final,
            f"a number in (0, {room * room / (2.0 * cfg.D):.6g}] for D = {cfg.D:g}: a plume 2 x {PLUME_SIGMAS:g} "
            f"sqrt(2 D t_final) wide at most {widest:g}, the {MAX_GRID_POINTS:,} points of a grid at spacing "
            f"{GRID_SPACING:g} (this one {span:.3g})",
        )


def _check_kernel_grid(cfg: RunConfig, span: float) -> None:
    """The fixed kernel's grid (models/pt.kernel_grid: the plume plus 6 h either side, at spacing
    at least min(0.1, h / 4)) within MAX_GRID_POINTS: h = sqrt(2 D fixed_kernel_time) neither so
    narrow that the spacing h / 4 needs more, nor so wide that its 12 h at spacing 0.1 do."""
    h = math.sqrt(2.0 * cfg.D * cfg.fixed_kernel_time)
    points = (span + 12.0 * h) / min(GRID_SPACING, h / 4.0)
    if points > MAX_GRID_POINTS:
        h_lo = 4.0 * span / (MAX_GRID_POINTS - 48.0)  # (span + 12 h) / (h / 4) = MAX_GRID_POINTS
        h_hi = (MAX_GRID_POINTS * GRID_SPACING - span) / 12.0  # (span + 12 h) / 0.1 = MAX_GRID_POINTS
        if h_lo > h_hi:  # no kernel fits: the plume itself is too wide for the grid
            raise SettingError(
                "t_final",
                cfg.t_final,
                f"a plume 2 x {PLUME_SIGMAS:g} sqrt(2 D t_final) = {span:.3g} that a fixed kernel's grid of at most "
                f"{MAX_GRID_POINTS:,} points holds at spacing h / 4 <= {GRID_SPACING:g} (D = {cfg.D:g})",
            )
        lo, hi = h_lo * h_lo / (2.0 * cfg.D), h_hi * h_hi / (2.0 * cfg.D)
        raise SettingError(
            "fixed_kernel_time",
            cfg.fixed_kernel_time,
            f"a number in [{lo:.3g}, {hi:.3g}] for D = {cfg.D:g}, t_final = {cfg.t_final:g}: a kernel "
            f"sqrt(2 D fixed_kernel_time) whose grid has at most {MAX_GRID_POINTS:,} points "
            f"(this one about {points:.3g})",
        )


def first_step_key(method: str, dt_growth: float) -> str:
    """The `time` setting of a run's first step: FD its fixed fd_dt; particles dt0, or fixed_dt
    when the step is fixed (dt_growth 1)."""
    if method == "fd":
        return "fd_dt"
    return "fixed_dt" if dt_growth == 1.0 else "dt0"


def first_step(method: str, dt_growth: float, time: Mapping | None = None) -> float:
    """The first time step of a run from a config's `time` section (the paper's where it has none)."""
    key = first_step_key(method, dt_growth)
    return float((time or {}).get(key, PAPER[key]))


def explicit_fd_stable(r: float) -> bool:
    """Whether explicit FD at r = D dt / dx^2 damps every mode: r < 1/2 strictly (the checkerboard
    mode's amplification factor 1 - 4 r is -1 at r = 1/2), r = 1/2 to round-off counting as 1/2."""
    return r < 0.5 and not math.isclose(r, 0.5, rel_tol=1e-12)


@dataclass(frozen=True)
class RunConfig:
    """One run: a ``Case`` at an N (the model's dimensions), a seed, and the shared physics and
    numerics settings (settings.SETTINGS: their defaults, ranges and meanings)."""

    case: Case
    seed: int = 0
    D: float = PAPER["D"]
    t_final: float = PAPER["t_final"]
    dt0: float | None = None  # None: first_step() with the paper's dt0, fd_dt, fixed_dt
    omega: float = PAPER["omega"]
    fd_length: float = PAPER["fd_length"]
    fixed_kernel_time: float = PAPER["fixed_kernel_time"]
    transfer_method: str = PAPER["transfer_method"]
    transfer_tolerance: float = PAPER["transfer_tolerance"]
    loop_arithmetic: str = PAPER["loop_arithmetic"]
    # the scene (core/sources.py, core/reference.py): the source and a uniform velocity; the paper's is a point at
    # x = 0 at rest. FD's advection scheme is used only when v != 0.
    source: Source = PAPER_SOURCE
    v: float = 0.0
    advection: str = DEFAULT_ADVECTION
    window: float | None = None  # the measurement points' span: None = the paper's (at rest) or fd_length
    # FD in a flow: the step that follows the grid, dt0 = courant dx / |v| (resolved()); None: dt0 as given
    courant: float | None = None
    # an operator applied after each transport step (core/reactions.Reaction: its kinetics and B), or None:
    # a conservative run of one species
    reaction: Reaction | None = None
    # a continuous release of the source's mass (core/release.py: rate q from start to end), or None: the
    # source's unit mass all at t = 0
    release: Release | None = None

    def __post_init__(self):
        if isinstance(self.source, Mapping):  # as a job's settings carry it: a pair x0 (or x and y) is 2-D
            object.__setattr__(self, "source", plane.source_of(self.source) or Source.of(**self.source))
        if plane.is_plane(self.source):  # (vx, vy) and the tensor D, hashable (core/plane.py)
            if isinstance(self.v, (list, tuple, np.ndarray)):
                object.__setattr__(self, "v", plane.pair(self.v))
            if isinstance(self.D, (list, tuple, np.ndarray)):
                object.__setattr__(self, "D", plane.tensor(self.D))
        if isinstance(self.reaction, Mapping):
            object.__setattr__(self, "reaction", Reaction.of(self.reaction))
        if isinstance(self.release, Mapping):  # a config's {rate, from, until}, or the fields {rate, start, end}
            spec = self.release
            object.__setattr__(
                self, "release", Release.from_spec(spec) if {"from", "until"} & set(spec) else Release(**spec)
            )

    @classmethod
    def of(
        cls,
        method: str = "mtpt",
        kernel: str | None = None,
        n: int = 300,
        eta=DEFAULT,
        truncation=DEFAULT,
        dt_growth=DEFAULT,
        scheme=DEFAULT,
        time_grid=DEFAULT,
        **settings,
    ) -> RunConfig:
        """A run from the case's dimensions and ``settings``; an unset (or None) kernel or
        dt_growth takes the method's default (DEFAULT_KERNEL; run_settings.DT_GROWTH for particles, 1 for FD)."""
        case = Case(
            method,
            DEFAULT_KERNEL.get(method) if kernel is None else kernel,
            n,
            eta,
            truncation,
            DEFAULT if dt_growth is None else dt_growth,
            scheme,
            time_grid,
        )
        return cls(case, **settings)

    @classmethod
    def for_case(cls, case: Case, **settings) -> RunConfig:
        """The run of ``case`` (which must have an N) with physics and numerics ``settings``."""
        if case.n is None:
            raise SettingError("n", None, "an integer: a run needs a case at one N")
        return cls(case, **settings)

    # the case's dimensions, read where a model reads its settings
    method = property(lambda self: self.case.method)
    kernel = property(lambda self: self.case.kernel)
    n = property(lambda self: self.case.n)
    eta = property(lambda self: self.case.eta)
    truncation = property(lambda self: self.case.truncation)
    dt_growth = property(lambda self: self.case.dt_growth)
    scheme = property(lambda self: self.case.scheme)
    time_grid = property(lambda self: self.case.time_grid)

    @property
    def dim(self) -> int:
        """The run's dimensions: 2 with a 2-D source (core/plane.py), else 1."""
        return 2 if plane.is_plane(self.source) else 1

    @property
    def at_rest(self) -> bool:
        """The paper's scene: a point source at x = 0 and no flow."""
        return self.source == PAPER_SOURCE and self.v == 0.0

    def reference(self, t: float):
        """The exact solution at time t that this run is measured against (2-D: core/reference2d.py); with a
        release, its released plume (core/released.py): its moments at every t, its scores against the exact
        plume at t_final only, the run's last row (NaN before: the exact plume costs ~10 ms to 2 s a time)."""
        if self.release is not None:
            from .released import ReleasedPlume, ReleasedPlume2D

            kind = ReleasedPlume2D if self.dim == 2 else ReleasedPlume
            return kind(self.source, self.D, self.v, t, self.release, self.t_final, scored=t >= self.t_final)
        if self.dim == 2:
            from .reference2d import Reference2D

            return Reference2D(self.source, self.D, self.v, t)
        return Reference(self.source, self.D, self.v, t)

    def mass(self, t: float) -> float:
        """The run's mass at time t: the source's unit mass, or the mass its release has released by t [M]."""
        return 1.0 if self.release is None else self.release.mass(t)

    def points(self, t: float) -> np.ndarray:
        """The measurement points at time t: the paper's 15 (measures.measurement_points), or a
        scene's over the span ``window`` around its plume (Scene.points_span), carried with the
        plume (Reference.points) [L]."""
        if self.dim == 2:  # a lattice along the plume's principal axes (Reference2D.points)
            return self.reference(t).points()
        if self.window is not None:  # a scene's: its plume's span, whatever its source, v and window
            return self.reference(t).points(self.window)
        return self.reference(t).points(None if self.at_rest else self.fd_length)

    def fd_span(self) -> tuple[float, float]:
        """(first node, length) of the FD grid: the paper's [-L/2, L/2] around the source's
        centre, lengthened by the path v t_final so that the grid holds the plume all the way [L]."""
        path = self.v * self.t_final
        lo = self.source.centre - self.fd_length / 2.0 + min(0.0, path)
        return lo, self.fd_length + abs(path)

    @property
    def dV(self) -> float:
        """A particle's sampling volume dV = Omega / N (the Delta V of Eqs. 5-9; the bin width of Eq. 11);
        in 2-D Omega^2 / N."""
        return self.omega**self.dim / self.n

    @property
    def fd_dx(self) -> float:
        """The FD grid's spacing: fd_length / N at rest, else the span's length / N (grid) [L]."""
        return (self.fd_length if self.at_rest else self.fd_span()[1]) / self.n

    def courant_number(self) -> float:
        """|v| dt0 / dx on the FD grid: the cells the plume crosses in the largest step (FD's step is
        fixed; the exact grid only shortens the last) [-]."""
        return abs(self.v) * self.dt0 / self.fd_dx

    def resolved(self) -> RunConfig:
        """Fill the first step (first_step; FD with a courant: courant dx / |v|) and check every setting."""
        if self.courant is not None and self.dim == 2:
            cfg = replace(self, dt0=plane.courant_step(self))
        elif self.courant is not None:
            self._check_courant()
            cfg = replace(self, dt0=self.courant * self.fd_dx / abs(self.v))
        elif self.dt0 is None:
            dt0 = first_step(self.method, self.dt_growth)
            cfg = replace(self, dt0=dt0)
        else:
            cfg = self
        cfg.check()
        return cfg

    def check(self) -> None:
        # the case dimensions are checked by Case; the shared settings by their definitions
        if not isinstance(self.case, Case) or self.case.n is None:
            raise SettingError("case", self.case, "a Case at one N")
        if self.method == "fd" and (self.n < FD_MIN_INTERVALS or self.n % 2):
            raise SettingError(
                "n",
                self.n,
                f"for fd an even number of intervals >= {FD_MIN_INTERVALS}: a node at x = 0 with an interior node "
                "either side for the 3-point stencil (with 2 its mass only drains into the zero ends)",
            )
        scalars = ("t_final", "dt0", "omega", "fd_length", "fixed_kernel_time", "transfer_tolerance")
        for name in scalars if self.dim == 2 else ("D", *scalars):
            check_setting(BY_NAME[name], getattr(self, name))
        if not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed <= MAX_SEED:
            raise SettingError(
                "seed", self.seed, f"an integer in [0, 2^63 - 1 = {MAX_SEED}] (tables store it as int64)"
            )
        steps = step_count(self.t_final, self.dt0, self.dt_growth)
        if steps > MAX_STEPS and self.courant is not None and self.dim == 1:
            self._check_courant()
            least = max_first_step(self.t_final, 1.0) * abs(self.v) / self.fd_dx
            raise SettingError(
                "courant",
                self.courant,
                f"a Courant number >= {least:.3g} at n = {self.n}: a step courant dx / |v| reaching t_final = "
                f"{self.t_final:g} in at most {MAX_STEPS:,} steps (this one needs {count_text(steps)})",
            )
        if steps > MAX_STEPS:
            raise SettingError(
                "dt0",
                self.dt0,
                f"a first step reaching t_final = {self.t_final:g} in at most {MAX_STEPS:,} steps with dt_growth = "
                f"{self.dt_growth:g}: >= {max_first_step(self.t_final, self.dt_growth):.3g} "
                f"(this one needs {count_text(steps)})",
            )
        if self.dim == 2:  # the plane's own checks (core/plane.py) instead of the line's below
            plane.check(self)
            self._check_release()
            return
        check_arithmetic(self)
        check_setting(BY_NAME["transfer_method"], self.transfer_method)
        check_setting(BY_NAME["loop_arithmetic"], self.loop_arithmetic)
        if not isinstance(self.source, Source):
            raise SettingError("source", self.source, f"a Source ({source_names()})")
        if not (isinstance(self.v, (int, float)) and math.isfinite(self.v)):
            raise SettingError("v", self.v, "a finite number [L/T]")
        if self.advection not in ADVECTION_SCHEMES:
            raise SettingError("advection", self.advection, f"one of {', '.join(ADVECTION_SCHEMES)}")
        self._check_reference()
        self._check_resolution()
        if self.courant is not None:
            self._check_courant()
        self._check_courant_limit()
        if self.method == "fd" and self.kernel == "explicit" and self.v != 0.0:
            raise SettingError(
                "kernel",
                self.kernel,
                f"implicit when v != 0 (v = {self.v:g}): explicit fd has no advection term (models/fd.py: "
                "only the implicit scheme carries the plume)",
            )
        if self.method == "fd" and self.kernel == "explicit":
            dx = self.fd_length / self.n
            r = self.D * self.dt0 / dx**2
            if not explicit_fd_stable(r) or self.dt_growth != 1.0:
                raise SettingError(
                    "dt0",
                    self.dt0,
                    f"explicit fd needs r = D dt / dx^2 < 1/2 with a fixed step (at r = 1/2 its checkerboard mode's "
                    f"factor 1 - 4 r is -1: it never decays): dt0 < {0.5 * dx**2 / self.D:.6g} and dt_growth = 1 for "
                    f"n={self.n} (got r = {r:.6g}, dt_growth = {self.dt_growth}); or use kernel implicit",
                )
        if self.transfer_method in ("taylor", "fgt") and self.truncation is not None:
            raise SettingError(
                "transfer_method",
                self.transfer_method,
                "auto or direct when truncation is set (taylor and fgt sum the whole Gaussian)",
            )
        self._check_release()

    def _check_release(self) -> None:
        """Refuse a release that is not a Release, that starts before 0 (a run starts empty) or at or after
        t_final (nothing would enter), that comes with a reaction (a reactive run's rows count its source's
        unit mass) or with the authors' time grid (whose last step ends past t_final, where a release has
        stopped)."""
        if self.release is None:
            return
        if not isinstance(self.release, Release):
            raise SettingError("release", self.release, "a Release (rate, start, end) or None")
        if not 0.0 <= self.release.start < self.t_final:
            raise SettingError(
                "release",
                self.release,
                f"a start in [0, t_final = {self.t_final:g}): a run starts empty at t = 0 and ends at t_final",
            )
        if self.method != "fd" and self.time_grid == "authors":
            raise SettingError(
                "time_grid", self.time_grid, "exact with a release: the authors' last step ends past t_final"
            )
        if self.reaction is not None:
            raise SettingError(
                "release", self.release, "none in a reactive run: reactions with a release are not built"
            )
        if self.method == "mtpt":
            self._check_release_domain()

    def _check_release_domain(self) -> None:
        """Refuse an MTPT omega that does not hold a release in a flow: the particles' square moves with v
        while the source stays, so that by the release's end t_e = min(end, t_final) the source lies
        |v| t_e behind its centre, with the plume's reach (the source's extent and the spread of 2 D
        t_final, as the instantaneous run's check) beyond it."""
        from .released import released_span

        t_e = released_span(self.release, self.t_final, self.t_final)[1]
        if self.dim == 2:
            D = np.asarray(self.D, dtype=np.float64)
            need = 2.0 * float(np.max(plane.sd_reach(self, D) + np.abs(np.asarray(self.v, dtype=np.float64)) * t_e))
        else:
            need = 2.0 * (abs(self.v) * t_e + self.source.half_width + math.sqrt(2.0 * self.D * self.t_final))
        if self.omega < need:
            raise SettingError(
                "omega",
                self.omega,
                f"a domain >= {need:.6g} for mtpt with a release: its particles move with v while the source "
                f"stays, |v| t_e behind their centre by the release's end t_e = {t_e:g}, with the plume's reach beyond",
            )

    def _check_courant(self) -> None:
        """Refuse a courant outside FD in a flow, or not a number > 0."""
        ok = isinstance(self.courant, (int, float)) and not isinstance(self.courant, bool)
        if not (ok and 0.0 < self.courant < math.inf):
            raise SettingError("courant", self.courant, "a number > 0: the step's Courant number |v| dt / dx")
        if self.method != "fd" or self.v == 0.0:
            raise SettingError(
                "courant",
                self.courant,
                f"no courant for {self.method} at v = {self.v:g}: fd in a flow (v != 0) only, its step following "
                "its grid",
            )

    def _check_courant_limit(self) -> None:
        """Refuse an FD step beyond its advection scheme's Courant limit (registry.COURANT_LIMIT: the
        explicit tvd scheme's |v| dt / dx <= 1, to round-off), naming courant, or else fd_dt."""
        limit = COURANT_LIMIT.get(self.advection)
        if self.method != "fd" or self.v == 0.0 or limit is None:
            return
        cr = self.courant_number()
        if cr <= limit or math.isclose(cr, limit, rel_tol=COURANT_SLACK):
            return
        why = (
            f"advection {self.advection} is explicit: stable and monotone only at a Courant number |v| dt / dx "
            f"<= {limit:g}"
        )
        if self.courant is not None:
            raise SettingError("courant", self.courant, f"a number in (0, {limit:g}]: {why}")
        raise SettingError(
            "fd_dt",
            self.dt0,
            f"a step <= {limit * self.fd_dx / abs(self.v):.6g} at n = {self.n} (dx = {self.fd_dx:.6g}, |v| = "
            f"{abs(self.v):g}): {why}, and this one gives {cr:.6g}; or set courant instead of fd_dt",
        )

    def _check_reference(self) -> None:
        """Refuse settings under which the Gaussian reference (Eq. 2) cannot be computed or an FD
        grid cannot hold it: 2 D t_final must be finite, and the FD domain at least 2 sqrt(2 D
        t_final) long (a plume wider than the grid leaves it: zero mass, -inf entropy)."""
        variance = 2.0 * self.D * self.t_final
        if not math.isfinite(4.0 * math.pi * math.e * variance):  # E = sqrt(2 pi e variance)
            raise SettingError("D", self.D, f"a number with 2 D t_final finite (t_final = {self.t_final:g})")
        width = 2.0 * (self.source.half_width + math.sqrt(variance))
        source = "" if self.source == PAPER_SOURCE else f" + the source's extent {2 * self.source.half_width:.6g}"
        for name, length, models in (("fd_length", self.fd_length, ("fd",)), ("omega", self.omega, ("pt", "mtpt"))):
            if self.method in models and length < width and (self.method != "pt" or not self.at_rest):
                raise SettingError(
                    name,
                    length,
                    f"a domain >= 2 sqrt(2 D t_final){source} = {width:.6g} for D = {self.D:g}, "
                    f"t_final = {self.t_final:g}: the plume would outgrow the "
                    + ("grid" if name == "fd_length" else "particles"),
                )

    def check_domain(self) -> None:
        """The domain checks alone (_check_reference), whatever the grid: a config's FD domain
        lengths before any of its grids (crosschecks.check_fd_domain)."""
        self._check_reference()

    def _check_resolution(self) -> None:
        """Refuse an FD grid whose dx is wider than the plume it measures at t_final: dx > E(t_final),
        the exact dilution index (sqrt(4 pi e D t_final) for the paper's point), i.e. t_final before
        the settling time dx^2 / (4 pi e D) of Section 3. The plume then sits on one node: the
        implicit solution and the sampled reference (Eq. 44, normalised on the same nodes) are both
        that spike, the SSE tends to 0 and COMIC (Eq. 43) to -inf, an extreme score that measures
        nothing. A grid with an advection term (a scene's v != 0) spreads the plume over v dx / 2 of
        numerical dispersion: it does not collapse, a coarse grid scores badly instead. Particles
        (MTPT's Omega / N, binned PT) are not bounded here: runs before their settling time are
        valid and flagged (the `settled` column)."""
        if self.method != "fd" or self.v != 0.0:
            return
        dx = self.fd_span()[1] / self.n
        # a release's oldest mass, released at its start, has spread the longest
        age = self.t_final if self.release is None else self.t_final - self.release.start
        spread = Reference(self.source, self.D, self.v, age).dilution()
        if dx <= spread:
            return
        low = 2.0 * (self.source.half_width + math.sqrt(2.0 * self.D * self.t_final))
        raise SettingError(
            "fd_length",
            self.fd_length,
            f"a length in [{low:.6g}, {self.n * spread:.6g}] for n = {self.n}, D = {self.D:g}, t_final = "
            f"{self.t_final:g}: its grid spacing dx = fd_length / n = {dx:.6g} must not exceed the plume's dilution "
            f"index E = {spread:.6g} at t_final (t_final past the settling time dx^2 / (4 pi e D) = "
            f"{settling_time(dx, self.D):.6g}), else the plume sits on one node and COMIC tends to -inf",
        )

    def rng(self, stream: int = 0) -> np.random.Generator:
        """Generator keyed by (seed, method, N): kernels, eta and schemes share positions and walks.
        Stream 1 feeds the sequential loop's partner orders, so that they leave the walks alone."""
        key = zlib.crc32(f"{self.method}:{self.n}".encode())
        spawn_key = (key,) if stream == 0 else (key, stream)
        return np.random.default_rng(np.random.SeedSequence(entropy=self.seed, spawn_key=spawn_key))

    def case_columns(self) -> dict:
        """The case parameters written beside every row of a result table."""
        D = float(self.D) if self.dim == 1 else plane.major(self.D)  # 2-D: D_L
        return {**self.case.columns(), "D": D, "seed": int(self.seed)}
