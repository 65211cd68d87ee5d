"""Draw one figure from its tables; write the figure and the data it plots (source data)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

from particle_entropy.core.case import Case
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.figures import figure_function
from particle_entropy.figures.style import save_figure

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

par, out = snakemake.params, snakemake.output
tables = [read_parquet(p) for p in snakemake.input]
cases = [Case.from_wildcards(c) for c in par.cases]
draw = figure_function(par.fig)
figure, data = draw(tables, cases, D=float(par.D), t_final=float(par.t_final), **par.options)
save_figure(figure, out.png, out.pdf)
write_parquet(data, out.data)
print(f"drew {par.fig}: {len(cases)} cases from {len(tables)} tables, {len(data)} plotted points", file=sys.stderr)
