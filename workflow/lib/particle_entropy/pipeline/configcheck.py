"""Check a workflow config before any job runs, each problem in one short message.

Three layers: YAML syntax (with the line and column), the typed config (``parse``: each section
by its pydantic model, pipeline/config.py; one error, named by its key path and value, with the
field's description and jsonschema's wording of the refusal, as when the config was checked
against the schema alone) and the rules between sections and runs (crosschecks.check_sweeps).
``validate_config`` runs the last two and returns the typed config. Snakemake's own loader and
validator report the first two without a line number and with the whole schema and config
around the one useful line.
"""

from __future__ import annotations

import json
import os
import re
import stat
from collections.abc import Mapping
from pathlib import Path

import yaml

from ..core.case import SettingError
from ..core.typed import (  # noqa: F401  (re-exported: the messages' helpers, where they were)
    ALLOWED_CHARS,
    MESSAGE_CHARS,
    SAFE_LOADER,
    bounded,
    clip,
    float_spelling,
    key_path,
    setting_error,
    short,
)
from .config import parse
from .crosschecks import check_memory, check_scene, check_search, check_sweeps

SCHEMA_PATH = Path(__file__).resolve().parents[3] / "schemas" / "config.schema.yaml"
_NUMBER_TEXT = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


YTE_KEY = "__use_yte__"  # Snakemake runs a config file holding this key as a yte template: Python code


class ConfigFileError(ValueError):
    """A config file that cannot be read as YAML; the message names the file, line and column."""


MAX_CONFIG_BYTES = 1_000_000  # a config file is read only up to this size: config.yaml is ~20 kB
MAX_VALUES = 100_000  # values a file may hold once its aliases are expanded: config.yaml has ~2,000
MAX_DEPTH = 40  # nesting levels of mappings and lists: config.yaml has 6
_MERGE_TAG = "tag:yaml.org,2002:merge"
_OCTAL_1_1 = re.compile(r"[-+]?0[0-7]+")  # YAML 1.1 octal (0-prefixed); 1.2's 0o17 is text to YAML 1.1


class _StrictLoader(SAFE_LOADER):
    """The safe loader, refusing what YAML would read other than as written: a key given twice in
    one mapping (YAML keeps the last one silently), YAML 1.1's octal (010 = 8) and base-60
    (1:30 = 90) numbers, a file whose aliases expand beyond MAX_VALUES values (or nest beyond
    MAX_DEPTH) and the yte switch (Snakemake would run the file's templates as Python code).
    Merge keys (<<: *anchor) work as in YAML 1.1, a key written beside them overriding theirs."""

    def get_single_data(self):
        node = self.get_single_node()
        if node is None:
            return None
        _expanded_size(node, 0, {}, set())  # before anything walks the values an alias repeats
        return self.construct_document(node)

    def construct_mapping(self, node, deep=False):
        seen = {}
        for key_node, _ in node.value:
            if key_node.tag == _MERGE_TAG:  # its keys may be overridden here: not a duplicate
                continue
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if key == YTE_KEY:
                raise ConfigFileError(
                    f"line {line}: {YTE_KEY} makes Snakemake run this file as a yte template, Python code; "
                    "a config of this workflow is data: remove the key and write the values out"
                )
            try:
                first = seen.get(key)
            except TypeError:  # an unhashable key: the base loader says so
                break
            seen[key] = line
            if first is not None:  # on any line, a flow mapping's too
                raise ConfigFileError(
                    f"line {line}: key {short(key)!r} given twice in one mapping (first at line {first}); each key once"
                )
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node):
        number = super().construct_yaml_int(node)
        _refuse_yaml11_number(node, number)
        return number

    def construct_yaml_float(self, node):
        number = super().construct_yaml_float(node)
        _refuse_yaml11_number(node, number)
        return number


_StrictLoader.add_constructor("tag:yaml.org,2002:int", _StrictLoader.construct_yaml_int)
_StrictLoader.add_constructor("tag:yaml.org,2002:float", _StrictLoader.construct_yaml_float)


def _refuse_yaml11_number(node, number) -> None:
    """ConfigFileError for a plain scalar that YAML 1.1 reads as octal or base 60."""
    text, line = str(node.value), node.start_mark.line + 1
    if node.style:  # quoted: written as text on purpose (plain: None, libyaml: "")
        return
    digits = text.replace("_", "")
    if ":" in digits:
        raise ConfigFileError(
            f"line {line}: {short(text)} is a YAML 1.1 base-60 number, read as {number!r}; write {number!r} "
            f"(or quote it, '{clip(text, 60)}', for text)"
        )
    if _OCTAL_1_1.fullmatch(digits):
        decimal = int(digits.lstrip("+-").lstrip("0") or "0") * (-1 if digits.startswith("-") else 1)
        spelling = f"write {decimal}" if decimal == number else f"write {decimal} for ten-based or {number!r}"
        raise ConfigFileError(
            f"line {line}: {short(text)} is a YAML 1.1 octal number, read as {number!r}; {spelling} (no leading zero)"
        )


