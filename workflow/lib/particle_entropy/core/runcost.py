"""The one cost model of a run: seconds of one run at a point, ``RunCost.seconds(point)``, counted
from what the run does, never timed, so that what it decides is the same on every machine. Two kinds:

- ``StepWork``: seconds = sum over the run's time steps of (per_step + per_unit x units + per_pair
  x pairs), where a step advances ``units`` particles or nodes (``per="work"``: as the run tables'
  `work` counts them, particles or FD's N + 1 nodes; ``per="n"``: the case's N) and visits ``pairs``
  particle pairs (a pair counter, given only where its constants price pairs). Its point is a
  resolved RunConfig. Each user keeps its own calibrated constants: the scenes' (settings.SCENE's
  `cost`, fitted by benchmarks/calibrate_scene_costs.py) and the simulation jobs' order
  (pipeline/jobcost.py, fitted to the paper run's jobs).
- ``Tabulated``: seconds per run written at some searched values (an optimum search's `cost`,
  calibrated by benchmarks/calibrate_search_costs.py), interpolated in log-log on the search's own
  axis and extrapolated with the end segments' slopes. Its point is the searched value.

The searches ask a point's cost through AdaptiveSearch.run_seconds (analysis/search.py), which
each kind answers with its model's ``seconds``. Units: seconds (of one core).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .runconfig import RunConfig
from .timegrid import time_steps, times

UNITS = ("work", "n")  # what StepWork's per_unit prices: a unit of the run tables' work, or one of the case's N
MIN_SECONDS = 1e-9  # a tabulated cost below this is taken as this (its logarithm stays finite)
MAX_SLOPE = 2.0  # no run here costs more than N^2 (steps^2): extrapolated slopes are kept in [-2, 2]


class RunCost(ABC):
    """A model of the seconds one run costs at a point (the kind says what a point is)."""

    @abstractmethod
    def seconds(self, point) -> float:
        """Seconds of one run at ``point`` [s]."""


@dataclass(frozen=True)
class Tally:
    """What a run does, counted: time steps, units of work (particle- or node-steps) and particle
    pairs visited; either totals, or arrays with one entry a step (steps then 1 each)."""

    steps: float | np.ndarray
    work: float | np.ndarray
    pairs: float | np.ndarray = 0.0


def run_steps(cfg: RunConfig) -> np.ndarray:
    """The time steps a run takes [T]: particles on their case's time grid, FD always on the exact
    one (its fixed step ends at t_final)."""
    grid = cfg.time_grid if cfg.method != "fd" else "exact"
    return time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, grid)


def units_per_step(cfg: RunConfig, per: str = "work") -> int:
    """The units one step advances: ``per="work"`` as a run table's `work` counts them (N particles,
    FD's (N + 1)^d nodes); ``per="n"`` the case's N."""
    if per not in UNITS:
        raise ValueError(f"per={per!r}: one of {', '.join(UNITS)}")
    return (cfg.n + 1) ** cfg.dim if per == "work" and cfg.method == "fd" else cfg.n


PairCount = Callable[[RunConfig, np.ndarray, np.ndarray], np.ndarray]  # (cfg, dt, step end times) -> pairs a step


@dataclass(frozen=True)
class StepWork(RunCost):
    """seconds = sum over steps of (per_step + per_unit x units + per_pair x pairs) [s]: a step's own
    cost (measures, records), each unit it advances (``per``: UNITS) and each pair it visits.

    Without a pair counter the run is counted in totals (steps, steps x units), as its table counts
    them; with one, step by step (a step's pairs follow its width). The same sum either way, up to
    rounding."""

    per_step: float  # [s a step]
    per_unit: float  # [s a unit a step]
    per_pair: float = 0.0  # [s a pair a step]
    per: str = "work"
    pairs: PairCount | None = None

    def counted(self, tally: Tally) -> float:
        """The seconds of a tally (totals or per step) [s]."""
        each = self.per_step * tally.steps + self.per_unit * tally.work + self.per_pair * tally.pairs
        return float(np.sum(each))

    def tally(self, cfg: RunConfig) -> Tally:
        """What a run of the resolved ``cfg`` does, known before it runs (run_steps, units_per_step,
        the pair counter): in totals, or step by step with a pair counter."""
        dt = run_steps(cfg)
        units = units_per_step(cfg, self.per)
        if self.pairs is None:
            return Tally(dt.size, dt.size * units)
        return Tally(np.ones(dt.size), np.full(dt.size, float(units)), self.pairs(cfg, dt, times(dt)[1:]))

    def seconds(self, point: RunConfig) -> float:
        """Seconds of one run of the resolved RunConfig ``point`` [s]."""
        return self.counted(self.tally(point))


class Tabulated(RunCost):
    """Seconds per run tabulated at searched values ``xs`` (increasing), interpolated linearly in u -
    log seconds, where u = ``to_u(x)`` is the search's axis (log N; log(dt_growth - 1)), and
    extrapolated with the end segments' slopes, kept in [-MAX_SLOPE, MAX_SLOPE]; one value alone:
    the slope ``alone`` (cost proportional to N: 1; to the steps of a growth search: -1)."""

    def __init__(self, xs, seconds, to_u: Callable = np.log, alone: float = 1.0):
        self.u = np.asarray(to_u(xs), dtype=np.float64)
        self.c = np.log(np.maximum(seconds, MIN_SECONDS))
        self.to_u = to_u
        self.lo, self.hi = self._slope(0, 1, alone), self._slope(-2, -1, alone)

    def _slope(self, i: int, j: int, alone: float) -> float:
        u, c = self.u, self.c
        return alone if len(u) < 2 else float(np.clip((c[j] - c[i]) / (u[j] - u[i]), -MAX_SLOPE, MAX_SLOPE))

    def seconds(self, point: float) -> float:
        """Seconds of one run at the searched value ``point`` [s]."""
        v = float(self.to_u(point))
        if v < self.u[0]:
            return float(math.exp(self.c[0] + self.lo * (v - self.u[0])))
        if v > self.u[-1]:
            return float(math.exp(self.c[-1] + self.hi * (v - self.u[-1])))
        return float(math.exp(np.interp(v, self.u, self.c)))
