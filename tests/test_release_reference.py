"""The exact plume of a continuous release (core/release.py) against closed forms derived apart from
its quadrature: the 1-D continuous point source with erfc and its steady state, Wilson and Miller's
2-D point source through Hantush's well function (itself against scipy's E1 and K0), the release that
ends as the difference of two that do not and as the spread of its state at the end, scipy's quad of
the closed forms (a box or Gaussian source's density as the point source's convolved with the
source, H_I), the radial form of the 2-D point source at v = 0, and the instantaneous references."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import entr, exp1, k0

from particle_entropy.core.reference import Reference
from particle_entropy.core.reference2d import Reference2D
from particle_entropy.core.release import (
    Release,
    ReleaseError,
    ReleaseReference,
    ReleaseReference2D,
    hantush_w,
    point_release,
    point_release_2d,
    steady_point_release,
)
from particle_entropy.core.sources import Source
from particle_entropy.core.sources2d import Source2D, dispersion_tensor


def _rel(a, b) -> float:
    """The largest relative difference of a from b."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return float(np.max(np.abs(a - b) / np.abs(b)))


def _quad_point_release(x, t, q, D, v) -> float:
    """q integral_0^t exp(-(x - v s)^2 / (4 D s)) / sqrt(4 pi D s) ds by scipy's quad, broken at the
    step s ~ x^2 / (4 D) and at the water's age x / v."""

    def g(s):
        return q * math.exp(-((x - v * s) ** 2) / (4.0 * D * s)) / math.sqrt(4.0 * math.pi * D * s)

    breaks = sorted({0.0, t, *(b for b in (x * x / (4.0 * D), x / v if v else 0.0) if 0.0 < b < t)})
    return sum(quad(g, a, b, epsabs=0.0, epsrel=1e-13, limit=400)[0] for a, b in zip(breaks[:-1], breaks[1:]))


# ------------------------------------------------------------------------ the release itself
@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"rate": 0.0}, "rate"),
        ({"rate": -1.0}, "rate"),
        ({"rate": math.inf}, "rate"),
        ({"rate": math.nan}, "rate"),
        ({"rate": True}, "rate"),
        ({"rate": "1"}, "rate"),
        ({"rate": 1.0, "start": math.nan}, "start"),
        ({"rate": 1.0, "start": 2.0, "end": 2.0}, "end"),
        ({"rate": 1.0, "start": 2.0, "end": 1.0}, "end"),
        ({"rate": 1.0, "end": math.inf}, "end"),
    ],
)
def test_a_release_out_of_range_names_its_field_value_and_range(kwargs, field):
    with pytest.raises(ReleaseError) as caught:
        Release(**kwargs)
    error = caught.value
    assert isinstance(error, ValueError)
    assert error.param == field and str(error).startswith(f"{field}: ")
    assert repr(kwargs[field]) in str(error)
    assert (error.value is kwargs[field]) or error.value == kwargs[field]


def test_a_config_release_is_named_by_its_keys():
    assert Release.from_spec({"rate": 2.0, "from": 1.0, "until": 3.0}) == Release(2.0, 1.0, 3.0)
    assert Release.from_spec({"rate": 2.0}) == Release(2.0, 0.0, None)
    for spec, key in [({"rate": 1.0, "from": 2.0, "until": 1.0}, "until"), ({"rate": 1, "from": None}, "from")]:
        with pytest.raises(ReleaseError, match=f"^{key}: ") as caught:
            Release.from_spec(spec)
        assert caught.value.param == key
    with pytest.raises(ReleaseError, match="^to: not a key"):
        Release.from_spec({"rate": 1.0, "to": 2.0})


def test_the_observation_comes_after_the_start():
    release = Release(1.5, start=2.0, end=5.0)
    for t in (2.0, 1.0, math.nan, math.inf):
        with pytest.raises(ReleaseError, match="^t: ") as caught:
            release.check(t)
        assert caught.value.param == "t"
        with pytest.raises(ReleaseError):
            ReleaseReference(Source.of("point"), release, 1.0, 1.0, t)
        with pytest.raises(ReleaseError):
            ReleaseReference2D(Source2D.of("point"), release, np.eye(2), [1.0, 0.0], t)


