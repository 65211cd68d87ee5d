"""Peak memory of one simulation, estimated before it starts, and the memory the machine has.

The model is linear, peak ~ base + per_step x steps + per_unit x N, fitted to peak resident set
sizes of `python -m particle_entropy simulate` and rounded up (benchmarks/bench_memory.py
compares the two): each time step keeps one row of the per-step table, each particle or node its
arrays (mass transfer also its neighbour windows). The CLI refuses a run whose estimate exceeds
the memory available; the workflow declares it as the job's mem_mb.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..core.runconfig import RunConfig
from ..core.timegrid import step_count

# measured (40 runs, one at a time): base 252 MB; 1.7-1.9 kB a step; per particle or node pt 19-39 B,
# fd 64-80 B, mtpt collision 107-138 B and SPH 126-202 B (rising with N: its FGT uses more boxes)
BASE_BYTES = 300e6
STEP_BYTES = 2.5e3
UNIT_BYTES = {"fd": 150.0, "pt": 100.0, "mtpt": 400.0}


def estimate_bytes(cfg: RunConfig) -> float:
    """Estimated peak memory of one run of a resolved ``cfg``, in bytes (an upper estimate)."""
    steps = step_count(cfg.t_final, cfg.dt0, cfg.dt_growth)
    if cfg.dim == 2:
        return BASE_BYTES + STEP_BYTES * steps + plane_bytes(cfg)
    return BASE_BYTES + STEP_BYTES * steps + UNIT_BYTES[cfg.method] * cfg.n


# 2-D runs (core/plane.py): FD holds its LU (core/plane.FD_BYTES_PER_NODE a node, which the Krylov
# solve falls back to); MTPT its pairs within the cut-off (numbers as the shear flow's, SHEAR_*);
# PT its kernel estimate's chunk of (point, particle) pairs (particles2d.KDE_CHUNK_PAIRS)
PLANE_PARTICLE_BYTES = 400.0
KDE_PAIR_BYTES = 64.0  # measured: 32,000 particles on 128 x 128 points peaked at 367 MB


def plane_bytes(cfg: RunConfig) -> float:
    """What a 2-D run adds to the base and its steps [bytes]: FD's grid and LU; MTPT's pairs at its
    largest step, N^2 / 2 x the share of the square omega^2 its cut-off ellipse covers; PT's chunk."""
    from ..core.plane import fd_bytes
    from ..numerics.particles2d import EXCHANGE_CUTOFF_SIGMAS, KDE_CHUNK_PAIRS

    if cfg.method == "fd":
        return fd_bytes(cfg.n)
    n = float(cfg.n)
    if cfg.method == "pt":
        return PLANE_PARTICLE_BYTES * n + KDE_PAIR_BYTES * KDE_CHUNK_PAIRS
    from ..core.timegrid import time_steps

    dt = float(max(time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, cfg.time_grid)))
    det = float(np.linalg.det(cfg.eta * np.asarray(cfg.D, dtype=np.float64)))
    # the cut-off k sd of the kernel of covariance 4 eta D dt: an ellipse of area pi k^2 4 dt sqrt(det)
    area = math.pi * EXCHANGE_CUTOFF_SIGMAS**2 * 4.0 * dt * math.sqrt(det)
    pairs = 0.5 * n * n * min(1.0, area / cfg.omega**2)
    return PLANE_PARTICLE_BYTES * n + SHEAR_PAIR_BYTES * pairs


def estimate_mb(cfg: RunConfig, runs: int = 1) -> int:
    """Estimated peak of ``runs`` runs in one process (a seed block keeps each run's per-step table), in MB."""
    one = estimate_bytes(cfg)
    steps_table = STEP_BYTES * step_count(cfg.t_final, cfg.dt0, cfg.dt_growth)
    return int((one + (runs - 1) * steps_table) / 2**20) + 1


def available_bytes() -> float | None:
    """Memory a new process can use now (MemAvailable of /proc/meminfo; total memory elsewhere); None if unknown."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return None


# measured on one mt transfer step (N = 20,000 and 80,000): 16-18 B a pair in numpy arrays, about
# 35 B a pair of resident memory with the KD tree's; rounded up, as memory.py's per-particle bytes
SHEAR_PAIR_BYTES = 64.0
SHEAR_PARTICLE_BYTES = 400.0


def shear_memory_mb(shear) -> int:
    """Estimated peak memory of the largest shear job (Fig. 10) of the typed section ``shear``
    (pipeline/config.py: Config.shear), in MB, by arithmetic: the base of
    every run (memory.BASE_BYTES), its particles' arrays and, for mass transfer, its neighbour pairs:
    N^2 / 2 x the kernel's share of the domain, pi s_c^2 / (L / sqrt(alpha_L) / sqrt(alpha_T)) in
    scaled distance (2 s_c / (L / sqrt(alpha_L)) for alpha_T = 0; shear2d.kernel_cutoff)."""
    from ..models.shear2d import ShearConfig, kernel_cutoff

    n = float(shear.n)
    need = BASE_BYTES + SHEAR_PARTICLE_BYTES * n
    if "mt" in shear.cases:
        cfg = ShearConfig(case="mt", **shear.model_dump(exclude={"cases", "n"}))
        cut, width = kernel_cutoff(cfg), cfg.length / math.sqrt(cfg.alpha_L)
        share = math.pi * cut**2 / (width / math.sqrt(cfg.alpha_T)) if cfg.alpha_T > 0 else 2.0 * cut / width
        need += SHEAR_PAIR_BYTES * n * n / 2.0 * min(share, 1.0)
    return int(need / 2**20) + 1
