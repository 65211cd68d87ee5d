"""What the rules read from the config: the figures of the default target, each figure's and
section's input tables and cases, a simulation job's case, settings and resources from its
wildcards, and the crate's and the report's parameters. The rule files call these
(workflow/rules/common.smk makes the one ``Inputs`` of a config); no job script imports this
module, so editing it reruns no rule.

A table path written by hand (a target) that names no valid run is refused in one line naming
the pattern expected: ``error`` is the exception a refusal raises (the workflow passes
Snakemake's WorkflowError, which Snakemake reports without a traceback).
"""

from __future__ import annotations

from collections.abc import Mapping

from pydantic import BaseModel

from ..core.case import Case, SettingError
from ..core.settings import MAX_REALISATIONS
from ..figures import BY_NAME as FIGURE
from ..figures import CASE_FIGURES
from ..figures import FIGURES as ALL_FIGURES
from .crate import provenance
from .jobcost import estimated_seconds
from .memory import estimate_mb
from .sweeps import (
    RUN_PATTERN,
    SUMMARY_PATTERN,
    Ensemble,
    case_run_paths,
    figure_ensembles,
    mechanism_ensembles,
    run_config,
    run_path,
    run_settings,
    spec_ensembles,
)

MAX_TARGET_SEEDS = MAX_REALISATIONS  # seeds of one hand-written run table: more is a typo, not a job
COMIC_TABLES = ("results/tables/comic.parquet", "results/tables/comic_minima.parquet")
CLAIMS = ("results/tables/paper_claims.parquet", "results/paper_claims.md")


def in_config(cfg, section: str) -> bool:
    """Whether the typed config ``cfg`` (pipeline/config.py) has ``section``, a dotted key
    (figures.fig3, tradeoff, shear): a section the config leaves out is None in it."""
    node = cfg
    for part in section.split("."):
        node = getattr(node, part, None) if isinstance(node, BaseModel) else None
        if node is None:
            return False
    return True


def plotted_figures(cfg) -> list[str]:
    """The figures of the default target drawn from their cases by the shared plot rule
    (figures.smk), those whose section the typed config has (figures.FIGURES, the one list)."""
    return [f for f in CASE_FIGURES if in_config(cfg, FIGURE[f].section)]


def default_targets(cfg) -> list[str]:
    """The default target's files: the figures whose section the config has (the shared plot
    rule's and the shear flow's), the trade-off table, the COMIC tables and the paper's claims."""
    shear = [f.name for f in ALL_FIGURES if f.section == "shear" and in_config(cfg, f.section)]
    figs = [f"figures/{f}.{ext}" for f in plotted_figures(cfg) + shear for ext in ("png", "pdf")]
    if in_config(cfg, "tradeoff"):
        figs.append("results/tables/tradeoff.parquet")
    return figs + [*COMIC_TABLES, *CLAIMS]


def coded_rules(rules) -> list[str]:
    """The rules with a `code` parameter (their code hash, pipeline/codeversion.py): the crate
    reads each job's from Snakemake's record of its params (pipeline/crate.py)."""
    return sorted(r.name for r in rules if "code" in r.params.keys())


def beyond_default_target(rules) -> list[str]:
    """The targets of these ``rules`` (the workflow's) outside the default one (the scenes and
    optimum searches, the mechanism figure): the crate describes those a run of this same config made."""
    by_name = {r.name: r for r in rules}
    found = [
        str(f) for name in ("scenes", "optimum") if name in by_name for f in by_name[name].input if not callable(f)
    ]
    if "plot_fig9_mechanism" in by_name:
        found += [str(f) for f in by_name["plot_fig9_mechanism"].output]
    return found


def figure_labels(figure: str, rule: str, data: str, drawn_by: str | None = None, *, config: Mapping, checkout):
    """The report's labels of a figure: where it came from (pipeline/crate.provenance), worked out
    when the report is built; ``data`` is its source-data table's path pattern, ``drawn_by`` the
    figures module that draws it (default: the one named for it), ``checkout`` the workflow's folder."""
    path = f"workflow/lib/particle_entropy/figures/{drawn_by or figure}.py"
    return lambda w: provenance(figure.format(**w), rule, path, data.format(**w), config, checkout)


