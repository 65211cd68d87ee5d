"""The 2-D sources (core/sources2d.py) and exact references (core/reference2d.py) against independent
evaluations: brute 2-D quadrature (scipy's dblquad), scipy.stats, products of 1-D erf differences and
the 1-D references, the trapezoid rule on a fine grid (spectrally accurate for these smooth, fast
decaying integrands) and Monte Carlo within 5 standard errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import dblquad, quad
from scipy.stats import multivariate_normal, norm

from particle_entropy.core.reference import Reference
from particle_entropy.core.reference2d import Reference2D, box_entropy2d
from particle_entropy.core.sources import Source, SourceError
from particle_entropy.core.sources2d import SOURCES2D, Source2D, dispersion_tensor


def _unit(degrees: float) -> np.ndarray:
    a = math.radians(degrees)
    return np.array([math.cos(a), math.sin(a)])


def _trapezoid_grid(lo, hi, h):
    """The nodes (M, 2) and weights (M,) of the trapezoid rule on a uniform grid of spacing ~h over [lo, hi]."""
    axes, weights = [], []
    for i in range(2):
        u = np.linspace(lo[i], hi[i], int(math.ceil((hi[i] - lo[i]) / h)) + 1)
        w = np.full(len(u), u[1] - u[0])
        w[[0, -1]] *= 0.5
        axes.append(u)
        weights.append(w)
    X, Y = np.meshgrid(*axes, indexing="ij")
    return np.stack([X.ravel(), Y.ravel()], axis=1), np.outer(*weights).ravel()


def _trapezoid_2d(f, lo, hi, h):
    """The trapezoid rule of f(points (M, 2)) on a uniform grid of spacing ~h over [lo, hi] (2,)."""
    p, w = _trapezoid_grid(lo, hi, h)
    return float(w @ f(p))


def _minus_c_ln_c(c):
    return -c * np.log(np.where(c > 0, c, 1.0))


# ------------------------------------------------------------------------ the dispersion tensor
@pytest.mark.parametrize("degrees", [0.0, 37.0, 90.0, 135.0, 212.0])
def test_dispersion_tensor_has_D_L_along_the_flow_and_D_T_across(degrees):
    u = _unit(degrees)
    across = np.array([-u[1], u[0]])
    D = dispersion_tensor(2.5 * u, {"L": 0.3, "T": 0.02})
    assert np.array_equal(D, D.T)
    np.testing.assert_allclose(D @ u, 0.3 * u, atol=1e-15)
    np.testing.assert_allclose(D @ across, 0.02 * across, atol=1e-15)
    assert sorted(np.linalg.eigvalsh(D)) == pytest.approx([0.02, 0.3], abs=1e-15)


@pytest.mark.parametrize("v", [[0.0, 0.0], [1.0, -2.0]])
def test_dispersion_tensor_from_x_and_y_is_diagonal_at_any_v(v):
    assert np.array_equal(dispersion_tensor(v, {"x": 0.4, "y": 0.1}), np.array([[0.4, 0.0], [0.0, 0.1]]))


@pytest.mark.parametrize(
    "v, D, key",
    [
        ([1.0, 0.0], {"L": -1.0, "T": 0.1}, "D.L"),
        ([1.0, 0.0], {"L": 1.0, "T": 0.0}, "D.T"),
        ([1.0, 0.0], {"L": math.nan, "T": 0.1}, "D.L"),
        ([1.0, 0.0], {"L": 1.0, "T": math.inf}, "D.T"),
        ([0.0, 0.0], {"L": 1.0, "T": 0.1}, "D.L"),
        ([0.0, 0.0], {"x": 1.0, "y": -0.1}, "D.y"),
        ([1.0, 0.0, 0.0], {"x": 1.0, "y": 1.0}, "v"),
        ([1.0, math.nan], {"L": 1.0, "T": 1.0}, "v"),
        ([1.0, 0.0], {"L": 1.0, "y": 1.0}, "D"),
    ],
)
def test_dispersion_tensor_refusals_name_the_key_and_range(v, D, key):
    with pytest.raises(ValueError, match=rf"^{key}: ") as refusal:
        dispersion_tensor(v, D)
    assert any(word in str(refusal.value) for word in ("> 0", "v != 0", "two finite", "keys"))


# ------------------------------------------------------------------------ the source kinds
SOURCES = [
    Source2D.of("point", x0=[0.5, -1.0]),
    Source2D.of("gaussian", x0=[0.5, -1.0], sd=[0.3, 0.1]),
    Source2D.of("box", x=[-1.0, 1.0], y=[-0.25, 0.5]),
]


@pytest.mark.parametrize("source", SOURCES, ids=lambda s: s.kind)
def test_sources_round_trip_through_their_pair_records(source):
    record = source.record()
    assert record["kind"] in SOURCES2D and SOURCES2D[record["kind"]] is type(source)
    assert all(isinstance(value, list) and len(value) == 2 for key, value in record.items() if key != "kind")
    assert Source2D.of(**record) == source


def test_records_use_the_configs_pair_form():
    assert SOURCES[0].record() == {"kind": "point", "x0": [0.5, -1.0]}
    assert SOURCES[1].record() == {"kind": "gaussian", "x0": [0.5, -1.0], "sd": [0.3, 0.1]}
    assert SOURCES[2].record() == {"kind": "box", "x": [-1.0, 1.0], "y": [-0.25, 0.5]}


@pytest.mark.parametrize(
    "spec, param",
    [
        ({"kind": "gaussian", "x0": [0, 0], "sd": [0.0, 1.0]}, "sd"),
        ({"kind": "gaussian", "x0": [0, 0]}, "sd"),
        ({"kind": "box", "x": [1.0, 0.0], "y": [0, 1]}, "x"),
        ({"kind": "box", "x": [0, 1], "y": [0.0, math.inf]}, "y"),
        ({"kind": "box", "x": [0, 1], "y": [0.5, 0.5]}, "y"),
        ({"kind": "point", "x0": [math.nan, 0.0]}, "x0"),
        ({"kind": "point", "x0": [1.0, 2.0, 3.0]}, "x0"),
        ({"kind": "point", "x0": [0, 0], "sd": [1, 1]}, "sd"),
        ({"kind": "disc", "x0": [0, 0]}, "kind"),
    ],
)
def test_source_refusals_name_the_parameter(spec, param):
    with pytest.raises(SourceError) as refusal:
        Source2D.of(**spec)
    assert refusal.value.param == param and str(refusal.value).startswith(f"{param}: ")


def test_covariances_are_the_kinds_own():
    assert np.array_equal(SOURCES[0].covariance, np.zeros((2, 2)))
    np.testing.assert_allclose(SOURCES[1].covariance, [[0.09, 0.0], [0.0, 0.01]], rtol=1e-15)
    np.testing.assert_allclose(SOURCES[2].covariance, [[4.0 / 12, 0.0], [0.0, 0.75**2 / 12]], rtol=1e-15)
    np.testing.assert_array_equal(SOURCES[2].centre, [0.0, 0.125])


@pytest.mark.parametrize("source", SOURCES[1:], ids=lambda s: s.kind)
def test_positions_have_the_sources_mean_and_covariance(source):
    """Monte Carlo, 5 standard errors: of the mean sd / sqrt(n), of a variance sqrt((mu4 - sd^4) / n)
    (mu4 = 3 sd^4 for a Gaussian, w^4 / 80 for a uniform of width w), of the covariance sx sy / sqrt(n)."""
    n = 200_000
    p = source.positions(n, np.random.default_rng(7))
    assert p.shape == (n, 2)
    var = np.diag(source.covariance)
    mu4 = 3 * var**2 if source.kind == "gaussian" else (np.sqrt(12 * var)) ** 4 / 80
    assert np.all(np.abs(p.mean(axis=0) - source.centre) < 5 * np.sqrt(var / n))
    cov = np.cov(p.T)
    assert np.all(np.abs(np.diag(cov) - var) < 5 * np.sqrt((mu4 - var**2) / n))
    assert abs(cov[0, 1]) < 5 * math.sqrt(var[0] * var[1] / n)
    if source.kind == "box":
        assert p[:, 0].min() >= -1.0 and p[:, 0].max() <= 1.0 and p[:, 1].min() >= -0.25 and p[:, 1].max() <= 0.5


def test_point_positions_are_the_point():
    assert np.array_equal(SOURCES[0].positions(3, np.random.default_rng(0)), [[0.5, -1.0]] * 3)


def test_box_cell_masses_are_overlap_areas():
    box = Source2D.of("box", x=[0.1, 0.35], y=[0.0, 0.2])
    m = box.cell_masses(np.array([0.05, 0.15, 0.25, 0.35]), np.array([-0.05, 0.05, 0.15, 0.25]), 0.1, 0.1)
    by_hand = np.outer([0.0, 0.4, 0.4, 0.2], [0.0, 0.5, 0.5, 0.0])  # overlaps 0.1, 0.1, 0.05 of 0.25
    np.testing.assert_allclose(m, by_hand, rtol=1e-14, atol=1e-16)


def test_point_cell_masses_are_all_in_the_cell_holding_it():
    m = SOURCES[0].cell_masses(np.arange(-2.0, 2.01, 0.5), np.arange(-2.0, 2.01, 0.5), 0.5, 0.5)
    assert m.sum() == 1.0 and m[5, 2] == 1.0  # x0 = 0.5 at the centre x = 0.5, y0 = -1 at y = -1
    with pytest.raises(ValueError, match="outside the grid"):
        SOURCES[0].cell_masses(np.arange(-2.0, 0.01, 0.5), np.arange(-2.0, 0.01, 0.5), 0.5, 0.5)


def test_gaussian_cell_masses_are_exact_and_tend_to_density_times_area():
    source = SOURCES[1]
    xc, yc = np.arange(-2.0, 3.0, 0.1) + 0.05, np.arange(-2.0, 0.0, 0.05) + 0.025
    m = source.cell_masses(xc, yc, 0.1, 0.05)
    assert m.sum() == pytest.approx(1.0, abs=1e-14)
    i, j = 24, 19  # the cell [0.4, 0.5] x [-1.05, -1.0]: brute quadrature of the pdf
    exact = dblquad(lambda y, x: norm.pdf(x, 0.5, 0.3) * norm.pdf(y, -1.0, 0.1), 0.4, 0.5, -1.05, -1.0, epsabs=1e-14)[0]
    assert m[i, j] == pytest.approx(exact, rel=1e-10)
    errors = []
    for h in (0.02, 0.01):
        xc, yc = np.arange(-1.5, 2.5, h) + h / 2, np.arange(-1.6, -0.4, h / 2) + h / 4
        X, Y = np.meshgrid(xc, yc, indexing="ij")
        density = norm.pdf(X, 0.5, 0.3) * norm.pdf(Y, -1.0, 0.1)
        errors.append(np.abs(source.cell_masses(xc, yc, h, h / 2) - density * h * h / 2).max())
    assert errors[1] < 0.3 * errors[0] and errors[1] < 1e-5  # second order: the midpoint rule's h^2


def test_box_cell_masses_tend_to_the_box_indicator():
    box = SOURCES[2]
    h = 0.01
    xc, yc = np.arange(-1.5, 1.5, h) + h / 2, np.arange(-0.5, 1.0, h) + h / 2
    m = box.cell_masses(xc, yc, h, h)
    assert m.sum() == pytest.approx(1.0, abs=1e-13)
    X, Y = np.meshgrid(xc, yc, indexing="ij")
    inside = (np.abs(X) < 1.0 - h) & (Y > -0.25 + h) & (Y < 0.5 - h)
    np.testing.assert_allclose(m[inside], h * h / box.area, rtol=1e-12)


# ------------------------------------------------------------------------ the exact densities
@pytest.mark.parametrize("kind", ["point", "gaussian"])
def test_point_and_gaussian_densities_are_the_normal_density_and_integrate_to_one(kind):
    source = SOURCES[0] if kind == "point" else SOURCES[1]
    v, t = 0.7 * _unit(37.0), 3.0
    D = dispersion_tensor(v, {"L": 0.05, "T": 0.005})
    ref = Reference2D(source, D, v, t)
    mean = np.array([0.5, -1.0]) + v * t
    cov = 2 * D * t + (np.diag([0.09, 0.01]) if kind == "gaussian" else 0.0)
    rng = np.random.default_rng(3)
    p = mean + rng.normal(size=(50, 2)) * 0.5
    np.testing.assert_allclose(ref.density(p), multivariate_normal(mean, cov).pdf(p), rtol=1e-12)
    reach = 12 * math.sqrt(cov.max())
    total = _trapezoid_2d(ref.density, mean - reach, mean + reach, 0.25 * math.sqrt(np.linalg.eigvalsh(cov)[0]))
    assert total == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(ref.centre, mean, rtol=1e-15)
    np.testing.assert_allclose(ref.covariance, cov, rtol=1e-14)


def test_a_point_at_t0_has_no_density():
    ref = Reference2D(SOURCES[0], np.eye(2), [1.0, 0.0], 0.0)
    with pytest.raises(ValueError, match="delta"):
        ref.density([[0.5, -1.0]])
    assert ref.h_i() == -math.inf and ref.dilution() == 0.0


def _brute_box_density(box, S, shift, p):
    """(1 / area) * integral over the box of the N(0, S) density at p - shift - x', by dblquad."""
    inv, det = np.linalg.inv(S), np.linalg.det(S)
    q = np.asarray(p) - shift

    def kernel(y, x):
        dx, dy = q[0] - x, q[1] - y
        return math.exp(-0.5 * (inv[0, 0] * dx * dx + 2 * inv[0, 1] * dx * dy + inv[1, 1] * dy * dy))

    total = dblquad(kernel, box.x[0], box.x[1], box.y[0], box.y[1], epsabs=1e-13, epsrel=1e-13)[0]
    return total / (2 * math.pi * math.sqrt(det) * box.area)


