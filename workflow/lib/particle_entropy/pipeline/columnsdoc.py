"""The page docs/columns.md, rendered from the column dicts of the code that writes each table.

One section per derived table: its path, what a row holds and the rule that writes it, then a row
per column from the dicts listed in ``sections()`` (``columns.RECORD_COLUMN_DOCS``,
``aggregate.SUMMARY_COLUMNS``, ...). A description's unit is its trailing ``[...]``; a run of the
case (or model) columns is one row that links to their own section. The meanings of the columns
simulation jobs write live where no such job imports them (core/columns.py, and here for the
shear flow's), so editing one reruns no simulation. The few tables whose module keeps no column
dict take their meanings from the dicts of this module too. ``python -m
particle_entropy.pipeline.columnsdoc --write docs/columns.md`` writes the page; ``--check``
exits 1 while the page differs from the dicts.
"""

from __future__ import annotations

import argparse
import re
import sys
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..analysis import claims, optimum, scene_search
from ..analysis.aggregate import ARGMIN_COLUMN_DOCS, MINIMA_COLUMN_DOCS, REALISATION_COLUMN_DOCS, SUMMARY_COLUMNS
from ..analysis.resampling import CONFIDENCE, N_RESAMPLES
from ..core import records
from ..core.case import CASE_COLUMNS, CASE_DIR, MODEL_COLUMNS
from ..core.columns import CASE_COLUMN_DOCS, RECORD_COLUMN_DOCS
from ..core.registry import SHEAR_CASES
from ..core.settings import SHEAR
from ..figures import fig10, style
from ..models.shear2d import WALL_BAND

PAGE = "docs/columns.md"
COMMAND = ".venv/bin/python -m particle_entropy.pipeline.columnsdoc --write"
UNIT = re.compile(r"\s*\[([^\[\]]+)\]$")  # a description's trailing [unit]
NO_UNIT = "–"
CASE_LINK = "[Case columns](#case-columns)"
MARKUP_START = re.compile(r"[-+*>#=]+|\d+[.)]")  # words that must not open a line
WIDTH = 100  # prose is wrapped to this many characters; table rows are one line each

