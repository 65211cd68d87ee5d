"""The one registry (registry.py) against its three copies: the config schema's enums and defaults,
the shipped config.yaml, and the command line's defaults and choices."""

from __future__ import annotations

import pytest
import yaml
from conftest import ROOT

from particle_entropy.cli import build_parser
from particle_entropy.core.registry import ALL_KERNELS, KERNELS, METHODS, SCHEMES, SHEAR_CASES, TRANSFER_METHODS
from particle_entropy.core.settings import PAPER

SCHEMA = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
CONFIG = yaml.safe_load((ROOT / "config.yaml").read_text())


def _resolve(node: dict) -> dict:
    """Follow a local ``$ref`` ('#/$defs/x') to its target; a node without one is returned as is."""
    ref = node.get("$ref")
    if ref is None:
        return node
    target = SCHEMA
    for part in ref.removeprefix("#/").split("/"):
        target = target[part]
    return _resolve(target)


# objects that are a user's problem, not settings: their defaults are a scene's (what an unset key
# means), and the shipped config writes its own problem there (the sweep's base scene)
USER_OBJECTS = {("scenes_peclet", "base"), ("scenes_peclet2d", "base")}


def _defaults(node: dict, path: tuple = ()) -> list[tuple[tuple, object]]:
    """(key path, default) of every property under ``node`` that declares a ``default`` itself
    (beside its ``$ref``, if any); ``$ref``s are followed into nested objects, but for USER_OBJECTS."""
    out = []
    if path in USER_OBJECTS:
        return out
    for key, prop in node.get("properties", {}).items():
        if "default" in prop:
            out.append(((*path, key), prop["default"]))
        out.extend(_defaults(_resolve(prop), (*path, key)))
    return out


def _at(config: dict, path: tuple):
    value = config
    for key in path:
        assert isinstance(value, dict) and key in value, f"config.yaml has no {'.'.join(path)}"
        value = value[key]
    return value


# --------------------------------------------------------------------------- schema enums
def test_schema_enums_equal_the_registry():
    defs = SCHEMA["$defs"]
    assert tuple(defs["method"]["enum"]) == METHODS
    assert tuple(defs["kernel"]["enum"]) == ALL_KERNELS
    assert tuple(defs["scheme"]["enum"]) == SCHEMES
    numerics = SCHEMA["properties"]["numerics"]["properties"]
    assert tuple(numerics["transfer_method"]["enum"]) == TRANSFER_METHODS
    assert tuple(SCHEMA["properties"]["shear"]["properties"]["cases"]["items"]["enum"]) == SHEAR_CASES


def test_registry_kernels_partition_all_kernels():
    # every kernel belongs to exactly one method, and ALL_KERNELS lists them method by method
    assert set(KERNELS) == set(METHODS)
    flat = [k for m in METHODS for k in KERNELS[m]]
    assert len(flat) == len(set(flat))
    assert ALL_KERNELS == ("bins", "fixed", "adaptive", "collision", "sph", "implicit", "explicit")


# --------------------------------------------------------------------------- schema defaults
def test_schema_walk_finds_the_defaults_of_every_section():
    paths = {p for p, _ in _defaults(SCHEMA)}
    for expected in [
        ("physics", "D"),
        ("physics", "fixed_kernel_time"),
        ("time", "fixed_dt"),
        ("base_seed",),
        ("seed_blocks", "size"),
        ("numerics", "transfer_tolerance"),
        ("case_defaults", "eta"),
        ("case_defaults", "truncation"),
        ("case_defaults", "scheme"),
        ("shear", "beta"),
    ]:
        assert expected in paths, expected


@pytest.mark.parametrize("path,default", _defaults(SCHEMA), ids=lambda v: ".".join(v) if isinstance(v, tuple) else None)
def test_schema_default_equals_shipped_config(path, default):
    value = _at(CONFIG, path)
    if isinstance(default, dict):  # an object's default: every key it sets agrees ({} agrees with anything)
        assert isinstance(value, dict)
        for k, v in default.items():
            assert value[k] == v, (path, k)
    else:
        assert value == default, (path, value, default)
        assert type(value) is type(default) or {type(value), type(default)} <= {int, float}


# --------------------------------------------------------------------------- PAPER vs config.yaml
@pytest.mark.parametrize("key", ["D", "t_final", "omega", "fd_length", "fixed_kernel_time"])
def test_paper_physics_equals_config(key):
    assert float(CONFIG["physics"][key]) == PAPER[key]


@pytest.mark.parametrize("key", ["dt0", "fd_dt", "fixed_dt"])
def test_paper_time_equals_config(key):
    assert float(CONFIG["time"][key]) == PAPER[key]


def test_paper_case_defaults_equal_config():
    cd = CONFIG["case_defaults"]
    assert float(cd["eta"]) == PAPER["eta"]
    assert cd["truncation"] == "none" and PAPER["truncation"] is None
    assert float(cd["dt_growth"]) == PAPER["dt_growth"]
    assert cd["scheme"] == PAPER["scheme"]


def test_paper_numerics_equal_config():
    assert CONFIG["numerics"]["transfer_method"] == PAPER["transfer_method"]
    assert float(CONFIG["numerics"]["transfer_tolerance"]) == PAPER["transfer_tolerance"]


def test_shear_defaults_are_the_papers_and_config_yamls():
    """Appendix B (experiments.md, Fig. 10): a 400 x 1 domain, the strip 90 < x < 110, alpha_L 1e-2,
    alpha_T 1e-3, 20,000 particles, dt 1 to t = 500; beta = 1/2 of Eq. 16; config.yaml says the same."""
    from particle_entropy.core.settings import SHEAR, defaults

    paper = {"n": 20_000, "length": 400, "strip_lo": 90, "strip_hi": 110, "alpha_L": 1e-2, "alpha_T": 1e-3}
    paper |= {"beta": 0.5, "dt": 1, "t_final": 500, "seed": 0}
    assert defaults(SHEAR) == paper
    assert {k: v for k, v in CONFIG["shear"].items() if k != "cases"} == paper


def test_paper_values_are_the_papers():
    # experiments.md / the paper: D = 1e-3, t = 1000, Omega = 10, FD on [-6, 6], dt0 = 0.01 growing 5%
    assert (PAPER["D"], PAPER["t_final"], PAPER["omega"], PAPER["fd_length"]) == (1e-3, 1000, 10, 12)
    assert (PAPER["dt0"], PAPER["dt_growth"], PAPER["eta"]) == (0.01, 1.05, 1)


# --------------------------------------------------------------------------- command line
def _simulate_parser():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    return sub.choices["simulate"]


def test_cli_defaults_equal_paper():
    a = build_parser().parse_args(["simulate", "--out", "x.parquet"])
    for key in [
        "D",
        "t_final",
        "omega",
        "fd_length",
        "fixed_kernel_time",
        "eta",
        "scheme",
        "transfer_method",
        "transfer_tolerance",
        "loop_arithmetic",
    ]:
        assert getattr(a, key) == PAPER[key], key


def test_cli_choices_equal_registry():
    choices = {a.dest: a.choices for a in _simulate_parser()._actions if a.choices is not None}
    assert tuple(choices["method"]) == METHODS
    assert tuple(choices["kernel"]) == ALL_KERNELS
    assert tuple(choices["scheme"]) == SCHEMES
    assert tuple(choices["transfer_method"]) == TRANSFER_METHODS
