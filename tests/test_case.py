"""The one identity of a model (case.py): Case construction and its refusals, round trips through
wildcards, paths and table rows, labels, and grouping tables by model."""

from __future__ import annotations

import dataclasses
import itertools
import math

import pandas as pd
import pytest

from particle_entropy.core.case import Case, SettingError, by_model, case_mask, case_of_table, models_in, rows_of, text
from particle_entropy.core.labels import case_label


def _grid() -> list[Case]:
    """Paper cases and variants of every method: truncation 3, dt_growth 1 and 1.01, the sequential
    scheme, eta 0.1 / 0.25 / 0.5."""
    cases = []
    for n in (30, 300):
        for kernel in ("implicit", "explicit"):
            cases.append(Case("fd", kernel, n))
        for kernel, growth in itertools.product(("bins", "fixed", "adaptive"), (1.0, 1.01, 1.05)):
            cases.append(Case("pt", kernel, n, dt_growth=growth))
        for kernel, eta, trunc, growth, scheme in itertools.product(
            ("collision", "sph"), (0.1, 0.25, 0.5, 1.0), (None, 3.0), (1.0, 1.01, 1.05), ("symmetric", "sequential")
        ):
            cases.append(Case("mtpt", kernel, n, eta=eta, truncation=trunc, dt_growth=growth, scheme=scheme))
    return cases


GRID = _grid()


# --------------------------------------------------------------------------- defaults
def test_unset_dimensions_take_papers_values_where_they_apply():
    mt = Case("mtpt", "collision", 300)
    assert (mt.eta, mt.truncation, mt.dt_growth, mt.scheme) == (1.0, None, 1.05, "symmetric")
    pt = Case("pt", "bins", 300)
    assert (pt.eta, pt.truncation, pt.dt_growth, pt.scheme) == (1.0, None, 1.05, "symmetric")
    fd = Case("fd", "implicit", 300)
    assert (fd.eta, fd.truncation, fd.dt_growth, fd.scheme) == (1.0, None, 1.0, "symmetric")


def test_case_is_frozen_and_hashable():
    c = Case("mtpt", "sph", 30)
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.eta = 0.5
    assert len({c, Case("mtpt", "sph", 30), Case("mtpt", "sph", 30, eta=1)}) == 1


def test_numbers_are_normalised():
    # an integer in config (eta: 1, truncation: 3) is the same case as its float
    assert Case("mtpt", "collision", 30, eta=1, truncation=3) == Case("mtpt", "collision", 30, eta=1.0, truncation=3.0)
    assert Case("mtpt", "collision", 30.0).n == 30 and isinstance(Case("mtpt", "collision", 30.0).n, int)


# --------------------------------------------------------------------------- round trips
def test_grid_is_what_it_claims():
    assert len(GRID) == len(set(GRID)) == 2 * (2 + 9 + 2 * 4 * 2 * 3 * 2)


@pytest.mark.parametrize("case", GRID, ids=lambda c: c.path())
def test_wildcards_round_trip(case):
    w = case.wildcards()
    assert all(isinstance(v, str) for v in w.values())
    assert Case.from_wildcards(w) == case


def test_rows_round_trip_through_a_parquet_table(tmp_path):
    df = pd.DataFrame([c.columns() for c in GRID])
    df.to_parquet(tmp_path / "cases.parquet")
    back = pd.read_parquet(tmp_path / "cases.parquet")
    assert [Case.from_row(r) for _, r in back.iterrows()] == GRID


def test_model_row_round_trip_and_truncation_as_inf():
    c = Case("mtpt", "collision", 300, eta=0.5)
    cols = c.model.columns()
    assert "n" not in cols and cols["truncation"] == math.inf
    assert Case.from_row(cols) == c.model and Case.from_row(cols).n is None
    assert Case("mtpt", "collision", 300, truncation=3).columns()["truncation"] == 3.0


def test_model_and_at():
    c = Case("mtpt", "sph", 300, eta=0.1, truncation=3)
    assert c.model.n is None and c.model.at(300) == c
    assert c.model == Case("mtpt", "sph", eta=0.1, truncation=3)
    with pytest.raises(SettingError) as e:
        c.model.wildcards()
    assert e.value.name == "n"


