"""Command line: python -m particle_entropy simulate ..."""

from __future__ import annotations

import os
import stat
import subprocess
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest

OPTIONS = [
    "--method",
    "--kernel",
    "--n",
    "--eta",
    "--D",
    "--t-final",
    "--dt0",
    "--dt-growth",
    "--truncation",
    "--seed",
    "--out",
    "--state-out",
]
TABLE_COLUMNS = [
    "step",
    "time",
    "dt",
    "H_D",
    "H_C",
    "E",
    "SSE",
    "COMIC",
    "mass_total",
    "mass_min",
    "beta",
    "h",
    "substeps",
    "wall_s",
]


def _cli(*args, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "particle_entropy", *args], capture_output=True, text=True, timeout=timeout
    )


def test_help_lists_every_option():
    res = _cli("simulate", "--help")
    assert res.returncode == 0
    for opt in OPTIONS:
        assert opt in res.stdout, opt


@pytest.mark.parametrize(
    "bad,option",
    [
        (["--n", "0"], "--n"),
        (["--D", "-1"], "--D"),
        (["--eta", "1.5"], "--eta"),
        (["--method", "pt", "--kernel", "sph"], "--kernel"),
        (["--truncation", "abc"], "--truncation"),
        (["--truncation", "0"], "--truncation"),
        (["--dt-growth", "0.5"], "--dt-growth"),
        (["--t-final", "0"], "--t-final"),
        (["--method", "fd", "--n", "7"], "--n"),
        # the Taylor Gauss transform cannot evaluate a truncated kernel (gauss.py): this
        # combination must be refused as a bad setting, not crash mid-run
        (["--truncation", "3", "--transfer-method", "taylor"], ("--truncation", "--transfer-method")),
        # checked before the run, not an OverflowError when the table is written
        (["--seed", str(2**70)], "--seed"),
        (["--seed", "-1"], "--seed"),
        # more than the step limit: a clean exit 2, not a traceback
        (["--dt0", "1e-9", "--dt-growth", "1"], "--dt0"),
        (["--method", "fd", "--t-final", "1e9"], "--dt0"),
    ],
)
def test_bad_values_exit_2_name_the_option_and_write_nothing(tmp_path, bad, option):
    out = tmp_path / "out.parquet"
    res = _cli(
        "simulate",
        "--method",
        "mtpt",
        "--n",
        "20",
        "--t-final",
        "1",
        *bad,
        "--out",
        str(out),
        "--state-out",
        str(tmp_path / "state.parquet"),
        "--quiet",
    )
    assert res.returncode == 2, res.stderr[-2000:]
    options = option if isinstance(option, tuple) else (option,)
    assert any(o in res.stderr for o in options), res.stderr[-2000:]
    assert "Traceback" not in res.stderr
    assert list(tmp_path.iterdir()) == []


def test_good_run_writes_table_and_state(tmp_path):
    out = tmp_path / "sub" / "run.parquet"
    state = tmp_path / "state.parquet"
    res = _cli(
        "simulate",
        "--method",
        "mtpt",
        "--n",
        "50",
        "--t-final",
        "1",
        "--seed",
        "3",
        "--truncation",
        "none",
        "--out",
        str(out),
        "--state-out",
        str(state),
    )
    assert res.returncode == 0, res.stderr[-2000:]
    tab = pq.read_table(out).to_pandas()
    for col in TABLE_COLUMNS:
        assert col in tab.columns, col
    assert tab["step"].tolist() == list(range(len(tab)))
    assert tab["time"].iloc[0] == 0.0 and tab["time"].iloc[-1] == pytest.approx(1.0, rel=1e-14)
    assert np.max(np.abs(tab["mass_total"] - 1.0)) <= 1e-12
    assert (tab["method"] == "mtpt").all() and (tab["n"] == 50).all() and (tab["seed"] == 3).all()
    st = pq.read_table(state).to_pandas()
    assert "x" in st.columns and "mass" in st.columns
    assert len(st) == 50
    assert np.all(np.diff(st["x"].to_numpy()) >= 0)
    assert st["mass"].sum() == pytest.approx(1.0, abs=1e-12)
    # no temporary files left beside the outputs (atomic writes)
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == [
        "run.parquet",
        "run.parquet.sha256",
        "state.parquet",
        "state.parquet.sha256",
    ]


def _small_run(*out_args):
    return _cli("simulate", "--method", "mtpt", "--n", "20", "--t-final", "1", "--quiet", *out_args)


def test_out_and_state_out_on_one_path_are_refused_before_the_run(tmp_path):
    same = tmp_path / "x.parquet"
    res = _small_run("--out", str(same), "--state-out", str(tmp_path / "." / "x.parquet"))
    assert res.returncode == 2 and "--state-out" in res.stderr and "also --out" in res.stderr
    assert "Traceback" not in res.stderr and list(tmp_path.iterdir()) == []


