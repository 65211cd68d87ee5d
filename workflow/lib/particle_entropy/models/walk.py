"""Random-walk step of the Ito equation dX = (v + a) dt + B sqrt(2 dt) xi, B B^T = D (Section 2), in d dimensions."""

from __future__ import annotations

import math

import numpy as np


def walk(x, D, dt: float, rng: np.random.Generator, v=0.0, drift=None) -> np.ndarray:
    """X <- ((X + v dt) + B sqrt(2 dt) xi) + a dt for positions ``x`` [L] of shape (N,) (d = 1) or (N, d).

    ``D`` [L^2/T]: a scalar (isotropic), per particle (N,) when d = 1; for (N, d) positions a (d,)
    diagonal, per-particle diagonals (N, d), per-particle tensors (N, d, d) or one tensor for all
    particles (1, d, d), whose B is the
    symmetric square root (eigenvalues below 0 from round-off taken as 0). ``v`` and the drift ``a``
    (e.g. the Ito term div D) [L/T] broadcast against ``x``; v = 0 (a scalar) adds nothing, and
    ``drift=None`` adds nothing. xi is drawn as ``rng.standard_normal((d, N))``, one row per
    direction, so that d = 1 draws ``standard_normal(N)`` and the additions run in the order
    written: a 1-D walk is bit-identical to ``x + sqrt(2 D dt) xi``.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        xi = rng.standard_normal(x.size)
    elif x.ndim == 2:
        xi = rng.standard_normal((x.shape[1], x.shape[0])).T
    else:
        raise ValueError(f"positions must be (N,) or (N, d), not {x.shape}")
    step = _scaled_noise(D, dt, xi, x.shape)
    out = x + step if np.ndim(v) == 0 and v == 0.0 else (x + np.multiply(v, dt)) + step
    return out if drift is None else out + np.multiply(drift, dt)


def _scaled_noise(D, dt: float, xi: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """B sqrt(2 dt) xi for the forms of D that ``walk`` takes."""
    if np.ndim(D) == 0:
        return math.sqrt(2.0 * float(D) * dt) * xi
    D = np.asarray(D, dtype=np.float64)
    if D.ndim == 3:
        n, d = shape
        if D.shape not in ((n, d, d), (1, d, d)):
            raise ValueError(f"tensors must be (N, d, d) = {(n, d, d)}, or (1, d, d) for all, not {D.shape}")
        lam, vec = np.linalg.eigh(D)
        root = np.sqrt(np.maximum(lam, 0.0))
        b = np.einsum("nij,nj,nkj->nik", vec, root, vec)  # B = V diag(sqrt(lambda)) V^T
        if D.shape[0] == 1 and n != 1:  # one tensor for every particle
            return math.sqrt(2.0 * dt) * (xi @ b[0].T)
        return math.sqrt(2.0 * dt) * np.einsum("nij,nj->ni", b, xi)
    if np.broadcast_shapes(D.shape, shape) != shape:
        raise ValueError(f"D of shape {D.shape} does not fit positions of shape {shape}")
    return np.sqrt(2.0 * D * dt) * xi
