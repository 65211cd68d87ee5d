"""Typed sections: pydantic models derived from the settings' one declaration, and their refusals.

Every config key is declared once, as a ``Setting`` (core/settings.py; the run settings and the
shear flow's in core/run_settings.py and core/shear_settings.py). This module derives a pydantic
model from those tuples (``section``: ``create_model`` with ``Field(ge/gt/le, description, unit)``)
and turns a model's refusal into the project's ``SettingError``: the key path, the value as
written, the allowed values (the field's description and jsonschema's wording of the refusal).

It sits in core, beside the declarations, so that every owner of a section parses it through the
same model whoever calls: the workflow (pipeline/config.py assembles the whole ``Config`` from these
models and validates it once), a job script, a test or a notebook that builds one scene
(scenes/scene.py: ``Scene.from_config``) or one search (analysis/optimum.py:
``Search.from_config``) from a raw mapping. ``shared`` builds the models such an owner needs: the
shared definitions (a case, lists of cases and of N), a search, a scene with its target and
candidates. Rules that need a built object or a run (a source that fits its window, a run that
fits its steps, two candidates that are one model) stay with the owner, which names the key the
user wrote.
"""

from __future__ import annotations

import difflib
import functools
import math
import operator
import re
import types
import typing
from collections.abc import Mapping
from types import SimpleNamespace
from typing import Annotated, ClassVar, Literal

import yaml
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    ValidationError,
    create_model,
    model_validator,
)
from pydantic_core import PydanticCustomError

from .case import N_MIN, NONE, SettingError, from_text
from .registry import ALL_KERNELS, COURANT_LIMIT, DEFAULT_ADVECTION, METHODS, PRESETS
from .run_settings import SETTINGS
from .settings import (
    BY_KEY,
    CASE_SECTION,
    MAX_REALISATIONS,
    REALISATIONS_DOC,
    RELEASE_SHAPE,
    SCENE,
    SCENES_PECLET,
    SCENES_PECLET2D,
    SEARCH,
    SECTION_DOCS,
    UNIQUE,
    Setting,
    array,
    integer,
    number,
)

SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's, where PyYAML has it: 10x faster
MESSAGE_CHARS = 300  # a value (or a quoted schema message) longer than this is abbreviated in a message
ALLOWED_CHARS = 1000  # the allowed text: a schema description (the longest ~400) and a hint
NAME_PATTERN = r"^[A-Za-z0-9_]+(?![\s\S])"  # a search's or a scene's key: letters, digits, _ (`$` also
# matches before a final newline: (?![\s\S]) is the very end)


# ------------------------------------------------------------------------------ models from settings
def description(s: Setting) -> str:
    """A setting's description: the meaning, the unit and the allowed values (the schema's, the
    docs' and the refusal messages' text)."""
    unit = "" if s.unit == "-" else f" [{s.unit}]"
    return f"{s.doc[0].upper()}{s.doc[1:]}{unit}; {s.allowed()}."


