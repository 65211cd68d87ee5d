# Reproduces every figure of Benson et al. (2020), "Entropy: (1) The former trouble with
# particle-tracking simulation, and (2) A measure of computational information penalty".
import sys
from pathlib import Path

from snakemake.utils import min_version

min_version("8.0")
sys.path.insert(0, str(Path(workflow.basedir) / "workflow" / "lib"))
from particle_entropy.pipeline.configcheck import load_yaml

if Path("config.yaml").exists():  # Snakemake's loader does not say where a YAML error is
    load_yaml("config.yaml")


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


rule all:
    default_target: True
    input:
        all_targets(),


onerror:
    from particle_entropy.core.verify import disk_space_problem

    problem = disk_space_problem(".")
    if problem:
        print(problem, file=sys.stderr)
