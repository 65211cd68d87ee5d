"""A simulation job loads kernels compiled ahead of time (numerics/compiled.py) and so imports
neither numba nor what numba pulls in (scipy), nor pandas; its kernels give the JIT's bits."""

from __future__ import annotations

import hashlib
import importlib.machinery
import json
import multiprocessing
import os
import re
import shutil
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, TINY, run_snakemake

from particle_entropy.core.case import Case
from particle_entropy.numerics import compiled, gauss
from particle_entropy.pipeline.sweeps import run_settings

LIB = ROOT / "workflow" / "lib"
# the job script run as Snakemake runs it, with a stand-in `snakemake`; prints the modules it imported
JOB = """
import json, runpy, sys, types
w, settings, out, log = json.loads(sys.argv[1])
class Wildcards(dict):
    __getattr__ = dict.__getitem__
snakemake = types.SimpleNamespace(wildcards=Wildcards(w), params=types.SimpleNamespace(settings=settings),
    output=[out], log=[log])
runpy.run_path(sys.argv[2], init_globals={"snakemake": snakemake}, run_name="__main__")
print(json.dumps(sorted(sys.modules)))
"""
CASES = [
    {"method": "pt", "kernel": "bins"},
    {"method": "pt", "kernel": "adaptive"},
    {"method": "mtpt", "kernel": "collision"},
    {"method": "mtpt", "kernel": "sph", "eta": 0.1},
    {"method": "fd", "kernel": "implicit"},
]
# the authors' loop (registry.SCHEME_RECORDS[...].sequential), in each arithmetic
SEQUENTIAL = [
    ({"method": "mtpt", "kernel": "sph", "preset": "authors"}, "fused"),
    ({"method": "mtpt", "kernel": "collision", "scheme": "sequential_symnorm"}, "exact"),
]


@pytest.fixture(scope="module")
def kernels(tmp_path_factory):
    folder = tmp_path_factory.mktemp("kernels")
    compiled.provide(folder)  # built, or copied from this machine's cache of this very target
    return folder


def _job(
    spec: dict, kernels: Path, tmp_path: Path, kind: str = "runs", n: int = 30, arithmetic: str = "fused"
) -> tuple[set, str]:
    case = Case.from_spec(spec, n)
    # t_final 10: FD n = 30 resolves the plume (dx = 0.4 below its dilution index 0.58: RunConfig.check)
    config = {"physics": {"t_final": 10.0}, "time": {"dt0": 0.01, "fixed_dt": 0.1, "fd_dt": 0.05}}
    config["numerics"] = {"loop_arithmetic": arithmetic}
    w = {**case.wildcards(), "kind": kind, "first": "0", "last": "1"}
    log = tmp_path / "job.log"
    arg = json.dumps([w, run_settings(case, config), str(tmp_path / "t.parquet"), str(log)])
    # the job takes the kernels of its working directory (compiled.take): these, or a record that
    # they could not be built, so that it runs the JIT rather than build them
    here = tmp_path / "work" / compiled.kernels_folder()
    here.parent.mkdir(parents=True, exist_ok=True)
    if kernels.is_dir():
        shutil.copytree(kernels, here, dirs_exist_ok=True)
    else:
        Path(str(here) + compiled.FAILED_SUFFIX).write_text("no compiler\n")
    env = {**os.environ, "PYTHONPATH": str(LIB)}
    script = str(ROOT / "workflow" / "scripts" / "simulate.py")
    res = subprocess.run(
        [sys.executable, "-c", JOB, arg, script],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        cwd=here.parents[2],
    )
    return set(json.loads(res.stdout.splitlines()[-1])), log.read_text()


@pytest.mark.parametrize("spec", CASES, ids=lambda s: f"{s['method']}-{s['kernel']}")
def test_a_simulation_job_imports_neither_numba_nor_scipy_nor_pandas(spec, kernels, tmp_path):
    for kind in ("runs", "snapshots"):
        modules, log = _job(spec, kernels, tmp_path, kind)
        assert "JIT" not in log, log  # the compiled module was taken
        heavy = {m.split(".")[0] for m in modules} & {"numba", "llvmlite", "scipy", "pandas"}
        assert not heavy, (spec, kind, heavy)


