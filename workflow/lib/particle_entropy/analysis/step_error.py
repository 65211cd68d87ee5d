"""A time-step error read from runs at successive steps: the mean of a per-seed error with its 95 %
t interval, and the observed order p of e(h) = e_0 + a h^p from three steps h, h / r, h / r^2 run on
the same seeds (a paired bootstrap over seeds, scipy.stats.bootstrap, percentile interval). Used by
benchmarks/reactive_step.py (issue 50 point 8: does a reactive answer hold at a finer step?)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .resampling import BOOTSTRAP_SEED, CONFIDENCE, N_RESAMPLES, scipy_rng_keyword


def mean_interval(values) -> tuple[float, float]:
    """Mean of per-seed values and the half-width of its 95 % t interval (nan with one value)."""
    from scipy import stats  # imported where used, as resampling does

    v = np.asarray(values, dtype=np.float64)
    mean = float(v.mean())
    if v.size < 2:
        return mean, math.nan
    return mean, float(stats.t.ppf(0.5 * (1.0 + CONFIDENCE), v.size - 1) * v.std(ddof=1) / math.sqrt(v.size))


@dataclass(frozen=True)
class Order:
    """Observed order p [-] of a step error with its 95 % interval (nan: one seed, or not resolved)."""

    p: float
    lo: float = math.nan
    hi: float = math.nan


def _order(d_coarse, d_fine, ratio: float, axis: int = -1):
    """log(mean d_coarse / mean d_fine) / log r: nan where the two changes differ in sign or vanish."""
    q = np.mean(d_coarse, axis=axis) / np.mean(d_fine, axis=axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(q > 0, np.log(np.where(q > 0, q, 1.0)) / math.log(ratio), np.nan)


def observed_order(coarse, mid, fine, ratio: float = 2.0) -> Order:
    """Order p of e(h) = e_0 + a h^p from per-seed errors at steps h, h / ratio, h / ratio^2 (the same
    seeds at each): p = log((e_h - e_h/r) / (e_h/r - e_h/r^2)) / log r, from the mean changes; its
    interval (percentile) resamples whole seeds (paired). p = 1: first order; p near 0: a change that does not
    shrink with the step; nan: the two changes differ in sign (no order); no interval (nan) where more than 2.5 % of
    the resamples have no order."""
    coarse, mid, fine = (np.asarray(x, dtype=np.float64) for x in (coarse, mid, fine))
    if not (coarse.shape == mid.shape == fine.shape and coarse.ndim == 1 and coarse.size):
        raise ValueError("coarse, mid and fine need one error per seed, the same seeds")
    if not ratio > 1.0:
        raise ValueError(f"ratio must be > 1, got {ratio!r}")
    d_coarse, d_fine = coarse - mid, mid - fine
    p = float(_order(d_coarse, d_fine, ratio))
    if coarse.size < 2 or not math.isfinite(p):
        return Order(p)
    import warnings

    from scipy import stats

    with warnings.catch_warnings():  # resamples whose changes differ in sign give nan: an unresolved bound
        warnings.simplefilter("ignore", RuntimeWarning)
        res = stats.bootstrap(
            (d_coarse, d_fine),
            lambda a, b, axis: _order(a, b, ratio, axis),
            paired=True,
            vectorized=True,
            confidence_level=CONFIDENCE,
            n_resamples=N_RESAMPLES,
            method="percentile",
            **{scipy_rng_keyword(): np.random.default_rng(BOOTSTRAP_SEED)},
        )
    dist = res.bootstrap_distribution
    tail = 0.5 * (1.0 - CONFIDENCE)
    if np.isnan(dist).mean() > tail:  # too many resamples without an order: no interval
        return Order(p)
    lo, hi = np.nanpercentile(dist, [100.0 * tail, 100.0 * (1.0 - tail)])
    return Order(p, float(lo), float(hi))
