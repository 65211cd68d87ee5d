"""Write the config schema's entries from their one declaration (core/settings.py).

The schema (workflow/schemas/config.schema.yaml) is hand-written except between the lines
``# BEGIN generated: <block>`` and ``# END generated: <block>``: there this module writes, from
the declarations of core/settings.py, the registry and the list of figures (figures.FIGURES),
the entries of physics, time, numerics and case_defaults, the $defs of the case dimensions and
of a section of cases, and the whole objects of figures, tradeoff, mechanism, shear, an adaptive
search, a scene, the Peclet sweep (its base a scene without v) and a `realisations` entry (type,
range or enum, default, description, required keys).
What stays hand-written is the frame: the top-level keys and the few rules between keys a schema
can say (a search's budget and range). Snakemake reads the schema from a file, so the generated
lines are committed; ``python -m particle_entropy.pipeline.schemagen --check`` (and
tests/test_settings.py) fails when they are stale, ``--write`` rewrites them.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from dataclasses import replace
from pathlib import Path

from ..core.case import NONE
from ..core.registry import ALL_KERNELS, METHODS, PRESETS
from ..core.settings import (
    BY_KEY,
    CASE_SECTION,
    CASE_SETTINGS,
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
    Setting,
)
from ..figures import PAPER_FIGURES
from .configcheck import SCHEMA_PATH

COMMAND = "python -m particle_entropy.pipeline.schemagen --write"
_BLOCK = re.compile(r"^([ \t]*)# BEGIN generated: (\w+)\n.*?^[ \t]*# END generated: \2\n", re.M | re.S)


def _yaml(value) -> str:
    """A value in YAML flow style that PyYAML reads back as the same value (1e-17 as a float:
    YAML 1.1 wants a decimal point)."""
    if isinstance(value, float):
        text = repr(value)
        if "e" in text and "." not in text.split("e")[0]:
            text = text.replace("e", ".0e", 1)
        return text
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_yaml(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml(v) for v in value) + "]"
    if isinstance(value, str) and not re.fullmatch(r"[A-Za-z_][\w-]*", value):
        return json.dumps(value)  # quoted; a plain word stays plain
    return str(value) if not isinstance(value, bool) else str(value).lower()


def _number(value: float):
    return int(value) if float(value).is_integer() else value


def description(s: Setting) -> str:
    """The schema's description: the meaning, the unit and the allowed values (configcheck
    quotes it when a value is refused)."""
    unit = "" if s.unit == "-" else f" [{s.unit}]"
    return f"{s.doc[0].upper()}{s.doc[1:]}{unit}; {s.allowed()}."


class Block(dict):
    """A mapping the schema writes in block style, one key a line (other mappings: flow style)."""


def entry(s: Setting, default: bool = True) -> dict:
    """The JSON-schema entry of one setting."""
    out: dict = {}
    if s.kind == "shape":
        out = dict(s.shape)
    elif s.kind == "boolean":
        out = {"type": "boolean"}
    elif s.choices is not None:
        out = {"type": "string", "enum": list(s.choices)}
    else:
        number = {"type": "integer" if s.kind == "integer" else "number"}
        if s.low is not None and s.low != -math.inf:
            number["exclusiveMinimum" if s.open_low else "minimum"] = _number(s.low)
        if s.high != math.inf:
            number["maximum"] = _number(s.high)
        out = {"oneOf": [{"type": "string", "enum": [NONE]}, number]} if s.none else number
    if default and s.has_default and "$ref" not in out:  # a referenced definition carries its own default
        out["default"] = NONE if s.none and s.default is None else s.default
    out["description"] = description(s)
    return out


def object_body(section: str, settings) -> Block:
    """The schema of the object at config key ``section``: its meaning (settings.SECTION_DOCS),
    an entry per setting directly in it, the objects nested in it (``section.sub``, in the order
    of their first setting) and the keys it requires."""
    props, required = Block(), []
    for s in settings:
        if s.section == section:
            props[s.name] = entry(s)
            if s.required:
                required.append(s.name)
        elif s.section.startswith(section + "."):
            sub = s.section[len(section) + 1 :].split(".")[0]
            if sub not in props:
                props[sub] = object_body(f"{section}.{sub}", settings)
    out = Block(type="object", description=SECTION_DOCS[section], additionalProperties=False, properties=props)
    if required:
        out["required"] = required
    return out


def case_section(section: str, extra=()) -> tuple[Setting, ...]:
    """The settings of a section of cases at config key ``section`` (settings.CASE_SECTION), and ``extra``."""
    return tuple(replace(s, key=f"{section}.{s.name}") for s in CASE_SECTION) + tuple(extra)


def figures_body() -> Block:
    """The `figures` object: one entry per paper figure (figures.PAPER_FIGURES), a section of cases
    with the figure's drawing options where it has some (settings.FIGURE_OPTIONS)."""
    props = Block()
    for fig in PAPER_FIGURES:
        options = [s for s in FIGURE_OPTIONS if s.section == f"figures.{fig}"]
        if options:
            body = object_body(
                "<section>", case_section("<section>", [replace(s, key=f"<section>.{s.name}") for s in options])
            )
            props[fig] = body
        else:
            props[fig] = {"$ref": "#/$defs/case_section"}
    return Block(type="object", description=SECTION_DOCS["figures"], additionalProperties=False, properties=props)


