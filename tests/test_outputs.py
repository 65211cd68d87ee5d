"""Outputs that belong together land together (issue 33): a table and its checksum, a run's
--out and --state-out; SIGINT and SIGTERM end with one line; bad output paths refused first."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

import particle_entropy.core.io as io
from particle_entropy.core.io import checksum_path, run_problem, write_parquet, write_run
from particle_entropy.pipeline.verify import CORRUPT_SUFFIX, set_aside_corrupt

OLD = pd.DataFrame({"step": range(40), "SSE": [1.0 / (k + 1) for k in range(40)]})
NEW = pd.DataFrame({"step": range(60), "SSE": [2.0 / (k + 1) for k in range(60)]})
OLD_STATE = pd.DataFrame({"x": [0.0, 1.0], "mass": [0.5, 0.5]})
NEW_STATE = pd.DataFrame({"x": [0.0, 1.0, 2.0], "mass": [0.25, 0.5, 0.25]})


class Killed(BaseException):
    """A process ended at this point (raised instead of SIGKILL, which no code can follow)."""


def _consistent(path: Path) -> bool:
    """Whether the table at ``path`` has no checksum or its own: never another table's digest."""
    record = checksum_path(path)
    if not record.exists():
        return True
    return record.read_text().split()[0] == hashlib.sha256(path.read_bytes()).hexdigest()


def _stop_at(monkeypatch, k: int, calls=("replace", "unlink")):
    """Make the k-th rename or removal of a file (counting from 0) end the process there."""
    seen = []
    real = {"replace": os.replace, "unlink": Path.unlink}

    def counted(name):
        def call(*args, **kwargs):
            if len(seen) == k:
                raise Killed(name)
            seen.append(name)
            return real[name](*args, **kwargs)

        return call

    monkeypatch.setattr(io.os, "replace", counted("replace"))
    monkeypatch.setattr(Path, "unlink", counted("unlink"))
    return seen


@pytest.mark.parametrize("k", range(4))
def test_a_write_stopped_between_its_steps_never_leaves_a_table_under_another_digest(tmp_path, monkeypatch, k):
    """Case 1: the table and its .sha256 were two renames; stopped between them the new table sat
    under the old digest. Stopped at every rename or removal of the write, each table is whole
    and has no checksum or its own."""
    out = tmp_path / "s.parquet"
    write_parquet(OLD, out)
    _stop_at(monkeypatch, k)
    with pytest.raises(Killed):
        write_parquet(NEW, out)
    monkeypatch.undo()
    assert _consistent(out)
    assert pd.read_parquet(out).equals(OLD) or pd.read_parquet(out).equals(NEW)
    write_parquet(NEW, out)  # the next write restores the checksum
    assert _consistent(out) and checksum_path(out).exists()


def test_a_real_process_killed_at_many_points_leaves_every_table_under_its_own_digest(tmp_path):
    """Case 1 with a real SIGKILL at 6 moments of a loop writing a pair of tables; the next
    write removes the temporaries a kill left (case 3)."""
    writer = (
        "import sys, itertools, pandas as pd\n"
        "from particle_entropy.core.io import write_run\n"
        "for k in itertools.count():\n"
        "    df = pd.DataFrame({'x': [float(k)] * 100000, 'k': k})\n"
        "    write_run({sys.argv[1]: df, sys.argv[2]: df.head(1000)})\n"
        "    print(k, flush=True)\n"
    )
    out, state = tmp_path / "o.parquet", tmp_path / "s.parquet"
    for delay in [0.0, 0.01, 0.02, 0.05, 0.1, 0.2]:
        proc = subprocess.Popen([sys.executable, "-c", writer, out, state], stdout=subprocess.PIPE, text=True)
        proc.stdout.readline()  # one pair written: the kill lands in a later write
        time.sleep(delay)
        proc.kill()
        proc.wait()
        proc.stdout.close()
        assert _consistent(out) and _consistent(state)
    write_run({out: NEW, state: NEW_STATE})
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "o.parquet",
        "o.parquet.sha256",
        "s.parquet",
        "s.parquet.sha256",
    ]


