# A finished run as a Workflow Run RO-Crate (pipeline/crate.py), for a repository to ingest:
# `snakemake -j2 crate` completes the default target, then writes results/ro-crate/. Not part of
# the default target.


rule crate:
    input:
        all_targets(),
    output:
        # update: Snakemake keeps the old metadata for the job, which keeps what a person added to it;
        # the crate's other files are links, kept where they hold
        update(f"{CRATE_DIR}/{CRATE_METADATA}"),
    log:
        "logs/crate.log",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        checkout=workflow.basedir,
        coded=lambda w: inputs.coded_rules(workflow.rules),
        optional=lambda w: inputs.beyond_default_target(workflow.rules),
        code=script_code(SCRIPTS / "crate.py"),
    script:
        "../scripts/crate.py"
