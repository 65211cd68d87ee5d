# Reproduces every figure of Benson et al. (2020), "Entropy: (1) The former trouble with
# particle-tracking simulation, and (2) A measure of computational information penalty".
from snakemake.utils import min_version

min_version("8.0")


configfile: "config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/aggregate.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/shear.smk"
include: "workflow/rules/mechanism.smk"


rule all:
    default_target: True
    input:
        all_targets(),
