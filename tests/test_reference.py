"""The exact references of a scene (core/reference.py) against independent quadrature, the PDE
and the paper's own Gaussian formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import erf

from particle_entropy.core import measures as M
from particle_entropy.core.reference import Reference
from particle_entropy.core.sources import Source, box_entropy, box_mean


def _quad_box_entropy(width: float, dt: float) -> float:
    """-integral c ln c dx of the dispersed box by scipy's adaptive quadrature, split at the edge."""
    s = math.sqrt(4.0 * dt)
    half = 0.5 * width

    def minus_c_ln_c(x):
        c = 0.5 * (math.erf((x + half) / s) - math.erf((x - half) / s)) / width
        return -c * math.log(c) if c > 0 else 0.0

    cuts = sorted({0.0, max(0.0, half - 12 * s), half, half + 12 * s})
    total = sum(quad(minus_c_ln_c, lo, hi, limit=400, epsabs=1e-15, epsrel=1e-13)[0] for lo, hi in zip(cuts, cuts[1:]))
    return 2.0 * total


@pytest.mark.parametrize(
    "width, dt", [(1.0, 1e-6), (1.0, 0.01), (1.0, 1.0), (0.001, 1.0), (10.0, 1e-8), (1.0, 100.0), (3.0, 0.2)]
)
def test_box_entropy_matches_scipy_quad(width, dt):
    assert box_entropy(width, dt) == pytest.approx(_quad_box_entropy(width, dt), abs=1e-11)


def test_box_entropy_limits():
    assert box_entropy(2.5, 0.0) == math.log(2.5)  # uniform on the box
    # a box much narrower than sqrt(4 D t) is a Gaussian of variance w^2/12 + 2 D t (to O((w/s)^4))
    w, dt = 1e-3, 4.0
    gaussian = 0.5 * math.log(2 * math.pi * math.e * (w * w / 12 + 2 * dt))
    assert box_entropy(w, dt) == pytest.approx(gaussian, abs=1e-14)
    # spreading only adds entropy
    values = [box_entropy(1.0, dt) for dt in (0.0, 1e-4, 1e-2, 1.0)]
    assert values == sorted(values) and len(set(values)) == 4


@pytest.mark.parametrize("width", [1e-6, 1e-10, 1e-14, 1e-15, 1e-16, 1e-17, 1e-20, 1e-100, 1e-300, 5e-324])
def test_a_narrowing_box_tends_to_the_point_sources_gaussian(width):
    """As the width -> 0 the dispersed box is the point source's Gaussian of variance 2 D t (plus the
    box's own w^2 / 12), whose entropy is ln sqrt(2 pi e sigma^2): down to the smallest float width.
    The erf difference lost all of it below ~1e-16 (0.36 too low at 1e-16, 0 from 1e-20)."""
    D, t = 1e-3, 50.0
    gaussian = 0.5 * math.log(2 * math.pi * math.e * (2 * D * t + width * width / 12))
    assert box_entropy(width, D * t) == pytest.approx(gaussian, abs=1e-14)
    point = Reference(Source.of("point", x0=width / 2), D, 0.01, t)
    box = Reference(Source.of("box", a=0.0, b=width), D, 0.01, t)  # at 0: any width is a float there
    x = np.linspace(point.centre - 1.0, point.centre + 1.0, 41)
    assert box.density(x) == pytest.approx(point.density(x), rel=1e-13)
    at_start = Reference(Source.of("box", a=0.0, b=width), D, 0.01, 0.0).sampled(np.array([-0.5, 0.0, 0.5]), 0.5)
    assert at_start.tolist() == [0.0, 2.0, 0.0]  # its indicator: 1 / width overflows below 5.6e-309


@pytest.mark.parametrize("a", [1e3, -7.5, 1e-3, 3e8])
def test_a_box_one_float_wide_is_the_point_source(a):
    """The narrowest box a float can hold at its position, [a, next float after a], is the point
    source at its centre: density, sampled reference, entropy (the erf difference of x - a and
    x - b lost ~1e-4 of the density at a = 1000)."""
    D, v, t = 1e-3, 0.01, 50.0
    b = math.nextafter(a, math.inf)
    box = Reference(Source.of("box", a=a, b=b), D, v, t)
    point = Reference(Source.of("point", x0=0.5 * (a + b)), D, v, t)
    x = np.linspace(point.centre - 1.0, point.centre + 1.0, 201)
    assert box.density(x) == pytest.approx(point.density(x), rel=1e-9)
    assert box.sampled(x, 0.01) == pytest.approx(point.sampled(x, 0.01), rel=1e-9)
    assert box.entropy() == pytest.approx(point.entropy(), abs=1e-14)