class Section(BaseModel):
    """A config section: unknown keys refused, values frozen once validated."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class OneOf(Section):
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
        return {"description": fragment["description"]} if "description" in fragment else {}
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
        return (defs or shared().defs)[fragment["$ref"].rsplit("/", 1)[1]]
    kind = fragment.get("type")
    if kind is None and "oneOf" in fragment:  # one of several shapes (a number or a pair: 1-D or 2-D)
        return functools.reduce(operator.or_, (annotation(f, defs) for f in fragment["oneOf"]))
    if "enum" in fragment:
        return Literal[tuple(fragment["enum"])]
    if kind == "null":  # a key that may be written null (a release's open until): the one value None
        return type(None)
    if kind in ("number", "integer"):
        bounds = {arg: fragment[key] for key, arg in _BOUNDS.items() if key in fragment}
        return integer(**bounds) if kind == "integer" else number(**bounds)
    if kind == "array":
        length = {arg: fragment[key] for key, arg in _LENGTHS.items() if key in fragment}
        checks = [UNIQUE] if fragment.get("uniqueItems") else []
        return array(annotation(fragment["items"], defs), *checks, **length)
    if kind == "object":  # a mapping of declared keys: the model of its owner's rules (x-model, kept
        # typed), else a plain dict (its consumer parses it further)
        required = set(fragment.get("required", ()))
        fields = {
            k: (annotation(v, defs), Field(... if k in required else None, **_ref_of(v)))
            for k, v in fragment["properties"].items()
        }
        owner = fragment.get("x-model")
        model = create_model(owner or "Shape", __base__=_OWNED[owner] if owner else OneOf, **fields)
        model.one_of = tuple(r["required"][0] for r in fragment.get("oneOf", []))
        return model if owner else Annotated[model, AfterValidator(lambda m: m.model_dump(exclude_unset=True))]
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


def refuse(key: str, allowed: str):
    """A section's rule broken at its ``key``: configcheck names the key path, the value as written
    and ``allowed``."""
    return PydanticCustomError("rule", allowed, {"key": key})


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


# ------------------------------------------------------------------------------ refusals
class _Abbreviated(str):
    """A value too long for a message, shown as its abbreviated repr (no quotes around it)."""

    def __repr__(self) -> str:
        return str(self)


def short(value, limit: int = 60):
    """``value`` itself, or its repr abbreviated to ``limit`` characters."""
    text = repr(value)
    return value if len(text) <= limit else _Abbreviated(text[: limit - 3] + "...")


def clip(text: str, limit: int = MESSAGE_CHARS) -> str:
    text = " ".join(str(text).split())  # one line
    return text if len(text) <= limit else text[: limit - 3] + "..."


def bounded(error: SettingError) -> SettingError:
    """``error`` with its name, value and allowed text abbreviated: at most ~1,600 characters."""
    value, allowed = short(error.value, MESSAGE_CHARS), clip(error.allowed, ALLOWED_CHARS)
    if value is error.value and allowed == error.allowed and len(error.name) <= MESSAGE_CHARS:
        return error
    return SettingError(clip(error.name), value, allowed)


def key_path(parts) -> str:
    """('figures', 'fig9', 'cases', 3, 'eta') -> 'figures.fig9.cases[3].eta'."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        elif not re.fullmatch(r"[A-Za-z0-9_.-]+", str(p)):  # a newline, a space: shown, not printed
            out += f"[{str(p)!r}]"
        else:
            out += f".{p}" if out else str(p)
    return out or "(top level)"


_NUMBER_PARTS = re.compile(r"([+-]?)(\d*)(?:\.(\d*))?(?:[eE]([+-]?)(\d+))?")


def float_spelling(text: str) -> str | None:
    """The number ``text`` spelt so that YAML 1.1 reads it as a float (a dot in the mantissa, a
    sign in the exponent: 1e3 -> 1.0e+3, .5e-2 -> 0.5e-2), or None when it is not a number."""
    m = _NUMBER_PARTS.fullmatch(text.strip())
    if m is None or not (m[2] or m[3]):
        return None
    sign, whole, fraction, exponent_sign, exponent = m.groups()
    out = f"{sign}{whole or '0'}.{fraction or '0'}" + (f"e{exponent_sign or '+'}{exponent}" if exponent else "")
    return out if isinstance(yaml.load(out, Loader=SAFE_LOADER), float) else None


def _number_hint(value, integer: bool = False) -> str:
    """How to write ``value`` as the number it looks like: YAML 1.1 reads 1e-3 (no dot in the
    mantissa, no sign in the exponent) and 0o17 as text; an ``integer`` setting takes no 1000.0."""
    if isinstance(value, float) and integer and value.is_integer() and abs(value) < 2**63:
        return f"; write {int(value)}: an integer, with no decimal point or exponent"
    if not isinstance(value, str):
        return ""
    text = value.strip()
    if re.fullmatch(r"[+-]?0o[0-7]+", text):
        return f"; YAML 1.1 reads {short(text)} as text: write {int(text.replace('0o', ''), 8)} (ten-based)"
    spelling = float_spelling(text)
    if spelling is None:
        return ""
    number = float(spelling)
    if integer and number.is_integer() and abs(number) < 2**63:
        return f"; YAML reads {short(text)} as text: write {int(number)}"
    return f"; YAML 1.1 reads {short(text)} as text: write {spelling}"


