"""heap.keep_freed_pages: a step's freed arrays give their pages to the next step's."""

import subprocess
import sys

import pytest

CHILD = r"""
import resource, sys
import numpy as np
from particle_entropy.core.heap import keep_freed_pages
if sys.argv[1] == "keep":
    assert keep_freed_pages()
def step():  # a step's work arrays at N = 30,000: twelve of 240 kB, freed at its end
    arrays = [np.ones(30000) for _ in range(12)]
    return sum(float(a[0]) for a in arrays)
for _ in range(3):
    step()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    step()
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def faults(mode: str) -> int:
    out = subprocess.run([sys.executable, "-c", CHILD, mode], capture_output=True, text=True, check=True)
    return int(out.stdout)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="mallopt is glibc's")
def test_steps_reuse_pages_only_when_kept():
    pages = 20 * 12 * (30000 * 8 // 4096)  # one fault per page of every array of 20 steps
    assert faults("default") > pages // 2  # the default gives the pages back each step
    assert faults("keep") < pages // 50
