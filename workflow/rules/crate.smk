# A finished run as a Workflow Run RO-Crate (pipeline/crate.py), for a repository to ingest:
# `snakemake -j2 crate` completes the default target, then writes results/ro-crate/. Not part of
# the default target.


def beyond_default_target():
    """This config's targets outside the default one (its scenes and optimum searches, the
    mechanism figure): the crate describes those a run of this same config made."""
    by_name = {r.name: r for r in workflow.rules}
    found = [str(f) for name in ("scenes", "optimum") if name in by_name for f in by_name[name].input]
    if "plot_fig9_mechanism" in by_name:
        found += [str(f) for f in by_name["plot_fig9_mechanism"].output]
    return found


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
        coded=lambda w: coded_rules(workflow.rules),
        optional=lambda w: beyond_default_target(),
        code=CRATE_CODE,
    script:
        "../scripts/crate.py"
