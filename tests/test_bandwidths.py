"""Kernel widths and the transfer coefficient against the paper's formulas with literal numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.core.registry import SCHEME_RECORDS
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.sources import Source
from particle_entropy.models.mtpt import kernel_for_step
from particle_entropy.models.pt import reconstruction_width
from particle_entropy.models.simulate import run
from particle_entropy.numerics.bandwidths import (
    beta_sph,
    collision_sigma,
    gaussian_pdf,
    h_de,
    h_sph,
    truncated_variance_fraction,
)


def test_h_de_eq23():
    # h_DE = 1.06 N^(-1/5) sqrt(2 D t), N = 300, D = 1e-3, t = 1000: the point's variance 2 D t = 2
    expected = 1.06 * 300 ** (-1 / 5) * math.sqrt(2 * 1e-3 * 1000)
    assert h_de(300, 2.0) == pytest.approx(expected, rel=1e-14)
    # by hand: 300^(-0.2) = 0.319577, sqrt(2) = 1.414214 -> 0.479067
    assert h_de(300, 2.0) == pytest.approx(0.479067, abs=2e-6)
    # N = 30000, t = 10: 1.06 * 30000^(-0.2) * sqrt(0.02)
    assert h_de(30000, 0.02) == pytest.approx(1.06 * 30000**-0.2 * math.sqrt(0.02), rel=1e-14)
    assert h_de(300, 0.0) == 0.0


def test_h_sph_eq26():
    # h_SPH = 0.82 (2 D t)^(2/5) (N / Omega)^(-1/5), N = 300, Omega = 10, D = 1e-3, t = 1000 (2 D t = 2)
    expected = 0.82 * (2 * 1e-3 * 1000) ** 0.4 * (300 / 10) ** -0.2
    assert h_sph(300, 10.0, 2.0) == pytest.approx(expected, rel=1e-14)
    # by hand: 0.82 * 2^0.4 (1.319508) * 30^(-0.2) (0.506496) -> 0.548027
    assert h_sph(300, 10.0, 2.0) == pytest.approx(0.548027, abs=2e-6)
    # scaling: t^(2/5) (variance 2 D t) and rho^(-1/5)
    assert h_sph(300, 10.0, 64.0) / h_sph(300, 10.0, 2.0) == pytest.approx(4.0, rel=1e-13)
    assert h_sph(32 * 300, 10.0, 2.0) / h_sph(300, 10.0, 2.0) == pytest.approx(0.5, rel=1e-13)
    assert h_sph(300, 10.0, 2.0) == pytest.approx(h_sph(3000, 100.0, 2.0), rel=1e-14)


def test_collision_sigma_eq17():
    """Eq. 17: exp(-r^2 / (8 eta D dt)) is a Gaussian of variance 4 eta D dt."""
    eta, D, dt = 0.5, 1e-3, 2.0
    s = collision_sigma(eta, D, dt)
    assert s * s == pytest.approx(4 * 0.5 * 1e-3 * 2.0, rel=1e-14)  # = 0.004
    assert s == pytest.approx(0.0632455532, abs=1e-10)
    r = np.linspace(0, 0.3, 7)
    np.testing.assert_allclose(np.exp(-(r**2) / (2 * s * s)), np.exp(-(r**2) / (8 * eta * D * dt)), rtol=1e-14)
    assert collision_sigma(1.0, 1e-3, 0.01) == pytest.approx(math.sqrt(4e-5), rel=1e-14)
    assert collision_sigma(0.0, 1e-3, 0.01) == 0.0


def test_beta_sph_eq20():
    # beta = 2 eta D dt / h^2 with eta = 0.1, D = 1e-3, dt = 47.6, h = 0.548
    assert beta_sph(0.1, 1e-3, 47.6, 0.548) == pytest.approx(2 * 0.1 * 1e-3 * 47.6 / 0.548**2, rel=1e-14)
    assert beta_sph(0.1, 1e-3, 47.6, 0.548) == pytest.approx(0.031701, abs=1e-6)
    # the variance moved per step, beta h^2, is 2 eta D dt whatever h is
    for h in (0.01, 0.3, 5.0):
        assert beta_sph(1.0, 1e-3, 0.5, h) * h * h == pytest.approx(1e-3, rel=1e-14)


def test_collision_kernel_moves_the_same_variance_as_sph():
    """beta * kernel variance = 2 eta D dt for both kernels (collision: beta = 1/2)."""
    eta, D, dt = 0.7, 1e-3, 3.0
    assert 0.5 * collision_sigma(eta, D, dt) ** 2 == pytest.approx(2 * eta * D * dt, rel=1e-14)


@pytest.mark.parametrize("var", [1e-4, 1.0, 9.0])
def test_gaussian_pdf_moments(var):
    s = math.sqrt(var)
    dx = s / 100
    x = np.arange(-12 * s, 12 * s + dx / 2, dx)
    g = gaussian_pdf(x, var)
    assert g.sum() * dx == pytest.approx(1.0, rel=1e-12)
    assert (g * x * x).sum() * dx == pytest.approx(var, rel=1e-12)
    assert gaussian_pdf(np.array([0.0]), var)[0] == pytest.approx(1 / math.sqrt(2 * math.pi * var), rel=1e-14)


@pytest.mark.parametrize("k", [1.0, 2.0, 3.0, 4.5])
def test_truncated_variance_fraction_equals_the_truncated_normal_variance(k):
    from scipy.stats import truncnorm

    assert truncated_variance_fraction(k) == pytest.approx(truncnorm.var(-k, k), rel=1e-12)


def test_truncated_variance_fraction_at_three_widths_and_whole():
    assert truncated_variance_fraction(3.0) == pytest.approx(0.9733, abs=5e-5)  # the 2.7 % the issue names
    assert truncated_variance_fraction(None) == 1.0


def _box_run(method: str, kernel: str, width: float, **settings) -> RunConfig:
    source = Source.of("box", a=-0.5 * width, b=0.5 * width)
    return RunConfig.of(method=method, kernel=kernel, n=300, omega=10.0, source=source, **settings)


@pytest.mark.parametrize("D, t", [(1e-3, 72.0), (1e-4, 1.0), (1e-3, 1000.0)])
def test_adaptive_bandwidths_follow_the_plume_not_the_point(D, t):
    """PT's h_DE and MTPT's h_SPH of a box of width 0.5 take the plume's variance, 0.5^2 / 12 + 2 D t:
    sqrt(1 + 0.5^2 / (24 D t)) times the point's h_DE (7 % at D t = 0.072), to the 2/5 power h_SPH."""
    variance = 0.5**2 / 12.0 + 2.0 * D * t
    pt_box = _box_run("pt", "adaptive", 0.5, D=D)
    assert reconstruction_width(pt_box, t) == pytest.approx(1.06 * 300**-0.2 * math.sqrt(variance), rel=1e-15)
    point = RunConfig.of(method="pt", kernel="adaptive", n=300, D=D)
    ratio = reconstruction_width(pt_box, t) / reconstruction_width(point, t)
    assert ratio == pytest.approx(math.sqrt(1.0 + 0.5**2 / (24.0 * D * t)), rel=1e-14)
    if (D, t) == (1e-3, 72.0):  # by hand: sqrt(1 + 0.25 / 1.728) = 1.0699
        assert ratio == pytest.approx(1.0699, abs=1e-4)
    mtpt_box = _box_run("mtpt", "sph", 0.5, D=D, eta=1.0)
    h, _ = kernel_for_step(mtpt_box, 1.0, t)
    constant = SCHEME_RECORDS[mtpt_box.scheme].sph_constant
    assert h == pytest.approx(constant * variance**0.4 * (300 / 10.0) ** -0.2, rel=1e-15)