# jsonschema's wording of each refusal, which the messages have quoted since the config was checked
# against the schema alone (tests hold it)
_WORDS = {
    "greater_than": "{value!r} is less than or equal to the minimum of {gt}",
    "greater_than_equal": "{value!r} is less than the minimum of {ge}",
    "less_than_equal": "{value!r} is greater than the maximum of {le}",
    "too_short": "{value!r} is too short",
    "empty": "{value!r} should be non-empty",
    "too_long": "{value!r} is too long",
    "int_type": "{value!r} is not of type 'integer'",
    "float_type": "{value!r} is not of type 'number'",
    "bool_type": "{value!r} is not of type 'boolean'",
    "list_type": "{value!r} is not of type 'array'",
    "dict_type": "{value!r} is not of type 'object'",
    "model_type": "{value!r} is not of type 'object'",
    "string_type": "{value!r} is not of type 'string'",
    "literal_error": "{value!r} is not one of {expected}",  # expected: the words, as a list
    "unique_items": "{value!r} has non-unique elements",
    "string_pattern_mismatch": "{value!r} does not match {pattern!r}",
    "union": "{value!r} is not valid under any of the given schemas",
}
_MISSING = object()


def _located(loc, config, model, missing: bool = False):
    """Walk a pydantic error location through the raw ``config`` and the typed ``model``: the key
    path (pydantic's tags of union members and validators left out), the raw value there (as
    written), the field there (its description) and the type there (its known keys). ``missing``:
    the location's last key is one the config does not hold."""
    path, value, info, kind = [], config, None, model
    for i, part in enumerate(loc):
        if isinstance(value, Mapping) and isinstance(part, str):
            absent = missing and i == len(loc) - 1
            step = part if part in value or absent else None
        elif isinstance(value, list) and isinstance(part, int) and 0 <= part < len(value):
            step = part
        else:
            step = None
        if step is None:  # a tag: a union's member, a validator
            continue
        path.append(step)
        value = value.get(step, _MISSING) if isinstance(value, Mapping) else value[step]
        kind, holder = _inner(kind, step)
        if is_model(holder) and step in holder.model_fields:
            info = holder.model_fields[step]
    return path, value, info, kind


def _inner(kind, step):
    """(type of the value at ``step`` inside a value of type ``kind``, the model that declares it)."""
    for t in members(kind):
        if is_model(t) and isinstance(step, str) and step in t.model_fields:
            return t.model_fields[step].annotation, t
        origin = typing.get_origin(t)
        if origin is dict and isinstance(step, str):
            return typing.get_args(t)[1], None
        if origin is list and isinstance(step, int):
            return typing.get_args(t)[0], None
    return None, None


