"""Write the config schema (workflow/schemas/config.schema.yaml), the whole file, from the typed config.

The schema is a rendering of the section models of pipeline/config.py (themselves derived from the
declarations of core/settings.py): each model an object (its docstring the description, unknown
keys refused, its required keys), each field its type, range or enum, default and description,
the shared definitions ($defs: a case's dimensions, a case, the lists of cases and of N, a
section of cases) referenced where a field has their type. Nothing in it is written by hand.
Snakemake reads the schema from a file (common.smk: ``validate``), so the file is committed;
``python -m particle_entropy.pipeline.schemagen --check`` (and tests/test_settings.py) fails when
it is stale, ``--write`` rewrites it.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import types
import typing
from pathlib import Path

import annotated_types as at
import yaml
from pydantic import StrictBool, StrictInt
from pydantic.fields import FieldInfo

from ..core.case import NONE
from ..core.settings import BY_KEY, SETTINGS, UNIQUE
from ..core.typed import SAFE_LOADER
from . import config as typed
from .configcheck import SCHEMA_PATH

COMMAND = "python -m particle_entropy.pipeline.schemagen --write"
HEADER = f"# Generated from pipeline/config.py (core/settings.py) by `{COMMAND}`; do not edit.\n"
FLOW_DEPTH = 3  # mappings nested deeper than this, and every entry of a setting, are written on one line


def _yaml(value) -> str:
    """A value in YAML flow style that PyYAML reads back as the same value (1e-5 as a float:
    YAML 1.1 wants a decimal point)."""
    if isinstance(value, float):
        text = repr(value)
        if "e" in text and "." not in text.split("e")[0]:
            text = text.replace("e", ".0e", 1)
        return text
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_yaml(k)}: {_yaml(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml(v) for v in value) + "]"
    if isinstance(value, str) and not re.fullmatch(r"[A-Za-z_][\w-]*", value):
        return json.dumps(value)  # quoted; a plain word stays plain ...
    if isinstance(value, str) and yaml.load(value, Loader=SAFE_LOADER) != value:
        return json.dumps(value)  # ... unless YAML reads it as another value (null, true, no)
    return str(value) if not isinstance(value, bool) else str(value).lower()


def _number(value):
    return int(value) if isinstance(value, float) and value.is_integer() else value


class Block(dict):
    """A mapping the schema writes in block style, one key a line (other mappings: flow style)."""


_BOUNDS = {at.Gt: ("exclusiveMinimum", "gt"), at.Ge: ("minimum", "ge"), at.Le: ("maximum", "le")}
_LENGTHS = {at.MinLen: ("minItems", "min_length"), at.MaxLen: ("maxItems", "max_length")}


def _constraints(metadata) -> dict:
    """The JSON-schema keywords of pydantic's constraints (bounds, lengths, uniqueness)."""
    out = {}
    for m in metadata:
        if isinstance(m, FieldInfo):
            out.update(_constraints(m.metadata))
        for kinds in (_BOUNDS, _LENGTHS):
            if type(m) in kinds:
                key, attr = kinds[type(m)]
                out[key] = _number(getattr(m, attr))
        if m is UNIQUE:
            out["uniqueItems"] = True
    return out