# ----------------------------------------------------------- columns whose module keeps no dict
RUN_SETTINGS = {  # run settings written beside the case columns (RunConfig.case_columns)
    "D": "diffusion coefficient [L²/T]",
    "seed": "seed of the realisation (realisation r has base_seed + r)",
}
SNAPSHOT_COLUMNS = {  # the final state of simulate.run(..., want_state=True)
    "x": "final position (PT sorted) [L]",
    "mass": "particle mass (PT 1/N; MTPT its mass); absent for FD",
    "c": "concentration at the particle or node: PT the reconstruction there (the density of its bin, or the "
    "kernel density at the particle), MTPT m / dV, FD the node value [1/L]",
}
# columns aggregate.summarise_runs copies from the lowest seed's run table
SUMMARY_COPIED = {
    **{c: RECORD_COLUMN_DOCS[c] for c in ("H_C_analytic", "E_analytic", "dV")},
    "n_sse": f"{RECORD_COLUMN_DOCS['n_sse']}; copied from the lowest seed",
    "settled": RECORD_COLUMN_DOCS["settled"],
}
COMIC_COLUMNS = {  # aggregate.comic_table: case summaries at the step nearest each requested time
    "label": REALISATION_COLUMN_DOCS["label"],
    **{c: CASE_COLUMN_DOCS[c] for c in CASE_COLUMNS},
    "time": "requested time [T]",
    "time_step": "time of the recorded step nearest to it [T]",
    "COMIC_mean": SUMMARY_COLUMNS["COMIC_mean"],
    "COMIC_std": SUMMARY_COLUMNS["COMIC_std"],
    "COMIC_reason": "why `COMIC_mean` (and `COMIC_std`) is NaN: the mean SSE is 0 or not finite, dV is not > 0, or a "
    "realisation's SSE is 0 or not finite (aggregate.UNSCORED); empty when it scores. An unscored N is never a "
    "minimum",
    "COMIC_of_mean_SSE": "COMIC of the ensemble-mean SSE, 2 ln(SSE_mean / n_sse) - ln dV (Eq. 43 applied to the "
    "mean, as the authors' script plots Fig. 9)",
    "COMIC_of_mean_SSE_lo": "the same with SSE_mean - SSE_std (-inf when the standard deviation reaches the mean)",
    "COMIC_of_mean_SSE_hi": "the same with SSE_mean + SSE_std (all three NaN when the mean SSE is 0 or not finite)",
    "SSE_mean": SUMMARY_COLUMNS["SSE_mean"],
    "SSE_std": SUMMARY_COLUMNS["SSE_std"],
    "n_realisations": "realisations behind the row",
}
TRADEOFF_COLUMNS = {  # aggregate.tradeoff_table
    "label": REALISATION_COLUMN_DOCS["label"],
    **{c: CASE_COLUMN_DOCS[c] for c in CASE_COLUMNS},
    "time": "requested time (the row is the recorded step nearest to it) [T]",
    "wall_s": "wall-clock seconds of one realisation from t = 0 to that step, ensemble mean (the summary's "
    "`wall_cum_mean`; differs run to run) [s]",
    "wall_s_std": "its standard deviation [s]",
    "work": "particle-steps (FD node-steps) to that step, ensemble mean",
    "peak_rss_mb": "largest peak resident memory of a realisation [MB]",
    "rmse": "concentration error sqrt(SSE_mean / n_sse), the root of the ensemble-mean SSE per point [1/L]",
    "H_C_error": "H_C_mean - H_C_analytic (Eq. 14) [nats]",
    "E_rel_error": "E_mean / E_analytic - 1",
    "COMIC_mean": SUMMARY_COLUMNS["COMIC_mean"],
    "COMIC_std": SUMMARY_COLUMNS["COMIC_std"],
    "COMIC_reason": COMIC_COLUMNS["COMIC_reason"],
    "n_realisations": "realisations behind the row",
    "is_comic_optimum": "this N has the least `COMIC_mean` of its model at this time (the smallest N among ties; "
    "never an unscored N)",
}
CLAIM_COLUMNS = {  # claims.COLUMNS
    "claim": "the claim in words, naming the model and N or time it is judged for",
    "paper": "what the paper states (text)",
    "reproduced": "what this run gives (text, numbers formatted)",
    "tolerance": "the criterion the claim is judged by (text; ranges from `claims` in the config)",
    "passed": "the reproduced value meets the criterion (the project's rule)",
    "as_drawn": "(a) what the paper's own Fig. 9 bars show, ln(SSE +- std) - ln(SSE) about the COMIC of the mean "
    "SSE (`judging.py`; empty where the rule does not apply)",
    "passed_as_drawn": "verdict of (a), null where it does not apply",
    "test": "(b) what a test at level 0.05 finds: the bootstrap interval of the argmin against the range, or "
    "Holm-adjusted one-sided Welch t-tests of each N against the best (`judging.py`; empty where not judged)",
    "passed_test": "verdict of (b), null where it does not apply or cannot be computed",
}
SHEAR_STEP_COLUMNS = {  # shear2d.run_shear's per-step table (its Recorder's rows)
    "step": "time-step index, 0 = initial condition",
    "time": "time at the end of the step (step × dt) [T]",
    "mass_total": "total particle mass (1 at t = 0)",
    "mass_min": "smallest particle mass",
    "wall_fraction": f"share of particles (random walks) or of mass (`mt`) within {WALL_BAND} of a wall; "
    f"{2 * WALL_BAND} if spread evenly in y",
    "mean_y": "mean lateral position: of all particles (random walks), mass-weighted (`mt`) [L]",
    "substeps": "mass-transfer substeps taken to keep masses non-negative (0 for random walks and step 0)",
    "max_offdiag_beta": "beta × the largest row sum of P_ij over j ≠ i before splitting (0: no transfer)",
    "n_pairs": "particle pairs within the kernel cut-off (`mt`; 0 for random walks)",
    "wall_s": "wall-clock seconds spent in the step [s]",
}
SHEAR_STATE_COLUMNS = {  # shear2d.run_shear's final particle table
    "x": "final position along the flow, in [0, length) [L]",
    "y": "final lateral position, in [0, 1] [L]",
    "mass": "final particle mass",
    "case": "shear case: " + ", ".join(f"`{c}`" for c in SHEAR_CASES),
    "seed": "random seed",
}
SHEAR_SETTINGS = {  # shear step columns beyond SHEAR_STEP_COLUMNS: the Recorder's and ShearConfig.case_columns
    "work": "running sum of `substeps` (0 for random walks); unlike the 1-D run tables it does not count particles",
    "peak_rss_mb": RECORD_COLUMN_DOCS["peak_rss_mb"],
    "case": SHEAR_STATE_COLUMNS["case"],
    "seed": SHEAR_STATE_COLUMNS["seed"],
    # the run's settings, as config `shear` declares them (settings.SHEAR)
    **{s.name: s.doc + ("" if s.unit == "-" else f" [{s.unit}]") for s in SHEAR if s.name not in ("cases", "seed")},
}
LATTICE_COLUMNS = {  # lattice.lattice_run
    **{c: CASE_COLUMN_DOCS[c] for c in CASE_COLUMNS},
    "time": "requested time [T]",
    "time_step": "time of the recorded step nearest to it [T]",
    "SSE": "SSE of the lattice run, Eq. 44 [1/L²]",
    "SSE_over_N": "SSE / N: the noise-free floor drawn in fig9_mechanism panel b [1/L²]",
    "COMIC": "2 ln(SSE / N) - ln dV, Eq. 43",
    "mass_total": "total mass at that step",
}
FD_DOMAIN_COLUMNS = {  # fd_domain.run_case, rows of fd_domain.domain_experiment
    "n": "the paper's grid label: intervals on the reference domain (`physics.fd_length`), which fixes "
    "dx = fd_length / n",
    "n_intervals": "intervals on this row's domain at that dx",
    "dx": "grid spacing [L]",
    "fd_length": "length of this row's domain, [-fd_length/2, fd_length/2] [L]",
    "fd_dt": "time step [T]",
    "reference": "what the SSE compares with: `unit` (the paper's: the Gaussian sampled at the nodes and normalised "
    "to unit mass; the only one the workflow asks for), `exact`, `fd_mass` or `images` (`fd_domain.reference`)",
    "time": "report time [T]",
    "SSE": "sum of squared errors over all nodes, Eq. 44 [1/L²]",
    "n_sse": "nodes (n_intervals + 1)",
    "ln_SSE_over_N": "ln(SSE / n_sse) (-inf for SSE = 0)",
    "COMIC": "2 ln(SSE / n_sse) - ln dx, Eq. 43",
    "SSE_edge": "the part of SSE from nodes with abs(x) > 4 [1/L²]",
    "edge_fraction": "SSE_edge / SSE (0 when SSE is 0)",
    "mass_total": "FD mass, the sum of c dx over the nodes",
    "mass_loss": "1 - mass_total: mass absorbed by the zero end nodes",
    "max_abs_error": "largest abs(c - reference) over the nodes [1/L]",
    "x_max_error": "distance from x = 0 of the node where it occurs [L]",
}
PLAN_COLUMN_DOCS = {  # optimum.PLAN_COLUMNS
    "round": "round that added the block",
    "n": "particles (FD: intervals)",
    "dt_growth": "time-step growth factor of the block's case (the searched value of a `growth_range` search)",
    "first": "first seed of the block (inclusive)",
    "last": "last seed of the block (inclusive)",
    "done": "the search has stopped (every row of the plan)",
    "reason": "why it stopped (`optimum.REASONS`); empty while it runs",
}