@pytest.mark.parametrize(
    "u, h",
    [(0.0, 0.0), (3.0, 0.0), (2.0, 1e-300), (-5.0, 1e-17), (0.3, 1e-9), (9.0, 0.02), (-0.1, 0.3), (0.2, 2.5),
     (4.0, 0.6), (15.0, 0.01), (-1e-12, 1e-12)],
)  # fmt: skip
def test_box_mean_is_the_gaussians_mean_over_the_interval(u, h):
    """(erf(u + h) - erf(u - h)) / (4 h), against scipy's quadrature of exp(-z^2) / sqrt(pi)."""
    f = lambda z: math.exp(-((u + h * z) ** 2)) / math.sqrt(math.pi)  # noqa: E731
    cuts = sorted({-1.0, 1.0, *[p for p in (-u / h if h else 2.0,) if -1 < p < 1]})
    exact = sum(quad(f, lo, hi, epsabs=0, epsrel=2e-14)[0] for lo, hi in zip(cuts, cuts[1:])) / 2
    assert box_mean(np.array([u, -u]), h) == pytest.approx([exact, exact], rel=1e-13)


@pytest.mark.parametrize(
    "source",
    [Source.of("point", x0=0.3), Source.of("gaussian", x0=-1.0, sd=0.2), Source.of("box", a=-0.5, b=0.25)],
)
def test_density_has_unit_mass_the_carried_centre_and_the_variance(source):
    ref = Reference(source, D=0.01, v=0.7, t=2.0)
    x = np.linspace(ref.centre - 20, ref.centre + 20, 400_001)
    c = ref.density(x)
    dx = x[1] - x[0]
    assert c.sum() * dx == pytest.approx(1.0, abs=1e-10)
    mean = (x * c).sum() * dx
    assert mean == pytest.approx(source.centre + 0.7 * 2.0, abs=1e-9)
    assert ((x - mean) ** 2 * c).sum() * dx == pytest.approx(source.variance + 2 * 0.01 * 2.0, rel=1e-8)
    h = -(c[c > 0] * np.log(c[c > 0])).sum() * dx
    assert ref.entropy() == pytest.approx(h, abs=1e-8)
    assert ref.dilution() == pytest.approx(math.exp(h), rel=1e-8)


@pytest.mark.parametrize("source", [Source.of("gaussian", x0=0.1, sd=0.3), Source.of("box", a=-0.2, b=0.4)])
def test_density_solves_advection_dispersion(source):
    """dc/dt + v dc/dx = D d2c/dx2, by centred differences in t and x."""
    D, v, t, h, k = 0.05, -1.3, 0.8, 1e-3, 1e-4
    x = np.linspace(-3, 3, 601)
    dcdt = (Reference(source, D, v, t + k).density(x) - Reference(source, D, v, t - k).density(x)) / (2 * k)
    now = Reference(source, D, v, t)
    dcdx = (now.density(x + h) - now.density(x - h)) / (2 * h)
    d2cdx2 = (now.density(x + h) - 2 * now.density(x) + now.density(x - h)) / h**2
    residual = dcdt + v * dcdx - D * d2cdx2
    assert np.max(np.abs(residual)) < 1e-5 * np.max(np.abs(dcdt))


def test_point_source_is_the_papers_gaussian_carried_by_v():
    D, t, v = 1e-3, 250.0, 0.02
    ref = Reference(Source.of("point", x0=0.5), D, v, t)
    narrow = Reference(Source.of("gaussian", x0=0.5, sd=1e-9), D, v, t)  # the general formula
    assert ref.entropy() == pytest.approx(narrow.entropy(), rel=1e-14)
    assert ref.entropy() == pytest.approx(0.5 * math.log(4 * math.pi * math.e * D * t), rel=1e-14)
    assert ref.dilution() == pytest.approx(M.analytic_dilution(D, t), rel=1e-14)
    assert ref.h_c(0.01) == pytest.approx(M.analytic_h_c(D, t, 0.01), rel=1e-14)
    x = np.linspace(-1, 1, 21)
    assert ref.density(x + 0.5 + v * t) == pytest.approx(M.gaussian_density(x, D, t), rel=1e-13)
    at_rest = Reference(Source.of("point"), D, 0.0, t)
    grid = np.linspace(-5, 5, 1001)
    assert at_rest.sampled(grid, 0.01).tobytes() == M.analytic_sampled(grid, D, t, 0.01).tobytes()
    assert at_rest.density(grid).tobytes() == M.gaussian_density(grid, D, t).tobytes()  # the paper's bits


