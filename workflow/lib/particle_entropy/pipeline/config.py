"""The typed config: one pydantic model per section, derived from the sections' one declaration.

Every key is declared once, as a ``Setting`` (core/settings.py; the run settings and the shear
flow's in core/run_settings.py and core/shear_settings.py): its default, unit, range, meaning
and, for a structured value, its shape. This module *derives* a pydantic model per section from
those tuples (``section``: ``create_model`` with ``Field(ge/gt/le, description, unit)``) instead
of replacing ``Setting`` by pydantic fields, for two concrete reasons:

- the simulation jobs import core/run_settings.py and core/shear_settings.py (and core/case.py,
  core/runconfig.py, models/shear2d.py, which read ``Setting``); a job's code hash covers what it
  imports (pipeline/codeversion.py), so rewriting them would rerun every simulation once, and
  would put pydantic into every job;
- experiments/scene.py and analysis/optimum.py read ``settings.SCENE`` and ``settings.SEARCH``.

A structured value's shape is declared once too, with its ``Setting``: a pydantic type (made
with settings.number, integer and array), or, where the shape is built from other declarations,
a JSON-schema fragment that ``annotation`` turns into one: a shared definition (``build().defs``:
a case, the lists of cases and of N, a section of cases), a scene's source and candidates (kept
plain dicts, which experiments/scene.py checks further) and the shear cases. schemagen renders
the schema from these models, so the schema and the models cannot disagree. Cross-field rules a
section can see alone are model validators here (a search's budget and range, a claim's [low,
high], each N of the ``realisations`` table once); the rules that need several sections or a run
(a case that builds, a time within t_final, memory) stay in pipeline/crosschecks.py.

``Config`` is what ``configcheck.validate_config`` returns: the merged config, parsed once. A key
the config may leave out and that has no default (a section, a search's ``n``) is None in it; an
explicit null is refused, as the schema refuses it (such fields are typed ``X`` with default None,
not ``X | None``).
"""

from __future__ import annotations

import functools
import math
import types
import typing
from types import SimpleNamespace
from typing import Annotated, ClassVar, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    create_model,
    model_validator,
)
from pydantic_core import PydanticCustomError

from ..core.case import N_MIN, NONE, from_text
from ..core.registry import ALL_KERNELS, METHODS, PRESETS
from ..core.settings import (
    BY_KEY,
    CASE_SECTION,
    CLAIMS,
    COMIC_TIMES,
    FIGURE_OPTIONS,
    MAX_REALISATIONS,
    MECHANISM,
    REALISATIONS_DOC,
    REALISATIONS_ENTRY,
    SCENE,
    SCENES_PECLET,
    SEARCH,
    SECTION_DOCS,
    SEEDS,
    SETTINGS,
    SHEAR,
    TRADEOFF,
    UNIQUE,
    Setting,
    array,
    integer,
    number,
)
from ..figures import PAPER_FIGURES

NAME_PATTERN = r"^[A-Za-z0-9_]+(?![\s\S])"  # a search's or a scene's key: letters, digits, _ (`$` also
# matches before a final newline: (?![\s\S]) is the very end)


def description(s: Setting) -> str:
    """A setting's description: the meaning, the unit and the allowed values (the schema's, the
    docs' and the refusal messages' text)."""
    unit = "" if s.unit == "-" else f" [{s.unit}]"
    return f"{s.doc[0].upper()}{s.doc[1:]}{unit}; {s.allowed()}."