# ----------------------------------------------------------------------------- fixed prose
TITLE = "# Columns of the tables the workflow writes"
# a case's folder as the page writes it: case.CASE_DIR with each value's wildcard as a capital letter
CASE_FOLDER = CASE_DIR.format(
    method="{method}", kernel="{kernel}", n="N", eta="E", trunc="T", growth="G", scheme="S", grid="R"
)
INTRO = f"""\
This page lists every Parquet table the workflow derives, one section per table: what one row
holds, the rule that writes it, and each column with its meaning, unit and, where one applies,
the paper's equation. It is generated from the column dicts of the code that writes each table
(named at the end of each section's paragraph; a description's trailing `[...]` is its unit), so
a meaning is written once, beside the code that computes it. Edit the dict, not this page, and
regenerate the page with

    {COMMAND} {PAGE}

`tests/test_columnsdoc.py` fails while the page differs from the dicts, and
`tests/test_workflow.py::test_every_derived_table_column_is_documented` holds every table of the
tiny workflow run to its section here, so a column added without a line in its dict fails it.

**Units.** L length, T time, s wall-clock seconds, nats natural-log entropy. Masses have no
unit (the total is 1 at t = 0), so a concentration is [1/L] and a sum of squared concentration
errors (SSE) is [1/L²]. Logarithms are natural. Equation numbers are those of Benson et al. (2020).

**Paths.** `<case>` stands for a case's folder
`{CASE_FOLDER}` (built by `Case.path`); other `<...>`
stand for one path segment. Every table has a `<name>.parquet.sha256` beside it (its checksum,
not a table).

**Times.** Tables read "at a time" (`comic_times`, `tradeoff.times` in the config) take the
recorded step nearest to it (`aggregate.at_times`). `time` is then the requested time and
`time_step` the time of that step; the trade-off table keeps only the requested time."""

