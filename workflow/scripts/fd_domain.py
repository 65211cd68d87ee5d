"""Fig. 8's late error: implicit FD on the paper's domain and on longer ones at the same dx."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.core.io import write_parquet
from particle_entropy.experiments.fd_domain import comic_optimum, domain_experiment

par = snakemake.params
table = domain_experiment(
    n_list=par.n, fd_lengths=par.lengths, fd_dts=(par.fd_dt,), times=par.times, D=par.D, ref_length=par.ref_length
)
write_parquet(table, snakemake.output[0])
print(comic_optimum(table).to_string(), file=sys.stderr)
