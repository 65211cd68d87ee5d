"""Source kinds (core/sources.py): one class per kind, listed once in SOURCES; what every kind
must give, its record, its config checks and the schema fragment derived from the registry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from particle_entropy.core.case import SettingError
from particle_entropy.core.settings import SOURCE_SHAPE
from particle_entropy.core.sources import LEGACY_FIELDS, SOURCES, Source, SourceError, TwoGaussians, source_shape
from particle_entropy.models import simulate
from particle_entropy.scenes.scene import Scene

# one valid spec per kind (a new kind adds one here and every test below covers it)
EXAMPLES = {
    "point": {"kind": "point", "x0": 0.3},
    "gaussian": {"kind": "gaussian", "x0": -0.2, "sd": 0.15},
    "box": {"kind": "box", "a": -0.4, "b": 0.1},
    "two_gaussians": {"kind": "two_gaussians", "x1": -0.5, "sd1": 0.1, "x2": 0.4, "sd2": 0.25, "fraction": 0.3},
}


def test_every_kind_has_an_example():
    assert set(EXAMPLES) == set(SOURCES)


def test_the_schema_lists_the_registrys_kinds_and_every_parameter():
    from dataclasses import fields

    from particle_entropy.core.sources2d import SOURCES2D, with_pairs

    assert SOURCE_SHAPE == with_pairs(source_shape())  # the line's kinds, and the plane's pairs
    assert SOURCE_SHAPE["properties"]["kind"]["enum"] == list(dict.fromkeys([*SOURCES, *SOURCES2D]))
    for cls in SOURCES.values():
        assert {p.name for p in cls.PARAMS} <= set(SOURCE_SHAPE["properties"])
    for cls in SOURCES2D.values():  # a key of both a number or a pair; the plane's own a pair
        for f in fields(cls):
            entry = SOURCE_SHAPE["properties"][f.name]
            pairs = [e for e in entry.get("oneOf", [entry]) if e.get("type") == "array"]
            assert len(pairs) == 1 and pairs[0]["minItems"] == pairs[0]["maxItems"] == 2


@pytest.mark.parametrize("kind", list(EXAMPLES))
def test_a_record_reads_back_as_the_same_source(kind):
    source = Source.from_spec(EXAMPLES[kind])
    assert source.kind == kind and isinstance(source, SOURCES[kind])
    record = source.record()
    assert record["kind"] == kind
    assert Source.of(**record) == source
    if SOURCES[kind].LEGACY:  # the digests of runs made before kinds were classes keep their fields
        assert list(record) == ["kind", *LEGACY_FIELDS]


@pytest.mark.parametrize("kind", list(EXAMPLES))
def test_unit_mass_on_particles_and_nodes_and_the_density_integrates_to_one(kind):
    source = Source.from_spec(EXAMPLES[kind])
    x = np.linspace(-3.0, 3.0, 6001)
    assert source.masses(x, x[1] - x[0]).sum() == pytest.approx(1.0, abs=1e-12)
    xs, m = source.weighted_particles(500, 6.0, 6.0 / 500, np.random.default_rng(1))
    assert xs.size == m.size == 500 and m.sum() == pytest.approx(1.0, abs=1e-12)
    c = source.density(x, 0.01, 0.5, 1.0)
    assert c.sum() * (x[1] - x[0]) == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("kind", list(EXAMPLES))
def test_the_sample_moments_are_the_sources(kind):
    source = Source.from_spec(EXAMPLES[kind])
    x = source.positions(200_000, np.random.default_rng(5))
    sd = math.sqrt(source.variance)
    assert x.mean() == pytest.approx(source.centre, abs=5 * sd / math.sqrt(x.size) + 1e-15)
    assert x.var() == pytest.approx(source.variance, rel=0.02, abs=1e-15)
    assert np.all(np.abs(x - source.centre) <= source.half_width + 1e-12)


@pytest.mark.parametrize(
    "spec, param, match",
    [
        ({"kind": "line"}, "kind", "one of point, gaussian, box"),
        ({"kind": "point", "sd": 1.0}, "sd", "not a key of a point source"),
        ({"kind": "gaussian", "x0": "0"}, "x0", "a finite number"),
        ({"kind": "gaussian", "sd": 1e-200}, "sd", "normal float"),
        ({"kind": "box", "a": 1.0, "b": 0.0}, "b", "a < b"),
    ],
)
def test_a_bad_spec_names_the_parameter(spec, param, match):
    with pytest.raises(SourceError, match=match) as err:
        Source.from_spec(spec)
    assert err.value.param == param


# ------------------------------------------------------------------------------ two_gaussians
def _two(**over) -> TwoGaussians:
    return Source.from_spec({**EXAMPLES["two_gaussians"], **over})


def _quad_entropy(source, D, t) -> float:
    """-integral c ln c dx by scipy's adaptive quadrature, split at each lobe's mean."""

    def f(x):
        c = float(source.density(np.array([x]), D, 0.0, t)[0])
        return -c * math.log(c) if c > 0 else 0.0

    lobes = sorted((source.x1, source.x2))
    reach = 14.0 * math.sqrt(max(source.sd1, source.sd2) ** 2 + 2 * D * t)
    cuts = [lobes[0] - reach, *lobes, lobes[1] + reach]
    return sum(quad(f, a, b, limit=400, epsabs=1e-13, epsrel=1e-12)[0] for a, b in zip(cuts, cuts[1:]))


def test_two_gaussians_mass_is_unit_and_the_first_lobe_holds_its_fraction():
    source = _two(x1=-2.0, sd1=0.1, x2=3.0, sd2=0.3, fraction=0.3)  # apart: 1e-23 of a lobe past x = 0
    x = np.linspace(-4.0, 6.0, 10001)
    m = source.masses(x, x[1] - x[0])
    assert m.sum() == pytest.approx(1.0, abs=1e-12)
    assert m[x < 0].sum() == pytest.approx(0.3, abs=1e-12)
    total, _ = quad(lambda y: float(source.density(np.array([y]), 1e-3, 0.5, 2.0)[0]), -10, 10, points=[-2, 3])
    assert total == pytest.approx(1.0, abs=1e-10)
    first, _ = quad(
        lambda y: float(source.density(np.array([y]), 0.0, 0.0, 0.0)[0]), -10, 0, points=[-2.0], epsabs=1e-14
    )
    assert first == pytest.approx(0.3, abs=1e-12)


@pytest.mark.parametrize(
    "over, D, t",
    [
        ({}, 1e-3, 0.0),
        ({}, 1e-2, 5.0),
        ({"x1": 0.0, "sd1": 0.01, "x2": 0.05, "sd2": 1.0, "fraction": 0.8}, 1e-4, 1.0),  # a narrow lobe in a wide one
        ({"x1": -0.1, "sd1": 0.05, "x2": 0.1, "sd2": 0.05, "fraction": 0.5}, 0.0, 0.0),  # overlapping
    ],
)
def test_two_gaussians_entropy_matches_quadrature(over, D, t):
    source = _two(**over)
    assert source.entropy(D, t) == pytest.approx(_quad_entropy(source, D, t), abs=1e-9)


def test_two_gaussians_entropy_limits_are_closed_forms():
    """Far apart: each lobe's entropy, weighted, plus the mixing entropy of the fractions; one place
    and one width: the Gaussian's ln sqrt(2 pi e variance) (Eq. 14)."""
    f, sd1, sd2 = 0.3, 0.1, 0.02
    far = _two(x1=-1e6, sd1=sd1, x2=1e6, sd2=sd2, fraction=f)
    gauss = [0.5 * math.log(2 * math.pi * math.e * sd**2) for sd in (sd1, sd2)]
    mixing = -f * math.log(f) - (1 - f) * math.log(1 - f)
    assert far.entropy(0.0, 0.0) == pytest.approx(f * gauss[0] + (1 - f) * gauss[1] + mixing, abs=1e-12)
    one = _two(x1=0.3, sd1=0.2, x2=0.3, sd2=0.2, fraction=0.4)
    D, t = 0.01, 3.0
    exact = Source.of("gaussian", x0=0.3, sd=0.2)
    assert one.entropy(D, t) == pytest.approx(exact.entropy(D, t), abs=1e-12)
    x = np.linspace(-1.0, 2.0, 301)
    np.testing.assert_allclose(one.density(x, D, 0.7, t), exact.density(x, D, 0.7, t), rtol=1e-13, atol=1e-300)