class Section(BaseModel):
    """A config section: unknown keys refused, values frozen once validated."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class _OneOf(Section):
    """A mapping that must hold exactly one of the keys ``one_of`` (none: any)."""

    one_of: ClassVar[tuple[str, ...]] = ()

    @model_validator(mode="after")
    def _exactly_one(self):
        if self.one_of and sum(k in self.model_fields_set for k in self.one_of) != 1:
            raise PydanticCustomError("one_of", "exactly one of {keys}", {"keys": ", ".join(self.one_of)})
        return self


def _ref_of(fragment: dict) -> dict:
    """The Field of a key of a shape: a shared definition's reference (pydantic folds an
    Annotated type into its field, so the schema could not tell it from its own entry) and
    meaning."""
    if "$ref" not in fragment:
        return {}
    name = fragment["$ref"].rsplit("/", 1)[1]
    setting = BY_KEY.get(f"case_defaults.{name}")
    text = description(setting) if setting is not None else DEF_DOCS.get(name)
    return {"json_schema_extra": {"ref": fragment["$ref"]}, "description": text}


_BOUNDS = {"minimum": "ge", "exclusiveMinimum": "gt", "maximum": "le"}
_LENGTHS = {"minItems": "min_length", "maxItems": "max_length"}


def annotation(fragment: dict, defs: dict | None = None):
    """The pydantic type of a JSON-schema fragment (a structured Setting's ``shape``): a reference
    to a shared definition, an enum, a number, an integer, an array or an object."""
    if "$ref" in fragment:
        return (defs or build().defs)[fragment["$ref"].rsplit("/", 1)[1]]
    kind = fragment.get("type")
    if "enum" in fragment:
        return Literal[tuple(fragment["enum"])]
    if kind in ("number", "integer"):
        bounds = {arg: fragment[key] for key, arg in _BOUNDS.items() if key in fragment}
        return integer(**bounds) if kind == "integer" else number(**bounds)
    if kind == "array":
        length = {arg: fragment[key] for key, arg in _LENGTHS.items() if key in fragment}
        checks = [UNIQUE] if fragment.get("uniqueItems") else []
        return array(annotation(fragment["items"], defs), *checks, **length)
    if kind == "object":  # a mapping of declared keys, kept a plain dict (its consumer parses it further)
        required = set(fragment.get("required", ()))
        fields = {
            k: (annotation(v, defs), Field(... if k in required else None, **_ref_of(v)))
            for k, v in fragment["properties"].items()
        }
        model = create_model("Shape", __base__=_OneOf, **fields)
        model.one_of = tuple(r["required"][0] for r in fragment.get("oneOf", []))
        return Annotated[model, AfterValidator(lambda m: m.model_dump(exclude_unset=True))]
    raise ValueError(f"no pydantic type for the shape {fragment}")


def annotation_of(s: Setting, defs: dict | None = None):
    """The pydantic type of one setting (without its default)."""
    if s.kind == "shape":
        return annotation(s.shape, defs) if isinstance(s.shape, dict) else s.shape
    if s.choices is not None:
        return Literal[s.choices]
    if s.kind == "boolean":
        return StrictBool
    bounds = {} if s.low is None or s.low == -math.inf else {"gt" if s.open_low else "ge": s.low}
    if s.high != math.inf:
        bounds["le"] = s.high
    value = integer(**bounds) if s.kind == "integer" else number(**bounds)
    if s.none:  # the word none (None), as truncation takes it
        return Annotated[Literal[NONE] | value, AfterValidator(from_text)]
    return value


# Run settings a config must give, though they have defaults (core/run_settings.py declares no
# `required`: the simulations' code hash covers that module, so it is said here, once)
REQUIRED_RUN_SETTINGS = ("physics.D", "physics.t_final", "physics.omega", "physics.fd_length", "time.dt0", "time.fd_dt")


def required(s: Setting) -> bool:
    return s.required or s.key in REQUIRED_RUN_SETTINGS


def field(s: Setting, defs: dict | None = None) -> tuple:
    """(type, Field) of one setting in its section's model: default (a required key's is only
    documented: the config must give it), description, unit."""
    kind = annotation_of(s, defs)
    info = {"description": description(s), "json_schema_extra": {"unit": s.unit}}
    if s.kind == "shape" and isinstance(s.shape, dict) and "$ref" in s.shape:  # the schema refers to it
        info["json_schema_extra"]["ref"] = s.shape["$ref"]
    if required(s):
        if s.has_default:
            info["json_schema_extra"]["default"] = s.default
        return kind, Field(..., **info)
    if s.has_default:
        return kind, Field(s.default, **info)
    return kind, Field(None, **info)  # absent: None (null itself is refused)


def section(name: str, settings, doc: str, parent=Section, defs: dict | None = None, order=(), **extra):
    """The model of a section: a field per setting directly in it (``settings`` keys below
    ``<key>.``: their last part), and ``extra`` fields (nested sections); keys named in ``order``
    first, in that order."""
    fields = {s.name: field(s, defs) for s in settings}
    fields.update(extra)  # a nested section, or a setting's own model in its place
    fields = {**{k: fields[k] for k in order if k in fields}, **fields}
    return create_model(name, __base__=parent, __doc__=doc, **fields)


def key_order(prefix: str, settings) -> list[str]:
    """The keys of the section at ``prefix`` in the order ``settings`` declares them, a nested
    section's where its first setting is (scenes.<name>: target after fd_length)."""
    names = [
        s.name if s.section == prefix else s.section[len(prefix) + 1 :].split(".")[0]
        for s in settings
        if s.section == prefix or s.section.startswith(prefix + ".")
    ]
    return list(dict.fromkeys(names))


