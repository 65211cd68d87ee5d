"""The cheapest model of a scene (scenes/scene.py) that reaches its accuracy, and the COMIC-best.

For each candidate, the smallest rung of its affordable ladder (Candidate.ladder, within the budget)
whose mean error meets the target: the one-sided upper bound mean + t_q s / sqrt(R) of R
realisations, q = 1 - 0.05 / (rungs blocks) (answer_confidence: Bonferroni over every look at every
rung, so that the answer, not each look, holds with 95 %; FD is deterministic: one run, its error).
The answer is the brute force's, as if every rung had run: errors need not fall with n (noise; FD
central's error can rise with it). A particle rung whose interval straddles the target (mean - t_q
se < target < mean + t_q se) gets another block of ``realisations`` seeds until it falls on one
side or reaches ``max_realisations`` (state): its final state depends on its own seeds only. The
search climbs CLIMB rungs a round until a rung passes (or the top is reached), then runs in one
round every unvisited rung below the lowest pass (on a ratio-2 ladder they cost about what that
rung does), refining straddling rungs that can still be the answer in the same rounds; it stops
once every rung below the lowest pass has run and settled (_next_rungs). Each round is a Snakemake checkpoint whose plan
names the run tables to make; the path depends on the config and the errors only, never on timings.
The rounds, plans, seed blocks and the rounds' inputs are the search engine's (search.py; the kind:
SceneSearch); this module is the rule for a candidate's next rungs (_next_rungs) and the result.

Costs are counted, not timed: work (particle- or node-steps, the run tables' ``work``) times the
scene's cost model of its method (``scenes.<name>.cost``: seconds a step and a unit of work, a
step-work model of core/runcost.py: Scene.cost_model); the measured core-seconds stand beside them.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pandas as pd

from ..core import plane
from ..core.io import read_parquet
from ..scenes import defined
from ..scenes.scene import SCENE_RUN_PATTERN, Candidate, Scene, sweep_of
from .resampling import CONFIDENCE
from .search import WALL, AdaptiveSearch, check_plan_columns, measured_core_s, new_plan, next_round, seed_block

CLIMB = 2  # rungs climbed a round while no rung passes
# half_step: the row runs the candidate at half its time step (Scene.half_step), checking its answer
PLAN_COLUMNS = check_plan_columns(["candidate", "label", "n", "half_step", "first", "last", "round", "done"])
NEGATIVE_TOLERANCE = 1e-12  # a node or particle mass below -this of the total, at any step, is a negative concentration
# The most of its unit mass a run may lose (FD: through its window's zero ends) and still be judged.
# H_C and E are computed on the mass left: a Gaussian that lost 1e-3 of its tails has an entropy
# 0.007 nats (E 0.7 %) below the whole's, 1e-2 already 0.048. The window lets at most 2 erfc(3) =
# 4.4e-5 of the exact plume out (Scene's window check); a coarse grid's heavier tails and numerical
# dispersion add to it (the paper's window at t = 1000: n = 30 loses 9.9e-5, n = 8 1.7e-3). FD's
# steps balance their mass to round-off (models/fd.py) and particles conserve it, so this bound is
# on what leaves through the ends, not on round-off
MASS_LOSS_MAX = 1e-3


RESULT_COLUMN_DOCS = {  # result(): one row per visited (candidate, n) of a finished scene
    "candidate": "the candidate's index in `scenes.<name>.candidates` as written (a Peclet scene: in its base's; "
    "at v = 0 an FD candidate that differs from an earlier one only in advection repeats its rows)",
    "label": "the candidate's name: method, kernel and dimensions (FD: its advection scheme and its step, "
    "dt=fd_dt or Cr=courant)",
    "method": "fd, pt or mtpt",
    "n": "the resolution: particles, or FD intervals",
    "realisations": "runs averaged, over every seed block run (particles: a multiple of the scene's `realisations`, "
    "more where the interval straddled the target, at most `max_realisations`; FD: 1, deterministic; 0: not run, "
    "its first rung over the budget)",
    "error_mean": "the mean error of the scene's `measure` at t_final over the realisations",
    "error_lo": "lower end of the mean's two-sided 95 % interval (Student t; FD: the error)",
    "error_hi": "upper end of that interval",
    "error_upper95": "the mean's one-sided upper bound at 1 - 0.05 / (rungs blocks), rungs those of the "
    "candidate's ladder and blocks the seed blocks a rung may run, `max_realisations` / `realisations` (Student t, "
    "Bonferroni-corrected over every look at every rung so that the answer, the lowest passing rung, holds with "
    "95 %; FD: the error): the rung meets the target when it is <= `target`",
    "meets": "the rung is scored and `error_upper95` <= `target`",
    "unscored": "why the rung cannot be judged (a concentration below -1e-12 of the total at any step: its "
    "first such step, the minimum and, for FD in a flow, the grid Peclet and Courant numbers; more than 1e-3 of "
    "the mass lost through the FD window's ends, or gained, in a reactive run of A + C or of B + C; not run: over "
    "budget), else empty",
    "steps": "time steps of a run",
    "work": "particle-steps (FD node-steps) of a run, MTPT substeps counted",
    "cost_s": "the counted cost of one run: `steps` and `work` times the scene's `cost` (a rung not run: "
    "Scene.run_cost) [s]",
    "core_s": "the measured core-seconds of one run (the sum of its steps' wall time) [s]",
    "COMIC_points": "mean COMIC (Eq. 43) at the common measurement points (NaN if unscored)",
    "scene": "the scene's name",
    "stopped": "why the candidate's search stopped: met (at the low end, or every rung below it fails), not met "
    "(within n_range, or the budget: every rung within it run), over budget, an at-rest twin, or target undefined "
    "(the reference makes no product, a field of zeros meets the target, or its own error reaches it: nothing runs "
    "and nothing is recommended)",
    "n_below": "the highest failing rung visited below `n` (NaN if none); every rung below a candidate's answer "
    "is run, so at its first passing row this is the rung just below",
    "recommended": "the cheapest candidate's smallest rung that meets the target (at most one row)",
    "comic_best": "the lowest `COMIC_points` of the scene (one row)",
    "target": "the scene's `target.value`",
    "budget": "the scene's `budget`, the most counted cost of a run (inf: none) [s]",
    "measure": "the scene's `target.measure`: rmse, entropy or dilution",
    "peclet": "the scene's Peclet number |v| L / D, L its FD window fd_length (the span around the source that "
    "holds the plume at rest, without the path v t_final): advection across the plume's own extent against "
    "dispersion",
    "grid_peclet": "FD in a flow: the grid Peclet number |v| dx / D of the rung (NaN for particles and at rest)",
    "courant": "FD in a flow: the Courant number |v| dt / dx of the rung's step (NaN for particles and at rest)",
    "half_step_error": "at a candidate's answer (its lowest passing rung): the mean error of the same rung and "
    "seeds run at half the time step (Scene.half_step: FD's fd_dt or Courant number halved, a particle's dt0 and "
    "growth - 1 halved); NaN on other rows",
    "half_step_upper95": "that mean's upper bound, at the level of `error_upper95`",
    "holds_at_half_step": "at a candidate's answer: whether it also meets the target at half its step (an answer "
    "that does not depends on its step, and is never recommended); NaN on other rows",
}


def error(scene: Scene, row: pd.Series | dict) -> float:
    """The scene's error measure of one run at t_final (its last row)."""
    if scene.measure == "rmse":
        return math.sqrt(row["SSE_points"] / scene.n_points)
    if scene.measure == "entropy":
        return abs(row["H_C"] - row["H_C_analytic"])
    if scene.measure == "product":  # a reactive scene's product mass against its reference
        return row["product_error"]
    if scene.measure == "product_rmse":  # and its product's concentration at the points
        return math.sqrt(row["SSE_points_C"] / scene.n_points)
    return abs(row["E"] / row["E_analytic"] - 1.0)


