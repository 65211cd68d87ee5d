"""Entropy and fitness measures (Sections 2, 3, 5.4 and Appendix A of the paper).

Conventions: natural logarithms; ``dV`` is the sampling volume; -inf is returned where
the paper says the quantity is -infinity (H_C of a delta, ln of a zero SSE).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .registry import MEASUREMENT_POINTS, MEASUREMENT_SEED
from .run_settings import PAPER


def entropy_discrete(p: np.ndarray) -> float:
    """H_D = -sum p ln p over the non-zero probabilities (Eq. 2)."""
    p = np.asarray(p, dtype=np.float64)
    p = p[p > 0]
    return float(-np.sum(p * np.log(p))) + 0.0  # + 0.0: no "-0" for a delta


def entropy_inconsistent(f: np.ndarray, dx: float) -> float:
    """H_I = -integral f ln f dx, Riemann sum over a uniform grid (Eq. 3)."""
    f = np.asarray(f, dtype=np.float64)
    f = f[f > 0]
    if f.size == 0:
        return -math.inf
    return float(-np.sum(f * np.log(f)) * dx)


def entropy_consistent(h_i: float, dV: float) -> float:
    """H_C = -ln dV + H_I (Eqs. 6-7)."""
    return -math.log(dV) + h_i


def dilution_index(h_c: float, dV: float) -> float:
    """E = dV exp(H_C) (Eqs. 8-9); 0 for H_C = -inf."""
    return dV * math.exp(h_c) if h_c > -math.inf else 0.0


def entropy_pmf(h_d: float, omega: float, n: int) -> float:
    """H_PMF = H_D + ln(Omega / N) (Section 5.4)."""
    return h_d + math.log(omega / n)


def analytic_h_i(D: float, t: float) -> float:
    """H_I of the Gaussian with variance 2 D t: ln sqrt(4 pi D t) + 1/2 (Eq. 14, dV = 1)."""
    if D * t <= 0:  # a delta: t = 0 or no diffusion
        return -math.inf
    return 0.5 * math.log(4.0 * math.pi * D * t) + 0.5


def analytic_h_c(D: float, t: float, dV: float) -> float:
    """H_C = -ln dV + ln sqrt(4 pi D t) + 1/2 of the Gaussian (Eq. 14); -inf at t = 0."""
    return -math.log(dV) + analytic_h_i(D, t)


def analytic_dilution(D: float, t: float) -> float:
    """E = sqrt(4 pi e D t) of the Gaussian (Eq. 14 into Eq. 8)."""
    return math.sqrt(4.0 * math.pi * math.e * D * max(t, 0.0))


def settling_time(dV: float, D: float) -> float:
    """Time after which H_C of a sampled Gaussian is meaningful, dV^2 / (4 pi e D) (Section 3)."""
    return dV * dV / (4.0 * math.pi * math.e * D) if D > 0 else math.inf


def analytic_sampled(x: np.ndarray, D: float, t: float, dV: float) -> np.ndarray:
    """Gaussian (variance 2 D t) sampled at ``x`` and normalised so that sum g dV = 1.

    Computed in log space, so a Gaussian narrower than the sample spacing (t -> 0) puts all
    its mass on the sample nearest x = 0 instead of under-flowing to 0 / 0.
    """
    x = np.asarray(x, dtype=np.float64)
    var = 2.0 * D * t
    if var > 0:
        logg = -0.5 * x * x / var
        g = np.exp(logg - logg.max())
    else:
        g = np.zeros_like(x)
        g[np.argmin(np.abs(x))] = 1.0
    return g / (g.sum() * dV)


def gaussian_density(x: np.ndarray, D: float, t: float) -> np.ndarray:
    """Exact density exp(-x^2 / (4 D t)) / sqrt(4 pi D t) of the Gaussian with variance 2 D t (D t > 0) [1/L]."""
    x = np.asarray(x, dtype=np.float64)
    return np.exp(-x * x / (4.0 * D * t)) / math.sqrt(4.0 * math.pi * D * t)


def sse(model: np.ndarray, reference: np.ndarray) -> float:
    """Sum of squared errors (Eq. 44)."""
    d = np.asarray(model, dtype=np.float64) - np.asarray(reference, dtype=np.float64)
    return float(np.dot(d, d))


def _log_mse(sse_value: float, n: int) -> float:
    if not sse_value > 0:  # an exact fit's -inf; an SSE that was not computed (NaN) stays NaN
        return -math.inf if sse_value == 0 else math.nan
    return math.log(sse_value) - math.log(n)  # no underflow of SSE / n


def aic(sse_value: float, n: int, k: int = 0) -> float:
    """AIC = 2 ln(SSE / n) + 2 k for Gaussian errors at the MLE (Eqs. 32, 41)."""
    return 2.0 * _log_mse(sse_value, n) + 2.0 * k


def comic(sse_value: float, n: int, dV: float) -> float:
    """COMIC = 2 ln(SSE / n) - ln dV (Eq. 43)."""
    return 2.0 * _log_mse(sse_value, n) - math.log(dV)


@functools.cache
def _measurement_points(fd_length: float) -> np.ndarray:
    rng = np.random.default_rng(MEASUREMENT_SEED)
    points = np.sort(rng.uniform(-fd_length / 2.0, fd_length / 2.0, MEASUREMENT_POINTS))
    points.flags.writeable = False  # shared by every run of the process
    return points


def measurement_points(fd_length: float = PAPER["fd_length"]) -> np.ndarray:
    """The 15 measurement points common to all models, uniform on [-L/2, L/2], sorted (Section 6, point 1) [L]."""
    return _measurement_points(float(fd_length))


def at_points(points: np.ndarray, x: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Concentration ``c`` given at increasing ``x``, linearly interpolated at ``points``; 0 outside [x_0, x_-1]."""
    return np.interp(points, x, c, left=0.0, right=0.0)


def sse_points(points: np.ndarray, x: np.ndarray, c: np.ndarray, D: float, t: float, dV: float) -> float:
    """SSE (Eq. 44) at the measurement ``points`` of the model concentration ``c`` at increasing
    ``x`` (at_points) against the exact Gaussian density of variance 2 D t there [1/L^2].

    Like SSE, the reference is the Gaussian sampled at a point (not averaged over a bin); unlike
    SSE's analytic_sampled, it is not rescaled to unit mass on the model's points (a factor that
    differs between models and tends to 1 as a model resolves the plume), so every model meets
    the same reference values. At t = 0 (or D = 0) the Gaussian is a delta with no value at a
    point: as in SSE, the reference is then the delta that analytic_sampled puts on the model
    point nearest x = 0 (height 1 / dV), interpolated like the model, so a model still at its
    initial delta scores 0."""
    model = at_points(points, x, c)
    if D * t > 0:
        reference = gaussian_density(points, D, t)
    else:
        reference = at_points(points, x, analytic_sampled(x, D, t, dV))
    return sse(model, reference)
