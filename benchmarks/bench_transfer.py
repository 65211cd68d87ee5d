"""Time per MTPT mass-transfer step: shipped method against the baselines, same run.

    python benchmarks/bench_transfer.py                  # N in 300 .. 300,000, early and late widths
    python benchmarks/bench_transfer.py --n 3000 --quick
    python benchmarks/bench_transfer.py --boxes          # FGT box width and direct/FGT crossover

Methods (all on the same particles and masses):
  shipped     particle_entropy.numerics.mass_transfer.mass_transfer, method auto (windowed sum or FGT)
  windowed    the same update with the exact windowed sum forced (O(N x neighbours))
  kdtree      scipy cKDTree.sparse_distance_matrix + scipy.sparse symmetric P (the usual approach)
  authors     a pure-Python port of the authors' sequential pairwise loop (N <= 3,000)
Kernel widths: collision kernel sigma = sqrt(4 D dt) at the first step (dt = 0.01) and at late
time (dt ~ 48, sigma ~ 0.44), D = 1e-3, whole Gaussian (cut-off 9 sigma) except `authors` (3 sigma).
Particles and masses: `run` = the state an MTPT run (collision kernel, eta = 1, Omega = 10)
really has at that step: one unit mass among empty particles at the first step, a spread
plume at the last; `dense` = uniform positions with every mass > 0 (the worst case for the FGT,
which skips empty boxes). Ratios are medians measured in this one run.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from particle_entropy.core.run_settings import DT_GROWTH
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.timegrid import time_steps
from particle_entropy.core.timegrid import times as step_times
from particle_entropy.models import mtpt
from particle_entropy.numerics import gauss
from particle_entropy.numerics.gauss import CUTOFF_SIGMAS, gauss_transform, neighbour_count
from particle_entropy.numerics.mass_transfer import mass_transfer

D = 1e-3
WIDTHS = {"early": math.sqrt(4 * D * 0.01), "late": math.sqrt(4 * D * 0.01 * DT_GROWTH**174)}
MEMORY_LIMIT = 4e9  # bytes: baselines that would need more are skipped with a reason


def particles(n: int, seed: int = 0):
    """`dense` state: uniform positions, every mass > 0."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(-5, 5, n))
    m = np.exp(-x * x / 2.0) * rng.uniform(0.5, 1.5, n)
    return x, m / m.sum()


def run_states(n: int, seed: int = 0):
    """`run` states: (x, m) of an MTPT run before its first and before its last step."""
    cfg = RunConfig.of(method="mtpt", kernel="collision", n=n, seed=seed).resolved()
    dts = time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth)
    ts = step_times(dts, cfg.t_final)
    rng = cfg.rng()
    x, m, label = mtpt.initial_state(cfg, rng)
    early = (x, m)
    for k, dt in enumerate(dts[:-1], start=1):
        x, m, label, *_ = mtpt.step(cfg, x, m, label, dt, ts[k], rng)
    return {"early": early, "late": (x, m)}


def kdtree_step(x, m, sigma, beta):
    """Baseline: neighbour pairs from a kd-tree, W as a sparse matrix, symmetric P."""
    tree = cKDTree(x[:, None])
    d = tree.sparse_distance_matrix(tree, CUTOFF_SIGMAS * sigma, output_type="coo_matrix")
    W = sp.csr_matrix((np.exp(-0.5 * (d.data / sigma) ** 2), (d.row, d.col)), shape=(x.size, x.size))
    W = W + sp.identity(x.size, format="csr")  # self pairs (distance 0 is not stored)
    r = np.asarray(W.sum(axis=1)).ravel()
    P = 0.5 * (sp.diags(1 / r) @ W + W @ sp.diags(1 / r))
    return m + beta * (P @ m - m * np.asarray(P.sum(axis=1)).ravel())


def authors_step(x, m, sigma, beta, rng):
    """Pure-Python port of the authors' loop: i in order, partners j > i within 3 sigma in
    random order, weights normalised by i's row sum only, masses clipped at zero."""
    m = m.copy()
    lo_idx = np.searchsorted(x, x - 3 * sigma, side="left")
    hi_idx = np.searchsorted(x, x + 3 * sigma, side="right")
    for i in range(x.size):
        lo, hi = lo_idx[i], hi_idx[i]
        w = np.exp(-((x[lo:hi] - x[i]) ** 2) / (2 * sigma * sigma))
        rescale = w.sum()
        partners = list(range(i + 1, hi))
        for j in rng.permutation(partners) if partners else []:
            v = w[j - lo] / rescale
            dm = beta * (m[i] - m[j]) * v
            m[i] = max(0.0, m[i] - dm)
            m[j] = max(0.0, m[j] + dm)
    return m


