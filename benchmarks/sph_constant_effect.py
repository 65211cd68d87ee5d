"""Controlled experiment: the authors' SPH constant 0.822 against Eq. 26's 0.82, all else the
authors' algorithm (their loop, kernel cut at 3 widths, their time grid), the same seeds.

    python benchmarks/sph_constant_effect.py --seeds 20 --n 300 1000 3000

For each N: COMIC at the last step (t = 1021.1) per seed with each constant, the paired
difference (mean, standard error, 95 % bootstrap interval by scipy.stats.bootstrap), and the
difference of the COMIC of the ensemble-mean SSE (Fig. 9's statistic). One change, shared
seeds: a difference outside its interval is the constant's effect, not noise.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.core.runconfig import RunConfig  # noqa: E402
from particle_entropy.models.simulate import run  # noqa: E402


def last_step(n: int, scheme: str, seed: int) -> tuple[float, float, float]:
    """(COMIC, SSE, time) at the last step of one SPH run of the authors' algorithm with ``scheme``."""
    cfg = RunConfig.of(method="mtpt", kernel="sph", n=n, truncation=3.0, scheme=scheme, time_grid="authors", seed=seed)
    last = run(cfg)[0].iloc[-1]
    return float(last["COMIC"]), float(last["SSE"]), float(last["time"])


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=20, help="realisations per N (seeds 0 ... seeds - 1)")
    p.add_argument("--n", type=int, nargs="+", default=[300, 1000, 3000], help="particle numbers")
    a = p.parse_args(argv)
    print("N      t       seeds  mean dCOMIC   s.e.    95% bootstrap CI      dCOMIC(mean SSE)")
    for n in a.n:
        runs = {s: [last_step(n, s, seed) for seed in range(a.seeds)] for s in ("authors", "sequential")}
        d = np.array([x[0] - y[0] for x, y in zip(runs["authors"], runs["sequential"], strict=True)])
        ci = stats.bootstrap((d,), np.mean, n_resamples=2000, random_state=0).confidence_interval
        of_mean = {s: 2 * math.log(np.mean([r[1] for r in v]) / n) - math.log(10.0 / n) for s, v in runs.items()}
        se = d.std(ddof=1) / math.sqrt(d.size)
        print(
            f"{n:<6d} {runs['authors'][0][2]:<7.1f} {a.seeds:<6d} {d.mean():+.4f}      {se:.4f}"
            f"  [{ci.low:+.4f}, {ci.high:+.4f}]   {of_mean['authors'] - of_mean['sequential']:+.4f}"
        )


if __name__ == "__main__":
    main()
