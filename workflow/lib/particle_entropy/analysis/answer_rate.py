"""How often a scene search's answer is wrong in expectation: the real search (scene_search's
next_plan, judged, result) replayed on noisy ladders whose true mean error at every rung is known.

A noisy ladder is one particle candidate's ratio-2 ladder with a true mean error m(n) = (n / n_0)^-slope
(slope 1/2: Monte Carlo) that crosses the target at n* within the ladder (log2(n* / n_0) = k + u, k
uniform on 1 .. rungs - 2, u on [0, width)), and per-run errors around m(n) with a coefficient of
variation ``cv`` (lognormal, or normal folded at zero), fixed per (rung, seed). The answer is wrong
when its rung's m(n) is above the target: it meets the target for the seeds it drew, not in
expectation. ``false_answer_rate`` counts those over an ensemble and gives the rate with its
Clopper-Pearson 95 % interval, and the runs and particle-runs the searches cost."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ..core.registry import MEASUREMENT_POINTS
from ..scenes.scene import Scene
from . import scene_search
from .resampling import CONFIDENCE


@dataclass(frozen=True)
class NoisyLadder:
    """One ladder's truth: the target, the true mean error of every rung, the per-run errors
    ``errors[rung, seed]`` (seeds 0 .. max_realisations - 1)."""

    target: float
    means: dict[int, float]
    errors: dict[int, np.ndarray]

    def law(self, n: int, seed: int) -> float:
        return float(self.errors[int(n)][int(seed)])


def noisy_ladders(
    ladder: list[int],
    count: int,
    seed: int,
    seeds: int,
    cv: tuple[float, float] = (0.3, 1.0),
    noise: str = "lognormal",
    slope: float = 0.5,
    width: float = 1.0,
) -> list[NoisyLadder]:
    """``count`` noisy ladders over ``ladder`` (module doc): cv uniform on ``cv``, ``seeds`` runs a rung,
    the crossing ``width`` rungs at most above a rung (1: anywhere; 0.1: the rung below at most
    3.5 % above the target, the hardest case)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        u = rng.integers(1, len(ladder) - 1) + rng.uniform(0.0, width)
        c = rng.uniform(*cv)
        z = rng.standard_normal((len(ladder), seeds))
        if noise == "lognormal":  # mean 1, sd c
            s = math.sqrt(math.log1p(c * c))
            factor, scale = np.exp(s * z - 0.5 * s * s), 1.0
        elif noise == "normal":  # |1 + c z|, folded at zero as an error is: its mean E|1 + c Z|
            factor = np.abs(1.0 + c * z)
            scale = c * math.sqrt(2.0 / math.pi) * math.exp(-0.5 / (c * c)) + math.erf(1.0 / (c * math.sqrt(2.0)))
        else:
            raise ValueError(f"noise {noise!r}: lognormal or normal")
        means = {n: scale * (n / ladder[0]) ** -slope for n in ladder}  # the true mean error of each rung
        target = scale * (2.0**u) ** -slope
        out.append(NoisyLadder(target, means, {n: means[n] / scale * factor[i] for i, n in enumerate(ladder)}))
    return out


def runs(plan: pd.DataFrame, law) -> pd.DataFrame:
    """The runs a plan would make, as read_runs gives them, each with RMSE law(n, seed) (a scene
    of measure rmse: SSE_points = MEASUREMENT_POINTS rmse^2), no negative step, no mass lost."""
    cols = [plan[c].to_numpy(dtype=np.int64) for c in ("candidate", "n", "half_step", "first", "last")]
    rows = [(c, n, h, s) for c, n, h, a, b in zip(*cols) for s in range(a, b + 1)]
    ci, n, half, seed = (np.array(c, dtype=np.int64) for c in zip(*rows)) if rows else (np.zeros(0, np.int64),) * 4
    e = np.array([law(a, b) for a, b in zip(n, seed)], dtype=float)
    size = e.size
    return pd.DataFrame(
        {
            "candidate": ci,
            "n": n,
            "half_step": half.astype(bool),  # an answer's check at half its step: the law knows no step
            "seed": seed,
            "SSE_points": MEASUREMENT_POINTS * e * e,
            "COMIC_points": np.log(e),
            **dict.fromkeys(("H_C", "H_C_analytic"), np.zeros(size)),
            **dict.fromkeys(("E", "E_analytic", "mass_total"), np.ones(size)),
            "mass_min": np.zeros(size),
            "negative_step": np.full(size, -1),
            **dict.fromkeys(("negative_t", "negative_dt"), np.full(size, math.nan)),
            "dV": np.full(size, 0.1),
            "work": 100.0 * n,
            "steps": np.full(size, 100.0),
            "core_s": np.zeros(size),
        }
    )


def search(scene: Scene, law, max_plans: int | None = None) -> tuple[int | None, pd.DataFrame]:
    """The scene's search replayed round by round on per-run errors law(n, seed) of its only
    candidate: (its answer, the lowest rung that meets the target, or None; the judged table)."""
    cap = scene_search.max_rounds(scene) if max_plans is None else max_plans
    plan, k = scene_search.next_plan(scene, None, None, 0), 1
    while not plan["done"].all():
        plan = scene_search.next_plan(scene, plan, runs(plan, law), 0)
        k += 1
        if k > cap:
            raise RuntimeError(f"no finished plan after {cap} rounds")
    table = scene_search.judged(scene, runs(plan, law))
    table = table[~table["half_step"]]
    met = table[table["meets"]]
    return (int(met["n"].min()) if len(met) else None), table