# what each figure puts in its source data: (figure, what it reads, its panels, x_name -> y_name)
FIGURE_CONTENTS = (
    (
        "fig1",
        "single runs (seed base_seed)",
        "one per N, ascending",
        "`time` → `H_C` of each case and analytic (Eq. 14); `H_D` of the first PT case (ln N); `settling time`, "
        "a vertical line at x = dV² / (4 π e D) with y NaN",
    ),
    ("fig2", "single runs", "one per N, descending", "`time` → `E` of each case and analytic sqrt(4 π e D t)"),
    ("fig3", "case summaries", "one (`panel` empty)", "`time` → `H_C` mean ± std of each case and N, analytic per N"),
    ("fig4, fig5", "case summaries", "one per N, descending", "`time` → `E` mean ± std, and analytic"),
    (
        "fig6",
        "case summaries",
        "one",
        "`time` → `H_PMF` mean (no band) per N; analytic `H_I` = ln sqrt(4 π D t) + 1/2",
    ),
    (
        "fig7",
        "final states",
        "one per N, descending",
        "`x` → `c`, one row per particle at t_final; the analytic Gaussian on an 801-point grid",
    ),
    (
        "fig8",
        "FD case summaries",
        "a, b, c",
        "a: `time` → `ln(SSE/N)` (= AIC/2, N the node count `n_sse`); b: `time` → `COMIC`; c: `dx` → `ln(SSE/N)` "
        "and `COMIC` at the step nearest t = 250",
    ),
    (
        "fig9",
        "`results/tables/fig9/` COMIC, minima and argmin tables",
        "per kernel, eta and dt growth (schemes and truncations side by side): a top panel (a, c, e, ...) and a bar "
        "panel below it (b, d, f, ...)",
        "top: `N` → `COMIC` (mean ± std) and `COMIC of mean SSE` (`y_lo`, `y_hi` from `COMIC_of_mean_SSE_lo`, "
        "`_hi`), at the COMIC time nearest t_final; bars: `N` → `share of resamples with this argmin` (convention "
        "`mean_COMIC`)",
    ),
    (
        "tradeoff",
        "`results/tables/tradeoff.parquet`",
        "two per requested time (a, b; c, d; ...)",
        "left: `wall_s` → `rmse`; right: `N` → `rmse`",
    ),
    (
        "fig9_mechanism",
        "`results/tables/mechanism/` COMIC and per-realisation tables, floors, fd_domain",
        "a, b, c, d",
        "a-c at the COMIC time nearest t_final. a: `N` → `COMIC` mean ± std; b: `N` → `SSE/N` = SSE_mean / N with "
        "`y_lo`, `y_hi` ± one standard error (SSE_std / N / sqrt(realisations)), each lattice floor as a two-point "
        "line over the N drawn, and the analytic floor of the cut kernel's variance deficit (`method` `analytic`); "
        "c: `N` → `paired COMIC difference`, the model's COMIC minus the equations' at the same seeds, mean with "
        "`y_lo`, `y_hi` ± one standard error, `n_realisations` = the paired seeds; d: `time` → `ln(SSE/N)` of each "
        "FD grid and domain length (`n` is the paper's grid label, N in the ratio too, not the node count)",
    ),
    (
        "scene",
        "`results/scenes/<name>.parquet` (drawn as `figures/scene_<name>.png`)",
        "a, b (2-D: c, d)",
        "a: `cost_s` → `error_mean` with `error_lo`, `error_hi` per candidate, the `target`, the `recommended` row "
        "starred; b: `n` → `COMIC_points` per candidate, the `comic_best` row ringed; 2-D: c the exact concentration "
        "at t_final on 200 × 200 points over ±4 sd of the plume, d the `recommended` row's (else the cheapest "
        "candidate's least-error rung) on the same grid and levels, its final state run once in the plot job on the "
        "first seed",
    ),
    (
        "scenes_peclet",
        "`results/scenes/peclet-<k>.parquet` and `peclet2d-<k>.parquet`, its source data "
        "`results/scenes_peclet.parquet`",
        "one",
        "`peclet` → `cost_s` per `family` (grid, particles) and `dim` (1-D full lines, 2-D dashed), bars down to "
        "`cost_lo`; each sweep's crossover shaded where `particles_cheaper` turns true",
    ),
)
FIGURE_NOTES = "\n".join(
    [
        "What each figure puts in the table:",
        "",
        "| figure | reads | panels | x_name → y_name |",
        "|---|---|---|---|",
        *("| " + " | ".join(row) + " |" for row in FIGURE_CONTENTS),
    ]
)