def test_out_and_state_out_through_a_symlinked_folder_are_refused(tmp_path):
    (tmp_path / "d").mkdir()
    (tmp_path / "dlink").symlink_to(tmp_path / "d")
    res = _small_run("--out", str(tmp_path / "d" / "x.parquet"), "--state-out", str(tmp_path / "dlink" / "x.parquet"))
    assert res.returncode == 2 and "also --out" in res.stderr
    assert list((tmp_path / "d").iterdir()) == []  # nothing written, nothing replaced


def test_out_and_state_out_as_hard_links_of_one_file_are_refused(tmp_path):
    out = tmp_path / "x.parquet"
    out.write_bytes(b"kept")
    os.link(out, tmp_path / "y.parquet")
    res = _small_run("--out", str(out), "--state-out", str(tmp_path / "y.parquet"))
    assert res.returncode == 2 and "also --out" in res.stderr
    assert out.read_bytes() == b"kept"


def test_a_device_or_directory_out_is_refused_and_left_alone(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)  # a non-regular file anyone can make (a character device needs root)
    res = _small_run("--out", str(fifo))
    assert res.returncode == 2 and "--out" in res.stderr and "not a regular file" in res.stderr
    assert stat.S_ISFIFO(fifo.stat().st_mode)  # still the pipe
    res = _small_run("--out", str(tmp_path))
    assert res.returncode == 2 and "is a directory" in res.stderr


@pytest.mark.parametrize("flag", ["--out", "--state-out"])
@pytest.mark.parametrize("name", ["newdir/", "newdir/.", "newdir/..", "."])
def test_an_out_that_names_a_folder_is_refused_in_one_line(tmp_path, flag, name):
    """`--out newdir/` wrote a file named `newdir` (round 4, P09): a path ending in a separator, `.`
    or `..` names a folder, new or existing, and is refused before the run; nothing is made."""
    target = os.path.join(str(tmp_path), name)
    other = ["--out", str(tmp_path / "x.parquet")] if flag == "--state-out" else []
    res = _small_run(*other, flag, target)
    assert res.returncode == 2, res.stderr
    last = res.stderr.strip().splitlines()[-1]
    assert f"{flag}: {target}: names a folder, not a file" in last and "run.parquet" in last
    assert "Traceback" not in res.stderr and sorted(p.name for p in tmp_path.iterdir()) == []


def test_an_out_inside_a_file_is_refused_before_the_run(tmp_path):
    blocker = tmp_path / "notes.txt"
    blocker.write_text("a file where a folder would be")
    res = _small_run("--out", str(blocker / "run.parquet"))
    assert res.returncode == 2 and "cannot write" in res.stderr and "notes.txt" in res.stderr
    assert blocker.read_text() == "a file where a folder would be"


def test_a_run_larger_than_the_memory_available_is_refused_before_it_starts(tmp_path, monkeypatch, capsys):
    import particle_entropy.pipeline.memory as memory
    from particle_entropy.cli import main

    monkeypatch.setattr(memory, "available_bytes", lambda: 200e6)  # a machine with 200 MB free
    out = tmp_path / "x.parquet"
    with pytest.raises(SystemExit) as stop:
        main(["simulate", "--method", "pt", "--n", "100", "--t-final", "1", "--out", str(out), "--quiet"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "need about 0.30 GB" in err and "more than the 0.20 GB available" in err and "lower --n" in err
    assert not out.exists()


def test_memory_estimate_is_above_a_measured_peak(tmp_path):
    """200,000 FD steps (one table row each): the estimate the CLI checks must bound the real peak."""
    from particle_entropy.core.runconfig import RunConfig
    from particle_entropy.pipeline.memory import estimate_bytes

    args = ["--method", "fd", "--n", "100", "--t-final", "1000", "--dt0", "0.005", "--quiet"]
    proc = subprocess.Popen([sys.executable, "-m", "particle_entropy", "simulate", *args, "--out", str(tmp_path / "x")])
    _, status, usage = os.wait4(proc.pid, 0)
    assert status == 0
    peak = usage.ru_maxrss * 1024  # Linux reports kB
    estimate = estimate_bytes(RunConfig.of(method="fd", n=100, t_final=1000.0, dt0=0.005).resolved())
    assert peak > 400e6  # the steps do cost memory (~1.9 kB each): the check is not vacuous
    assert peak < estimate < 2 * peak


@pytest.mark.parametrize(
    "option,value,reason",
    [("--t-final", "1e-300", "SSE = 0")],  # omega 1e-300 no longer runs: the plume outgrows it (test_degenerate)
)
def test_a_run_comic_cannot_score_says_so(tmp_path, option, value, reason):
    """A meaningful run (mass conserved) whose COMIC is -inf (t_final 1e-300: SSE = 0) or inf
    (omega 1e-300: the densities overflow) ended with exit 0 and no word; it now warns, naming why."""
    out = tmp_path / "x.parquet"
    res = _cli("simulate", "--method", "mtpt", "--n", "100", option, value, "--quiet", "--out", str(out))
    assert res.returncode == 0 and out.exists()
    assert "warning: COMIC at t=" in res.stderr and f"does not score this run: {reason}" in res.stderr
    good = _small_run("--out", str(out))
    assert good.returncode == 0 and "warning" not in good.stderr