def unscored(scene: Scene, row) -> str:
    """Why a run cannot be judged ('' if it can): a concentration below -NEGATIVE_TOLERANCE of the
    total at any step (an unstable or oscillating scheme, e.g. FD central past grid Peclet 2: such a
    state has no entropy, even if later steps smooth it out; read_runs finds the first), and a run
    whose mass at t_final is off its unit initial mass by more than MASS_LOSS_MAX (a plume that left
    its FD window) has H_C and E of a remnant: neither is ever chosen."""
    if row["negative_step"] >= 0:
        why = (
            f"negative concentrations from step {int(row['negative_step']):,} (t = {row['negative_t']:.4g}): "
            f"minimum {row['mass_min']:.3g} of the total"
        )
        if scene.candidates[int(row["candidate"])].case.method == "fd" and scene.speed != 0.0:
            cand = scene.candidates[int(row["candidate"])]
            peclet, courant = grid_numbers(scene, cand, int(row["n"]), row["negative_dt"])
            why += f"; grid Peclet {peclet:.3g}{' > 2' if peclet > 2 else ''}, Courant {courant:.3g}"
        return why
    for name, lost in conserved_losses(row).items():
        if not abs(lost) <= MASS_LOSS_MAX:
            what = "lost through the window's ends" if lost > 0 else "gained"
            return f"{name} {what}: {abs(lost):.3g} of it (at most {MASS_LOSS_MAX:g})"
    if not np.isfinite(error(scene, row)):
        return f"its {scene.measure} error is not finite"
    return ""


def conserved_losses(row) -> dict[str, float]:
    """The fraction of each conserved total a run lost by t_final (negative: gained): its mass (A + C
    held, in a reactive run), and a reactive run's B + C (mass_lost_BC; NaN in a conservative run)."""
    reactive = "mass_lost_BC" in row and np.isfinite(row["mass_lost_BC"])
    out = {"A + C" if reactive else "mass": 1.0 - row["mass_total"]}
    if reactive:
        out["B + C"] = row["mass_lost_BC"]
    return out