@pytest.mark.parametrize("degrees, ratio", [(37.0, 10.0), (-120.0, 1000.0)])
def test_box_density_in_an_oblique_flow_matches_brute_2d_quadrature(degrees, ratio):
    box = SOURCES[2]
    v, t = 0.4 * _unit(degrees), 2.0
    D = dispersion_tensor(v, {"L": 0.05, "T": 0.05 / ratio})
    ref = Reference2D(box, D, v, t)
    rng = np.random.default_rng(11)
    p = ref.centre + rng.normal(size=(8, 2)) * np.sqrt(np.diag(ref.covariance))
    p = np.vstack([p, ref.centre, ref.centre + [1.0, 0.375]])  # the middle and a corner, carried
    brute = np.array([_brute_box_density(box, 2 * D * t, v * t, q) for q in p])
    peak = 1.0 / box.area
    assert np.abs(ref.density(p) - brute).max() < 1e-10 * peak
    assert ref.density(p).max() > 0.2 * peak  # the points see the plume


def test_box_density_with_diagonal_D_is_a_product_of_erf_differences():
    box = SOURCES[2]
    v, t, Dx, Dy = np.array([0.3, 0.0]), 1.5, 0.04, 0.01
    ref = Reference2D(box, dispersion_tensor(v, {"L": Dx, "T": Dy}), v, t)
    rng = np.random.default_rng(5)
    p = ref.centre + rng.normal(size=(40, 2)) * [0.8, 0.4]

    def side(u, lo, hi, D):
        s = math.sqrt(4 * D * t)
        return 0.5 * (math.erf((u - lo) / s) - math.erf((u - hi) / s)) / (hi - lo)

    product = [side(x - 0.3 * t, -1.0, 1.0, Dx) * side(y, -0.25, 0.5, Dy) for x, y in p]
    np.testing.assert_allclose(ref.density(p), product, rtol=0, atol=1e-14)