OUTRO = """\
## Other files in the results folder (not tables)

- `<name>.parquet.sha256`: the SHA-256 of a table, checked at the start of each run;
  `<name>.parquet.corrupt`: a table that failed that check, set aside (docs/robustness.md).
- `results/benchmarks/**/*.tsv`: Snakemake's benchmark files, one per simulation job
  (Snakemake's own columns: `s`, `h:m:s`, `max_rss`, `max_vms`, `max_uss`, `max_pss`, `io_in`,
  `io_out`, `mean_load`, `cpu_time`; see the Snakemake documentation).
- `results/paper_claims.md`: described with the claims table above."""


# ----------------------------------------------------------------------------- the sections
@dataclass(frozen=True)
class Section:
    """One table of the page: its title, the paths it is written to, a paragraph on what a row
    holds and which rule writes it, its columns as (source name, dict) parts in table order, the
    text of its case-columns row and any Markdown after its table."""

    title: str
    paths: tuple[str, ...]
    about: str
    parts: tuple[tuple[str, Mapping[str, str]], ...]
    case_row: str = f"the case ({CASE_LINK})"
    notes: str = ""
    grouped: bool = True  # a run of the case or model columns is one row


def keyed(names: Sequence[str], docs: Mapping[str, str]) -> dict[str, str]:
    """``docs`` in the order of ``names``, the columns a module writes; refuses a column without a
    meaning and a meaning without a column."""
    missing, extra = [n for n in names if n not in docs], [n for n in docs if n not in names]
    if missing or extra:
        raise ValueError(f"columns without a meaning: {missing}; meanings without a column: {extra}")
    return {n: docs[n] for n in names}


