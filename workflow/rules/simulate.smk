# One job per simulation case and block of seeds -> one tidy Parquet table (a `seed` column).
# kind: runs = one row per time step; snapshots = the final particle or grid states (Fig. 7).
# Each job loads the kernels compile_kernels built ahead of time for this code, numba and CPU
# (numerics/compiled.py), so that it imports no numba: a small job costs what it computes. They
# are rebuilt when that target changes (params); a job never reruns for it (ancient), and one
# whose module is not for its target, or fails its digest, runs numba's JIT: the same bits.
# A checkpoint, so that Snakemake judges the jobs after it again once it is done: while a job
# reruns, Snakemake does not look at the jobs that take its output as `ancient` input, and would
# end the run "100% done" without the simulations still to make.


checkpoint compile_kernels:
    output:
        directory(KERNELS),
    log:
        f"logs/compile_kernels/{KERNEL_TARGET}.log",
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        target=KERNEL_TARGET,
    script:
        "../scripts/compile_kernels.py"


rule simulate:
    input:
        kernels=ancient(KERNELS),  # rebuilt per target; neither its age nor its target reruns a job
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
