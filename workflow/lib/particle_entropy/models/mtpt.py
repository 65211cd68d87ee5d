"""Mass-transfer particle tracking in 1-D (Section 4): collision kernel (Eq. 17, beta = 1/2)
or adaptive SPH kernel (Eqs. 20, 21, 26); a fraction 1 - eta of D by random walks."""

from __future__ import annotations

import math

import numpy as np

from ..core import measures as M
from ..core.registry import SCHEME_RECORDS
from ..core.runconfig import RunConfig
from ..numerics.bandwidths import beta_sph, collision_sigma, h_sph, truncated_variance_fraction
from .conservation import check_particle_mass
from .walk import walk as ito_walk


def initial_state(cfg: RunConfig, rng: np.random.Generator):
    """N particles on [-Omega/2, Omega/2] around the source carrying its unit mass
    (Source.weighted_particles: a point's on one particle stored first, others' by their density)
    -> (positions sorted, masses, storage index of each), as sequential.py stores them. With a release
    the N particles are uniform there and carry nothing yet: its mass enters them step by step
    (models/release_step.py)."""
    if cfg.release is not None:
        centre = cfg.source.centre
        x = rng.uniform(centre - cfg.omega / 2.0, centre + cfg.omega / 2.0, cfg.n)
        m = np.zeros(cfg.n)
    else:
        x, m = cfg.source.weighted_particles(cfg.n, cfg.omega, cfg.dV, rng)
    order = np.argsort(x, kind="stable")
    return x[order], m[order], order


def kernel(eta: float, D: float, dt: float, h: float | None = None) -> tuple[float, float]:
    """(sigma, beta) of the transfer kernel for a step dt: the collision kernel (Eq. 17, beta 1/2), or
    with ``h`` an SPH kernel of that width (Eqs. 20, 21)."""
    if h is None:
        return collision_sigma(eta, D, dt), 0.5
    return h, beta_sph(eta, D, dt, h)


def kernel_for_step(cfg: RunConfig, dt: float, t_end: float):
    """(sigma, beta) of the transfer kernel for a step of size dt ending at t_end (0, 0: no transfer);
    the SPH width is h_SPH of the plume at t_end (Eq. 26)."""
    if cfg.eta * cfg.D == 0.0:
        return 0.0, 0.0
    if cfg.kernel == "collision":
        return kernel(cfg.eta, cfg.D, dt)
    h = h_sph(cfg.n, cfg.omega, cfg.reference(t_end).kernel_variance, SCHEME_RECORDS[cfg.scheme].sph_constant)
    if h == 0.0:  # a point's release before any of its mass has spread: nothing to transfer yet
        return 0.0, 0.0
    return kernel(cfg.eta, cfg.D, dt, h)


def walk(x, m, label, d_walk: float, dt: float, rng: np.random.Generator, domain=None):
    """The random walk with ``d_walk`` = (1 - eta) D of every particle (reflected into ``domain`` (lo, hi)
    when given), in 1-D re-sorted -> (x, m, label); ``m`` (N,) or (species, N), its columns moved with x.
    Positions may be (N, d), with d_walk a tensor (models/walk.py); they keep their order."""
    if np.any(np.asarray(d_walk) > 0):
        x = ito_walk(x, d_walk, dt, rng)
        if domain is not None:
            x = reflect(x, *domain)
        if x.ndim == 1:
            order = np.argsort(x, kind="stable")
            x, m = x[order], m[..., order]
            label = None if label is None else label[order]
    return x, m, label


