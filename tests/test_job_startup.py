"""A simulation job loads kernels compiled ahead of time (numerics/compiled.py) and so imports
neither numba nor what numba pulls in (scipy), nor pandas; its kernels give the JIT's bits."""

from __future__ import annotations

import json
import multiprocessing
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

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


def test_a_module_built_for_another_target_is_refused(kernels, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    for f in kernels.iterdir():
        (other / f.name).write_bytes(f.read_bytes())
    (other / compiled.TARGET_FILE).write_text((kernels / compiled.TARGET_FILE).read_text().replace("cpu ", "cpu x"))
    code = f"from particle_entropy.numerics import compiled; print(compiled.use({str(other)!r}))"
    res = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(LIB)}, capture_output=True)
    assert res.stdout.decode().strip() == "False" and b"other code, numba, CPU" in res.stderr


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
@pytest.fixture
def fake_build(tmp_path, monkeypatch):
    """build() replaced by one that writes a stand-in module for this target; the cache in tmp_path."""
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "cache"))
    builds = []

    def build(folder):
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{compiled.MODULE}.so").write_bytes(b"a module")
        (folder / compiled.TARGET_FILE).write_text(compiled.target())
        builds.append(folder)

    monkeypatch.setattr(compiled, "build", build)
    return builds


def test_a_second_working_directory_copies_the_module_the_first_built(tmp_path, fake_build):
    assert compiled.provide(tmp_path / "a" / "kernels") == "built"
    assert compiled.provide(tmp_path / "b" / "kernels") == "copied"
    assert fake_build == [tmp_path / "a" / "kernels"]  # compiled once on this machine
    for name in (f"{compiled.MODULE}.so", compiled.TARGET_FILE):
        assert (tmp_path / "b" / "kernels" / name).read_bytes() == (tmp_path / "a" / "kernels" / name).read_bytes()
    assert not list((tmp_path / "cache").glob(".*.tmp"))  # published whole, nothing left half-written


def test_a_cached_module_of_another_target_is_not_taken(tmp_path, fake_build):
    cache = compiled.cache_folder()
    cache.mkdir(parents=True)
    (cache / f"{compiled.MODULE}.so").write_bytes(b"old")
    (cache / compiled.TARGET_FILE).write_text("code another\n")
    assert compiled.provide(tmp_path / "a") == "built"
    assert (tmp_path / "a" / f"{compiled.MODULE}.so").read_bytes() == b"a module"


def test_an_empty_cache_setting_keeps_no_copy(tmp_path, fake_build, monkeypatch):
    monkeypatch.setenv(compiled.CACHE_ENV, "")
    assert compiled.cache_folder() is None
    assert [compiled.provide(tmp_path / d) for d in "ab"] == ["built", "built"]


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
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{compiled.MODULE}.so").write_bytes(b"a module")
        (folder / compiled.TARGET_FILE).write_text(compiled.target())

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
    (half / f"{compiled.MODULE}.so").write_bytes(b"cut sh")  # killed before its target was written
    assert compiled.take(root)
    assert len(_builds(counted_build)) == 1 and (half / f"{compiled.MODULE}.so").read_bytes() == b"a module"
    assert compiled.take(root) and len(_builds(counted_build)) == 1  # then taken as it is


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
