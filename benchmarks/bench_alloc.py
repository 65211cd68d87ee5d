"""What fresh arrays cost a late step at N = 30,000: the same step with and without page faults.

    python benchmarks/bench_alloc.py [--n 30000] [--repeats 20]

glibc serves arrays above 128 kB (16,000 doubles) by mmap, so every fresh work array of a step
at N = 30,000 arrives as new pages, each a page fault, which virtual machines make dear. This
benchmark times one step of a late state in child processes that differ only in how freed
memory is kept: glibc's defaults; MALLOC_MMAP_THRESHOLD_ at 1 GiB, where freed arrays return
to the heap and the next step reuses their pages (what reusing work buffers would give, at
most); and a call of heap.keep_freed_pages(), what simulation jobs do. "saved" compares the
first and the last. Steps: MTPT with the equations (collision kernel, whole Gaussian: the fast
Gauss transform), the authors' loop (collision, cut at 3 widths) and the FD step (implicit, N
intervals) with its measurement. Each figure is the median of ``repeats`` steps after two
untimed ones.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

CHILD = r"""
import json, math, statistics, sys, time
import numpy as np
from particle_entropy.models import fd, mtpt
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.run_settings import DT_GROWTH
n, repeats = int(sys.argv[1]), int(sys.argv[2])
if sys.argv[3] == "keep":
    from particle_entropy.core.heap import keep_freed_pages
    assert keep_freed_pages()
out = {}
D, dt, t = 1e-3, 0.01 * DT_GROWTH**174, 1000.0
rng = np.random.default_rng(0)
x = np.sort(rng.uniform(-5, 5, n))
m0 = np.exp(-x * x / (4 * D * t)); m0 /= m0.sum()
label = rng.permutation(n)
for name, kw in {"mtpt equations": dict(scheme="symmetric"),
                 "authors' loop": dict(scheme="sequential", truncation=3.0)}.items():
    cfg = RunConfig.of(method="mtpt", kernel="collision", n=n, **kw).resolved()
    mtpt.warm_up(cfg)
    times = []
    for k in range(repeats + 2):
        m = m0.copy()
        t0 = time.perf_counter()
        mtpt.step(cfg, x, m, label, dt, t, np.random.default_rng(k))
        times.append(time.perf_counter() - t0)
    out[name] = statistics.median(times[2:])
cfg = RunConfig.of(method="fd", kernel="implicit", n=n).resolved()
xg, dx = fd.grid(cfg)
c = np.exp(-xg * xg / (4 * D * t)) / math.sqrt(4 * math.pi * D * t)
solver = fd.ImplicitSolver(n - 1, D * 0.05 / dx**2)
times = []
for k in range(repeats + 2):
    t0 = time.perf_counter()
    c[1:-1] = solver.solve(c[1:-1])
    fd.measure(cfg, xg, c, dx, t)
    times.append(time.perf_counter() - t0)
out["fd step + measure"] = statistics.median(times[2:])
print(json.dumps(out))
"""


def child(n: int, repeats: int, env: dict, mode: str = "default") -> dict:
    res = subprocess.run(
        [sys.executable, "-c", CHILD, str(n), str(repeats), mode], env=env, capture_output=True, text=True
    )
    if res.returncode != 0:
        raise SystemExit(res.stderr[-2000:])
    return json.loads(res.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=30000)
    ap.add_argument("--repeats", type=int, default=20)
    a = ap.parse_args()
    fresh = dict(os.environ)
    fresh.pop("MALLOC_MMAP_THRESHOLD_", None)
    reuse = {**fresh, "MALLOC_MMAP_THRESHOLD_": str(2**30), "MALLOC_TRIM_THRESHOLD_": str(2**31)}
    runs = {"fresh": [], "reuse": [], "keep": []}
    for _ in range(3):  # alternate, so drifts in the machine hit all alike
        runs["fresh"].append(child(a.n, a.repeats, fresh))
        runs["reuse"].append(child(a.n, a.repeats, reuse))
        runs["keep"].append(child(a.n, a.repeats, fresh, "keep"))
    print(f"N = {a.n:,}: ms per step, best of 3 processes (median of {a.repeats} steps each)")
    print(f"{'step':<20} {'fresh pages':>12} {'pages reused':>13} {'keep_freed_pages':>17} {'saved':>7}")
    for name in runs["fresh"][0]:
        f, u, k = (min(r[name] for r in runs[v]) * 1e3 for v in ("fresh", "reuse", "keep"))
        print(f"{name:<20} {f:>12.2f} {u:>13.2f} {k:>17.2f} {100 * (f - k) / f:>6.1f}%")


if __name__ == "__main__":
    main()