def sections() -> list[Section]:
    """The page's tables in order, built from the column dicts as they are now."""
    case = ("columns.CASE_COLUMN_DOCS", keyed(CASE_COLUMNS, CASE_COLUMN_DOCS))
    d = ("columnsdoc.RUN_SETTINGS", {"D": RUN_SETTINGS["D"]})
    same_columns = "(same columns for `fig9` and `mechanism`;"
    return [
        Section(
            "Case columns",
            (),
            "Most tables carry the case of a row as typed columns (`Case.columns()`). A *model* is a case at every "
            "N: tables keyed by model (minima, argmin shares) have all of these except `n`.",
            (case,),
            grouped=False,
        ),
        Section(
            "Per-step run tables",
            ("results/runs/<case>/seeds~<first>-<last>.parquet",),
            "One row per time step of one realisation; a file holds the realisations (seeds) `first` to `last` of "
            "one case, told apart by `seed`, and step 0 is the initial condition. Written by rule `simulate` "
            "(`workflow/scripts/simulate.py`, `simulate.run_seeds`); what a measure is computed on depends on the "
            "method.",
            (
                ("columns.RECORD_COLUMN_DOCS", keyed(records.COLUMNS, RECORD_COLUMN_DOCS)),
                case,
                ("columnsdoc.RUN_SETTINGS", RUN_SETTINGS),
            ),
        ),
        Section(
            "Final states",
            ("results/snapshots/<case>/seeds~<first>-<last>.parquet",),
            "One row per particle (FD: per node) of one realisation at the end of the run (t_final), for the cases "
            "of Fig. 7. Written by rule `simulate` with output kind `snapshots` (`simulate.run(..., "
            "want_state=True)`).",
            (("columnsdoc.SNAPSHOT_COLUMNS", SNAPSHOT_COLUMNS), case, ("columnsdoc.RUN_SETTINGS", RUN_SETTINGS)),
        ),
        Section(
            "Case summaries",
            ("results/tables/cases/<case>/r~<K>.parquet",),
            "One row per time step of one case, over its K realisations (`n_realisations`). Written by rule "
            "`summarise_case` (`aggregate.summarise_files`). Standard deviations use ddof = 1 and are 0 for a "
            "single realisation or where they are not finite (a -inf at t = 0).",
            (
                ("aggregate.SUMMARY_COLUMNS", SUMMARY_COLUMNS),
                ("columnsdoc.SUMMARY_COPIED", SUMMARY_COPIED),
                case,
                d,
            ),
        ),
        Section(
            "COMIC table",
            ("results/tables/comic.parquet", "results/tables/<section>/comic.parquet"),
            "One row per model, N and requested time (`comic_times`), read from the case summaries. Written by rule "
            "`comic_tables` over the COMIC models (FD of Fig. 8 and the models of Fig. 9) and by rule "
            "`comic_tables_section` for `<section>` = `fig9` (Fig. 9's models alone, what `figures/fig9.png` draws) "
            "or `mechanism` (the mechanism sweeps); the copies have the same columns (`aggregate.comic_table`).",
            (("columnsdoc.COMIC_COLUMNS", COMIC_COLUMNS),),
        ),
        Section(
            "COMIC minima",
            ("results/tables/comic_minima.parquet", "results/tables/<section>/comic_minima.parquet"),
            "One row per model and requested time: the N that minimises mean COMIC over the model's grid of N, its "
            f"neighbours on the grid, and the bootstrap interval of that minimum. Written by rules `comic_tables` "
            f"and `comic_tables_section` {same_columns} `aggregate.comic_minima`). The bootstrap columns come "
            f"from the argmin table below; the interval is the {CONFIDENCE * 100:g} % percentile interval of the "
            "resampled argmin, widened outward to grid values of N.",
            (("aggregate.MINIMA_COLUMN_DOCS", MINIMA_COLUMN_DOCS),),
        ),
        Section(
            "Per-realisation COMIC",
            ("results/tables/comic_realisations.parquet", "results/tables/<section>/comic_realisations.parquet"),
            "One row per case, requested time and seed: the values the bootstrap resamples, read from the run "
            f"tables. Written by rules `comic_tables` and `comic_tables_section` {same_columns} "
            "`aggregate.realisations_table`).",
            (("aggregate.REALISATION_COLUMN_DOCS", REALISATION_COLUMN_DOCS),),
        ),
        Section(
            "Bootstrap argmin shares",
            ("results/tables/comic_argmin.parquet", "results/tables/<section>/comic_argmin.parquet"),
            "One row per model, requested time, convention and N: how often that N has the least COMIC when the "
            f"realisations of every N are resampled ({N_RESAMPLES} resamples, `scipy.stats.bootstrap`, each N on "
            "its own; an N with one realisation is held fixed). Written by rules `comic_tables` and "
            f"`comic_tables_section` {same_columns} `aggregate.comic_argmin`).",
            (("aggregate.ARGMIN_COLUMN_DOCS", ARGMIN_COLUMN_DOCS),),
        ),
        Section(
            "Trade-off table",
            ("results/tables/tradeoff.parquet",),
            "One row per case and requested time (`tradeoff.times`): cost beside error, from the case summaries of "
            "the `tradeoff` section. Written by rule `tradeoff_table` (`aggregate.tradeoff_table`).",
            (("columnsdoc.TRADEOFF_COLUMNS", TRADEOFF_COLUMNS),),
        ),
        Section(
            "Paper claims",
            ("results/tables/paper_claims.parquet",),
            "One row per quantitative claim of the paper, judged against the reproduced tables (single runs of "
            "Fig. 1, ensembles of Figs. 3 and 5, the COMIC table and minima). Written by rule `paper_claims` "
            "(`claims.py`), which also writes `results/paper_claims.md`: the same rows as a Markdown table with the "
            "columns claim, paper, reproduced, tolerance and result (`pass` or `FAIL`), under a line counting the "
            "claims that pass. With no figure to judge the table is empty but keeps its columns.",
            (("columnsdoc.CLAIM_COLUMNS", keyed(claims.COLUMNS, CLAIM_COLUMNS)),),
        ),
        Section(
            "Figure source data",
            ("results/figures/<fig>.parquet",),
            "One row per plotted point of one figure: `fig1` ... `fig9`, `tradeoff` (rules `plot_<fig>`, "
            "`workflow/scripts/plot_figure.py`) and `fig9_mechanism` (rule `plot_fig9_mechanism`), the same "
            "columns in each. A series is one legend entry on one panel. Analytic reference curves have `method` = "
            "`analytic`, no kernel or scheme, NaN for `eta`, `truncation` and `dt_growth`, and `n` the N they "
            "depend on (else missing). Fig. 10 has its own columns (next section).",
            (("style.SOURCE_COLUMNS", style.SOURCE_COLUMNS),),
            case_row=f"the case of the point ({CASE_LINK}), or the analytic marker above",
            notes=FIGURE_NOTES,
        ),
        Section(
            "Fig. 10 source data",
            ("results/figures/fig10.parquet",),
            "One row per plotted point of Fig. 10 (the 2-D shear flow, Appendix B): a particle of panels a-c or a "
            "histogram bin or reference-line end of panels d-f. Written by rule `plot_fig10` "
            "(`fig10.source_data`).",
            (("fig10.SOURCE_COLUMNS", fig10.SOURCE_COLUMNS),),
        ),
        Section(
            "Shear-flow steps",
            ("results/shear/<shear_case>/seed~<S>/steps.parquet",),
            "One row per time step of one Appendix-B shear-flow run (case `rw_nodrift`, `rw_drift` or `mt`, seed "
            "S), the run's settings repeated on every row. Written by rule `simulate_shear` (`shear2d.run_shear`).",
            (("columnsdoc.SHEAR_STEP_COLUMNS", SHEAR_STEP_COLUMNS), ("columnsdoc.SHEAR_SETTINGS", SHEAR_SETTINGS)),
        ),
        Section(
            "Shear-flow final states",
            ("results/shear/<shear_case>/seed~<S>/state.parquet",),
            "One row per particle at t_final of one shear-flow run. Written by rule `simulate_shear`.",
            (("columnsdoc.SHEAR_STATE_COLUMNS", SHEAR_STATE_COLUMNS),),
        ),
        Section(
            "Lattice floors",
            ("results/tables/mechanism/floors.parquet",),
            "One row per case and requested time (`comic_times`): each mechanism model, plus "
            "`mechanism.lattice.cases`, run once on N evenly spaced particles (`mechanism.lattice.n`, odd), which "
            "removes the sampling error and leaves the scheme's own SSE. Written by rule `mechanism_floors` "
            "(`lattice.lattice_run`). MTPT with eta = 1 only.",
            (("columnsdoc.LATTICE_COLUMNS", LATTICE_COLUMNS),),
            case_row=f"the case, `n` the lattice's particle count ({CASE_LINK})",
        ),
        Section(
            "FD domain experiment",
            ("results/tables/mechanism/fd_domain.parquet",),
            "One row per FD grid, domain length, time step, SSE reference and report time: implicit FD (backward "
            "Euler, zero end nodes) on the paper's domain and on longer ones at the same dx, the experiment behind "
            "Fig. 8's late rise. Report times are 20 even steps to t_final on the FD time grid. Written by rule "
            "`fd_domain` (`fd_domain.domain_experiment`).",
            (("columnsdoc.FD_DOMAIN_COLUMNS", FD_DOMAIN_COLUMNS),),
        ),
        Section(
            "Optimum search plans",
            ("results/optimum/<name>/round~<k>.parquet",),
            "One row per seed block a search has planned by round k: round 0 is the lowest points of the coarse "
            "grid, each later round adds blocks (new N, or more seeds of an N visited before); the first plan with "
            "`done` set is the last (it repeats the previous plan's blocks). Each block is one simulation job, "
            "`results/runs/<case>/seeds~<first>-<last>.parquet`. Written by checkpoint `optimum_round` "
            "(`optimum.initial_plan`, `optimum.next_plan`).",
            (("columnsdoc.PLAN_COLUMN_DOCS", keyed(optimum.PLAN_COLUMNS, PLAN_COLUMN_DOCS)),),
        ),
        Section(
            "Optimum search results",
            ("results/optimum/<name>.parquet",),
            "One row per visited point (an N, or a dt growth for a `growth_range` search) of a finished search "
            "`optimum.<name>`; the search-level columns repeat on every row, and the optimum's columns hold values "
            "of the searched dimension (`over`). Written by rule `optimum_table` (`optimum.result_table`).",
            (("optimum.RESULT_COLUMN_DOCS", optimum.RESULT_COLUMN_DOCS),),
        ),
        Section(
            "Scene results",
            ("results/scenes/<name>.parquet",),
            "One row per visited (candidate, resolution) of a finished scene `scenes.<name>` (or a scene of the "
            "Peclet sweep, `peclet-<k>`); the scene-level columns repeat on every row. Written by rule "
            "`scene_table` (`scene_search.result`); docs/scenes.md explains the search.",
            (("scene_search.RESULT_COLUMN_DOCS", scene_search.RESULT_COLUMN_DOCS),),
        ),
    ]


