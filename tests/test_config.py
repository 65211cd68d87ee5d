"""The typed config (pipeline/config.py): one model per section, derived from the declarations of
core/settings.py, returned typed by configcheck.validate_config, and the generated docs table."""

from __future__ import annotations

import copy
import math

import pytest
import yaml
from conftest import ROOT, TINY

from particle_entropy.core import settings as S
from particle_entropy.core.case import SettingError
from particle_entropy.pipeline import config as C
from particle_entropy.pipeline import schemagen
from particle_entropy.pipeline.configcheck import check_config, parse, validate_config

BASE = yaml.safe_load((ROOT / "config.yaml").read_text())


def test_validate_config_returns_the_typed_config_with_its_defaults():
    cfg = validate_config(BASE)
    assert isinstance(cfg, C.Config)
    assert cfg.physics.D == BASE["physics"]["D"] and isinstance(cfg.physics.t_final, float)
    assert cfg.case_defaults.truncation is None  # the word none, typed
    assert cfg.figures.fig9.bars == "eq43"  # a figure option's default
    assert set(cfg.optimum) == set(BASE["optimum"]) and cfg.optimum["fd_t250"].width == 10.0
    assert isinstance(check_config(BASE), C.Config)  # the dry run's checks return it too


def test_the_tiny_config_layered_over_the_shipped_one_parses():
    from snakemake.utils import update_config

    merged = copy.deepcopy(BASE)
    update_config(merged, yaml.safe_load(TINY.read_text()))
    assert validate_config(merged).physics.t_final == merged["physics"]["t_final"]


# every key of a section with a fixed name (a sweep's base is a scene's model, not a value)
FIXED = [s for s in S.DECLARED if s.section and "<" not in s.key and not s.key.endswith(".base")]


@pytest.mark.parametrize("setting", FIXED, ids=lambda s: s.key)
def test_every_field_is_its_declaration(setting):
    """Default, bounds and description of a field are its Setting's: declared once."""
    model = C.build()
    section = {"physics": model.Physics, "time": model.Time, "numerics": model.Numerics}.get(setting.section)
    if section is None:
        section = {
            "case_defaults": model.CaseDefaults,
            "seed_blocks": model.SeedBlocks,
            "claims": model.Claims,
            "shear": model.Shear,
            "tradeoff": model.Tradeoff,
            "mechanism": model.Mechanism,
            "mechanism.lattice": model.Lattice,
            "mechanism.fd_domain": model.FdDomain,
            "scenes_peclet": model.ScenesPeclet,
            "scenes_peclet2d": model.ScenesPeclet2D,
            "figures.fig9": model.Fig9,
            "realisations[]": model.RealisationsEntry,
        }[setting.section]
    info = section.model_fields[setting.name]
    assert info.description == C.description(setting)
    assert info.json_schema_extra["unit"] == setting.unit
    if setting.has_default and not info.is_required():
        assert info.default == setting.default
    bounds = {type(m).__name__: m for m in info.metadata}
    if setting.kind in ("number", "integer") and setting.choices is None and not setting.none:
        if setting.low not in (None, -math.inf):
            key = "Gt" if setting.open_low else "Ge"
            assert getattr(bounds[key], key.lower()) == setting.low
        if setting.high != math.inf:
            assert bounds["Le"].le == setting.high


def test_a_section_rule_is_a_model_validator():
    cfg = copy.deepcopy(BASE)
    del cfg["optimum"]["fd_t250"]["n_range"]
    with pytest.raises(SettingError, match=r"optimum\.fd_t250=.*exactly one of n_range and growth_range"):
        parse(cfg)


def test_docs_table_is_current_and_lists_every_section():
    text = (ROOT / "docs" / "config.md").read_text(encoding="utf-8")
    assert schemagen.docs() == text, f"stale docs/config.md: run `{schemagen.COMMAND}`"
    for section in ("physics", "shear", "optimum.<name>", "scenes.<name>.target", "$defs.case_section"):
        assert f"## `{section}`" in text
