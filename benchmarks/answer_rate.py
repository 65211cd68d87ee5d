"""Measure: how often a scene search's answer is above the target in expectation (issue 50, point 7).

    python benchmarks/answer_rate.py --ladders 1200 --workers 2
    python benchmarks/answer_rate.py --ladders 400 --ensemble 2 --rule 0 --rule 1

The real search (analysis/scene_search.py) replayed on noisy ladders whose true mean error is known
(analysis/answer_rate.py): a PT candidate on the ratio-2 ladder 30 .. 7680 (9 rungs), true mean
error (n / 30)^-1/2 crossing the target within the ladder, per-run noise with coefficient of
variation uniform on [0.3, 1.0] (the issue's decay: about 0.7), realisations 8, max_realisations 32.
Each ensemble is run under three rules for a rung's one-sided bound: the old 95 % per rung, the
shipped Bonferroni correction over the ladder (1 - 0.05 / rungs: scene_search.answer_confidence) and
one over rungs and seed blocks (1 - 0.05 / (rungs blocks)). Prints, per ensemble and rule, the rate
of false answers with its Clopper-Pearson 95 % interval, the searches that met nothing, the mean runs
and particle-runs (sum of n, the cost) a search, and the answers' mean rungs above the ideal one.
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from unittest import mock

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.analysis import answer_rate as A  # noqa: E402
from particle_entropy.analysis import scene_search as S  # noqa: E402
from particle_entropy.analysis.resampling import CONFIDENCE  # noqa: E402

LADDER = [30 * 2**k for k in range(9)]
REALISATIONS, MOST = 8, 32
RULES = {
    "95 % per rung (old)": lambda c: CONFIDENCE,
    "1 - 0.05 / rungs (shipped)": S.answer_confidence,
    "1 - 0.05 / (rungs blocks)": lambda c: 1.0 - (1.0 - CONFIDENCE) / (len(c.ladder()) * MOST // REALISATIONS),
}
ENSEMBLES = {  # name: (noise, width, seed)
    "lognormal, crossing anywhere": ("lognormal", 1.0, 50),
    "normal, crossing anywhere": ("normal", 1.0, 51),
    "lognormal, rung below <= 3.5 % above the target": ("lognormal", 0.1, 52),
}


def _chunk(job) -> list[dict]:
    rule, ladders = job
    scene = A.ladder_scene(LADDER, REALISATIONS, MOST)
    with mock.patch.object(S, "answer_confidence", RULES[rule]):
        return [A.outcome(scene, lad) for lad in ladders]


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ladders", type=int, default=2000, help="noisy ladders an ensemble")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--ensemble", type=int, action="append", help="only these ENSEMBLES (index; repeatable)")
    p.add_argument("--rule", type=int, action="append", help="only these RULES (index; repeatable)")
    args = p.parse_args(argv)
    ensembles = [e for i, e in enumerate(ENSEMBLES) if args.ensemble is None or i in args.ensemble]
    rules = [r for i, r in enumerate(RULES) if args.rule is None or i in args.rule]
    print(f"ladder {LADDER}, realisations {REALISATIONS}, max_realisations {MOST}, {args.ladders} ladders each")
    with ProcessPoolExecutor(args.workers) as pool:
        for name in ensembles:
            noise, width, seed = ENSEMBLES[name]
            ladders = A.noisy_ladders(LADDER, args.ladders, seed, MOST, noise=noise, width=width)
            chunks = [ladders[i : i + 50] for i in range(0, len(ladders), 50)]
            print(f"\n{name}")
            for rule in rules:
                start = time.perf_counter()
                outcomes = [o for part in pool.map(_chunk, [(rule, c) for c in chunks]) for o in part]
                s = A.summary(outcomes)
                print(
                    f"  {rule:28s} false {s['false']:4d}/{s['ladders']} = {100 * s['rate']:.2f} % "
                    f"[{100 * s['lo']:.2f}, {100 * s['hi']:.2f}]  not met {s['not_met']}  "
                    f"runs {s['runs']:.1f}  particle-runs {s['particle_runs']:,.0f}  "
                    f"rungs above ideal {s['above_ideal']:.2f}  ({time.perf_counter() - start:.0f} s)",
                    flush=True,
                )


if __name__ == "__main__":
    main()
