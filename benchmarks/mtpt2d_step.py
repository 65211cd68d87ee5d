"""One 2-D MTPT step, the walk and the exchange, at N = 10,000, 30,000 and 100,000 (issue 52 point 7).

    python benchmarks/mtpt2d_step.py [--n 10000 30000 100000] [--eta 0.5] [--cutoff-sds 6 9]
        [--repeats 5]

The scene (written out here so the benchmark stays put): the paper's problem in 2-D, a plume at
rest spreading to t = 1000 by D = R(30 deg) diag(1e-3, 2.5e-4) R^T [L^2/T] (longitudinal to
transverse 4:1, axes turned 30 degrees from x), dt = 1 [T] (1000 steps), N particles uniform on
the square [-5, 5]^2 (area 100, the paper's Omega = 10 in each direction: +- 3.5 of the final
plume's s.d. along its long axis), v = (1e-3, 5e-4) [L/T], eta 0.5 by default (a half of D by
the walk, a half by the exchange). The masses are a Gaussian of covariance 2 D t at t = 500.

A step: models/walk.walk with (1 - eta) D as one (1, 2, 2) tensor and v, then
numerics/particles2d.mtpt_exchange_2d with eta D; each N runs in its own process (so that its
peak RSS, ru_maxrss, is its own) after one warm-up step that loads numba's compiled loops.
Printed per N and cut-off: the median of --repeats steps, the walk's and the exchange's medians,
the exchange's stages (whitening, the k-d tree's pairs, the weights, Eqs. 16-18) from one more
step timed stage by stage with the same library calls, mean neighbour count, pairs, substeps,
peak RSS and the kernel's mass beyond the cut-off, exp(-k^2/2) (mtpt_exchange_2d's docstring); the
CPU (/proc/cpuinfo's model name) and whether 0.5 s at N = 100,000 is met. The default cut-offs are
the exchange's default (particles2d.EXCHANGE_CUTOFF_SIGMAS, 6) and the untruncated 9.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow" / "lib"))
from machine import cpu  # noqa: E402

from particle_entropy.models.walk import walk  # noqa: E402
from particle_entropy.numerics import pair_transfer as pt  # noqa: E402
from particle_entropy.numerics.bandwidths import CUTOFF_SIGMAS  # noqa: E402
from particle_entropy.numerics.neighbours import pairs_within  # noqa: E402
from particle_entropy.numerics.particles2d import (  # noqa: E402
    COLLISION_BETA,
    EXCHANGE_CUTOFF_SIGMAS,
    exchange_cutoff,
    mtpt_exchange_2d,
    whiten,
)

TARGET_SECONDS = 0.5  # issue 52 point 7, at N = 100,000
SIDE = 10.0  # [L]
DT = 1.0  # [T]
T_MASSES = 500.0  # the time whose plume the masses hold [T]
V = np.array([1.0e-3, 5.0e-4])  # [L/T]


def tensor() -> np.ndarray:
    a = math.radians(30.0)
    R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return R @ np.diag([1.0e-3, 2.5e-4]) @ R.T


def state(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    x = rng.uniform(-SIDE / 2, SIDE / 2, (n, 2))
    cov = 2.0 * tensor() * T_MASSES
    q = np.einsum("ni,ij,nj->n", x, np.linalg.inv(cov), x)
    m = np.exp(-0.5 * q)
    return x, m / m.sum(), rng


def step(x, m, rng, eta: float, cutoff_sds: float):
    D = tensor()
    t0 = time.perf_counter()
    x = walk(x, ((1.0 - eta) * D)[None], DT, rng, V)
    t1 = time.perf_counter()
    res = mtpt_exchange_2d(x, m, D, eta, DT, cutoff_sds)
    t2 = time.perf_counter()
    return x, res, t1 - t0, t2 - t1


def stages(x, m, eta: float, cutoff_sds: float) -> dict:
    """The exchange's stages, timed one by one with the calls mtpt_exchange_2d makes."""
    n = x.shape[0]
    out = {}
    t = time.perf_counter()
    s = whiten(x, eta * tensor())
    out["whiten"] = time.perf_counter() - t
    t = time.perf_counter()
    pairs = pairs_within(s, exchange_cutoff(DT, cutoff_sds))
    out["pairs"] = time.perf_counter() - t
    t = time.perf_counter()
    w = pt.pair_weights(s, np.ones((n, 2)), pairs, DT)
    out["weights"] = time.perf_counter() - t
    t = time.perf_counter()
    pt.transfer(pairs, w, np.ones(n), m, COLLISION_BETA)
    out["transfer"] = time.perf_counter() - t
    return out


def one(n: int, eta: float, cutoff_sds: float, repeats: int) -> dict:
    x, m, rng = state(n)
    step(x[:200], m[:200], np.random.default_rng(1), eta, cutoff_sds)  # warm-up: numba's loops
    totals, walks, exchanges = [], [], []
    for _ in range(repeats):
        x, res, tw, te = step(x, m, rng, eta, cutoff_sds)
        m = res.mass
        totals.append(tw + te)
        walks.append(tw)
        exchanges.append(te)
    st = stages(x, m, eta, cutoff_sds)
    return {
        "n": n,
        "cutoff_sds": cutoff_sds,
        "step_s": float(np.median(totals)),
        "walk_s": float(np.median(walks)),
        "exchange_s": float(np.median(exchanges)),
        "stages": st,
        "neighbours": res.mean_neighbours,
        "pairs": res.mean_neighbours * n / 2.0,
        "substeps": res.substeps,
        "mass_error": abs(float(m.sum()) - 1.0),
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[10_000, 30_000, 100_000])
    ap.add_argument("--eta", type=float, default=0.5)
    ap.add_argument("--cutoff-sds", type=float, nargs="+", default=[EXCHANGE_CUTOFF_SIGMAS, CUTOFF_SIGMAS])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)  # a child: one N, one cut-off
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(a.n[0], a.eta, a.cutoff_sds[0], a.repeats)))
        return
    print(f"CPU: {cpu()}; eta {a.eta}, dt {DT}, D = R(30) diag(1e-3, 2.5e-4) R^T, square side {SIDE}")
    head = "N        cut  step s  walk s  exch s  whiten  pairs  weights  transfer  neighbours  substeps  RSS MB"
    head += "  dropped"
    print(head)
    rows = []
    for cut in a.cutoff_sds:
        for n in a.n:
            cmd = [sys.executable, __file__, "--one", "--n", str(n), "--eta", str(a.eta)]
            cmd += ["--cutoff-sds", str(cut), "--repeats", str(a.repeats)]
            r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
            rows.append(r)
            s = r["stages"]
            print(
                f"{n:<8d} {cut:3.0f}  {r['step_s']:6.3f}  {r['walk_s']:6.3f}  {r['exchange_s']:6.3f}  "
                f"{s['whiten']:6.3f}  {s['pairs']:5.3f}  {s['weights']:7.3f}  {s['transfer']:8.3f}  "
                f"{r['neighbours']:10.1f}  {r['substeps']:8d}  {r['peak_rss_mb']:6.0f}  "
                f"{math.exp(-0.5 * cut * cut):7.1e}"
            )
    for r in rows:
        if r["n"] == 100_000:
            verdict = "met" if r["step_s"] <= TARGET_SECONDS else f"missed by x{r['step_s'] / TARGET_SECONDS:.1f}"
            print(f"N = 100,000 at {r['cutoff_sds']:g} s.d.: {r['step_s']:.3f} s, target {TARGET_SECONDS} s {verdict}")


if __name__ == "__main__":
    main()