@functools.cache
def _t_quantile(quantile: float, dof: int):
    """Student t's ``quantile`` at ``dof`` degrees of freedom (scipy.special.stdtrit, the inverse of its
    CDF: scipy.stats.t.ppf's own, without scipy.stats' 0.6 s import in every round), kept: a search asks
    for the same few hundreds of times."""
    from scipy.special import stdtrit

    return float(stdtrit(dof, quantile))


def _t_margin(errors: np.ndarray, quantile: float) -> float:
    """Student t's ``quantile`` times the mean's standard error; 0 for a single value."""
    if errors.size == 1:
        return 0.0
    return float(_t_quantile(quantile, errors.size - 1) * errors.std(ddof=1) / math.sqrt(errors.size))


def upper_bound(errors: np.ndarray, confidence: float = CONFIDENCE) -> float:
    """The mean's one-sided ``confidence`` upper bound (Student t; 95 % unless told); one value: itself."""
    errors = np.asarray(errors, dtype=float)
    return float(errors.mean() + _t_margin(errors, confidence))


def answer_confidence(scene: Scene, candidate: Candidate) -> float:
    """The one-sided confidence of each look at a rung's bound, Bonferroni-corrected over every look
    the answer could rest on: 1 - (1 - CONFIDENCE) / (rungs blocks), rungs the candidate's ladder's,
    blocks the seed blocks a rung may run (_blocks; FD: one, and no margin). The search takes the
    lowest passing rung of up to ``rungs``, and judges a straddling rung again after each block: at
    95 % a look, or corrected over the rungs alone, a rung whose true mean is above the target became
    the answer in far more than 5 % of the hardest noisy ladders (benchmarks/answer_rate.py; the
    rates: docs/scenes.md). A constant of the candidate, so a rung's state depends on its own runs
    only and the search still equals brute force."""
    return 1.0 - (1.0 - CONFIDENCE) / (len(candidate.ladder()) * _blocks(scene, candidate))


def seeds(scene: Scene, candidate: Candidate, base_seed: int, block: int = 0) -> tuple[int, int]:
    """The first and last seed of a rung's seed block ``block`` (0, 1, ...): base_seed + block R to
    base_seed + (block + 1) R - 1, R the scene's realisations (FD: one run, block 0)."""
    count = block_size(scene, candidate)
    return seed_block(base_seed, block * count, count)


def block_size(scene: Scene, candidate: Candidate) -> int:
    """The runs of one seed block of a candidate's rung: the scene's realisations (FD: one run)."""
    return 1 if candidate.case.method == "fd" else scene.realisations


# judged(): a row per (candidate, n, half_step) run; result() folds the half-step rows into their answers'
JUDGED_COLUMNS = [*list(RESULT_COLUMN_DOCS)[: list(RESULT_COLUMN_DOCS).index("COMIC_points") + 1], "half_step"]


def judge(scene: Scene, candidate: Candidate, errors: np.ndarray, reason: str = "") -> dict:
    """A rung's verdict from its runs' errors: realisations, error mean, its two-sided 95 % interval
    (t), its one-sided upper bound at answer_confidence, whether that meets the target (never if the
    rung is unscored: ``reason``), and ``reason``. The judged row's part that state() reads."""
    errors = np.asarray(errors, dtype=float)
    mean = float(errors.mean())
    half = _t_margin(errors, 0.5 * (1.0 + CONFIDENCE))  # two-sided
    up = upper_bound(errors, answer_confidence(scene, candidate))
    return {
        "realisations": int(errors.size),
        "error_mean": mean,
        "error_lo": mean - half,
        "error_hi": mean + half,
        "error_upper95": up,
        "meets": bool(not reason and up <= scene.value),
        "unscored": reason,
    }


def judged(scene: Scene, runs: pd.DataFrame) -> pd.DataFrame:
    """One row per (candidate, n) visited: error mean, its 95 % interval (two-sided, t) and upper
    bound, whether it meets the target, why not scored, work and core-seconds, COMIC at the points
    (no runs: no rows)."""
    rows = []
    if runs.empty:
        return pd.DataFrame(rows, columns=JUDGED_COLUMNS)
    # the records of every run at once, each group's picked by position: the same dicts as each
    # group's own to_dict("records"), without pandas' per-column cost once per group
    if "half_step" not in runs:
        runs = runs.assign(half_step=False)
    every = runs.to_dict("records")
    groups = runs.groupby(["candidate", "n", "half_step"], sort=True)
    for (ci, n, at_half), g in groups:
        cand = scene.candidates[ci]
        records = [every[i] for i in groups.indices[(ci, n, at_half)]]
        reason = next((why for why in (unscored(scene, r) for r in records) if why), "")
        errs = np.array([error(scene, r) for r in records])
        rows.append(
            {
                "candidate": int(ci),
                "label": cand.label,
                "method": cand.case.method,
                "n": int(n),
                **judge(scene, cand, errs, reason),
                "steps": float(g["steps"].mean()),
                "work": float(g["work"].mean()),
                "cost_s": scene.cost_s(cand.case.method, g["steps"].mean(), g["work"].mean()),
                "core_s": float(g["core_s"].mean()),
                "COMIC_points": float(g["COMIC_points"].mean()) if not reason else math.nan,
                "half_step": bool(at_half),
            }
        )
    return pd.DataFrame(rows, columns=JUDGED_COLUMNS)


