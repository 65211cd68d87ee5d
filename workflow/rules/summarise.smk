# Ensembles -> per-step means and standard deviations, one summary per case. This file holds
# this rule alone: its text is part of the summaries' code hash (common.smk SUMMARY_CODE), so an
# edit to another rule reruns no summary.


# Averages the realisations of one case, step by step. A `run:` block: with the default
# profile (force-use-threads) it runs inside the Snakemake process, saving a Python
# start-up (~1 s of CPU) for each of the ~90 summaries.
rule summarise_case:
    input:
        summary_runs,
    output:
        SUMMARY_PATTERN,
    log:
        f"logs/summarise_case/{CASE_DIR}/r~{{nreal}}.log",
    localrule: True
    resources:
        mem_mb=500,
    params:
        code=SUMMARY_CODE,
    run:
        from particle_entropy.analysis.aggregate import summarise_files  # pandas: not at parse

        count = summarise_files(list(input), output[0])
        Path(log[0]).write_text(f"summarised {count} realisations\n")
