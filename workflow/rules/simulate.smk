# One job per simulation case and block of seeds -> one tidy Parquet table (a `seed` column).


rule simulate:
    output:
        "results/runs/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.parquet",
    log:
        "logs/simulate/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.log",
    benchmark:
        "results/benchmarks/simulate/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.tsv"
    params:
        D=config["physics"]["D"],
        t_final=config["physics"]["t_final"],
        omega=config["physics"]["omega"],
        fd_length=config["physics"]["fd_length"],
        dt0=first_step,
        transfer_method=config["numerics"]["transfer_method"],
        transfer_tolerance=config["numerics"]["transfer_tolerance"],
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
        "results/benchmarks/snapshot/{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}/seeds~{first}-{last}.tsv"
    params:
        D=config["physics"]["D"],
        t_final=config["physics"]["t_final"],
        omega=config["physics"]["omega"],
        fd_length=config["physics"]["fd_length"],
        dt0=first_step,
        transfer_method=config["numerics"]["transfer_method"],
        transfer_tolerance=config["numerics"]["transfer_tolerance"],
    resources:
        mem_mb=sim_mem_mb,
        runtime=sim_runtime_min,
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/simulate.py"