def timed(fn, min_time=0.5, max_reps=50):
    """Median wall time of fn() over repeats (at least 3, or until min_time is spent)."""
    times = []
    while len(times) < 3 or (sum(times) < min_time and len(times) < max_reps):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
        if times[-1] > 20:  # one slow baseline call is enough
            break
    return float(np.median(times))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--n", type=int, nargs="+", default=[300, 3000, 30000, 300000])
    p.add_argument("--quick", action="store_true", help="fewer repeats")
    p.add_argument("--states", nargs="+", default=["run", "dense"], choices=["run", "dense"])
    p.add_argument("--boxes", action="store_true", help="time FGT box widths and the direct sum instead")
    a = p.parse_args()
    min_time = 0.1 if a.quick else 0.5
    warm_x, warm_m = particles(50)
    for method in ("direct", "fgt"):  # load the compiled kernels before timing
        mass_transfer(warm_x, warm_m, 0.5, 0.5, method=method)
    if a.boxes:
        box_widths(min_time)
        return
    print(
        "| N | width | masses | sigma | neighbours (9 sigma) | shipped ms | us per particle | windowed ms "
        "| kdtree ms | authors ms | windowed / shipped | kdtree / shipped | authors / shipped |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n in a.n:
        states = {}
        if "run" in a.states:
            states.update({(label, "run"): xm for label, xm in run_states(n).items()})
        if "dense" in a.states:
            states.update({(label, "dense"): particles(n) for label in WIDTHS})
        for (label, kind), (x, m) in sorted(states.items()):
            bench_row(n, label, kind, x, m, WIDTHS[label], min_time)


def bench_row(n, label, kind, x, m, sigma, min_time):
    nb = neighbour_count(x, x, CUTOFF_SIGMAS * sigma)
    row = {"shipped": timed(lambda: mass_transfer(x, m, sigma, 0.5), min_time)}
    reasons = []
    pairs = n * nb
    if pairs * 10e-9 < 60:  # about 10 ns a pair: skip beyond a minute
        row["windowed"] = timed(lambda: mass_transfer(x, m, sigma, 0.5, method="direct"), min_time)
    else:
        reasons.append(f"windowed skipped: {pairs:.2g} pairs (~{pairs * 10e-9:.0f} s)")
    kd_bytes = pairs * 48  # coo (row, col, data) + csr copies of W and P
    if kd_bytes < MEMORY_LIMIT:
        row["kdtree"] = timed(lambda: kdtree_step(x, m, sigma, 0.5), min_time)
    else:
        reasons.append(f"kdtree skipped: ~{kd_bytes / 1e9:.0f} GB > 4 GB")
    if n <= 3000:
        rng = np.random.default_rng(1)
        row["authors"] = timed(lambda: authors_step(x, m, sigma, 0.5, rng), min_time, max_reps=3)
    else:
        reasons.append("authors skipped: N > 3,000 (pure Python)")
    ms = {k: f"{1e3 * v:.3g}" for k, v in row.items()}
    ratio = {k: f"{row[k] / row['shipped']:.3g}x" for k in ("windowed", "kdtree", "authors") if k in row}
    print(
        f"| {n:,} | {label} | {kind} | {sigma:.4f} | {nb:.0f} | {ms['shipped']} | {1e6 * row['shipped'] / n:.3g} "
        f"| {ms.get('windowed', '-')} | {ms.get('kdtree', '-')} | {ms.get('authors', '-')} "
        f"| {ratio.get('windowed', '-')} | {ratio.get('kdtree', '-')} | {ratio.get('authors', '-')} |"
    )
    for r in reasons:
        print(f"<!-- N={n} {label} {kind}: {r} -->")


def box_widths(min_time, n=30000, ratios=(0.5, 1.0, 1.5, 2.5, 3.5)):
    """ms per Gauss transform of n uniform sources with all weights > 0: the FGT at fixed box
    widths (in sigma), as planned (fgt_plan), and the windowed sum, from 3 to 1000 sources per
    sigma, for k weight vectors."""
    x = np.sort(np.random.default_rng(0).uniform(-5, 5, n))
    default = gauss.FGT_BOX_RATIOS
    print(
        "| weights | sources per sigma | "
        + " | ".join(f"fgt {r} sigma" for r in ratios)
        + " | fgt planned | windowed |"
    )
    print("|---" * (len(ratios) + 4) + "|")
    try:
        for k in (1, 3):
            q = np.ones((k, n))
            for per_sigma in (3, 5, 7, 10, 20, 30, 100, 1000):
                sigma = per_sigma * 10.0 / n
                cells = []
                for r in ratios + (None,):
                    gauss.FGT_BOX_RATIOS = default if r is None else (r,)
                    fgt = lambda q=q, sigma=sigma: gauss_transform(x, x, q, sigma, method="fgt")
                    cells.append(timed(fgt, min_time))
                direct = (
                    timed(lambda q=q, sigma=sigma: gauss_transform(x, x, q, sigma, method="direct"), min_time)
                    if per_sigma <= 30
                    else None
                )
                text = " | ".join(f"{1e3 * c:.3g}" for c in cells)
                print(f"| {k} | {per_sigma} | {text} | {'-' if direct is None else f'{1e3 * direct:.3g}'} |")
    finally:
        gauss.FGT_BOX_RATIOS = default


if __name__ == "__main__":
    main()