class Inputs:
    """The input, params and resources functions of the rules, for one ``config`` (see the module):
    the sections, cases and seed blocks are planned from ``typed``, the config parsed once
    (pipeline/config.py; parsed here when not given); a run's settings from the mapping as written
    (sweeps.run_settings: the simulate jobs' params)."""

    def __init__(self, config: Mapping, error: type[Exception] = ValueError, typed=None):
        from .config import parse

        self.config = config
        self.typed = typed if typed is not None else parse(config)
        self.error = error

    # --------------------------------------------------------------- sections and figures
    def ensembles(self, section: str) -> list[Ensemble]:
        """The ensembles of a figure (fig1 ... fig9), of `tradeoff` or of `mechanism`."""
        typed = self.typed
        if section == "tradeoff":
            return spec_ensembles(typed.tradeoff, typed) if typed.tradeoff is not None else []
        if section == "mechanism":
            return mechanism_ensembles(typed)
        return figure_ensembles(typed, section) if getattr(typed.figures, section, None) is not None else []

    def section_inputs(self, section: str) -> list[str]:
        """What a figure reads, in the order of its cases: single runs, final states, the COMIC
        table or case summaries (figures.FIGURES)."""
        reads = FIGURE[section].reads
        if reads == "comic":  # the COMIC table, its minima and the bootstrap argmin shares
            return [f"results/tables/{section}/{t}.parquet" for t in ("comic", "comic_minima", "comic_argmin")]
        if reads == "tradeoff":
            return ["results/tables/tradeoff.parquet"]
        if reads in ("runs", "snapshots"):
            return [run_path(e.case, self.typed.base_seed, kind=reads) for e in self.ensembles(section)]
        return [e.summary_path() for e in self.ensembles(section)]

    def section_cases(self, section: str) -> list[dict]:
        """The cases of a section as wildcard dicts (a plot rule's parameter)."""
        return [e.case.wildcards() for e in self.ensembles(section)]

    def summaries_of(self, *sections: str) -> list[str]:
        """The case summaries of these sections' ensembles."""
        return [e.summary_path() for s in sections for e in self.ensembles(s)]

    def runs_of(self, *sections: str) -> list[str]:
        """The run tables behind the ensembles of these sections (per-realisation values), each once."""
        paths = (p for s in sections for e in self.ensembles(s) for p in case_run_paths(e, self.typed))
        return list(dict.fromkeys(paths))

    def fd_report_times(self, count: int = 20) -> list[float]:
        """Times of the FD domain experiment: count even steps to t_final, on the FD time grid."""
        t_final, dt = self.typed.physics.t_final, self.typed.time.fd_dt
        return [round(k * t_final / count / dt) * dt for k in range(1, count + 1)]

    # --------------------------------------------------------------- one job, from its wildcards
    def target_case(self, wildcards, pattern: str) -> Case:
        """The case a (perhaps hand-written) table path names, checked: one line naming the pattern
        expected where it names none (eta~1e, n~1, seeds~5-2, r~0), never a traceback from a job."""
        try:
            case = Case.from_wildcards(wildcards)
            seeds = (int(wildcards.first), int(wildcards.last)) if "first" in wildcards.keys() else (0, 0)
            if "nreal" in wildcards.keys() and int(wildcards.nreal) < 1:
                raise ValueError(f"r~{wildcards.nreal}: an ensemble of at least 1 realisation")
            if not 0 <= seeds[0] <= seeds[1] or seeds[1] - seeds[0] >= MAX_TARGET_SEEDS:
                raise ValueError(f"seeds~{seeds[0]}-{seeds[1]}: first <= last, at most {MAX_TARGET_SEEDS:,} seeds")
            run_config(case, self.config)
        except (ValueError, SettingError) as e:
            example = pattern.format(
                **Case("mtpt", "collision", 1000).wildcards(), kind="runs", first=0, last=3, nreal=20
            )
            raise self.error(f"a table path names no valid run ({e}); expected {pattern}, e.g. {example}") from None
        return case

    def summary_runs(self, wildcards) -> list[str]:
        """The run tables that one case summary averages."""
        self.target_case(wildcards, SUMMARY_PATTERN)
        return case_run_paths(Ensemble.from_wildcards(wildcards), self.typed)

    def sim_mem_mb(self, wildcards) -> int:
        """Estimated peak memory of a job's runs (memory.py, fitted to measured peaks)."""
        seeds = int(wildcards.last) - int(wildcards.first) + 1
        return estimate_mb(run_config(self.target_case(wildcards, RUN_PATTERN), self.config), seeds)

    def sim_priority(self, wildcards) -> float:
        """The job's estimated seconds (jobcost): Snakemake starts the longest simulations first."""
        seeds = int(wildcards.last) - int(wildcards.first) + 1
        return estimated_seconds(run_config(self.target_case(wildcards, RUN_PATTERN), self.config), seeds)

    def sim_runtime_min(self, wildcards) -> int:
        """The job's runtime request in minutes: 2 a seed up to N = 3,000, else 10."""
        seeds = int(wildcards.last) - int(wildcards.first) + 1
        return seeds * (2 if int(wildcards.n) <= 3000 else 10)

    def sim_settings(self, wildcards) -> dict:
        """Physics and numerics of a run (config.physics, config.time, config.numerics)."""
        return run_settings(self.target_case(wildcards, RUN_PATTERN), self.config)
