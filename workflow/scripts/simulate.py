"""Run one block of seeds of one case from Snakemake wildcards -> one tidy Parquet table
(per-step tables, or final states when the output kind is `snapshots`)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.core.case import Case
from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.io import write_parquet
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models.simulate import run_seeds_arrow
from particle_entropy.numerics.compiled import take

take()  # the kernels compiled ahead of time (the first job builds them): this job imports no numba
keep_freed_pages()  # steps reuse the pages of the last step's arrays
w = snakemake.wildcards
cfg = RunConfig.for_case(Case.from_wildcards(w), **snakemake.params.settings).resolved()
seeds = range(int(w.first), int(w.last) + 1)
table = run_seeds_arrow(cfg, seeds, progress=lambda msg: print(msg, file=sys.stderr), state=w.kind == "snapshots")
write_parquet(table, snakemake.output[0])