def setting_error(error: ValidationError, config: Mapping, model) -> SettingError:
    """One pydantic ValidationError of ``model`` validating the raw ``config`` as a SettingError: key
    path (within ``config``), value as written, allowed values (the field's description, and
    jsonschema's wording of the refusal)."""
    errors = error.errors()
    first = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])  # a typo before its missing key
    kind, ctx = first["type"], first.get("ctx", {})
    path, value, info, _ = _located(first["loc"], config, model, missing=kind == "missing")
    deeper = [
        e for e in errors if len(p := _located(e["loc"], config, model)[0]) > len(path) and p[: len(path)] == path
    ]
    if deeper and kind.endswith("_type"):  # a union's value of another member's type (a pair, a mapping where
        # a number is one member): that member's refusal names the key or item within it
        first = max(deeper, key=lambda e: len(_located(e["loc"], config, model)[0]))
        kind, ctx = first["type"], first.get("ctx", {})
        path, value, info, _ = _located(first["loc"], config, model, missing=kind == "missing")
    same = [e for e in errors if _located(e["loc"], config, model)[0] == path]
    if len(same) > 1 and kind not in ("missing", "extra_forbidden"):  # each member of a union refused it:
        # a member of its type names the bound it breaks, else none is of its type
        typed = [e for e in same if not e["type"].endswith("_type") and e["type"] != "literal_error"]
        first = typed[0] if typed else first
        kind, ctx = (first["type"], first.get("ctx", {})) if typed else ("union", {})
    if kind == "extra_forbidden" or "[key]" in first["loc"]:
        parent = _located(first["loc"][:-1], config, model)
        models = [t for t in members(parent[3]) if hasattr(t, "model_fields")]
        known = list(models[0].model_fields) if models and "[key]" not in first["loc"] else []
        if "[key]" in first["loc"]:
            key = first["loc"][first["loc"].index("[key]") - 1]
            path = list(path if path and path[-1] == key else [*path, key])
            allowed = parent[2].description if parent[2] is not None and parent[2].description else "a known key"
        else:
            allowed = "a known key: " + ", ".join(known)
            key = path[-1]
        near = difflib.get_close_matches(str(key), known, n=1)
        return SettingError(key_path(path), "(unknown key)", allowed + (f"; did you mean {near[0]}?" if near else ""))
    described = info.description if info is not None and info.description else ""
    if kind == "missing":
        return SettingError(key_path(path), "(missing)", "a required key" + (f": {described}" if described else ""))
    if kind == "each_once":
        return SettingError(f"realisations[{ctx['index']}].n", config["realisations"][ctx["index"]]["n"], first["msg"])
    if kind == "rule":  # the key the rule names, within the value (a dotted key: cost.fd)
        parts, here = ctx["key"].split("."), value
        for part in parts:
            here = here.get(part, "(missing)") if isinstance(here, Mapping) else "(missing)"
        return SettingError(key_path([*path, *parts]), here, first["msg"])
    if kind in ("one_of", "missing_one_of"):
        return SettingError(key_path(path), "(missing)", first["msg"])
    bound = kind in ("greater_than", "greater_than_equal", "less_than_equal")
    if bound and isinstance(value, float) and math.isnan(value):  # nan passes every bound in the schema:
        # refused as not finite, as check_finite does
        return SettingError(key_path(path), value, "a finite number (YAML .nan and .inf are not settings)")
    ctx = {k: int(v) if isinstance(v, float) and v.is_integer() else v for k, v in ctx.items()}
    if kind == "literal_error":  # jsonschema's words: a type, then the enum
        kind = "string_type" if not isinstance(value, str) else kind
        ctx = {"expected": re.findall(r"'([^']*)'", str(ctx.get("expected", "")))}
    if kind == "too_short" and ctx.get("min_length") == 1:
        kind = "empty"
    words = _WORDS.get(kind)
    message = clip(words.format(value=short(value), **ctx) if words else first["msg"])
    allowed = f"{described} ({message})" if described else message
    if kind in ("int_type", "float_type", "string_type", "literal_error", "union"):
        allowed += _number_hint(value, integer=kind == "int_type")
    return SettingError(key_path(path), short(value), allowed)