def test_box_density_is_continuous_as_D_turns_diagonal():
    """A tensor a hair off diagonal goes through the quadrature; it must agree with the product form."""
    box, t = SOURCES[2], 1.0
    ref = Reference2D(box, np.diag([0.04, 0.01]), [0.0, 0.0], t)
    near = Reference2D(box, np.array([[0.04, 1e-9], [1e-9, 0.01]]), [0.0, 0.0], t)
    p = np.random.default_rng(2).normal(size=(30, 2))
    np.testing.assert_allclose(near.density(p), ref.density(p), rtol=0, atol=1e-8)


def test_box_density_at_t0_is_the_box():
    ref = Reference2D(SOURCES[2], np.eye(2), [1.0, 1.0], 0.0)
    c = ref.density([[0.0, 0.0], [0.99, 0.49], [1.01, 0.0], [0.0, -0.3]])
    np.testing.assert_array_equal(c, [1 / 1.5, 1 / 1.5, 0.0, 0.0])
    assert ref.h_i() == pytest.approx(math.log(1.5), abs=1e-15)


def test_box_density_integrates_to_one_with_the_boxs_moments():
    v, t = 0.4 * _unit(37.0), 2.0
    ref = Reference2D(SOURCES[2], dispersion_tensor(v, {"L": 0.05, "T": 0.005}), v, t)
    c0, reach = ref.centre, 1.0 + 8 * math.sqrt(ref.spread.max())
    p, w = _trapezoid_grid(c0 - reach, c0 + reach, 0.05)
    wc = w * ref.density(p)
    z = p - c0
    assert wc.sum() == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(wc @ z, 0.0, atol=1e-12)
    cov = (z * wc[:, None]).T @ z  # the box's own covariance plus 2 D t: no x-y covariance from the box
    np.testing.assert_allclose(cov, ref.spread + SOURCES[2].covariance, rtol=0, atol=1e-12)


