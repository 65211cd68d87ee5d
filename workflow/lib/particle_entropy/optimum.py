"""COMIC-guided resolution: an adaptive search, round by round, for the N minimising mean COMIC (Eq. 43).

A search starts from a coarse grid in log N with a few realisations. Each round reads the
per-realisation COMIC of every run so far at the search's time and resamples it
(aggregate.argmin_bootstrap). The optimum's *bracket* runs from the visited N just below the
bootstrap interval of the argmin to the one just above it; the smooth COMIC curve has its
minimum inside it. The round then
- refines: a geometric midpoint in every gap of the bracket wider than ``min_step``;
- replicates: doubles the realisations (up to ``max_realisations``) of every N of the bracket
  whose mean COMIC is within 2 combined standard errors of the minimum, where the comparison
  is not yet resolved.
The search stops when the bracket is no wider than ``width`` (n_hi / n_lo), when nothing is
left to add, or when the next round would exceed the budget of runs. FD is deterministic: one
run per N, and the search is a bracketing search in log N.

A plan is a table of seed blocks, one row per (N, block of seeds) added in some round; every
block is an ordinary simulation job (sweeps.run_path), so its results are cached and shared.
No Snakemake here: the rules in workflow/rules/optimum.smk call these functions.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .aggregate import CONVENTIONS, argmin_bootstrap, convention_samples
from .case import Case, SettingError

MAX_ROUNDS = 12  # a search that has not converged by then stops ("round limit")
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
    "n": "a visited N (particles; FD: intervals)",
    "realisations": "realisations of this N",
    "round_added": "round in which this N was first visited (0 = the coarse grid)",
    "COMIC_mean": "mean over realisations of per-realisation COMIC (Eq. 43) [nats]",
    "COMIC_std": "its standard deviation over realisations (NaN for one realisation)",
    "COMIC_se": "standard error of the mean (std / sqrt(realisations); 0 for FD)",
    "share": "fraction of bootstrap resamples whose argmin is this N",
    "core_s": "measured wall time of this N's runs, summed over realisations (step timings) [s]",
    "n_opt": "N minimising the search's convention (mean COMIC unless set otherwise)",
    "ci_lo": "lower end of the 95 % bootstrap interval of the argmin (a visited N)",
    "ci_hi": "its upper end",
    "bracket_lo": "visited N just below ci_lo (the range end if none): the minimum lies above it",
    "bracket_hi": "visited N just above ci_hi: the minimum lies below it",
    "reason": "why the search stopped: " + ", ".join(REASONS),
    "rounds": "rounds evaluated",
    "runs_spent": "runs (realisations x N) the search used",
    "core_s_spent": "sum of core_s over every visited N [s]",
    "full_sweep_core_s": "estimated cost of a full grid sweep giving the same bracket: every N of a "
    "geometric grid over the range with step sqrt(bracket_hi / bracket_lo) (a grid brackets its minimum "
    "between the argmin's neighbours), each with the search's largest realisation count, at the "
    "measured cost per run interpolated in log N [s]",
}
RESULT_COLUMNS = list(RESULT_COLUMN_DOCS)


@dataclass(frozen=True)
class Search:
    """One adaptive search: a model (a case without N), the time COMIC is judged at, an N range
    and when to stop."""

    name: str
    model: Case
    time: float
    n_lo: int
    n_hi: int
    width: float = 10.0  # stop when bracket_hi / bracket_lo <= width
    budget_runs: int = 200
    initial_points: int = 5
    initial_realisations: int = 4
    max_realisations: int = 64
    min_step: float = 1.1  # no two visited N closer than this ratio
    convention: str = "mean_COMIC"  # or COMIC_of_mean_SSE (aggregate.CONVENTIONS): what is minimised

    @property
    def fd(self) -> bool:
        return self.model.method == "fd"

    @property
    def realisations(self) -> int:
        """Realisations of a newly visited N (FD, deterministic: one)."""
        return 1 if self.fd else self.initial_realisations

    @classmethod
    def from_config(cls, name: str, spec: Mapping, config: Mapping) -> Search:
        """The search ``optimum.<name>`` of a workflow config; SettingError names the key path."""
        where = f"optimum.{name}"
        try:
            model = Case.from_spec(spec["case"], None, config.get("case_defaults", {}))
        except SettingError as e:
            raise SettingError(f"{where}.case.{e.name}", e.value, e.allowed) from None
        lo, hi = (int(v) for v in spec["n_range"])
        search = cls(
            name=name,
            model=model,
            time=float(spec["time"]),
            n_lo=lo,
            n_hi=hi,
            width=float(spec.get("width", cls.width)),
            budget_runs=int(spec["budget_runs"]),
            initial_points=int(spec.get("initial_points", cls.initial_points)),
            initial_realisations=int(spec.get("realisations", cls.initial_realisations)),
            max_realisations=int(spec.get("max_realisations", cls.max_realisations)),
            convention=str(spec.get("convention", cls.convention)),
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
        if self.initial_points < 3:
            raise SettingError(f"{where}.initial_points", self.initial_points, "an integer >= 3 (a minimum needs 3)")
        if not self.fd and self.max_realisations < self.initial_realisations:
            raise SettingError(
                f"{where}.max_realisations", self.max_realisations, f">= realisations ({self.initial_realisations})"
            )
        points = len(grid(self.n_lo, self.n_hi, self.initial_points, self.fd))
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
    """Round 0: the coarse grid, each N with the first realisations (seeds base_seed ...)."""
    r = search.realisations
    rows = [
        (0, n, base_seed, base_seed + r - 1, False, "")
        for n in grid(search.n_lo, search.n_hi, search.initial_points, search.fd)
    ]
    return pd.DataFrame(rows, columns=PLAN_COLUMNS)


def runs_in(plan: pd.DataFrame) -> int:
    return int((plan["last"] - plan["first"] + 1).sum())


def evaluate(search: Search, realisations: pd.DataFrame) -> tuple[pd.DataFrame, dict]:
    """Per-N statistics (n, realisations, COMIC_mean, COMIC_std, COMIC_se, share) and the
    search-level optimum (n_opt, ci_lo, ci_hi, bracket_lo, bracket_hi) of the search's
    convention, from per-realisation values (columns n, seed, COMIC; for COMIC_of_mean_SSE also
    SSE, n_sse, dV: aggregate.realisations_table at the search's time)."""
    per_n = [g for _, g in realisations.groupby("n", sort=True)]
    ns = [int(g["n"].iloc[0]) for g in per_n]
    samples = [g["COMIC"].to_numpy(dtype=np.float64) for g in per_n]
    # mean COMIC, or Eq. 43 of the mean SSE (the paper warns the convention can move the optimum)
    resampled, objective = convention_samples(per_n, search.convention)
    shares, lo, hi, _ = argmin_bootstrap(resampled, objective)
    with np.errstate(divide="ignore"):  # a zero SSE: COMIC -inf, a valid minimum
        minimised = objective(np.array([r.mean() for r in resampled])[:, None])[:, 0]
    means = np.array([s.mean() for s in samples])
    stds = np.array([s.std(ddof=1) if len(s) > 1 else math.nan for s in samples])
    counts = np.array([len(s) for s in samples])
    se = np.where(counts > 1, stds / np.sqrt(counts), 0.0)
    table = pd.DataFrame(
        {"n": ns, "realisations": counts, "COMIC_mean": means, "COMIC_std": stds, "COMIC_se": se, "share": shares}
    )
    i_opt = int(np.argmin(minimised))
    optimum = {
        "n_opt": ns[i_opt],
        "ci_lo": ns[lo],
        "ci_hi": ns[hi],
        "bracket_lo": ns[lo - 1] if lo > 0 else ns[0],
        "bracket_hi": ns[hi + 1] if hi + 1 < len(ns) else ns[-1],
    }
    return table, optimum


def _unresolved(table: pd.DataFrame, n_opt: int) -> list[int]:
    """N whose mean COMIC is within 2 combined standard errors of the minimum's (judged on mean
    COMIC under either convention: its standard error is the one at hand)."""
    opt = table[table["n"] == n_opt].iloc[0]
    gap = (table["COMIC_mean"] - opt["COMIC_mean"]).abs()
    noise = np.sqrt(table["COMIC_se"] ** 2 + opt["COMIC_se"] ** 2)
    return table.loc[(gap <= 2 * noise) & (noise > 0), "n"].astype(int).tolist()


def next_plan(search: Search, plan: pd.DataFrame, realisations: pd.DataFrame) -> pd.DataFrame:
    """The plan after one more round: ``plan`` plus the blocks this round adds, or ``plan``
    with `done` set and the reason (REASONS) when the search stops."""
    k = int(plan["round"].max()) + 1
    table, opt = evaluate(search, realisations)
    ns = table["n"].tolist()

    def stop(reason):
        out = plan.copy()
        out["done"], out["reason"] = True, reason
        return out

    if opt["bracket_hi"] / opt["bracket_lo"] <= search.width:
        return stop(REASONS[4] if opt["n_opt"] in (ns[0], ns[-1]) else REASONS[0])
    if k > MAX_ROUNDS:
        return stop(REASONS[3])
    inside = [n for n in ns if opt["bracket_lo"] <= n <= opt["bracket_hi"]]
    new_n = []
    for a, b in zip(inside, inside[1:]):  # refine every gap of the bracket
        if b / a > search.min_step:
            mid = _valid_n(math.sqrt(a * b), search.fd)
            if a < mid < b and mid not in ns:
                new_n.append(mid)
    more = [] if search.fd else [n for n in _unresolved(table, opt["n_opt"]) if n in inside]
    base = int(plan["first"].min())
    added, spent = [], runs_in(plan)
    for n in sorted(new_n, key=lambda n: abs(math.log(n / opt["n_opt"]))):  # nearest the minimum first
        r = search.realisations
        if spent + r <= search.budget_runs:
            added.append((k, n, base, base + r - 1, False, ""))
            spent += r
    counts = dict(zip(table["n"], table["realisations"]))
    for n in sorted(more, key=lambda n: abs(math.log(n / opt["n_opt"]))):
        have = int(counts[n])
        extra = min(have, search.max_realisations - have)
        if extra > 0 and spent + extra <= search.budget_runs:
            added.append((k, n, base + have, base + have + extra - 1, False, ""))
            spent += extra
    if not added:
        wanted = bool(new_n) or any(counts[n] < search.max_realisations for n in more)
        return stop(REASONS[1] if wanted else REASONS[2])
    return pd.concat([plan, pd.DataFrame(added, columns=PLAN_COLUMNS)], ignore_index=True)


def result_table(search: Search, plan: pd.DataFrame, realisations: pd.DataFrame, costs: pd.DataFrame) -> pd.DataFrame:
    """Every visited N of a finished search with its statistics, the optimum, the cost spent and
    the estimated cost of the full sweep (RESULT_COLUMN_DOCS). ``costs``: columns n, seed, core_s."""
    table, opt = evaluate(search, realisations)
    first_round = plan.groupby("n")["round"].min()
    cost_n = costs.groupby("n")["core_s"].sum()
    per_run = costs.groupby("n")["core_s"].mean()
    table["round_added"] = table["n"].map(first_round).astype(int)
    table["core_s"] = table["n"].map(cost_n).astype(float)
    # a grid brackets its minimum between the argmin's two neighbours: to give the same bracket
    # a full sweep needs the step sqrt(bracket_hi / bracket_lo) over the whole range
    step = max(search.min_step, math.sqrt(opt["bracket_hi"] / opt["bracket_lo"]))
    count = math.ceil(math.log(search.n_hi / search.n_lo) / math.log(step)) + 1
    sweep = grid(search.n_lo, search.n_hi, count, search.fd)
    log_cost = np.interp(np.log(sweep), np.log(per_run.index.to_numpy(float)), np.log(per_run.to_numpy(float)))
    full = float(np.exp(log_cost).sum() * table["realisations"].max())
    out = table.assign(
        search=search.name,
        label=search.model.label(),
        time=search.time,
        convention=search.convention,
        **opt,
        reason=str(plan["reason"].iloc[-1]),
        rounds=int(plan["round"].max()) + 1,
        runs_spent=runs_in(plan),
        core_s_spent=float(table["core_s"].sum()),
        full_sweep_core_s=full,
    )
    return out[RESULT_COLUMNS]