def check_finite(value, where: str = "") -> None:
    """Every number of a config must be finite: YAML's .nan and .inf pass a model's bounds (inf
    passes ``ge``) but no setting means them. SettingError names the key path."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            check_finite(v, f"{where}.{k}" if where else str(k))
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            check_finite(v, f"{where}[{i}]")
    elif isinstance(value, float) and not math.isfinite(value):
        raise SettingError(where, value, "a finite number (YAML .nan and .inf are not settings)")


def validate(model, raw, where=key_path):
    """``raw`` parsed by ``model`` (its numbers finite), else SettingError naming the key path:
    ``where(path)`` of the path within ``raw`` (a list of keys and indexes; default key_path)."""
    if not isinstance(raw, Mapping):
        raise bounded(SettingError(where([]), short(raw), f"a mapping: {model.__doc__.strip()}"))
    try:
        typed = model.model_validate(dict(raw))
        check_finite(dict(raw))
    except ValidationError as e:
        error = setting_error(e, raw, model)
        raise bounded(SettingError(where(_parts(error.name)), error.value, error.allowed)) from None
    except SettingError as e:
        raise bounded(SettingError(where(_parts(e.name)), e.value, e.allowed)) from None
    return typed


def _parts(path: str) -> list:
    """key_path's inverse: 'candidates[1].n_range' -> ['candidates', 1, 'n_range'] ('(top level)': [])."""
    if path == "(top level)":
        return []
    out = []
    for name, index in re.findall(r"([^.\[\]]+)|\[(\d+)\]", path):
        out.append(int(index) if index else name)
    return out


# ------------------------------------------------------------------------------ the owners' models
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
        if self.n_range is not None and self.growth_range is not None:  # named by the key the user added
            raise refuse("n_range", "absent when growth_range is set (one dimension)")
        if self.n_range is None and self.growth_range is None:
            raise PydanticCustomError("missing_one_of", "exactly one of n_range and growth_range")
        return self


FD_ONLY = ("advection", "fd_dt", "courant")  # a scene candidate's keys that only FD takes
PARTICLE_ONLY = ("dt0",)  # and those only particles take (FD's step: fd_dt or courant)


class _Candidate(OneOf):
    """A scene's candidate: its resolutions (n_range, or a ladder of its own) and FD's keys."""

    @model_validator(mode="after")
    def _exactly_one(self):  # replaces OneOf's: a ladder names itself when n_range is there too
        ladder, n_range, fd = self.ladder, self.n_range, self.method == "fd"
        if ladder is not None and (n_range is not None or any(b <= a for a, b in zip(ladder, ladder[1:]))):
            raise refuse("ladder", "at least two integers >= 2, ascending (instead of n_range)")
        if ladder is None and (n_range is None or not n_range[0] < n_range[1]):
            raise refuse("n_range", "[low, high], integers with 2 <= low < high")
        if fd and ladder is None and any(n % 2 for n in n_range):
            even = "for fd [low, high], even numbers of intervals (a node at x = 0) with 4 <= low < high"
            raise refuse("n_range", even)
        if not fd and (given := [k for k in FD_ONLY if k in self.model_fields_set]):
            raise refuse(given[0], "fd candidates only")
        if fd and (given := [k for k in PARTICLE_ONLY if k in self.model_fields_set]):
            raise refuse(given[0], "particle candidates only (FD's step: fd_dt, or courant in a flow)")
        if fd and ladder is not None and any(n % 2 for n in ladder):
            raise refuse("ladder", "for fd even numbers of intervals")
        limit = COURANT_LIMIT.get(self.advection or DEFAULT_ADVECTION, math.inf)
        if self.courant is not None and self.courant > limit:
            raise refuse(
                "courant",
                f"a number > 0 and <= {limit:g} for advection {self.advection or DEFAULT_ADVECTION} (explicit): "
                "the step's Courant number |v| dt / dx",
            )
        return self