# ------------------------------------------------------------------------ H_I and E
def test_gaussian_h_i_is_the_closed_form_and_e_its_exponential():
    v, t = 0.7 * _unit(37.0), 3.0
    ref = Reference2D(SOURCES[1], dispersion_tensor(v, {"L": 0.05, "T": 0.005}), v, t)
    sd = math.sqrt(np.linalg.eigvalsh(ref.covariance).max())
    numeric = _trapezoid_2d(lambda p: _minus_c_ln_c(ref.density(p)), ref.centre - 12 * sd, ref.centre + 12 * sd, 0.02)
    assert ref.h_i() == pytest.approx(numeric, abs=1e-10)
    cov = np.diag([0.09, 0.01]) + 2 * t * ref.D
    by_hand = math.log(2 * math.pi * math.e * math.sqrt(cov[0, 0] * cov[1, 1] - cov[0, 1] ** 2))
    assert ref.h_i() == pytest.approx(by_hand, abs=1e-14)
    assert ref.dilution() == pytest.approx(math.exp(ref.h_i()), rel=1e-15)


def _quad_box_entropy_1d(width: float, spread: float) -> float:
    """-integral c ln c of a box of ``width`` convolved with N(0, spread), by scipy's quad."""
    s = math.sqrt(2 * spread)

    def f(x):
        c = 0.5 * (math.erfc((x - width / 2) / s) - math.erfc((x + width / 2) / s)) / width
        return -c * math.log(c) if c > 0 else 0.0

    cuts = [-width / 2 - 12 * s, -width / 2, 0.0, width / 2, width / 2 + 12 * s]
    return sum(quad(f, a, b, epsabs=1e-15, epsrel=1e-13, limit=200)[0] for a, b in zip(cuts, cuts[1:]))


