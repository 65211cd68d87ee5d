# One job per simulation case and block of seeds -> one tidy Parquet table (a `seed` column).
# kind: runs = one row per time step; snapshots = the final particle or grid states (Fig. 7).
# Each job loads the kernels compiled ahead of time for this code, numba and CPU, which the first
# job to need them builds (numerics/compiled.take), so that it imports no numba: a small job costs
# what it computes. They are no input: no simulation reruns when they are rebuilt.

# The code of a job: simulate.py, what it imports and its method's module, not the other methods'
# (codeversion.simulation_code); simulate_scene (scenes.smk), conservative or reactive, runs the same code.
SIM_CODE = {m: simulation_code(m, METHODS, SCRIPTS / "simulate.py") for m in METHODS}


rule simulate:
    output:
        RUN_PATTERN,
    log:
        f"logs/simulate/{{kind}}/{CASE_DIR}/seeds~{{first}}-{{last}}.log",
    benchmark:
        f"results/benchmarks/simulate/{{kind}}/{CASE_DIR}/seeds~{{first}}-{{last}}.tsv"
    priority: INPUTS.sim_priority  # the longest first (jobcost.estimated_seconds)
    conda:
        "../../envs/particle-entropy.yaml"
    resources:
        mem_mb=INPUTS.sim_mem_mb,
        runtime=INPUTS.sim_runtime_min,
    params:
        settings=INPUTS.sim_settings,
        code=lambda w: SIM_CODE[w.method],
    script:
        "../scripts/simulate.py"
