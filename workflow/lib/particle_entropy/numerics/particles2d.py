"""Particles in 2-D with a uniform dispersion tensor: MTPT's mass exchange by Eq. 17's collision
kernel written with the tensor (Eqs. 16-18), PT's kernel reconstruction at points with a bandwidth
matrix shaped by the plume's covariance (Eq. 22 with d = 2), and MTPT's concentration at points.

Nothing here builds an N x N (or N x M) matrix: the exchange works on the pairs within a cut-off
(numerics/neighbours.py, one k-d tree) and moves masses by numerics/pair_transfer.py; the
reconstruction sums over the (point, particle) pairs within a cut-off, a chunk of points at a time.
The random walk of both models is models/walk.py's (a uniform tensor D is given to it as
``D[None]``, one (1, 2, 2) tensor for every particle).

Units: positions [L], tensors [L^2/T], dt [T], masses dimensionless, concentrations [L^-2].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .bandwidths import CUTOFF_SIGMAS, collision_sigma
from .neighbours import pairs_within

COLLISION_BETA = 0.5  # Eq. 16's factor 1/2: with P of covariance 4 eta D dt, the masses spread by 2 eta D dt
# The exchange's cut-off in kernel standard deviations. Not bandwidths.CUTOFF_SIGMAS (9, shared
# with the 1-D code, where it means "untruncated"): in 2-D the pairs grow as the cut-off squared and
# at 9 s.d. an exchange step at N = 100,000 takes 0.78 s against issue 52's 0.5 s; 6 s.d. takes 0.41 s
# (Intel Xeon, benchmarks/mtpt2d_step.py) and drops exp(-18) = 1.5e-8 of the kernel's mass and 2.9e-7
# of its variance, far below the 1 / (1 + n_K) under-dispersion of the exchange itself, and changes
# the RMSE at N = 16,000 of tests/test_particles2d_rates.py by less than 1e-4 of its 0.02.
EXCHANGE_CUTOFF_SIGMAS = 6.0
KDE_CHUNK_PAIRS = 4_000_000  # (point, particle) pairs held at once by kde_2d: about 100 MB (24 B each)


class Exchange(NamedTuple):
    mass: np.ndarray  # the masses after the exchange, the shape of the masses given
    substeps: int  # equal parts of beta the step was split into to keep masses non-negative
    mean_neighbours: float  # 2 n_pairs / N: partners within the cut-off per particle


def tensor_2d(D) -> np.ndarray:
    """A symmetric positive definite 2 x 2 tensor as float64; ValueError otherwise."""
    D = np.asarray(D, dtype=np.float64)
    if D.shape != (2, 2):
        raise ValueError(f"a 2-D tensor is 2 x 2, not {D.shape}")
    if not np.allclose(D, D.T, rtol=1e-12, atol=0.0):
        raise ValueError(f"the tensor must be symmetric: {D.tolist()}")
    if not (D[0, 0] > 0.0 and np.linalg.det(D) > 0.0):
        raise ValueError(f"the tensor must be positive definite: {D.tolist()}")
    return 0.5 * (D + D.T)


def whiten(x, A) -> np.ndarray:
    """s = L^-1 x for positions (N, 2), A = L L^T (Cholesky): |s_i - s_j|^2 = r^T A^-1 r, r = x_i - x_j.
    A rotation of x and of A (x -> R x, A -> R A R^T) leaves every |s_i - s_j| unchanged."""
    low = np.linalg.cholesky(tensor_2d(A))
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 2:
        raise ValueError(f"positions must be (N, 2), not {x.shape}")
    inv = np.linalg.inv(low)  # lower triangular 2 x 2
    return x @ inv.T


def exchange_cutoff(dt: float, cutoff_sds: float = EXCHANGE_CUTOFF_SIGMAS) -> float:
    """Cut-off radius in the coordinates whitened by eta D (``whiten``): ``cutoff_sds`` standard
    deviations sqrt(4 dt) of the collision kernel there (collision_sigma with eta D = 1)."""
    return cutoff_sds * collision_sigma(1.0, 1.0, dt)


def mtpt_exchange_2d(x, m, D, eta: float, dt: float, cutoff_sds: float = EXCHANGE_CUTOFF_SIGMAS) -> Exchange:
    """One mass exchange m_i <- m_i + (1/2) sum_j P_ij (m_j - m_i) (Eq. 16) with Eq. 17's collision
    kernel of the uniform tensor eta D: W_ij = exp(-r^T (eta D)^-1 r / (8 dt)), a Gaussian of
    covariance 4 eta D dt (in 1-D the variance of bandwidths.collision_sigma), P the average of the
    row- and the column-normalised W, self weight included (Eq. 18). Masses spread by 2 eta D dt a step.

    ``x`` (N, 2) positions [L]; ``m`` (N,) or (species, N) masses, every species row moved by the
    same P and the same substeps; ``D`` the 2 x 2 tensor [L^2/T]; ``eta`` the fraction of D done by
    the exchange (the walk does 1 - eta); ``dt`` [T]. -> Exchange(masses, substeps, mean neighbours).

    How: positions whitened by eta D (``whiten``), so that Eq. 17 is the isotropic exp(-|s_i - s_j|^2
    / (8 dt)) (the factor 1 / sqrt(det(8 pi eta D dt)) is shared by every weight and cancels in
    Eq. 18); the pairs within ``exchange_cutoff`` from one k-d tree (neighbours.pairs_within); the
    weights and Eqs. 16-18 by pair_transfer.pair_weights and pair_transfer.transfer (unit tensors
    in the whitened coordinates). P is a function of the pairs and weights only, so each species'
    call builds the same P and splits into the same substeps. Memory is O(pairs): about 40 bytes a
    pair (the (n_pairs, 2) int64 list, the weights, the compiled loop's P), never N x N.

    Cut-off and truncation error: pairs beyond ``cutoff_sds`` kernel standard deviations
    (r^T (4 eta D dt)^-1 r > cutoff_sds^2) are dropped. A dropped weight is below
    exp(-cutoff_sds^2 / 2) of the self weight; of a 2-D Gaussian kernel the mass beyond is
    exp(-k^2/2) and the share of its variance (k^2 + 2) exp(-k^2/2) / 2, k = cutoff_sds. The
    default, EXCHANGE_CUTOFF_SIGMAS = 6, drops 1.5e-8 of the kernel and 2.9e-7 of its variance for
    (6/9)^2 = 0.44 of the pairs of CUTOFF_SIGMAS = 9 (the reach of the untruncated 1-D kernels),
    which drops 2.6e-18 (round-off of the self term) and 1.1e-16; 7 drops 2.3e-11 and 5.8e-10, 8
    1.3e-14 and 4.2e-13. Mass is conserved to round-off whatever the cut-off (P is symmetric).
    """
    from . import pair_transfer as pt  # numba: loaded by the jobs that step

    masses = np.asarray(m, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    if masses.shape[-1] != n or masses.ndim not in (1, 2):
        raise ValueError(f"masses must be (N,) or (species, N) with N = {n}, not {masses.shape}")
    if not (0.0 <= eta <= 1.0) or dt < 0.0:
        raise ValueError(f"need 0 <= eta <= 1 and dt >= 0, not eta = {eta}, dt = {dt}")
    tensor_2d(D)
    if eta == 0.0 or dt == 0.0 or n < 2:
        return Exchange(masses.copy(), 1, 0.0)
    s = whiten(x, eta * np.asarray(D, dtype=np.float64))
    pairs = pairs_within(s, exchange_cutoff(dt, cutoff_sds))
    w = pt.pair_weights(s, np.ones((n, 2)), pairs, dt)  # exp(-|s_i - s_j|^2 / (8 dt)) / 1
    w_self = np.ones(n)
    rows = masses[None, :] if masses.ndim == 1 else masses
    out = np.empty_like(rows)
    substeps = 1
    for k, row in enumerate(rows):
        out[k], substeps, _ = pt.transfer(pairs, w, w_self, row, COLLISION_BETA)
    return Exchange(out[0] if masses.ndim == 1 else out, substeps, 2.0 * pairs.shape[0] / n)


def plume_bandwidth_2d(n: int, covariance) -> np.ndarray:
    """Bandwidth matrix H = N^(-1/3) Sigma (the kernel's covariance) of a Gaussian kernel for N
    equal-mass particles of a plume of covariance ``Sigma`` [L^2].

    The paper's Eq. 22 with d = 2 in the coordinates where the plume is a standard Gaussian
    (int (lap f)^2 = 1 / (2 pi) there) gives h^6 = 2 / (4 pi N / (2 pi)) = 1 / N, h = N^(-1/6):
    the AMISE-optimal normal-reference rule, Silverman (1986, Density Estimation, Eq. 4.14 and
    Table 4.1: (4 / (d + 2))^(1 / (d + 4)) N^(-1 / (d + 4)), which is N^(-1/6) at d = 2) and, in 2-D
    the same, Scott's rule (Scott 1992, Multivariate Density Estimation, Eq. 6.42). The 2-D form of
    bandwidths.h_de (Eq. 23, 1.06 N^(-1/5) in 1-D). Sigma is the caller's: the exact plume's
    (Sigma_0 + 2 D t, as h_de takes the reference's variance) or the particles' sample covariance.
    """
    return float(n) ** (-1.0 / 3.0) * tensor_2d(covariance)


def kde_2d(points, x, H, cutoff_sds: float = CUTOFF_SIGMAS, chunk_pairs: int = KDE_CHUNK_PAIRS) -> np.ndarray:
    """c(p) = (1/N) sum_i phi_H(p - x_i) at ``points`` (M, 2) from particles ``x`` (N, 2) of mass 1/N
    each [L^-2]; phi_H the Gaussian of covariance ``H`` (2 x 2, e.g. plume_bandwidth_2d) (Eq. 10 in 2-D).

    Particles beyond ``cutoff_sds`` kernel deviations of a point (r^T H^-1 r > cutoff_sds^2) are
    dropped, each below exp(-cutoff_sds^2 / 2) of the kernel's peak: 2.6e-18 at the default 9, so the
    sum is exact to round-off. Both sets are whitened by H and the pairs within the cut-off come
    from two k-d trees, a chunk of points at a time; a chunk holds at most ``chunk_pairs`` // N points,
    so that its pairs stay below ``chunk_pairs`` even where every particle is in reach: memory about
    24 bytes a pair held plus O(N + M), never an N x M matrix. (Sizing the chunks from the first
    chunk's pairs per point, as before, sent the plume's dense middle in one chunk after a sparse
    corner: 1.6 GB for 32,000 particles on 128 x 128 points.)
    """
    from scipy.spatial import cKDTree

    H = tensor_2d(H)
    p = whiten(points, H)
    s = whiten(x, H)
    n, mpts = s.shape[0], p.shape[0]
    out = np.zeros(mpts)
    if n == 0 or mpts == 0:
        return out
    radius = float(cutoff_sds)
    tree = cKDTree(s)
    norm = 1.0 / (n * 2.0 * math.pi * math.sqrt(np.linalg.det(H)))
    size = max(1, min(mpts, chunk_pairs // n))  # points a chunk, as if every particle were in reach
    for start in range(0, mpts, size):
        stop = min(mpts, start + size)
        chunk = cKDTree(p[start:stop])
        d = chunk.sparse_distance_matrix(tree, radius, output_type="ndarray")
        out[start:stop] = np.bincount(d["i"], weights=np.exp(-0.5 * d["v"] ** 2), minlength=stop - start)
    return out * norm


def mtpt_concentration_2d(points, x, m, dV: float) -> np.ndarray:
    """MTPT's concentration at ``points`` (M, 2): c_i = m_i / dV on the particles ``x`` (N, 2),
    linearly interpolated on their Delaunay triangles, 0 outside their convex hull [L^-2].

    dV = area / N, the area of the particles' domain. Linear interpolation is the 2-D form of the
    1-D MTPT's rule (models/mtpt.measure: m / dV interpolated between the sorted particles, 0
    outside the cloud), so the two dimensions score alike; it adds no smoothing, whereas a kernel
    sum of the masses would add its bandwidth's covariance to a plume that the exchange has already
    spread (a second, numerical dispersion). ``m`` (N,) or (species, N) -> (M,) or (species, M).

    The triangles are Qhull's (scipy.spatial.Delaunay); each point's triangle and barycentric
    weights come from ``_locate``, in closed form. scipy's own find_simplex first computes every
    triangle's transform by LAPACK, which took 2-11 s for 8,000 particles where two jobs shared
    two cores (OpenBLAS threads contending), against 0.02 s on one thread.
    """
    from scipy.spatial import Delaunay

    x = np.asarray(x, dtype=np.float64)
    c = np.asarray(m, dtype=np.float64) / dV
    p = np.asarray(points, dtype=np.float64)
    tri = Delaunay(x)
    simplex, weights = _locate(x, tri.simplices, p)
    rows = c[None, :] if c.ndim == 1 else c
    inside = simplex >= 0
    out = np.zeros((rows.shape[0], p.shape[0]))
    corners = tri.simplices[simplex[inside]]  # (K, 3)
    out[:, inside] = np.einsum("skj,kj->sk", rows[:, corners], weights[inside])
    return out[0] if c.ndim == 1 else out


LOCATE_NEAREST = 12  # triangles tried first for each point: those of the nearest centroids


def _locate(x: np.ndarray, triangles: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(triangle index, barycentric weights (M, 3)) of each point of ``p`` (M, 2) in the triangulation
    ``triangles`` (K, 3) of ``x``; -1 outside every triangle. Each point tries the LOCATE_NEAREST
    triangles of nearest centroid (a k-d tree), then, if none holds it, every triangle, a chunk of
    points at a time; weights from the closed-form inverse of each triangle's 2 x 2 edge matrix,
    a point on an edge (weight >= -1e-12 of its triangle's scale) counted in."""
    from scipy.spatial import cKDTree

    a, b, c = (x[triangles[:, k]] for k in range(3))
    e1, e2 = b - a, c - a
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]

    def weights(k: np.ndarray, q: np.ndarray) -> np.ndarray:
        r = q - a[k]
        w1 = (r[..., 0] * e2[k, 1] - r[..., 1] * e2[k, 0]) / det[k]
        w2 = (e1[k, 0] * r[..., 1] - e1[k, 1] * r[..., 0]) / det[k]
        return np.stack([1.0 - w1 - w2, w1, w2], axis=-1)

    simplex = np.full(p.shape[0], -1)
    found = np.zeros((p.shape[0], 3))
    if not triangles.shape[0]:
        return simplex, found
    tol = -1e-12
    k = min(LOCATE_NEAREST, triangles.shape[0])
    _, near = cKDTree((a + b + c) / 3.0).query(p, k=k)
    near = near.reshape(p.shape[0], k)
    w = weights(near, p[:, None, :])  # (M, k, 3)
    ok = np.all(w >= tol, axis=-1)
    hit = ok.any(axis=1)
    first = np.argmax(ok, axis=1)
    rows = np.flatnonzero(hit)
    simplex[rows] = near[rows, first[rows]]
    found[rows] = w[rows, first[rows]]
    every = np.arange(triangles.shape[0])
    for i in np.flatnonzero(~hit):  # far from the cloud's middle or outside it: every triangle
        wi = weights(every, p[i][None, :])
        inside = np.flatnonzero(np.all(wi >= tol, axis=-1))
        if inside.size:
            simplex[i], found[i] = inside[0], wi[inside[0]]
    return simplex, found
