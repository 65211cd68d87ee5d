"""Draw figures/fig9_mechanism.png from the mechanism COMIC tables and the FD domain experiment."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

import pandas as pd

from particle_entropy.core.case import Case
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.figures.fig9_mechanism import fig9_mechanism
from particle_entropy.figures.style import save_figure

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par, out = snakemake.input, snakemake.params, snakemake.output
cases = [Case.from_wildcards(c) for c in par.cases]
figure, data = fig9_mechanism(
    read_parquet(inp.comic),
    read_parquet(inp.realisations),
    read_parquet(inp.fd) if inp.fd else pd.DataFrame(),
    cases,
    D=float(par.D),
    t_final=float(par.t_final),
    omega=float(par.omega),
    floors=read_parquet(inp.floors) if inp.floors else None,
)
save_figure(figure, out.png, out.pdf)
write_parquet(data, out.data)
print(f"drew fig9_mechanism: {len(cases)} cases, {len(data)} plotted points", file=sys.stderr)
