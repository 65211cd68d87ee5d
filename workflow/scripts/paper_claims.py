"""Judge each quantitative claim of the paper against the reproduced tables."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from pathlib import Path  # noqa: E402

import pandas as pd  # noqa: E402

from particle_entropy import claims as C  # noqa: E402
from particle_entropy.io import write_parquet  # noqa: E402

inp, par = snakemake.input, snakemake.params  # noqa: F821
tol, defaults = par.claims, par.case_defaults
rows = C.single_run_claims([pd.read_parquet(p) for p in inp.runs], defaults)
rows += C.ensemble_claims([pd.read_parquet(p) for p in inp.summaries], float(tol["adaptive_pt_hc_tolerance"]), defaults)
rows += C.comic_claims(pd.read_parquet(inp.minima), pd.read_parquet(inp.comic), tol)
claims = C.claims_table(rows)
write_parquet(claims, snakemake.output.table)  # noqa: F821
Path(snakemake.output.md).write_text(C.to_markdown(claims))  # noqa: F821
print(claims.to_string(), file=sys.stderr)
