# One job per simulation: (method, kernel, N, eta, truncation, dt growth, seed) -> Parquet.


def sim_mem_mb(wildcards):
    return 300 + int(wildcards.n) // 20


def sim_runtime_min(wildcards):
    n = int(wildcards.n)
    return 5 if n <= 3000 else 30


rule simulate:
    output:
        "results/runs/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seed~{seed}.parquet",
    log:
        "logs/simulate/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seed~{seed}.log",
    benchmark:
        "benchmarks/simulate/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seed~{seed}.tsv"
    params:
        physics=config["physics"],
        time=config["time"],
    resources:
        mem_mb=sim_mem_mb,
        runtime=sim_runtime_min,
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/simulate.py"


rule snapshot:
    output:
        "results/snapshots/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seed~{seed}.parquet",
    log:
        "logs/snapshot/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seed~{seed}.log",
    benchmark:
        "benchmarks/snapshot/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seed~{seed}.tsv"
    params:
        physics=config["physics"],
        time=config["time"],
    resources:
        mem_mb=sim_mem_mb,
        runtime=sim_runtime_min,
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/simulate.py"