def test_the_released_mass_and_ages():
    open_, ended = Release(1.5, start=2.0), Release(1.5, start=2.0, end=5.0)
    assert open_.mass(7.0) == 1.5 * 5.0 and open_.ages(7.0) == (0.0, 5.0)
    assert ended.mass(3.0) == 1.5 and ended.ages(3.0) == (0.0, 1.0)
    assert ended.mass(7.0) == 1.5 * 3.0 and ended.ages(7.0) == (2.0, 5.0)
    assert ended.mass(1.0) == 0.0  # before the start
    assert ReleaseReference(Source.of("point"), ended, 1.0, 1.0, 7.0).mass == 4.5


# ------------------------------------------------------------------------ the closed forms themselves
@pytest.mark.parametrize(
    "x, t, D, v",
    [(0.0, 1.0, 0.7, 1.3), (1e-6, 1e-3, 0.7, 1.3), (0.5, 0.01, 0.7, 1.3), (-0.3, 2.0, 0.7, 1.3), (3.0, 2.0, 0.7, 1.3),
     (10.0, 3.0, 0.7, 1.3), (-2.0, 50.0, 0.7, 1.3), (2.0, 1.0, 0.5, -1.0), (0.4, 2.0, 1.0, 0.0), (3.0, 0.5, 1.0, 0.0)],
)  # fmt: skip
def test_the_1d_closed_form_is_its_integral(x, t, D, v):
    """point_release against scipy's quad of the integral it is derived from (within 1e-14 measured)."""
    assert _rel(point_release(x, t, 2.0, D, v), _quad_point_release(x, t, 2.0, D, v)) < 1e-12


def test_the_1d_closed_form_tends_to_the_steady_state():
    x = np.linspace(-20.0, 20.0, 81)
    assert _rel(point_release(x, 500.0, 2.0, 1.0, 1.0), steady_point_release(x, 2.0, 1.0, 1.0)) < 1e-13


def test_hantush_w_is_theis_e1_without_leakage_and_2_k0_at_u_0():
    u = np.array([1e-8, 1e-4, 0.1, 1.0, 5.0, 30.0, 200.0])
    assert _rel(hantush_w(u, 0.0), exp1(u)) < 1e-12
    beta = np.array([1e-6, 1e-3, 0.1, 1.0, 5.0, 30.0, 300.0])
    assert _rel(hantush_w(0.0, beta), 2.0 * k0(beta)) < 1e-12
    assert hantush_w(0.0, 0.0) == math.inf
    # decreasing in u and in beta
    assert np.all(np.diff(hantush_w(np.geomspace(1e-3, 10.0, 9), 0.5)) < 0)
    assert np.all(np.diff(hantush_w(0.2, np.geomspace(1e-3, 10.0, 9))) < 0)


# ------------------------------------------------------------------------ 1-D
_FLOWS_1D = [(1.0, 1.0, 1.0), (1.0, 1.0, 500.0), (0.01, 1.0, 10.0), (1.0, 0.01, 10.0), (1.0, -2.0, 3.0),
             (0.1, 5.0, 100.0), (1.0, 0.0, 2.0), (1e-3, 1.0, 1e-3), (1.0, 1.0, 1e4)]  # fmt: skip


@pytest.mark.parametrize("D, v, t", _FLOWS_1D)
def test_a_1d_point_release_matches_its_closed_form(D, v, t):
    """At random points over the plume and its tails (down to 1e-80 of the peak), at the source and
    1e-9 from it, at early and late times: within 1.3e-11 relative (measured)."""
    rng = np.random.default_rng(11)
    reach = math.sqrt(4.0 * D * t) + abs(v) * t
    x = np.concatenate([rng.uniform(-reach, reach + abs(v) * t, 200), [0.0, 1e-9, 1e-6 * reach, -1e-4 * reach, v * t]])
    exact = point_release(x + 0.25, t, 2.0, D, v, x0=0.25)
    shown = exact > 1e-300
    c = ReleaseReference(Source.of("point", x0=0.25), Release(2.0), D, v, t).density(x + 0.25)
    assert _rel(c[shown], exact[shown]) < 1e-10


