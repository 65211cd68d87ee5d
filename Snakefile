# Reproduces every figure of Benson et al. (2020), "Entropy: (1) The former trouble with
# particle-tracking simulation, and (2) A measure of computational information penalty".
import sys
from pathlib import Path

from snakemake.utils import min_version

min_version("8.0")
sys.path.insert(0, str(Path(workflow.basedir) / "workflow" / "lib"))
from particle_entropy.pipeline.configcheck import load_yaml

# Snakemake's loader does not say where a YAML error is, keeps the last of two equal keys, reads
# 010 as 8 and 1:30 as 90, expands alias bombs and reads pipes and devices without end, and runs a
# file with __use_yte__ as a template (code): config.yaml is checked (load_yaml: a regular file of
# at most 1 MB, as written) before it is loaded. A --configfile was loaded, by Snakemake's command
# line before this file runs, so it is refused here after the fact; one Snakemake cannot load at all
# (missing, a folder, not UTF-8, nested too deep, a pipe, a device) stops there with Snakemake's own
# error (docs/running.md: "Config files"). The README: a --configfile is trusted like the Snakefile.
for _config_file in (["config.yaml"] if Path("config.yaml").exists() else []) + list(workflow.overwrite_configfiles):
    load_yaml(_config_file)


configfile: "config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/search.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/summarise.smk"
include: "workflow/rules/aggregate.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/shear.smk"
include: "workflow/rules/mechanism.smk"
include: "workflow/rules/optimum.smk"
include: "workflow/rules/scenes.smk"
include: "workflow/rules/crate.smk"


rule all:
    default_target: True
    input:
        all_targets(),


# Each run of jobs records the commit it runs at, whether tracked files differed, and the config's
# digest; the crate gives every job the record of the run it started in (pipeline/crate.py).
onstart:
    RUN_RECORDS.append(start_session(workflow.basedir, config))


onsuccess:
    for record in RUN_RECORDS:
        end_session(record)
    # Snakemake can end a run "100% done" with a target unmade (a rerun job with an ancient output
    # hides the jobs after it): a run exits 0 only when every requested target is there.
    if unmade := unmade_targets(workflow.dag):
        raise WorkflowError(
            f"the run ended without making {len(unmade)} of its targets: {', '.join(unmade[:5])}"
            + (" ..." if len(unmade) > 5 else "")
            + "; run the same command again"
        )


onerror:
    for record in RUN_RECORDS:
        end_session(record)
    from particle_entropy.pipeline.joblogs import unshown_job_logs
    from particle_entropy.pipeline.verify import disk_space_problems

    # Snakemake's report stops at a failed job's first empty log: a SLURM job's error may follow it.
    for line in unshown_job_logs(log):
        print(line, file=sys.stderr)
    for problem in disk_space_problems((".", "results", ".snakemake")):
        print(problem, file=sys.stderr)