def _in(prefix: str, settings) -> tuple:
    return tuple(s for s in settings if s.section == prefix)


# ------------------------------------------------------------------------------ the sections
class _Search(Section):
    # the schema's spelling of this validator (JSON schema can say these two rules)
    model_config = ConfigDict(
        json_schema_extra={
            "allOf": [
                {"anyOf": [{"required": ["budget_runs"]}, {"required": ["budget_core_s"]}]},
                {"oneOf": [{"required": ["n_range"]}, {"required": ["growth_range"]}]},
            ]
        }
    )

    @model_validator(mode="after")
    def _budget_and_range(self):
        if self.budget_runs is None and self.budget_core_s is None:
            raise PydanticCustomError("missing_one_of", "a budget: budget_runs, budget_core_s or both")
        if (self.n_range is None) == (self.growth_range is None):
            raise PydanticCustomError("missing_one_of", "exactly one of n_range and growth_range")
        return self


def refuse(key: str, allowed: str):
    """A section's rule broken at its ``key``: configcheck names the key path, the value as written
    and ``allowed``."""
    return PydanticCustomError("rule", allowed, {"key": key})


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


# what the schema's shared definitions ($defs) mean where no setting declares them
DEF_DOCS = {
    "method": "pt, mtpt or fd (registry.METHODS).",
    "kernel": "The method's kernel (registry.KERNELS).",
    "preset": "Named case dimensions (registry.PRESETS; a dimension the case sets wins): "
    + "; ".join(
        f"{k}: {', '.join(f'{d} {v:g}' if isinstance(v, float) else f'{d} {v}' for d, v in dims.items())}"
        for k, dims in PRESETS.items()
    )
    + ".",
    "cases": "Model settings drawn in the figure; unset dimensions come from case_defaults.",
    "ns": "Particle numbers (FD intervals), each >= 2 (case.N_MIN; one particle scores a perfect COMIC -inf).",
    "realisations": f"Realisations per N, {REALISATIONS_DOC}.",
}


