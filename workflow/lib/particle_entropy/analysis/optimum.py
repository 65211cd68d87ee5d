"""COMIC-guided resolution: an adaptive search, round by round, for the N minimising mean COMIC (Eq. 43).

Runs are spent where the answer needs them, and the expensive large N only when the minimum
may lie there:
- round 0 runs the lowest ``start_points`` of a coarse grid in log N (``initial_points`` over
  the range), a few realisations each;
- every later round reads the per-realisation COMIC of every run so far at the search's time
  and locates the minimum by a weighted quadratic in log N through the points around the
  lowest mean (``fitted_minimum``); its bootstrap over realisations gives the interval. While
  the lowest mean is at the highest (lowest) visited N, or that end stays within the argmin's
  95 % interval once its realisations are doubled, and the range goes on, the search *walks*
  one coarse step further (half a step when the fit already turns up inside), and does
  nothing else;
- once bracketed, a round *refines* (a geometric midpoint in each gap beside the lowest mean
  and beside the fitted optimum, if wider than ``min_step``) and *replicates* (doubles the
  realisations, cheapest first, of every N of the bracket whose mean is within 2 combined
  standard errors of the lowest, up to ``max_realisations``): on a flat, noisy minimum the
  interval narrows by replication, not by more points.
A search over the dt growth (``over``) does the same in log(dt_growth - 1) at a fixed N,
starting at the cheap end (the largest growth, fewest steps).
The search stops when the bracket (the visited N around the interval) is no wider than
``width``, when nothing is left to add, or when the next runs would exceed the budget of runs
or of core-seconds. Core-seconds are counted by the search's calibrated cost model
(``Search.cost``, ``calibrated_cost``: seconds per run written in the config, a tabulated curve of
the run cost model, core/runcost.py; asked through Search.run_seconds), never measured:
a search's path depends only on its config and the seeds, on any machine. The measured
core-seconds are reported beside it (``core_s``). FD is deterministic: one run per N, a
bracketing search.

A plan is a table of seed blocks, one row per (N, block of seeds) added in some round; every
block is an ordinary simulation job (sweeps.run_path), so its results are cached and shared.
The rounds, plans, seed blocks and the rounds' inputs are the search engine's (search.py); this
module is the rule for the next points (next_plan) and the result. No Snakemake here: the rules
in workflow/rules/optimum.smk call these functions.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import pandas as pd

from ..core.case import APPLIES, Case, SettingError
from ..core.io import read_parquet
from ..core.labels import case_label
from ..core.registry import MEASURE_NAMES, MEASUREMENT_POINTS
from ..core.runconfig import first_step
from ..core.runcost import Tabulated
from ..core.settings import PAPER, SEARCH, defaults
from ..core.timegrid import step_count
from ..core.typed import key_path, shared, validate
from .aggregate import CONVENTIONS, RUN_COLUMNS, convention_samples, realisations_table
from .resampling import argmin_bootstrap, bootstrap_of_means, lowest, nan_argmin
from .search import (
    AdaptiveSearch,
    check_plan_columns,
    counted_seconds,
    extended,
    measured_core_s,
    new_plan,
    next_round,
    runs_in,
    seed_block,
    stopped,
)

SEARCH_DEFAULTS = defaults(SEARCH)  # settings.SEARCH: one search's keys, defaults and ranges
SPEC = shared().Search  # a search's model: its keys, their ranges and the rules between them (core/typed.py)
MEASURES = dict(
    zip(
        MEASURE_NAMES,  # own, points
        (
            "SSE at the model's own points: particles or nodes (Eq. 44)",
            f"SSE at the {MEASUREMENT_POINTS} measurement points common to all models (section 6, point 1)",
        ),
        strict=True,
    )
)
OVER = {
    "n": "N (particles; FD intervals), searched in log N",
    "dt_growth": "the time-step growth factor at a fixed N (pt, mtpt), searched in log(dt_growth - 1)",
}
MAX_ROUNDS = 16  # a search that has not converged by then stops ("round limit")
PLAN_COLUMNS = check_plan_columns(["round", "n", "dt_growth", "first", "last", "done", "reason"])
REASONS = (
    "bracket narrow enough",
    "budget spent",
    "nothing left to add",
    "round limit",
    "minimum at an end of the range",  # the bracket is narrow, but the minimum may lie beyond the range
)
RESULT_COLUMN_DOCS = {
    "search": "name of the search (config key under `optimum`)",
    "label": "legend label of the searched model",
    "time": "time at which COMIC is judged (nearest recorded step) [T]",
    "convention": "what is minimised over N: " + " or ".join(f"`{k}` ({what})" for k, (_, what) in CONVENTIONS.items()),
    "measure": "where SSE is taken: " + "; ".join(f"`{k}`, {v}" for k, v in MEASURES.items()),
    "time_volume": "the time step is part of the sampling volume: COMIC - ln(mean dt), mean dt = time / steps "
    "(Section 6, point 3)",
    "over": "the searched dimension: " + "; ".join(f"`{k}`, {v}" for k, v in OVER.items()),
    "n": "N of this point (particles; FD: intervals): the searched value when `over` is `n`",
    "dt_growth": "time-step growth factor of this point: the searched value when `over` is `dt_growth`",
    "realisations": "realisations of this point",
    "round_added": "round in which this point was first visited (0 = the first coarse points)",
    "COMIC_mean": "mean over realisations of per-realisation COMIC, Eq. 43",
    "COMIC_std": "its standard deviation over realisations (NaN for one realisation)",
    "COMIC_se": "standard error of the mean, std / sqrt(realisations) (0 for FD)",
    "share": "fraction of bootstrap resamples whose lowest visited point is this one",
    "core_s": "measured wall time of this point's runs, the sum of their steps' `wall_s` over realisations "
    "(differs between machines and runs; reported, never used to decide) [s]",
    "cost_s": "the cost model's core-seconds of this point's runs: realisations x the calibrated seconds per run "
    "(`cost`; NaN for a search without one) [s]",
    "best": "the visited value (N or dt growth) with the lowest value of the search's convention",
    "at_end": "`low` or `high` when `best` is the lowest or highest visited value: the minimum may lie beyond it "
    "(beyond the range when that end is the range's), else empty",
    "optimum": "the fitted optimum: vertex of a quadratic in log N (log(dt_growth - 1)), weighted by "
    "realisations, through the visited values within two of `best`; `best` at an end of the visited values",
    "ci_lo": "lower end of the 95 % bootstrap percentile interval of `optimum`, widened to every visited value whose "
    "mean COMIC is within 2 combined standard errors of `best`'s (FD, deterministic: the visited value below `best`)",
    "ci_hi": "its upper end (FD: the visited value above `best`)",
    "bracket_lo": "the largest visited value <= `ci_lo` (the lowest visited if none): the minimum lies above it",
    "bracket_hi": "the smallest visited value >= `ci_hi` (the highest visited if none): the minimum lies below it",
    "reason": "why the search stopped: " + ", ".join(f"`{r}`" for r in REASONS),
    "rounds": "rounds evaluated",
    "runs_spent": "runs (realisations × N) the search used",
    "core_s_spent": "sum of `core_s` over the visited points (measured) [s]",
    "cost_s_spent": "sum of `cost_s`: the core-seconds the budget counted [s]",
    "budget_core_s": "the search's budget of model core-seconds (inf: none) [s]",
    "full_sweep_core_s": "estimated cost of a full grid sweep giving the same bracket: every value of a "
    "grid even in log N (log(dt_growth - 1)) over the range, with the step half the bracket's width in "
    "that log (a grid brackets its minimum "
    "between the argmin's neighbours), each with the search's largest realisation count, at the "
    "measured cost per run (`cost_model`; differs between machines and runs) [s]",
}
RESULT_COLUMNS = list(RESULT_COLUMN_DOCS)


@dataclass(frozen=True)
class Search(AdaptiveSearch):
    """One adaptive search: a model (a case without N; with one for a dt-growth search), the time
    COMIC is judged at, the searched dimension and its range, a budget and when to stop; a kind of
    the search engine (search.AdaptiveSearch), whose rule for the next points is next_plan."""

    name: str
    model: Case
    time: float
    lo: float  # the range of the searched value (OVER)
    hi: float
    over: str = "n"
    width: float = SEARCH_DEFAULTS["width"]  # stop when bracket_hi / bracket_lo <= width (growth: of dt_growth - 1)
    budget_runs: float = math.inf  # runs (realisations x N); a config sets this, budget_core_s or both
    budget_core_s: float = math.inf  # stop before the cost model's core-seconds would exceed this
    cost: tuple = ()  # calibrated ((searched value, seconds per run), ...): the cost model (calibrated_cost)
    initial_points: int = SEARCH_DEFAULTS["initial_points"]  # the coarse grid over the range
    start_points: int = SEARCH_DEFAULTS["start_points"]  # round 0 visits the lowest of them
    initial_realisations: int = SEARCH_DEFAULTS["realisations"]
    max_realisations: int = SEARCH_DEFAULTS["max_realisations"]
    min_step: float = 1.1  # no two visited values closer than this ratio (dt growth: of dt_growth - 1)
    convention: str = SEARCH_DEFAULTS["convention"]  # what is minimised over N (aggregate.CONVENTIONS)
    measure: str = SEARCH_DEFAULTS["measure"]  # where SSE is taken (MEASURES)
    steps: Mapping | None = None  # time.dt0, fd_dt, fixed_dt: set, the time step joins the sampling volume

    @property
    def title(self) -> str:
        return f"optimum search {self.name}"

    @property
    def max_plans(self) -> int:
        return MAX_ROUNDS + 2  # next_plan stops by round MAX_ROUNDS + 1

    def first_plan(self, base_seed: int) -> pd.DataFrame:
        return initial_plan(self, base_seed)

    def next_plan(self, plan: pd.DataFrame, runs: pd.DataFrame, base_seed: int) -> pd.DataFrame:
        return next_plan(self, plan, runs)  # the blocks' seeds follow the plan's own (base_seed of round 0)

    @cached_property
    def cost_curve(self) -> Tabulated | None:
        """The calibrated cost model (calibrated_cost: runcost.Tabulated), None without ``cost``."""
        return calibrated_cost(self)

    def run_seconds(self, point) -> float:
        """Seconds of one run at the searched value ``point`` by the cost model (NaN without one)."""
        return math.nan if self.cost_curve is None else self.cost_curve.seconds(point)

    def read_runs(self, plan: pd.DataFrame, paths: list[str]) -> pd.DataFrame:
        """The runs' values at the search's time; their measured wall times are not read."""
        frames = [read_parquet(p, columns=RUN_COLUMNS) for p in paths]
        return realisations_table(frames, [self.time])

    @property
    def time_volume(self) -> bool:
        """COMIC counts the time step in the sampling volume (the paper's section 6, point 3)."""
        return self.steps is not None

    @property
    def label(self) -> str:
        """The searched model's legend label (a growth search: at its N, without a growth)."""
        if self.over == "dt_growth":
            return case_label(replace(self.model, dt_growth=PAPER["dt_growth"]))
        return case_label(self.model)

    def u(self, x):
        """The searched value on the axis the search is even in: log N, or log(dt_growth - 1)."""
        x = np.asarray(x, dtype=np.float64)
        return np.log(x - 1.0) if self.over == "dt_growth" else np.log(x)

    def x(self, u: float):
        """The value at ``u`` (inverse of ``u``), made valid (valid)."""
        return self.valid(1.0 + math.exp(u) if self.over == "dt_growth" else math.exp(u))

    def valid(self, x: float):
        """A value a run can take: N an integer (FD: even); a growth with 3 significant digits past 1."""
        if self.over == "dt_growth":
            return 1.0 + float(f"{x - 1.0:.3g}")
        return max(2, 2 * round(x / 2)) if self.fd else max(1, round(x))

    def case_at(self, x) -> Case:
        """The simulated case at searched value ``x``."""
        return replace(self.model, dt_growth=float(x)) if self.over == "dt_growth" else self.model.at(int(x))

    @property
    def max_initial_points(self) -> int:
        """The finest coarse grid that keeps the search honest: two of its steps (the bracket round
        0 may stop on) at least ``width`` wide, 1 + 2 (u(hi) - u(lo)) / ln(width) points."""
        span = float(self.u(self.hi) - self.u(self.lo)) if self.hi > self.lo else 0.0
        return max(3, int(math.floor(1.0 + 2.0 * span / math.log(self.width) + 1e-9))) if self.width > 1 else 3

    def grid(self, count: int) -> list:
        """``count`` values spaced evenly in ``u`` from lo to hi, each once."""
        return sorted({self.x(v) for v in np.linspace(float(self.u(self.lo)), float(self.u(self.hi)), count)})

    @property
    def fd(self) -> bool:
        return self.model.method == "fd"

    @property
    def realisations(self) -> int:
        """Realisations of a newly visited N (FD, deterministic: one)."""
        return 1 if self.fd else self.initial_realisations

    @property
    def coarse(self) -> list:
        """The coarse grid the search starts on and walks along."""
        return self.grid(self.initial_points)

    @classmethod
    def from_config(cls, name: str, spec, config: Mapping) -> Search:
        """The search ``optimum.<name>`` of a workflow config: ``spec`` as written (parsed here by the
        search's model, core/typed.py, as the workflow parses it) or that model parsed; SettingError
        names the key path, also for the rules that need its numbers (check)."""
        where = f"optimum.{name}"
        s = spec if isinstance(spec, SPEC) else validate(SPEC, spec, lambda path: key_path(["optimum", name, *path]))
        over = "n" if s.growth_range is None else "dt_growth"
        if over == "dt_growth" and s.n is None:
            raise SettingError(f"{where}.n", None, "the N at which a growth_range search runs, an integer >= 1")
        try:
            n = s.n if over == "dt_growth" else None
            model = Case.from_spec(s.case.model_dump(exclude_unset=True), n, config.get("case_defaults", {}))
        except SettingError as e:
            raise SettingError(f"{where}.case.{e.name}", e.value, e.allowed) from None
        lo, hi = s.growth_range if over == "dt_growth" else s.n_range
        search = cls(
            name=name,
            model=model,
            time=s.time,
            lo=lo,
            hi=hi,
            over=over,
            width=s.width,
            budget_runs=math.inf if s.budget_runs is None else s.budget_runs,
            budget_core_s=math.inf if s.budget_core_s is None else s.budget_core_s,
            cost=tuple(tuple(p) for p in s.cost or ()),
            initial_points=s.initial_points,
            start_points=s.start_points,
            initial_realisations=s.realisations,
            max_realisations=s.max_realisations,
            convention=s.convention,
            measure=s.measure,
            steps=dict(config.get("time", {})) if s.time_volume else None,
        )
        search.check(where, float(config["physics"]["t_final"]))
        return search

    def check(self, where: str, t_final: float) -> None:
        """Refuse a search that cannot run: an empty range, a budget below one round, a time past t_final."""
        if self.over == "dt_growth":
            if self.model.method not in APPLIES["dt_growth"]:
                methods = ", ".join(APPLIES["dt_growth"])
                raise SettingError(f"{where}.growth_range", [self.lo, self.hi], f"a method with a dt growth: {methods}")
            if not 1 < self.lo < self.hi or self.valid(self.lo) == self.valid(self.hi):
                allowed = "[low, high] with 1 < low < high (1 = a fixed step, not a growth)"
                raise SettingError(f"{where}.growth_range", [self.lo, self.hi], allowed)
        elif not 1 <= self.lo < self.hi:
            raise SettingError(f"{where}.n_range", [self.lo, self.hi], "[low, high] with 1 <= low < high")
        elif self.fd and self.lo < 2:
            raise SettingError(f"{where}.n_range", [self.lo, self.hi], "for fd a low end >= 2 (even intervals)")
        if not 0 < self.time <= t_final:
            raise SettingError(f"{where}.time", self.time, f"a time in (0, physics.t_final = {t_final:g}]")
        span = math.exp(float(self.u(self.hi) - self.u(self.lo)))  # the range as a ratio (growth: of dt_growth - 1)
        if not self.min_step < self.width <= span:
            raise SettingError(
                f"{where}.width",
                self.width,
                f"a ratio high / low in ({self.min_step}, {span:.4g}]: a bracket wider than the range stops at once",
            )
        if self.convention not in CONVENTIONS:
            raise SettingError(f"{where}.convention", self.convention, f"one of {', '.join(CONVENTIONS)}")
        if self.measure not in MEASURES:
            raise SettingError(f"{where}.measure", self.measure, f"one of {', '.join(MEASURES)}")
        most = self.max_initial_points
        if not 3 <= self.initial_points <= most:
            raise SettingError(
                f"{where}.initial_points",
                self.initial_points,
                f"an integer in [3, {most}] (a minimum needs 3; with more, two steps of the coarse grid span "
                f"less than width = {self.width:g}, and round 0 would stop on a bracket among the lowest points "
                "before the range is walked)",
            )
        if not 3 <= self.start_points <= self.initial_points:
            raise SettingError(
                f"{where}.start_points", self.start_points, f"an integer in [3, initial_points = {self.initial_points}]"
            )
        if not self.budget_core_s > 0:
            raise SettingError(f"{where}.budget_core_s", self.budget_core_s, "a number of core-seconds > 0")
        self._check_cost(where)
        if not self.fd and self.max_realisations < self.initial_realisations:
            raise SettingError(
                f"{where}.max_realisations", self.max_realisations, f">= realisations ({self.initial_realisations})"
            )
        points = len(self.coarse[: self.start_points])
        first = points * self.realisations
        if self.budget_runs < first:
            raise SettingError(
                f"{where}.budget_runs",
                self.budget_runs,
                f"at least the first round's {first} runs ({points} N x {self.realisations})",
            )

    def _check_cost(self, where: str) -> None:
        """A core-second budget needs a calibrated cost model: points at distinct valid values, seconds > 0."""
        wanted = f"[[{'N' if self.over == 'n' else 'dt_growth'}, seconds per run], ...], seconds > 0 at distinct values"
        if math.isfinite(self.budget_core_s) and not self.cost:
            raise SettingError(
                f"{where}.cost",
                None,
                f"{wanted}, needed with budget_core_s (the budget counts modelled, not measured, seconds: "
                "print them with benchmarks/calibrate_search_costs.py)",
            )
        xs = [x for x, _ in self.cost]
        valid = (lambda x: x >= 1) if self.over == "n" else (lambda x: x > 1)  # N >= 1; a growth > 1
        bad = len(set(xs)) != len(xs) or any(not (math.isfinite(c) and c > 0) for _, c in self.cost)
        if bad or any(not (math.isfinite(x) and valid(x)) for x in xs):
            raise SettingError(f"{where}.cost", [list(p) for p in self.cost], wanted)


def _block(search: Search, k: int, x, base: int, have: int, count: int) -> tuple:
    """Round ``k``'s block of ``count`` runs at ``x`` after the ``have`` it has run (search.seed_block)."""
    case = search.case_at(x)
    return (k, case.n, case.dt_growth, *seed_block(base, have, count), False, "")


def initial_plan(search: Search, base_seed: int) -> pd.DataFrame:
    """Round 0: the lowest ``start_points`` of the coarse grid, each with the first realisations
    (seeds base_seed ...): the cheap end first (for a growth search, the largest growth: fewest
    steps), the expensive end only when the minimum may lie there."""
    coarse = search.coarse[::-1] if search.over == "dt_growth" else search.coarse
    rows = [_block(search, 0, x, base_seed, 0, search.realisations) for x in coarse[: search.start_points]]
    return new_plan(rows, PLAN_COLUMNS)


def cost_model(costs: pd.DataFrame, search: Search | None = None) -> Callable[[float], float]:
    """Predicted core-seconds of one run at a searched value from measured runs (columns of the
    searched dimension, seed, core_s), for the report only (the full-sweep estimate): the mean
    per value, interpolated (tabulated)."""
    column = search.over if search else "n"
    per_run = costs.groupby(column)["core_s"].mean()
    if per_run.empty:
        return lambda x: 0.0
    return tabulated(per_run.index.to_numpy(np.float64), per_run.to_numpy(np.float64), search).seconds


def calibrated_cost(search: Search) -> Tabulated | None:
    """The search's cost model: core-seconds of one run at a searched value from its calibrated
    points (``Search.cost``), interpolated (tabulated); None without points."""
    if not search.cost:
        return None
    xs, seconds = zip(*sorted(search.cost))
    return tabulated(np.array(xs), np.array(seconds), search)


def cost_order(search: Search) -> Callable[[float], float]:
    """A key that orders runs by cost: the cost model, or without one N (the steps, for a growth
    search) in arbitrary units."""
    return (search.cost_curve or tabulated(np.array([float(search.lo)]), np.array([1.0]), search)).seconds


def planned_cost_s(search: Search, plan: pd.DataFrame) -> float:
    """Core-seconds of every run of ``plan`` by the cost model (NaN without one): what the budget counts."""
    if search.cost_curve is None:
        return math.nan
    return counted_seconds(search, plan[search.over], plan["last"] - plan["first"] + 1)


def tabulated(xs: np.ndarray, seconds: np.ndarray, search: Search | None) -> Tabulated:
    """Seconds per run at searched values ``xs`` (increasing) as a tabulated cost model (runcost.Tabulated)
    on the search's axis u (log N; log(dt_growth - 1)); one value: cost proportional to N (to
    steps for a growth search)."""
    if search is None:
        return Tabulated(xs, seconds)
    return Tabulated(xs, seconds, search.u, -1.0 if search.over == "dt_growth" else 1.0)


def fitted_minimum(u: np.ndarray, values: np.ndarray, weights: np.ndarray, reach: int = 2) -> np.ndarray:
    """Where the minimum over u (log N) lies, for each column of ``values`` (shape (points, columns),
    rows in increasing ``u``): the vertex of a quadratic in u, least squares weighted by
    ``weights`` (realisations), through the rows within ``reach`` of the column's lowest, kept
    between that row's neighbours; the lowest row itself when it is an end row or the fit does
    not turn up. Fitting several points at once keeps one lucky mean from being taken for the minimum."""
    values = np.asarray(values, dtype=np.float64)
    values = values[:, None] if values.ndim == 1 else values
    k = nan_argmin(values, axis=0)
    out = u[k].astype(np.float64)
    for best in np.unique(k):
        if best == 0 or best == len(u) - 1:
            continue
        lo, hi = max(0, best - reach), min(len(u), best + reach + 1)
        cols = np.flatnonzero(k == best)
        y = values[lo:hi][:, cols]
        ok = np.isfinite(y).all(axis=0)  # a zero SSE (COMIC -inf) is a minimum, not a curve
        if not ok.any():
            continue
        a, b, _ = np.polyfit(u[lo:hi], y[:, ok], 2, w=np.sqrt(weights[lo:hi]))
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = np.where(a > 0, -b / (2 * a), u[best])
        out[cols[ok]] = np.clip(vertex, u[best - 1], u[best + 1])
    return out


def _fitted_interval(u, resampled, objective, counts) -> tuple[float, float]:
    """95 % percentile interval of the fitted minimum (in u) over bootstrap resamples of the
    realisations (resampling.bootstrap_of_means: each point on its own, single realisations fixed)."""

    def vertex(stacked):
        return fitted_minimum(u, objective(stacked.reshape(len(u), -1)), counts).reshape(stacked.shape[1:])

    with warnings.catch_warnings():  # a degenerate distribution (every resample alike) is an answer here
        warnings.simplefilter("ignore")
        res = bootstrap_of_means(resampled, vertex)
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


def judged(search: Search, realisations: pd.DataFrame) -> pd.DataFrame:
    """The per-realisation values a search minimises: SSE and COMIC at the model's own points or at
    the common measurement points (``measure``), and with the time step in the sampling volume
    (``time_volume``): COMIC - ln(mean dt) and dV x mean dt, mean dt = time / steps to reach it."""
    r = realisations
    if search.measure == "points":
        r = r.assign(COMIC=r["COMIC_points"], SSE=r["SSE_points"], n_sse=MEASUREMENT_POINTS)
        if "COMIC_points_reason" in r:
            r = r.assign(COMIC_reason=r["COMIC_points_reason"])
    if search.time_volume:
        s, method = search.steps, search.model.method
        times = r["time_step"].to_numpy(np.float64)
        growth = r["dt_growth"].to_numpy(np.float64)
        first = [first_step(method, g, s) for g in growth]
        mean_dt = times / np.array([step_count(t, d, g) for t, d, g in zip(times, first, growth)])
        r = r.assign(COMIC=r["COMIC"] - np.log(mean_dt), dV=r["dV"] * mean_dt)
    return r


def evaluate(search: Search, realisations: pd.DataFrame) -> tuple[pd.DataFrame, dict]:
    """Per-point statistics (the searched column, realisations, COMIC_mean, COMIC_std, COMIC_se,
    share) and the search-level optimum (best, optimum, ci_lo, ci_hi, bracket_lo, bracket_hi, and
    for the walk ``argmin_lo`` / ``argmin_hi``, the visited values bounding the argmin's 95 %
    interval) of the search's convention, from per-realisation values (columns n, dt_growth,
    seed, COMIC; as needed SSE, n_sse, dV, time_step, SSE_points, COMIC_points:
    aggregate.realisations_table at the search's time)."""
    values = judged(search, realisations)
    per_x = [g for _, g in values.groupby(search.over, sort=True)]
    xs = np.array([g[search.over].iloc[0] for g in per_x])
    samples = [g["COMIC"].to_numpy(dtype=np.float64) for g in per_x]
    # mean COMIC, or Eq. 43 of the mean SSE (the paper warns the convention can move the optimum)
    resampled, objective = convention_samples(per_x, search.convention)
    shares, lo, hi, _ = argmin_bootstrap(resampled, objective)
    counts = np.array([len(s) for s in samples])
    u = np.asarray(search.u(xs), dtype=np.float64)
    minimised = objective(np.array([r.mean() for r in resampled])[:, None])[:, 0]
    best = lowest(minimised)  # an unscored point (COMIC NaN: aggregate.UNSCORED) is never the best
    if best < 0:
        why = values.get("COMIC_reason", pd.Series(["COMIC NaN"]))
        reasons = sorted(set(why) - {""})
        where, key = f"optimum.{search.name}", "growth_range" if search.over == "dt_growth" else "n_range"
        raise ValueError(
            f"search {search.name}: no visited point scores a COMIC ({'; '.join(reasons)}); try a later "
            f"{where}.time (now {search.time:g}) or another {where}.{key} ({search.lo:g} to {search.hi:g})"
        )
    x_opt = search.x(float(fitted_minimum(u, minimised, counts)[0]))
    means = np.array([s.mean() for s in samples])
    stds = np.array([s.std(ddof=1) if len(s) > 1 else math.nan for s in samples])
    se = np.where(counts > 1, stds / np.sqrt(counts), 0.0)
    if (counts > 1).any():
        u_lo, u_hi = _fitted_interval(u, resampled, objective, counts)
        # the bootstrap cannot see that a mean of few realisations is lucky: the interval also
        # spans every visited value whose mean COMIC is within 2 combined standard errors of the lowest
        noise = np.sqrt(se**2 + se[best] ** 2)
        rival = ((np.abs(means - means[best]) <= 2 * noise) & (noise > 0)) | (np.arange(len(xs)) == best)
        ci_lo, ci_hi = search.x(min(u_lo, u[rival].min())), search.x(max(u_hi, u[rival].max()))
    else:  # deterministic (FD): the minimum lies between the lowest point's neighbours
        ci_lo, ci_hi = xs[max(best - 1, 0)], xs[min(best + 1, len(xs) - 1)]
    below, above = xs[u <= search.u(ci_lo) + 1e-12], xs[u >= search.u(ci_hi) - 1e-12]
    table = pd.DataFrame(
        {
            search.over: xs,
            "realisations": counts,
            "COMIC_mean": means,
            "COMIC_std": stds,
            "COMIC_se": se,
            "share": shares,
        }
    )
    optimum = {
        "best": xs[best].item(),
        "optimum": x_opt,
        "ci_lo": ci_lo.item() if hasattr(ci_lo, "item") else ci_lo,
        "ci_hi": ci_hi.item() if hasattr(ci_hi, "item") else ci_hi,
        "bracket_lo": (below.max() if below.size else xs[0]).item(),
        "bracket_hi": (above.min() if above.size else xs[-1]).item(),
        "argmin_lo": xs[lo].item(),
        "argmin_hi": xs[hi].item(),
    }
    return table, optimum


def _unresolved(table: pd.DataFrame, search: Search, best) -> list:
    """Values whose mean COMIC is within 2 combined standard errors of the lowest mean's (judged on
    mean COMIC under either convention: its standard error is the one at hand)."""
    opt = table[table[search.over] == best].iloc[0]
    gap = (table["COMIC_mean"] - opt["COMIC_mean"]).abs()
    noise = np.sqrt(table["COMIC_se"] ** 2 + opt["COMIC_se"] ** 2)
    return table.loc[(gap <= 2 * noise) & (noise > 0), search.over].tolist()


def _walk(search: Search, table: pd.DataFrame, opt: dict) -> tuple[list, list]:
    """(the next values beyond the visited ones, the end points to replicate first). The search
    walks one coarse step in u past the highest (lowest) visited value when the lowest mean is
    there, or when that end is still within the argmin's 95 % interval after its realisations
    were doubled once: half a step when the fitted minimum already lies inside the visited values
    (the next point only has to show the curve turning up). An end within the interval that has
    not been doubled yet is replicated instead: a doubling there costs less than a step further,
    and decides whether the curve still falls (a flat or bumpy start must not stop the search)."""
    xs = table[search.over].tolist()
    counts = dict(zip(xs, table["realisations"]))
    step = float(search.u(search.hi) - search.u(search.lo)) / (search.initial_points - 1)
    near = math.log(search.min_step)
    out, replicate = [], []
    for end, bound, sign, limit in ((xs[-1], opt["argmin_hi"], 1, search.hi), (xs[0], opt["argmin_lo"], -1, search.lo)):
        if end == limit or (end != opt["best"] and bound != end):
            continue
        if end != opt["best"] and counts[end] < 2 * search.realisations:
            replicate.append(end)
            continue
        beyond = sign * (float(search.u(opt["optimum"])) - float(search.u(end))) >= 0
        v = float(search.u(end)) + sign * (step if beyond else step / 2)
        reach = sign * (v + sign * near - float(search.u(limit))) >= 0
        out.append(limit if reach else search.x(v))
    return [x for x in out if x not in xs], replicate


def next_plan(search: Search, plan: pd.DataFrame, realisations: pd.DataFrame) -> pd.DataFrame:
    """The plan after one more round: ``plan`` plus the blocks this round adds, or ``plan``
    with `done` set and the reason (REASONS) when the search stops. The cost model
    (calibrated_cost) counts the core-seconds budget and orders replication cheapest first:
    the plan depends on the config and the runs' values, never on how long they took."""
    k = next_round(plan)
    table, opt = evaluate(search, realisations)
    xs = table[search.over].tolist()

    def stop(reason):
        return stopped(plan, reason=reason)

    walk, ends = _walk(search, table, opt)
    counts = dict(zip(table[search.over], table["realisations"]))
    rivals = [] if search.fd else _unresolved(table, search, opt["best"])
    # winner's curse: a point newly added with few realisations may hold the lowest mean by luck;
    # it wins only once it has as many realisations as the rivals within its noise
    lucky = [opt["best"]] if rivals and counts[opt["best"]] < max(counts[x] for x in rivals) else []
    at_end = opt["argmin_lo"] == search.lo or opt["argmin_hi"] == search.hi
    if (
        not walk
        and not ends
        and not lucky
        and search.u(opt["bracket_hi"]) - search.u(opt["bracket_lo"]) <= math.log(search.width) + 1e-12
    ):
        return stop(REASONS[4] if at_end else REASONS[0])
    if k > MAX_ROUNDS:
        return stop(REASONS[3])
    # while walking, the bracket is not known yet: refining or replicating inside it would be spent
    # on N the walk may leave behind
    inside = [] if walk else [x for x in xs if opt["bracket_lo"] <= x <= opt["bracket_hi"]]
    u_opt = float(search.u(opt["optimum"]))
    anchors = {opt["best"], min(xs, key=lambda x: abs(float(search.u(x)) - u_opt))}
    new = []
    for a, b in zip(inside, inside[1:]):  # refine the gaps beside the lowest mean and the fitted optimum
        if a not in anchors and b not in anchors:
            continue
        ua, ub = float(search.u(a)), float(search.u(b))
        if ub - ua > math.log(search.min_step):
            mid = search.x((ua + ub) / 2)
            if a < mid < b and mid not in xs:
                new.append(mid)
    new.sort(key=lambda x: abs(float(search.u(x)) - u_opt))  # nearest the optimum first
    model, order = search.cost_curve, cost_order(search)
    unresolved = [x for x in rivals if x in inside]
    more = sorted(set(ends) | set(unresolved) | set([] if walk else lucky), key=order)
    base = int(plan["first"].min())
    added = []
    spent, spent_s = runs_in(plan), planned_cost_s(search, plan) if model else 0.0

    def add(x, have, count):
        nonlocal spent, spent_s
        cost = count * search.run_seconds(x) if model else 0.0
        if spent + count > search.budget_runs or spent_s + cost > search.budget_core_s:
            return
        added.append(_block(search, k, x, base, have, count))
        spent, spent_s = spent + count, spent_s + cost

    for x in [*walk, *new]:
        add(x, 0, search.realisations)
    for x in more:  # cheapest first: a doubling at small N costs little
        have = int(counts[x])
        if have < search.max_realisations:
            add(x, have, min(have, search.max_realisations - have))
    if not added:
        wanted = bool(walk or new) or any(counts[x] < search.max_realisations for x in more)
        return stop(REASONS[1] if wanted else REASONS[2])
    return extended(plan, added, PLAN_COLUMNS)


COST_KEYS = ["n", "dt_growth", "seed"]


def _costs(frames: list[pd.DataFrame]) -> pd.DataFrame:
    """Measured core-seconds of every run (n, dt_growth, seed, core_s: summed step wall times)."""
    if not frames:
        return measured_core_s(pd.DataFrame(), COST_KEYS)
    return measured_core_s(pd.concat([f[[*COST_KEYS, "wall_s"]] for f in frames], ignore_index=True), COST_KEYS)


def read_costs(paths: list[str]) -> pd.DataFrame:
    """Measured core-seconds of every run in the run tables at ``paths`` (_costs)."""
    return _costs([read_parquet(p, columns=[*COST_KEYS, "wall_s"]) for p in paths])


def read_runs(paths: list[str], time: float) -> tuple[pd.DataFrame, pd.DataFrame]:
    """A search's inputs from its run tables, each read once: the per-realisation values at
    ``time`` (aggregate.realisations_table) and the measured costs (_costs)."""
    frames = [read_parquet(p, columns=list(dict.fromkeys([*RUN_COLUMNS, "wall_s"]))) for p in paths]
    return realisations_table(frames, [time]), _costs(frames)


def _visited_end(table: pd.DataFrame, search: Search, best) -> str:
    """`low` / `high` when ``best`` is the lowest / highest visited value (the minimum may lie beyond), else ''."""
    xs = table[search.over]
    return "low" if best == xs.min() else "high" if best == xs.max() else ""


def advance(search: Search, plan: pd.DataFrame, paths: list[str]) -> pd.DataFrame:
    """The next plan (next_plan) from the run tables of ``plan``'s seed blocks at ``paths``: their
    values at the search's time (Search.read_runs); their measured wall times are not read."""
    return search.round(plan, paths, int(plan["first"].min()))


def result_table(search: Search, plan: pd.DataFrame, realisations: pd.DataFrame, costs: pd.DataFrame) -> pd.DataFrame:
    """Every visited point of a finished search with its statistics, the optimum, the cost spent
    and the estimated cost of the full sweep (RESULT_COLUMN_DOCS). ``costs``: columns n,
    dt_growth, seed, core_s."""
    table, opt = evaluate(search, realisations)
    first_round = plan.groupby(search.over)["round"].min()
    cost_x = costs.groupby(search.over)["core_s"].sum()
    table["round_added"] = table[search.over].map(first_round).astype(int)
    table["core_s"] = table[search.over].map(cost_x).astype(float)
    model = search.cost_curve
    table["cost_s"] = table["realisations"] * table[search.over].map(search.run_seconds) if model else math.nan
    other = "dt_growth" if search.over == "n" else "n"
    table[other] = getattr(search.model, other)
    # a grid brackets its minimum between the argmin's two neighbours: to give the same bracket
    # a full sweep needs half the bracket's width in u as its step over the whole range
    width = float(search.u(opt["bracket_hi"]) - search.u(opt["bracket_lo"]))
    step = max(math.log(search.min_step), width / 2)
    span = float(search.u(search.hi) - search.u(search.lo))
    predict = cost_model(costs, search)
    sweep = search.grid(math.ceil(span / step - 1e-9) + 1)
    full = float(sum(predict(x) for x in sweep) * table["realisations"].max())
    out = table.assign(
        search=search.name,
        label=search.label,
        time=search.time,
        convention=search.convention,
        measure=search.measure,
        time_volume=search.time_volume,
        over=search.over,
        **{k: float(v) for k, v in opt.items() if k in RESULT_COLUMN_DOCS},
        reason=str(plan["reason"].iloc[-1]),
        rounds=int(plan["round"].max()) + 1,
        runs_spent=runs_in(plan),
        core_s_spent=float(table["core_s"].sum()),
        cost_s_spent=planned_cost_s(search, plan),
        budget_core_s=search.budget_core_s,
        at_end=_visited_end(table, search, opt["best"]),
        full_sweep_core_s=full,
    )
    return out[RESULT_COLUMNS]
