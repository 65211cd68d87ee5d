"""Draw Fig. 10 (Appendix B shear flow) from the final particle tables of the three cases; write
the figure and the data it plots (source data)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.figures import fig10

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

out = snakemake.output
states = [read_parquet(p) for p in snakemake.input]
figure, data = fig10.fig10(states)
fig10.save_figure(figure, out.png, out.pdf)
write_parquet(data, out.data)
print(f"drew fig10 from {len(states)} state tables, {len(data)} plotted points", file=sys.stderr)
