"""Config files read as written and judged as the run judges them (issue 33): keys once per mapping,
no YAML 1.1 octal or base-60 numbers, merge keys, alias bombs and long values bounded, number hints
that parse, only regular files of bounded size, --config values typed, and check-config agreeing
with the run about sections that only their own targets use."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import time

import pytest
import yaml
from conftest import ROOT, TINY, run_snakemake

from particle_entropy.cli import main
from particle_entropy.core.case import SettingError
from particle_entropy.pipeline.configcheck import ConfigFileError, check_schema, load_schema, load_yaml

CONFIG = ROOT / "config.yaml"


def _write(tmp_path, text: str, name: str = "overlay.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _check(capsys, *files) -> tuple[int, str, str]:
    code = main(["check-config", *map(str, files)])
    out = capsys.readouterr()
    return code, out.out, out.err


def _check_in_a_process(*files, seconds: float = 20) -> subprocess.CompletedProcess:
    """check-config in its own process, at most 1 GB of memory and ``seconds``: a file read without
    end fails this instead of the test session."""

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))

    return subprocess.run(
        [sys.executable, "-m", "particle_entropy", "check-config", *map(str, files)],
        capture_output=True,
        text=True,
        timeout=seconds,
        preexec_fn=limit,
    )


# --- 1. a key once per mapping, on any line ---------------------------------------------------------


@pytest.mark.parametrize(
    "text, line",
    [
        ("physics: {D: 0.001, D: 0.002}\n", 1),
        ("time: {dt0: 0.01}\nfigures:\n  fig6: {n: [30, 100], realisations: 1, n: [30]}\n", 3),
        ("base_seed: 0\n\nbase_seed: 1\n", 3),
    ],
)
def test_a_key_given_twice_is_refused_on_one_line_too(tmp_path, capsys, text, line):
    code, _, err = _check(capsys, CONFIG, _write(tmp_path, text))
    assert code == 2
    assert f"overlay.yaml: line {line}: key " in err and "given twice in one mapping" in err
    assert len(err.splitlines()) == 1


def test_a_key_given_twice_in_json_is_refused_and_json_is_read_as_json(tmp_path):
    with pytest.raises(ConfigFileError, match=r"o\.json: key 'D' given twice"):
        load_yaml(_write(tmp_path, '{"physics": {"D": 0.001, "D": 0.002}}', "o.json"))
    # Snakemake reads a JSON file with json, where 1e3 is a number (YAML 1.1: text)
    assert load_yaml(_write(tmp_path, '{"physics": {"D": 1e3}}', "n.json"))["physics"]["D"] == 1000.0


# --- 2. YAML 1.1 octal and base-60 numbers ----------------------------------------------------------


@pytest.mark.parametrize(
    "value, words",
    [
        ("010", ["line 3", "010 is a YAML 1.1 octal number, read as 8", "write 10"]),
        ("-07", ["line 3", "-07 is a YAML 1.1 octal number, read as -7", "write -7"]),
        ("1:30", ["line 3", "1:30 is a YAML 1.1 base-60 number, read as 90", "write 90"]),
        ("1:30.5", ["line 3", "1:30.5 is a YAML 1.1 base-60 number, read as 90.5", "write 90.5"]),
    ],
)
def test_yaml_11_octal_and_base_60_numbers_are_refused_naming_value_and_line(tmp_path, capsys, value, words):
    code, _, err = _check(capsys, CONFIG, _write(tmp_path, f"figures:\n  fig6:\n    n: [30, {value}]\n"))
    assert code == 2
    for word in words:
        assert word in err
    assert len(err.splitlines()) == 1


def test_a_quoted_zero_prefixed_value_and_a_plain_zero_stay_as_written(tmp_path):
    data = load_yaml(_write(tmp_path, "a: '010'\nb: 0\nc: 10\nd: 0.5\n"))
    assert data == {"a": "010", "b": 0, "c": 10, "d": 0.5}


# --- 3. merge keys ------------------------------------------------------------------------------------


def test_merge_keys_work_and_a_key_beside_them_overrides_theirs(tmp_path, capsys):
    text = (
        "figures:\n  fig5:\n    cases:\n"
        "      - &b {method: mtpt, kernel: collision, eta: 1}\n"
        "      - {<<: *b, eta: 0.5}\n"
        "    n: [300, 30000]\n"
    )
    overlay = _write(tmp_path, text)
    assert load_yaml(overlay)["figures"]["fig5"]["cases"][1] == {"method": "mtpt", "kernel": "collision", "eta": 0.5}
    code, out, err = _check(capsys, CONFIG, overlay)
    assert (code, err) == (0, "") and "accepted" in out
    with pytest.raises(ConfigFileError, match=r"line 2: key 'eta' given twice"):  # its own keys still once
        load_yaml(_write(tmp_path, "a: &b {eta: 1}\nc: {<<: *b, eta: 0.5, eta: 0.2}\n"))


# --- 4. alias bombs, bounded messages -----------------------------------------------------------------


def _bomb(levels: int, key: str) -> str:
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x]"]
    for i in range(1, levels):
        lines.append(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]")
    return "\n".join(lines) + f"\n{key}: [" + ", ".join([f"*l{levels - 1}"] * 9) + "]\n"


@pytest.mark.parametrize("levels, key", [(9, "comic_times"), (7, "comic_times"), (7, "figures: {fig6: {n")])
def test_an_alias_bomb_is_refused_at_once_naming_the_line(tmp_path, levels, key):
    text = _bomb(levels, key)
    if key.startswith("figures"):
        text = text.rstrip("\n") + "}}\n"
    overlay = _write(tmp_path, text)
    assert overlay.stat().st_size < 600
    start = time.monotonic()
    proc = _check_in_a_process(CONFIG, overlay)
    assert time.monotonic() - start < 15
    assert proc.returncode == 2
    assert "overlay.yaml: line " in proc.stderr and "aliases expand it to more than 100000 values" in proc.stderr
    assert len(proc.stderr) < 400


def test_a_value_that_contains_itself_is_refused(tmp_path):
    with pytest.raises(ConfigFileError, match=r"line 1: this value contains itself"):
        load_yaml(_write(tmp_path, "comic_times: &a [250, *a]\n"))


def test_nesting_past_the_limit_is_refused_in_one_line(tmp_path):
    with pytest.raises(ConfigFileError, match=r"nested deeper than 40 levels"):
        load_yaml(_write(tmp_path, "a: " + "[" * 100 + "]" * 100 + "\n"))
    with pytest.raises(ConfigFileError, match=r"nested deeper than 40 levels"):
        load_yaml(_write(tmp_path, "[" * 100_000 + "]" * 100_000, "deep.json"))


@pytest.mark.parametrize(
    "overlay",
    [
        {"comic_times": "x" * 100_000},  # the schema's message quotes the value
        {"figures": {"fig6": {"n": list(range(1, 50_000))}}},  # a crosscheck's message quotes the list
        {"physics": {"D": -1.0}, "claims": {"x" * 100_000: 1}},
    ],
)
def test_every_message_is_bounded(tmp_path, capsys, overlay):
    code, _, err = _check(capsys, CONFIG, _write(tmp_path, yaml.safe_dump(overlay, width=1_000_000)))
    assert code == 2
    assert len(err) < 2000 and len(err.splitlines()) == 1


# --- 5. number hints that parse ---------------------------------------------------------------------


@pytest.mark.parametrize("text", ["1.0e308", "1e3", "1E-3", "1e-3", ".5e3", "5.e3", "+2e2", "25e-1"])
def test_the_hint_for_a_number_read_as_text_is_a_float_yaml_reads(tmp_path, capsys, text):
    code, _, err = _check(capsys, CONFIG, _write(tmp_path, f"physics: {{D: {text}}}\n"))
    assert code == 2 and f"physics.D='{text}'" in err
    spelling = err.rsplit("write ", 1)[1].split()[0]
    read = yaml.load(spelling, Loader=yaml.SafeLoader)
    assert isinstance(read, float) and read == float(text)
    assert isinstance(load_yaml(_write(tmp_path, f"D: {spelling}\n", "fixed.yaml"))["D"], float)


def test_an_integer_written_as_a_float_or_text_is_refused_with_its_integer_spelling():
    config = dict(load_yaml(CONFIG))
    schema = load_schema()
    for value in (1000.0, "1e3", "1.0e+3"):
        with pytest.raises(SettingError, match=r"base_seed=.*write 1000\b") as err:
            check_schema({**config, "base_seed": value}, schema)
        assert err.value.name == "base_seed"
    check_schema({**config, "base_seed": 1000}, schema)  # an int: fine


# --- 6. devices, pipes, folders, big files ----------------------------------------------------------


def test_only_regular_files_of_bounded_size_are_read(tmp_path):
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    big = _write(tmp_path, "comic_times: [" + "250, " * 300_000 + "250]\n", "big.yaml")
    (tmp_path / "folder.yaml").mkdir()
    cases = {
        fifo: "a pipe (FIFO), not a config file; a config is a regular file of at most 1 MB",
        big: "larger than 1000000 bytes; a config is a regular file of at most 1 MB",
        tmp_path / "folder.yaml": "a folder, not a config file",
        tmp_path / "missing.yaml": "no such file",
    }
    if os.path.exists("/dev/urandom"):
        cases["/dev/urandom"] = "a character device, not a config file; a config is a regular file of at most 1 MB"
    for path, words in cases.items():
        proc = _check_in_a_process(CONFIG, path, seconds=15)
        assert proc.returncode == 2, (path, proc.stderr[-500:])
        assert proc.stderr.startswith(f"check-config: {path}: ") and proc.stderr.count("\n") == 1
        assert words in proc.stderr


# --- 7. what Snakemake loads before the workflow, and what the workflow then refuses ----------------


@pytest.mark.parametrize(
    "name, content, error",
    [
        ("missing.yaml", None, FileNotFoundError),
        ("folder.yaml", "folder", IsADirectoryError),
        ("latin1.yaml", b"physics: {D: 0.001}\n# caf\xe9\n", UnicodeDecodeError),
        ("deep.json", b"[" * 100_000 + b"]" * 100_000, RecursionError),
    ],
)
def test_snakemake_loads_a_configfile_before_the_workflow_runs(tmp_path, name, content, error):
    """What remains uncaught (docs/running.md, "Config files"): Snakemake's command line loads every
    --configfile (ConfigSettings) before the Snakefile's first line runs, so a file it cannot load
    stops there with its own error; check-config refuses each of them in one line."""
    from snakemake.settings.types import ConfigSettings

    path = tmp_path / name
    if content == "folder":
        path.mkdir()
    elif content is not None:
        path.write_bytes(content)
    with pytest.raises(error):
        ConfigSettings(configfiles=[path])
    with pytest.raises(ConfigFileError, match=rf"{name}: "):
        load_yaml(path)


def test_the_workflow_refuses_a_configfile_snakemake_loaded_and_an_untyped_config_value(tmp_path):
    text = TINY.read_text().replace("physics: {D: 0.001,", "physics: {D: 0.001, D: 0.002,", 1)
    assert "D: 0.002" in text
    twice = _write(tmp_path, text, "twice.yaml")
    proc = run_snakemake(tmp_path, dry_run=True, configfile=twice, check=False)
    assert proc.returncode != 0
    assert "twice.yaml: line 1: key 'D' given twice in one mapping" in proc.stdout + proc.stderr
    # --config base_seed=1e3 reaches the config as 1000.0 (Snakemake tries int, then float)
    proc = run_snakemake(tmp_path, "--config", "base_seed=1e3", dry_run=True, configfile=TINY, check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "MissingInputException" not in out
    assert "base_seed=1000.0 is not allowed" in out and "write 1000" in out


# --- 8. check-config judges a set of files as the run does -----------------------------------------


def test_check_config_accepts_what_the_run_accepts_and_names_what_it_did_not_judge(capsys):
    code, out, err = _check(capsys, CONFIG, TINY)
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0] == f"check-config: {CONFIG} + {TINY}: accepted"
    searches = [n for n in load_yaml(CONFIG)["optimum"] if n not in load_yaml(TINY)["optimum"]]
    assert len(lines) == 1 + len(searches)  # one line each: config.yaml's searches past the tiny t_final
    for name, line in zip(searches, lines[1:], strict=True):
        assert line.startswith(f"check-config: optimum.{name} not judged: only `snakemake optimum`")
        assert f"optimum.{name}.time=" in line and "physics.t_final = 20" in line


def test_check_config_still_refuses_a_bad_value_in_a_section_the_run_uses(tmp_path, capsys):
    overlay = _write(tmp_path, "figures:\n  fig1:\n    n: [30, 0]\n")
    code, out, err = _check(capsys, CONFIG, TINY, overlay)
    assert code == 2 and out == "" and "figures.fig1.n" in err