class Writer:
    """The schema of the models of ``build(settings)``: ``entry`` of a type, ``body`` of a model."""

    def __init__(self, settings: tuple):
        self.m = typed.build(settings)
        self.names = {id(t): name for name, t in self.m.defs.items()}

    def _inline(self, tp) -> bool:
        """Whether ``tp`` is a section model written in place (not a shared definition, not a shape)."""
        return typed.is_model(tp) and not issubclass(tp, typed.OneOf) and self.ref(tp) is None

    def ref(self, tp) -> dict | None:
        name = self.names.get(id(tp))
        return None if name is None else {"$ref": f"#/$defs/{name}"}

    def entry(self, tp, metadata=(), top: bool = False) -> dict:
        """The JSON-schema entry of a value of type ``tp`` (constraints ``metadata``); a shared
        definition is referenced unless ``top`` (its own entry in $defs)."""
        if not top and (ref := self.ref(tp)) is not None:
            return ref
        origin, args = typing.get_origin(tp), typing.get_args(tp)
        if origin is typing.Annotated:
            return self.entry(args[0], [*args[1:], *metadata])
        if origin in (typing.Union, types.UnionType):
            kinds = [a for a in args if a is not type(None)]
            null = [{"type": "null"}] if len(kinds) < len(args) else []  # a key that may be written null
            if len(kinds) == 1 and not null:
                return self.entry(kinds[0], metadata)
            return {"oneOf": [self.entry(a) for a in kinds] + null}
        if origin is typing.Literal:
            return {"type": "string", "enum": list(args)}
        if origin is list:
            return {"type": "array", "items": self.entry(args[0]), **_constraints(metadata)}
        if tp in (int, StrictInt):
            return {"type": "integer", **_constraints(metadata)}
        if tp is float:
            return {"type": "number", **_constraints(metadata)}
        if tp in (bool, StrictBool):
            return {"type": "boolean"}
        if tp is dict:
            return {"type": "object"}
        if origin is dict:  # keys of an enum, each with a value of one type
            keys = self.entry(args[0])
            return {"type": "object", "propertyNames": keys, "additionalProperties": self.entry(args[1])}
        if typed.is_model(tp):
            return self.body(tp, flow=True)
        raise TypeError(f"no schema entry for {tp!r}")

    def field(self, info: FieldInfo) -> dict:
        """A field's entry, its default (a required key's documented one too) and description."""
        extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
        out = {"$ref": extra["ref"]} if "ref" in extra else dict(self.entry(info.annotation, info.metadata))
        default = extra.get("default", info.default)
        if "$ref" in out:  # the referenced definition carries its own default
            default = None
        if default is not None and repr(default) != "PydanticUndefined":
            out["default"] = NONE if default is None else default
        if info.description:
            out["description"] = info.description
        return out

    def body(self, model, flow: bool = False) -> dict:
        """The object of a section model: its meaning, a key per field, the keys it requires."""
        props = {}
        for name, info in model.model_fields.items():
            tp = info.annotation
            nested = [t for t in typed.members(tp) if typed.is_model(t) and not issubclass(t, typed.OneOf)]
            if model is self.m.CaseDefaults:  # each dimension: its $defs entry and its default
                props[name] = {"$ref": f"#/$defs/{name}", "default": NONE if info.default is None else info.default}
            elif nested and self._inline(nested[0]) and not flow:
                props[name] = self.body(nested[0])
                extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
                if "default" in extra:  # written after the type
                    props[name] = Block(
                        type="object", default=extra["default"], **{k: v for k, v in props[name].items() if k != "type"}
                    )
                if info.description and nested[0].__doc__ != info.description:
                    props[name]["description"] = info.description
            elif typing.get_origin(tp) is dict and typed.is_model(typing.get_args(tp)[1]):  # one per name
                pattern = typing.get_args(typing.get_args(tp)[0])[1].metadata[0].pattern
                value = typing.get_args(tp)[1]
                props[name] = Block(
                    type="object",
                    description=info.description,
                    additionalProperties=False,
                    patternProperties=Block({pattern: self.body(value)}),
                )
            elif typing.get_origin(tp) is list and self._inline(typing.get_args(tp)[0]) and not flow:
                item = typing.get_args(tp)[0]
                props[name] = Block(type="array", description=info.description, items=self.body(item))
            else:
                props[name] = self.field(info)
        shape = issubclass(model, typed.OneOf)  # a structured value's mapping: described by its field
        out = {"type": "object", "description": _doc(model), "additionalProperties": False, "properties": props}
        if shape:
            del out["description"]
        required = [n for n, info in model.model_fields.items() if info.is_required()]
        if required:
            out["required"] = required
        if shape and model.one_of:
            out["oneOf"] = [{"required": [k]} for k in model.one_of]
        extra = model.model_config.get("json_schema_extra")
        if isinstance(extra, dict):
            out.update(extra)
        return out if flow else Block(out, properties=Block(props))

    def schema(self) -> Block:
        """The whole schema: the config's object and the shared definitions."""
        out = Block({"$schema": "https://json-schema.org/draft/2020-12/schema"})
        out.update(self.body(self.m.Config))
        defs = Block()
        for name, tp in self.m.defs.items():
            if typed.is_model(tp):
                defs[name] = self.body(tp)
                continue
            entry = self.entry(tp, top=True)
            if name in typed.DEF_DOCS:
                entry = {"description": typed.DEF_DOCS[name], **entry}
            if name == "realisations":
                entry = {**entry, "default": 1}
            setting = BY_KEY.get(f"case_defaults.{name}")
            if setting is not None:
                entry["description"] = typed.description(setting)
            defs[name] = entry
        out["$defs"] = defs
        return out


