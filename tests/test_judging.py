"""The three rules of judging.py against independent references: the authors' bars as their script
computes them, Welch's t against scipy's t-test, Holm's adjustment by hand, the permutation test's
power and size, and flatness judged on built ensembles."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from particle_entropy.analysis import judging
from particle_entropy.analysis.judging import (
    flat_as_drawn,
    flat_tested,
    holm,
    overlapping_minimum,
    paper_bars,
    permutation_p,
    welch_t,
    worse_p,
)


# --------------------------------------------------------------------------- (a) the paper's bars
def test_paper_bars_are_the_scripts_log_differences_added_to_the_drawn_curve():
    comic, sse, std = np.array([-10.0, -12.0, -9.0]), np.array([2e-4, 1e-4, 5e-5]), np.array([5e-5, 1e-4, 8e-5])
    lo, hi = paper_bars(comic, sse, std)
    # the script: pos = log(SSE + std) - log(SSE), neg = log(SSE - std) - log(SSE), unscaled by Eq. 43's 2
    assert hi == pytest.approx(comic + (np.log(sse + std) - np.log(sse)), rel=1e-14)
    assert lo[0] == pytest.approx(comic[0] + (math.log(sse[0] - std[0]) - math.log(sse[0])), rel=1e-14)
    assert hi[0] - comic[0] == pytest.approx(math.log(1.25))  # half of 2 ln(1.25), Eq. 43's width
    assert np.isneginf(lo[1]) and np.isneginf(lo[2])  # std = mean and std > mean: unbounded below


def _drawn(points: list[tuple[int, float, float]]) -> pd.DataFrame:
    """(N, COMIC of mean SSE, std / mean of SSE) -> COMIC-table rows of one model."""
    return pd.DataFrame(
        {
            "n": [p[0] for p in points],
            "COMIC_of_mean_SSE": [p[1] for p in points],
            "SSE_mean": 1.0,
            "SSE_std": [p[2] for p in points],
        }
    )


def test_a_bar_unbounded_below_overlaps_every_lower_minimum():
    # N = 100's bar reaches -inf (std > mean), so it overlaps the minimum at N = 1000 however far above it sits
    rows = _drawn([(30, 5.0, 0.1), (100, 3.0, 1.5), (300, 0.2, 0.2), (1000, 0.0, 0.2)])
    f = flat_as_drawn(rows, 100)
    assert f == {"flat": True, "n_opt": 1000, "apart": [], "unbounded": [100]}
    # the same N = 100 with std 0.5 x mean: its bar [3 + ln 0.5, 3 + ln 1.5] misses [ln 0.8, ln 1.2]
    f = flat_as_drawn(rows.assign(SSE_std=[0.1, 0.5, 0.2, 0.2]), 100)
    assert f["flat"] is False and f["apart"] == [100] and f["unbounded"] == []
    # bars that just touch overlap: 0.2 + ln 0.8 = -0.023 <= ln 1.2 = 0.182 at N = 300
    assert 300 in overlapping_minimum(rows)["overlapping"]


def test_flat_as_drawn_ignores_n_below_the_threshold():
    rows = _drawn([(30, 9.0, 0.01), (100, 0.05, 0.1), (300, 0.0, 0.1)])
    assert flat_as_drawn(rows, 100)["flat"] is True
    assert flat_as_drawn(rows, 30)["flat"] is False


# --------------------------------------------------------------------------- (b) the test
def test_welch_t_matches_scipys_unequal_variance_t_test():
    rng = np.random.default_rng(1)
    x, y = rng.normal(0.3, 1.0, 17), rng.normal(0.0, 3.0, 5)
    assert welch_t(x, y) == pytest.approx(stats.ttest_ind(x, y, equal_var=False).statistic, rel=1e-12)


def test_holm_by_hand():
    # sorted 0.01, 0.03, 0.04 -> 3 x 0.01, 2 x 0.03, max(1 x 0.04, 0.06): in the input order
    assert holm([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])
    assert holm([0.5, 0.9]) == [1.0, 1.0]
    assert holm([]) == []


def test_worse_p_finds_a_shift_and_the_permutation_test_agrees():
    rng = np.random.default_rng(2)
    best, worse = rng.normal(0.0, 1.0, 20), rng.normal(2.0, 1.0, 20)
    assert worse_p(worse, best) < 1e-6
    assert permutation_p(worse, best) < 1e-3 and permutation_p(worse, best) == permutation_p(worse, best)
    assert worse_p(best, worse) > 0.99 and permutation_p(best, worse) > 0.99  # the other direction: not worse
    assert worse_p(np.ones(3), np.ones(4)) == 1.0  # equal constants: no evidence, not NaN


# H0 true (equal means), Fig. 9's most unequal shapes: 4 realisations with 5x the spread of 80
SHAPES = [((4, 1.0), (80, 0.2)), ((80, 0.2), (4, 1.0)), ((80, 1.0), (4, 0.2)), ((4, 1.0), (4, 1.0))]


@pytest.mark.parametrize("worse,best", SHAPES)
def test_welchs_t_keeps_its_level_where_sizes_and_spreads_differ(worse, best):
    rng = np.random.default_rng(3)
    trials = 2000
    p = [worse_p(rng.normal(0, worse[1], worse[0]), rng.normal(0, best[1], best[0])) for _ in range(trials)]
    rate = np.mean(np.array(p) < 0.05)
    assert abs(rate - 0.05) < 4 * math.sqrt(0.05 * 0.95 / trials)  # within 4 binomial sd of 5 %


def test_the_permutation_check_is_liberal_with_few_spread_realisations(monkeypatch):
    # why it is only the cross-check: with the small sample the spread one, it rejects a true H0 too often
    monkeypatch.setattr(judging, "N_PERMUTATIONS", 499)
    rng = np.random.default_rng(3)
    trials = 300
    rejected = sum(permutation_p(rng.normal(0, 1.0, 4), rng.normal(0, 0.2, 80), seed=k) < 0.05 for k in range(trials))
    assert rejected / trials > 0.075  # measured 9 %; 5 % would be 15 of 300 (sd 3.8)


def _realisations(samples: dict[int, np.ndarray]) -> pd.DataFrame:
    ns = np.concatenate([[n] * len(v) for n, v in samples.items()])
    return pd.DataFrame({"n": ns, "COMIC": np.concatenate(list(samples.values()))})


def test_flat_tested_finds_the_worse_n_and_adjusts_over_the_n_tested():
    rng = np.random.default_rng(4)
    rows = _realisations(
        {
            30: rng.normal(5.0, 1.0, 40),  # below the threshold: never tested
            100: rng.normal(1.5, 1.0, 40),  # 1.5 sd above the best, 40 realisations: significant
            300: rng.normal(0.1, 1.0, 20),
            1000: rng.normal(0.0, 1.0, 10),
        }
    )
    f = flat_tested(rows, 100)
    assert f["n_opt"] == int(rows.groupby("n")["COMIC"].mean().idxmin())
    assert f["flat"] is False and f["n_worst"] == 100 and f["p_worst"] < 0.01
    assert sorted(f["tested"]) == sorted(n for n in (100, 300, 1000) if n != f["n_opt"])
    best = rows[rows["n"] == f["n_opt"]]["COMIC"]
    one_sided = lambda n: stats.ttest_ind(rows[rows["n"] == n]["COMIC"], best, equal_var=False, alternative="greater")
    raw = {n: one_sided(n).pvalue for n in f["tested"]}
    assert f["p"] == pytest.approx(dict(zip(raw, holm(list(raw.values())))), rel=1e-9)
    assert f["p_check_worst"] < 0.01  # the permutation test agrees on N = 100
    flat = flat_tested(rows[rows["n"] != 100], 100)
    assert flat["flat"] is True and flat["p_worst"] >= judging.LEVEL


def test_flat_tested_cannot_judge_a_single_realisation():
    rows = _realisations({100: np.array([1.0, 1.2, 0.9]), 300: np.array([0.5])})
    f = flat_tested(rows, 100)
    assert f["flat"] is None and f["untestable"] == [300]


def test_the_tests_level_is_the_bootstrap_intervals_complement():
    from particle_entropy.analysis.resampling import CONFIDENCE

    assert judging.LEVEL == pytest.approx(1 - CONFIDENCE) and 0 < judging.LEVEL < 0.5
