# One job per simulation case and block of seeds -> one tidy Parquet table (a `seed` column).
# kind: runs = one row per time step; snapshots = the final particle or grid states (Fig. 7).
# Each job loads the kernels compiled ahead of time for this code, numba and CPU, which the first
# job to need them builds (numerics/compiled.take), so that it imports no numba: a small job costs
# what it computes. They are no input: no simulation reruns when they are rebuilt.


rule simulate:
    output:
        RUN_PATTERN,
    log:
        f"logs/simulate/{{kind}}/{CASE_DIR}/seeds~{{first}}-{{last}}.log",
    benchmark:
        f"results/benchmarks/simulate/{{kind}}/{CASE_DIR}/seeds~{{first}}-{{last}}.tsv"
    priority: sim_priority  # the longest first (jobcost.estimated_seconds)
    conda:
        "../../envs/particle-entropy.yaml"
    resources:
        mem_mb=sim_mem_mb,
        runtime=sim_runtime_min,
    params:
        settings=sim_settings,
        code=lambda w: SIM_CODE[w.method],
    script:
        "../scripts/simulate.py"
