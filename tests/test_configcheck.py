"""Every config value that would make a job fail is refused before any job, in one message that
names the key path, the value and the allowed range (configcheck.check_config = what a dry run
checks). Each bad input is a one-key change of the shipped config.yaml."""

from __future__ import annotations

import copy

import pytest
import yaml
from conftest import ROOT, TINY

from particle_entropy.cli import main
from particle_entropy.core.case import SettingError
from particle_entropy.pipeline.configcheck import ConfigFileError, check_config, load_yaml, parse

BASE = yaml.safe_load((ROOT / "config.yaml").read_text())


def _set(path, value):
    def change(cfg):
        node = cfg
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value

    return change


def _add_case(section, case, n=None):
    def change(cfg):
        spec = cfg["figures"][section] if section.startswith("fig") else cfg[section]
        spec["cases"].append(case)
        if n is not None:
            spec["n"] = n

    return change


def _rename_in(path, old, new):
    def change(cfg):
        node = cfg
        for k in path:
            node = node[k]
        node[new] = node.pop(old)

    return change


def _rename_top(old, new):
    return lambda cfg: cfg.update({new: cfg.pop(old)})


# (id, change, text the message must contain: the key path, then a word of the allowed range)
BAD = [
    ("D nan", _set(("physics", "D"), float("nan")), ["physics.D=nan", "finite"]),
    ("t_final inf", _set(("physics", "t_final"), float("inf")), ["physics.t_final=inf", "finite"]),
    ("dt0 nan", _set(("time", "dt0"), float("nan")), ["time.dt0=nan", "finite"]),
    ("omega -inf", _set(("physics", "omega"), float("-inf")), ["physics.omega=-inf", "minimum of 0"]),
    ("D 0", _set(("physics", "D"), 0), ["physics.D=0", "> 0"]),
    ("D as text", _set(("physics", "D"), "1e-3"), ["physics.D='1e-3'", "write 1.0e-3"]),
    ("top-level typo", _rename_top("physics", "physic"), ["physic=", "did you mean physics?"]),
    ("time typo", _set(("time", "dt_0"), 0.01), ["time.dt_0=", "did you mean dt0?"]),
    ("unknown figure", lambda c: c["figures"].update(fig11=c["figures"]["fig1"]), ["figures.fig11", "fig8, fig9;"]),
    ("missing key", lambda c: c["physics"].pop("t_final"), ["physics.t_final='(missing)'", "Final time"]),
    ("base_seed 2^70", _set(("base_seed",), 2**70), ["base_seed=", "int64"]),
    ("base_seed 2^63-1", _set(("base_seed",), 2**63 - 1), ["base_seed=", "int64"]),
    (
        "tradeoff kernel mismatch",
        _add_case("tradeoff", {"method": "pt", "kernel": "collision"}),
        ["tradeoff.cases[", "kernel='collision'", "bins, fixed, adaptive"],
    ),
    ("tradeoff fd odd n", _set(("tradeoff", "n"), [31, 100]), ["tradeoff.cases[0].n=31", "even"]),
    (
        "explicit fd unstable",
        _add_case("fig8", {"method": "fd", "kernel": "explicit"}),
        ["time.fd_dt=0.05", "r = D dt / dx^2 < 1/2", "figures.fig8.cases[1]"],
    ),
    (
        "fixed_dt 1e-12",
        lambda c: (
            c["time"].update(fixed_dt=1e-12),
            _add_case("fig3", {"method": "pt", "kernel": "bins", "dt_growth": 1})(c),
        ),
        ["time.fixed_dt=1e-12", "10,000,000 steps"],
    ),
    ("fd_dt 1e-9", _set(("time", "fd_dt"), 1e-9), ["time.fd_dt=1e-09", "10,000,000 steps"]),
    ("t_final 1e12", _set(("physics", "t_final"), 1e12), ["physics.omega=10", "89442.7", "outgrow the particles"]),
    ("shear strip reversed", _set(("shear", "strip_lo"), 120), ["shear.strip_hi=110", "> 120"]),
    ("shear strip outside", _set(("shear", "strip_hi"), 500), ["shear.strip_hi=500", "<= 400"]),
    ("shear t_final not whole steps", _set(("shear", "t_final"), 500.5), ["shear.t_final=500.5", "whole number"]),
    ("shear too many steps", _set(("shear", "dt"), 1e-6), ["shear.dt=1e-06", "10,000,000 steps"]),
    ("shear seed 2^63", _set(("shear", "seed"), 2**63), ["shear.seed=", "int64"]),
    ("comic time past t_final", _set(("comic_times",), [250, 2000]), ["comic_times=2000", "[0, physics.t_final"]),
    ("tradeoff time past t_final", _set(("tradeoff", "times"), [250, 2000]), ["tradeoff.times=2000", "t_final"]),
    (
        "duplicate realisations",
        lambda c: c["realisations"].append({"n": 30, "count": 5}),
        ["realisations[", "].n=30", "each N once"],
    ),
    ("claims range reversed", _set(("claims", "fd_optimum_nodes"), [10000, 1000]), ["claims.fd_optimum_nodes", "low"]),
    (
        "N without an ensemble size",
        lambda c: c["figures"]["fig9"]["n"].append(123),
        ["figures.fig9.n=123", "add {n: 123, count: ...}"],
    ),
    (
        "eta out of range",
        _add_case("fig5", {"method": "mtpt", "kernel": "collision", "eta": 1.5}),
        ["figures.fig5.cases[", "eta=1.5", "[0, 1]"],
    ),
    (
        "compensated without truncation",
        _add_case("fig9", {"method": "mtpt", "kernel": "collision", "scheme": "compensated"}),
        ["figures.fig9.cases[", "scheme='compensated'"],
    ),
    (
        "optimum empty range",
        _set(("optimum", "fd_t250", "n_range"), [100, 100]),
        ["optimum.fd_t250.n_range", "low < high"],
    ),
    (
        "optimum budget below one round",
        _set(("optimum", "collision_eta1", "budget_runs"), 10),
        ["optimum.collision_eta1.budget_runs=10", "first round's 12 runs"],
    ),
    (
        "optimum case that does not exist",
        _set(("optimum", "collision_eta1", "case"), {"method": "pt", "kernel": "sph"}),
        ["optimum.collision_eta1.case.kernel='sph'", "bins, fixed, adaptive"],
    ),
    ("optimum time past t_final", _set(("optimum", "fd_t250", "time"), 2000), ["optimum.fd_t250.time=2000", "t_final"]),
    # the dry run built every seed block of 10**12 realisations (7.3 GB in 60 s) and hung
    ("realisations count 10**12", _set(("realisations", 0, "count"), 10**12), ["realisations[0].count=", "10000"]),
    (
        "max_realisations 10**9",
        _set(("mechanism", "sweeps", 0, "max_realisations"), 10**9),
        ["mechanism.sweeps[0].max_realisations=", "10000"],
    ),
    # an optimum search's cap: reported under n_range by the dry run's memory check, before
    (
        "optimum max_realisations 10**12",
        _set(("optimum", "collision_eta1", "max_realisations"), 10**12),
        ["optimum.collision_eta1.max_realisations=", "10000"],
    ),
    # `$` in a schema pattern also matches before a final newline: a key "fig1\n" was accepted and ignored
    (
        "figure key ending in a newline",
        _rename_in(("figures",), "fig1", "fig1\n"),
        ["figures['fig1\\n']", "fig8, fig9;"],
    ),
    ("optimum name ending in a newline", _rename_in(("optimum",), "fd_t250", "x\n"), ["optimum['x\\n']", "letters"]),
    # issue 23: accepted by the dry run, failing in the job (or after removing the good tables)
    ("fd_domain odd grid", _set(("mechanism", "fd_domain", "n"), [31]), ["mechanism.fd_domain.n=31", "even whole"]),
    (
        "fd_domain grid not fitting a length",
        _set(("mechanism", "fd_domain", "lengths"), [12, 13]),
        ["mechanism.fd_domain.n=1000", "fits an even whole number (>= 4) of times in 13"],
    ),
    (
        "fd_domain length below the plume",
        _set(("mechanism", "fd_domain", "lengths"), [12, 1e-6]),
        ["mechanism.fd_domain.lengths=1e-06", "2 sqrt(2 D t_final)"],
    ),
    ("comic_times twice", _set(("comic_times",), [5, 5, 20]), ["comic_times=[5, 5, 20]", "each once"]),
    ("tradeoff times twice", _set(("tradeoff", "times"), [250, 250.0]), ["tradeoff.times=[250, 250.0]", "each once"]),
    ("shear n past the cap", _set(("shear", "n"), 10**12), ["shear.n=1000000000000", "maximum of 100000000"]),
]


