"""Compile the simulation kernels ahead of time for this CPU (numerics/compiled.py), once per
target: code, numba, CPU and numba's settings (a copy from this user's machine-wide cache where
another working directory built them, if that cache folder is sound and no one else can write
it): every simulate job then loads them instead of starting numba's JIT. Where they
cannot be built (no C compiler or Python headers in the job's environment), the folder is left
without a module and the jobs run numba's JIT, as before: slower to start, the same results."""

import sys
import traceback
from pathlib import Path

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.numerics.compiled import provide

try:
    print(f"{provide(snakemake.output[0])} the compiled kernels into {snakemake.output[0]}", file=sys.stderr)
except Exception:
    traceback.print_exc()
    Path(snakemake.output[0]).mkdir(parents=True, exist_ok=True)
    print("no compiled kernels: the simulate jobs run numba's JIT", file=sys.stderr)
