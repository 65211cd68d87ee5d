"""Classical random-walk particle tracking with bin and kernel reconstructions (Eqs. 10-13, 23)."""

from __future__ import annotations

import math

import numpy as np

from ..core import measures as M
from ..core.runconfig import RunConfig
from ..numerics import gauss
from ..numerics.bandwidths import h_de
from ..numerics.gauss import gauss_transform
from .walk import walk


def reconstruction_width(cfg: RunConfig, t: float, n: int | None = None) -> float:
    """Bin width dx = Omega / N (Eq. 11), fixed kernel sqrt(2 D t_k), or h_DE (Eq. 23) of the plume's
    variance (the source's plus 2 D t; a release's puffs' mean, core/released.py) for ``n`` particles
    (default N)."""
    if cfg.kernel == "bins":
        return cfg.dV
    if cfg.kernel == "fixed":
        return math.sqrt(2.0 * cfg.D * cfg.fixed_kernel_time)
    return h_de(cfg.n if n is None else n, cfg.reference(t).kernel_variance)


def bin_density(x: np.ndarray, dx: float, origin: float):
    """Bin centres and densities c = count / (N dx) on a lattice of width dx through origin (Eq. 11)."""
    idx = np.floor((x - origin) / dx).astype(np.int64)
    lo = min(int(idx.min()), 0)
    counts = np.bincount(idx - lo)
    centres = origin + (lo + np.arange(counts.size) + 0.5) * dx
    return centres, counts / (x.size * dx)


def kernel_grid(x_sorted: np.ndarray, h: float, D: float, t: float) -> np.ndarray:
    """Evaluation grid of a kernel reconstruction: covers every particle +- 6h, spacing
    min(0.1, sqrt(2 D t + h^2) / 4, h / 2), fine enough for a converged Riemann sum of H_I."""
    spread = math.sqrt(2.0 * D * t + h * h)
    spacing = min(0.1, spread / 4.0, h / 2.0)
    lo, hi = x_sorted[0] - 6.0 * h, x_sorted[-1] + 6.0 * h
    n = int(math.ceil((hi - lo) / spacing)) + 1
    return lo + spacing * np.arange(n), spacing


def kernel_density(points: np.ndarray, x_sorted: np.ndarray, h: float) -> np.ndarray:
    """c_N(points) = (1/N) sum_i phi_h(points - X_i), Gaussian phi of width h (Eq. 10)."""
    w = np.full(x_sorted.size, 1.0 / x_sorted.size)
    return gauss_transform(points, x_sorted, w, h) / (math.sqrt(2.0 * math.pi) * h)


def bin_origin(cfg: RunConfig, t: float) -> float:
    """The bins' lattice starts at the particle domain's left end, -Omega/2, carried by v t with the
    plume (and centred on the source) [L]."""
    if cfg.at_rest:
        return -cfg.omega / 2.0
    return cfg.reference(t).centre - cfg.omega / 2.0


def reconstruct(cfg: RunConfig, x_sorted: np.ndarray, t: float, n: int | None = None):
    """(points, density, point spacing, width) of the chosen reconstruction at time t (its width for ``n``
    particles, default N: reconstruction_width)."""
    h = reconstruction_width(cfg, t, n)
    if cfg.kernel == "bins":
        pts, f = bin_density(x_sorted, h, bin_origin(cfg, t))
        return pts, f, h, h
    if h == 0.0:  # a point's adaptive kernel at t = 0: the reconstruction is the particles' delta
        return np.zeros(1), np.ones(1), 1.0, 0.0
    pts, spacing = kernel_grid(x_sorted, h, cfg.D, t)
    return pts, kernel_density(pts, x_sorted, h), spacing, h


