# COMIC tables, minima, paper claims and the trade-off table, from the case summaries
# (summarise.smk) and run tables.


# COMIC per model, N and time over the COMIC models: FD (Fig. 8) and Fig. 9's models; the
# per-realisation SSE and COMIC at those times, a bootstrap over realisations of how often each
# N is the argmin, and the minima with their bootstrap intervals.
rule comic_tables:
    input:
        summaries=INPUTS.summaries_of("fig8", "fig9"),
        runs=INPUTS.runs_of("fig8", "fig9"),
    output:
        comic="results/tables/comic.parquet",
        minima="results/tables/comic_minima.parquet",
        realisations="results/tables/comic_realisations.parquet",
        argmin="results/tables/comic_argmin.parquet",
        comic_html=report("results/tables/comic.html", caption="../report/comic.rst", category="COMIC"),
        minima_html=report("results/tables/comic_minima.html", caption="../report/comic_minima.rst", category="COMIC"),
    log:
        "logs/comic_tables.log",
    benchmark:
        "results/benchmarks/comic_tables/all.tsv"
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        times=config["comic_times"],
        code=script_code(SCRIPTS / "comic_tables.py"),
    script:
        "../scripts/comic_tables.py"


# A section's own COMIC tables (Fig. 9's, the mechanism sweeps'), so that its target pulls
# only its own runs.
rule comic_tables_section:
    input:
        summaries=lambda w: INPUTS.summaries_of(w.section),
        runs=lambda w: INPUTS.runs_of(w.section),
    output:
        comic="results/tables/{section}/comic.parquet",
        minima="results/tables/{section}/comic_minima.parquet",
        realisations="results/tables/{section}/comic_realisations.parquet",
        argmin="results/tables/{section}/comic_argmin.parquet",
    log:
        "logs/comic_tables_{section}.log",
    benchmark:
        "results/benchmarks/comic_tables/{section}.tsv"
    wildcard_constraints:
        section="fig9|mechanism",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        times=config["comic_times"],
        code=script_code(SCRIPTS / "comic_tables.py"),
    script:
        "../scripts/comic_tables.py"


rule paper_claims:
    input:
        minima="results/tables/comic_minima.parquet",
        comic="results/tables/comic.parquet",
        realisations="results/tables/comic_realisations.parquet",
        summaries=INPUTS.summaries_of("fig3", "fig5"),
        runs=INPUTS.section_inputs("fig1") if "fig1" in PLOTTED else [],
    output:
        table="results/tables/paper_claims.parquet",
        md="results/paper_claims.md",
        html=report("results/paper_claims.html", caption="../report/paper_claims.rst", category="Claims"),
    log:
        "logs/paper_claims.log",
    benchmark:
        "results/benchmarks/paper_claims/all.tsv"
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        claims=config["claims"],
        case_defaults=config.get("case_defaults", {}),
        code=script_code(SCRIPTS / "paper_claims.py"),
    script:
        "../scripts/paper_claims.py"


rule tradeoff_table:
    input:
        INPUTS.summaries_of("tradeoff"),
    output:
        "results/tables/tradeoff.parquet",
    log:
        "logs/tradeoff_table.log",
    benchmark:
        "results/benchmarks/tradeoff_table/all.tsv"
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        times=config.get("tradeoff", {}).get("times", []),
        code=script_code(SCRIPTS / "tradeoff_table.py"),
    script:
        "../scripts/tradeoff_table.py"