def settled(scene: Scene, law) -> int | None:
    """The answer of the brute force the search equals (tests/test_scene_search.py holds them equal):
    each affordable rung of the only candidate, from the lowest, given a seed block more while open
    and judged by the real rule (scene_search.judge and state); the lowest that passes (None: none).
    No tables and no rounds: fast enough for thousands of ladders in a test."""
    cand = scene.candidates[0]
    for n in scene_search.affordable(scene, cand):
        block = 0
        while True:
            last = scene_search.seeds(scene, cand, 0, block)[1]
            row = scene_search.judge(scene, cand, np.array([law(n, seed) for seed in range(last + 1)]))
            verdict = scene_search.state(scene, cand, row)
            if verdict != scene_search.OPEN:
                break
            block += 1
        if verdict == scene_search.PASS:
            return n
    return None


def rung_pass_rate(scene: Scene, mean: float, cv: float, draws: int, seed: int) -> tuple[float, float]:
    """How often one rung of ``scene``'s only candidate whose per-run errors are lognormal with
    ``mean`` and coefficient of variation ``cv`` passes the target: (on its first seed block alone,
    once settled by the real rule: scene_search.judge and state), over ``draws`` seed draws."""
    cand = scene.candidates[0]
    s = math.sqrt(math.log1p(cv * cv))
    rng = np.random.default_rng(seed)
    errors = mean * np.exp(s * rng.standard_normal((draws, scene.blocks * scene.realisations)) - 0.5 * s * s)
    first = settled_pass = 0
    for e in errors:
        block = 1
        while True:
            row = scene_search.judge(scene, cand, e[: block * scene.realisations])
            first += block == 1 and row["meets"]
            verdict = scene_search.state(scene, cand, row)
            if verdict != scene_search.OPEN:
                break
            block += 1
        settled_pass += verdict == scene_search.PASS
    return first / draws, settled_pass / draws


def binomial_interval(k: int, n: int, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """Clopper-Pearson two-sided ``confidence`` interval of a rate k / n (scipy.stats.binomtest)."""
    from scipy.stats import binomtest

    ci = binomtest(k, n).proportion_ci(confidence_level=confidence, method="exact")
    return float(ci.low), float(ci.high)


def outcome(scene: Scene, ladder: NoisyLadder, replay: str = "search") -> dict:
    """The real search on one ladder (``scene``: one particle candidate over the ladder's rungs, its
    target replaced by the ladder's): its answer (None: not met), whether the answer is above the
    target in expectation (``false``), its rungs above the lowest that truly meets it, the runs and
    particle-runs (sum of n) the search made. ``replay`` "settled": the brute force's answer (the
    same; settled), fast, without the search's runs (NaN)."""
    at = replace(scene, value=ladder.target)
    if replay == "settled":
        answer, runs_, particle_runs = settled(at, ladder.law), math.nan, math.nan
    else:
        answer, table = search(at, ladder.law)
        runs_, particle_runs = int(table["realisations"].sum()), int((table["realisations"] * table["n"]).sum())
    rungs = sorted(ladder.means)
    ideal = next(i for i, n in enumerate(rungs) if ladder.means[n] <= ladder.target)
    return {
        "answer": answer,
        "false": bool(answer is not None and ladder.means[answer] > ladder.target),
        "above_ideal": math.nan if answer is None else rungs.index(answer) - ideal,
        "runs": runs_,
        "particle_runs": particle_runs,
    }


def summary(outcomes: list[dict]) -> dict:
    """An ensemble's outcomes in a few numbers: ladders, false answers, their rate and Clopper-Pearson
    95 % interval, searches that met nothing, mean runs and particle-runs a search, and the answers'
    mean rungs above the ideal one."""
    total = len(outcomes)
    false = sum(o["false"] for o in outcomes)
    lo, hi = binomial_interval(false, total)
    above = [o["above_ideal"] for o in outcomes if o["answer"] is not None]
    return {
        "ladders": total,
        "false": int(false),
        "rate": false / total,
        "lo": lo,
        "hi": hi,
        "not_met": sum(o["answer"] is None for o in outcomes),
        "runs": float(np.mean([o["runs"] for o in outcomes])),
        "particle_runs": float(np.mean([o["particle_runs"] for o in outcomes])),
        "above_ideal": float(np.mean(above)) if above else math.nan,
    }


def false_answer_rate(scene: Scene, ladders: list[NoisyLadder], replay: str = "search") -> dict:
    """How often the search's answer is above the target in expectation over ``ladders`` (summary;
    ``replay``: outcome's)."""
    return summary([outcome(scene, lad, replay) for lad in ladders])


def ladder_scene(ladder: list[int], realisations: int = 8, max_realisations: int = 32) -> Scene:
    """A scene of one PT candidate over ``ladder`` (measure rmse; its target set per noisy ladder)."""
    candidate = {"method": "pt", "kernel": "adaptive", "ladder": list(ladder)}
    spec = {"v": 0.01, "t_final": 50.0, "realisations": realisations, "max_realisations": max_realisations}
    return Scene.from_config("answer_rate", {**spec, "target": {"value": 0.1}, "candidates": [candidate]})
