"""Discrete Gauss transforms in 1-D: out[k, i] = sum_j exp(-(y_i - x_j)^2 / (2 sigma^2)) q[k, j].

These sums are the only O(N^2)-looking work of the project (MTPT transfer weights,
Eqs. 17 and 21, and kernel reconstructions, Eq. 10). Three methods, exact to round-off,
share one entry point, :func:`gauss_transform`; none builds an N x N matrix:

* ``direct``: windowed sum over sorted sources, O(N x neighbours) time, O(N) memory.
  Used for truncated kernels (exactly the pairs with |y - x| <= truncation * sigma) and
  whenever the neighbour count is small (``auto`` below ``DIRECT_MAX_NEIGHBOURS``).
* ``fgt``: fast Gauss transform, the ``auto`` choice at large neighbour counts. Source
  boxes 1 to 2.5 sigma wide (``fgt_plan``) carry p Hermite moments, translated to Taylor
  expansions about each target box (one table of Hermite functions per box offset);
  sparse box pairs are summed exactly. p is the fewest terms whose proven error bound
  (``fgt_error_bound``) is below ``tolerance`` (default ``registry.FGT_TOLERANCE`` of the
  summed |weights|, round-off: the transform stays symmetric and MTPT conserves mass
  to round-off).
  O(N p) time plus O(boxes x p^2).
* ``taylor``: per-target evaluation of each source box's Taylor moments of exp(u v);
  O(N x P_TERMS x boxes-in-range), kept as an independent cross-check of ``fgt``.

The compiled loops of the three methods are in gauss_kernels.py, reached through
compiled.kernels() (numba's JIT, or the same loops compiled ahead of time for a job).

For the untruncated Gaussian all methods drop pairs farther apart than
``kernels.CUTOFF_SIGMAS`` sigma, where the kernel is below exp(-CUTOFF_SIGMAS^2 / 2) = 2.6e-18,
i.e. below double-precision resolution of the self term (which is 1).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..core.registry import FGT_TOLERANCE, FGT_TOLERANCE_RANGE
from .compiled import kernels
from .kernels import cutoff_radius

P_TERMS = 24
# Box widths of the fast Gauss transform, in sigma, that fgt_plan chooses from: wide boxes
# mean fewer translations (each p^2) but more terms p. A translation's term pair costs about
# as much as a particle's term (benchmarks/bench_transfer.py --boxes).
FGT_BOX_RATIOS = (1.0, 1.5, 2.5)
FGT_TRANSLATION_COST = 1.0
# The fast Gauss transform wins once a target sees more sources than this within the
# cut-off, about 11 per sigma (measured crossover, benchmarks/bench_transfer.py --boxes).
DIRECT_MAX_NEIGHBOURS = 200.0


def fgt_box_width(sigma: float, ratio: float) -> float:
    """The largest k 2^e <= ratio sigma with k in 4..7, so within 25 % of it: box centres
    (b + 1/2) k 2^e and their offsets d k 2^e are exact in floating point."""
    target = ratio * sigma
    e = math.floor(math.log2(target)) - 2  # 4 * 2^e <= target < 8 * 2^e
    return max(k * 2.0**e for k in (4, 5, 6, 7) if k * 2.0**e <= target)


def fgt_plan(y, x, sigma, radius, nk, tolerance=FGT_TOLERANCE) -> tuple[float, np.ndarray]:
    """(box width, terms per box offset) of the FGT with the least modelled work: N p per
    weight vector for moments and evaluation against target boxes x sum over offsets of p_d^2
    translations (FGT_TRANSLATION_COST per term pair, measured). Dense particles favour narrow
    boxes (fewer terms), sparse ones wide boxes (fewer translations)."""
    span = max(x[-1], y[-1]) - min(x[0], y[0])
    best = None
    for ratio in FGT_BOX_RATIOS:
        width = fgt_box_width(sigma, ratio)
        terms = fgt_offset_terms(sigma, radius, width, tolerance)
        boxes = min(float(y.size), span / width + 1.0)
        pairs = float(terms[0] ** 2 + 2 * (terms[1:] ** 2).sum())
        work = nk * ((x.size + y.size) * terms[0] + FGT_TRANSLATION_COST * boxes * pairs)
        if best is None or work < best[0]:
            best = (work, width, terms)
    return best[1], best[2]


def fgt_offset_terms(sigma, radius, width, tolerance=FGT_TOLERANCE) -> np.ndarray:
    """Terms for box pairs d = 0, 1, ..., kmax boxes apart. The bound of fgt_error_bound
    carries a factor exp(-t^2 / 2) at centre offset t = d width / (sqrt 2 sigma) (Cramer's
    inequality), so farther pairs meet the tolerance with fewer terms."""
    kmax = int(math.ceil(radius / width)) + 1
    ratio = width / sigma
    # the bound grows with the ratio and the factor falls with t: round both the safe way
    return _offset_terms(_ratio_ceiling(ratio), math.floor(ratio * 64.0) / 64.0, kmax, tolerance)


@functools.lru_cache(maxsize=4096)
def _offset_terms(ratio_up, ratio_down, kmax, tolerance):
    t = np.arange(kmax + 1) * (ratio_down / math.sqrt(2.0))
    terms = np.array([fgt_terms(ratio_up, tolerance * math.exp(min(0.5 * ti * ti, 700.0))) for ti in t], dtype=np.int64)
    terms.flags.writeable = False  # shared by the cache
    return terms


def _ratio_ceiling(ratio: float) -> float:
    """ratio rounded up to 1/64: the bound grows with the ratio, so terms for the rounded
    ratio are safe, and fgt_terms is cached on few distinct values."""
    return math.ceil(ratio * 64.0) / 64.0


def fgt_error_bound(ratio: float, p: int) -> float:
    """Bound on |FGT - exact| per unit of summed |weights| in reach, for boxes ``ratio`` sigma
    wide and p Hermite / Taylor terms.

    In units where the kernel is exp(-(Y - X)^2), a source at X = c_s + u and a target at
    Y = c_t + v (|u|, |v| <= a / 2, a = ratio / sqrt 2) interact through
    exp(-(t + v - u)^2) = sum_{n,m} h_{n+m}(t) u^n (-v)^m / (n! m!) (h_k = Hermite functions,
    t = c_t - c_s). With |h_k(t)| <= K 2^(k/2) sqrt(k!) exp(-t^2 / 2), K = 1.09 (Cramer's
    inequality) and (n + m)! <= 2^(n+m) n! m!, a term is at most K a^n a^m / sqrt(n! m!),
    so the terms dropped (n >= p or m >= p) sum to at most 2 K S(a) T_p(a), where
    S(a) = sum_n a^n / sqrt(n!) and T_p(a) = a^p / sqrt(p!) / (1 - a / sqrt(p + 1)) bounds
    the tail from p on (when a < sqrt(p + 1)).
    """
    a = ratio / math.sqrt(2.0)
    if a >= math.sqrt(p + 1.0):
        return math.inf
    return _bound_prefactor(a) * _tail(a, p)


def _bound_prefactor(a: float) -> float:
    """2 K S(a) of fgt_error_bound, K = 1.09 (Cramer's inequality)."""
    return 2.0 * 1.09 * _hermite_sum(a)


def _hermite_sum(a: float) -> float:
    """S(a) = sum_n a^n / sqrt(n!), summed until the terms fall below 1e-20 of it."""
    total, n = 0.0, 0
    while True:
        term = math.exp(n * math.log(a) - 0.5 * math.lgamma(n + 1.0))
        total += term
        if n > a * a and term < 1e-20 * total:
            return total
        n += 1


def _tail(a: float, p: int) -> float:
    """a^p / sqrt(p!) / (1 - a / sqrt(p + 1)) >= sum_{n >= p} a^n / sqrt(n!), a < sqrt(p + 1)."""
    return math.exp(p * math.log(a) - 0.5 * math.lgamma(p + 1.0)) / (1.0 - a / math.sqrt(p + 1.0))


@functools.lru_cache(maxsize=4096)
def fgt_terms(ratio: float, tolerance: float) -> int:
    """Fewest Hermite / Taylor terms p with fgt_error_bound(ratio, p) <= tolerance."""
    if not ratio > 0:
        raise ValueError(f"box width ratio must be > 0, got {ratio!r}")
    a = ratio / math.sqrt(2.0)
    scale = _bound_prefactor(a)  # once: only the tail depends on p
    p = max(1, math.floor(a * a))  # the tail bound needs a < sqrt(p + 1)
    while scale * _tail(a, p) > tolerance:
        p += 1
    return p


def neighbour_count(y: np.ndarray, x: np.ndarray, radius: float, samples: int | None = None) -> float:
    """Mean number of sources within ``radius`` of a target (sorted inputs); over ``samples``
    evenly spaced targets when given (an estimate, cheap for large N)."""
    if y.size == 0 or x.size == 0:
        return 0.0
    if samples is not None and y.size > samples:
        y = y[:: y.size // samples]
    hi = np.searchsorted(x, y + radius, side="right")
    lo = np.searchsorted(x, y - radius, side="left")
    return float(np.mean(hi - lo))


def choose_method(y, x, sigma, truncation) -> str:
    """Pick ``direct`` or ``fgt`` for this transform (see module docstring)."""
    if truncation is not None:
        return "direct"
    if neighbour_count(y, x, cutoff_radius(sigma, None), samples=512) <= DIRECT_MAX_NEIGHBOURS:
        return "direct"
    return "fgt"


def gauss_transform(
    y: np.ndarray,
    x: np.ndarray,
    q: np.ndarray,
    sigma: float,
    truncation: float | None = None,
    method: str = "auto",
    skip_self: bool = False,
    tolerance: float = FGT_TOLERANCE,
) -> np.ndarray:
    """Return out[k, i] = sum_j exp(-(y_i - x_j)^2 / (2 sigma^2)) q[k, j].

    ``y`` and ``x`` must be sorted ascending; ``q`` has shape (k, len(x)) or (len(x),).
    ``truncation``: None for the whole Gaussian, else drop pairs with |y - x| > truncation * sigma.
    ``skip_self`` (only when ``y is x``): leave out the j == i term (direct method only).
    """
    same = y is x
    y = np.ascontiguousarray(y, dtype=np.float64)
    x = y if same else np.ascontiguousarray(x, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    squeeze = q.ndim == 1
    q2 = np.ascontiguousarray(np.atleast_2d(q))
    if q2.shape[1] != x.shape[0]:
        raise ValueError(f"weights have {q2.shape[1]} columns for {x.shape[0]} sources")
    if not (sigma > 0 and math.isfinite(sigma)):
        raise ValueError(f"sigma must be positive and finite, got {sigma!r}")
    if not FGT_TOLERANCE_RANGE[0] <= tolerance <= FGT_TOLERANCE_RANGE[1]:
        raise ValueError(
            f"tolerance={tolerance!r} is not allowed: a number in "
            f"[{FGT_TOLERANCE_RANGE[0]:g}, {FGT_TOLERANCE_RANGE[1]:g}]"
        )
    if method == "auto":
        method = choose_method(y, x, sigma, truncation)
    radius = cutoff_radius(sigma, truncation)
    if method == "direct" and same and not skip_self:
        out = kernels().direct_symmetric(x, q2, float(sigma), float(radius))
    elif method == "direct":
        out = kernels().direct(y, x, q2, float(sigma), float(radius), bool(skip_self))
    elif method == "fgt":
        if truncation is not None:
            raise ValueError("the fgt method evaluates the untruncated kernel only")
        if skip_self:
            raise ValueError("skip_self is only supported by the direct method")
        if x.size == 0 or y.size == 0:
            out = np.zeros((q2.shape[0], y.size))
        else:
            width, terms = fgt_plan(y, x, sigma, radius, q2.shape[0], tolerance)
            out = kernels().fgt(y, x, q2, float(sigma), width, terms)
    elif method == "taylor":
        if truncation is not None:
            raise ValueError("the taylor method evaluates the untruncated kernel only")
        if skip_self:
            raise ValueError("skip_self is only supported by the direct method")
        if x.size == 0:
            out = np.zeros((q2.shape[0], y.size))
        else:
            centres, A = kernels().taylor_moments(x, q2, float(sigma), float(x[0]), P_TERMS)
            out = kernels().taylor_eval(y, centres, A, float(sigma), float(radius))
    else:
        raise ValueError(f"method must be 'auto', 'direct', 'fgt' or 'taylor', got {method!r}")
    return out[0] if squeeze else out


def warm_up(methods=("direct", "fgt"), transfer: bool = True, reconstruction: bool = True) -> None:
    """Load the compiled transforms a run will call (numba's on-disk cache): for transfers (targets
    = sources) and reconstructions (other targets), by the given methods."""
    x = np.linspace(-1.0, 1.0, 64)
    for m in methods:
        if transfer:
            gauss_transform(x, x, np.ones((3, x.size)), 0.5, method=m)
        if reconstruction:
            gauss_transform(x[::2], x, np.ones((1, x.size)), 0.5, method=m)
