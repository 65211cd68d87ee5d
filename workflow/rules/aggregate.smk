# Ensembles -> per-step means and standard deviations; COMIC tables, minima, paper claims.


rule summarise_case:
    """Averages the realisations of one case, step by step. A `run:` block: with the default
    profile (force-use-threads) it runs inside the Snakemake process, saving a Python
    start-up (~1 s of CPU) for each of the ~90 summaries."""
    input:
        summary_runs,
    output:
        "results/tables/cases/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/r~{nreal}.parquet",
    log:
        "logs/summarise_case/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/r~{nreal}.log",
    resources:
        mem_mb=500,
    run:
        count = summarise_files(list(input), output[0])
        Path(log[0]).write_text(f"summarised {count} realisations\n")


rule comic_tables:
    input:
        comic_summaries(),
    output:
        comic="results/tables/comic.parquet",
        minima="results/tables/comic_minima.parquet",
    log:
        "logs/comic_tables.log",
    params:
        times=config["comic_times"],
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/comic_tables.py"


rule comic_tables_fig9:
    """Fig. 9's own COMIC table, so that its target pulls no FD run."""
    input:
        [summary_path(c) for c in figure_cases(config, "fig9")] if "fig9" in FIGURES else [],
    output:
        comic="results/tables/fig9/comic.parquet",
        minima="results/tables/fig9/comic_minima.parquet",
    log:
        "logs/comic_tables_fig9.log",
    params:
        times=config["comic_times"],
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/comic_tables.py"


rule paper_claims:
    input:
        minima="results/tables/comic_minima.parquet",
        comic="results/tables/comic.parquet",
        summaries=[summary_path(c) for f in ("fig3", "fig5") if f in FIGURES for c in figure_cases(config, f)],
        runs=[run_path(c, config["base_seed"]) for c in figure_cases(config, "fig1")] if "fig1" in FIGURES else [],
    output:
        table="results/tables/paper_claims.parquet",
        md="results/paper_claims.md",
    log:
        "logs/paper_claims.log",
    params:
        claims=config["claims"],
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/paper_claims.py"


rule tradeoff_table:
    input:
        [summary_path(c) for c in spec_cases(config["tradeoff"], config)] if "tradeoff" in config else [],
    output:
        "results/tables/tradeoff.parquet",
    log:
        "logs/tradeoff_table.log",
    params:
        times=config.get("tradeoff", {}).get("times", []),
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/tradeoff_table.py"
