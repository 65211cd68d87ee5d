"""The run's RO-Crate: results/ro-crate/ (pipeline/crate.py)."""

import sys
from pathlib import Path

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.pipeline.crate import CrateError, build_crate

par = snakemake.params
try:
    summary = build_crate(
        ".",
        par.checkout,
        snakemake.config,
        par.coded,
        out=Path(snakemake.output[0]).parent,
        progress=lambda line: print(line, file=sys.stderr),
        targets=list(snakemake.input),  # the jobs these needed: this config's run
        optional=par.optional,  # its scenes and searches, where a run of this config made them
    )
except CrateError as e:
    print(f"crate: {e}", file=sys.stderr)
    sys.exit(1)
print(
    f"crate: {summary['files']} files, {summary['jobs']} jobs, {summary['hashed']} files hashed "
    f"({summary['tables']} tables hashed) -> {summary['path']}",
    file=sys.stderr,
)