def test_a_point_at_t0_is_a_delta_on_the_nearest_sample():
    ref = Reference(Source.of("point", x0=0.26), D=1.0, v=5.0, t=0.0)
    x = np.linspace(-1, 1, 11)  # spacing 0.2: 0.2 is nearest to 0.26
    g = ref.sampled(x, 0.2)
    assert g.tolist() == [0.0] * 6 + [5.0] + [0.0] * 4
    assert ref.entropy() == -math.inf and ref.dilution() == 0.0
    with pytest.raises(ValueError, match="delta"):
        ref.density(x)


def test_box_density_at_t0_and_the_erf_difference():
    ref = Reference(Source.of("box", a=1.0, b=3.0), D=0.5, v=1.0, t=0.0)
    assert ref.density(np.array([0.9, 1.5, 2.9, 3.1])).tolist() == [0.0, 0.5, 0.5, 0.0]
    later = Reference(Source.of("box", a=1.0, b=3.0), D=0.5, v=1.0, t=2.0)
    x = np.array([2.0, 4.0, 6.0])
    s = math.sqrt(4 * 0.5 * 2.0)
    expected = [0.25 * (erf((xi - 3.0) / s) - erf((xi - 5.0) / s)) for xi in x]
    assert later.density(x) == pytest.approx(expected, rel=1e-14)


def test_source_masses_sum_to_one_and_a_narrow_box_takes_one_node():
    x = np.linspace(-1, 1, 201)
    for source in (Source.of("point", x0=0.013), Source.of("gaussian", sd=0.1), Source.of("box", a=-0.3, b=0.3)):
        m = source.masses(x, 0.01)
        assert m.sum() == pytest.approx(1.0, abs=1e-15) and (m >= 0).all()
    narrow = Source.of("box", a=0.5001, b=0.5002).masses(x, 0.01)
    assert np.count_nonzero(narrow) == 1 and narrow[150] == 1.0
    box = Source.of("box", a=-0.3, b=0.3).masses(x, 0.01)
    assert np.count_nonzero(box) == 61  # nodes -0.3 .. 0.3, the end ones half covered
    assert box[70] == pytest.approx(box[100] / 2)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"kind": "line"}, "point, gaussian, box"),
        ({"kind": "gaussian", "sd": 0.0}, "sd > 0"),
        ({"kind": "box", "a": 1.0, "b": 1.0}, "a < b"),
        ({"kind": "box", "a": 0.0, "b": math.inf}, "a < b"),
    ],
)
def test_bad_sources_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Source.of(**kwargs)


