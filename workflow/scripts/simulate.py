"""Run one block of seeds of one case from Snakemake wildcards -> one tidy Parquet table.

The `snapshot` rule writes the final particle or grid states instead of the per-step tables.
"""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from particle_entropy.io import write_parquet  # noqa: E402
from particle_entropy.runconfig import RunConfig  # noqa: E402
from particle_entropy.simulate import run_seeds  # noqa: E402

w, par = snakemake.wildcards, snakemake.params  # noqa: F821
cfg = RunConfig(
    method=w.method,
    kernel=w.kernel,
    n=int(w.n),
    eta=float(w.eta),
    D=float(par.D),
    t_final=float(par.t_final),
    dt0=float(par.dt0),
    dt_growth=float(w.growth),
    truncation=None if w.trunc == "none" else float(w.trunc),
    omega=float(par.omega),
    fd_length=float(par.fd_length),
    transfer_method=par.transfer_method,
    transfer_tolerance=float(par.transfer_tolerance),
)
snapshot = snakemake.rule == "snapshot"  # noqa: F821
seeds = range(int(w.first), int(w.last) + 1)
table = run_seeds(cfg, seeds, progress=lambda msg: print(msg, file=sys.stderr), state=snapshot)
write_parquet(table, snakemake.output[0])  # noqa: F821