def max_rounds(scene: Scene) -> int:
    """The most plans a scene's search writes (common.smk asks for this many): while no rung passes, a
    candidate's climb reaches its top rung by round T = ceil((rungs - 1) / CLIMB); the round after, at
    the latest, it fills every rung below its lowest pass (or all); each rung visited takes at most
    ``blocks`` rounds to settle (FD: one); the round after those runs the answer at half its step
    (one round, every seed block at once), and the round after that finds it stopped: T + blocks + 3."""
    return max(math.ceil((len(c.ladder()) - 1) / CLIMB) + _blocks(scene, c) + 3 for c in scene.candidates)


def _twin_reason(scene: Scene, ci: int) -> str:
    return f"the same runs as candidates[{scene.same_as(ci)}]: at v = 0 advection moves nothing"


def affordable(scene: Scene, candidate: Candidate) -> list[int]:
    """The rungs of a candidate's ladder whose run costs at most the scene's budget (Scene.run_cost)."""
    ladder = candidate.ladder()
    if not math.isfinite(scene.budget):
        return ladder
    return [n for n in ladder if scene.run_cost(candidate, n) <= scene.budget]


def _blocks(scene: Scene, candidate: Candidate) -> int:
    """The most seed blocks a rung of ``candidate`` runs (FD, deterministic: one)."""
    return 1 if candidate.case.method == "fd" else scene.blocks


PASS, FAIL, OPEN = "pass", "fail", "open"


def state(scene: Scene, candidate: Candidate, row) -> str:
    """A visited rung's state from its judged row: PASS (its upper bound meets the target), FAIL
    (settled: unscored, FD, its one-sided lower bound mean - t_q se at or above the target, q the
    bound's answer_confidence, or ``max_realisations`` run) or OPEN (its interval straddles the
    target: another seed block may settle it). A function of the rung's own runs only."""
    if row["meets"]:
        return PASS
    if row["unscored"] or candidate.case.method == "fd" or row["realisations"] >= scene.max_realisations:
        return FAIL
    lower = 2.0 * row["error_mean"] - row["error_upper95"]  # the bound's margin, on the other side
    return OPEN if lower < scene.value else FAIL