def _expanded_size(node, depth: int, sizes: dict, open_nodes: set) -> int:
    """The number of values ``node`` holds once every alias in it is written out (an alias is the
    same node object again: counted once per use, computed once); ConfigFileError naming the line
    past MAX_VALUES, MAX_DEPTH or a value that contains itself."""
    key = id(node)
    if key in sizes:
        return sizes[key]
    line = node.start_mark.line + 1
    if depth > MAX_DEPTH:
        raise ConfigFileError(f"line {line}: nested deeper than {MAX_DEPTH} levels of mappings and lists")
    if key in open_nodes:
        raise ConfigFileError(f"line {line}: this value contains itself through an alias; write it out")
    if isinstance(node, yaml.ScalarNode):
        return 1
    open_nodes.add(key)
    children = node.value if isinstance(node, yaml.SequenceNode) else [n for pair in node.value for n in pair]
    total = 1
    for child in children:
        total += _expanded_size(child, depth + 1, sizes, open_nodes)
        if total > MAX_VALUES:
            raise ConfigFileError(
                f"line {line}: this value's aliases expand it to more than {MAX_VALUES} values "
                "(a config has a few thousand); write the values out or use fewer aliases"
            )
    open_nodes.discard(key)
    sizes[key] = total
    return total


_KIND = {
    stat.S_IFIFO: "a pipe (FIFO)",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
    stat.S_IFDIR: "a folder",
}


def read_config_text(path: str | Path) -> str:
    """The text of the config file at ``path``: a regular file of at most MAX_CONFIG_BYTES bytes of
    UTF-8, checked before it is opened (a pipe or a device is never read); ConfigFileError else."""
    limit = f"a config is a regular file of at most {MAX_CONFIG_BYTES // 1_000_000} MB"
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise ConfigFileError(f"{path}: no such file") from None
    except OSError as e:
        raise ConfigFileError(f"{path}: cannot be read ({e.strerror or e})") from None
    if not stat.S_ISREG(info.st_mode):
        kind = _KIND.get(stat.S_IFMT(info.st_mode), "not a regular file")
        raise ConfigFileError(f"{path}: {kind}, not a config file; {limit}")
    too_big = ConfigFileError(f"{path}: larger than {MAX_CONFIG_BYTES} bytes; {limit}")
    if info.st_size > MAX_CONFIG_BYTES:
        raise too_big
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_CONFIG_BYTES + 1)  # a file that grows, or a /proc file of size 0
    except OSError as e:
        raise ConfigFileError(f"{path}: cannot be read ({e.strerror or e})") from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise too_big
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:  # the whole file: the offset counts from its start
        line = raw[: e.start].count(b"\n") + 1
        where = f"line {line} (byte {e.start} is 0x{raw[e.start]:02x})"
        raise ConfigFileError(f"{path}: not UTF-8 text at {where}") from None


def _json_object(pairs):
    """A JSON object as a dict, refusing a key given twice (json keeps the last one)."""
    out = {}
    for key, value in pairs:
        if key in out:
            raise ConfigFileError(f"key {short(key)!r} given twice in one JSON object; each key once")
        out[key] = value
    return out


def load_yaml(path: str | Path) -> Mapping:
    """The config file at ``path`` as a mapping, read as Snakemake reads it (JSON when it is JSON,
    else YAML 1.1) but only from a regular file of at most MAX_CONFIG_BYTES (read_config_text);
    ConfigFileError names the line of a syntax error, of a key given twice, of a YAML 1.1 octal or
    base-60 number, of an alias bomb, of the yte switch, and a file that is not UTF-8 text."""
    text = read_config_text(path)
    try:
        try:
            data = json.loads(text, object_pairs_hook=_json_object)  # Snakemake tries JSON first
        except json.JSONDecodeError:
            data = yaml.load(text, Loader=_StrictLoader)
    except ConfigFileError as e:
        raise ConfigFileError(f"{path}: {e}") from None
    except RecursionError:
        raise ConfigFileError(f"{path}: nested deeper than {MAX_DEPTH} levels of mappings and lists") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else "somewhere"
        problem = getattr(e, "problem", None) or str(e).splitlines()[0]
        context, start = getattr(e, "context", None), getattr(e, "context_mark", None)
        if context and start is not None:
            context += f" started at line {start.line + 1}, column {start.column + 1}"
        raise ConfigFileError(
            clip(f"{path}: not valid YAML at {where}: {problem}" + (f" ({context})" if context else ""))
        ) from None
    if not isinstance(data, Mapping):
        raise ConfigFileError(f"{path}: a config is a YAML mapping of keys (physics:, time:, ...), got {short(data)!r}")
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