@pytest.mark.parametrize("spec, arithmetic", SEQUENTIAL, ids=["authors-fused", "sequential_symnorm-exact"])
def test_a_job_of_the_authors_loop_imports_neither_numba_nor_scipy_nor_pandas(spec, arithmetic, kernels, tmp_path):
    modules, log = _job(spec, kernels, tmp_path, n=100, arithmetic=arithmetic)
    assert "JIT" not in log, log
    assert "particle_entropy.numerics.sequential" in modules  # the loop ran
    heavy = {m.split(".")[0] for m in modules} & {"numba", "llvmlite", "scipy", "pandas"}
    assert not heavy, (spec, arithmetic, heavy)


def test_without_its_module_a_job_runs_the_jit(tmp_path):
    modules, log = _job(CASES[2], tmp_path / "none", tmp_path)
    assert "numba's JIT runs them" in log and "numba" in modules


def _use(folder: Path, prelude: str = "") -> tuple[bool, str]:
    """``compiled.use(folder)`` in a fresh process (after ``prelude``) -> (taken, its stderr)."""
    code = f"from particle_entropy.numerics import compiled\n{prelude}\nprint(compiled.use({str(folder)!r}))"
    res = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(LIB)}, capture_output=True)
    assert res.returncode == 0, res.stderr.decode()[-3000:]
    return res.stdout.decode().split()[-1] == "True", res.stderr.decode()


def _copy(kernels: Path, to: Path) -> tuple[Path, dict]:
    """A copy of the built module's folder -> (the copy's module, its record)."""
    to.mkdir()
    for f in kernels.iterdir():
        (to / f.name).write_bytes(f.read_bytes())
    record = json.loads((to / compiled.RECORD).read_text())
    return to / record["module"], record


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def test_a_module_built_for_another_target_is_refused(kernels, tmp_path):
    _, record = _copy(kernels, tmp_path / "other")
    record["target"] = record["target"].replace("cpu ", "cpu x")
    (tmp_path / "other" / compiled.RECORD).write_text(json.dumps(record))
    taken, err = _use(tmp_path / "other")
    assert not taken and "other code, numba, CPU" in err


def test_a_planted_file_beside_the_module_is_never_run(kernels, tmp_path):
    """Only the file the build recorded is loaded: a .py named like the module (it sorts first)
    is never executed, in the run's folder or the cache (provide copies only the module)."""
    _copy(kernels, tmp_path / "k")
    marker = tmp_path / "planted-code-ran"
    (tmp_path / "k" / f"{compiled.MODULE}.a.py").write_text(f"open({str(marker)!r}, 'w').write('x')\n")
    taken, err = _use(tmp_path / "k")
    assert taken and not marker.exists(), err


def test_a_foreign_module_under_a_copied_record_is_refused(kernels, tmp_path):
    """A module of other bytes (here: the real one, one byte longer, which still loads) under this
    build's record fails the SHA-256 the record binds to this target; and a record forged to match
    it is caught by the code key the module carries (IDENTITY), checked after loading."""
    module, record = _copy(kernels, tmp_path / "k")
    module.write_bytes(module.read_bytes() + b"\0")
    taken, err = _use(tmp_path / "k")
    assert not taken and "fails the SHA-256" in err and "JIT runs them" in err
    # a consistent record of a module built from other code: code_key() here is another one
    record["sha256"] = _sha256(module.read_bytes())
    (tmp_path / "k" / compiled.RECORD).write_text(json.dumps(record))
    assert _use(tmp_path / "k")[0]  # a sound record: taken
    other = "here = compiled.target()\ncompiled.code_key = lambda: 'f' * 64\ncompiled.target = lambda: here"
    taken, err = _use(tmp_path / "k", other)
    assert not taken and "built from other code" in err