@pytest.mark.parametrize("change,expected", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_config_is_refused_naming_key_and_range(change, expected):
    cfg = copy.deepcopy(BASE)
    change(cfg)
    with pytest.raises(SettingError) as err:
        check_config(cfg)
    message = str(err.value)
    for text in expected:
        assert text in message, message
    assert len(message) < 400 and "\n" not in message  # one line, not the whole schema


@pytest.mark.parametrize("path", [ROOT / "config.yaml", TINY], ids=["config.yaml", "tiny"])
def test_shipped_configs_are_accepted(path):
    check_config(load_yaml(path))  # would raise


def test_figures_may_be_empty():
    cfg = copy.deepcopy(BASE)
    cfg["figures"] = {}
    check_config(cfg)  # the claims table is then empty (test_claims), not a KeyError


def test_yaml_error_names_line_and_column(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("physics:\n  D: 1.0e-3\n  t_final: [1000\ntime: {dt0: 0.01}\n")
    with pytest.raises(ConfigFileError) as err:
        load_yaml(bad)
    assert "bad.yaml: not valid YAML at line 4" in str(err.value)
    assert "started at line 3" in str(err.value)


def test_check_config_command(tmp_path, capsys):
    assert main(["check-config", str(ROOT / "config.yaml")]) == 0
    assert "accepted" in capsys.readouterr().out
    overlay = tmp_path / "more.yaml"
    overlay.write_text("physics:\n  D: 0\n")  # merged over config.yaml as Snakemake merges --configfile
    assert main(["check-config", str(ROOT / "config.yaml"), str(overlay)]) == 2
    assert "physics.D=0 is not allowed" in capsys.readouterr().err
    broken = tmp_path / "broken.yaml"
    broken.write_text("physics: {D: 1.0e-3\n")
    assert main(["check-config", str(broken)]) == 2
    assert "line 2" in capsys.readouterr().err


@pytest.mark.parametrize(
    "text,expected",
    [
        (
            "physics:\n  D: 1.0e-3\n  t_final: 1000\n  D: 2.0e-3\n",
            "line 4: key 'D' given twice in one mapping (first at line 2)",
        ),
        ("__use_yte__: true\n?if True:\n  physics: {D: 1.0e-3}\n", "line 1: __use_yte__ makes Snakemake run this file"),
        ("figures:\n  fig1: {__use_yte__: true}\n", "line 2: __use_yte__"),
    ],
    ids=["duplicate key", "yte template", "yte key nested"],
)
def test_config_is_data_a_duplicate_key_or_a_template_is_refused_by_line(tmp_path, text, expected):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ConfigFileError) as err:
        load_yaml(path)
    assert str(err.value).startswith(f"{path}: ") and expected in str(err.value)


def test_equal_keys_in_different_mappings_are_fine(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("a: {n: 1}\nb: {n: 2}\nc: [{n: 1}, {n: 2}]\n")
    assert load_yaml(path) == {"a": {"n": 1}, "b": {"n": 2}, "c": [{"n": 1}, {"n": 2}]}


def test_check_config_refuses_a_non_utf8_file_and_a_template_in_one_line(tmp_path, capsys):
    binary = tmp_path / "latin1.yaml"
    binary.write_bytes("physics: {D: 1.0e-3}  # caf\xe9\n".encode("latin-1"))
    assert main(["check-config", str(binary)]) == 2
    err = capsys.readouterr().err
    assert "latin1.yaml: not UTF-8 text at line 1 (byte 27 is 0xe9)" in err and len(err.splitlines()) == 1
    template = tmp_path / "template.yaml"
    template.write_text("__use_yte__: true\n")
    assert main(["check-config", str(ROOT / "config.yaml"), str(template)]) == 2
    assert "__use_yte__" in capsys.readouterr().err


def test_nested_command_line_overrides_are_typed_as_a_file_types_them():
    from particle_entropy.pipeline.configcheck import retype_overrides, typed

    # what Snakemake's parse_config hands on for --config physics={D: 0.002, t_final: 1e3} comic_times=[250, 1000]
    assert typed({"D": "0.002", "t_final": "1e3", "tag": "none", "flag": "true"}) == {
        "D": 0.002,
        "t_final": 1000.0,
        "tag": "none",
        "flag": True,
    }
    assert typed(["250", "1000"]) == [250, 1000]
    cfg = copy.deepcopy(BASE)
    overrides = {"physics": {"D": "0.002"}, "comic_times": ["250", "1000"]}
    cfg["physics"]["D"], cfg["comic_times"] = "0.002", ["250", "1000"]  # as Snakemake merged them
    retype_overrides(cfg, overrides)
    assert cfg["physics"] == {**BASE["physics"], "D": 0.002} and cfg["comic_times"] == [250, 1000]
    check_config(cfg)  # accepted
    cfg["physics"]["D"] = "abc"
    retype_overrides(cfg, {"physics": {"D": "abc"}})
    with pytest.raises(SettingError, match=r"physics.D='abc'"):
        check_config(cfg)


def test_the_largest_seed_block_is_computed_not_built_and_the_caps_agree():
    from particle_entropy.core.case import Case
    from particle_entropy.core.settings import MAX_REALISATIONS
    from particle_entropy.pipeline.sweeps import Ensemble, block_size, seed_blocks

    typed = parse(BASE)
    for n, count in [(30, 80), (300, 7), (3000, 1), (30000, 4), (100, 33)]:
        ens = Ensemble(Case("mtpt", "collision", n), count)
        assert block_size(ens, typed) == max(b - a + 1 for a, b in seed_blocks(ens, typed))
    # arithmetic: building the 10**12 / size blocks would exhaust memory here
    assert block_size(Ensemble(Case("mtpt", "collision", 30), 10**12), typed) == BASE["seed_blocks"]["size"]
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    caps = [
        schema["properties"]["realisations"]["items"]["properties"]["count"]["maximum"],
        schema["$defs"]["realisations"]["oneOf"][0]["maximum"],
        schema["$defs"]["case_section"]["properties"]["max_realisations"]["maximum"],
        schema["properties"]["optimum"]["patternProperties"]["^[A-Za-z0-9_]+(?![\\s\\S])"]["properties"][
            "max_realisations"
        ]["maximum"],
    ]
    assert caps == [MAX_REALISATIONS] * 4


def test_shear_n_is_checked_against_memory_by_arithmetic():
    """shear.n = 10**7 (within the schema's cap) had no memory check (the job failed or thrashed).
    The estimate is arithmetic, so a dry run and check-config refuse it at once, naming shear.n."""
    import time

    from particle_entropy.pipeline.config import build
    from particle_entropy.pipeline.memory import shear_memory_mb

    shear_section = build().Shear

    cfg = copy.deepcopy(BASE)
    check_config(cfg, available=24e9)
    cfg["shear"]["n"] = 10**7
    start = time.perf_counter()
    with pytest.raises(SettingError, match=r"shear.n=10000000 is not allowed: an N whose shear job fits"):
        check_config(cfg, available=24e9)
    assert time.perf_counter() - start < 5.0
    # pairs grow as N^2: four times the particles, about sixteen times the pair memory
    small, large = (shear_memory_mb(shear_section(**{**BASE["shear"], "n": n})) for n in (10**6, 4 * 10**6))
    assert 14 < (large - 300) / (small - 300) < 17
    no_mt = shear_section(**{**BASE["shear"], "n": 10**6, "cases": ["rw_drift"]})
    assert shear_memory_mb(no_mt) < 1000  # random walks only: no pairs


def test_check_config_command_runs_the_dry_runs_memory_check(tmp_path, capsys):
    """check-config accepted configs the dry run refused for memory."""
    overlay = tmp_path / "big.yaml"
    for text, named in [
        ("shear:\n  n: 10000000\n", "shear.n=10000000 is not allowed: an N whose shear job fits"),
        ("figures:\n  fig1:\n    n: [1000000000]\n", "figures.fig1.n=1000000000 is not allowed: an N whose job fits"),
    ]:
        overlay.write_text(text)
        assert main(["check-config", str(ROOT / "config.yaml"), str(overlay)]) == 2
        assert named in capsys.readouterr().err


def test_the_shear_n_cap_is_the_schemas():
    """10^8 particles: 5,000 x the paper's (settings.SHEAR_MAX_N, held to the schema and to ShearConfig)."""
    from particle_entropy.core.settings import SHEAR_MAX_N

    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    assert schema["properties"]["shear"]["properties"]["n"]["maximum"] == SHEAR_MAX_N == 10**8


def test_the_parse_checks_the_config_in_one_call():
    """check_parsed_config: --config overrides retyped, the schema, the defaults filled in (by the
    given function, Snakemake's validate in the workflow), then the rules between fields."""
    from particle_entropy.pipeline.configcheck import SCHEMA_PATH, check_parsed_config

    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    filled = []
    check_parsed_config(config, {}, SCHEMA_PATH, lambda c, path: filled.append(path))
    assert filled == [str(SCHEMA_PATH)]
    bad = copy.deepcopy(config) | {"base_seed": 1000.0}  # --config base_seed=1e3, as Snakemake reads it
    with pytest.raises(SettingError, match="base_seed"):
        check_parsed_config(bad, {}, SCHEMA_PATH, lambda c, path: filled.append(path))
    assert len(filled) == 1  # refused before the defaults are filled in
