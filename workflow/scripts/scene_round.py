"""One round of a scene's search: round 0 plans each candidate's lowest rung; round k reads the runs
of plan k-1 (those plan k-2 had through what round k-1 read: input `read`) and writes the next plan
(done when every candidate has stopped) and what it read (output `read`)."""

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
search = SceneSearch(scene, reference)
if plan is None:
    plan = search.first_plan(int(par.base_seed))
    runs = search.read_runs(plan.iloc[:0], [])  # none yet
else:
    earlier = read_parquet(inp.read) if "read" in inp.keys() else None
    runs = search.runs_since(plan, list(inp.runs), earlier)
    plan = search.next_plan(plan, runs, int(par.base_seed))  # the search engine's round
write_parquet(plan, out.plan)
write_parquet(runs, out.read)
print(plan.to_string(), file=sys.stderr)