# --------------------------------------------------------------------------- path text
@pytest.mark.parametrize(
    "case,path",
    [
        (
            Case("mtpt", "collision", 300),
            "mtpt/collision/n~300/eta~1/trunc~none/growth~1.05/scheme~symmetric/grid~exact",
        ),
        (
            Case("mtpt", "collision", 30000, eta=0.5),
            "mtpt/collision/n~30000/eta~0.5/trunc~none/growth~1.05/scheme~symmetric/grid~exact",
        ),
        (
            Case("mtpt", "sph", 100, eta=0.1, truncation=3, dt_growth=1.01, scheme="sequential"),
            "mtpt/sph/n~100/eta~0.1/trunc~3/growth~1.01/scheme~sequential/grid~exact",
        ),
        (
            Case("mtpt", "collision", 300, eta=0.25, truncation=2.5, dt_growth=1),
            "mtpt/collision/n~300/eta~0.25/trunc~2.5/growth~1/scheme~symmetric/grid~exact",
        ),
        (Case("pt", "adaptive", 1000), "pt/adaptive/n~1000/eta~1/trunc~none/growth~1.05/scheme~symmetric/grid~exact"),
        (Case("fd", "implicit", 3000), "fd/implicit/n~3000/eta~1/trunc~none/growth~1/scheme~symmetric/grid~exact"),
        (
            Case("mtpt", "collision", 300, truncation=3, scheme="sequential", time_grid="authors"),
            "mtpt/collision/n~300/eta~1/trunc~3/growth~1.05/scheme~sequential/grid~authors",
        ),
    ],
)
def test_path_text_written_by_hand(case, path):
    assert case.path() == path


@pytest.mark.parametrize(
    "value,expected",
    [(1.0, "1"), (1, "1"), (0.5, "0.5"), (0.1, "0.1"), (1.05, "1.05"), (3.0, "3"), (None, "none"), ("sph", "sph")],
)
def test_text(value, expected):
    assert text(value) == expected


# --------------------------------------------------------------------------- one dimension apart
BASE = Case("mtpt", "collision", 300)


@pytest.mark.parametrize(
    "change",
    [
        {"kernel": "sph"},
        {"n": 1000},
        {"eta": 0.5},
        {"truncation": 3.0},
        {"dt_growth": 1.01},
        {"dt_growth": 1.0},
        {"scheme": "sequential"},
    ],
    ids=lambda d: "-".join(f"{k}={v}" for k, v in d.items()),
)
def test_cases_one_dimension_apart_differ_everywhere(change):
    other = dataclasses.replace(BASE, **change)
    assert other != BASE
    assert other.path() != BASE.path()
    assert other.columns() != BASE.columns()
    assert case_label(other) != case_label(BASE)
    assert other.wildcards() != BASE.wildcards()


# --------------------------------------------------------------------------- refusals
@pytest.mark.parametrize(
    "kwargs,name,value",
    [
        ({"method": "mtpt", "kernel": "bins"}, "kernel", "bins"),
        ({"method": "pt", "kernel": "collision"}, "kernel", "collision"),
        ({"method": "walk", "kernel": "bins"}, "method", "walk"),
        ({"method": "pt", "kernel": "bins", "scheme": "sequential"}, "scheme", "sequential"),
        ({"method": "pt", "kernel": "fixed", "truncation": 3}, "truncation", "3"),
        ({"method": "fd", "kernel": "implicit", "eta": 0.5}, "eta", "0.5"),
        ({"method": "fd", "kernel": "implicit", "dt_growth": 1.05}, "dt_growth", "1.05"),
        ({"method": "mtpt", "kernel": "collision", "eta": 1.5}, "eta", "1.5"),
        ({"method": "mtpt", "kernel": "collision", "eta": -0.1}, "eta", "-0.1"),
        ({"method": "mtpt", "kernel": "collision", "truncation": 0}, "truncation", "0"),
        ({"method": "mtpt", "kernel": "collision", "truncation": -3}, "truncation", "-3"),
        ({"method": "mtpt", "kernel": "collision", "dt_growth": 0.9}, "dt_growth", "0.9"),
        ({"method": "mtpt", "kernel": "collision", "scheme": "matrix"}, "scheme", "matrix"),
        ({"method": "mtpt", "kernel": "collision", "n": 0}, "n", "0"),
        ({"method": "mtpt", "kernel": "collision", "n": 2.5}, "n", "2.5"),
    ],
)
def test_refusals_name_key_and_value(kwargs, name, value):
    with pytest.raises(SettingError) as e:
        Case(**kwargs)
    assert e.value.name == name
    assert name in str(e.value) and value in str(e.value)


def test_from_spec_refuses_unknown_key_and_inapplicable_dimension():
    with pytest.raises(SettingError) as e:
        Case.from_spec({"method": "mtpt", "kernel": "collision", "beta": 0.5}, 300)
    assert "beta" in str(e.value)
    with pytest.raises(SettingError) as e:
        Case.from_spec({"method": "fd", "kernel": "implicit", "eta": 0.5}, 30)
    assert e.value.name == "eta" and "0.5" in str(e.value)
    with pytest.raises(SettingError) as e:
        Case.from_spec({"method": "pt", "kernel": "bins", "scheme": "sequential"}, 30)
    assert e.value.name == "scheme" and "sequential" in str(e.value)


