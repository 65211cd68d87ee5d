"""Resampling over realisations: a bootstrap of statistics of per-N sample means and of where
their minimum over N lies (scipy.stats.bootstrap, percentile intervals), with a NaN-safe argmin
(an unscored COMIC is never a minimum). Used by the COMIC tables (`aggregate`), the adaptive
searches (`optimum`) and the judging of claims (`judging`, `claims`)."""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from functools import cache

import numpy as np

N_RESAMPLES = 2000  # bootstrap resamples of every argmin distribution
BOOTSTRAP_SEED = 2020  # fixed: the same realisations give byte-identical tables
CONFIDENCE = 0.95


def nan_argmin(values, axis=None):
    """np.argmin that never picks a NaN (an unscored COMIC): NaN counts as +inf."""
    v = np.asarray(values, dtype=np.float64)
    return np.argmin(np.where(np.isnan(v), np.inf, v), axis=axis)


def lowest(values) -> int:
    """Index of the lowest value, NaN never (-1 when every value is NaN)."""
    v = np.asarray(values, dtype=np.float64)
    return -1 if np.isnan(v).all() else int(nan_argmin(v))


def argmin_bootstrap(
    samples: list[np.ndarray],
    value: Callable[[np.ndarray], np.ndarray] = lambda means: means,
    n_resamples: int = N_RESAMPLES,
    seed: int = BOOTSTRAP_SEED,
) -> tuple[np.ndarray, int, int, int]:
    """Where the minimum over N lies, resampled: ``samples[i]`` are the realisations of the i-th
    N, ``value`` maps the stacked sample means (shape (N count, resamples)) to the statistic
    minimised over axis 0. Returns (share of resamples whose argmin is each i, interval low
    index, high index, resamples drawn).

    Each N is resampled on its own (scipy.stats.bootstrap, paired=False: realisations with
    replacement, the same count), the argmin recomputed per resample. The interval is the 95 %
    percentile interval of the bootstrap argmin index (2.5 and 97.5 percentiles, linear
    interpolation) widened outward to grid points: low = floor, high = ceil. Being a set of
    grid points bounded by order statistics, it is the same whether the argmin is counted in
    index, N or log N. An N whose statistic is NaN (unscored) is never the argmin; when every N's
    is, the shares are NaN and the interval (-1, -1). An N with a single realisation cannot be
    resampled meaningfully (every resample would repeat it): it is held fixed at its value;
    when every N has one realisation (FD, deterministic) nothing is resampled, the share is 1
    at the point estimate and the interval that point. Every call draws from its own Generator
    seeded with ``seed``, so equal inputs give equal results and two conventions of one model
    see the same resamples."""
    samples = [np.asarray(s, dtype=np.float64) for s in samples]
    if not samples or any(len(s) == 0 for s in samples):
        raise ValueError("every N needs at least one realisation")
    means = np.array([s.mean() for s in samples])
    with np.errstate(divide="ignore", invalid="ignore"):
        point = lowest(value(means[:, None])[:, 0])
    free = [i for i, s in enumerate(samples) if len(s) > 1]
    shares = np.zeros(len(samples))
    if point < 0:  # no N scores (every COMIC NaN): no minimum, no interval
        return shares * np.nan, -1, -1, 0
    if not free:
        shares[point] = 1.0
        return shares, point, point, 0

    def argmin(stacked):  # an N whose mean is NaN (an unscored realisation) is never the argmin
        return nan_argmin(value(stacked), axis=0).astype(np.float64)  # float: scipy casts its levels

    res = bootstrap_of_means(samples, argmin, n_resamples, seed)
    dist = np.asarray(res.bootstrap_distribution).astype(np.int64)
    shares = np.bincount(dist, minlength=len(samples)) / len(dist)
    lo, hi = res.confidence_interval.low, res.confidence_interval.high
    return shares, int(math.floor(lo)), int(math.ceil(hi)), len(dist)


@cache
def scipy_rng_keyword() -> str:
    """scipy's name for the Generator argument of its resampling functions (bootstrap,
    permutation_test): ``rng`` from scipy 1.15, ``random_state`` before. Read once."""
    from scipy import stats

    return "rng" if "rng" in inspect.signature(stats.bootstrap).parameters else "random_state"


def bootstrap_of_means(
    samples: list[np.ndarray],
    of_means: Callable[[np.ndarray], np.ndarray],
    n_resamples: int = N_RESAMPLES,
    seed: int = BOOTSTRAP_SEED,
):
    """scipy.stats.bootstrap (95 % percentile) of a statistic of the per-N sample means:
    ``of_means`` maps the stacked means, shape (N count, *batch), to the statistic, shape
    (batch). Each N with more than one realisation is resampled on its own (paired=False); a
    single realisation is held fixed. At least one N must have two or more. The Generator is
    seeded with ``seed``: equal inputs see equal resamples."""
    means = np.array([np.mean(s) for s in samples])
    free = [i for i, s in enumerate(samples) if len(s) > 1]

    def statistic(*resampled, axis=-1):
        batch = resampled[0].shape[:-1]  # scipy passes (resamples, realisations) per N
        stacked = np.empty((len(means), *batch))
        stacked[:] = means.reshape(-1, *[1] * len(batch))  # single realisations: fixed
        for i, r in zip(free, resampled):
            stacked[i] = r.mean(axis=axis)
        with np.errstate(divide="ignore", invalid="ignore"):  # a zero SSE: COMIC -inf, a valid minimum
            return of_means(stacked)

    from scipy import stats  # 1 s to import: only the jobs that resample pay it, not the workflow's parse

    rng = scipy_rng_keyword()
    return stats.bootstrap(
        [samples[i] for i in free],
        statistic,
        n_resamples=n_resamples,
        vectorized=True,
        paired=False,
        confidence_level=CONFIDENCE,
        method="percentile",
        **{rng: np.random.default_rng(seed)},
    )
