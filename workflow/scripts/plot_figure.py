"""Draw one paper figure from its tables."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import matplotlib  # noqa: E402

matplotlib.use("Agg")

import pandas as pd  # noqa: E402

from particle_entropy import plots  # noqa: E402

fig_name = snakemake.params.fig  # noqa: F821
tables = [pd.read_parquet(p) for p in snakemake.input]  # noqa: F821
D, t_final = float(snakemake.params.D), float(snakemake.params.t_final)  # noqa: F821
draw = {
    "fig1": lambda: plots.fig1(tables),
    "fig2": lambda: plots.fig2(tables),
    "fig3": lambda: plots.fig3(tables),
    "fig4": lambda: plots.fig4(tables),
    "fig5": lambda: plots.fig5(tables),
    "fig6": lambda: plots.fig6(tables, D=D),
    "fig7": lambda: plots.fig7(tables, D=D, t=t_final),
    "fig8": lambda: plots.fig8(tables),
    "fig9": lambda: plots.fig9(tables[0], time=t_final),
}[fig_name]
plots.save_figure(draw(), snakemake.output.png, snakemake.output.pdf)  # noqa: F821
print(f"drew {fig_name} from {len(tables)} tables", file=sys.stderr)
