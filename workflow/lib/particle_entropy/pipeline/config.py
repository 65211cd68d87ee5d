"""The typed config: one pydantic model per section, derived from the sections' one declaration.

Every key is declared once, as a ``Setting`` (core/settings.py; the run settings and the shear
flow's in core/run_settings.py and core/shear_settings.py). core/typed.py derives a pydantic model
per section from those tuples and turns a model's refusal into a SettingError; it builds there the
models whose owners parse them alone too (a search, a scene and its candidates: ``typed.shared``),
so that a notebook's ``Scene.from_config`` and the workflow refuse a value in the same words. This
module assembles the whole ``Config`` from them, with the rules a section can see alone as model
validators (a claim's [low, high], each N of the ``realisations`` table once, the lattice's odd N);
the rules that need several sections or a run (a case that builds, a time within t_final, memory)
stay in pipeline/crosschecks.py. ``Setting`` is not rewritten as pydantic fields: the simulation
jobs import core/run_settings.py and core/shear_settings.py, and a job's code hash covers what it
imports (pipeline/codeversion.py), so a rewrite would rerun every simulation once and put pydantic
into every job. schemagen renders the schema and docs/config.md from these models.

``Config`` is what ``parse`` returns and ``configcheck.validate_config`` returns checked: the merged
config, parsed once. It sits here, below the checks that read it (pipeline/crosschecks.py, then
pipeline/configcheck.py), so that no module imports one that imports it back. A key
the config may leave out and that has no default (a section, a search's ``n``) is None in it; an
explicit null is refused, as the schema refuses it (such fields are typed ``X`` with default None,
not ``X | None``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from types import SimpleNamespace
from typing import Annotated

from pydantic import ConfigDict, Field, ValidationError, create_model, model_validator
from pydantic_core import PydanticCustomError

from ..core.settings import (
    CLAIMS,
    COMIC_TIMES,
    FIGURE_OPTIONS,
    MECHANISM,
    REALISATIONS_ENTRY,
    SECTION_DOCS,
    SEEDS,
    SETTINGS,
    SHEAR,
    TRADEOFF,
)
from ..core.typed import (  # noqa: F401  (the model builders, re-exported for schemagen and the tests)
    DEF_DOCS,
    NAME_PATTERN,
    OneOf,
    Section,
    annotation,
    annotation_of,
    bounded,
    description,
    field,
    is_model,
    key_order,
    keys_in,
    members,
    refuse,
    required,
    section,
    setting_error,
    shared,
)
from ..figures import PAPER_FIGURES


class _Claims(Section):
    @model_validator(mode="after")
    def _ranges(self):
        for key, value in self:
            if isinstance(value, list) and all(map(math.isfinite, value)) and value[0] > value[1]:
                raise refuse(key, "a range [low, high] with low <= high")
        return self


class _Lattice(Section):
    @model_validator(mode="after")
    def _odd(self):
        if self.n % 2 == 0:
            raise refuse("n", "an odd integer >= 3, so that a particle sits at x = 0")
        return self


class _Config(Section):
    model_config = ConfigDict(regex_engine="python-re")  # NAME_PATTERN's look-ahead

    def case_sections(self) -> dict:
        """Every section that lists cases, by its key: each figure, `tradeoff` and each sweep of
        `mechanism` (what pipeline/sweeps.py plans)."""
        out = {f"figures.{fig}": spec for fig, spec in self.figures if spec is not None}
        if self.tradeoff is not None:
            out["tradeoff"] = self.tradeoff
        for i, spec in enumerate(self.mechanism.sweeps if self.mechanism else []):
            out[f"mechanism.sweeps[{i}]"] = spec
        return out

    @model_validator(mode="after")
    def _each_n_once(self):
        seen: dict[int, int] = {}
        for i, entry in enumerate(self.realisations):
            if entry.n in seen:
                raise PydanticCustomError(
                    "each_once", "each N once (also at realisations[{first}])", {"index": i, "first": seen[entry.n]}
                )
            seen[entry.n] = i
        return self


@functools.cache
def build(settings: tuple = SETTINGS) -> SimpleNamespace:
    """Every section's model, from the run settings ``settings`` (settings.SETTINGS) and the other
    sections' declarations; the shared definitions (``defs``: a case's dimensions, a case, a list
    of cases, of N, a section of cases) by name, as the schema's $defs names them."""
    m = SimpleNamespace(**vars(shared(settings)))  # defs, CaseSection, Search, the scenes'
    defs = m.defs

    def of(name: str, keys, doc: str, parent=Section, order=(), **extra):
        return section(name, keys, doc, parent=parent, defs=defs, order=order, **extra)

    m.Physics = of("Physics", keys_in("physics", settings), "The 1-D diffusion problem shared by all figures.")
    m.Time = of("Time", keys_in("time", settings), "Time stepping.")
    m.Numerics = of(
        "Numerics",
        keys_in("numerics", settings),
        "How the mass-transfer Gauss transforms are computed (results agree to the tolerance).",
    )
    m.CaseDefaults = of(
        "CaseDefaults",
        keys_in("case_defaults", settings),
        "Defaults for every case that does not set its own (dimensions that apply to its method).",
    )
    m.SeedBlocks = of("SeedBlocks", keys_in("seed_blocks", SEEDS), SECTION_DOCS["seed_blocks"])
    m.RealisationsEntry = of("RealisationsEntry", REALISATIONS_ENTRY, SECTION_DOCS["realisations[]"])
    m.Claims = of("Claims", CLAIMS, SECTION_DOCS["claims"], parent=_Claims)
    m.Shear = of("Shear", SHEAR, SECTION_DOCS["shear"])
    m.Fig9 = of("Fig9", FIGURE_OPTIONS, SECTION_DOCS["<section>"], parent=m.CaseSection)
    m.Figures = create_model(
        "Figures",
        __base__=Section,
        __doc__=SECTION_DOCS["figures"],
        **{fig: ((m.Fig9 if fig == "fig9" else m.CaseSection), None) for fig in PAPER_FIGURES},
    )
    m.Tradeoff = of("Tradeoff", TRADEOFF, SECTION_DOCS["tradeoff"], parent=m.CaseSection)
    m.Lattice = of(
        "Lattice", keys_in("mechanism.lattice", MECHANISM), SECTION_DOCS["mechanism.lattice"], parent=_Lattice
    )
    m.FdDomain = of("FdDomain", keys_in("mechanism.fd_domain", MECHANISM), SECTION_DOCS["mechanism.fd_domain"])
    m.Mechanism = of(
        "Mechanism",
        keys_in("mechanism", MECHANISM),
        SECTION_DOCS["mechanism"],
        lattice=(m.Lattice, None),
        fd_domain=(m.FdDomain, None),
    )
    name = Annotated[str, Field(pattern=NAME_PATTERN)]
    m.Config = create_model(
        "Config",
        __base__=_Config,
        __doc__="Configuration of the particle-entropy workflow (Benson et al. 2020 reproduction).",
        physics=(m.Physics, ...),
        time=(m.Time, ...),
        numerics=(m.Numerics, Field(default_factory=m.Numerics, json_schema_extra={"default": {}})),
        base_seed=field(SEEDS[0]),
        seed_blocks=(m.SeedBlocks, ...),
        realisations=(
            list[m.RealisationsEntry],
            Field(..., description="Realisations per N for figures with realisations set to ensemble."),
        ),
        case_defaults=(m.CaseDefaults, Field(default_factory=m.CaseDefaults)),
        figures=(m.Figures, ...),
        tradeoff=(m.Tradeoff, None),
        mechanism=(m.Mechanism, None),
        comic_times=field(COMIC_TIMES[0]),
        claims=(m.Claims, ...),
        shear=(m.Shear, None),
        optimum=(dict[name, m.Search], Field(default_factory=dict, description=SECTION_DOCS["optimum"])),
        scenes=(dict[name, m.Scene], Field(default_factory=dict, description=SECTION_DOCS["scenes"])),
        scenes_peclet=(m.ScenesPeclet, None),
        scenes_peclet2d=(m.ScenesPeclet2D, None),
    )
    return m


_MODELS = build()
Config = _MODELS.Config  # the whole config; its sections' models: build()


def parse(config: Mapping):
    """The config as its typed form (``Config``): each section by its model (types, ranges, required
    and unknown keys, the rules within a section); SettingError names the key path, the value and the
    allowed range, as the schema's check did. Only parses: configcheck.validate_config also checks the
    rules between sections and the runs the config plans (pipeline/crosschecks.py)."""
    try:
        return Config.model_validate(dict(config))
    except ValidationError as e:
        raise bounded(setting_error(e, config, Config)) from None
