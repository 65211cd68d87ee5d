"""The adaptive-search engine: rounds of seed blocks, each round a plan read back for the next.

A search kind (a COMIC minimum over N, `optimum`; a scene's cheapest model that meets its
target, `scene_search`) says only how it picks its next points from the runs so far
(AdaptiveSearch.next_plan), which run table each plan row names and how it reads them; the
engine owns what they share:
- the plan: a table with one row per seed block added in some round, columns ``round``,
  ``first`` and ``last`` (the block's seeds), ``done`` (set on every row once the search stops)
  beside the kind's own (PLAN_COLUMNS, check_plan_columns, new_plan, stopped, next_round);
- seed blocks: a point's next ``count`` runs take the seeds after the ``have`` it has run, from
  the search's base seed on (seed_block), so every block is an ordinary, cached simulation job;
- run reading shared by every kind: a run's measured core-seconds, its steps' wall times summed
  (measured_core_s), reported beside what the kind counts and never used to decide;
- the cost a kind counts: one question, a run's seconds at a point (AdaptiveSearch.run_seconds,
  answered by the kind's cost model, core/runcost.RunCost.seconds), and the seconds of runs at
  points (counted_seconds);
- the rounds: round 0 reads nothing, round k reads plan k-1 and its runs (none after a finished
  plan), and the finished plan is the first of at most ``max_plans`` plans with ``done`` set
  (round_inputs, final_inputs: what the Snakemake checkpoints of workflow/rules/search.smk ask for).
A new kind writes its ``next_plan`` (and ``first_plan``), its run reader, a result table and a
plot. No Snakemake here: plans are found through a ``plan_at(k)`` callable (a checkpoint's
output) and a plan's run tables through a ``plan_paths(plan)`` one (the workflow knows the paths).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence

import pandas as pd

from ..core.io import read_parquet
from .rounds import read_path

ROUND, FIRST, LAST, DONE = "round", "first", "last", "done"
PLAN_COLUMNS = (ROUND, FIRST, LAST, DONE)  # every kind's plan has these, beside its own columns
WALL, CORE_S = "wall_s", "core_s"  # a step's measured wall time (run tables); a run's, summed
PlanPaths = Callable[[pd.DataFrame], list[str]]  # the run table of each row of a plan, in its order


def check_plan_columns(columns: Sequence[str]) -> list[str]:
    """A kind's plan columns (in its order), refused unless they hold the engine's (PLAN_COLUMNS) once each."""
    columns = list(columns)
    missing = [c for c in PLAN_COLUMNS if columns.count(c) != 1]
    if missing or len(set(columns)) != len(columns):
        raise ValueError(f"plan columns {columns}: each of {', '.join(PLAN_COLUMNS)} once, no column twice")
    return columns


def seed_block(base_seed: int, have: int, count: int) -> tuple[int, int]:
    """The first and last seed of a point's next ``count`` runs after the ``have`` it has run:
    base_seed + have to base_seed + have + count - 1."""
    if have < 0 or count < 1:
        raise ValueError(f"a seed block of {count} runs after {have}: count >= 1, have >= 0")
    return base_seed + have, base_seed + have + count - 1


def measured_core_s(steps: pd.DataFrame, keys: Sequence[str]) -> pd.DataFrame:
    """Measured core-seconds of every run of per-step tables (columns ``keys`` naming a run, and
    wall_s): one row per run, ``keys`` and core_s, its steps' wall times summed."""
    keys = list(keys)
    if steps.empty:
        return pd.DataFrame(columns=[*keys, CORE_S])
    return steps.groupby(keys, as_index=False)[WALL].sum().rename(columns={WALL: CORE_S})


def counted_seconds(search: AdaptiveSearch, points, counts) -> float:
    """Seconds of ``counts[i]`` runs at each ``points[i]`` by the search's cost model (run_seconds) [s]."""
    return float(sum(c * search.run_seconds(x) for x, c in zip(points, counts)))


def runs_in(plan: pd.DataFrame) -> int:
    """Runs (seeds) of every block of a plan."""
    return int((plan[LAST] - plan[FIRST] + 1).sum())


def next_round(plan: pd.DataFrame | None) -> int:
    """The round that follows ``plan`` (0 before any plan)."""
    return 0 if plan is None else int(plan[ROUND].max()) + 1


def new_plan(rows, columns: Sequence[str], done: bool | None = None) -> pd.DataFrame:
    """A plan of ``rows`` (tuples in ``columns``' order, or records) with the kind's columns; ``done``
    given: set on every row."""
    out = pd.DataFrame(rows, columns=[c for c in columns if done is None or c != DONE])
    if done is not None:
        out[DONE] = done
    return out


def stopped(plan: pd.DataFrame, **fields) -> pd.DataFrame:
    """``plan`` finished: ``done`` set on every row, and ``fields`` (a kind's own, e.g. a reason)."""
    out = plan.copy()
    out[DONE] = True
    for key, value in fields.items():
        out[key] = value
    return out