def test_a_module_that_does_not_import_leaves_the_jit(kernels, tmp_path):
    module, record = _copy(kernels, tmp_path / "k")
    module.write_bytes(os.urandom(4096))  # and a record that matches it: only the import fails
    (tmp_path / "k" / compiled.RECORD).write_text(json.dumps({**record, "sha256": _sha256(module.read_bytes())}))
    taken, err = _use(tmp_path / "k")
    assert not taken and "does not load (ImportError" in err and len(err.strip().splitlines()) == 1, err


def test_a_truncated_module_of_the_run_is_replaced_whole_by_the_next_job(kernels, tmp_path):
    module, record = _copy(kernels, tmp_path / "k")
    module.write_bytes(module.read_bytes()[:100_000])
    modules, log = _job(CASES[2], tmp_path / "k", tmp_path)  # raises unless the job succeeds
    assert "the compiled kernels into" in log and "JIT" not in log, log  # provided again, then taken
    assert not {m.split(".")[0] for m in modules} & {"numba", "llvmlite"}
    here = tmp_path / "work" / compiled.kernels_folder() / record["module"]
    assert _sha256(here.read_bytes()) == record["sha256"]  # whole again
    assert (tmp_path / "t.parquet").stat().st_size > 0


def test_a_module_that_does_not_load_leaves_the_jit_and_the_job_succeeds(kernels, tmp_path):
    module, record = _copy(kernels, tmp_path / "k")
    junk = b"not an ELF file"  # a broken build, recorded as it was: the digest holds, the import fails
    module.write_bytes(junk)
    (module.parent / compiled.RECORD).write_text(json.dumps({**record, "sha256": _sha256(junk)}))
    modules, log = _job(CASES[2], tmp_path / "k", tmp_path)
    assert "does not load" in log and "numba's JIT runs them" in log and "numba" in modules, log
    assert (tmp_path / "t.parquet").stat().st_size > 0


def test_the_compiled_kernels_give_the_jits_bits(kernels):
    """Every exported kernel, on inputs of several sizes and widths, against numba's JIT."""
    code = f"""
import numpy as np
from particle_entropy.numerics import compiled, gauss
jit = compiled._jit()
assert compiled.use({str(kernels)!r})
aot = compiled.kernels()
rng = np.random.default_rng(7)
def same(a, b):
    a, b = (a if isinstance(a, tuple) else (a,)), (b if isinstance(b, tuple) else (b,))
    assert all(np.asarray(u).tobytes() == np.asarray(v).tobytes() for u, v in zip(a, b, strict=True))
for n in (2, 37, 3000):
    x = np.sort(rng.normal(0, 1, n)); q = rng.random((3, n)); y = np.sort(rng.uniform(-2, 2, n // 2 + 1))
    for s in (1e-3, 0.3):
        r = 9 * s
        same(aot.direct_symmetric(x, q, s, r), jit.direct_symmetric(x, q, s, r))
        same(aot.direct(y, x, q, s, r, False), jit.direct(y, x, q, s, r, False))
        for ratio in gauss.FGT_BOX_RATIOS:
            w = gauss.fgt_box_width(s, ratio); t = gauss.fgt_offset_terms(s, r, w)
            same(aot.fgt(y, x, q, s, w, t), jit.fgt(y, x, q, s, w, t))
        c, A = jit.taylor_moments(x, q, s, float(x[0]), gauss.P_TERMS)
        same(aot.taylor_moments(x, q, s, float(x[0]), gauss.P_TERMS), (c, A))
        same(aot.taylor_eval(y, c, A, s, r), jit.taylor_eval(y, c, A, s, r))
        rr, m = rng.random(n) + 1, rng.random(n)
        inv, qq = jit.weights(rr, m)
        same(aot.weights(rr, m), (inv, qq))
        same(aot.offdiag(q[0], inv, m, 0.4), jit.offdiag(q[0], inv, m, 0.4))
        same(aot.update(m, q[1], 0.3, q[0], q[2], inv), jit.update(m, q[1], 0.3, q[0], q[2], inv))
    f = jit.thomas_factor(n, 0.7)
    same(aot.thomas_factor(n, 0.7), f)
    d = rng.random(n)
    same(aot.thomas_solve(f[0], f[1], 0.7, d), jit.thomas_solve(f[0], f[1], 0.7, d))
    if n > 2:
        from scipy.linalg import lapack
        g = lapack.dgttrf(np.full(n - 1, -3.6), np.full(n, 1.8), np.full(n - 1, 2.8))[:5]  # pivots
        same(aot.gt_solve(*g, d), jit.gt_solve(*g, d))
    for p in (0.75, -0.3):
        same(aot.tvd_advect(d, p), jit.tvd_advect(d, p))
print("ok")
"""
    res = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(LIB)}, capture_output=True)
    assert res.returncode == 0 and res.stdout.decode().strip() == "ok", res.stderr.decode()[-3000:]