def _doc(model) -> str:
    return " ".join((model.__doc__ or "").split())


def _lines(block: dict, indent: str = "") -> list[str]:
    """``block`` as schema lines at ``indent``: Blocks in block style, other values in flow style."""
    out = []
    for key, value in block.items():
        if isinstance(value, Block):
            out += [f"{indent}{_yaml(key)}:\n", *_lines(value, indent + "  ")]
        else:
            out.append(f"{indent}{_yaml(key)}: {_yaml(value)}\n")
    return out


def _cell(value) -> str:
    return str(value).replace("|", "\\|").replace("\n", " ")


def docs(settings: tuple = SETTINGS) -> str:
    """docs/config.md: a table per section (each model once, at the first key it sits at) of its
    keys, defaults, units and meanings with their allowed values."""
    m = typed.build(settings)
    names = {id(t): f"$defs.{n}" for n, t in m.defs.items()}
    out = [
        "# Config settings\n\n",
        f"Generated from the typed config (pipeline/config.py, declared in core/settings.py) by `{COMMAND}`;\n",
        "do not edit. `workflow/schemas/config.schema.yaml` is generated from the same models.\n",
    ]
    seen, todo = set(), [("config", m.Config)]
    while todo:
        path, model = todo.pop(0)
        if id(model) in seen:
            continue
        seen.add(id(model))
        out += [f"\n## `{names.get(id(model), path)}`\n\n{_doc(model)}\n\n"]
        out += ["| key | default | unit | meaning; allowed values |\n", "|---|---|---|---|\n"]
        nested = []
        for name, info in model.model_fields.items():
            tp = info.annotation
            inner = typing.get_args(tp)[1] if typing.get_origin(tp) is dict else tp
            inner = typing.get_args(inner)[0] if typing.get_origin(inner) is list else inner
            models = [t for t in typed.members(inner) if typed.is_model(t) and not issubclass(t, typed.OneOf)]
            where = f"{path}.{name}" if path != "config" else name
            if models:
                key = where + (".<name>" if typing.get_origin(tp) is dict else "[]" if inner is not tp else "")
                nested.append((key, models[0]))
                shown = names.get(id(models[0]), key)
                out.append(
                    f"| `{name}` | | | section `{shown}`{': ' + info.description if info.description else ''} |\n"
                )
                continue
            extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
            default = extra.get("default", info.default)
            default = "" if default is None or repr(default) == "PydanticUndefined" else f"`{_yaml(default)}`"
            if info.is_required():
                default = (default + " " if default else "") + "(required)"
            unit = "" if extra.get("unit", "-") == "-" else extra["unit"]
            out.append(f"| `{name}` | {_cell(default)} | {_cell(unit)} | {_cell(info.description or '')} |\n")
        todo += nested
    return "".join(out)


def render(text: str = "") -> str:
    """The schema's text, written afresh from the models (``text``, the file as it stands, is not
    read: nothing in it is kept)."""
    return HEADER + "".join(_lines(Writer(SETTINGS).schema()))


DOCS_PATH = SCHEMA_PATH.parents[2] / "docs" / "config.md"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m particle_entropy.pipeline.schemagen", description=__doc__)
    p.add_argument("--check", action="store_true", help="exit 1 when the schema file or the docs table is stale")
    p.add_argument("--write", action="store_true", help="rewrite the schema file and the docs table")
    p.add_argument("--schema", default=str(SCHEMA_PATH), help="schema file (default: the workflow's)")
    p.add_argument("--docs", default=str(DOCS_PATH), help="docs table of the settings (default: docs/config.md)")
    a = p.parse_args(argv)
    stale = []
    for path, new in ((Path(a.schema), render()), (Path(a.docs), docs())):
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        if a.write and new != text:
            path.write_text(new, encoding="utf-8")
        elif new != text:
            stale.append(path)
        if not (a.write or a.check) and path == Path(a.schema):
            sys.stdout.write(new)
    if a.check and stale:
        print(f"{', '.join(map(str, stale))}: stale; run `{COMMAND}`", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
