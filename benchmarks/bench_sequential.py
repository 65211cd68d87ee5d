"""The authors' loop, both its forms against the reference they replaced, side by side in one process.

    python benchmarks/bench_sequential.py                   # N = 3,000, 10,000, 30,000
    python benchmarks/bench_sequential.py --n 3000 --repeats 5 --forms fast

Reference: tests/sequential_reference.py, the loop as it was before issue 20. Forms: ``exact``
(sequential_kernels._sweep, bit for bit the reference's results, checked here on every timed
step) and ``fast`` (sequential_kernels._sweep_fma, the default, equal to it to round-off: the
largest difference is printed, relative to the total mass). States: N positions uniform on
[-Omega/2, Omega/2] stored in random order, a Gaussian plume of variance 2 D t as masses, the
collision kernel at eta = 1 cut at 3 widths, at steps 100, 140 and 174 of the authors' time grid
(dt0 = 0.01, growth run_settings.DT_GROWTH): the late steps hold most of a run's pair updates. A pair update is
one (i, j) exchange; the count is measured on the state, not modelled. Each timing is the least
of ``repeats`` alternating runs (ref, exact, fast, ref, ...), after one untimed run of each;
``/ref`` is a form's time over the reference's.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from particle_entropy.core.run_settings import DT_GROWTH
from particle_entropy.numerics import sequential_kernels
from particle_entropy.numerics.kernels import collision_sigma

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import sequential_reference  # noqa: E402  (the loop before issue 20, kept as the tests' reference)

D, OMEGA, TRUNCATION, BETA = 1e-3, 10.0, 3.0, 0.5
STEPS = (100, 140, 174)


def state(n: int, step: int, seed: int = 0):
    """(x sorted, m, storage labels, sigma) of a collision-kernel run before ``step``."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(-OMEGA / 2, OMEGA / 2, n))
    dt = 0.01 * DT_GROWTH**step
    t = 0.01 * (DT_GROWTH**step - 1.0) / (DT_GROWTH - 1.0)
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


FORMS = {  # name: (sweep, held to the reference bit for bit)
    "exact": ("_sweep", True),
    "fast": ("_sweep_fma", False),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[3000, 10000, 30000])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--forms", nargs="+", default=list(FORMS), choices=list(FORMS))
    args = ap.parse_args()
    head = " ".join(f"{f + ' ns':>9} {'/ref':>5}" for f in args.forms)
    print(f"{'N':>7} {'step':>5} {'pairs':>11} {'ref ns':>8} {head}  {'max |diff| / mass':>17}")
    for n in args.n:
        tot_pairs, tot = 0, dict.fromkeys(["ref", *args.forms], 0.0)
        for step in STEPS:
            x, m, label, sigma = state(n, step)
            radius = TRUNCATION * sigma
            seed = np.uint64(12345 + step)
            forms = {f: getattr(sequential_kernels, FORMS[f][0]) for f in args.forms}
            sweeps = {"ref": sequential_reference._sweep} | forms
            rest = (label, sigma, radius, BETA, seed, False, True)
            runs = {f: (lambda fn=fn, x=x, m=m, rest=rest: fn(x, m.copy(), *rest)) for f, fn in sweeps.items()}
            outs = {f: run() for f, run in runs.items()}  # compile or load from numba's cache, untimed
            best = dict.fromkeys(runs, math.inf)
            for _ in range(args.repeats):  # alternate, so drifts in the machine hit all alike
                for f, run in runs.items():
                    t, outs[f] = timed(run, 1)
                    best[f] = min(best[f], t)
            pairs = pair_updates(x, radius)
            for f in args.forms:
                same = outs[f].tobytes() == outs["ref"].tobytes()
                if FORMS[f][1] and not same:
                    raise SystemExit(f"{f} is not bit-identical to the reference at N = {n}, step {step}")
            diff = max(float(np.max(np.abs(outs[f] - outs["ref"]))) for f in args.forms) / m.sum()
            tot_pairs += pairs
            for f in best:
                tot[f] += best[f]
            cells = " ".join(f"{1e9 * best[f] / pairs:>9.2f} {best[f] / best['ref']:>5.2f}" for f in args.forms)
            print(f"{n:>7} {step:>5} {pairs:>11,} {1e9 * best['ref'] / pairs:>8.2f} {cells}  {diff:>17.1e}")
        cells = " ".join(f"{1e9 * tot[f] / tot_pairs:>9.2f} {tot[f] / tot['ref']:>5.2f}" for f in args.forms)
        print(f"{n:>7} {'all':>5} {tot_pairs:>11,} {1e9 * tot['ref'] / tot_pairs:>8.2f} {cells}")


if __name__ == "__main__":
    main()
