"""The run's RO-Crate: results/ro-crate/ (pipeline/crate.py)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.pipeline.crate import build_crate

par = snakemake.params
summary = build_crate(
    ".",
    par.checkout,
    snakemake.config,
    par.coded,
    out=snakemake.output[0],
    progress=lambda line: print(line, file=sys.stderr),
)
print(
    f"crate: {summary['files']} files, {summary['jobs']} jobs, {summary['hashed']} files hashed -> {summary['path']}",
    file=sys.stderr,
)
