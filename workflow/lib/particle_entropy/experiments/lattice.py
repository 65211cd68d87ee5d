"""Noise-free floors of the mass-transfer schemes: a run on evenly spaced particles.

With particles at random positions the SSE (Eq. 44) has a sampling part that falls like 1/N
and a part that does not: what the scheme and its time step leave of the Gaussian. On an even
lattice there is no sampling part, so the SSE per particle of a lattice run is that floor (it
does not change with N once the lattice resolves the kernel). Needs eta = 1: random walks would
move the particles off the lattice.
"""

from __future__ import annotations

import numpy as np

from ..core.runconfig import RunConfig
from ..core.timegrid import time_steps, times
from ..models import mtpt


def lattice_state(cfg: RunConfig, rng: np.random.Generator):
    """N (odd) particles evenly spaced on [-Omega/2, Omega/2], the unit mass at x = 0 stored first
    and the others in random storage order: (positions, masses, storage index of each)."""
    if cfg.n % 2 == 0:
        raise ValueError(f"a lattice needs an odd N to put a particle at x = 0, got {cfg.n}")
    x = np.linspace(-cfg.omega / 2.0, cfg.omega / 2.0, cfg.n)
    mid = cfg.n // 2
    x[mid] = 0.0
    m = np.zeros(cfg.n)
    m[mid] = 1.0
    others = 1 + rng.permutation(cfg.n - 1)
    label = np.concatenate([others[:mid], [0], others[mid:]])
    return x, m, label


def lattice_run(cfg: RunConfig, report_times) -> list[dict]:
    """A run of ``cfg`` (mtpt, eta = 1) on the lattice: SSE, SSE/N and COMIC at the steps nearest
    ``report_times``."""
    cfg = cfg.resolved()
    if cfg.method != "mtpt" or cfg.eta != 1.0:
        raise ValueError(f"a lattice run needs method mtpt and eta = 1, got {cfg.method}, eta = {cfg.eta}")
    dts = time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, cfg.time_grid)
    ts = times(dts, cfg.t_final if cfg.time_grid == "exact" else None)
    want = {int(np.argmin(np.abs(ts - t))): float(t) for t in report_times}
    rng, order_rng = cfg.rng(), cfg.rng(stream=1)
    x, m, label = lattice_state(cfg, rng)
    rows = []
    for k, dt in enumerate(dts, start=1):
        x, m, label, *_ = mtpt.step(cfg, x, m, label, dt, ts[k], rng, order_rng)
        if k in want:
            meas = mtpt.measure(cfg, x, m, ts[k])
            rows.append(
                {
                    **cfg.case.columns(),
                    "time": want[k],
                    "time_step": float(ts[k]),
                    "SSE": meas["SSE"],
                    "SSE_over_N": meas["SSE"] / cfg.n,
                    "COMIC": meas["COMIC"],
                    "mass_total": meas["mass_total"],
                }
            )
    return rows