# ----------------------------------------------------------------------------- rendering
def split_unit(description: str) -> tuple[str, str]:
    """(meaning, unit) of a column description: its trailing ``[unit]``, or no unit."""
    m = UNIT.search(description)
    return (description[: m.start()], m.group(1)) if m else (description, NO_UNIT)


def _row(names: Sequence[str], meaning: str, unit: str) -> str:
    cells = [", ".join(f"`{n}`" for n in names), meaning.replace("|", "\\|"), unit]
    return "| " + " | ".join(cells) + " |"


def table_rows(section: Section) -> list[str]:
    """The column table of ``section``: one row per column, a run of the case or model columns
    as one row."""
    items = [(name, doc) for _, part in section.parts for name, doc in part.items()]
    names = [name for name, _ in items]
    rows, k = ["| column | meaning | unit |", "|---|---|---|"], 0
    while k < len(items):
        if section.grouped and tuple(names[k : k + len(CASE_COLUMNS)]) == CASE_COLUMNS:
            rows.append(_row(CASE_COLUMNS, section.case_row, NO_UNIT))
            k += len(CASE_COLUMNS)
        elif section.grouped and tuple(names[k : k + len(MODEL_COLUMNS)]) == MODEL_COLUMNS:
            rows.append(_row(MODEL_COLUMNS, f"the model ({CASE_LINK}, no `n`)", NO_UNIT))
            k += len(MODEL_COLUMNS)
        else:
            rows.append(_row([names[k]], *split_unit(items[k][1])))
            k += 1
    return rows


