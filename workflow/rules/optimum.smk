# Adaptive searches for the N minimising mean COMIC (config `optimum`, optimum.py): each round is
# a checkpoint whose plan names the seed blocks to run next; every block is an ordinary
# `simulate` job, so runs are cached and shared. Their own target: `snakemake -j2 optimum`.


# One round: round 0 is the coarse grid, round k the plan after reading plan k-1's runs.
checkpoint optimum_round:
    input:
        unpack(optimum_round_inputs),
    output:
        "results/optimum/{name}/round~{k}.parquet",
    log:
        "logs/optimum/{name}/round~{k}.log",
    benchmark:
        "results/benchmarks/optimum_round/{name}/round~{k}.tsv"
    wildcard_constraints:
        name=r"[A-Za-z0-9_]+",
        k=r"\d+",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        spec=lambda w: config["optimum"][w.name],
        settings=optimum_settings,
        base_seed=config["base_seed"],
        code=script_code(SCRIPTS / "optimum_round.py"),
    script:
        "../scripts/optimum_round.py"


# A finished search: every visited N, the optimum, its bracket and the cost.
rule optimum_table:
    input:
        unpack(optimum_final_inputs),
    output:
        "results/optimum/{name}.parquet",
    log:
        "logs/optimum/{name}.log",
    benchmark:
        "results/benchmarks/optimum_table/{name}.tsv"
    wildcard_constraints:
        name=r"[A-Za-z0-9_]+",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        spec=lambda w: config["optimum"][w.name],
        settings=optimum_settings,
        code=script_code(SCRIPTS / "optimum_table.py"),
    script:
        "../scripts/optimum_table.py"


rule plot_optimum:
    input:
        "results/optimum/{name}.parquet",
    output:
        png=report(
            "figures/optimum_{name}.png",
            caption="../report/optimum.rst",
            category=FIGURE["optimum"].category,
            labels=figure_labels("optimum_{name}", "plot_optimum", "results/optimum/{name}.parquet", "optimum"),
        ),
        pdf="figures/optimum_{name}.pdf",
    log:
        "logs/plot/optimum_{name}.log",
    benchmark:
        "results/benchmarks/plot/optimum_{name}.tsv"
    wildcard_constraints:
        name=r"[A-Za-z0-9_]+",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    resources:
        mem_mb=1000,
    params:
        code=script_code(SCRIPTS / "plot_optimum.py"),
    script:
        "../scripts/plot_optimum.py"


# Every configured search: `snakemake -j2 optimum` (not part of the default target).
rule optimum:
    input:
        expand("results/optimum/{name}.parquet", name=OPTIMUM),
        expand("figures/optimum_{name}.{ext}", name=OPTIMUM, ext=("png", "pdf")),
    localrule: True
