"""COMIC-guided resolution: an adaptive search, round by round, for the N minimising mean COMIC (Eq. 43).

Runs are spent where the answer needs them, and the expensive large N only when the minimum
may lie there:
- round 0 runs the lowest ``start_points`` of a coarse grid in log N (``initial_points`` over
  the range), a few realisations each;
- every later round reads the per-realisation COMIC of every run so far at the search's time
  and locates the minimum by a weighted quadratic in log N through the points around the
  lowest mean (``fitted_minimum``); its bootstrap over realisations gives the interval. While
  that interval reaches the highest (lowest) visited N and the range goes on, the search
  *walks* one coarse step further (half a step when the fit already turns up inside);
- once bracketed, a round *refines* (a geometric midpoint in every gap of the bracket wider
  than ``min_step``, nearest the optimum first) and *replicates* (doubles the realisations,
  cheapest N first, of every N of the bracket whose mean is within 2 combined standard errors
  of the lowest, up to ``max_realisations``).
The search stops when the bracket (the visited N around the interval) is no wider than
``width``, when nothing is left to add, or when the next runs would exceed the budget of runs
or of core-seconds (predicted from the measured cost per run, ``cost_model``). FD is
deterministic: one run per N, a bracketing search.

A plan is a table of seed blocks, one row per (N, block of seeds) added in some round; every
block is an ordinary simulation job (sweeps.run_path), so its results are cached and shared.
No Snakemake here: the rules in workflow/rules/optimum.smk call these functions.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from .aggregate import _RNG, BOOTSTRAP_SEED, CONFIDENCE, CONVENTIONS, N_RESAMPLES, argmin_bootstrap, convention_samples
from .case import Case, SettingError
from .registry import MEASUREMENT_POINTS, PAPER
from .runconfig import first_step
from .timegrid import step_count

MEASURES = {
    "own": "SSE at the model's own points: particles or nodes (Eq. 44)",
    "points": f"SSE at the {MEASUREMENT_POINTS} measurement points common to all models (section 6, point 1)",
}
TIME_DEFAULTS = {"dt0": PAPER["dt0"], "fd_dt": PAPER["fd_dt"], "fixed_dt": PAPER["fixed_dt"]}
MAX_ROUNDS = 16  # a search that has not converged by then stops ("round limit")
PLAN_COLUMNS = ["round", "n", "first", "last", "done", "reason"]
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
    "time": "time at which COMIC is judged [T]",
    "convention": "what is minimised over N: " + "; ".join(f"{k} = {what}" for k, (_, what) in CONVENTIONS.items()),
    "measure": "where SSE is taken: " + "; ".join(f"{k} = {v}" for k, v in MEASURES.items()),
    "time_volume": "the time step is part of the sampling volume: COMIC - ln(mean dt) (section 6, point 3)",
    "n": "a visited N (particles; FD: intervals)",
    "realisations": "realisations of this N",
    "round_added": "round in which this N was first visited (0 = the first coarse points)",
    "COMIC_mean": "mean over realisations of per-realisation COMIC (Eq. 43) [nats]",
    "COMIC_std": "its standard deviation over realisations (NaN for one realisation)",
    "COMIC_se": "standard error of the mean (std / sqrt(realisations); 0 for FD)",
    "share": "fraction of bootstrap resamples whose lowest visited N is this N",
    "core_s": "measured wall time of this N's runs, summed over realisations (step timings) [s]",
    "n_best": "the visited N with the lowest value of the search's convention",
    "n_opt": "the fitted optimum: vertex of a quadratic in log N, weighted by realisations, through the "
    "visited N within two of n_best (n_best itself at an end of the visited N)",
    "ci_lo": "lower end of the 95 % bootstrap interval of n_opt (FD, deterministic: the visited N below n_best)",
    "ci_hi": "its upper end (FD: the visited N above n_best)",
    "bracket_lo": "the largest visited N <= ci_lo (the lowest visited N if none): the minimum lies above it",
    "bracket_hi": "the smallest visited N >= ci_hi (the highest visited N if none): the minimum lies below it",
    "reason": "why the search stopped: " + ", ".join(REASONS),
    "rounds": "rounds evaluated",
    "runs_spent": "runs (realisations x N) the search used",
    "core_s_spent": "sum of core_s over every visited N [s]",
    "full_sweep_core_s": "estimated cost of a full grid sweep giving the same bracket: every N of a "
    "geometric grid over the range with step sqrt(bracket_hi / bracket_lo) (a grid brackets its minimum "
    "between the argmin's neighbours), each with the search's largest realisation count, at the "
    "measured cost per run (cost_model) [s]",
}
RESULT_COLUMNS = list(RESULT_COLUMN_DOCS)


@dataclass(frozen=True)
class Search:
    """One adaptive search: a model (a case without N), the time COMIC is judged at, an N range,
    a budget and when to stop."""

    name: str
    model: Case
    time: float
    n_lo: int
    n_hi: int
    width: float = 10.0  # stop when bracket_hi / bracket_lo <= width
    budget_runs: float = math.inf  # runs (realisations x N); a config sets this, budget_core_s or both
    budget_core_s: float = math.inf  # stop before the predicted core-seconds would exceed this
    initial_points: int = 7  # the coarse grid over the range (7 over 30 ... 30,000: half decades)
    start_points: int = 3  # round 0 visits the lowest of them; later rounds walk up only as needed
    initial_realisations: int = 4
    max_realisations: int = 64
    min_step: float = 1.1  # no two visited N closer than this ratio
    convention: str = "mean_COMIC"  # or COMIC_of_mean_SSE (aggregate.CONVENTIONS): what is minimised
    measure: str = "own"  # or "points": SSE at the measurement points common to all models (MEASURES)
    first_dt: float | None = None  # the model's first time step: set, the step joins the sampling volume

    @property
    def time_volume(self) -> bool:
        """COMIC counts the time step in the sampling volume (the paper's section 6, point 3)."""
        return self.first_dt is not None

    @property
    def fd(self) -> bool:
        return self.model.method == "fd"

    @property
    def realisations(self) -> int:
        """Realisations of a newly visited N (FD, deterministic: one)."""
        return 1 if self.fd else self.initial_realisations

    @property
    def coarse(self) -> list[int]:
        """The coarse grid the search starts on and walks along."""
        return grid(self.n_lo, self.n_hi, self.initial_points, self.fd)

    @classmethod
    def from_config(cls, name: str, spec: Mapping, config: Mapping) -> Search:
        """The search ``optimum.<name>`` of a workflow config; SettingError names the key path."""
        where = f"optimum.{name}"
        try:
            model = Case.from_spec(spec["case"], None, config.get("case_defaults", {}))
        except SettingError as e:
            raise SettingError(f"{where}.case.{e.name}", e.value, e.allowed) from None
        lo, hi = (int(v) for v in spec["n_range"])
        first_dt = None
        if spec.get("time_volume", False):
            t = {**TIME_DEFAULTS, **config.get("time", {})}
            first_dt = first_step(model.method, model.dt_growth, t["dt0"], t["fd_dt"], t["fixed_dt"])
        search = cls(
            name=name,
            model=model,
            time=float(spec["time"]),
            n_lo=lo,
            n_hi=hi,
            width=float(spec.get("width", cls.width)),
            budget_runs=int(spec["budget_runs"]) if "budget_runs" in spec else math.inf,
            budget_core_s=float(spec.get("budget_core_s", cls.budget_core_s)),
            initial_points=int(spec.get("initial_points", cls.initial_points)),
            start_points=int(spec.get("start_points", cls.start_points)),
            initial_realisations=int(spec.get("realisations", cls.initial_realisations)),
            max_realisations=int(spec.get("max_realisations", cls.max_realisations)),
            convention=str(spec.get("convention", cls.convention)),
            measure=str(spec.get("measure", cls.measure)),
            first_dt=first_dt,
        )
        search.check(where, float(config["physics"]["t_final"]))
        return search

    def check(self, where: str, t_final: float) -> None:
        """Refuse a search that cannot run: an empty range, a budget below one round, a time past t_final."""
        if not 1 <= self.n_lo < self.n_hi:
            raise SettingError(f"{where}.n_range", [self.n_lo, self.n_hi], "[low, high] with 1 <= low < high")
        if self.fd and self.n_lo < 2:
            raise SettingError(f"{where}.n_range", [self.n_lo, self.n_hi], "for fd a low end >= 2 (even intervals)")
        if not 0 < self.time <= t_final:
            raise SettingError(f"{where}.time", self.time, f"a time in (0, physics.t_final = {t_final:g}]")
        if not self.width > self.min_step:
            raise SettingError(f"{where}.width", self.width, f"a ratio n_hi / n_lo > {self.min_step}")
        if self.convention not in CONVENTIONS:
            raise SettingError(f"{where}.convention", self.convention, f"one of {', '.join(CONVENTIONS)}")
        if self.measure not in MEASURES:
            raise SettingError(f"{where}.measure", self.measure, f"one of {', '.join(MEASURES)}")
        if self.initial_points < 3:
            raise SettingError(f"{where}.initial_points", self.initial_points, "an integer >= 3 (a minimum needs 3)")
        if not 3 <= self.start_points <= self.initial_points:
            raise SettingError(
                f"{where}.start_points", self.start_points, f"an integer in [3, initial_points = {self.initial_points}]"
            )
        if not self.budget_core_s > 0:
            raise SettingError(f"{where}.budget_core_s", self.budget_core_s, "a number of core-seconds > 0")
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


def _valid_n(n: float, fd: bool) -> int:
    return max(2, 2 * round(n / 2)) if fd else max(1, round(n))


def grid(lo: int, hi: int, count: int, fd: bool = False) -> list[int]:
    """``count`` N spaced evenly in log N from lo to hi (FD: even), each once."""
    points = np.exp(np.linspace(math.log(lo), math.log(hi), count))
    return sorted({_valid_n(p, fd) for p in points})


def initial_plan(search: Search, base_seed: int) -> pd.DataFrame:
    """Round 0: the lowest ``start_points`` of the coarse grid, each with the first realisations
    (seeds base_seed ...): the cheap end first, larger N only when the minimum may lie there."""
    r = search.realisations
    rows = [(0, n, base_seed, base_seed + r - 1, False, "") for n in search.coarse[: search.start_points]]
    return pd.DataFrame(rows, columns=PLAN_COLUMNS)


def runs_in(plan: pd.DataFrame) -> int:
    return int((plan["last"] - plan["first"] + 1).sum())


def cost_model(costs: pd.DataFrame) -> Callable[[float], float]:
    """Predicted core-seconds of one run at N from measured runs (columns n, seed, core_s): the mean
    per N interpolated in log N - log cost, extrapolated with the end segments' slopes (kept in
    [0, 2]: no method here costs more than N^2); one measured N: cost proportional to N."""
    per_run = costs.groupby("n")["core_s"].mean()
    if per_run.empty:
        return lambda n: 0.0
    u = np.log(per_run.index.to_numpy(np.float64))
    c = np.log(np.maximum(per_run.to_numpy(np.float64), 1e-9))

    def slope(i, j):
        return 1.0 if len(u) < 2 else float(np.clip((c[j] - c[i]) / (u[j] - u[i]), 0.0, 2.0))

    lo, hi = slope(0, 1), slope(-2, -1)

    def predict(n: float) -> float:
        x = math.log(n)
        if x < u[0]:
            return float(math.exp(c[0] + lo * (x - u[0])))
        if x > u[-1]:
            return float(math.exp(c[-1] + hi * (x - u[-1])))
        return float(math.exp(np.interp(x, u, c)))

    return predict


def fitted_minimum(u: np.ndarray, values: np.ndarray, weights: np.ndarray, reach: int = 2) -> np.ndarray:
    """Where the minimum over log N lies, for each column of ``values`` (shape (N count, columns),
    rows in increasing ``u`` = log N): the vertex of a quadratic in u, least squares weighted by
    ``weights`` (realisations), through the rows within ``reach`` of the column's lowest, kept
    between that row's neighbours; the lowest row itself when it is an end row or the fit does
    not turn up. Fitting several N at once keeps one lucky mean from being taken for the minimum."""
    values = np.asarray(values, dtype=np.float64)
    values = values[:, None] if values.ndim == 1 else values
    k = np.argmin(np.where(np.isnan(values), np.inf, values), axis=0)
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
    """95 % percentile interval of the fitted minimum (log N) over bootstrap resamples of the
    realisations (scipy.stats.bootstrap, each N on its own; single realisations held fixed)."""
    free = [i for i, r in enumerate(resampled) if len(r) > 1]
    means = np.array([r.mean() for r in resampled])

    def statistic(*drawn, axis=-1):
        batch = drawn[0].shape[:-1]
        stacked = np.empty((len(means), *batch))
        stacked[:] = means.reshape(-1, *[1] * len(batch))
        for i, r in zip(free, drawn):
            stacked[i] = r.mean(axis=axis)
        with np.errstate(divide="ignore", invalid="ignore"):
            values = objective(stacked.reshape(len(means), -1))
        return fitted_minimum(u, values, counts).reshape(batch)

    with warnings.catch_warnings():  # a degenerate distribution (every resample alike) is an answer here
        warnings.simplefilter("ignore")
        res = stats.bootstrap(
            [resampled[i] for i in free],
            statistic,
            n_resamples=N_RESAMPLES,
            vectorized=True,
            paired=False,
            confidence_level=CONFIDENCE,
            method="percentile",
            **{_RNG: np.random.default_rng(BOOTSTRAP_SEED)},
        )
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


def judged(search: Search, realisations: pd.DataFrame) -> pd.DataFrame:
    """The per-realisation values a search minimises: SSE and COMIC at the model's own points or at
    the common measurement points (``measure``), and with the time step in the sampling volume
    (``time_volume``): COMIC - ln(mean dt) and dV x mean dt, mean dt = time / steps to reach it."""
    r = realisations
    if search.measure == "points":
        r = r.assign(COMIC=r["COMIC_points"], SSE=r["SSE_points"], n_sse=MEASUREMENT_POINTS)
    if search.time_volume:
        times = r["time_step"].to_numpy(np.float64)
        steps = np.array([step_count(t, search.first_dt, search.model.dt_growth) for t in times])
        mean_dt = times / steps
        r = r.assign(COMIC=r["COMIC"] - np.log(mean_dt), dV=r["dV"] * mean_dt)
    return r


def evaluate(search: Search, realisations: pd.DataFrame) -> tuple[pd.DataFrame, dict]:
    """Per-N statistics (n, realisations, COMIC_mean, COMIC_std, COMIC_se, share) and the
    search-level optimum (n_best, n_opt, ci_lo, ci_hi, bracket_lo, bracket_hi, and for the walk
    ``argmin_lo`` / ``argmin_hi``, the visited N bounding the argmin's 95 % interval) of the
    search's convention, from per-realisation values (columns n, seed, COMIC; for
    COMIC_of_mean_SSE also SSE, n_sse, dV: aggregate.realisations_table at the search's time)."""
    per_n = [g for _, g in judged(search, realisations).groupby("n", sort=True)]
    ns = np.array([int(g["n"].iloc[0]) for g in per_n])
    samples = [g["COMIC"].to_numpy(dtype=np.float64) for g in per_n]
    # mean COMIC, or Eq. 43 of the mean SSE (the paper warns the convention can move the optimum)
    resampled, objective = convention_samples(per_n, search.convention)
    shares, lo, hi, _ = argmin_bootstrap(resampled, objective)
    counts = np.array([len(s) for s in samples])
    u = np.log(ns.astype(np.float64))
    with np.errstate(divide="ignore"):  # a zero SSE: COMIC -inf, a valid minimum
        minimised = objective(np.array([r.mean() for r in resampled])[:, None])[:, 0]
    best = int(np.argmin(minimised))
    n_opt = _valid_n(math.exp(fitted_minimum(u, minimised, counts)[0]), search.fd)
    if (counts > 1).any():
        u_lo, u_hi = _fitted_interval(u, resampled, objective, counts)
        ci_lo, ci_hi = math.exp(u_lo), math.exp(u_hi)
    else:  # deterministic (FD): the minimum lies between the lowest point's neighbours
        ci_lo, ci_hi = float(ns[max(best - 1, 0)]), float(ns[min(best + 1, len(ns) - 1)])
    below, above = ns[ns <= ci_lo * (1 + 1e-12)], ns[ns >= ci_hi * (1 - 1e-12)]
    means = np.array([s.mean() for s in samples])
    stds = np.array([s.std(ddof=1) if len(s) > 1 else math.nan for s in samples])
    se = np.where(counts > 1, stds / np.sqrt(counts), 0.0)
    table = pd.DataFrame(
        {"n": ns, "realisations": counts, "COMIC_mean": means, "COMIC_std": stds, "COMIC_se": se, "share": shares}
    )
    optimum = {
        "n_best": int(ns[best]),
        "n_opt": n_opt,
        "ci_lo": int(round(ci_lo)),
        "ci_hi": int(round(ci_hi)),
        "bracket_lo": int(below.max()) if below.size else int(ns[0]),
        "bracket_hi": int(above.min()) if above.size else int(ns[-1]),
        "argmin_lo": int(ns[lo]),
        "argmin_hi": int(ns[hi]),
    }
    return table, optimum


def _unresolved(table: pd.DataFrame, n_best: int) -> list[int]:
    """N whose mean COMIC is within 2 combined standard errors of the lowest mean's (judged on mean
    COMIC under either convention: its standard error is the one at hand)."""
    opt = table[table["n"] == n_best].iloc[0]
    gap = (table["COMIC_mean"] - opt["COMIC_mean"]).abs()
    noise = np.sqrt(table["COMIC_se"] ** 2 + opt["COMIC_se"] ** 2)
    return table.loc[(gap <= 2 * noise) & (noise > 0), "n"].astype(int).tolist()


def _walk(search: Search, ns: list[int], opt: dict) -> list[int]:
    """The next N beyond the visited ones, while the argmin's interval reaches the highest (lowest)
    visited N and the range goes on: one coarse step, or half of one when the fitted minimum
    already lies inside the visited N (the next point only has to show the curve turning up)."""
    step = (search.n_hi / search.n_lo) ** (1.0 / (search.initial_points - 1))
    out = []
    if opt["argmin_hi"] == ns[-1] and ns[-1] < search.n_hi:
        factor = step if opt["n_opt"] >= ns[-1] else math.sqrt(step)
        n = ns[-1] * factor
        out.append(search.n_hi if n * search.min_step >= search.n_hi else _valid_n(n, search.fd))
    if opt["argmin_lo"] == ns[0] and ns[0] > search.n_lo:
        factor = step if opt["n_opt"] <= ns[0] else math.sqrt(step)
        n = ns[0] / factor
        out.append(search.n_lo if n / search.min_step <= search.n_lo else _valid_n(n, search.fd))
    return [n for n in out if n not in ns]


def next_plan(
    search: Search, plan: pd.DataFrame, realisations: pd.DataFrame, costs: pd.DataFrame | None = None
) -> pd.DataFrame:
    """The plan after one more round: ``plan`` plus the blocks this round adds, or ``plan``
    with `done` set and the reason (REASONS) when the search stops. ``costs`` (columns n, seed,
    core_s: the measured runs so far) predicts what new runs cost, for the core-seconds budget
    and to replicate the cheapest N first; without it every run counts as free."""
    costs = pd.DataFrame(columns=["n", "seed", "core_s"]) if costs is None else costs
    k = int(plan["round"].max()) + 1
    table, opt = evaluate(search, realisations)
    ns = table["n"].tolist()

    def stop(reason):
        out = plan.copy()
        out["done"], out["reason"] = True, reason
        return out

    walk = _walk(search, ns, opt)
    at_end = opt["argmin_lo"] == search.n_lo or opt["argmin_hi"] == search.n_hi
    if not walk and opt["bracket_hi"] / opt["bracket_lo"] <= search.width:
        return stop(REASONS[4] if at_end else REASONS[0])
    if k > MAX_ROUNDS:
        return stop(REASONS[3])
    inside = [n for n in ns if opt["bracket_lo"] <= n <= opt["bracket_hi"]]
    new_n = []
    for a, b in zip(inside, inside[1:]):  # refine every gap of the bracket
        if b / a > search.min_step:
            mid = _valid_n(math.sqrt(a * b), search.fd)
            if a < mid < b and mid not in ns:
                new_n.append(mid)
    new_n.sort(key=lambda n: abs(math.log(n / opt["n_opt"])))  # nearest the optimum first
    predict = cost_model(costs)
    more = [] if search.fd else sorted((n for n in _unresolved(table, opt["n_best"]) if n in inside), key=predict)
    base = int(plan["first"].min())
    added = []
    spent, spent_s = runs_in(plan), float(costs["core_s"].sum())

    def add(n, first, count):
        nonlocal spent, spent_s
        cost = count * predict(n)
        if spent + count > search.budget_runs or spent_s + cost > search.budget_core_s:
            return
        added.append((k, n, first, first + count - 1, False, ""))
        spent, spent_s = spent + count, spent_s + cost

    for n in [*walk, *new_n]:
        add(n, base, search.realisations)
    counts = dict(zip(table["n"], table["realisations"]))
    for n in more:  # cheapest first: a doubling at small N costs little
        have = int(counts[n])
        add(n, base + have, min(have, search.max_realisations - have))
    if not added:
        wanted = bool(walk or new_n) or any(counts[n] < search.max_realisations for n in more)
        return stop(REASONS[1] if wanted else REASONS[2])
    return pd.concat([plan, pd.DataFrame(added, columns=PLAN_COLUMNS)], ignore_index=True)


def read_costs(paths: list[str]) -> pd.DataFrame:
    """Measured core-seconds of every run (n, seed, core_s: summed step wall times) in run tables."""
    if not paths:
        return pd.DataFrame(columns=["n", "seed", "core_s"])
    steps = pd.concat([pd.read_parquet(p, columns=["n", "seed", "wall_s"]) for p in paths], ignore_index=True)
    costs = steps.groupby(["n", "seed"], as_index=False)["wall_s"].sum()
    return costs.rename(columns={"wall_s": "core_s"})


def result_table(search: Search, plan: pd.DataFrame, realisations: pd.DataFrame, costs: pd.DataFrame) -> pd.DataFrame:
    """Every visited N of a finished search with its statistics, the optimum, the cost spent and
    the estimated cost of the full sweep (RESULT_COLUMN_DOCS). ``costs``: columns n, seed, core_s."""
    table, opt = evaluate(search, realisations)
    first_round = plan.groupby("n")["round"].min()
    cost_n = costs.groupby("n")["core_s"].sum()
    table["round_added"] = table["n"].map(first_round).astype(int)
    table["core_s"] = table["n"].map(cost_n).astype(float)
    # a grid brackets its minimum between the argmin's two neighbours: to give the same bracket
    # a full sweep needs the step sqrt(bracket_hi / bracket_lo) over the whole range
    step = max(search.min_step, math.sqrt(opt["bracket_hi"] / opt["bracket_lo"]))
    count = math.ceil(math.log(search.n_hi / search.n_lo) / math.log(step)) + 1
    predict = cost_model(costs)
    sweep = grid(search.n_lo, search.n_hi, count, search.fd)
    full = float(sum(predict(n) for n in sweep) * table["realisations"].max())
    out = table.assign(
        search=search.name,
        label=search.model.label(),
        time=search.time,
        convention=search.convention,
        measure=search.measure,
        time_volume=search.time_volume,
        **{k: v for k, v in opt.items() if k in RESULT_COLUMN_DOCS},
        reason=str(plan["reason"].iloc[-1]),
        rounds=int(plan["round"].max()) + 1,
        runs_spent=runs_in(plan),
        core_s_spent=float(table["core_s"].sum()),
        full_sweep_core_s=full,
    )
    return out[RESULT_COLUMNS]
