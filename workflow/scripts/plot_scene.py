"""Draw one scene's figure from its table; a 2-D scene's with its maps, the model's final state run
here once (figures/scene_maps.model_run: the recommended rung on the scene's first seed)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

from particle_entropy.core.io import exit_on_table_errors, read_parquet
from particle_entropy.figures.scene import scene
from particle_entropy.figures.style import save_figure
from particle_entropy.scenes.scene import Scene

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

table, par = read_parquet(snakemake.input[0]), snakemake.params
built, maps, profile = Scene.from_config(snakemake.wildcards.name, par.spec, par.case_defaults), None, None
if built.dim == 2:  # its maps: the model's final state, run here
    from particle_entropy.figures.scene_maps import model_run

    run = model_run(built, table, par.base_seed)
    if run is not None:
        print(f"map of {run.row['label']} at n = {run.row['n']}: run in {run.wall_s:.2f} s", file=sys.stderr)
    maps = (built, run)
    if built.release is not None:  # and the plume's axis: the recommended and each FD scheme's best rung
        from particle_entropy.figures.scene_profile import profile_runs

        profile = profile_runs(built, table, par.base_seed, [run])
figure = scene(table, maps, profile)
if profile is not None:
    for label in figure.profile.models:
        print(f"along the axis, {label}: max |error| {figure.profile.max_error(label):.4g} beyond B", file=sys.stderr)
save_figure(figure, snakemake.output.png, snakemake.output.pdf)