def test_two_gaussians_density_solves_advection_dispersion():
    source, D, v, t, k = _two(), 0.01, 0.3, 1.5, 1e-4
    x = np.linspace(-1.5, 2.0, 71)
    h = 1e-3
    dcdt = (source.density(x, D, v, t + k) - source.density(x, D, v, t - k)) / (2 * k)
    c = lambda y: source.density(y, D, v, t)  # noqa: E731
    dcdx = (c(x + h) - c(x - h)) / (2 * h)
    d2cdx2 = (c(x + h) - 2 * c(x) + c(x - h)) / h**2
    np.testing.assert_allclose(dcdt, D * d2cdx2 - v * dcdx, atol=2e-4)


def test_two_gaussians_positions_have_the_sources_moments():
    source = _two()
    x = source.positions(400_000, np.random.default_rng(11))
    assert x.mean() == pytest.approx(source.centre, abs=4e-3)
    assert x.var() == pytest.approx(source.variance, rel=5e-3)
    skew = np.mean((x - x.mean()) ** 3)  # the third central moment of the mixture
    f, d1, d2 = 0.3, source.x1 - source.centre, source.x2 - source.centre
    exact = f * (d1**3 + 3 * d1 * source.sd1**2) + (1 - f) * (d2**3 + 3 * d2 * source.sd2**2)
    assert skew == pytest.approx(exact, abs=2e-3)
    apart = _two(x1=-2.0, sd1=0.1, x2=2.0, sd2=0.3).positions(400_000, np.random.default_rng(12))
    assert np.mean(apart < 0) == pytest.approx(0.3, abs=3 * math.sqrt(0.3 * 0.7 / 400_000))