def test_every_kernel_is_exported_and_reached_through_kernels():
    ns = compiled._jit()
    assert set(vars(ns)) == set(compiled.EXPORTS)
    x = np.linspace(-1.0, 1.0, 20)
    assert gauss.gauss_transform(x, x, np.ones(20), 0.3).shape == (20,)


def test_the_compiled_loop_gives_the_jits_bits(kernels):
    """Both forms of the authors' loop (sequential_kernels._sweep, _sweep_fma) on states of several
    sizes, cut-offs, weights (symnorm), clipping and beta (> 1.9: _sweep_fma's other path; negative
    masses: clipping acts), with the arguments sequential_transfer passes, against numba's JIT."""
    code = f"""
import numpy as np
from particle_entropy.numerics import compiled
jit = compiled._jit()
assert compiled.use({str(kernels)!r})
aot = compiled.kernels()
rng = np.random.default_rng(11)
for n in (1, 2, 65, 3000, 8000):
    x = np.sort(rng.uniform(-1, 1, n))
    label = rng.permutation(n).astype(np.int64)
    for negative in (False, True):
        m = rng.exponential(1.0, n) * (rng.random(n) < 0.5)
        if negative:
            m[rng.random(n) < 0.1] *= -1.0
        for sigma, truncation in ((0.002, 3.0), (0.02, 1.0), (0.01, 9.0)):
            for beta in (0.5, 1.0, 1.95, 2.5):
                for symnorm, clip in ((False, True), (True, True), (False, False)):
                    args = (label, sigma, truncation * sigma, beta, np.uint64(rng.integers(0, 2**63)), symnorm, clip)
                    for form in ("_sweep", "_sweep_fma"):
                        a = getattr(aot, form)(x, m.copy(), *args)
                        b = getattr(jit, form)(x, m.copy(), *args)
                        assert a.tobytes() == b.tobytes(), (form, n, negative, sigma, truncation, beta, symnorm, clip)
print("ok")
"""
    res = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(LIB)}, capture_output=True)
    assert res.returncode == 0 and res.stdout.decode().strip() == "ok", res.stderr.decode()[-3000:]


# ------------------------------------------------------------------ the machine-wide cache
NAME = compiled.MODULE + importlib.machinery.EXTENSION_SUFFIXES[0]  # the module's one file name


def _stand_in(folder: Path, data: bytes = b"a module", digest: str | None = None) -> None:
    """A stand-in module and its record (SHA-256 ``digest``, else the data's) for this target."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / NAME).write_bytes(data)
    record = {"module": NAME, "sha256": digest or _sha256(data), "target": compiled.target()}
    (folder / compiled.RECORD).write_text(json.dumps(record))


@pytest.fixture
def fake_build(tmp_path, monkeypatch):
    """build() replaced by one that writes a stand-in module for this target; the cache in tmp_path."""
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "cache"))
    builds = []

    def build(folder):
        _stand_in(Path(folder))
        builds.append(Path(folder))

    monkeypatch.setattr(compiled, "build", build)
    return builds


def _cached(data: bytes, mode: int = 0o700) -> Path:
    """The cache folder of this target, this user's, holding a stand-in of ``data``."""
    cache = compiled.cache_folder()
    _stand_in(cache, data)
    cache.chmod(mode)
    return cache