def test_a_1d_point_release_approaches_the_steady_state():
    """At t = 500 D / v^2, within 20 D / v of the source: q / v downstream, (q / v) exp(v x / D) up."""
    x = np.concatenate([np.linspace(-20.0, 20.0, 81), [1e-9, -1e-9]])
    c = ReleaseReference(Source.of("point", x0=1.0), Release(3.0), 1.0, 1.0, 500.0).density(x + 1.0)
    assert _rel(c, steady_point_release(x, 3.0, 1.0, 1.0)) < 1e-10


@pytest.mark.parametrize("D, v", [(0.5, 1.0), (1.0, 0.0), (0.2, -3.0)])
def test_a_release_that_ended_is_one_from_its_start_less_one_from_its_end(D, v):
    """Linearity: a release on [t0, t1] observed at t > t1 is C(t - t0) - C(t - t1)."""
    t0, t1, t = 0.5, 2.0, 3.0
    x = np.linspace(-3.0, 3.0 + 4.0 * v, 61)
    c = ReleaseReference(Source.of("point"), Release(2.0, t0, t1), D, v, t).density(x)
    exact = point_release(x, t, 2.0, D, v, start=t0) - point_release(x, t, 2.0, D, v, start=t1)
    shown = exact > 1e-6 * exact.max()  # the difference cancels in the far tails
    assert _rel(c[shown], exact[shown]) < 1e-10


@pytest.mark.parametrize("kind, params", [("point", {"x0": 0.0}), ("box", {"a": -1.0, "b": 0.5})])
def test_a_release_that_ended_spreads_its_state_at_the_end(kind, params):
    """c(x, t) = integral G(x - y, t - t1) c(y, t1) dy for a release ended at t1: the state at t1 (the
    release still on, on its spatial rule) spread by N(v (t - t1), 2 D (t - t1))."""
    source, D, v, t1, t = Source.of(kind, **params), 0.3, 1.0, 2.0, 2.5
    before = ReleaseReference(source, Release(1.0, 0.0), D, v, t1)
    y, w = before.spatial_rule()
    state = before.density(y)
    x = np.linspace(-2.0, 4.0, 25)
    lag = t - t1
    kernel = np.exp(-((x[:, None] - y[None, :] - v * lag) ** 2) / (4.0 * D * lag)) / math.sqrt(4.0 * math.pi * D * lag)
    spread = kernel @ (w * state)
    c = ReleaseReference(source, Release(1.0, 0.0, t1), D, v, t).density(x)
    assert _rel(c, spread) < 1e-10


def _convolved(x, weight, lo, hi, t, q, D, v) -> float:
    """integral weight(z) point_release(x - z) dz over [lo, hi] by scipy's quad, broken at x."""
    f = lambda z: weight(z) * float(point_release(x - z, t, q, D, v))  # noqa: E731
    points = [x] if lo < x < hi else None
    return quad(f, lo, hi, points=points, epsabs=0.0, epsrel=1e-13, limit=400)[0]


def test_a_1d_box_or_gaussian_release_is_the_point_release_convolved_with_the_source():
    """Within 3e-13 relative (measured), at and near the box's edges too."""
    D, v, q, t = 0.5, 1.0, 2.0, 3.0
    x = np.array([-2.0, -1.0, -0.999, -0.5, 0.0, 0.3, 0.999999, 1.0, 1.2, 2.0, 3.5, 5.0])
    box = ReleaseReference(Source.of("box", a=-1.0, b=1.0), Release(q), D, v, t).density(x)
    exact = [_convolved(xi, lambda z: 0.5, -1.0, 1.0, t, q, D, v) for xi in x]
    assert _rel(box, exact) < 1e-11
    sd = 0.1
    normal = lambda z: math.exp(-0.5 * ((z - 0.2) / sd) ** 2) / (sd * math.sqrt(2.0 * math.pi))  # noqa: E731
    gauss = ReleaseReference(Source.of("gaussian", x0=0.2, sd=sd), Release(q), D, v, t).density(x)
    exact = [_convolved(xi, normal, 0.2 - 14 * sd, 0.2 + 14 * sd, t, q, D, v) for xi in x]
    assert _rel(gauss, exact) < 1e-11