def check_schema(config: Mapping, schema: Mapping | None = None) -> None:
    """SettingError for the first way ``config`` breaks the workflow's schema (none if it conforms).
    The schema is generated from the typed config's models (schemagen), so the config is checked
    by those models (parse): one check and one form of message, for a dry run as for check-config.
    ``schema``, when given (common.smk passes the file Snakemake's validate then reads), must be
    that generated schema."""
    if schema is not None and schema != load_schema():
        raise ValueError("check_schema checks the workflow's schema, which pipeline/config.py generates")
    parse(config)


def load_schema(path: str | Path = SCHEMA_PATH) -> Mapping:
    with open(path, encoding="utf-8") as f:
        return yaml.load(f, Loader=SAFE_LOADER)


def validate_config(config: Mapping):
    """The merged config validated once and returned typed (pipeline.config.Config): parsed by its
    section models (parse), then the rules between sections and runs (crosschecks.check_sweeps)
    checked on it. SettingError names the key path, the value and the allowed range; its message
    is bounded."""
    typed = parse(config)
    try:
        check_sweeps(config, typed)
    except SettingError as e:
        raise bounded(e) from None
    return typed


def check_config(
    config: Mapping, schema: Mapping | None = None, available: float | None = None, not_judged: list | None = None
):
    """Everything a dry run checks, returning the typed config (pipeline.config.Config): each
    section and every rule between fields (validate_config),
    with ``available`` bytes (the machine's, for the check-config command) that every job fits
    (crosschecks.check_memory), and every adaptive search and scene. A run checks a search or a
    scene only when a requested target needs it (none of the default target's do): given a list
    ``not_judged``, one that would be refused is not raised but said there, one line each, naming
    the targets that would refuse it (the check-config command: judged as the run judges).
    Every message is bounded (``bounded``): a long value is abbreviated."""
    from ..scenes.scene import scenes, sweep_of

    if schema is not None:  # the workflow's, as check_schema takes it
        check_schema(config, schema)
    typed = validate_config(config)
    try:
        if available is not None:
            check_memory(config, available, typed)
    except SettingError as e:
        raise bounded(e) from None

    def judge(check, section: str, targets: str) -> None:
        try:
            check()
        except SettingError as e:
            if not_judged is None:
                raise bounded(e) from None
            not_judged.append(f"{section} not judged: only {targets} use it, and they would refuse it: {bounded(e)}")

    for name in config.get("optimum", {}) or {}:
        judge(
            lambda name=name: check_search(name, config, available),
            f"optimum.{name}",
            f"`snakemake optimum` and results/optimum/{name}.parquet",
        )
    every = scenes(config, lambda scene: check_scene(scene, config["base_seed"], available))
    for name in every:  # builds and checks each scene
        sweep = sweep_of(name)
        judge(
            lambda name=name: every[name],
            f"{sweep[0]} (its scene {name})" if sweep else f"scenes.{name}",
            "`snakemake scenes` and " + ("figures/scenes_peclet.png" if sweep else f"figures/scene_{name}.png"),
        )
    return typed


def check_parsed_config(
    config: dict, overrides: Mapping, schema_path: str | Path, fill_defaults, available: float | None = None
):
    """The merged config (config.yaml, --configfile, --config) as the Snakefile's parse checks it,
    in one call, returned typed (pipeline.config.Config, parsed once): the ``overrides`` of --config
    retyped as YAML reads them (``retype_overrides``: --config physics={D: 0.002} is a number); each
    section by its model (``parse``: one short message naming the key path; an integer is an int, so
    --config base_seed=1e3, 1000.0 to Snakemake, is refused, not run as seeds~1000.0); the generated
    schema's defaults filled into ``config`` by ``fill_defaults(config, schema_path)`` (Snakemake's
    validate); every rule between fields (crosschecks.check_sweeps); and given the ``available``
    bytes of the machine the jobs run on, that each job fits (crosschecks.check_memory). The
    searches and scenes are checked when a target first needs them."""
    retype_overrides(config, overrides)
    typed = parse(config)
    fill_defaults(config, str(schema_path))
    check_sweeps(config, typed)
    if available is not None:
        check_memory(config, available, typed)
    return typed
