"""Source kinds (core/sources.py): one class per kind, listed once in SOURCES; what every kind
must give, its record, its config checks and the schema fragment derived from the registry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from particle_entropy.core.settings import SOURCE_SHAPE
from particle_entropy.core.sources import LEGACY_FIELDS, SOURCES, Source, SourceError, source_shape

# one valid spec per kind (a new kind adds one here and every test below covers it)
EXAMPLES = {
    "point": {"kind": "point", "x0": 0.3},
    "gaussian": {"kind": "gaussian", "x0": -0.2, "sd": 0.15},
    "box": {"kind": "box", "a": -0.4, "b": 0.1},
}


def test_every_kind_has_an_example():
    assert set(EXAMPLES) == set(SOURCES)


def test_the_schema_lists_the_registrys_kinds_and_every_parameter():
    assert SOURCE_SHAPE == source_shape()
    assert SOURCE_SHAPE["properties"]["kind"]["enum"] == list(SOURCES)
    for cls in SOURCES.values():
        assert {p.name for p in cls.PARAMS} <= set(SOURCE_SHAPE["properties"])


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