def _paragraph(text: str) -> str:
    """``text`` wrapped to WIDTH; a line that would open with what Markdown reads as a list item,
    quote or heading keeps that word on the line before."""
    lines = textwrap.wrap(text, WIDTH, break_long_words=False, break_on_hyphens=False)
    out = lines[:1]
    for line in lines[1:]:
        word, _, rest = line.partition(" ")
        if MARKUP_START.fullmatch(word):
            out[-1] += f" {word}"
            line = rest
        if line:
            out.append(line)
    return "\n".join(out)


def render_section(section: Section) -> str:
    """The Markdown of one section: heading with its paths, paragraph, column table, notes."""
    heading = f"## {section.title}" + "".join(f"{': ' if k == 0 else ', '}`{p}`" for k, p in enumerate(section.paths))
    sources = ", ".join(f"`{name}`" for name in dict.fromkeys(name for name, _ in section.parts))
    blocks = [heading, _paragraph(f"{section.about} Column meanings: {sources}."), "\n".join(table_rows(section))]
    return "\n\n".join(blocks + ([section.notes] if section.notes else []))


def render() -> str:
    """The whole of docs/columns.md."""
    header = f"<!-- Generated from the column dicts of the library by `{COMMAND} {PAGE}`: do not edit. -->"
    blocks = [header, TITLE, INTRO, *(render_section(s) for s in sections()), OUTRO]
    return "\n\n".join(blocks) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m particle_entropy.pipeline.columnsdoc",
        description="Render docs/columns.md from the column dicts of the library (to standard output by default).",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--write", metavar="PATH", help="write the page to PATH")
    where.add_argument(
        "--check",
        metavar="PATH",
        nargs="?",
        const=PAGE,
        help=f"exit 1 if PATH (default {PAGE}) differs from the page the dicts give",
    )
    a = parser.parse_args(argv)
    text = render()
    if a.check is not None:
        path = Path(a.check)
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            state = "differs from" if path.is_file() else "is missing, so it cannot match"
            print(f"{path} {state} the column dicts; regenerate it: {COMMAND} {path}", file=sys.stderr)
            return 1
        return 0
    if a.write is not None:
        Path(a.write).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
