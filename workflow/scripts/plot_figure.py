"""Draw one figure from its tables; write the figure and the data it plots (source data)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import matplotlib  # noqa: E402

matplotlib.use("Agg")

import pandas as pd  # noqa: E402

from particle_entropy.core.case import Case  # noqa: E402
from particle_entropy.core.io import write_parquet  # noqa: E402
from particle_entropy.figures import plots  # noqa: E402

par, out = snakemake.params, snakemake.output  # noqa: F821
tables = [pd.read_parquet(p) for p in snakemake.input]  # noqa: F821
cases = [Case.from_wildcards(c) for c in par.cases]
figure, data = plots.FIGURES[par.fig](tables, cases, D=float(par.D), t_final=float(par.t_final))
plots.save_figure(figure, out.png, out.pdf)
write_parquet(data, out.data)
print(f"drew {par.fig}: {len(cases)} cases from {len(tables)} tables, {len(data)} plotted points", file=sys.stderr)