def test_a_second_working_directory_copies_the_module_the_first_built(tmp_path, fake_build):
    assert compiled.provide(tmp_path / "a" / "kernels") == "built"
    assert compiled.provide(tmp_path / "b" / "kernels") == "copied"
    assert fake_build == [tmp_path / "a" / "kernels"]  # compiled once on this machine
    for name in (NAME, compiled.RECORD):
        assert (tmp_path / "b" / "kernels" / name).read_bytes() == (tmp_path / "a" / "kernels" / name).read_bytes()
    assert not list((tmp_path / "cache").glob(".*.tmp"))  # published whole, nothing left half-written


def test_a_cached_module_of_another_target_is_not_taken(tmp_path, fake_build):
    cache = _cached(b"old")
    record = json.loads((cache / compiled.RECORD).read_text())
    (cache / compiled.RECORD).write_text(json.dumps({**record, "target": "code another\n"}))
    assert compiled.provide(tmp_path / "a") == "built"
    assert (tmp_path / "a" / NAME).read_bytes() == b"a module"


def test_an_empty_cache_setting_keeps_no_copy(tmp_path, fake_build, monkeypatch):
    monkeypatch.setenv(compiled.CACHE_ENV, "")
    assert compiled.cache_folder() is None
    assert [compiled.provide(tmp_path / d) for d in "ab"] == ["built", "built"]


@pytest.mark.parametrize("bad", [b"", b"random bytes \x00\xff", b"a modu"], ids=["empty", "random", "truncated"])
def test_a_corrupt_cached_module_is_rebuilt_and_replaced_never_copied(tmp_path, fake_build, capsys, bad):
    cache = _cached(b"a module")
    (cache / NAME).write_bytes(bad)  # decayed after its record was written
    assert compiled.provide(tmp_path / "a") == "built"
    assert (tmp_path / "a" / NAME).read_bytes() == b"a module"
    assert "fails the SHA-256" in capsys.readouterr().err
    assert (cache / NAME).read_bytes() == b"a module"  # repaired: the next directory copies it
    assert compiled.provide(tmp_path / "b") == "copied" and len(fake_build) == 1


def test_only_the_recorded_module_is_copied_from_the_cache(tmp_path, fake_build):
    cache = _cached(b"a module")
    (cache / f"{compiled.MODULE}.a.py").write_text("raise SystemExit('planted')\n")
    assert compiled.provide(tmp_path / "a") == "copied"
    assert sorted(f.name for f in (tmp_path / "a").iterdir()) == sorted([NAME, compiled.RECORD])


def test_a_cache_folder_of_another_user_is_not_trusted(tmp_path, fake_build, monkeypatch, capsys):
    cache = _cached(b"their module")
    monkeypatch.setattr(os, "getuid", lambda: os.stat(cache).st_uid + 1)  # the folder is another's
    assert compiled.provide(tmp_path / "a") == "built"
    assert (tmp_path / "a" / NAME).read_bytes() == b"a module"
    err = capsys.readouterr().err
    assert "belongs to uid" in err and "left the cache alone" in err and len(err.splitlines()) == 1
    assert (cache / NAME).read_bytes() == b"their module"  # neither read nor replaced


def test_a_cache_folder_others_can_write_is_not_read_but_replaced(tmp_path, fake_build, capsys):
    cache = _cached(b"maybe someone else's", mode=0o770)
    assert compiled.provide(tmp_path / "a") == "built"
    assert (tmp_path / "a" / NAME).read_bytes() == b"a module"
    assert "can be written by others (mode 770)" in capsys.readouterr().err
    assert (cache / NAME).read_bytes() == b"a module" and stat.S_IMODE(cache.stat().st_mode) == 0o700


def test_a_group_writable_module_file_is_not_read(tmp_path, fake_build, capsys):
    cache = _cached(b"maybe someone else's")
    (cache / NAME).chmod(0o664)
    assert compiled.provide(tmp_path / "a") == "built"
    assert f"its {NAME} can be written by others" in capsys.readouterr().err