@pytest.mark.parametrize("Sxx, Syy", [(0.1, 0.02), (1e-3, 4.0), (2.0, 2.0)])
def test_box_h_i_with_diagonal_spread_is_the_sum_of_the_sides(Sxx, Syy):
    """c = c_x c_y, so H_I = H_x + H_y: each side's 1-D entropy by scipy's adaptive quad."""
    box = SOURCES[2]
    sides = _quad_box_entropy_1d(2.0, Sxx) + _quad_box_entropy_1d(0.75, Syy)
    assert box_entropy2d(box, np.diag([Sxx, Syy])) == pytest.approx(sides, abs=1e-11)


@pytest.mark.parametrize("degrees, ratio, t", [(37.0, 10.0, 2.0), (60.0, 30.0, 1.0)])
def test_box_h_i_in_an_oblique_flow_matches_the_trapezoid_rule(degrees, ratio, t):
    """The quadrature of box_entropy2d against another rule, the trapezoid on a fine uniform grid, of
    the density tested against dblquad above; and the mirror image (flow at -theta) has the same H_I."""
    box = SOURCES[2]
    v = 0.4 * _unit(degrees)
    ref = Reference2D(box, dispersion_tensor(v, {"L": 0.05, "T": 0.05 / ratio}), v, t)
    sd = np.sqrt(np.diag(ref.spread))
    lo, hi = np.array([-1.0, -0.25]) - 8 * sd, np.array([1.0, 0.5]) + 8 * sd
    h = 0.5 * math.sqrt(np.linalg.eigvalsh(ref.spread).min())
    numeric = _trapezoid_2d(lambda p: _minus_c_ln_c(ref.density(p + v * t)), lo, hi, h)
    assert ref.h_i() == pytest.approx(numeric, abs=1e-10)
    mirror = Reference2D(box, dispersion_tensor(v * [1, -1], {"L": 0.05, "T": 0.05 / ratio}), v * [1, -1], t)
    assert mirror.h_i() == pytest.approx(ref.h_i(), abs=1e-12)