class _Scene(Section):
    """A scene: its seed blocks fit its realisations."""

    @model_validator(mode="after")
    def _measure_of_kind(self):
        measure, reactive = self.target.measure, self.reaction is not None
        if measure in ("product", "product_rmse") and not reactive:
            raise refuse("target.measure", "rmse, entropy or dilution: a scene without a reaction makes no product")
        if reactive and measure in ("entropy", "dilution"):
            raise refuse(
                "target.measure", "rmse (of C_A), product or product_rmse: a reactive scene's reference has no entropy"
            )
        return self

    @model_validator(mode="after")
    def _release_in_time(self):
        """A source's release must put mass in before t_final, and only into a conservative scene: the
        reactive runs count their source's unit mass at t = 0 (core/runconfig.py refuses a reactive run
        with a release)."""
        release = self.source.get("release") if isinstance(self.source, Mapping) else None
        if release is None:
            return self
        if self.reaction is not None:
            raise refuse(
                "source.release",
                "absent in a reactive scene: its runs and reference start from the source's unit mass at t = 0 "
                "(a reaction with a release is not built); drop the release or the reaction",
            )
        start = release.get("from", 0.0)
        if not start < self.t_final:
            raise refuse(
                "source.release.from",
                f"a time in [0, t_final = {self.t_final:g}) [T]: a release that starts at or after the observation "
                "has put no mass in by then",
            )
        return self

    @model_validator(mode="after")
    def _blocks(self):
        r, most = self.realisations, self.max_realisations
        if most is not None and (most < r or most % r):
            raise refuse(
                "max_realisations",
                f"a multiple of realisations ({r}) in [{r}, {MAX_REALISATIONS:,}]: "
                "rungs are refined a seed block of realisations at a time",
            )
        return self


class _SceneBase(_Scene):
    """A Peclet sweep's base: a scene without v."""

    @model_validator(mode="before")
    @classmethod
    def _no_v(cls, data):
        if isinstance(data, Mapping) and "v" in data:
            raise refuse("v", "no v: the sweep sets it (its section's v)")
        return data


class _ScenesPeclet(Section):
    """A Peclet sweep: its velocities (in 2-D its speeds) ascend."""

    @model_validator(mode="after")
    def _ascending(self):
        if any(b <= a for a, b in zip(self.v, self.v[1:])):
            raise refuse("v", BY_KEY[f"{self.KEY}.v"].range_text)
        return self


class _ScenesPeclet1D(_ScenesPeclet):
    KEY: ClassVar[str] = "scenes_peclet"


class _ScenesPeclet2D(_ScenesPeclet):
    KEY: ClassVar[str] = "scenes_peclet2d"


class _Reaction(OneOf):
    """A scene's reaction: each kind its PARAMS (core/reactions.py), and B where it consumes B."""

    @model_validator(mode="after")
    def _keys_of_kind(self):
        from .reactions import REACTIONS

        given = self.model_fields_set
        kinetics = REACTIONS[self.kind]
        own = (*kinetics.PARAMS, *(("B",) if kinetics.CONSUMES_B else ()))
        for key in own:
            if key not in given:
                raise refuse(key, f"a required key of a {self.kind} reaction")
        every = dict.fromkeys(key for cls in REACTIONS.values() for key in cls.PARAMS) | {"B": None}
        for key in every:
            if key in given and key not in own:
                raise refuse(key, f"not a key of a {self.kind} reaction (it takes {', '.join(own)})")
        return self


class _SpeciesB(OneOf):
    """B's initial condition: a uniform background or a plume with its mass."""

    @model_validator(mode="after")
    def _exactly_one(self):
        given = self.model_fields_set
        if ("uniform" in given) == ("source" in given):
            raise PydanticCustomError("one_of", "exactly one of {keys}", {"keys": "uniform, source"})
        if "mass" in given and "uniform" in given:
            raise refuse("mass", "with source only (a uniform B's mass is C0 times its extent)")
        return self


class _Dispersion(OneOf):
    """A 2-D scene's dispersion: {L, T} along and across the flow, or {x, y} along the axes."""

    # the schema's spelling of the rule below
    model_config = ConfigDict(json_schema_extra={"oneOf": [{"required": ["L", "T"]}, {"required": ["x", "y"]}]})

    @model_validator(mode="after")
    def _exactly_one(self):
        given = self.model_fields_set
        for pair in (("L", "T"), ("x", "y")):
            other = [k for k in ("L", "T", "x", "y") if k not in pair and k in given]
            if any(k in given for k in pair):
                if other:
                    raise refuse(other[0], f"absent with {pair[0]}: D is {{L, T}} or {{x, y}}, not both")
                for k in pair:
                    if k not in given:
                        raise refuse(k, f"a number > 0 with {pair[0] if k == pair[1] else pair[1]} [L^2/T]")
                return self
        raise PydanticCustomError("one_of", "exactly one of {keys}", {"keys": "{L, T}, {x, y}"})

    def tensor_spec(self) -> dict:
        """The keys written: {L, T} or {x, y} (core/sources2d.dispersion_tensor reads them)."""
        return self.model_dump(exclude_unset=True)


