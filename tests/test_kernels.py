"""Kernel widths and the transfer coefficient against the paper's formulas with literal numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.numerics.kernels import (
    beta_sph,
    collision_sigma,
    gaussian_pdf,
    h_de,
    h_sph,
    truncated_variance_fraction,
)


def test_h_de_eq23():
    # h_DE = 1.06 N^(-1/5) sqrt(2 D t), N = 300, D = 1e-3, t = 1000
    expected = 1.06 * 300 ** (-1 / 5) * math.sqrt(2 * 1e-3 * 1000)
    assert h_de(300, 1e-3, 1000.0) == pytest.approx(expected, rel=1e-14)
    # by hand: 300^(-0.2) = 0.319577, sqrt(2) = 1.414214 -> 0.479067
    assert h_de(300, 1e-3, 1000.0) == pytest.approx(0.479067, abs=2e-6)
    # N = 30000, t = 10: 1.06 * 30000^(-0.2) * sqrt(0.02)
    assert h_de(30000, 1e-3, 10.0) == pytest.approx(1.06 * 30000**-0.2 * math.sqrt(0.02), rel=1e-14)
    assert h_de(300, 1e-3, 0.0) == 0.0


def test_h_sph_eq26():
    # h_SPH = 0.82 (2 D t)^(2/5) (N / Omega)^(-1/5), N = 300, Omega = 10, D = 1e-3, t = 1000
    expected = 0.82 * (2 * 1e-3 * 1000) ** 0.4 * (300 / 10) ** -0.2
    assert h_sph(300, 10.0, 1e-3, 1000.0) == pytest.approx(expected, rel=1e-14)
    # by hand: 0.82 * 2^0.4 (1.319508) * 30^(-0.2) (0.506496) -> 0.548027
    assert h_sph(300, 10.0, 1e-3, 1000.0) == pytest.approx(0.548027, abs=2e-6)
    # scaling: t^(2/5) and rho^(-1/5)
    assert h_sph(300, 10.0, 1e-3, 32 * 1000.0) / h_sph(300, 10.0, 1e-3, 1000.0) == pytest.approx(4.0, rel=1e-13)
    assert h_sph(32 * 300, 10.0, 1e-3, 1000.0) / h_sph(300, 10.0, 1e-3, 1000.0) == pytest.approx(0.5, rel=1e-13)
    assert h_sph(300, 10.0, 1e-3, 1000.0) == pytest.approx(h_sph(3000, 100.0, 1e-3, 1000.0), rel=1e-14)


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