# --------------------------------------------------------------------------- from_spec and defaults
DEFAULTS = {"eta": 0.5, "truncation": 3, "dt_growth": 1.3, "scheme": "sequential"}


def test_from_spec_takes_defaults_only_where_they_apply():
    fd = Case.from_spec({"method": "fd", "kernel": "implicit"}, 100, DEFAULTS)
    assert fd == Case("fd", "implicit", 100) and fd.dt_growth == 1.0
    pt = Case.from_spec({"method": "pt", "kernel": "fixed"}, 100, DEFAULTS)
    assert (pt.dt_growth, pt.eta, pt.truncation, pt.scheme) == (1.3, 1.0, None, "symmetric")
    mt = Case.from_spec({"method": "mtpt", "kernel": "sph"}, 100, DEFAULTS)
    assert (mt.dt_growth, mt.eta, mt.truncation, mt.scheme) == (1.3, 0.5, 3.0, "sequential")


def test_from_spec_spec_beats_defaults_and_none_means_whole_kernel():
    mt = Case.from_spec(
        {"method": "mtpt", "kernel": "collision", "eta": 1, "truncation": "none", "dt_growth": 1}, 30, DEFAULTS
    )
    assert (mt.eta, mt.truncation, mt.dt_growth, mt.scheme) == (1.0, None, 1.0, "sequential")
    # config case_defaults write truncation: none
    paper = Case.from_spec({"method": "mtpt", "kernel": "collision"}, 30, {"truncation": "none", "dt_growth": 1.05})
    assert paper == Case("mtpt", "collision", 30)
    # no defaults: the paper's
    assert Case.from_spec({"method": "pt", "kernel": "bins"}, 30) == Case("pt", "bins", 30)
    assert Case.from_spec({"method": "pt", "kernel": "bins"}).n is None


# --------------------------------------------------------------------------- labels
def test_labels_name_variants_and_not_paper_cases():
    paper = Case("mtpt", "collision", 300)
    trunc = Case("mtpt", "collision", 300, truncation=3)
    seq = Case("mtpt", "collision", 300, scheme="sequential")
    fixed = Case("mtpt", "collision", 300, dt_growth=1)
    assert "truncation 3" in case_label(trunc) and "sequential" not in case_label(trunc)
    assert "sequential" in case_label(seq) and "truncation" not in case_label(seq)
    for word in ("truncation", "sequential", "growth", "fixed"):
        assert word not in case_label(paper)
    assert case_label(fixed) != case_label(paper) and case_label(fixed) != case_label(
        Case("mtpt", "collision", 300, dt_growth=1.01)
    )
    assert "N=300" in case_label(paper) and "N=" not in case_label(paper, n=False)
    assert "300" in case_label(paper) and "300" not in case_label(paper.model)
    assert "MTPT" in case_label(paper) and "η=1" in case_label(paper)
    assert case_label(Case("fd", "implicit", 30)) != case_label(Case("fd", "explicit", 30))


def test_variant_lists_only_the_dimensions_off_the_paper():
    assert Case("mtpt", "collision", 300).variant() == {}
    assert Case("mtpt", "collision", 300, eta=0.1).variant() == {}  # eta is a paper dimension (Fig. 5)
    assert Case("mtpt", "collision", 300, truncation=3, scheme="sequential").variant() == {
        "truncation": 3.0,
        "scheme": "sequential",
    }
    assert Case("pt", "bins", 300, dt_growth=1).variant() == {"dt_growth": 1.0}
    assert Case("fd", "implicit", 300).variant() == {}


def test_sort_key_orders_methods_kernels_eta_and_variants():
    ordered = [
        Case("pt", "bins", 30),
        Case("pt", "adaptive", 30),
        Case("mtpt", "collision", 30),
        Case("mtpt", "collision", 300),
        Case("mtpt", "collision", 30, truncation=3),
        Case("mtpt", "collision", 30, eta=0.5),
        Case("mtpt", "sph", 30),
        Case("fd", "implicit", 30),
    ]
    shuffled = [ordered[i] for i in (7, 3, 5, 0, 6, 2, 4, 1)]
    assert sorted(shuffled, key=Case.sort_key) == ordered


