"""Check a workflow config before any job runs, each problem in one short message.

Three layers: YAML syntax (with the line and column), the JSON schema (one error, named by its
key path, with the allowed values from the schema's own description) and the rules between
fields that a schema cannot say (crosschecks.check_sweeps). Snakemake's own loader and validator
report the first two without a line number and with the whole schema and config around the
one useful line.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping
from pathlib import Path

import yaml

from ..core.case import SettingError

SCHEMA_PATH = Path(__file__).resolve().parents[3] / "schemas" / "config.schema.yaml"
_NUMBER_TEXT = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's, where PyYAML has it: 10x faster
YTE_KEY = "__use_yte__"  # Snakemake runs a config file holding this key as a yte template: Python code


class ConfigFileError(ValueError):
    """A config file that cannot be read as YAML; the message names the file, line and column."""


class _StrictLoader(SAFE_LOADER):
    """The safe loader, refusing a key given twice in one mapping (YAML keeps the last one
    silently) and the yte switch (Snakemake would run the file's templates as Python code)."""

    def construct_mapping(self, node, deep=False):
        seen = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if key == YTE_KEY:
                raise ConfigFileError(
                    f"line {line}: {YTE_KEY} makes Snakemake run this file as a yte template, Python code; "
                    "a config of this workflow is data: remove the key and write the values out"
                )
            try:
                first = seen.setdefault(key, line)
            except TypeError:  # an unhashable key: the base loader says so
                break
            if first != line:
                raise ConfigFileError(f"line {line}: key {key!r} given twice in one mapping (first at line {first})")
        return super().construct_mapping(node, deep=deep)


def load_yaml(path: str | Path) -> Mapping:
    """The YAML file at ``path`` as a mapping; ConfigFileError names the line of a syntax error, of
    a key given twice or of the yte switch, and a file that is not UTF-8 text."""
    try:
        with open(path, encoding="utf-8") as f:
            data = yaml.load(f, Loader=_StrictLoader)
    except ConfigFileError as e:
        raise ConfigFileError(f"{path}: {e}") from None
    except UnicodeDecodeError:
        raw = Path(path).read_bytes()
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError as e:  # the whole file: the offset counts from its start
            line = raw[: e.start].count(b"\n") + 1
            where = f"line {line} (byte {e.start} is 0x{raw[e.start]:02x})"
            raise ConfigFileError(f"{path}: not UTF-8 text at {where}") from None
        raise
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else "somewhere"
        problem = getattr(e, "problem", None) or str(e).splitlines()[0]
        context, start = getattr(e, "context", None), getattr(e, "context_mark", None)
        if context and start is not None:
            context += f" started at line {start.line + 1}, column {start.column + 1}"
        raise ConfigFileError(
            f"{path}: not valid YAML at {where}: {problem}" + (f" ({context})" if context else "")
        ) from None
    if not isinstance(data, Mapping):
        raise ConfigFileError(f"{path}: a config is a YAML mapping of keys (physics:, time:, ...), got {data!r}")
    return data


def typed(value):
    """A value of a nested ``--config`` override with its scalars typed as a config file types them.
    Snakemake reads the nested part of ``--config physics={D: 0.002}`` with YAML's BaseLoader, so
    every scalar arrives as text; 1e-3, a number on a command line, is a number here too."""
    if isinstance(value, Mapping):
        return {k: typed(v) for k, v in value.items()}
    if isinstance(value, list):
        return [typed(v) for v in value]
    if not isinstance(value, str):
        return value
    try:
        out = yaml.load(value, Loader=SAFE_LOADER)
    except yaml.YAMLError:
        return value
    if isinstance(out, str) and _NUMBER_TEXT.match(out.strip()):
        return float(out)
    return out if isinstance(out, (bool, int, float, str)) or out is None else value


def retype_overrides(config: dict, overrides: Mapping) -> None:
    """Type, in ``config``, the nested values that came from ``--config`` (``overrides``, as
    Snakemake parsed them); top-level values Snakemake has typed itself."""
    for key, value in overrides.items():
        if isinstance(value, (Mapping, list)) and config.get(key) is not None:
            _merge_typed(config, key, typed(value))


def _merge_typed(into: dict, key, value) -> None:
    if isinstance(value, Mapping) and isinstance(into.get(key), dict):
        for k, v in value.items():
            _merge_typed(into[key], k, v)
    else:
        into[key] = value


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


def _short(value, limit: int = 60):
    text = repr(value)
    return value if len(text) <= limit else text[: limit - 3] + "..."


def _number_hint(value) -> str:
    """YAML 1.1 reads 1e-3 (no decimal point) as text: say how to write it as a number."""
    if isinstance(value, str) and _NUMBER_TEXT.match(value.strip()):
        mantissa, _, exponent = value.strip().lower().partition("e")
        fixed = (mantissa if "." in mantissa else mantissa + ".0") + (f"e{exponent}" if exponent else "")
        return f"; YAML reads {value} as text: write {fixed}"
    return ""


def _schema_error_to_setting(error) -> SettingError:
    """One jsonschema ValidationError as a SettingError: key path, value, allowed values."""
    path = list(error.absolute_path)
    schema = error.schema if isinstance(error.schema, Mapping) else {}
    if error.validator == "additionalProperties":
        known = list(schema.get("properties", {}))
        unexpected = [k for k in error.instance if k not in known]
        unexpected = [k for k in unexpected if not any(re.match(p, k) for p in schema.get("patternProperties", {}))]
        key = unexpected[0] if unexpected else "?"
        if schema.get("patternProperties") or not known:  # keys by pattern: the description says which
            allowed = schema.get("description", "a known key")
        else:
            allowed = "a known key: " + ", ".join(known)
        near = difflib.get_close_matches(str(key), known, n=1)
        return SettingError(
            key_path([*path, key]), "(unknown key)", allowed + (f"; did you mean {near[0]}?" if near else "")
        )
    if error.validator == "required":
        key = re.match(r"'([^']+)'", error.message)
        key = key.group(1) if key else "?"
        described = schema.get("properties", {}).get(key, {}).get("description", "")
        return SettingError(
            key_path([*path, key]), "(missing)", "a required key" + (f": {described}" if described else "")
        )
    described = schema.get("description", "")
    allowed = f"{described} ({error.message})" if described else error.message
    if error.validator in ("type", "oneOf"):
        allowed += _number_hint(error.instance)
    return SettingError(key_path(path), _short(error.instance), allowed)


def check_schema(config: Mapping, schema: Mapping) -> None:
    """SettingError for the most relevant way ``config`` breaks ``schema`` (none if it conforms)."""
    from jsonschema import Draft202012Validator
    from jsonschema.exceptions import best_match

    error = best_match(Draft202012Validator(schema).iter_errors(dict(config)))
    if error is not None:
        raise _schema_error_to_setting(error)


def load_schema(path: str | Path = SCHEMA_PATH) -> Mapping:
    with open(path, encoding="utf-8") as f:
        return yaml.load(f, Loader=SAFE_LOADER)


def check_config(config: Mapping, schema: Mapping | None = None, available: float | None = None) -> None:
    """Everything a dry run checks: the schema, then every rule between fields (crosschecks.check_sweeps),
    with ``available`` bytes (the machine's, for the check-config command) that every job fits
    (crosschecks.check_memory), and every adaptive search and scene, which a dry run checks only when
    a target needs it."""
    from ..experiments.scene import scenes
    from .crosschecks import check_memory, check_optimum, check_scene_memory, check_sweeps

    check_schema(config, load_schema() if schema is None else schema)
    check_sweeps(config)
    if available is not None:
        check_memory(config, available)
    check_optimum(config, available)
    every = scenes(config, None if available is None else lambda scene: check_scene_memory(scene, available))
    for name in every:  # builds and checks each scene
        every[name]