def test_a_cache_folder_that_is_a_link_is_not_followed(tmp_path, fake_build, capsys):
    elsewhere = tmp_path / "elsewhere"
    _stand_in(elsewhere, b"their module")
    elsewhere.chmod(0o700)
    cache = compiled.cache_folder()
    cache.parent.mkdir(parents=True)
    cache.symlink_to(elsewhere)
    assert compiled.provide(tmp_path / "a") == "built"
    assert "is a symbolic link" in capsys.readouterr().err
    assert cache.is_symlink() and (elsewhere / NAME).read_bytes() == b"their module"


def test_cache_folders_are_private_whatever_the_umask(tmp_path, fake_build):
    old = os.umask(0o002)
    try:
        compiled.provide(tmp_path / "a")
    finally:
        os.umask(old)
    cache = compiled.cache_folder()
    for folder in (cache.parent, cache):
        assert stat.S_IMODE(folder.stat().st_mode) == 0o700, folder
    for f in cache.iterdir():
        assert stat.S_IMODE(f.stat().st_mode) == 0o600, f


# ------------------------------------------------------------------ the workflow's kernels
RUN = "results/runs/fd/implicit/n~{n}/eta~1/trunc~none/growth~1/scheme~symmetric/grid~exact/seeds~0-0.parquet"


def test_another_target_rebuilds_the_kernels_and_reruns_no_simulation(kernels, tmp_path, monkeypatch):
    """Another NUMBA_OPT, as another CPU or numba, is another target(): the next job to run takes
    its kernels, a finished simulation does not rerun (the module gives the JIT's bits: the target
    is no part of a run's identity), and a simulation still to make is made in the same run."""
    other = "1" if os.environ.get("NUMBA_OPT") == "0" else "0"
    record = json.loads((kernels / compiled.RECORD).read_text())
    for opt in (os.environ.get("NUMBA_OPT"), other):  # the cache holds the module for both targets
        with monkeypatch.context() as m:
            m.delenv("NUMBA_OPT", raising=False) if opt is None else m.setenv("NUMBA_OPT", opt)
            cache, here = tmp_path / "cache" / compiled.target_key(), compiled.target()
        cache.mkdir(parents=True, mode=0o700)
        for f in kernels.iterdir():
            (cache / f.name).write_bytes(f.read_bytes())
        (cache / compiled.RECORD).write_text(json.dumps({**record, "target": here}))
        for f in cache.iterdir():
            f.chmod(0o600)
    env = {**os.environ, compiled.CACHE_ENV: str(tmp_path / "cache")}
    work, first, second = tmp_path / "work", RUN.format(n=30), RUN.format(n=60)
    run_snakemake(work, first, configfile=TINY, env=env)
    log = next((work / "logs" / "simulate").rglob("*.log")).read_text()
    assert "copied the compiled kernels" in log and "JIT" not in log

    def plan(env):
        proc = run_snakemake(work, first, dry_run=True, configfile=TINY, env=env)
        return set(re.findall(r"^\s*(?:local)?(?:rule|checkpoint) (\w+):", proc.stdout + proc.stderr, flags=re.M))

    assert plan(env) == set()
    env = {**env, "NUMBA_OPT": other}
    assert plan(env) == set()
    made = (work / first).stat().st_mtime_ns
    run_snakemake(work, first, second, configfile=TINY, env=env)
    assert (work / second).exists() and (work / first).stat().st_mtime_ns == made
    with monkeypatch.context() as m:
        m.setenv("NUMBA_OPT", other)
        folder = work / compiled.kernels_folder()
    assert json.loads((folder / compiled.RECORD).read_text())["target"].endswith(f"NUMBA_OPT={other}\n")
    log = next(p for p in (work / "logs" / "simulate").rglob("*.log") if "n~60" in str(p)).read_text()
    assert "copied the compiled kernels" in log and "JIT" not in log


# ------------------------------------------------------------------ provided by the first job
@pytest.fixture
def counted_build(tmp_path, monkeypatch):
    """build() replaced by a slow stand-in that counts its calls in a file (forked jobs share it);
    use() by one that only says whether the folder is complete (a stand-in module cannot load)."""
    monkeypatch.setenv(compiled.CACHE_ENV, "")
    calls = tmp_path / "builds.txt"

    def build(folder):
        with open(calls, "a") as f:
            f.write(f"{folder}\n")
        time.sleep(0.5)  # long enough for a second job to arrive meanwhile
        _stand_in(Path(folder))

    monkeypatch.setattr(compiled, "build", build)
    monkeypatch.setattr(compiled, "use", lambda folder: compiled._complete(Path(folder)))
    return calls


