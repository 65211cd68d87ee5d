"""The numbers the README quotes (the scene table, the Peclet sweep and its crossover), from the
finished scene tables: the file docs/numbers.json holds, written by `prose --from results --write`."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from pathlib import Path

from particle_entropy.core.io import exit_on_table_errors, read_parquet
from particle_entropy.pipeline.prose import dump, numbers_from_tables

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

text = dump(numbers_from_tables([read_parquet(p) for p in snakemake.input]))
Path(snakemake.output[0]).write_text(text, encoding="utf-8")
print(text, file=sys.stderr)