def measure(cfg: RunConfig, x_sorted: np.ndarray, t: float, m_p: float | None = None) -> dict:
    """Entropies, dilution index and fitness of the reconstruction at time t; SSE_points and
    COMIC_points interpolate the same reconstruction (bin centres or the kernel's grid) to the
    measurement points (measures.sse_points). ``m_p``: a release's particle mass (models/release_step.py),
    its particles those released so far (none yet: NaN measures), whose SSEs are of the estimate times
    the mass they hold, as the exact plume's concentration carries the mass released (core/released.py);
    None: N particles of 1 / N."""
    dV = cfg.dV
    n = cfg.n if m_p is None else x_sorted.size
    if n == 0:
        return {
            **dict.fromkeys(_MEASURED, math.nan),
            "n_sse": 0,
            "dV": dV,
            "mass_total": 0.0,
            "mass_min": math.nan,
            **_STEP,
        }
    pts, f, spacing, h = reconstruct(cfg, x_sorted, t, n)
    ref = cfg.reference(t)
    points = cfg.points(t)
    if h == 0.0:
        h_i, err, n_pts, err_points = -math.inf, 0.0, 1, 0.0
    else:
        h_i = M.entropy_inconsistent(f, spacing)
        c = f if m_p is None else f * (n * m_p)  # a release's: the estimate times the mass its particles hold
        err, n_pts = M.sse(c, ref.sampled(pts, spacing)), pts.size
        err_points = ref.sse_points(points, pts, c, spacing)
    h_c = M.entropy_consistent(h_i, dV)
    h_d = math.log(n)  # Eq. 13: equal masses 1/N
    return {
        "H_D": h_d,
        "H_C": h_c,
        "H_I": h_i,
        "H_PMF": M.entropy_pmf(h_d, cfg.omega, cfg.n),
        "E": M.dilution_index(h_c, dV),
        "SSE": err,
        "n_sse": n_pts,
        "AIC": M.aic(err, n_pts),
        "COMIC": M.comic(err, n_pts, dV),
        "SSE_points": err_points,
        "COMIC_points": M.comic(err_points, points.size, dV),
        "dV": dV,
        "mass_total": 1.0 if m_p is None else n * m_p,
        "mass_min": 1.0 / cfg.n if m_p is None else m_p,
        "beta": 0.0,
        "h": h,
        "substeps": 1,
    }


# a PT row's measured columns, NaN while a release has released no particle
_MEASURED = ("H_D", "H_C", "H_I", "H_PMF", "E", "SSE", "AIC", "COMIC", "SSE_points", "COMIC_points", "h")
_STEP = {"beta": 0.0, "substeps": 1}


def initial_positions(cfg: RunConfig, rng: np.random.Generator) -> np.ndarray:
    """N equal masses drawn from the source: the paper's delta puts all N at x = 0 and draws nothing."""
    if cfg.at_rest:
        return np.zeros(cfg.n)
    return cfg.source.positions(cfg.n, rng)


def step(xs: list[np.ndarray], D: float, dt: float, rng: np.random.Generator, v: float = 0.0, period=None) -> list:
    """One step of every species' particles (``xs``, one position array each, (N,) or (N, d), walked in
    order; D a scalar or, in d dimensions, a tensor: models/walk.py): the walk, then folded into the
    periodic [0, period) (a reaction's domain, in the frame moving with v), or in 1-D sorted (the
    reconstructions need the order; d-dimensional positions keep theirs)."""
    out = []
    for x in xs:
        x = walk(x, D, dt, rng, v)
        if period is not None:
            out.append(np.mod(x, period))
        else:
            out.append(np.sort(x) if x.ndim == 1 else x)
    return out


def final_state(cfg: RunConfig, x_sorted: np.ndarray, t: float, m_p: float | None = None) -> dict:
    """Particle positions, masses and the reconstructed concentration at each particle: the density of unit
    mass, or with a release's particle mass ``m_p`` the concentration of the mass held (m_p each)."""
    if m_p is not None and not x_sorted.size:
        return {"x": x_sorted, "mass": np.empty(0), "c": np.empty(0)}
    h = reconstruction_width(cfg, t, None if m_p is None else x_sorted.size)
    if cfg.kernel == "bins":
        pts, f = bin_density(x_sorted, h, bin_origin(cfg, t))
        idx = np.floor((x_sorted - pts[0] + 0.5 * h) / h).astype(np.int64)
        c = f[idx]
    else:
        c = kernel_density(x_sorted, x_sorted, h) if h > 0 else np.full(x_sorted.size, np.inf)
    if m_p is not None:
        return {"x": x_sorted, "mass": np.full(x_sorted.size, m_p), "c": x_sorted.size * m_p * c}
    return {"x": x_sorted, "mass": np.full(x_sorted.size, 1.0 / cfg.n), "c": c}


def warm_up(cfg: RunConfig) -> None:
    """Load the compiled reconstruction of this case before the timed steps (bins need none)."""
    if cfg.kernel != "bins":
        gauss.warm_up(("direct", "fgt"), transfer=False, reconstruction=True)
