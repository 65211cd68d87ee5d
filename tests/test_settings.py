"""One definition of the run settings: the schema's entries, the CLI's options and RunConfig's
checks all follow settings.SETTINGS, and the committed schema is what schemagen writes."""

from __future__ import annotations

import copy
import dataclasses
import math

import pytest
import yaml

from particle_entropy.cli import CLI_SETTINGS, build_parser
from particle_entropy.core import settings as S
from particle_entropy.core.case import Case, SettingError
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.pipeline import schemagen
from particle_entropy.pipeline.configcheck import SCHEMA_PATH, check_schema, load_schema
from particle_entropy.pipeline.sweeps import run_config

CONFIG = yaml.safe_load((SCHEMA_PATH.parents[2] / "config.yaml").read_text())
SCHEMA = load_schema()


def test_committed_schema_is_what_schemagen_writes():
    text = SCHEMA_PATH.read_text(encoding="utf-8")
    assert schemagen.render(text) == text, f"stale schema: run `{schemagen.COMMAND}`"
    assert schemagen.main(["--check"]) == 0


def test_a_changed_setting_changes_the_schema(monkeypatch, tmp_path):
    changed = tuple(dataclasses.replace(s, default=2e-3) if s.name == "D" else s for s in S.SETTINGS)
    monkeypatch.setattr(schemagen, "SETTINGS", changed)
    stale = tmp_path / "schema.yaml"
    stale.write_text(SCHEMA_PATH.read_text(encoding="utf-8"), encoding="utf-8")
    assert schemagen.main(["--check", "--schema", str(stale)]) == 1
    assert schemagen.main(["--write", "--schema", str(stale)]) == 0
    assert yaml.safe_load(stale.read_text())["properties"]["physics"]["properties"]["D"]["default"] == 2e-3


def _schema_entry(setting):
    section, key = setting.key.split(".")
    if section == "case_defaults":
        return SCHEMA["$defs"][key], SCHEMA["properties"][section]["properties"][key]["default"]
    entry = SCHEMA["properties"][section]["properties"][key]
    return entry, entry["default"]


@pytest.mark.parametrize("setting", S.SETTINGS, ids=lambda s: s.key)
def test_schema_entry_reads_back_as_the_setting(setting):
    entry, default = _schema_entry(setting)
    assert default == ("none" if setting.none and setting.default is None else setting.default)
    if setting.choices is not None:
        assert tuple(entry["enum"]) == setting.choices
    assert setting.doc[1:] in entry["description"]


def _config_with(setting, value):
    cfg = copy.deepcopy(CONFIG)
    section, key = setting.key.split(".")
    cfg.setdefault(section, {})[key] = value
    return cfg


# the config's first steps reach a run as its dt0 (runconfig.first_step), for these cases
FIRST_STEP_CASES = {"fd_dt": Case("fd", "implicit", 300), "fixed_dt": Case("mtpt", "collision", 300, dt_growth=1.0)}


def _run_with(setting, value):
    if setting.section == "case_defaults":
        return Case("mtpt", "collision", 300, **{setting.name: value})
    if setting.name in FIRST_STEP_CASES:
        return run_config(FIRST_STEP_CASES[setting.name], _config_with(setting, value))
    return RunConfig.of(method="mtpt", n=300, **{setting.name: value}).resolved()


NUMBERS = [s for s in S.SETTINGS if s.choices is None]


@pytest.mark.parametrize("setting", NUMBERS, ids=lambda s: s.key)
def test_schema_and_run_refuse_the_same_edges(setting):
    """Just outside each bound both the config check and the run refuse; at a closed bound both accept."""
    outside = [setting.low if setting.open_low else setting.low - 1e-9 * max(1.0, abs(setting.low))]
    if setting.high != math.inf:
        outside.append(setting.high * (1 + 1e-9))
    for value in outside:
        with pytest.raises(SettingError):
            check_schema(_config_with(setting, value), SCHEMA)
        with pytest.raises(SettingError, match="dt0" if setting.name in FIRST_STEP_CASES else setting.name):
            _run_with(setting, value)
    if not setting.open_low and setting.name != "dt_growth":  # growth 1 with dt0 = 0.01 is many steps
        check_schema(_config_with(setting, setting.low), SCHEMA)
        _run_with(setting, setting.low)