@pytest.mark.parametrize("D, v, t", [(1.0, 1.0, 1.0), (0.1, 1.0, 5.0), (1.0, 0.0, 2.0), (0.05, 2.0, 20.0)])
def test_1d_entropy_matches_quad_of_the_closed_form(D, v, t):
    """H_I = -integral p ln p of the continuous point source: within 4e-15 nats of scipy's quad (measured)."""
    ref = ReleaseReference(Source.of("point", x0=0.0), Release(1.0), D, v, t)
    width = math.sqrt(4.0 * D * t)
    lo, hi = -12.0 * width - (50.0 * D / abs(v) if v else 0.0), v * t + 12.0 * width
    f = lambda x: float(entr(point_release(x, t, 1.0, D, v) / ref.mass))  # noqa: E731
    cuts = sorted({lo, 0.0, hi, *np.linspace(lo, hi, 41)})
    exact = sum(quad(f, a, b, epsabs=1e-16, epsrel=1e-13, limit=400)[0] for a, b in zip(cuts[:-1], cuts[1:]))
    assert ref.entropy() == pytest.approx(exact, abs=1e-12)
    assert ref.dilution() == pytest.approx(math.exp(exact), rel=1e-12)


_SOURCES_1D = [("point", {"x0": 0.3}), ("gaussian", {"x0": -1.0, "sd": 0.2}), ("box", {"a": -1.0, "b": 2.0}),
               ("two_gaussians", {"x1": 0.0, "sd1": 0.1, "x2": 3.0, "sd2": 0.5, "fraction": 0.3})]  # fmt: skip


@pytest.mark.parametrize("kind, params", _SOURCES_1D)
@pytest.mark.parametrize(
    "D, v, t, release",
    [(1.0, 1.0, 1.0, Release(2.0)), (0.01, 1.0, 10.0, Release(1.0)), (1.0, 0.0, 3.0, Release(1.0, 0.5)),
     (0.1, 2.0, 5.0, Release(1.0, 1.0, 3.0))],
)  # fmt: skip
def test_1d_mass_is_the_released_mass(kind, params, D, v, t, release):
    """integral c dx = M(t): within 1e-15 relative (measured), a narrow lobe of two_gaussians too."""
    ref = ReleaseReference(Source.of(kind, **params), release, D, v, t)
    assert ref.total() == pytest.approx(ref.mass, rel=1e-8)
    x, w = ref.spatial_rule()
    assert w @ ref.density(x) == pytest.approx(ref.mass, rel=1e-8)


@pytest.mark.parametrize("kind, params", _SOURCES_1D[:3])
def test_1d_entropy_of_a_short_release_tends_to_the_instantaneous_one(kind, params):
    """A release on [0, d] seen at t is the instantaneous plume of age ~ t - d/2: H_I within O(d^2)."""
    D, v, t = 0.5, 1.0, 2.0
    source = Source.of(kind, **params)
    gaps = []
    for d in (1e-2, 1e-3):
        h = ReleaseReference(source, Release(1.0, 0.0, d), D, v, t).entropy()
        gaps.append(abs(h - Reference(source, D, v, t - 0.5 * d).entropy()))
        assert h == pytest.approx(Reference(source, D, v, t).entropy(), abs=2 * d)
    assert gaps[1] < 1e-7 and gaps[1] < gaps[0] / 50  # second order in d


# ------------------------------------------------------------------------ 2-D
def _unit(degrees: float) -> np.ndarray:
    a = math.radians(degrees)
    return np.array([math.cos(a), math.sin(a)])