class _Release(OneOf):
    """A source's release (core/release.py's Release): every number finite, until after from (the rule
    between release.from and the scene's t_final is the scene's: _Scene)."""

    @model_validator(mode="before")
    @classmethod
    def _finite(cls, data):  # before the bounds, so that nan and inf are refused with their range
        if not isinstance(data, Mapping):
            return data
        for key in ("rate", "from", "until"):
            value = data.get(key)
            if isinstance(value, float) and not math.isfinite(value):
                described = RELEASE_SHAPE["properties"][key]["description"]
                raise refuse(key, f"{described} (a finite number: YAML .nan and .inf are not settings)")
        return data

    @model_validator(mode="after")
    def _until_after_from(self):
        start, end = getattr(self, "from") or 0.0, self.until
        if end is not None and not end > start:
            raise refuse(
                "until",
                f"a time > from = {start:g} [T]: the release stops after it starts; or absent "
                "(null): it releases up to t_final",
            )
        return self


# the models of structured values whose rules their owner states
_OWNED = {
    "Candidate": _Candidate,
    "Reaction": _Reaction,
    "SpeciesB": _SpeciesB,
    "Dispersion": _Dispersion,
    "Release": _Release,
}


def keys_in(prefix: str, settings) -> tuple:
    return tuple(s for s in settings if s.section == prefix)


@functools.cache
def shared(settings: tuple = SETTINGS) -> SimpleNamespace:
    """The models an owner parses its section by, from the run settings ``settings``: the shared
    definitions (``defs``: a case's dimensions, a case, lists of cases and of N, a section of cases,
    as the schema's $defs names them), a search (``Search``), a scene (``Scene``, its ``Target`` and
    its candidates) and the Peclet sweep's base scene (``SceneBase``: a scene without v)."""
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

    m.Search = of("Search", SEARCH, SECTION_DOCS["optimum.<name>"], parent=_Search)
    m.Target = of("Target", keys_in("scenes.<name>.target", SCENE), SECTION_DOCS["scenes.<name>.target"])
    scene = keys_in("scenes.<name>", SCENE)
    order = key_order("scenes.<name>", SCENE)
    target = (m.Target, Field(..., description=SECTION_DOCS["scenes.<name>.target"]))
    m.Scene = of("Scene", scene, SECTION_DOCS["scenes.<name>"], parent=_Scene, order=order, target=target)
    base = BY_KEY["scenes_peclet.base"]
    without_v = [s for s in scene if s.name != "v"]
    m.SceneBase = of("SceneBase", without_v, description(base), parent=_SceneBase, order=order, target=target)
    m.ScenesPeclet = of(
        "ScenesPeclet",
        SCENES_PECLET,
        SECTION_DOCS["scenes_peclet"],
        parent=_ScenesPeclet1D,
        base=(m.SceneBase, Field(..., description=description(base))),
    )
    base2d = BY_KEY["scenes_peclet2d.base"]
    m.SceneBase2D = of("SceneBase2D", without_v, description(base2d), parent=_SceneBase, order=order, target=target)
    m.ScenesPeclet2D = of(
        "ScenesPeclet2D",
        SCENES_PECLET2D,
        SECTION_DOCS["scenes_peclet2d"],
        parent=_ScenesPeclet2D,
        base=(m.SceneBase2D, Field(..., description=description(base2d))),
    )
    return m
