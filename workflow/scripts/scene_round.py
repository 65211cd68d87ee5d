"""One round of a scene's search: round 0 plans each candidate's lowest rung; round k reads the runs
of plan k-1 and writes the next plan (done when every candidate has stopped)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.scene_search import SceneSearch
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.scenes.scene import Scene

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par, out = snakemake.input, snakemake.params, snakemake.output
scene = Scene.from_config(snakemake.wildcards.name, par.spec, par.case_defaults)
plan = read_parquet(inp.plan) if "plan" in inp.keys() else None
reference = None
if "reference" in inp.keys():  # a reactive scene's: a target it cannot judge stops the search at once
    from particle_entropy.scenes.reference import read

    reference = read(inp.reference)
plan = SceneSearch(scene, reference).round(
    plan, list(inp.runs) if plan is not None else [], int(par.base_seed)
)  # the search engine's round
write_parquet(plan, out[0])
print(plan.to_string(), file=sys.stderr)
