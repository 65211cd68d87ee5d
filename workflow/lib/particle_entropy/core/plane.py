"""A run in the plane (d = 2, issue 52): its settings as a RunConfig carries them and their checks.

A run is 2-D when its source is a core/sources2d.Source2D. Then ``v`` is (vx, vy) [L/T] and ``D`` the
dispersion tensor ((Dxx, Dxy), (Dxy, Dyy)) [L^2/T] (from a scene's {L, T} or {x, y}:
sources2d.dispersion_tensor). The FD window is the square of side fd_length around the source's
centre, lengthened along each axis by the path v t_final (grid_span); the particles' domain the
square of side omega around it, so that MTPT's sampling volume is dV = omega^2 / N. What a 2-D run
cannot do yet is refused here by name: a reaction, MTPT's SPH kernel and the authors' sequential
loop, PT's bins and fixed kernel, explicit FD.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from .case import SettingError
from .sources2d import Source2D

# What 2-D runs take (the models/plane.py forms): FD implicit with upwind, central or tvd advection;
# MTPT's collision kernel (Eq. 17 with the tensor) by the symmetric matrix scheme; PT's kernel estimate
# with the plume's bandwidth matrix (numerics/particles2d.plume_bandwidth_2d), the adaptive kernel's 2-D form.
KERNELS = {"fd": ("implicit",), "mtpt": ("collision",), "pt": ("adaptive",)}
# The memory an FD rung may take at most [bytes], estimated as FD_BYTES_PER_NODE a node: the sparse LU's
# factors and the matrix (benchmarks/fd2d_step.py: 1.8 GB at 1,025^2 nodes, about 1,700 bytes a node).
# Grids of 2^16 unknowns and more take BiCGSTAB instead (about 260 MB there), but fall back to that LU
# where it does not converge: the bound keeps room for it.
FD_BYTES_PER_NODE = 1_700
FD_MAX_BYTES = 4 * 2**30
# The plume's reach each side of the source that a window must hold, in standard deviations of 2 D t_final
# along each axis: the 1-D scenes' 3 sqrt(4 D t) = 3 sqrt(2) sd (settings.SCENE_REACH).
REACH_SDS = 3.0 * math.sqrt(2.0)


def major(D) -> float:
    """The largest eigenvalue of the tensor D: D_L in a flow [L^2/T]."""
    return float(np.linalg.eigvalsh(np.asarray(D, dtype=np.float64))[-1])


def is_plane(source) -> bool:
    """Whether a run with ``source`` is 2-D."""
    return isinstance(source, Source2D)


def source_of(spec: Mapping):
    """A 2-D source from its config form when it has one (a pair x0, or x and y), else None."""
    x0 = spec.get("x0")
    if isinstance(x0, (list, tuple)) or "y" in spec:
        return Source2D.of(**spec)
    return None


def pair(value) -> tuple[float, float]:
    """A velocity as a tuple of two floats."""
    return tuple(float(u) for u in value)


def tensor(value) -> tuple[tuple[float, float], tuple[float, float]]:
    """A dispersion tensor as a tuple of two rows of floats (hashable, as a RunConfig's fields are)."""
    a = np.asarray(value, dtype=np.float64)
    return ((float(a[0, 0]), float(a[0, 1])), (float(a[1, 0]), float(a[1, 1])))


def check(cfg) -> None:
    """Refuse a 2-D run's settings by name: v two finite components, D a finite symmetric positive
    definite tensor, a kernel 2-D runs take (KERNELS), no reaction, domains holding the plume, an FD
    grid within FD_MAX_BYTES, and FD's Courant limit over both axes."""
    D = check_physics(cfg)
    if cfg.reaction is not None:
        raise SettingError("reaction", cfg.reaction.record(), "none in a 2-D run: 2-D reactions do not exist yet")
    kernels = KERNELS[cfg.method]
    if cfg.kernel not in kernels:
        raise SettingError("kernel", cfg.kernel, f"for {cfg.method} in 2-D: {', '.join(kernels)}")
    if cfg.method == "mtpt" and cfg.scheme != "symmetric":
        raise SettingError("scheme", cfg.scheme, "symmetric in 2-D (Eqs. 16-21 on the pairs within the cut-off)")
    if cfg.method == "mtpt" and cfg.truncation is not None:
        raise SettingError(
            "truncation", cfg.truncation, "none in 2-D: the exchange keeps every pair within its cut-off (6 sd)"
        )
    _check_domains(cfg, D)
    if cfg.method == "fd":
        check_fd_memory(cfg.n)
        _check_courant(cfg)


def check_physics(cfg) -> np.ndarray:
    """Refuse a 2-D run's v unless two finite components and its D unless a finite symmetric positive
    definite 2 x 2 tensor, by name -> D as an array."""
    v = np.asarray(cfg.v, dtype=np.float64)
    if v.shape != (2,) or not np.all(np.isfinite(v)):
        raise SettingError("v", cfg.v, "two finite components [vx, vy] [L/T] in a 2-D run")
    D = np.asarray(cfg.D, dtype=np.float64)
    ok = D.shape == (2, 2) and np.all(np.isfinite(D)) and D[0, 1] == D[1, 0]
    if not (ok and D[0, 0] > 0 and np.linalg.det(D) > 0):
        raise SettingError("D", cfg.D, "a finite symmetric positive definite 2 x 2 tensor [L^2/T] in a 2-D run")
    return D


def source_reach(source) -> np.ndarray:
    """The source's own half extent along each axis around its centre: 3 sd of its covariance, a box's
    half side [L] (2,)."""
    if source.kind == "box":
        return 0.5 * np.array([np.ptp(source.x), np.ptp(source.y)])
    return 3.0 * np.sqrt(np.diag(source.covariance))


def sd_reach(cfg, D: np.ndarray) -> np.ndarray:
    """The half width each axis of a domain must hold around the source's centre: the source's own
    (source_reach) plus REACH_SDS sd of 2 D t_final [L] (2,)."""
    return source_reach(cfg.source) + REACH_SDS * np.sqrt(np.diag(2.0 * D * cfg.t_final))


def _check_domains(cfg, D: np.ndarray) -> None:
    """The FD window (fd_length) or the particles' square (omega) must hold the plume on both axes."""
    need = 2.0 * float(sd_reach(cfg, D).max())
    name, length = ("fd_length", cfg.fd_length) if cfg.method == "fd" else ("omega", cfg.omega)
    if length < need:
        raise SettingError(
            name,
            length,
            f"a side >= {need:.6g} in 2-D: the source's extent plus {REACH_SDS:.3g} sd of 2 D t_final each side "
            f"on both axes (D = {np.asarray(cfg.D).tolist()}, t_final = {cfg.t_final:g})",
        )


def fd_bytes(n: int) -> float:
    """The memory an n x n FD grid takes (FD_BYTES_PER_NODE a node) [bytes]."""
    return float(n + 1) ** 2 * FD_BYTES_PER_NODE


def check_fd_memory(n: int, where: str = "n") -> None:
    """Refuse an FD rung whose grid would take more than FD_MAX_BYTES, naming it, its n x n and the bytes."""
    need = fd_bytes(n)
    if need > FD_MAX_BYTES:
        most = int(math.sqrt(FD_MAX_BYTES / FD_BYTES_PER_NODE)) - 1
        raise SettingError(
            where,
            n,
            f"at most {most - most % 2:,} nodes per axis in 2-D: an FD rung of {n:,} x {n:,} needs about "
            f"{need / 2**30:.3g} GiB ({need:.3g} bytes), over the {FD_MAX_BYTES / 2**30:g} GiB a run may take",
        )


def grid_span(cfg) -> tuple[np.ndarray, np.ndarray]:
    """(first node (2,), spacing (dx, dy)) of a 2-D run's n x n FD grid: the square window fd_length
    around the source's centre lengthened along each axis by the path v t_final (as the line's
    fd_span), then shifted by less than half a cell so that the source's centre is a node, as on the
    line (a point's mass then sits on one node, whatever n) [L]."""
    centre = np.asarray(cfg.source.centre, dtype=np.float64)
    path = np.asarray(cfg.v, dtype=np.float64) * cfg.t_final
    lo = centre - 0.5 * cfg.fd_length + np.minimum(path, 0.0)
    h = (cfg.fd_length + np.abs(path)) / cfg.n
    return centre - np.round((centre - lo) / h) * h, h


def grid_numbers(cfg, dt: float) -> tuple[float, float]:
    """(grid Peclet max_i |v_i| dx_i / D_ii, Courant max_i |v_i| dt / dx_i) of a 2-D FD run at step dt."""
    _, h = grid_span(cfg)
    v, D = np.abs(np.asarray(cfg.v, dtype=np.float64)), np.diag(np.asarray(cfg.D, dtype=np.float64))
    return float(np.max(v * h / D)), float(np.max(v * dt / h))


def courant_step(cfg) -> float:
    """FD's step at its Courant number: courant / max(|vx| / dx, |vy| / dy) [T]."""
    check_physics(cfg)
    ok = isinstance(cfg.courant, (int, float)) and not isinstance(cfg.courant, bool)
    if not (ok and 0.0 < cfg.courant < math.inf) or cfg.method != "fd":
        raise SettingError("courant", cfg.courant, "a number > 0 for fd in a flow: the step's Courant number")
    _, (dx, dy) = grid_span(cfg)
    rate = max(abs(cfg.v[0]) / dx, abs(cfg.v[1]) / dy)
    if not rate > 0:
        raise SettingError("courant", cfg.courant, "no courant at v = 0: fd in a flow only")
    return cfg.courant / rate


def _check_courant(cfg) -> None:
    """Refuse a tvd step beyond Courant 1 on either axis (grid_numbers), naming courant or fd_dt."""
    from .registry import COURANT_LIMIT, COURANT_SLACK

    limit = COURANT_LIMIT.get(cfg.advection)
    if limit is None or not any(cfg.v):
        return
    _, cr = grid_numbers(cfg, cfg.dt0)
    if cr <= limit or math.isclose(cr, limit, rel_tol=COURANT_SLACK):
        return
    name, value = ("courant", cfg.courant) if cfg.courant is not None else ("fd_dt", cfg.dt0)
    raise SettingError(
        name, value, f"a step whose Courant number max(|vx| dt / dx, |vy| dt / dy) <= {limit:g} (this one {cr:.6g})"
    )
