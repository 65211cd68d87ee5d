"""Estimated seconds of a simulation job, by arithmetic on its case, so that the workflow starts
the longest jobs first (Snakemake `priority`) and a run does not end on one long job alone
(the shear flow's jobs: ``shear_seconds``).

The model is the run cost model's step-work kind (core/runcost.StepWork, which counts the steps),
one a method (JOB_COST), with the pairs a sequential (the authors') loop visits priced too:
    seconds = seeds x sum over steps of (STEP_S + UNIT_S[method] x N + PAIR_S x pairs),
where ``pairs`` counts every particle with the neighbours inside its cut-off radius r, each pair
once, N^2 r / Omega. The symmetric transfer sums with windowed or fast Gauss transforms, whose cost
grows with N alone. The constants are the per-step, per-node or particle (per N, not per FD node)
and per-pair seconds of the paper run's 175 simulation jobs (2-vCPU Xeon, 2026-12-03), rounded:
only the order of the jobs matters, not the seconds.
"""

from __future__ import annotations

import numpy as np

from ..core.registry import SCHEME_RECORDS
from ..core.runconfig import RunConfig
from ..core.runcost import StepWork
from ..numerics.bandwidths import collision_sigma, cutoff_radius, h_sph

STEP_S = {"fd": 3e-5, "pt": 5e-5, "mtpt": 8e-5}  # a step's own cost (measures, records) [s]
UNIT_S = {"fd": 1.5e-8, "pt": 3e-8, "mtpt": 2.5e-7}  # per node or particle and step [s]
PAIR_S = 5e-9  # per pair visited by the sequential loop [s]


def pairs_per_step(cfg: RunConfig, dt: np.ndarray, t_end: np.ndarray) -> np.ndarray:
    """Pairs within the cut-off of each step of a sequential MTPT run (0 for the others)."""
    if cfg.method != "mtpt" or not SCHEME_RECORDS[cfg.scheme].sequential:
        return np.zeros_like(dt)
    if cfg.kernel == "collision":
        sigma = np.array([collision_sigma(cfg.eta, cfg.D, d) for d in dt])
    else:
        constant = SCHEME_RECORDS[cfg.scheme].sph_constant
        sigma = np.array([h_sph(cfg.n, cfg.omega, cfg.reference(t).kernel_variance, constant) for t in t_end])
    radius = np.array([cutoff_radius(s, cfg.truncation) for s in sigma])
    return cfg.n * np.minimum(cfg.n * radius / cfg.omega, cfg.n / 2.0)


# the simulation jobs' cost model, one a method (the constants above; per N, pairs counted)
JOB_COST = {m: StepWork(STEP_S[m], UNIT_S[m], PAIR_S, per="n", pairs=pairs_per_step) for m in STEP_S}


def estimated_seconds(cfg: RunConfig, seeds: int = 1) -> float:
    """Estimated seconds of ``seeds`` runs of a resolved ``cfg`` (the model above)."""
    return seeds * JOB_COST[cfg.method].seconds(cfg)


# a shear step per particle: mass transfer among neighbours (`mt`) or a random walk [s]; the paper
# run's mt job (N = 20,000, 500 steps) took 11.8 s, a walk 0.9 s, mostly start-up
SHEAR_PARTICLE_STEP_S = {"mt": 1.2e-6, "rw_nodrift": 1e-8, "rw_drift": 1e-8}


def shear_seconds(case: str, shear) -> float:
    """Estimated seconds of one shear job of the typed section ``shear`` (Config.shear, its
    defaults filled in by its model)."""
    return SHEAR_PARTICLE_STEP_S[case] * float(shear.n) * float(shear.t_final) / float(shear.dt)