@pytest.mark.parametrize(
    "over, key",
    [
        ({"fraction": 1.0}, "scenes.s.source.fraction"),
        ({"fraction": 0.0}, "scenes.s.source.fraction"),
        ({"sd2": -0.1}, "scenes.s.source.sd2"),
        ({"sd1": 1e-200}, "scenes.s.source.sd1"),
        ({"x2": None}, "scenes.s.source.x2"),
        ({"sd": 0.1}, "scenes.s.source.sd"),
    ],
)
def test_two_gaussians_bad_parameters_are_refused_naming_the_key(over, key):
    spec = {**EXAMPLES["two_gaussians"], **over}
    spec = {k: v for k, v in spec.items() if v is not None}
    scene = {
        "t_final": 10.0,
        "target": {"value": 0.02},
        "source": spec,
        "candidates": [{"method": "pt", "kernel": "adaptive", "n_range": [30, 100]}],
    }
    with pytest.raises(SettingError) as err:
        Scene.from_config("s", scene)
    assert err.value.name == key


def test_a_two_gaussians_scene_runs_every_method():
    spec = {
        "t_final": 10.0,
        "target": {"value": 0.02},
        "source": EXAMPLES["two_gaussians"],
        "v": 0.01,
        "candidates": [
            {"method": "fd", "kernel": "implicit", "fd_dt": 0.5, "n_range": [64, 128]},
            {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [100, 200]},
            {"method": "pt", "kernel": "adaptive", "n_range": [100, 200]},
        ],
    }
    scene = Scene.from_config("s", spec)
    assert scene.source.record()["kind"] == "two_gaussians"
    for cand in scene.candidates:
        table = simulate.run(scene.run_config(cand, cand.n_lo))[0]
        assert np.isfinite(table["SSE"]).all() and np.isfinite(table["H_C_analytic"]).all()
        last = table.iloc[-1]
        exact = scene.reference.h_c(float(last["dV"]))
        assert float(last["H_C_analytic"]) == pytest.approx(exact, rel=1e-12)
