"""Three ways to judge a Fig. 9 claim from its ensembles: (a) as the paper drew it, from the
authors' error bars; (b) as a statistical test at a stated level; (c) by the project's rule of one
combined standard deviation. claims.py writes each verdict in its own column (docs/paper_claims.md)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .resampling import BOOTSTRAP_SEED, CONFIDENCE, scipy_rng_keyword

LEVEL = round(1.0 - CONFIDENCE, 12)  # 0.05: the tests' family-wise level, the complement of the bootstrap intervals
N_PERMUTATIONS = 9999  # random permutations per comparison (fewer when every split can be enumerated)


# --------------------------------------------------------------------------- (a) the paper's bars
def paper_bars(comic_of_mean_sse, sse_mean, sse_std) -> tuple[np.ndarray, np.ndarray]:
    """The authors' Fig. 9 bars about the COMIC of the mean SSE (their script's `pos` and `neg`):
    ln(SSE_mean +- SSE_std) - ln(SSE_mean), not doubled as Eq. 43 would double a change of ln SSE;
    the lower end is -inf where the std reaches the mean. Returns (lower ends, upper ends)."""
    c, m, s = (np.asarray(v, dtype=np.float64) for v in (comic_of_mean_sse, sse_mean, sse_std))
    ratio = s / m
    with np.errstate(divide="ignore"):
        lo = c + np.log(np.maximum(1.0 - ratio, 0.0))
    return lo, c + np.log1p(ratio)


def _bars(rows: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """N, the paper's bars and the index of the drawn minimum (least COMIC of the mean SSE)."""
    g = rows.sort_values("n")
    lo, hi = paper_bars(g["COMIC_of_mean_SSE"], g["SSE_mean"], g["SSE_std"])
    return g["n"].to_numpy(int), lo, hi, int(np.argmin(g["COMIC_of_mean_SSE"].to_numpy()))


def overlapping_minimum(rows: pd.DataFrame) -> dict:
    """The N whose paper bar overlaps the bar of the drawn minimum. ``rows``: one model at one
    time (COMIC table rows with COMIC_of_mean_SSE, SSE_mean, SSE_std)."""
    n, lo, hi, k = _bars(rows)
    overlaps = (lo <= hi[k]) & (hi >= lo[k])
    return {"n_opt": int(n[k]), "overlapping": n[overlaps].tolist(), "unbounded": n[np.isneginf(lo)].tolist()}


def flat_as_drawn(rows: pd.DataFrame, min_n: int) -> dict:
    """Flat as the paper drew it: every N >= ``min_n`` has a bar overlapping the drawn minimum's
    bar. Returns the verdict, the minimum, the N >= min_n whose bars miss it and the N whose lower
    bar is unbounded (std >= mean)."""
    o = overlapping_minimum(rows)
    judged = sorted(int(v) for v in rows["n"] if v >= min_n)
    apart = [v for v in judged if v not in o["overlapping"]]
    return {"flat": bool(judged) and not apart, "n_opt": o["n_opt"], "apart": apart, "unbounded": o["unbounded"]}


# --------------------------------------------------------------------------- (b) a test
def welch_t(x: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    """Welch's t of mean(x) - mean(y), unequal variances (ddof = 1)."""
    vx, vy = np.var(x, axis=axis, ddof=1), np.var(y, axis=axis, ddof=1)
    return (np.mean(x, axis=axis) - np.mean(y, axis=axis)) / np.sqrt(vx / x.shape[axis] + vy / y.shape[axis])


def worse_p(worse, best) -> float:
    """One-sided p-value that ``worse`` has the larger mean: Welch's t-test (unequal variances,
    Welch-Satterthwaite degrees of freedom), the verdict's test. It keeps its level where a
    permutation test does not: 4 realisations of five times the spread of 80 (Fig. 9's N = 30,000
    against N = 100) are rejected 9-14 % of the time at 5 % by the permutation test of the same t
    (tests/test_judging.py). Two constant samples: 0 if ``worse`` is the larger, else 1."""
    from scipy import stats  # 1 s to import: only the claims job pays it

    worse, best = np.asarray(worse, dtype=np.float64), np.asarray(best, dtype=np.float64)
    if np.ptp(worse) == 0 and np.ptp(best) == 0:  # no spread: t is +-inf or undefined
        return 0.0 if worse[0] > best[0] else 1.0
    return float(stats.ttest_ind(worse, best, equal_var=False, alternative="greater").pvalue)


def permutation_p(worse, best, seed: int = BOOTSTRAP_SEED) -> float:
    """The cross-check beside ``worse_p``: a permutation test of Welch's t over independent
    samples (studentised; exact only when the two samples' distributions are equal)."""
    from scipy import stats

    res = stats.permutation_test(
        (np.asarray(worse, dtype=np.float64), np.asarray(best, dtype=np.float64)),
        welch_t,
        permutation_type="independent",
        vectorized=True,
        n_resamples=N_PERMUTATIONS,
        alternative="greater",
        **{scipy_rng_keyword(): np.random.default_rng(seed)},
    )
    return 1.0 if math.isnan(res.pvalue) else float(res.pvalue)


def holm(p: list[float]) -> list[float]:
    """Holm's step-down adjustment of ``p`` (family-wise error at the level compared with)."""
    order = np.argsort(p, kind="stable")
    adjusted, running = np.empty(len(p)), 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (len(p) - rank) * p[i]))
        adjusted[i] = running
    return adjusted.tolist()


def flat_tested(realisations: pd.DataFrame, min_n: int, level: float = LEVEL) -> dict:
    """Flat as a test judges it: no N >= ``min_n`` has a mean COMIC significantly above that of
    the N of least mean COMIC, each N tested one-sided against it (``worse_p``, Welch's t-test) and
    the p-values Holm-adjusted over the N tested, at family-wise ``level``; ``p_check`` holds the
    same for the permutation test (``permutation_p``). ``realisations``: per-realisation
    COMIC of one model at one time (comic_realisations rows). The realisations of different N come
    from independent streams (RunConfig.rng keys by N), so the samples are independent, not paired.
    An N with fewer than two realisations, or a best N with fewer than two, cannot be tested: the
    verdict is then None."""
    samples = {int(n): g["COMIC"].to_numpy(np.float64) for n, g in realisations.groupby("n", sort=True)}
    best = min(samples, key=lambda n: samples[n].mean())
    judged = [n for n in samples if n >= min_n and n != best]
    out = {"n_opt": best, "level": level, "tested": judged, "p": {}, "p_check": {}, "n_worst": -1}
    out |= {"p_worst": math.nan, "p_check_worst": math.nan}
    small = [n for n in [best, *judged] if len(samples[n]) < 2]
    if small:
        return {**out, "flat": None, "untestable": small}
    if not judged:
        return {**out, "flat": True, "untestable": []}
    adjusted = dict(zip(judged, holm([worse_p(samples[n], samples[best]) for n in judged])))
    check = dict(zip(judged, holm([permutation_p(samples[n], samples[best]) for n in judged])))
    worst = min(judged, key=lambda n: adjusted[n])
    return {
        **out,
        "flat": all(p >= level for p in adjusted.values()),
        "untestable": [],
        "p": adjusted,
        "p_check": check,
        "n_worst": worst,
        "p_worst": adjusted[worst],
        "p_check_worst": check[worst],
    }
