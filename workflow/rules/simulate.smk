# One job per simulation case and block of seeds -> one tidy Parquet table (a `seed` column).


def sim_mem_mb(wildcards):
    return 300 + int(wildcards.n) // 20


def sim_runtime_min(wildcards):
    seeds = int(wildcards.last) - int(wildcards.first) + 1
    return seeds * (2 if int(wildcards.n) <= 3000 else 20)


def first_step(wildcards):
    """FD runs use their own fixed step (Fig. 8); particle runs start at dt0, or take the
    fixed step time.fixed_dt when their growth factor is 1."""
    if wildcards.method == "fd":
        return config["time"]["fd_dt"]
    return config["time"]["fixed_dt"] if float(wildcards.growth) == 1.0 else config["time"]["dt0"]


rule simulate:
    output:
        "results/runs/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.parquet",
    log:
        "logs/simulate/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.log",
    benchmark:
        "benchmarks/simulate/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.tsv"
    params:
        D=config["physics"]["D"],
        t_final=config["physics"]["t_final"],
        omega=config["physics"]["omega"],
        fd_length=config["physics"]["fd_length"],
        dt0=first_step,
    resources:
        mem_mb=sim_mem_mb,
        runtime=sim_runtime_min,
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/simulate.py"


rule snapshot:
    output:
        "results/snapshots/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.parquet",
    log:
        "logs/snapshot/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.log",
    benchmark:
        "benchmarks/snapshot/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.tsv"
    params:
        D=config["physics"]["D"],
        t_final=config["physics"]["t_final"],
        omega=config["physics"]["omega"],
        fd_length=config["physics"]["fd_length"],
        dt0=first_step,
    resources:
        mem_mb=sim_mem_mb,
        runtime=sim_runtime_min,
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/simulate.py"
