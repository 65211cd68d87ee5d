"""The authors' sequential pairwise mass transfer, and variants of it that change one detail.

Facts about the authors' MATLAB script (repository dbenson5225/Particle_Entropy, file
RW_entropy_ens_GSM_COMIC.m), checked line by line against that script and implemented here:

1. Storage. Particles keep the order in which they were created: the unit mass at x = 0 first,
   then N - 1 positions uniform on [-Omega/2, Omega/2]. Storage order is random in space and
   never changes; random walks move particles, not their place in storage.
2. Visits. Each step visits particles i = 1 ... N in storage order. Particle i exchanges with
   every neighbour j within the cut-off that comes later in storage (j > i); these lie on both
   sides of i.
3. Partner order. The partners of i are taken in a random order, a fresh permutation for each i.
4. Weights. The weight of pair (i, j) is W_ij / r_i, where W_ij = exp(-(x_i - x_j)^2 / (2 h^2))
   (the kernel's prefactor cancels) and r_i sums W over all of i's neighbours within the cut-off,
   i itself included. Positions do not change during the transfer, so r_i is fixed for the step.
5. Cut-off. Neighbours are found by a range search of radius 3 h (|x_i - x_j| <= 3 h).
6. Update. dm = beta (m_i - m_j) W_ij / r_i, then m_i <- max(0, m_i - dm) and
   m_j <- max(0, m_j + dm). The clipping breaks mass conservation only when it acts, which
   needs beta W_ij / r_i > 1. With beta = 1/2 it never acts, because W_ij <= r_i.
7. Kernels. Collision: h = sqrt(4 eta D dt), beta = 1/2 (Eq. 17). SPH: h = 0.822 (2 D t)^(2/5)
   (Omega/N)^(1/5), with D (not eta D) and t the time at the end of the step; beta =
   2 eta D dt / h^2 (Eq. 20), used as it is even above 1 (no splitting).
8. Random walk. When eta < 1, the same particles first take a random walk with (1 - eta) D,
   then the transfer.
9. Time loop. The clock advances by dt before the step, and the loop runs while t < t_final;
   dt grows by the factor run_settings.DT_GROWTH after each step. With dt0 = 0.01 and t_final = 1000 it ends after 175
   steps at t = 1021.1 (timegrid.time_steps with grid "authors").
10. Details kept as the paper has them (each a small difference): the script's SPH constant is
   0.822 where Eq. 26 has 0.82 (0.24 % in h, 0.5 % in beta), and both kernels' lines are in the
   script, the SPH ones overriding the collision ones (one is commented in or out by hand).
11. Error and COMIC. The script's SSE is sum_i (g_i - m_i/dV)^2 / N with g the Gaussian at the
   particles normalised so that sum_i g_i dV = 1 (measures.sse over N, the same). Its Fig. 9
   is the COMIC of the ensemble-mean SSE at the last step, 2 ln(mean SSE/N) - ln(Omega/N), with
   error bars ln(mean +- std) - ln(mean) of the SSE: not doubled, so on the COMIC scale they are
   half the +-1 std of the SSE (aggregate.comic_of_mean_sse draws them doubled); its variance is
   a running estimate, not the sample variance.

Variants for the controlled experiments (registry.SCHEMES) each change one detail:
- ``sorted``: visit particles left to right, partners to the right only (storage = position
  order);
- ``symnorm``: weight W_ij (1/r_i + 1/r_j) / 2, the pair weight of the symmetric matrix
  (Eq. 18);
- ``noclip``: no clipping.

r_i is built during the sweep. When i is visited, every neighbour stored before i has already
been visited and has added its W to i's sum, so each pair's kernel is evaluated once. A visited
particle never changes again within the step, so the sweep keeps the unvisited ones in compact
arrays in position order, and each window holds almost only partners. The random
permutations come from a SplitMix64 stream that is seeded for each step from the run's numpy
Generator.

Two forms of the loop compute this: ``_sweep``, bit for bit the loop before issue 20
(tests/sequential_reference.py), and ``_sweep_fma``, the default, equal to it to round-off and
at 0.5-0.6 of its time for N >= 10,000 (docs/speed.md); ``sequential_transfer(..., exact=True)``
selects the first. Both are numba kernels in sequential_kernels.py, reached through
compiled.kernels() (numba's JIT, or the same kernels compiled ahead of time for a job).
"""

from __future__ import annotations

import numpy as np

from .compiled import kernels
from .gauss import cutoff_radius


def sequential_transfer(
    x: np.ndarray,
    m: np.ndarray,
    sigma: float,
    beta: float,
    truncation: float | None,
    rng: np.random.Generator,
    label: np.ndarray | None = None,
    symnorm: bool = False,
    clip: bool = True,
    exact: bool = False,
) -> np.ndarray:
    """One step of the authors' loop on sorted positions ``x``; ``label`` is the storage index of
    each particle (None: storage order = position order, the ``sorted`` variant). ``rng`` seeds
    the partner permutations of this step. The input masses are not changed. ``exact``: the form
    bit-identical to the loop before issue 20 (_sweep), else the fast form equal to it to
    round-off (_sweep_fma, the default)."""
    radius = cutoff_radius(sigma, truncation)
    if label is None:
        label = np.arange(x.size, dtype=np.int64)
    seed = int(rng.integers(0, 2**63))
    sweep = kernels()._sweep if exact else kernels()._sweep_fma
    return sweep(
        np.ascontiguousarray(x, dtype=np.float64),
        np.array(m, dtype=np.float64),
        np.ascontiguousarray(label, dtype=np.int64),
        float(sigma),
        float(radius),
        float(beta),
        np.uint64(seed),
        bool(symnorm),
        bool(clip),
    )


def warm_up() -> None:
    """Load the compiled loop (the module compiled ahead of time, or numba's on-disk cache; the
    default form) before the timed steps."""
    x = np.linspace(-1.0, 1.0, 8)
    sequential_transfer(x, np.ones(8), 0.5, 0.5, 3.0, np.random.default_rng(0), label=np.arange(8)[::-1].copy())
