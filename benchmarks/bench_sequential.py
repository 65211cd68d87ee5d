"""The authors' loop, today's code against the reference it replaced, side by side in one process.

    python benchmarks/bench_sequential.py                   # N = 3,000, 10,000, 30,000
    python benchmarks/bench_sequential.py --n 3000 --repeats 5

Reference: tests/sequential_reference.py, the loop as it was before issue 20 (bit for bit the
same results, checked here on every timed step). States: N positions uniform on [-Omega/2,
Omega/2] stored in random order, a Gaussian plume of variance 2 D t as masses, the collision
kernel at eta = 1 cut at 3 widths, at steps 100, 140 and 174 of the authors' time grid (dt0 =
0.01, growth 1.05): the late steps hold most of a run's pair updates. A pair update is one
(i, j) exchange; the count is measured on the state, not modelled. Each timing is the least of
``repeats`` alternating runs (old, new, old, new, ...), after one untimed run of each.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from particle_entropy.numerics import sequential
from particle_entropy.numerics.kernels import collision_sigma

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import sequential_reference  # noqa: E402  (the loop before issue 20, kept as the tests' reference)

D, OMEGA, TRUNCATION, BETA = 1e-3, 10.0, 3.0, 0.5
STEPS = (100, 140, 174)


def state(n: int, step: int, seed: int = 0):
    """(x sorted, m, storage labels, sigma) of a collision-kernel run before ``step``."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(-OMEGA / 2, OMEGA / 2, n))
    dt = 0.01 * 1.05**step
    t = 0.01 * (1.05**step - 1.0) / 0.05
    m = np.exp(-x * x / (4.0 * D * t))
    return x, m / m.sum(), rng.permutation(n).astype(np.int64), collision_sigma(1.0, D, dt)


def pair_updates(x: np.ndarray, radius: float) -> int:
    """Pairs (i, j), i != j, within the cut-off: one exchange each per step."""
    inside = np.searchsorted(x, x + radius, side="right") - np.searchsorted(x, x - radius, side="left")
    return int((inside.sum() - x.size) // 2)


def timed(fn, repeats: int) -> tuple[float, np.ndarray]:
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[3000, 10000, 30000])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    print(f"{'N':>7} {'step':>5} {'pairs':>11} {'old ns/pair':>12} {'new ns/pair':>12} {'ratio':>6}  identical")
    for n in args.n:
        tot_pairs = tot_old = tot_new = 0.0
        for step in STEPS:
            x, m, label, sigma = state(n, step)
            radius = TRUNCATION * sigma
            seed = np.uint64(12345 + step)

            def old(x=x, m=m, label=label, sigma=sigma, radius=radius, seed=seed):
                return sequential_reference._sweep(x, m.copy(), label, sigma, radius, BETA, seed, False, True)

            def new(x=x, m=m, label=label, sigma=sigma, radius=radius, seed=seed):
                return sequential._sweep(x, m.copy(), label, sigma, radius, BETA, seed, False, True)

            old(), new()  # compile or load from numba's cache, untimed
            t_old = t_new = math.inf
            for _ in range(args.repeats):  # alternate, so drifts in the machine hit both alike
                a, ma = timed(old, 1)
                b, mb = timed(new, 1)
                t_old, t_new = min(t_old, a), min(t_new, b)
            pairs = pair_updates(x, radius)
            same = ma.tobytes() == mb.tobytes()
            tot_pairs, tot_old, tot_new = tot_pairs + pairs, tot_old + t_old, tot_new + t_new
            print(
                f"{n:>7} {step:>5} {pairs:>11,} {1e9 * t_old / pairs:>12.2f} {1e9 * t_new / pairs:>12.2f}"
                f" {t_old / t_new:>6.2f}  {same}"
            )
        print(
            f"{n:>7} {'all':>5} {int(tot_pairs):>11,} {1e9 * tot_old / tot_pairs:>12.2f}"
            f" {1e9 * tot_new / tot_pairs:>12.2f} {tot_old / tot_new:>6.2f}"
        )


if __name__ == "__main__":
    main()