def _next_rungs(scene: Scene, candidate: Candidate, visited: pd.DataFrame) -> tuple[list[tuple[int, int, bool]], str]:
    """The next (resolution, seed block, at half step) runs of one candidate's search, or ([], why it stops).

    L is the lowest rung that passes (a pass is settled: its bound is below the target). Every rung
    at or below L (all while none passes) may still be the answer: an open one gets its next seed
    block; once L exists, or the climb has reached the top rung, every unvisited rung below L (all)
    gets its first; before, the climb visits the rung CLIMB above the highest visited. The search
    stops when every rung below L (all) has run and settled: L is then the lowest passing rung of
    the brute force that settles every rung by the same rule (state). Then L runs once more at half
    its time step, on the same seed blocks (Scene.half_step): the answer holds only if that meets the
    target too (_half_step_check)."""
    if len(visited) and "half_step" in visited:
        checks, visited = visited[visited["half_step"].astype(bool)], visited[~visited["half_step"].astype(bool)]
    else:
        checks = visited.iloc[0:0]
    whole = candidate.ladder()
    ladder = affordable(scene, candidate)
    if not ladder:
        return [], f"over budget: n = {whole[0]:,} costs {scene.run_cost(candidate, whole[0]):.3g} s a run"
    if visited.empty:
        return [(ladder[0], 0, False)], ""
    rows = {int(r["n"]): r for r in visited.to_dict("records")}
    states = [state(scene, candidate, rows[n]) if n in rows else None for n in ladder]
    lowest = states.index(PASS) if PASS in states else None
    limit = len(ladder) if lowest is None else lowest
    top = max(i for i, s in enumerate(states) if s is not None)
    per_block = block_size(scene, candidate)
    todo = [
        (ladder[i], int(rows[ladder[i]]["realisations"]) // per_block, False) for i in range(limit) if states[i] == OPEN
    ]
    if lowest is not None or top == len(ladder) - 1:
        todo += [(ladder[i], 0, False) for i in range(limit) if states[i] is None]
    else:
        todo.append((ladder[min(top + CLIMB, len(ladder) - 1)], 0, False))
    if todo:
        return sorted(todo), ""
    if lowest is not None:
        answer = ladder[lowest]
        check = checks[checks["n"] == answer]
        if check.empty:  # the answer's every seed block again, at half the step
            return [(answer, b, True) for b in range(int(rows[answer]["realisations"]) // per_block)], ""
        met = "met at n_range's low end" if lowest == 0 else "met: every rung below it fails"
        return [], met + _half_step_check(scene, candidate, check.iloc[0])
    if len(ladder) < len(whole):
        return [], f"not met within the budget (n <= {ladder[-1]:,})"
    return [], "not met within n_range"


def _half_step_check(scene: Scene, candidate: Candidate, row) -> str:
    """What a stop reason adds for an answer's run at half its step (``row``, judged): '' if it meets the
    target too, else that the answer depends on its step, with the half step's error and bound."""
    if row["meets"]:
        return ""
    why = row["unscored"] or f"error {row['error_mean']:.3g}, bound {row['error_upper95']:.3g} > {scene.value:g}"
    return f", but not at half its step ({scene.half_step(candidate).label}: {why}): the answer depends on its step"


def next_plan(
    scene: Scene, plan: pd.DataFrame | None, runs: pd.DataFrame | None, base_seed: int, undefined: str = ""
) -> pd.DataFrame:
    """The plan after ``plan`` (None: round 0) given the runs it made: every earlier row, and a row
    per run table each candidate still searching makes next (a rung's seed block: seeds); ``done``
    on every row when no candidate searches on, at once when the target is ``undefined`` (why, from
    scenes/defined.py: no run can answer it)."""
    k = next_round(plan)
    rows = [] if plan is None else plan.drop(columns="done").to_dict("records")
    if undefined:
        return new_plan(rows, PLAN_COLUMNS, done=True)
    if runs is not None and len(runs) and "half_step" not in runs:
        raise ValueError("a scene's runs need their 'half_step' column (read_runs): without it no check is seen")
    table = judged(scene, runs) if runs is not None and len(runs) else pd.DataFrame(columns=JUDGED_COLUMNS)
    planned = {(r["candidate"], r["n"], r["half_step"], r["first"], r["last"]) for r in rows}
    added = False
    for ci, cand in enumerate(scene.candidates):
        if scene.same_as(ci) != ci:  # its runs are an earlier candidate's (result copies its rows)
            continue
        visited = table[table["candidate"] == ci] if len(table) else table
        todo, _why = _next_rungs(scene, cand, visited)
        for n, block, at_half in todo:
            lo, hi = seeds(scene, cand, base_seed, block)
            label = scene.half_step(cand).label if at_half else cand.label
            row = {"candidate": ci, "label": label, "n": int(n), "half_step": at_half, "first": lo, "last": hi}
            if (ci, int(n), at_half, lo, hi) in planned:  # a search that repeats a run would never end
                where = f"{label} at n = {n} on seeds {lo}-{hi}"
                raise RuntimeError(f"scene {scene.name}: round {k} would run {where} again")
            rows.append({**row, "round": k})
            added = True
    return new_plan(rows, PLAN_COLUMNS, done=not added)


class SceneSearch(AdaptiveSearch):
    """A scene's search as a kind of the search engine (search.AdaptiveSearch): its rule for the
    next points is next_plan (each candidate's _next_rungs)."""

    def __init__(self, scene: Scene, reference: dict | None = None):
        self.scene = scene
        # why the target cannot be judged against a reactive scene's solved reference ('' if it can)
        self.undefined = "" if reference is None else defined.undefined(scene.measure, scene.value, reference)

    @property
    def title(self) -> str:
        return f"scene {self.scene.name}"

    @property
    def max_plans(self) -> int:
        return max_rounds(self.scene)

    def first_plan(self, base_seed: int) -> pd.DataFrame:
        return next_plan(self.scene, None, None, base_seed, self.undefined)

    def next_plan(self, plan: pd.DataFrame, runs: pd.DataFrame, base_seed: int) -> pd.DataFrame:
        return next_plan(self.scene, plan, runs, base_seed, self.undefined)

    KEEPS_READS = True  # read_runs: a row per run, in the plan's order

    def read_runs(self, plan: pd.DataFrame, paths: list[str]) -> pd.DataFrame:
        return read_runs(plan, paths)

    def plan_paths(self, plan: pd.DataFrame) -> list[str]:
        return plan_paths(self.scene, plan)

    def run_seconds(self, point) -> float:
        """Seconds of one run at ``point`` = (candidate index, n): Scene.run_cost, its method's cost model."""
        ci, n = point
        return self.scene.run_cost(self.scene.candidates[int(ci)], int(n))


def stop_reasons(scene: Scene, table: pd.DataFrame, undefined: str = "") -> dict[int, str]:
    """Each candidate's reason to have stopped (every one's: the target is ``undefined``, and why)."""
    if undefined:
        return dict.fromkeys(range(len(scene.candidates)), f"target undefined: {undefined}")
    return {
        ci: _next_rungs(scene, cand, table[table["candidate"] == ci])[1]
        if scene.same_as(ci) == ci
        else _twin_reason(scene, ci)
        for ci, cand in enumerate(scene.candidates)
    }


def _unvisited(scene: Scene, table: pd.DataFrame, undefined: str = "") -> pd.DataFrame:
    """The rows of candidates the search never ran: an at-rest twin's are its first's (Scene.same_as),
    a candidate whose first rung is over the budget, or of a scene whose target is ``undefined``, has
    one row saying so (realisations 0, its counted cost, no error)."""
    visited, rows = set(table["candidate"]), []
    for ci, cand in enumerate(scene.candidates):
        if ci in visited:
            continue
        first = scene.same_as(ci)
        if first != ci:
            rows += table[table["candidate"] == first].assign(candidate=ci).to_dict("records")
            continue
        n = cand.ladder()[0]
        row = dict.fromkeys(JUDGED_COLUMNS, math.nan)
        row.update(
            candidate=ci,
            label=cand.label,
            method=cand.case.method,
            n=n,
            realisations=0,
            meets=False,
            unscored=f"not run: target undefined: {undefined}" if undefined else "not run: over budget",
            cost_s=scene.run_cost(cand, n),
        )
        rows.append(row)
    return pd.DataFrame(rows, columns=JUDGED_COLUMNS)


def result(scene: Scene, table: pd.DataFrame, undefined: str = "") -> pd.DataFrame:
    """The scene's table: every visited (candidate, n) with its error, interval, counted cost, measured
    core-seconds and COMIC at the common points; ``recommended`` on the cheapest row that meets the
    target (at most one row), ``n_below`` the highest failing rung visited below each row (at a
    candidate's answer the rung just below: every rung below it is run), ``comic_best`` on the lowest
    COMIC_points of the scene's own rows; ``stopped`` says why each candidate stopped (a target
    ``undefined`` against the reference: every one, with the reason, and nothing recommended). Each
    candidate's answer carries its run at half its step (half_step_*): one that misses the target
    there depends on its step and is not recommended."""
    reasons = stop_reasons(scene, table, undefined)
    at_half = table["half_step"].astype(bool) if "half_step" in table else pd.Series(False, index=table.index)
    halves = {(int(r["candidate"]), int(r["n"])): r for r in table[at_half].to_dict("records")}
    table = table[~at_half].drop(columns="half_step", errors="ignore")
    extra = _unvisited(scene, table, undefined)
    parts = [t for t in (table, extra) if len(t)]
    out = pd.concat(parts, ignore_index=True) if parts else table.copy()
    out = out.sort_values(["candidate", "n"], kind="stable").reset_index(drop=True)
    out = out.astype({"candidate": int, "n": int, "realisations": int, "meets": bool})
    own = np.array([scene.same_as(c) == c for c in out["candidate"]], dtype=bool)  # twins' rows are copies
    out["scene"] = scene.name
    out["stopped"] = [reasons[c] for c in out["candidate"]]
    out["n_below"] = [
        out[(out["candidate"] == c) & (out["n"] < n) & ~out["meets"]]["n"].max()
        for c, n in zip(out["candidate"], out["n"])
    ]  # the highest visited rung below that fails
    half = [halves.get((scene.same_as(c), n)) for c, n in zip(out["candidate"], out["n"])]
    out["half_step_error"] = [math.nan if h is None else float(h["error_mean"]) for h in half]
    out["half_step_upper95"] = [math.nan if h is None else float(h["error_upper95"]) for h in half]
    out["holds_at_half_step"] = pd.Series([None if h is None else bool(h["meets"]) for h in half], dtype=object)
    out["recommended"] = False
    meets = out[out["meets"] & own]
    if len(meets):
        # per candidate its smallest passing rung, if it holds at half its step; the cheapest of those
        firsts = meets.sort_values("n").groupby("candidate", sort=False).head(1)
        firsts = firsts[firsts["holds_at_half_step"].map(lambda h: h is not False)]
        if len(firsts):
            out.loc[firsts["cost_s"].idxmin(), "recommended"] = True
    out["comic_best"] = False
    scored = out[np.isfinite(out["COMIC_points"].astype(float)) & own]
    if len(scored):
        out.loc[scored["COMIC_points"].idxmin(), "comic_best"] = True
    out["target"] = scene.value
    out["budget"] = scene.budget
    out["measure"] = scene.measure
    out["peclet"] = scene.peclet
    numbers = [grid_numbers(scene, scene.candidates[c], n) for c, n in zip(out["candidate"], out["n"])]
    out["grid_peclet"] = [p for p, _ in numbers]
    out["courant"] = [c for _, c in numbers]
    return out[list(RESULT_COLUMN_DOCS)].reset_index(drop=True)


def product_series(plan: pd.DataFrame, paths: list[str], times: np.ndarray) -> dict[tuple[int, int], list]:
    """A reactive scene's product mass at ``times`` for every visited (candidate, n): each run's mass_C
    linearly interpolated in time, then averaged over its seeds (the scene figure's panel b)."""
    runs: dict[tuple[int, int], list] = {}
    for r, path in zip(plan.itertuples(), paths):
        if getattr(r, "half_step", False):  # an answer's check at half its step: not the rung's own series
            continue
        table = read_parquet(path, columns=["seed", "time", "mass_C"])
        for _, g in table.groupby("seed", sort=True):
            runs.setdefault((int(r.candidate), int(r.n)), []).append(np.interp(times, g["time"], g["mass_C"]))
    return {key: np.mean(series, axis=0).tolist() for key, series in runs.items()}


def with_reference(scene: Scene, table: pd.DataFrame, plan: pd.DataFrame, paths: list[str], ref: dict) -> pd.DataFrame:
    """A reactive scene's table with the product's mass over time: each row's (``product_series``) and
    the reference's (``reference_series``, its error estimate ``reference_error``) at ``series_times``."""
    times = np.asarray(ref["times"], dtype=np.float64)
    series = product_series(plan, paths, times)
    out = table.copy()
    out["series_times"] = [times.tolist()] * len(out)
    out["product_series"] = [series.get((int(c), int(n)), []) for c, n in zip(out["candidate"], out["n"])]
    out["reference_series"] = [np.asarray(ref["product_series"], dtype=float).tolist()] * len(out)
    out["reference_product"] = float(ref["product_mass"])
    out["reference_error"] = float(ref["product_error"])
    return out


def run_path(scene: Scene, candidate: Candidate, n: int, first: int, last: int) -> str:
    """The table of a candidate's runs at resolution n, seeds first..last (SCENE_RUN_PATTERN; the
    paper run's own table where the scene shares its runs: Scene.paper_runs)."""
    from dataclasses import replace

    case = replace(candidate.case, n=int(n))
    if candidate in scene.candidates and scene.candidates.index(candidate) in scene.paper_runs:  # the paper's table
        return scene.paper_pattern.format(kind="runs", first=first, last=last, **case.wildcards())
    kind = "runs" if scene.reaction is None else "reactive"  # rule simulate_scene's two kinds
    return SCENE_RUN_PATTERN.format(
        scene_id=scene.identity(candidate), kind=kind, first=first, last=last, **case.wildcards()
    )


def plan_paths(scene: Scene, plan: pd.DataFrame) -> list[str]:
    """The run tables of every row of a plan, in its order."""
    out = []
    for r in plan.itertuples():
        cand = scene.candidates[int(r.candidate)]
        out.append(run_path(scene, scene.half_step(cand) if r.half_step else cand, r.n, int(r.first), int(r.last)))
    return out


def negative_steps(table: pd.DataFrame) -> tuple[int, float, float, float]:
    """(first step, its time and dt, smallest node or particle mass over every step) of one run's
    table: the first step whose smallest mass is below -NEGATIVE_TOLERANCE of that step's total
    (-1, NaN, NaN if none), so that a state that went negative and recovered by t_final is caught."""
    low = table["mass_min"].to_numpy() < -NEGATIVE_TOLERANCE * table["mass_total"].abs().to_numpy()
    smallest = float(table["mass_min"].min())
    if not low.any():
        return -1, math.nan, math.nan, smallest
    first = table.iloc[int(np.argmax(low))]
    return int(first["step"]), float(first["time"]), float(first["dt"]), smallest


REACTIVE_ONLY = ("product_error", "SSE_points_C", "mass_lost_BC")  # a reactive run's columns (models/simulate.py)
RELEASED = "mass_released"  # a release run's column (models/simulate.py): the mass let out by then


def _run_columns(path: str, keep: list[str]) -> list[str] | None:
    """The columns of the run table at ``path`` that read_runs reads: a run table holds every step's
    measures (dozens of columns), of which a round needs a few; a conservative run has no REACTIVE_ONLY, a
    spill no RELEASED.
    None (every column) where its schema cannot be read, so that read_parquet names the table's fault."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        have = set(pq.read_schema(path).names)
    except (OSError, pa.ArrowException):
        return None
    return [
        "seed",
        "step",
        "time",
        "dt",
        "mass_min",
        WALL,
        *keep,
        *(k for k in (*REACTIVE_ONLY, RELEASED) if k in have),
    ]


def read_runs(plan: pd.DataFrame, paths: list[str]) -> pd.DataFrame:
    """One row per run of a plan (``paths`` in its order): the last step's measures, the smallest
    mass over every step and its first negative step (negative_steps), the run's work and its
    measured core-seconds (the sum of its steps' wall time: search.measured_core_s). A release run's
    ``mass_total`` is the fraction it holds of the mass released by t_final (``held``), 1 for a whole
    plume, as a spill's is of its unit mass."""
    keep = ["SSE_points", "COMIC_points", "H_C", "H_C_analytic", "E", "E_analytic", "mass_total"]
    keep += ["dV", "work"]
    columns = [
        "candidate",
        "n",
        "half_step",
        "seed",
        *keep,
        *REACTIVE_ONLY,
        "mass_min",
        "negative_step",
        "negative_t",
        "negative_dt",
    ]
    rows = []
    if plan.empty:  # every candidate over the budget: nothing ran
        return pd.DataFrame(rows, columns=[*columns, "steps", "core_s"])
    for r, path in zip(plan.itertuples(), paths):
        table = read_parquet(path, columns=_run_columns(path, keep))
        core_s = measured_core_s(table, ["seed"]).set_index("seed")["core_s"]
        for seed, g in table.groupby("seed", sort=True):
            g = g.sort_values("step")
            last = g.iloc[-1]
            step, t, dt, smallest = negative_steps(g)
            rows.append(
                {
                    "candidate": int(r.candidate),
                    "n": int(r.n),
                    "half_step": bool(getattr(r, "half_step", False)),
                    "seed": int(seed),
                    **{k: float(last[k]) for k in keep},
                    "mass_total": held(last),
                    **{k: float(last[k]) if k in g else math.nan for k in REACTIVE_ONLY},
                    "mass_min": smallest,
                    "negative_step": step,
                    "negative_t": t,
                    "negative_dt": dt,
                    "steps": float(last["step"]),
                    "core_s": float(core_s[seed]),
                }
            )
    return pd.DataFrame(rows)


def held(last) -> float:
    """The mass a run holds at its ``last`` row: a spill's of its unit mass, a release's the fraction of the
    mass released by then (``mass_released``), so that what left an FD window counts alike."""
    released = float(last[RELEASED]) if RELEASED in last else math.nan
    return float(last["mass_total"]) / released if released > 0 else float(last["mass_total"])


FAMILIES = {"fd": "grid (best FD)", "pt": "particles (best PT or MTPT)", "mtpt": "particles (best PT or MTPT)"}


def grid_numbers(scene: Scene, candidate: Candidate, n: int, dt: float | None = None) -> tuple[float, float]:
    """(grid Peclet |v| dx / D, Courant |v| dt / dx) of an FD candidate's rung n in a flow at its step dt
    (default its first, dt0); NaN, NaN for particles and at rest."""
    if candidate.case.method != "fd" or scene.speed == 0.0:
        return math.nan, math.nan
    cfg = scene.run_config(candidate, n)
    dt = cfg.dt0 if dt is None else dt
    if scene.dim == 2:  # along the axis where each is largest (core/plane.grid_numbers)
        return plane.grid_numbers(cfg, dt)
    return abs(scene.v) * cfg.fd_dx / scene.D, abs(scene.v) * dt / cfg.fd_dx


def peclet_table(tables: list[pd.DataFrame]) -> pd.DataFrame:
    """The Peclet sweep's answer: per scene and family (the grid: FD candidates; particles: PT and
    MTPT), the cheapest candidate's smallest rung that meets the target, its counted cost, the
    cost at the failing rung below it (the answer's cost lies in (cost_lo, cost_s]) and an FD answer's
    grid Peclet and Courant numbers; NaN where no candidate of the family meets it.
    ``particles_cheaper`` marks the scenes where particles win."""
    rows = []
    for t in tables:
        peclet, name = float(t["peclet"].iloc[0]), str(t["scene"].iloc[0])
        dim = sweep_of(name)[1] if sweep_of(name) else 1
        t = t.assign(family=t["method"].map(FAMILIES))
        for family in dict.fromkeys(FAMILIES.values()):
            meets = t[(t["family"] == family) & t["meets"]]
            row = {"scene": name, "dim": dim, "peclet": peclet, "family": family, "label": "", "n": np.nan}
            row["cost_s"] = np.nan
            row.update(cost_lo=np.nan, grid_peclet=np.nan, courant=np.nan)
            first = meets.sort_values("n").groupby("candidate").head(1)
            if "holds_at_half_step" in first:  # an answer that depends on its step answers nothing here
                first = first[first["holds_at_half_step"].map(lambda h: h is not False)]
            if len(first):
                best = first.loc[first["cost_s"].idxmin()]
                below = t[(t["candidate"] == best["candidate"]) & (t["n"] == best["n_below"])]
                row.update(label=best["label"], n=float(best["n"]), cost_s=float(best["cost_s"]))
                row.update(grid_peclet=float(best["grid_peclet"]), courant=float(best["courant"]))
                row["cost_lo"] = float(below["cost_s"].iloc[0]) if len(below) else np.nan
            rows.append(row)
    out = pd.DataFrame(rows).sort_values(["dim", "peclet", "family"]).reset_index(drop=True)
    wide = out.pivot(index=["dim", "peclet"], columns="family", values="cost_s")
    grid, particles = wide.get(FAMILIES["fd"]), wide.get(FAMILIES["pt"])
    cheaper = {
        p: bool(np.isfinite(q) and (not np.isfinite(g) or q < g)) for p, g, q in zip(wide.index, grid, particles)
    }
    out["particles_cheaper"] = [cheaper[key] for key in zip(out["dim"], out["peclet"])]
    return out


def crossover(table: pd.DataFrame, dim: int = 1) -> tuple[float, float] | None:
    """(Pe_lo, Pe_hi]: in the sweep of dimension ``dim``, the particles first win at Pe_hi and did not
    at Pe_lo, the sweep's previous point (the crossover's uncertainty: the sweep's spacing); None if
    they never win or always do."""
    if "dim" in table:
        table = table[table["dim"] == dim]
    by = table.drop_duplicates("peclet").sort_values("peclet")
    pe, win = by["peclet"].to_numpy(), by["particles_cheaper"].to_numpy()
    for k in range(1, len(pe)):
        if win[k] and not win[k - 1]:
            return float(pe[k - 1]), float(pe[k])
    return None
