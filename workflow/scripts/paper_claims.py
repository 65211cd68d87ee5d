"""Judge each quantitative claim of the paper against the reproduced tables; write them as Parquet,
Markdown and an HTML page for `snakemake --report` (which renders HTML tables, not Markdown)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from pathlib import Path

from particle_entropy.analysis import claims as C
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.pipeline.htmlpage import page

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par = snakemake.input, snakemake.params
tol, defaults = par.claims, par.case_defaults
rows = C.single_run_claims([read_parquet(p) for p in inp.runs], defaults)
rows += C.ensemble_claims([read_parquet(p) for p in inp.summaries], float(tol["adaptive_pt_hc_tolerance"]), defaults)
rows += C.comic_claims(read_parquet(inp.minima), read_parquet(inp.comic), tol, read_parquet(inp.realisations))
claims = C.claims_table(rows)
write_parquet(claims, snakemake.output.table)
Path(snakemake.output.md).write_text(C.to_markdown(claims))

# The report's copy: the Markdown table's columns, result cells classed for colour; no timestamp.
STYLE = (
    "th,td{border:1px solid #ccc;padding:3px 6px;text-align:left;vertical-align:top}"
    "td.pass{color:#05612d}td.fail{color:#b00020;font-weight:bold}"
)
table = C.display_table(claims).to_html(index=False, border=0, classes="claims")
for verdict in ("pass", "FAIL"):  # the result cells, and the other rules' cells by their first word
    table = table.replace(f"<td>{verdict}</td>", f'<td class="{verdict.lower()}">{verdict}</td>')
    table = table.replace(f"<td>{verdict}: ", f'<td class="{verdict.lower()}">{verdict}: ')
body = f"<p>{C.summary_line(claims)}</p>\n{table}\n"
Path(snakemake.output.html).write_text(page("Paper claims", body, STYLE, "Paper claims: reproduced values"))
print(claims.to_string(), file=sys.stderr)
