"""Run one Appendix-B shear-flow case (Fig. 10) from Snakemake wildcards -> step and state Parquet tables.

Wildcards: case (rw_nodrift, rw_drift, mt) and seed. Params: any ShearConfig fields, given
directly or inside dict-valued params (e.g. ``params: shear=config["shear"]``).
"""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from dataclasses import fields

from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.io import write_parquet
from particle_entropy.models.shear2d import ShearConfig, run_shear

keep_freed_pages()  # steps reuse the pages of the last step's arrays

settings = {}
for key, value in snakemake.params.items():
    settings.update(value if isinstance(value, dict) else {key: value})
names = {f.name for f in fields(ShearConfig)} - {"case", "seed"}
w = snakemake.wildcards
cfg = ShearConfig(case=w.case, seed=int(w.seed), **{k: v for k, v in settings.items() if k in names})
steps, state = run_shear(cfg, progress=lambda msg: print(msg, file=sys.stderr))
write_parquet(steps, snakemake.output.steps)
write_parquet(state, snakemake.output.state)
last = steps.iloc[-1]
print(
    f"{cfg.case} seed {cfg.seed}: wall_fraction {last.wall_fraction:.4f}, mass_total {last.mass_total:.15g}, "
    f"mass_min {steps.mass_min.min():.3g}, {steps.wall_s.sum():.1f} s",
    file=sys.stderr,
)