def test_sigint_inside_a_commit_waits_until_the_table_and_its_checksum_are_in_place(tmp_path, monkeypatch):
    """Case 1 and 3: a Ctrl-C arriving while the table is renamed takes effect once its checksum is too."""
    out = tmp_path / "s.parquet"
    write_parquet(OLD, out)
    real = os.replace

    def replace_and_interrupt(src, dst):
        real(src, dst)
        if Path(dst) == out:
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(io.os, "replace", replace_and_interrupt)
    # Python's own Ctrl-C: a shell that starts pytest in the background hands it SIGINT ignored
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    with pytest.raises(KeyboardInterrupt):
        write_parquet(NEW, out)
    signal.signal(signal.SIGINT, previous)
    assert pd.read_parquet(out).equals(NEW) and _consistent(out) and checksum_path(out).exists()
    assert not list(tmp_path.glob(".*.tmp"))


@pytest.mark.parametrize("k", [3])  # after the first table's rename (2 removals, 1 rename): the old partner
def test_a_pair_from_two_runs_is_named_and_set_aside(tmp_path, monkeypatch, k):
    """Case 2: a run stopped between its two tables left the new --out beside the old --state-out.
    Each table names its run: the pair is refused by run_problem and set aside before a workflow run."""
    out, state = tmp_path / "runs" / "o.parquet", tmp_path / "runs" / "s.parquet"
    first = write_run({out: OLD, state: OLD_STATE})
    assert run_problem({"--out": out, "--state-out": state}) is None
    _stop_at(monkeypatch, k)
    with pytest.raises(Killed):
        write_run({out: NEW, state: NEW_STATE})
    monkeypatch.undo()
    assert pd.read_parquet(out).equals(NEW) and pd.read_parquet(state).equals(OLD_STATE)  # the mix
    problem = run_problem({"--out": out, "--state-out": state})
    assert f"--state-out {state} (run {first[:12]})" in problem and "tables of different runs" in problem
    lines = []
    moved = set_aside_corrupt(tmp_path, report=lines.append)
    assert sorted(moved) == [out, state] and len(lines) == 2 and "from another run" in lines[0]
    assert (out.parent / ("o.parquet" + CORRUPT_SUFFIX)).exists() and not out.exists() and not state.exists()


def test_a_runs_tables_share_an_id_that_depends_only_on_their_content(tmp_path):
    """Case 2: equal tables are still equal bytes (the id is a digest of the contents); a table
    written alone names no run, and a partner without a run id is another run."""
    a = write_run({tmp_path / "a.parquet": OLD, tmp_path / "sa.parquet": OLD_STATE})
    b = write_run({tmp_path / "b" / "a.parquet": OLD, tmp_path / "b" / "sa.parquet": OLD_STATE})
    assert a == b and (tmp_path / "a.parquet").read_bytes() == (tmp_path / "b" / "a.parquet").read_bytes()
    c = write_run({tmp_path / "c.parquet": OLD, tmp_path / "sc.parquet": NEW_STATE})
    assert c != a
    meta = pq.read_schema(tmp_path / "c.parquet").metadata
    assert c in meta[io.RUN_KEY].decode() and "sc.parquet" in meta[io.RUN_KEY].decode()
    write_parquet(OLD_STATE, tmp_path / "sc.parquet")  # an older version's state: no run id
    assert "(no run id)" in run_problem({"--out": tmp_path / "c.parquet", "--state-out": tmp_path / "sc.parquet"})
    assert set_aside_corrupt(tmp_path, report=lambda line: None) == [tmp_path / "c.parquet"]
    assert (tmp_path / "a.parquet").exists()  # a whole pair is left alone


def test_only_this_tables_stale_temporaries_are_removed(tmp_path):
    """Case 3: the next write of a table removes its own and its checksum's temporaries, as
    mkstemp names them, and not those of a table whose name begins with its own."""
    target = tmp_path / "t.parquet"
    stale = [tmp_path / ".t.parquet.k2_x9abc.tmp", tmp_path / ".t.parquet.sha256.0aq7_zzz.tmp"]
    others = [tmp_path / ".t.parquet.v2.parquet.ab12cd34.tmp", tmp_path / ".t.parquet.b.ab12cd34.tmp"]
    for f in [*stale, *others]:
        f.write_bytes(b"half a table")
    write_parquet(OLD, target)
    assert not any(f.exists() for f in stale) and all(f.exists() for f in others)