# box_entropy at main 77a862f (its Gauss-Legendre quadrature in x, rebuilt every call), rows: width
_OLD_WIDTHS = (1e-300, 1e-16, 1e-8, 1e-3, 0.1, 0.5, 1.0, 3.0, 1e3, 1e100)
_OLD_DTS = (1e-300, 1e-30, 1e-12, 1e-6, 1e-3, 0.05, 1.0, 1e3, 1e12, 1e300)
_OLD_BOX_ENTROPY = (
    (
        -343.6222518256222,
        -32.77326427142604,
        -12.049998434479628,
        -5.142243155497491,
        -1.6883655160064226,
        0.26764598670764994,
        1.7655121234846451,
        5.219389762975714,
        15.581022681448918,
        347.15327607259144,
    ),
    (
        -36.841361487904734,
        -32.773055981483424,
        -12.049998434479628,
        -5.142243155497491,
        -1.6883655160064228,
        0.26764598670764994,
        1.7655121234846451,
        5.219389762975714,
        15.581022681448918,
        347.15327607259144,
    ),
    (
        -18.420680743952367,
        -18.4206804884896,
        -12.049996351150634,
        -5.142243155495407,
        -1.6883655160064208,
        0.26764598670764994,
        1.7655121234846454,
        5.219389762975714,
        15.581022681448918,
        347.15327607259144,
    ),
    (
        -6.907755278982137,
        -6.9077552789795815,
        -6.905200651280638,
        -5.1218322352991885,
        -1.6883446831071056,
        0.2676464033741429,
        1.765512144317978,
        5.2193897629965464,
        15.581022681448916,
        347.15327607259144,
    ),
    (
        -2.3025850929940455,
        -2.30258509299402,
        -2.302559546717031,
        -2.2770388159790516,
        -1.5144697306455075,
        0.27179538797502384,
        1.7657204134272515,
        5.219389971309003,
        15.581022681448918,
        347.15327607259144,
    ),
    (
        -0.6931471805599453,
        -0.6931471805599401,
        -0.6931420713045422,
        -0.6880379251569465,
        -0.5315783383499665,
        0.3622390358554223,
        1.770693516663467,
        5.219394971281919,
        15.581022681448921,
        347.15327607259144,
    ),
    (
        0.0,
        2.55565521443195e-15,
        2.5546277015012013e-06,
        0.002554627701499429,
        0.08078442110498946,
        0.5689953126499911,
        1.7859230436829483,
        5.219410595875031,
        15.581022681448939,
        347.15327607259144,
    ),
    (
        1.0986122886681098,
        1.0986122886681107,
        1.098613140210677,
        1.0994638312352762,
        1.1255404290364397,
        1.2890229952597918,
        1.9245518078651367,
        5.219577227828249,
        15.581022681449106,
        347.15327607259144,
    ),
    (
        6.907755278982137,
        6.907755278982137,
        6.907755281536764,
        6.907757833609839,
        6.907836063403242,
        6.908326511101912,
        6.910309906683636,
        6.988539700087126,
        15.581022702282251,
        347.15327607259144,
    ),
    (
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        230.25850929940458,
        347.15327607259144,
    ),
)


@pytest.mark.parametrize("i, width", list(enumerate(_OLD_WIDTHS)))
def test_box_entropy_equals_the_old_quadrature_to_round_off(i, width):
    """The rule built once in u = x / s, and the closed form of a box many s wide, give the old
    values to 1e-13 of the terms summed (|H| + |ln width|), from dt = 1e-300 to 1e300 and widths
    1e-300 to 1e100; 1e-16 absolute where the old nodes in x could not resolve s at the box's edge
    (width 1, dt <= 1e-12: the old was off by ~1e-18, the closed form is exact)."""
    for dt, old in zip(_OLD_DTS, _OLD_BOX_ENTROPY[i]):
        new = box_entropy(width, dt)
        assert abs(new - old) <= 1e-13 * (abs(old) + abs(math.log(width))) + 1e-16, (width, dt, old, new)


def test_a_box_many_widths_of_spread_wide_gains_k_s_over_width():
    """Where the edges spread apart (h = width / (2 s) >= 12, s = sqrt(4 D t)) the entropy is
    ln(width) + K s / width, K = integral of -erfc ln erfc + 2 ln 2 [v < 0] dv (scipy's quad here),
    and the quadrature just below h = 12 agrees with it."""

    def inner(v):
        e = math.erfc(v)
        return -e * math.log(e) + 2.0 * math.log(2.0)

    K = quad(inner, -np.inf, 0.0)[0] + quad(lambda v: -math.erfc(v) * math.log(math.erfc(v)), 0.0, 27.0)[0]
    for dt in (1e-300, 1e-30, 1e-12, 1e-6, 1.5e-4):
        s = math.sqrt(4.0 * dt)
        assert box_entropy(1.0, dt) == pytest.approx(K * s, rel=1e-12, abs=0)
        if dt >= 1e-6:  # below, K s / 3 is lost to ln 3's round-off
            assert box_entropy(3.0, dt) - math.log(3.0) == pytest.approx(K * s / 3.0, rel=1e-9, abs=0)
    edge = (0.5 / 12.0) ** 2 / 4.0  # dt at h = 12 for width 1
    below, above = box_entropy(1.0, edge * (1 + 1e-12)), box_entropy(1.0, edge * (1 - 1e-12))
    assert below == pytest.approx(above, rel=1e-12, abs=0)