# --------------------------------------------------------------------------- tables
def _table() -> pd.DataFrame:
    """A hand-built result table: two MTPT models differing only in truncation, one PT, one FD."""
    rows = []
    for tag, case in [
        ("a30", Case("mtpt", "collision", 30)),
        ("a100", Case("mtpt", "collision", 100)),
        ("t30", Case("mtpt", "collision", 30, truncation=3)),
        ("t100", Case("mtpt", "collision", 100, truncation=3)),
        ("p30", Case("pt", "bins", 30)),
        ("f30", Case("fd", "implicit", 30)),
        ("f100", Case("fd", "implicit", 100)),
        ("a30b", Case("mtpt", "collision", 30)),
    ]:
        rows.append({**case.columns(), "tag": tag})
    return pd.DataFrame(rows)


def test_by_model_groups_rows_into_the_right_models():
    groups = {model: sorted(rows["tag"]) for model, rows in by_model(_table())}
    assert groups == {
        Case("pt", "bins"): ["p30"],
        Case("mtpt", "collision"): ["a100", "a30", "a30b"],
        Case("mtpt", "collision", truncation=3): ["t100", "t30"],
        Case("fd", "implicit"): ["f100", "f30"],
    }
    assert models_in(_table()) == [
        Case("pt", "bins"),
        Case("mtpt", "collision"),
        Case("mtpt", "collision", truncation=3),
        Case("fd", "implicit"),
    ]


def test_case_mask_and_rows_of_select_one_case_or_a_model():
    df = _table()
    assert list(df[case_mask(df, Case("mtpt", "collision", 30))]["tag"]) == ["a30", "a30b"]
    assert list(rows_of(df, Case("mtpt", "collision", 100, truncation=3))["tag"]) == ["t100"]
    assert rows_of(df, Case("mtpt", "sph")).empty
    assert case_of_table(df.iloc[2:4]) == Case("mtpt", "collision", 30, truncation=3)


@pytest.mark.parametrize("n", [math.nan, math.inf, 2.5, -1])
def test_non_integer_n_is_refused_naming_n(n):
    with pytest.raises(SettingError, match=r"^n="):
        Case("mtpt", "collision", n)


def test_the_word_none_reads_as_none_in_configs_paths_and_options():
    from particle_entropy.cli import build_parser
    from particle_entropy.core.case import from_text, text

    assert from_text("none") is None and from_text("None") is None and from_text(3.0) == 3.0
    assert text(from_text("none")) == "none" and from_text(text(None)) is None
    spec = Case.from_spec({"method": "mtpt", "kernel": "collision", "truncation": "none"}, 30)
    assert spec.truncation is None
    assert Case.from_wildcards({**spec.wildcards()}).truncation is None
    args = build_parser().parse_args(["simulate", "--truncation", "None", "--out", "x.parquet"])
    assert args.truncation is None


def test_the_time_grid_is_a_dimension_of_particle_cases_only():
    from particle_entropy.core.labels import case_label

    authors = Case("pt", "bins", 100, time_grid="authors")
    assert authors != Case("pt", "bins", 100) and authors.path() != Case("pt", "bins", 100).path()
    assert Case.from_wildcards(authors.wildcards()) == authors
    assert Case.from_row(authors.columns()) == authors
    assert authors.columns()["time_grid"] == "authors" and "authors' time grid" in case_label(authors)
    assert Case("fd", "implicit", 30).time_grid == "exact"
    with pytest.raises(SettingError, match="time_grid applies to method pt and mtpt only"):
        Case("fd", "implicit", 30, time_grid="authors")
    with pytest.raises(SettingError, match="time_grid='daily' is not allowed: one of exact, authors"):
        Case("mtpt", "collision", 30, time_grid="daily")
    spec = Case.from_spec({"method": "mtpt", "kernel": "sph"}, 30, {"time_grid": "authors"})
    assert spec.time_grid == "authors"  # from case_defaults


def test_the_authors_preset_is_all_of_their_algorithm_and_explicit_keys_win():
    from particle_entropy.core.labels import case_label

    spec = {"method": "mtpt", "kernel": "sph", "eta": 1, "preset": "authors"}
    authors = Case.from_spec(spec, 300, {"truncation": "none", "time_grid": "exact"})
    assert (authors.scheme, authors.truncation, authors.time_grid) == ("authors", 3.0, "authors")
    assert "the authors' algorithm" in case_label(authors)
    exact = Case.from_spec({**spec, "time_grid": "exact"}, 300)  # one change from the preset
    assert (exact.scheme, exact.truncation, exact.time_grid) == ("authors", 3.0, "exact")
    assert "the authors' algorithm" not in case_label(exact) and "SPH constant 0.822" in case_label(exact)
    with pytest.raises(SettingError, match="preset='theirs' is not allowed: one of authors"):
        Case.from_spec({**spec, "preset": "theirs"}, 300)
    with pytest.raises(SettingError, match="preset='authors' is not allowed: a preset of mtpt cases"):
        Case.from_spec({"method": "pt", "kernel": "bins", "preset": "authors"}, 300)
