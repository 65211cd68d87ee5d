"""Run one block of seeds of one case from Snakemake wildcards -> one tidy Parquet table
(per-step tables, or final states when the output kind is `snapshots`); a reactive scene's runs
(settings with a reaction) are judged against the scene's reference (input `reference`)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.core.case import Case
from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.io import exit_on_table_errors, write_parquet
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models.simulate import run_seeds_arrow
from particle_entropy.numerics.compiled import take

exit_on_table_errors()  # a reference that fails its checks: one line naming it, exit 1
take()  # the kernels compiled ahead of time (the first job builds them): this job imports no numba
keep_freed_pages()  # steps reuse the pages of the last step's arrays
w = snakemake.wildcards
cfg = RunConfig.for_case(Case.from_wildcards(w), **snakemake.params.settings).resolved()
reference = None
if cfg.reaction is not None:
    from particle_entropy.core.reference_file import read

    reference = read(snakemake.input.reference)
seeds = range(int(w.first), int(w.last) + 1)
progress = lambda msg: print(msg, file=sys.stderr)  # noqa: E731
table = run_seeds_arrow(cfg, seeds, progress, state=w.kind == "snapshots", reference=reference)
write_parquet(table, snakemake.output[0])
