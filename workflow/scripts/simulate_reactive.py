"""Run one block of seeds of one candidate of a reactive scene -> one tidy Parquet table, judged
against the scene's reference (models/reactive_run.py)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.core.case import Case
from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.io import exit_on_table_errors, write_parquet
from particle_entropy.core.reactions import Reaction
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.experiments.reactive import read
from particle_entropy.models.reactive_run import run_seeds_arrow
from particle_entropy.numerics.compiled import take

exit_on_table_errors()  # a reference that fails its checks: one line naming it, exit 1
take()  # the kernels compiled ahead of time (the first job builds them): this job imports no numba
keep_freed_pages()
w = snakemake.wildcards
settings = dict(snakemake.params.settings)
reaction = Reaction.of(settings.pop("reaction"))
cfg = RunConfig.for_case(Case.from_wildcards(w), **settings).resolved()
seeds = range(int(w.first), int(w.last) + 1)
table = run_seeds_arrow(cfg, reaction, read(snakemake.input.reference), seeds, lambda msg: print(msg, file=sys.stderr))
write_parquet(table, snakemake.output[0])