def test_a_gaussian_sources_bandwidth_adds_its_variance():
    sd, D, t = 0.2, 1e-3, 50.0
    cfg = RunConfig.of(method="pt", kernel="adaptive", n=1000, D=D, source=Source.of("gaussian", sd=sd))
    assert reconstruction_width(cfg, t) == pytest.approx(1.06 * 1000**-0.2 * math.sqrt(sd * sd + 2 * D * t), rel=1e-15)


def test_the_paper_points_bandwidths_and_runs_are_unchanged():
    """A point's plume variance is 2 D t to the bit (0 + 2 D max(t, 0)): Eqs. 23 and 26 as before,
    and runs equal to those of main at 77a862f to round-off (sums over every step of the tables)."""
    D = 1e-3
    for t in (0.0, 0.1, 1.7, 1000.0):
        pt = RunConfig.of(method="pt", kernel="adaptive", n=300, D=D)
        assert reconstruction_width(pt, t) == 1.06 * 300 ** (-0.2) * math.sqrt(2.0 * D * t)
        if t > 0:
            mtpt = RunConfig.of(method="mtpt", kernel="sph", n=300, D=D, eta=1.0)
            constant = SCHEME_RECORDS[mtpt.scheme].sph_constant
            assert kernel_for_step(mtpt, 0.1, t)[0] == constant * (2.0 * D * t) ** 0.4 * (300 / mtpt.omega) ** (-0.2)
    frozen = {  # (H_C, SSE, h) summed over the steps, at 77a862f
        ("pt", "adaptive", 300, 50.0, 7): (-math.inf, 3124.6634014763204, 4.106095488785124),
        ("mtpt", "sph", 200, 20.0, 5): (158.47378915900276, 626.0818701785163, 5.188584881610363),
    }
    for (method, kernel, n, t_final, seed), sums in frozen.items():
        eta = {"eta": 1.0} if method == "mtpt" else {}
        table, _ = run(RunConfig.of(method=method, kernel=kernel, n=n, t_final=t_final, seed=seed, **eta))
        # to round-off, not to the bit: numpy's vectorised exp and log take other SIMD paths on other CPUs
        # (this SSE sum is ...3204 on an Intel Xeon and ...3217 on an AMD EPYC, 4e-16 apart)
        got = tuple(float(table[c].sum()) for c in ("H_C", "SSE", "h"))
        assert got == pytest.approx(sums, rel=1e-12, abs=0.0)