def _default_signals() -> None:
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, signal.SIG_DFL)


def _simulate(*args):
    return [sys.executable, "-m", "particle_entropy", "simulate", "--method", "mtpt", *args]


@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_sigint_and_sigterm_end_the_cli_with_one_line_and_no_temporary(tmp_path, sig, code):
    """Case 3: SIGINT printed a traceback (exit -2); SIGTERM ended silently (exit -15)."""
    out, state = tmp_path / "o.parquet", tmp_path / "s.parquet"
    args = _simulate("--n", "10000", "--t-final", "1000", "--out", str(out), "--state-out", str(state))
    # the child starts with the default dispositions whatever this process inherited (a shell that
    # starts a job in the background ignores SIGINT in it, and an ignored signal stays ignored)
    proc = subprocess.Popen(args, stderr=subprocess.PIPE, text=True, preexec_fn=_default_signals)
    first = proc.stderr.readline()  # the first progress line: the run has started
    proc.send_signal(sig)
    rest = proc.stderr.read()
    proc.wait(timeout=60)
    proc.stderr.close()
    assert first and proc.returncode == code
    name = signal.Signals(sig).name
    assert rest == f"simulate: stopped by {name}; nothing written (--out and --state-out as they were)\n"
    assert list(tmp_path.iterdir()) == []


@pytest.fixture
def no_run(monkeypatch):
    """The simulation itself, made to fail: a refusal must come before it."""
    import particle_entropy.models.simulate as simulate

    def run(*args, **kwargs):
        raise AssertionError("the run started")

    monkeypatch.setattr(simulate, "run", run)


def _refused(capsys, *args) -> str:
    from particle_entropy.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["simulate", "--method", "mtpt", "--n", "20", "--t-final", "1", "--quiet", *args])
    err = capsys.readouterr().err.strip().splitlines()
    assert stop.value.code == 2 and "Traceback" not in err[-1]
    return err[-1]


def test_an_out_name_over_255_bytes_is_refused_before_the_run(tmp_path, capsys, no_run):
    """Case 4: a 308-byte name raised OSError "File name too long" (a stat before the length check)."""
    out = tmp_path / ("x" * 300 + ".parquet")
    err = _refused(capsys, "--out", str(out))
    assert f"--out: {out}: a name of 308 bytes; at most 248 here" in err
    folder = tmp_path / ("d" * 256) / "o.parquet"
    err = _refused(capsys, "--out", str(tmp_path / "o.parquet"), "--state-out", str(folder))
    assert f"--state-out: {folder}: a folder name of 256 bytes; at most 255 here" in err
    assert list(tmp_path.iterdir()) == []


def test_an_out_whose_checksum_path_is_a_folder_is_refused_before_the_run(tmp_path, capsys, no_run):
    """Case 4: x.parquet.sha256 a folder failed after the whole run, leaving x.parquet without a checksum."""
    (tmp_path / "x.parquet.sha256").mkdir()
    err = _refused(capsys, "--out", str(tmp_path / "x.parquet"))
    assert f"--out: {tmp_path / 'x.parquet'}: {tmp_path / 'x.parquet.sha256'} is a directory" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.parquet.sha256"]


@pytest.mark.parametrize("where", ["loop/o.parquet", "loop"])
def test_an_out_through_a_loop_of_links_is_refused_before_the_run(tmp_path, capsys, no_run, where):
    """Case 4: --out loop/o.parquet (loop -> loop) failed after the run (mkdir: File exists), and
    --out loop replaced the link with the table."""
    (tmp_path / "loop").symlink_to("loop")
    err = _refused(capsys, "--out", str(tmp_path / "o2.parquet"), "--state-out", str(tmp_path / where))
    assert f"--state-out: {tmp_path / where}: {tmp_path / 'loop'} is a loop of symbolic links" in err
    assert (tmp_path / "loop").is_symlink() and sorted(p.name for p in tmp_path.iterdir()) == ["loop"]