@pytest.mark.parametrize(
    "D_L, D_T, speed, t, degrees",
    [(1.0, 0.1, 1.0, 20.0, 0.0), (0.5, 0.5, 2.0, 3.0, 30.0), (1.0, 0.01, 1.0, 100.0, 0.0), (0.1, 0.01, 1.0, 50.0, 60.0),
     (1.0, 1.0, 0.01, 10.0, 0.0)],
)  # fmt: skip
def test_a_2d_point_release_matches_wilson_and_miller(D_L, D_T, speed, t, degrees):
    """Along, across and off the axis, upstream and beyond the front, down to 1e-8 from the source:
    within 3e-11 relative (measured)."""
    v = speed * _unit(degrees)
    x0 = np.array([0.3, -0.2])
    ref = ReleaseReference2D(
        Source2D.of("point", x0=list(x0)), Release(1.5), dispersion_tensor(v, {"L": D_L, "T": D_T}), v, t
    )
    rng = np.random.default_rng(5)
    half = math.sqrt(4.0 * D_L * t)
    local = np.column_stack(
        [rng.uniform(-half, speed * t + half, 100), rng.uniform(-2, 2, 100) * math.sqrt(4 * D_T * t)]
    )
    axis = [[1e-3, 0.0], [0.0, 1e-3], [-1e-6, 0.0], [1e-8, 0.0], [speed * t, 0.0], [2 * speed * t, 0.0], [-half, 0.0]]
    local = np.vstack([local, axis])
    along = _unit(degrees)
    points = x0 + np.outer(local[:, 0], along) + np.outer(local[:, 1], [-along[1], along[0]])
    exact = point_release_2d(points, t, 1.5, D_L, D_T, v, x0=x0)
    shown = exact > 1e-300
    assert _rel(ref.density(points)[shown], exact[shown]) < 1e-9


def test_a_2d_point_release_is_infinite_at_its_point_only_while_it_releases():
    D, v = np.diag([1.0, 0.2]), np.array([1.0, 0.0])
    on = ReleaseReference2D(Source2D.of("point", x0=[1.0, 2.0]), Release(1.0), D, v, 2.0)
    c = on.density([[1.0, 2.0], [1.0 + 1e-9, 2.0]])
    assert c[0] == math.inf and math.isfinite(c[1]) and c[1] > 0
    ended = ReleaseReference2D(Source2D.of("point", x0=[1.0, 2.0]), Release(1.0, 0.0, 1.0), D, v, 2.0)
    assert math.isfinite(ended.density([[1.0, 2.0]])[0])


@pytest.mark.parametrize("degrees", [0.0, 35.0])
def test_a_2d_box_wide_across_is_the_1d_box_over_its_width(degrees):
    """A box [a, b] x [-L, L] with L far beyond the plume: on y = 0, c = c_1D(x; D_xx, v_x) / (2 L)
    (the y-marginal of the spreading holds all its mass), in an oblique flow too."""
    v = 1.2 * _unit(degrees)
    D = dispersion_tensor(v, {"L": 0.4, "T": 0.04})
    half_across, t = 1e3, 2.0
    ref = ReleaseReference2D(Source2D.of("box", x=[-0.5, 1.0], y=[-half_across, half_across]), Release(2.0), D, v, t)
    x = np.array([-1.0, -0.5, 0.0, 0.999, 1.0, 2.0, 3.0])
    one_d = ReleaseReference(Source.of("box", a=-0.5, b=1.0), Release(2.0), float(D[0, 0]), float(v[0]), t)
    c = ref.density(np.column_stack([x, np.zeros_like(x)]))
    assert _rel(c, one_d.density(x) / (2.0 * half_across)) < 1e-10


def _radial_entropy(D: float, t: float) -> float:
    """H_I of the 2-D point release at v = 0, c = q E1(r^2 / (4 D t)) / (4 pi D), by scipy's quad in r."""
    f = lambda r: 2.0 * math.pi * r * float(entr(exp1(r * r / (4.0 * D * t)) / (4.0 * math.pi * D * t)))  # noqa: E731
    width = math.sqrt(4.0 * D * t)
    cuts = [0.0, *(width * 10.0**k for k in range(-12, 1)), 3.0 * width, 10.0 * width]
    return sum(quad(f, a, b, epsabs=1e-15, epsrel=1e-13, limit=400)[0] for a, b in zip(cuts[:-1], cuts[1:]))


