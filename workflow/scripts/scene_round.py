"""One round of a scene's search: round 0 plans each candidate's lowest rung; round k reads the runs
of plan k-1 and writes the next plan (done when every candidate has stopped)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.scene_search import next_plan, read_runs
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.experiments.scene import Scene

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par, out = snakemake.input, snakemake.params, snakemake.output
scene = Scene.from_config(snakemake.wildcards.name, par.spec, par.case_defaults)
if "plan" in inp.keys():
    plan = read_parquet(inp.plan)
    plan = next_plan(scene, plan, read_runs(plan, list(inp.runs)), int(par.base_seed))
else:
    plan = next_plan(scene, None, None, int(par.base_seed))
write_parquet(plan, out[0])
print(plan.to_string(), file=sys.stderr)