def peclet_body() -> Block:
    """The `scenes_peclet` object: its base is a scene's object without v (the sweep sets it), so
    that a typo there is refused as it is under scenes.<name>."""
    body = object_body("scenes_peclet", SCENES_PECLET)
    base = object_body("scenes.<name>", [s for s in SCENE if s.name != "v"])
    base["description"] = description(BY_KEY["scenes_peclet.base"])
    body["properties"]["base"] = base
    return body


def blocks() -> dict[str, Block]:
    """Every generated block: its keys and their values, as the schema writes them."""
    out: dict[str, list[tuple[str, dict]]] = {"physics": [], "time": [], "numerics": [], "case_defaults": []}
    defs = [
        ("method", {"type": "string", "enum": list(METHODS), "description": "pt, mtpt or fd (registry.METHODS)."}),
        (
            "kernel",
            {"type": "string", "enum": list(ALL_KERNELS), "description": "The method's kernel (registry.KERNELS)."},
        ),
    ]
    presets = "; ".join(
        f"{k}: {', '.join(f'{d} {v:g}' if isinstance(v, float) else f'{d} {v}' for d, v in dims.items())}"
        for k, dims in PRESETS.items()
    )
    defs.append(
        (
            "preset",
            {
                "type": "string",
                "enum": list(PRESETS),
                "description": f"Named case dimensions (registry.PRESETS; a dimension the case sets wins): {presets}.",
            },
        )
    )
    for s in SETTINGS:
        key = s.key.split(".", 1)[1]
        if s.section == "case_defaults":
            defs.append((key, entry(s, default=False)))
            d = NONE if s.none and s.default is None else s.default
            out["case_defaults"].append((key, {"$ref": f"#/$defs/{key}", "default": d}))
        else:
            out[s.section].append((key, entry(s)))
    case = {k: {"$ref": f"#/$defs/{k}"} for k in ("method", "kernel", "preset", *CASE_SETTINGS)}
    defs.append(
        (
            "case",
            Block(
                type="object",
                description=f"One model: method and kernel, and the dimensions {', '.join(CASE_SETTINGS)} that apply "
                "to it "
                "(unset ones come from case_defaults).",
                additionalProperties=False,
                properties=Block(case),
                required=["method", "kernel"],
            ),
        )
    )
    defs.append(("case_section", object_body("<section>", CASE_SECTION)))
    defs.append(
        (
            "realisations",
            {
                "description": f"Realisations per N, {REALISATIONS_DOC}.",
                "default": BY_KEY["<section>.realisations"].default,
                "oneOf": [
                    {"type": "integer", "minimum": 1, "maximum": MAX_REALISATIONS},
                    {"type": "string", "enum": ["ensemble"]},
                ],
            },
        )
    )
    out["defs"] = defs
    generated = {name: Block(pairs) for name, pairs in out.items()}
    generated["seeds"] = Block(base_seed=entry(SEEDS[0]), seed_blocks=object_body("seed_blocks", SEEDS))
    generated["comic_times"] = Block(comic_times=entry(COMIC_TIMES[0]))
    generated["claims"] = object_body("claims", CLAIMS)
    generated["figures"] = figures_body()
    generated["tradeoff"] = object_body("tradeoff", case_section("tradeoff", TRADEOFF))
    generated["mechanism"] = object_body("mechanism", MECHANISM)
    generated["shear"] = object_body("shear", SHEAR)
    generated["search"] = object_body("optimum.<name>", SEARCH)
    generated["scene"] = object_body("scenes.<name>", SCENE)
    generated["scenes_peclet"] = peclet_body()
    generated["realisations_entry"] = Block(items=object_body("realisations[]", REALISATIONS_ENTRY))
    return generated


def _lines(block: Block, indent: str) -> list[str]:
    """``block`` as schema lines at ``indent``: nested Blocks in block style, other values in flow style."""
    out = []
    for key, value in block.items():
        if isinstance(value, Block):
            out += [f"{indent}{key}:\n", *_lines(value, indent + "  ")]
        else:
            out.append(f"{indent}{key}: {_yaml(value)}\n")
    return out


def render(text: str) -> str:
    """``text`` (the schema) with every generated block written afresh."""
    generated = blocks()
    seen = set()

    def fill(match: re.Match) -> str:
        indent, name = match.group(1), match.group(2)
        if name not in generated:
            raise ValueError(f"schema block {name!r} is not one this module writes: {', '.join(generated)}")
        seen.add(name)
        lines = [f"{indent}# BEGIN generated: {name} (from core/settings.py by `{COMMAND}`; do not edit)\n"]
        lines += _lines(generated[name], indent)
        return "".join(lines) + f"{indent}# END generated: {name}\n"

    out = _BLOCK.sub(fill, re.sub(r"# BEGIN generated: (\w+) \(.*\)\n", r"# BEGIN generated: \1\n", text))
    missing = set(generated) - seen
    if missing:
        raise ValueError(f"the schema has no generated block for {', '.join(sorted(missing))}")
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m particle_entropy.pipeline.schemagen", description=__doc__)
    p.add_argument("--check", action="store_true", help="exit 1 when the schema's generated lines are stale")
    p.add_argument("--write", action="store_true", help="rewrite the generated lines in place")
    p.add_argument("--schema", default=str(SCHEMA_PATH), help="schema file (default: the workflow's)")
    a = p.parse_args(argv)
    path = Path(a.schema)
    text = path.read_text(encoding="utf-8")
    new = render(text)
    if a.write:
        if new != text:
            path.write_text(new, encoding="utf-8")
        return 0
    if a.check and new != text:
        print(f"{path}: the generated settings are stale; run `{COMMAND}`", file=sys.stderr)
        return 1
    if not a.check:
        sys.stdout.write(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