def test_a_small_box_has_the_gaussians_h_i():
    """A box of width w much below the spread is the Gaussian of covariance box + S, to O((w/s)^4)."""
    v = _unit(37.0)
    box = Source2D.of("box", x=[0.0, 2e-3], y=[0.0, 1e-3])
    ref = Reference2D(box, dispersion_tensor(v, {"L": 0.5, "T": 0.05}), v, 1.0)
    cov = box.covariance + 2 * ref.D
    gaussian = math.log(2 * math.pi * math.e * math.sqrt(np.linalg.det(cov)))
    assert ref.h_i() == pytest.approx(gaussian, abs=1e-11)


def test_e_grows_like_sqrt_det_sigma():
    """A point: E = 2 pi e sqrt(det 2 D t) grows like t (sqrt t in 1-D); a box's H_I stays below the
    Gaussian's of the same covariance (the normal law maximises entropy) and tends to it."""
    v = 0.5 * _unit(37.0)
    D = dispersion_tensor(v, {"L": 0.05, "T": 0.005})
    point = [Reference2D(SOURCES[0], D, v, t).dilution() for t in (1.0, 4.0, 16.0)]
    assert point[1] / point[0] == pytest.approx(4.0, rel=1e-13) and point[2] / point[1] == pytest.approx(4.0, rel=1e-13)
    assert point[0] == pytest.approx(2 * math.pi * math.e * 2 * math.sqrt(np.linalg.det(D)), rel=1e-14)
    gaps = []
    for t in (0.5, 5.0, 50.0):
        ref = Reference2D(SOURCES[2], D, v, t)
        gaps.append(math.log(2 * math.pi * math.e * math.sqrt(np.linalg.det(ref.covariance))) - ref.h_i())
    assert all(g > 0 for g in gaps) and gaps[0] > gaps[1] > gaps[2] and gaps[2] < 1e-3


