"""The segregation runs of experiments/segregation.py judged: the slope of log <c_A> against log t
over a window with a 95 % bootstrap interval over seeds (scipy.stats.bootstrap, whole runs
resampled), to compare with the segregated -1/4 (Ovchinnikov & Zeldovich 1978; Paster, Bolster &
Benson 2014) and the well-mixed -1, and <c_A> over the well-mixed C0 / (1 + k C0 t)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.reactions import well_mixed
from .resampling import CONFIDENCE, scipy_rng_keyword

SLOPE_RESAMPLES = 2000  # bootstrap resamples of the seeds
SLOPE_BOOTSTRAP_SEED = 0  # fixed: the same runs give the same interval


@dataclass(frozen=True)
class SlopeInterval:
    """A log-log slope of the mean over seeds (``estimate``) and its bootstrap interval (low, high)."""

    estimate: float
    low: float
    high: float
    seeds: int

    def __str__(self) -> str:
        return f"{self.estimate:.4f} [{self.low:.4f}, {self.high:.4f}] over {self.seeds} seeds"


def loglog_slope(t: np.ndarray, c: np.ndarray, lo: float, hi: float) -> float:
    """Least-squares slope of log c against log t over lo <= t <= hi (c > 0): the exponent of c ~ t^slope."""
    w = (t >= lo) & (t <= hi) & (c > 0)
    return float(np.polyfit(np.log(t[w]), np.log(c[w]), 1)[0])


def slope_interval(
    t: np.ndarray, c: np.ndarray, lo: float, hi: float, n_resamples: int = SLOPE_RESAMPLES
) -> SlopeInterval:
    """The slope of log <c_A> (the mean over the rows of ``c``, one a seed) against log t over
    [lo, hi], with its 95 % bootstrap interval (scipy.stats.bootstrap, BCa, seeds resampled whole,
    from a Generator seeded with SLOPE_BOOTSTRAP_SEED)."""
    from scipy import stats

    c = np.asarray(c, dtype=np.float64)

    def of_seeds(idx, axis=-1):
        return loglog_slope(t, c[np.asarray(idx, dtype=int)].mean(axis=0), lo, hi)

    ci = stats.bootstrap(
        (np.arange(c.shape[0]),), of_seeds, vectorized=False, n_resamples=n_resamples,
        confidence_level=CONFIDENCE, **{scipy_rng_keyword(): np.random.default_rng(SLOPE_BOOTSTRAP_SEED)},
    ).confidence_interval  # fmt: skip
    return SlopeInterval(of_seeds(np.arange(c.shape[0])), float(ci.low), float(ci.high), c.shape[0])


def well_mixed_ratio(t: np.ndarray, c: np.ndarray, c0: float, k: float) -> np.ndarray:
    """<c_A> (the mean over the rows of ``c``) over the well-mixed C0 / (1 + k C0 t) at each t."""
    return np.asarray(c).mean(axis=0) / well_mixed(c0, c0, k, t)[0]
