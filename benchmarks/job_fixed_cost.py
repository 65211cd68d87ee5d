"""Fixed cost of a simulate job per case: whole-process wall time minus the time in its steps.

    python benchmarks/job_fixed_cost.py [--n 30] [--seeds 1] [--repeats 7] [--other CHECKOUT]

Runs workflow/scripts/simulate.py as Snakemake runs it (a fresh ``python`` process) with a
stand-in ``snakemake`` object (wildcards, the paper config's settings, output, log), for one
case of each kind, and prints for each the least over ``--repeats`` of (process wall - sum of
the table's wall_s): the issue's "job wall minus in-step wall", less Snakemake's own preamble
(about 0.07 s, the same for any script). A checkout with numerics/compiled.py gets its kernels
built ahead of time first, as the workflow's first simulation job builds them; numba's cache is
filled by one untimed run of each case.
``--other`` times another checkout's script and library (e.g. ``git archive REV | tar -x -C
DIR``) alternately with this one, so both see the same load on the machine.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq
import yaml

HERE = Path(__file__).resolve().parents[1]
CASES = {  # label -> (method, kernel, config case keys beyond method and kernel)
    "pt bins": ("pt", "bins", {}),
    "pt fixed": ("pt", "fixed", {}),
    "pt adaptive": ("pt", "adaptive", {}),
    "mtpt collision": ("mtpt", "collision", {}),
    "mtpt sph": ("mtpt", "sph", {}),
    "mtpt authors": ("mtpt", "sph", {"preset": "authors"}),
    "fd implicit": ("fd", "implicit", {}),
}
RUNNER = """
import runpy, sys, types

class Wildcards(dict):
    __getattr__ = dict.__getitem__

w, settings, inputs, out, log, script = eval(sys.argv[1])
snakemake = types.SimpleNamespace(
    wildcards=Wildcards(w),
    params=types.SimpleNamespace(settings=settings),
    input=types.SimpleNamespace(**inputs),
    output=[out],
    log=[log],
)
runpy.run_path(script, init_globals={"snakemake": snakemake}, run_name="__main__")
"""


def job_inputs(label: str, n: int, seeds: int) -> tuple[dict, dict]:
    """(wildcards, settings) of the job of case ``label`` at ``n`` (this checkout's library)."""
    sys.path.insert(0, str(HERE / "workflow" / "lib"))
    from particle_entropy.core.case import Case
    from particle_entropy.pipeline.sweeps import run_settings

    config = yaml.safe_load((HERE / "config.yaml").read_text())
    method, kernel, extra = CASES[label]
    case = Case.from_spec({"method": method, "kernel": kernel, **extra}, n, config.get("case_defaults"))
    return {**case.wildcards(), "kind": "runs", "first": "0", "last": str(seeds - 1)}, run_settings(case, config)


def kernel_inputs(checkout: Path, tmp: Path) -> dict:
    """The job's ``kernels`` input, built by ``checkout``'s library (numerics/compiled.py) into
    ``tmp``, as the workflow's first job builds it; none for a checkout without it."""
    lib = checkout / "workflow" / "lib"
    if not (lib / "particle_entropy" / "numerics" / "compiled.py").exists():
        return {}
    folder = tmp / f"kernels-{abs(hash(str(checkout)))}"
    code = f"from particle_entropy.numerics.compiled import build; build({str(folder)!r})"
    subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(lib)}, check=True)
    return {"kernels": str(folder)}


def run_job(checkout: Path, w: dict, settings: dict, inputs: dict, out: Path, log: Path) -> float:
    """Run ``checkout``'s simulate script in a fresh process -> its wall time [s]."""
    script = checkout / "workflow" / "scripts" / "simulate.py"
    env = {**os.environ, "PYTHONPATH": str(checkout / "workflow" / "lib")}
    arg = repr((w, settings, inputs, str(out), str(log), str(script)))
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", RUNNER, arg], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise SystemExit(f"job failed under {checkout}:\n{res.stderr[-3000:]}\n{log.read_text()[-2000:]}")
    return wall


def fixed_cost(checkout: Path, w: dict, settings: dict, inputs: dict, tmp: Path) -> float:
    """Wall time of one job process minus the time its table records in steps [s]."""
    out = tmp / "job.parquet"
    wall = run_job(checkout, w, settings, inputs, out, tmp / "job.log")
    return wall - float(pq.read_table(out, columns=["wall_s"]).column("wall_s").to_numpy().sum())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=30, help="particles or FD intervals (default 30)")
    ap.add_argument("--seeds", type=int, default=1, help="seeds in the job's block (default 1)")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--other", type=Path, help="another checkout to time alongside")
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    args = ap.parse_args()
    checkouts = {"this": HERE}
    if args.other:
        checkouts["other"] = args.other.resolve()
    print(f"fixed cost of a job [s], least of {args.repeats}; N = {args.n}, {args.seeds} seed(s) a job")
    print(f"{'case':<16}" + "".join(f"{name:>10}" for name in checkouts) + ("   ratio" if args.other else ""))
    with tempfile.TemporaryDirectory() as tmp:
        inputs = {name: kernel_inputs(checkout, Path(tmp)) for name, checkout in checkouts.items()}
        for label in args.cases:
            w, settings = job_inputs(label, args.n, args.seeds)
            for name, checkout in checkouts.items():
                fixed_cost(checkout, w, settings, inputs[name], Path(tmp))  # numba's cache filled or loaded
            best = {name: float("inf") for name in checkouts}
            for _ in range(args.repeats):
                for name, checkout in checkouts.items():
                    best[name] = min(best[name], fixed_cost(checkout, w, settings, inputs[name], Path(tmp)))
            ratio = f"{best['this'] / best['other']:8.2f}" if args.other else ""
            print(f"{label:<16}" + "".join(f"{best[n]:>10.3f}" for n in checkouts) + ratio, flush=True)


if __name__ == "__main__":
    main()
