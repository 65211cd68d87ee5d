"""How long `snakemake -j2 scenes` takes, and what each scene answers (docs/scenes.md's table of answers).

    python benchmarks/scenes_time.py WORKDIR        # runs the scenes in WORKDIR (a finished paper run or empty)

Runs `snakemake -j2 scenes` with this checkout's Snakefile in WORKDIR (config.yaml of this
checkout unless WORKDIR has its own), times it, and prints per scene its Peclet number, the
recommendation with its interval of resolutions and counted cost, the COMIC-best, and the
simulation jobs it ran with their summed seconds (Snakemake's benchmark files).
"""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.analysis.scene_search import crossover, peclet_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main(workdir: Path) -> None:
    workdir.mkdir(parents=True, exist_ok=True)
    if not (workdir / "config.yaml").exists():
        shutil.copy(ROOT / "config.yaml", workdir / "config.yaml")
    cmd = [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "-d", str(workdir), "-j2", "scenes"]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(proc.stderr[-3000:])
    bench = list((workdir / "results/benchmarks/simulate_scene").rglob("*.tsv"))
    seconds = sum(float(next(csv.DictReader(p.open(), delimiter="\t"))["s"]) for p in bench)
    print(f"snakemake -j2 scenes: {wall:.1f} s wall; {len(bench)} simulation jobs on record, {seconds:.1f} job-s")
    for table in sorted((workdir / "results/scenes").glob("*.parquet")):
        t = pd.read_parquet(table)
        best, comic = t[t["recommended"]], t[t["comic_best"]]
        head = f"{table.stem}: Peclet {t['peclet'].iloc[0]:,.0f}, {t['measure'].iloc[0]} <= {t['target'].iloc[0]:g}"
        if len(best):
            r = best.iloc[0]
            answer = f"{r['label']}, n in ({r['n_below']:g}, {r['n']}], {r['cost_s']:.3g} s a run"
        else:
            answer = "none meets it"
        c = comic.iloc[0] if len(comic) else None
        tail = f"; COMIC-best {c['label']}, n = {c['n']}" if c is not None else ""
        print(f"  {head}: {answer}{tail}")
    sweep = workdir / "results/scenes_peclet.parquet"  # the sweep's table (scene_search.peclet_table)
    if sweep.exists():
        t = pd.read_parquet(sweep)
        print(t.to_string())
        cross = crossover(t)
        print(f"  Peclet sweep: particles overtake the grid at Pe in {cross}" if cross else "  no crossover")
        # the same sweep without the tvd candidates: each candidate's search is its own, so this is
        # the crossover a sweep of upwind and central alone gives
        tables = [pd.read_parquet(p) for p in sorted((workdir / "results/scenes").glob("peclet-*.parquet"))]
        plain = peclet_table([x[~x["label"].str.contains(" tvd ")] for x in tables])
        print(plain.to_string())
        cross = crossover(plain)
        print(
            f"  without tvd: particles overtake the grid at Pe in {cross}" if cross else "  without tvd: no crossover"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("scenes_run"))
