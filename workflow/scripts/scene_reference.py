"""A reactive scene's reference at t_final, once per physics digest (scenes/reference.py)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.scenes.reference import write

write(dict(snakemake.params.physics), snakemake.output[0])
print(open(snakemake.output[0]).read()[:2000], file=sys.stderr)
