"""COMIC statistics per model, N and time, the per-realisation values behind them, a bootstrap of
where the COMIC minimum lies, and the N that minimises mean COMIC with its interval. Where the rule
asks for them, HTML copies of the COMIC table and the minima for `snakemake --report`."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import html
from pathlib import Path

import pandas as pd

from particle_entropy.analysis.aggregate import (
    MINIMA_COLUMN_DOCS,
    comic_argmin,
    comic_minima,
    comic_table,
    read_realisations,
)
from particle_entropy.core.case import MODEL_COLUMNS
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.pipeline.htmlpage import page

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, out = snakemake.input, snakemake.output
times = [float(t) for t in snakemake.params.times]
comic = comic_table([read_parquet(p) for p in inp.summaries], times)
realisations = read_realisations(list(inp.runs), times)
argmin = comic_argmin(realisations)
minima = comic_minima(comic, argmin)
for table, path in ((comic, out.comic), (realisations, out.realisations), (argmin, out.argmin), (minima, out.minima)):
    write_parquet(table, path)
print(minima.to_string(), file=sys.stderr)

STYLE = (
    "th,td{border:1px solid #ccc;padding:3px 6px;text-align:right}td:first-child{text-align:left}dt{font-weight:bold}"
)


def write_html(table: pd.DataFrame, path: str, title: str, notes: str = "") -> None:
    """A report copy of a table: the label names the model, so its dimension columns are left out."""
    shown = table.drop(columns=list(MODEL_COLUMNS))
    body = shown.to_html(index=False, border=0, float_format=lambda v: f"{v:.4g}", na_rep="")
    Path(path).write_text(page(title, f"{body}\n{notes}", STYLE))


if "comic_html" in out.keys():
    write_html(comic, out.comic_html, "COMIC per model, N and time")
if "minima_html" in out.keys():
    shown = [c for c in MINIMA_COLUMN_DOCS if c not in MODEL_COLUMNS]
    notes = "<dl>" + "".join(f"<dt>{c}</dt><dd>{html.escape(MINIMA_COLUMN_DOCS[c])}</dd>" for c in shown) + "</dl>\n"
    write_html(minima, out.minima_html, "N minimising mean COMIC", notes)
