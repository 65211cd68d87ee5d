"""A finished scene: every visited (candidate, resolution) with its error, interval, cost and COMIC,
the recommendation and the COMIC-best."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.scene_search import judged, result
from particle_entropy.analysis.search import runs_in
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.scenes.scene import Scene

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par = snakemake.input, snakemake.params
scene = Scene.from_config(snakemake.wildcards.name, par.spec, par.case_defaults)
plan = read_parquet(inp.plan)
reference, why = None, ""
if scene.reaction is not None:  # judged against its reference, which may leave the target undefined
    from particle_entropy.scenes.defined import undefined
    from particle_entropy.scenes.reference import read

    reference = read(inp.reference)
    why = undefined(scene.measure, scene.value, reference)
runs = read_parquet(inp.read)  # what the finished plan's round read: every run of it (AdaptiveSearch.final_inputs)
if len(runs) != runs_in(plan):
    raise RuntimeError(f"{inp.read}: {len(runs)} runs read, where the finished plan {inp.plan} has {runs_in(plan)}")
table = result(scene, judged(scene, runs), why)
if reference is not None:  # the product over time, each rung's and the reference's (panel b)
    from particle_entropy.analysis.scene_search import with_reference

    table = with_reference(scene, table, plan, list(inp.runs), reference)
write_parquet(table, snakemake.output[0])
print(table.to_string(), file=sys.stderr)
