# Reproduces every figure of Benson et al. (2020), "Entropy: (1) The former trouble with
# particle-tracking simulation, and (2) A measure of computational information penalty".
import sys
from pathlib import Path

from snakemake.utils import min_version

min_version("8.0")
sys.path.insert(0, str(Path(workflow.basedir) / "workflow" / "lib"))
from particle_entropy.pipeline.configcheck import load_yaml

# Snakemake's loader does not say where a YAML error is, keeps the last of two equal keys and runs
# a file with __use_yte__ as a template (code): config.yaml is checked before it is loaded; a
# --configfile was loaded (and any template run) before this file, so it is refused here after
# the fact (the README: a --configfile is trusted like the Snakefile).
for _config_file in (["config.yaml"] if Path("config.yaml").exists() else []) + list(workflow.overwrite_configfiles):
    load_yaml(_config_file)


configfile: "config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/summarise.smk"
include: "workflow/rules/aggregate.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/shear.smk"
include: "workflow/rules/mechanism.smk"
include: "workflow/rules/optimum.smk"
include: "workflow/rules/scenes.smk"


rule all:
    default_target: True
    input:
        all_targets(),


onerror:
    from particle_entropy.pipeline.verify import disk_space_problems

    for problem in disk_space_problems((".", "results", ".snakemake")):
        print(problem, file=sys.stderr)
