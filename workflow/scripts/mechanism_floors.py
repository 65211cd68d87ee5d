"""Noise-free SSE floors: each mechanism model run on evenly spaced particles."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import pandas as pd

from particle_entropy.core.case import Case
from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.io import write_parquet
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.experiments.lattice import lattice_run

keep_freed_pages()  # steps reuse the pages of the last step's arrays

par = snakemake.params
rows = []
for run in par.runs:
    case = Case.from_wildcards(run["case"])
    rows += lattice_run(RunConfig.for_case(case, **run["settings"]), [float(t) for t in par.times])
    print(f"{case.path()}: SSE/N {rows[-1]['SSE_over_N']:.4g} at t = {rows[-1]['time_step']:g}", file=sys.stderr)
write_parquet(pd.DataFrame(rows), snakemake.output[0])
