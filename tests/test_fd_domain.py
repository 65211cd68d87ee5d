"""Fig. 8's late error rise is the zero-concentration ends of [-6, 6] (particle_entropy.experiments.fd_domain).

Each test changes one setting of the paper's run (domain length at the same dx, time step, or the
reference of the SSE) and checks what the boundary explanation predicts; the tests fail if the rise
came from the time step, the normalisation of the reference or the grid instead.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import gaussian

from particle_entropy.core.runconfig import RunConfig
from particle_entropy.experiments import fd_domain as F
from particle_entropy.models.simulate import run

D = 1e-3
TIMES = (250.0, 800.0, 1000.0)


def _at(table, n, time, fd_length=12.0, fd_dt=0.05, reference="unit", column="ln_SSE_over_N"):
    row = table[
        (table.n == n)
        & (table.time == time)
        & (table.fd_length == fd_length)
        & (table.fd_dt == fd_dt)
        & (table.reference == reference)
    ]
    assert len(row) == 1
    return float(row[column].iloc[0])


@pytest.fixture(scope="module")
def paper_dt():
    """Grids 300..10000 (dx = 12/n) on lengths 12 and 24, dt = 0.05, every reference (~5 s)."""
    return F.domain_experiment((300, 1000, 3000, 10000), (12.0, 24.0), (0.05,), TIMES, references=F.REFERENCES)


# --------------------------------------------------------------------------- the module itself
def test_run_case_is_the_workflow_fd_run():
    """Same solver, grid, initial delta and measures as simulate.run (Fig. 8's runs)."""
    tab, _ = run(RunConfig.of(method="fd", kernel="implicit", n=100, t_final=20.0))
    rows = F.run_case(100, times=(5.0, 20.0))
    for r in rows:
        s = tab.loc[np.isclose(tab.time, r["time"])].iloc[0]
        assert r["SSE"] == pytest.approx(s["SSE"], rel=1e-6)
        assert r["COMIC"] == pytest.approx(s["COMIC"], abs=1e-6)
        assert r["mass_total"] == pytest.approx(s["mass_total"], abs=1e-14)
        assert r["n_sse"] == s["n_sse"] == 101


def test_longer_domain_keeps_dx_and_the_centre_nodes():
    rows = F.run_case(100, fd_length=24.0, times=(1.0,))
    assert rows[0]["n_intervals"] == 200 and rows[0]["dx"] == pytest.approx(0.12)
    with pytest.raises(ValueError):
        F.run_case(30, fd_length=18.0, times=(1.0,))  # 45 intervals: no node at x = 0
    with pytest.raises(ValueError):
        F.run_case(100, times=(0.03,))  # not a whole number of steps


def test_references():
    x = np.linspace(-6.0, 6.0, 3001)
    dx = x[1] - x[0]
    t = 1000.0
    unit = F.reference(x, D, t, dx, 12.0, "unit")
    exact = F.reference(x, D, t, dx, 12.0, "exact")
    images = F.reference(x, D, t, dx, 12.0, "images")
    assert unit.sum() * dx == pytest.approx(1.0, abs=1e-13)
    # exact: the Gaussian with its own normalisation; unit lifts it by 1 / erf(6 / sqrt(4 D t))
    np.testing.assert_allclose(exact, gaussian(x, D, t), rtol=1e-12)
    assert unit[1500] / exact[1500] - 1.0 == pytest.approx(1.0 / math.erf(6.0 / math.sqrt(4 * D * t)) - 1.0, rel=0.02)
    # images: zero at the walls, and the mass the absorbing walls leave, 1 - 2 erfc(a / sqrt(4 D t))
    assert abs(images[0]) < 1e-12 and abs(images[-1]) < 1e-12
    assert images.sum() * dx == pytest.approx(1.0 - 2.0 * math.erfc(6.0 / math.sqrt(4 * D * t)), abs=1e-8)
    np.testing.assert_allclose(F.reference(x, D, t, dx, 12.0, "fd_mass", 0.5), 0.5 * unit)


# --------------------------------------------------------------------------- the cause
def test_error_of_fine_grid_turns_up_on_length_12_only(paper_dt):
    for n in (3000, 10000):
        e12 = [_at(paper_dt, n, t) for t in TIMES]
        e24 = [_at(paper_dt, n, t, fd_length=24.0) for t in TIMES]
        assert e12[2] > e12[1] + 1.0  # Fig. 8: up by > 1 (~1.6) from t = 800 to 1000
        assert e24[0] > e24[1] > e24[2]  # the same grid on [-12, 12] keeps improving
        assert e24[1] - e24[2] > 0.4  # ... at the Gaussian's own rate (~0.55 per 200 T)
        # early, the walls do nothing: length 24 only adds ln 2 (twice the nodes, zero error there)
        assert e12[0] - e24[0] == pytest.approx(math.log(2.0), abs=0.01)


def test_comic_optimum_moves_only_with_the_walls(paper_dt):
    best = F.comic_optimum(paper_dt).set_index(["fd_length", "reference", "time"])["n"]
    assert best[(12.0, "unit", 250.0)] == 3000 and best[(24.0, "unit", 250.0)] == 3000
    assert best[(12.0, "unit", 1000.0)] == 1000  # the paper's shift to N = 1000 at t = 1000
    assert best[(24.0, "unit", 1000.0)] == 3000  # gone on the longer domain
    assert best[(12.0, "images", 1000.0)] == 3000  # and against the bounded problem's solution


def test_fd_on_length_12_solves_the_bounded_problem(paper_dt):
    """Against the exact solution with zero ends (images) the length-12 error is that of length
    24 against the free Gaussian: the FD is right, the walls make a different problem."""
    for n in (1000, 3000, 10000):
        for t in TIMES:
            e12_images = _at(paper_dt, n, t, reference="images")
            e24 = _at(paper_dt, n, t, fd_length=24.0)
            assert e12_images - e24 == pytest.approx(math.log(2.0), abs=0.02)


def test_late_error_sits_at_the_walls(paper_dt):
    for n in (3000, 10000):
        assert _at(paper_dt, n, 1000.0, column="edge_fraction") > 0.6  # |x| > 4: ~0.79
        assert _at(paper_dt, n, 1000.0, column="x_max_error") == pytest.approx(6.0)
        assert _at(paper_dt, n, 1000.0, fd_length=24.0, column="edge_fraction") < 0.05
        assert _at(paper_dt, n, 250.0, column="edge_fraction") < 1e-3


def test_mass_leaves_through_the_walls(paper_dt):
    """Absorbing ends at +-a lose 2 erfc(a / sqrt(4 D t)) (reflection principle): 4.4e-5 at t = 1000."""
    lost = 2.0 * math.erfc(6.0 / math.sqrt(4 * D * 1000.0))
    for n in (1000, 3000, 10000):
        assert _at(paper_dt, n, 1000.0, column="mass_loss") == pytest.approx(lost, rel=0.01)
        assert abs(_at(paper_dt, n, 1000.0, fd_length=24.0, column="mass_loss")) < 1e-8
        assert abs(_at(paper_dt, n, 250.0, column="mass_loss")) < 1e-9  # round-off of 5000 solves


# --------------------------------------------------------------------------- not the cause
def test_not_the_normalisation_of_the_reference(paper_dt):
    """Neither the Gaussian's own mass nor the FD's mass as the reference's removes the rise."""
    for ref in ("exact", "fd_mass"):
        for n in (3000, 10000):
            assert _at(paper_dt, n, 1000.0, reference=ref) > _at(paper_dt, n, 800.0, reference=ref) + 1.0
        best = F.comic_optimum(paper_dt).set_index(["fd_length", "reference", "time"])["n"]
        assert best[(12.0, ref, 1000.0)] == 1000


def test_not_the_time_step():
    """dt / 4: the fine grid's error drops by ~ln 16 on [-12, 12] (first order in time: it is the
    floor of the fine grids), but on [-6, 6] the late rise stays, and grows."""
    tab = F.domain_experiment((1000,), (12.0, 24.0), (0.05, 0.0125), (800.0, 1000.0))
    coarse_dt = _at(tab, 1000, 1000.0, fd_length=24.0)
    fine_dt = _at(tab, 1000, 1000.0, fd_length=24.0, fd_dt=0.0125)
    assert 1.0 < coarse_dt - fine_dt < math.log(16.0)  # dx^2 error of N = 1000 left below the time error
    assert _at(tab, 1000, 1000.0, fd_dt=0.0125) > _at(tab, 1000, 800.0, fd_dt=0.0125) + 2.0
    assert _at(tab, 1000, 1000.0, fd_length=24.0, fd_dt=0.0125) < _at(tab, 1000, 800.0, fd_length=24.0, fd_dt=0.0125)