@functools.cache
def build(settings: tuple = SETTINGS) -> SimpleNamespace:
    """Every section's model, from the run settings ``settings`` (settings.SETTINGS) and the other
    sections' declarations; the shared definitions (``defs``: a case's dimensions, a case, a list
    of cases, of N, a section of cases) by name, as the schema's $defs names them."""
    m = SimpleNamespace()
    dims = {s.name: (annotation_of(s), description(s)) for s in settings if s.section == "case_defaults"}
    case = create_model(
        "CaseSpec",
        __base__=Section,
        __doc__=f"One model: method and kernel, and the dimensions {', '.join(dims)} that apply to it "
        "(unset ones come from case_defaults).",
        method=(Literal[METHODS], Field(..., description=DEF_DOCS["method"])),
        kernel=(Literal[ALL_KERNELS], Field(..., description=DEF_DOCS["kernel"])),
        preset=(Literal[tuple(PRESETS)], Field(None, description=DEF_DOCS["preset"])),
        **{
            name: (kind, Field(None, description=text, json_schema_extra={"ref": f"#/$defs/{name}"}))
            for name, (kind, text) in dims.items()
        },
    )
    m.defs = defs = {
        "method": Literal[METHODS],
        "kernel": Literal[ALL_KERNELS],
        "preset": Literal[tuple(PRESETS)],
        **{name: kind for name, (kind, _) in dims.items()},
        "case": case,
        "cases": array(case, min_length=1),
        "ns": array(integer(ge=N_MIN), min_length=1),
        "realisations": integer(ge=1, le=MAX_REALISATIONS) | Literal["ensemble"],
    }
    defs["case_section"] = m.CaseSection = section("CaseSection", CASE_SECTION, SECTION_DOCS["<section>"], defs=defs)

    def of(name: str, keys, doc: str, parent=Section, order=(), **extra):
        return section(name, keys, doc, parent=parent, defs=defs, order=order, **extra)

    m.Physics = of("Physics", _in("physics", settings), "The 1-D diffusion problem shared by all figures.")
    m.Time = of("Time", _in("time", settings), "Time stepping.")
    m.Numerics = of(
        "Numerics",
        _in("numerics", settings),
        "How the mass-transfer Gauss transforms are computed (results agree to the tolerance).",
    )
    m.CaseDefaults = of(
        "CaseDefaults",
        _in("case_defaults", settings),
        "Defaults for every case that does not set its own (dimensions that apply to its method).",
    )
    m.SeedBlocks = of("SeedBlocks", _in("seed_blocks", SEEDS), SECTION_DOCS["seed_blocks"])
    m.RealisationsEntry = of("RealisationsEntry", REALISATIONS_ENTRY, SECTION_DOCS["realisations[]"])
    m.Claims = of("Claims", CLAIMS, SECTION_DOCS["claims"], parent=_Claims)
    m.Shear = of("Shear", SHEAR, SECTION_DOCS["shear"])
    m.Search = of("Search", SEARCH, SECTION_DOCS["optimum.<name>"], parent=_Search)
    m.Fig9 = of("Fig9", FIGURE_OPTIONS, SECTION_DOCS["<section>"], parent=m.CaseSection)
    m.Figures = create_model(
        "Figures",
        __base__=Section,
        __doc__=SECTION_DOCS["figures"],
        **{fig: ((m.Fig9 if fig == "fig9" else m.CaseSection), None) for fig in PAPER_FIGURES},
    )
    m.Tradeoff = of("Tradeoff", TRADEOFF, SECTION_DOCS["tradeoff"], parent=m.CaseSection)
    m.Lattice = of("Lattice", _in("mechanism.lattice", MECHANISM), SECTION_DOCS["mechanism.lattice"], parent=_Lattice)
    m.FdDomain = of("FdDomain", _in("mechanism.fd_domain", MECHANISM), SECTION_DOCS["mechanism.fd_domain"])
    m.Mechanism = of(
        "Mechanism",
        _in("mechanism", MECHANISM),
        SECTION_DOCS["mechanism"],
        lattice=(m.Lattice, None),
        fd_domain=(m.FdDomain, None),
    )
    m.Target = of("Target", _in("scenes.<name>.target", SCENE), SECTION_DOCS["scenes.<name>.target"])
    scene = _in("scenes.<name>", SCENE)
    order = key_order("scenes.<name>", SCENE)
    m.Scene = of("Scene", scene, SECTION_DOCS["scenes.<name>"], order=order, target=(m.Target, None))
    base = BY_KEY["scenes_peclet.base"]
    without_v = [s for s in scene if s.name != "v"]
    m.SceneBase = of("SceneBase", without_v, description(base), order=order, target=(m.Target, None))
    m.ScenesPeclet = of(
        "ScenesPeclet",
        SCENES_PECLET,
        SECTION_DOCS["scenes_peclet"],
        base=(m.SceneBase, Field(..., description=description(base))),
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
    )
    return m


_MODELS = build()
Config = _MODELS.Config  # the whole config; its sections' models: build()


def members(tp) -> list:
    """The types a value of type ``tp`` may have (Annotated and unions unwrapped)."""
    origin = typing.get_origin(tp)
    if origin is Annotated:
        return members(typing.get_args(tp)[0])
    if origin in (typing.Union, types.UnionType):
        return [m for a in typing.get_args(tp) for m in members(a)]
    return [tp]


def is_model(tp) -> bool:
    """Whether ``tp`` is a model class (a section or an item of one)."""
    return isinstance(tp, type) and issubclass(tp, BaseModel)
