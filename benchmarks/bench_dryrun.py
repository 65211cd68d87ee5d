"""Wall time of `snakemake -n` on the paper's config (config.yaml): a fresh clone, a built directory
and Snakemake's own floor, for this checkout and optionally another one.

    python benchmarks/bench_dryrun.py [--other PATH] [--workdir DIR] [--repeats 3]

- fresh clone: `git clone` of the checkout (its uncommitted edits copied over) into a new folder,
  then `snakemake -n` there: no results/, no .snakemake/, no __pycache__ of the library. A new
  clone for every repeat; the clone itself is not timed.
- built: `snakemake -s CHECKOUT/Snakefile -d DIR -n --configfile CHECKOUT/config.yaml` in a folder
  holding a finished paper run (``--workdir``, default /tmp/paper/main when it exists): every
  output exists, so Snakemake also reads each one's metadata. Runs written by other code are
  planned again (their code hashes differ); the planned job count is printed.
- floor: `snakemake -n` on a Snakefile of one rule that imports nothing: Snakemake importing
  itself and its plugins, parsing, and a one-job DAG. No workflow parses faster.
- tables: what a real run's parse adds in the built folder (a dry run only looks): the library's
  `corrupt_tables` over DIR/results, in process, reading every table, then with a warm digests
  file (kept in a temporary folder: the built folder is not written). Page cache warm.

``--other`` points to another checkout (e.g. a clone of the previous commit), timed alternately
with this one. Prints medians of ``--repeats`` runs, in seconds, using this Python's Snakemake.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
BUILT = Path("/tmp/paper/main")
FLOOR_SNAKEFILE = 'rule all:\n    output:\n        "a.txt",\n    shell:\n        "touch {output}"\n'


def dry_run(snakefile: Path, workdir: Path, configfile: Path | None = None) -> tuple[float, int]:
    """Wall seconds of `snakemake -n` and the number of jobs it plans."""
    cmd = [sys.executable, "-m", "snakemake", "-s", str(snakefile), "-d", str(workdir), "-n"]
    cmd += ["--configfile", str(configfile)] if configfile else []
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise SystemExit(f"dry run failed ({snakefile}, {workdir}):\n{res.stderr[-2000:]}")
    totals = [line.split()[-1] for line in (res.stdout + res.stderr).splitlines() if line.startswith("total ")]
    return wall, int(totals[-1]) if totals else 0


def fresh_clone(checkout: Path, dest: Path) -> Path:
    """``git clone`` of ``checkout``, its uncommitted edits (changed, new and deleted files) applied."""
    subprocess.run(["git", "clone", "-q", str(checkout), str(dest)], check=True)
    listed = subprocess.run(
        ["git", "-C", str(checkout), "ls-files", "-z", "--modified", "--others", "--exclude-standard"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    for rel in filter(None, listed.split("\0")):
        src, out = checkout / rel, dest / rel
        if src.is_file():
            out.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, out)
        else:  # deleted in the checkout
            out.unlink(missing_ok=True)
    return dest


def table_check(checkout: Path, results: Path, repeats: int) -> tuple[float, float, int, float]:
    """Medians of corrupt_tables over ``results``: every table read, then a warm digests file;
    the table count and their size in MB."""
    sys.path.insert(0, str(checkout / "workflow" / "lib"))
    from particle_entropy.pipeline.verify import corrupt_tables

    tables = list(results.rglob("*.parquet"))
    size = sum(p.stat().st_size for p in tables if p.is_file()) / 1e6
    every, warm = [], []
    with tempfile.TemporaryDirectory() as tmp:
        digests = Path(tmp) / "table_digests.json"
        corrupt_tables(results, digests)  # page cache and digests filled, untimed
        for _ in range(repeats):
            t0 = time.perf_counter()
            corrupt_tables(results)
            every.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            corrupt_tables(results, digests)
            warm.append(time.perf_counter() - t0)
    return statistics.median(every), statistics.median(warm), len(tables), size


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--other", type=Path, help="another checkout to time alongside")
    ap.add_argument("--workdir", type=Path, default=BUILT if BUILT.is_dir() else None, help="a built paper run")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    checkouts = {"this": HERE}
    if args.other:
        checkouts["other"] = args.other.resolve()
    built = args.workdir.resolve() if args.workdir else None
    walls = {(line, name): [] for line in ("fresh clone", "built", "floor") for name in checkouts}
    jobs = {}
    with tempfile.TemporaryDirectory() as tmp:
        floor = Path(tmp) / "floor"
        floor.mkdir()
        (floor / "Snakefile").write_text(FLOOR_SNAKEFILE)
        dry_run(floor / "Snakefile", floor)  # Snakemake's files in the page cache, untimed
        for k in range(args.repeats):
            for name, checkout in checkouts.items():
                clone = fresh_clone(checkout, Path(tmp) / f"{name}{k}")
                walls["fresh clone", name].append(dry_run(clone / "Snakefile", clone)[0])
                shutil.rmtree(clone)
                if built:
                    wall, jobs[name] = dry_run(checkout / "Snakefile", built, checkout / "config.yaml")
                    walls["built", name].append(wall)
                walls["floor", name].append(dry_run(floor / "Snakefile", floor)[0])
                shutil.rmtree(floor / ".snakemake", ignore_errors=True)
    cores = len(os.sched_getaffinity(0))
    print(f"snakemake -n, paper config, median of {args.repeats}, {cores} cores, load {os.getloadavg()[0]:.1f}")
    print(f"{'line':<14}" + "".join(f" {name + ' s':>10}" for name in checkouts))
    for line in ("fresh clone", "built", "floor"):
        if walls[line, "this"]:
            print(f"{line:<14}" + "".join(f" {statistics.median(walls[line, n]):>10.2f}" for n in checkouts))
    if built:
        print(f"built: {built}, jobs planned " + ", ".join(f"{n} {jobs[n]}" for n in checkouts))
        every, warm, count, size = table_check(HERE, built / "results", args.repeats)
        print(f"tables ({count}, {size:.0f} MB), this library: every one read {every:.3f} s, warm digests {warm:.3f} s")
    else:
        print("built: no --workdir given and /tmp/paper/main does not exist; run the paper once and pass its folder")


if __name__ == "__main__":
    main()