def extended(plan: pd.DataFrame, rows, columns: Sequence[str]) -> pd.DataFrame:
    """``plan`` with the blocks ``rows`` (tuples in ``columns``' order) of a new round appended."""
    return pd.concat([plan, pd.DataFrame(rows, columns=list(columns))], ignore_index=True)


class AdaptiveSearch(ABC):
    """One search of a kind: how its next points are chosen, and where its runs are. The engine
    (round, round_inputs, final_inputs) does the rest."""

    # its rounds write what they read (read_path) and read only the run tables of the rows the last
    # round added (runs_since): round k otherwise reads every run of rounds 0 .. k-1 again
    KEEPS_READS: bool = False

    @property
    @abstractmethod
    def title(self) -> str:
        """How messages name the search: "optimum search <name>", "scene <name>"."""

    @property
    @abstractmethod
    def max_plans(self) -> int:
        """The most plans the search writes: a finished plan is among rounds 0 .. max_plans - 1."""

    @abstractmethod
    def first_plan(self, base_seed: int) -> pd.DataFrame:
        """Round 0: the first seed blocks, seeds from ``base_seed`` on."""

    @abstractmethod
    def next_plan(self, plan: pd.DataFrame, runs, base_seed: int) -> pd.DataFrame:
        """The plan after ``plan`` given what read_runs read of its runs: ``plan`` and the next
        round's blocks, or ``plan`` stopped. The kind's own rule: the only part it must write."""

    @abstractmethod
    def read_runs(self, plan: pd.DataFrame, paths: list[str]):
        """What next_plan needs of the run tables of ``plan``'s rows at ``paths``."""

    def run_seconds(self, point) -> float:
        """Seconds of one run at ``point`` (a searched value; a scene's (candidate, n)) by the kind's
        cost model (core/runcost.RunCost.seconds): what its budget counts. NaN: the kind has none."""
        return math.nan

    def round(self, plan: pd.DataFrame | None, paths: list[str], base_seed: int) -> pd.DataFrame:
        """One round: the first plan (``plan`` None), else the plan after ``plan`` and its runs at ``paths``."""
        if plan is None:
            return self.first_plan(base_seed)
        return self.next_plan(plan, self.read_runs(plan, list(paths)), base_seed)

    def runs_since(self, plan: pd.DataFrame, paths: list[str], earlier: pd.DataFrame | None) -> pd.DataFrame:
        """What read_runs reads of ``plan``'s runs at ``paths``, given ``earlier``: what the round before
        read (of every row but those ``plan``'s last round added, which come last: ``extended``), so
        that only the new rows' run tables are read. ``earlier`` None: every row's. A kind whose
        read_runs gives a table with a row per run, in the plan's order (KEEPS_READS)."""
        new = (plan[ROUND] == plan[ROUND].max()).to_numpy()  # an empty plan: none, and all() holds
        if earlier is None or new.all():
            return self.read_runs(plan, list(paths))
        first = int(new.argmax())
        if not new[first:].all():
            raise ValueError(f"{self.title}: a plan's last round must add its rows after the earlier ones")
        added = self.read_runs(plan.iloc[first:].reset_index(drop=True), list(paths)[first:])
        return added if earlier.empty else pd.concat([earlier, added], ignore_index=True)

    def round_inputs(self, k: int, plan_at: Callable[[int], str], plan_paths: PlanPaths) -> dict:
        """What round ``k`` reads: nothing for round 0; plan k-1 (its path: ``plan_at(k - 1)``) and
        its runs (``plan_paths``: the run table of each row), and for a kind that KEEPS_READS what
        round k-1 read of them (``read``: read_path). A finished plan has no round after it (ValueError)."""
        if k == 0:
            return {}
        path = plan_at(k - 1)
        plan = read_parquet(path)  # every page checked (core.io)
        if plan[DONE].any():
            raise ValueError(f"{self.title} stopped at round {k - 1}: there is no round {k}")
        out = {"plan": path, "runs": plan_paths(plan)}
        return {**out, "read": read_path(path)} if self.KEEPS_READS and k > 1 else out

    def final_inputs(self, plan_at: Callable[[int], str], plan_paths: PlanPaths) -> dict:
        """The first finished plan and its runs, and for a kind that KEEPS_READS what its round read
        of them (``read``: a finished plan adds no row, so that is every run of it); plans are asked
        for one at a time (``plan_at``, a checkpoint's output), at most ``max_plans`` (ValueError if
        none is finished)."""
        for k in range(self.max_plans):
            path = plan_at(k)
            plan = read_parquet(path)  # every page checked (core.io)
            if plan[DONE].all():
                out = {"plan": path, "runs": plan_paths(plan)}
                return {**out, "read": read_path(path)} if self.KEEPS_READS else out
        raise ValueError(f"{self.title}: no finished plan after {self.max_plans} rounds")