@pytest.mark.parametrize("name", CLI_SETTINGS)
def test_cli_options_follow_the_settings(name):
    setting = S.BY_NAME[name]
    sub = next(a for a in build_parser()._actions if a.dest == "command").choices["simulate"]
    (action,) = [a for a in sub._actions if a.dest == name]
    assert action.option_strings == [setting.option]
    assert setting.doc in action.help
    if setting.choices is not None:
        assert tuple(action.choices) == setting.choices
    if name not in ("dt0", "dt_growth"):  # method-dependent defaults, filled by RunConfig
        assert action.default == setting.default


def test_runconfig_defaults_are_the_settings():
    cfg = RunConfig.of(method="mtpt", n=300).resolved()
    for s in S.SETTINGS:
        assert getattr(cfg, s.name, getattr(cfg.case, s.name, None)) == s.default or s.name in ("fd_dt", "fixed_dt"), s


# --------------------------------------------------------------------------- every declared section
def _entry_at(key: str) -> dict:
    """The schema entry of a declared setting's key, wherever its section sits in the schema."""
    parts = key.replace("[]", ".[]").split(".")
    if parts[0] == "<section>":
        node = SCHEMA["$defs"]["case_section"]
        parts = parts[1:]
    else:
        node = SCHEMA
    for part in parts:
        if part == "[]":
            node = node["items"]
        elif part == "<name>":
            (node,) = node["patternProperties"].values()
        else:
            node = node["properties"][part]
    return node


@pytest.mark.parametrize("setting", [s for s in S.DECLARED if s.section != "case_defaults"], ids=lambda s: s.key)
def test_every_declared_setting_reads_back_from_the_schema(setting):
    """Default, words, bounds and meaning of every declared key are the schema's (schemagen)."""
    entry = _entry_at(setting.key)
    assert setting.doc[1:] in entry["description"] and setting.allowed() in entry["description"]
    if setting.has_default and "$ref" in entry:  # the referenced definition carries it
        assert SCHEMA["$defs"][entry["$ref"].rsplit("/", 1)[1]]["default"] == setting.default
    elif setting.has_default:
        assert entry["default"] == ("none" if setting.none and setting.default is None else setting.default)
    else:
        assert "default" not in entry
    if setting.choices is not None:
        assert tuple(entry["enum"]) == setting.choices
    if setting.kind in ("number", "integer") and setting.choices is None and not setting.none:
        assert entry["type"] == setting.kind
        low = entry.get("exclusiveMinimum" if setting.open_low else "minimum", -math.inf)  # none: unbounded below
        assert low == setting.low and entry.get("maximum", math.inf) == setting.high


def test_a_declared_section_is_required_where_it_says():
    shear = SCHEMA["properties"]["shear"]
    assert shear["required"] == [s.name for s in S.SHEAR if s.required]
    assert "beta" not in shear["required"]  # it has a default that config.yaml may leave to it
    search = SCHEMA["properties"]["optimum"]["patternProperties"]
    (search,) = search.values()
    assert search["required"] == ["case", "time"]


def test_the_caps_are_declared_once():
    """Every cap on realisations in the schema is settings.MAX_REALISATIONS (10,000: more is a typo)."""
    assert S.MAX_REALISATIONS == 10_000
    caps = [
        _entry_at("realisations[].count")["maximum"],
        SCHEMA["$defs"]["realisations"]["oneOf"][0]["maximum"],
        _entry_at("<section>.max_realisations")["maximum"],
        _entry_at("optimum.<name>.max_realisations")["maximum"],
    ]
    assert caps == [S.MAX_REALISATIONS] * 4


def test_every_paper_figure_has_its_schema_entry_and_only_those():
    from particle_entropy.figures import PAPER_FIGURES

    assert list(SCHEMA["properties"]["figures"]["properties"]) == list(PAPER_FIGURES)
    assert PAPER_FIGURES == tuple(f"fig{k}" for k in range(1, 10))  # the paper's case-drawn figures