# ------------------------------------------------------------------------ the measurement lattice
@pytest.mark.parametrize("degrees", [0.0, 37.0, 150.0])
def test_the_lattice_lies_along_the_flow_and_turns_with_it(degrees):
    u = _unit(degrees)
    t, D_L, D_T = 4.0, 0.05, 0.005
    ref = Reference2D(SOURCES[0], dispersion_tensor(0.3 * u, {"L": D_L, "T": D_T}), 0.3 * u, t)
    p = ref.points()
    assert p.shape == (225, 2)
    centre = np.array([0.5, -1.0]) + 0.3 * u * t
    np.testing.assert_allclose(p.mean(axis=0), centre, atol=1e-12)
    np.testing.assert_allclose(p[7 * 15 + 7], centre, atol=1e-12)  # the middle point is the centre
    rel = (p - centre).reshape(15, 15, 2)
    across = np.array([-u[1], u[0]])
    along_sd, across_sd = math.sqrt(2 * D_L * t), math.sqrt(2 * D_T * t)
    np.testing.assert_allclose(rel[:, 7] @ u, np.linspace(-3, 3, 15) * along_sd, atol=1e-12)
    np.testing.assert_allclose(rel[:, 7] @ across, 0.0, atol=1e-12)
    np.testing.assert_allclose(rel[7, :] @ across, np.linspace(-3, 3, 15) * across_sd, atol=1e-12)
    base = Reference2D(SOURCES[0], dispersion_tensor([0.3, 0.0], {"L": D_L, "T": D_T}), [0.3, 0.0], t)
    turn = np.array([[u[0], -u[1]], [u[1], u[0]]])
    rotated = (base.points() - base.centre) @ turn.T
    np.testing.assert_allclose(rel.reshape(-1, 2), rotated, atol=1e-12)


def test_the_lattice_follows_the_plumes_principal_axes():
    """A Gaussian source in an oblique flow: the axes are Sigma's eigenvectors, the span +-3 sd."""
    v = 0.3 * _unit(70.0)
    ref = Reference2D(SOURCES[1], dispersion_tensor(v, {"L": 0.02, "T": 0.002}), v, 1.0)
    p = ref.points(n=5, sds=2.0).reshape(5, 5, 2)
    first, second = p[4, 2] - p[0, 2], p[2, 4] - p[2, 0]
    cov = ref.covariance
    for axis in (first, second):
        w = cov @ axis
        assert abs(w[0] * axis[1] - w[1] * axis[0]) < 1e-12 * np.linalg.norm(w) * np.linalg.norm(axis)
    lam = np.linalg.eigvalsh(cov)
    assert np.linalg.norm(first) == pytest.approx(4 * math.sqrt(lam[1]), rel=1e-12)
    assert np.linalg.norm(second) == pytest.approx(4 * math.sqrt(lam[0]), rel=1e-12)


def test_a_point_at_t0_has_no_lattice():
    with pytest.raises(ValueError, match="no spread"):
        Reference2D(SOURCES[0], np.eye(2), [1.0, 0.0], 0.0).points()


@pytest.mark.parametrize("kind", ["point", "gaussian", "box"])
def test_a_flow_along_x_is_the_1d_reference_times_the_transverse_one(kind):
    """At theta = 0 the density separates: the 1-D reference (core/reference.py) of the same source
    along x with D_L and v, times the transverse 1-D reference with D_T at rest."""
    u, t, D_L, D_T = 0.6, 2.5, 0.05, 0.004
    spec2, along, across = {
        "point": ({"x0": [0.5, -1.0]}, Source.of("point", x0=0.5), Source.of("point", x0=-1.0)),
        "gaussian": ({"x0": [0.5, -1.0], "sd": [0.3, 0.1]}, Source.of("gaussian", x0=0.5, sd=0.3), None),
        "box": (
            {"x": [-1.0, 1.0], "y": [-0.25, 0.5]},
            Source.of("box", a=-1.0, b=1.0),
            Source.of("box", a=-0.25, b=0.5),
        ),
    }[kind]
    ref = Reference2D(Source2D.of(kind, **spec2), dispersion_tensor([u, 0.0], {"L": D_L, "T": D_T}), [u, 0.0], t)
    p = ref.points()
    x_part = Reference(along, D_L, u, t).density(p[:, 0])
    if across is None:  # a y Gaussian of variance sd^2 + 2 D_T t
        y_part = norm.pdf(p[:, 1], -1.0, math.sqrt(0.01 + 2 * D_T * t))
    else:
        y_part = Reference(across, D_T, 0.0, t).density(p[:, 1])
    np.testing.assert_allclose(ref.density(p), x_part * y_part, rtol=1e-12, atol=1e-15)
