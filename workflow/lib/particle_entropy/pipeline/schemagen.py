"""Write the run settings' entries of the config schema from their one definition (settings.py).

The schema (workflow/schemas/config.schema.yaml) is hand-written except between the lines
``# BEGIN generated: <block>`` and ``# END generated: <block>``: there this module writes the
entries of physics, time, numerics and case_defaults (type, range or enum, default, description),
the $defs of the case dimensions and the shear cases' enum, from ``settings.SETTINGS`` and the registry. Snakemake
reads the schema from a file, so the generated lines are committed;
``python -m particle_entropy.pipeline.schemagen --check`` (and tests/test_settings.py) fails
when they are stale, ``--write`` rewrites them.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

from ..core.case import NONE
from ..core.registry import ALL_KERNELS, METHODS, PRESETS, SHEAR_CASES
from ..core.settings import SETTINGS, Setting
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


def entry(s: Setting, default: bool = True) -> dict:
    """The JSON-schema entry of one setting."""
    out: dict = {}
    if s.choices is not None:
        out = {"type": "string", "enum": list(s.choices)}
    else:
        number = {"type": "number"}
        if s.low is not None:
            number["exclusiveMinimum" if s.open_low else "minimum"] = _number(s.low)
        if s.high != math.inf:
            number["maximum"] = _number(s.high)
        out = {"oneOf": [{"type": "string", "enum": [NONE]}, number]} if s.none else number
    if default:
        out["default"] = NONE if s.none and s.default is None else s.default
    out["description"] = description(s)
    return out


def blocks() -> dict[str, list[tuple[str, dict]]]:
    """(key, entry) lines of every generated block."""
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
    out["defs"] = defs
    out["shear_cases"] = [("items", {"type": "string", "enum": list(SHEAR_CASES)})]
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
        lines = [
            f"{indent}# BEGIN generated: {name} (from core/settings.py and registry.py by `{COMMAND}`; do not edit)\n"
        ]
        lines += [f"{indent}{key}: {_yaml(value)}\n" for key, value in generated[name]]
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