def reflect(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Positions folded back into [lo, hi] by reflection at both walls (any number of crossings)."""
    span = hi - lo
    y = np.mod(x - lo, 2.0 * span)
    return lo + np.where(y > span, 2.0 * span - y, y)


def step(cfg: RunConfig, x, m, label, dt: float, t_end: float, rng: np.random.Generator, order_rng=None):
    """Random walk with (1 - eta) D, re-sort, then one mass transfer with eta D (Eq. 19) by the
    case's scheme, every species row of ``m`` ((N,) or (species, N)) by the same P
    -> (x, m, label, kernel width, beta, substeps). ``order_rng`` draws the sequential loop's
    partner orders (default: ``rng``); the authors' loop carries one species."""
    if cfg.v != 0.0:  # carried by the flow: a uniform shift leaves the order and the transfer alone
        x = x + cfg.v * dt
    x, m, label = walk(x, m, label, (1.0 - cfg.eta) * cfg.D, dt, rng)
    sigma, beta = kernel_for_step(cfg, dt, t_end)  # (0, 0) when eta D = 0
    if sigma == 0.0 or beta == 0.0:
        return x, m, label, sigma, 0.0, 1
    scheme = SCHEME_RECORDS[cfg.scheme]
    if scheme.sequential:
        from ..numerics.sequential import sequential_transfer  # a job loads only its scheme's kernels

        if m.ndim != 1:
            raise ValueError(f"scheme {cfg.scheme!r} (the authors' loop) carries one species, not {m.shape[0]}")
        m = sequential_transfer(
            x,
            m,
            sigma,
            beta,
            cfg.truncation,
            order_rng if order_rng is not None else rng,
            label=label if scheme.by_label else None,
            symnorm=scheme.symnorm,
            clip=scheme.clip,
            exact=cfg.loop_arithmetic == "exact",
        )
        return x, m, label, sigma, beta, 1
    if scheme.compensated:  # widen the cut kernel so that its variance is the whole one's
        sigma = sigma / math.sqrt(truncated_variance_fraction(cfg.truncation))
    from ..numerics.mass_transfer import mass_transfer

    res = mass_transfer(x, m, sigma, beta, cfg.truncation, cfg.transfer_method, cfg.transfer_tolerance)
    return x, res.mass, label, sigma, beta, res.substeps


def measure(cfg: RunConfig, x, m, t: float) -> dict:
    """H_D of the masses (Eq. 2), E (Eq. 9), H_PMF, SSE and COMIC against the Gaussian, and both at
    the measurement points (m / dV linearly interpolated between the sorted particles, 0 outside
    the cloud, measures.sse_points)."""
    dV = cfg.dV
    total = float(m.sum())
    # a transfer that lost or made mass is a failure, never a score; with a release, the mass it released by t
    check_particle_mass(total, t, expected=cfg.mass(t))
    h_d = M.entropy_discrete(m / total) if total > 0 else math.nan  # a release's particles before it starts
    ref = cfg.reference(t)
    g = ref.sampled(x, dV)
    c = m / dV
    err = M.sse(c, g)
    points = cfg.points(t)
    err_points = ref.sse_points(points, x, c, dV)
    return {
        "H_D": h_d,
        "H_C": h_d,  # particles carry the sampling volume dV = Omega / N: H_C = H_D
        "H_I": h_d + math.log(dV),
        "H_PMF": M.entropy_pmf(h_d, cfg.omega, cfg.n),
        "E": M.dilution_index(h_d, dV),
        "SSE": err,
        "n_sse": cfg.n,
        "AIC": M.aic(err, cfg.n),
        "COMIC": M.comic(err, cfg.n, dV),
        "SSE_points": err_points,
        "COMIC_points": M.comic(err_points, points.size, dV),
        "dV": dV,
        "mass_total": total,
        "mass_min": float(m.min()),
    }


def warm_up(cfg: RunConfig) -> None:
    """Load the compiled kernels this case's transfer calls before the timed steps: the authors'
    loop, or the transforms of Eqs. 16-21 (both methods when ``auto`` may choose either)."""
    if SCHEME_RECORDS[cfg.scheme].sequential:
        from ..numerics import sequential

        sequential.warm_up()
        return
    from ..numerics import gauss
    from ..numerics.mass_transfer import mass_transfer

    if cfg.transfer_method != "auto":
        methods = (cfg.transfer_method,)
    else:  # gauss.choose_method: a truncated kernel is always summed directly
        methods = ("direct",) if cfg.truncation is not None else ("direct", "fgt")
    gauss.warm_up(methods, transfer=True, reconstruction=False)
    x = np.linspace(-1.0, 1.0, 64)
    m = np.zeros(64)
    m[30] = 1.0
    mass_transfer(x, m, 0.1, 0.5, cfg.truncation, "direct", cfg.transfer_tolerance)  # its own kernels
