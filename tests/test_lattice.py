"""Noise-free floors on evenly spaced particles: the lattice, and floors that do not depend on N
but do on the time step and on the kernel's truncation."""

from __future__ import annotations

import numpy as np
import pytest

from particle_entropy.core.runconfig import RunConfig
from particle_entropy.experiments.lattice import lattice_run, lattice_state


def floor(n=1001, **kw) -> float:
    return lattice_run(RunConfig.of(method="mtpt", kernel="collision", n=n, **kw), [1000.0])[-1]["SSE_over_N"]


def test_lattice_is_even_with_the_unit_mass_stored_first_at_zero():
    cfg = RunConfig.of(method="mtpt", n=11).resolved()
    x, m, label = lattice_state(cfg, np.random.default_rng(0))
    np.testing.assert_allclose(np.diff(x), 1.0)  # Omega = 10 over 10 gaps
    assert x[5] == 0.0 and m[5] == 1.0 and m.sum() == 1.0 and label[5] == 0
    assert sorted(label) == list(range(11))
    with pytest.raises(ValueError, match="odd"):
        lattice_state(RunConfig.of(method="mtpt", n=10).resolved(), np.random.default_rng(0))


def test_lattice_run_refuses_random_walks():
    with pytest.raises(ValueError, match="eta = 1"):
        lattice_run(RunConfig.of(method="mtpt", n=11, eta=0.5), [1.0])


def test_the_equations_floor_does_not_depend_on_n_and_falls_with_the_time_step():
    coarse, fine = floor(1001), floor(3001)
    assert fine == pytest.approx(coarse, rel=0.01)  # no sampling error left: the same floor
    smaller_steps = floor(1001, dt_growth=1.01)
    assert smaller_steps < coarse / 10  # the floor is the time step's


def test_a_cut_kernel_raises_the_floor_and_widening_it_brings_it_back():
    whole = floor()
    cut = floor(truncation=3.0)
    widened = floor(truncation=3.0, scheme="compensated")
    assert cut > 4 * whole
    assert widened == pytest.approx(whole, rel=0.25)
    assert floor(truncation=3.0, scheme="sequential") > 1.5 * cut  # the authors' loop adds its own