def _builds(calls):
    return calls.read_text().splitlines() if calls.exists() else []


def test_jobs_that_start_together_build_the_kernels_once(tmp_path, counted_build):
    root = tmp_path / "results" / "kernels"
    fork = multiprocessing.get_context("fork")
    jobs = [fork.Process(target=compiled.take, args=(root,)) for _ in range(3)]
    for job in jobs:
        job.start()
    for job in jobs:
        job.join(30)
    assert [job.exitcode for job in jobs] == [0, 0, 0]
    assert len(_builds(counted_build)) == 1  # the others waited for the first, then took its module
    assert compiled._complete(Path(compiled.kernels_folder(str(root))))
    assert not list(root.glob(".*.tmp"))  # built aside and renamed into place


def test_a_kernels_folder_left_half_made_is_rebuilt(tmp_path, counted_build):
    root = tmp_path / "kernels"
    half = Path(compiled.kernels_folder(str(root)))
    half.mkdir(parents=True)
    killed = half.with_name(f".{half.name}.99999999.tmp")  # a job killed while it built
    killed.mkdir()
    (half / NAME).write_bytes(b"cut sh")  # killed before its record was written
    assert compiled.take(root)
    assert len(_builds(counted_build)) == 1 and (half / NAME).read_bytes() == b"a module"
    assert compiled.take(root) and len(_builds(counted_build)) == 1  # then taken as it is
    assert not killed.exists()  # what a killed build left is cleared by the next one


def test_a_failed_build_is_recorded_once_and_the_jobs_run_the_jit(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(compiled.CACHE_ENV, "")
    calls = []

    def build(folder):
        calls.append(folder)
        raise OSError("no C compiler")

    monkeypatch.setattr(compiled, "build", build)
    root = tmp_path / "kernels"
    assert not compiled.take(root) and not compiled.take(root)  # the JIT runs, the job goes on
    assert len(calls) == 1  # the second job read the record and did not try again
    err = capsys.readouterr().err
    assert "could not compile the kernels (OSError: no C compiler)" in err and "JIT" in err
    failed = Path(compiled.kernels_folder(str(root)) + compiled.FAILED_SUFFIX)
    assert "no C compiler" in failed.read_text()


def test_an_unknown_cpu_runs_the_jit_without_building(tmp_path, counted_build, monkeypatch):
    monkeypatch.setattr(compiled, "_cpu", lambda: None)  # no /proc/cpuinfo (macOS), or none of its fields
    assert not compiled.take(tmp_path / "kernels") and not compiled.take(tmp_path / "kernels")
    assert _builds(counted_build) == []  # a module built for no target could never be taken


def test_a_file_system_without_locks_still_provides_the_kernels(tmp_path, counted_build, monkeypatch, capsys):
    import errno

    def no_locks(fd, op):
        raise OSError(errno.ENOSYS, os.strerror(errno.ENOSYS))

    monkeypatch.setattr("fcntl.flock", no_locks)
    assert compiled.take(tmp_path / "kernels")  # built aside and renamed, not a failed job
    assert len(_builds(counted_build)) == 1 and "no file lock" in capsys.readouterr().err


def test_the_run_s_kernels_folders_are_not_group_writable_whatever_the_umask(tmp_path, counted_build):
    old = os.umask(0o002)
    try:
        assert compiled.take(tmp_path / "kernels")
    finally:
        os.umask(old)
    folder = Path(compiled.kernels_folder(str(tmp_path / "kernels")))
    for f in (folder.parent, folder):
        assert not stat.S_IMODE(f.stat().st_mode) & 0o022, f


def test_no_home_folder_keeps_no_cache_copy(monkeypatch):
    monkeypatch.delenv(compiled.CACHE_ENV, raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)

    def homeless():
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.setattr(Path, "home", staticmethod(homeless))
    assert compiled.cache_folder() is None