@pytest.mark.parametrize("D, t", [(1.0, 1.0), (0.3, 7.0)])
def test_2d_entropy_of_a_point_release_at_rest_matches_its_radial_form(D, t):
    """The density is infinite at the source (log singularity); H_I within 4e-14 nats (measured)."""
    ref = ReleaseReference2D(Source2D.of("point", x0=[0.5, 1.0]), Release(1.0), np.diag([D, D]), [0.0, 0.0], t)
    assert ref.h_i() == pytest.approx(_radial_entropy(D, t), abs=1e-10)
    assert ref.total() == pytest.approx(ref.mass, rel=1e-12)


_SOURCES_2D = [("point", {"x0": [0.0, 0.0]}), ("gaussian", {"x0": [0.0, 0.0], "sd": [0.3, 0.1]}),
               ("box", {"x": [-1.0, 1.0], "y": [0.0, 0.5]})]  # fmt: skip
_FLOWS_2D = [([1.0, 0.0], (1.0, 0.1), 5.0, Release(1.0)), ([1.0, 1.0], (0.5, 0.05), 4.0, Release(2.0, 1.0)),
             ([2.0, 0.0], (0.2, 0.02), 10.0, Release(1.0, 0.0, 5.0))]  # fmt: skip


@pytest.mark.parametrize("kind, params", _SOURCES_2D)
@pytest.mark.parametrize("v, D, t, release", _FLOWS_2D)
def test_2d_mass_is_the_released_mass(kind, params, v, D, t, release):
    """integral c dA = M(t): within 1e-14 relative (measured); H_I of a box in an oblique flow refused."""
    v = np.array(v)
    ref = ReleaseReference2D(Source2D.of(kind, **params), release, dispersion_tensor(v, dict(zip("LT", D))), v, t)
    if kind == "box" and v[1] != 0:
        with pytest.raises(ValueError, match="oblique flow"):
            ref.total()
        return
    assert ref.total() == pytest.approx(ref.mass, rel=1e-8)


def test_2d_rule_nodes_carry_the_density():
    """spatial_rule's nodes, in x and y (D's principal axes for a point in an oblique flow), and the
    density there give the same mass as the rule's own sum."""
    v = np.array([1.0, 1.0])
    ref = ReleaseReference2D(
        Source2D.of("point", x0=[0.2, 0.1]), Release(1.0), dispersion_tensor(v, {"L": 0.5, "T": 0.05}), v, 1.5
    )
    points, w = ref.spatial_rule()
    rng = np.random.default_rng(2)
    pick = rng.choice(len(points), 2000, replace=False)
    assert _rel(ref.density(points[pick]), ref.density_on_rule()[pick]) < 1e-10
    assert ref.total() == pytest.approx(ref.mass, rel=1e-12)


@pytest.mark.parametrize("kind, params", _SOURCES_2D)
def test_2d_entropy_of_a_short_release_tends_to_the_instantaneous_one(kind, params):
    """A release on [0, d] seen at t: H_I within O(d^2) of Reference2D's at age t - d/2."""
    v, D, t = np.array([1.0, 0.0]), np.diag([0.5, 0.1]), 2.0
    source = Source2D.of(kind, **params)
    gaps = []
    for d in (1e-2, 1e-3):
        h = ReleaseReference2D(source, Release(1.0, 0.0, d), D, v, t).h_i()
        gaps.append(abs(h - Reference2D(source, D, v, t - 0.5 * d).h_i()))
        assert h == pytest.approx(Reference2D(source, D, v, t).h_i(), abs=2 * d)
    assert gaps[1] < 1e-7 and gaps[1] < gaps[0] / 50


@pytest.mark.parametrize("kind, params", _SOURCES_2D)
def test_a_2d_density_at_the_measurement_lattice_is_fast(kind, params):
    """225 points (Reference2D.points) in well under a second (~0.1 s measured, flow along x)."""
    v, D = np.array([1.0, 0.0]), np.diag([0.5, 0.05])
    source = Source2D.of(kind, **params)
    ref = ReleaseReference2D(source, Release(1.0), D, v, 4.0)
    points = Reference2D(source, D, v, 2.0).points()
    start = time.perf_counter()
    c = ref.density(points)
    assert time.perf_counter() - start < 1.0
    assert c.shape == (225,) and np.all(c > 0)
