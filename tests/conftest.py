"""Shared references, paths and fixtures for the particle_entropy test suite.

Every reference here is built from the paper's formulas with plain dense numpy, independently
of the library code it is compared with. Paths are module constants, imported as
``from conftest import ROOT, TINY`` (pytest puts tests/ on sys.path), so that module-level code
such as parametrize lists can use them; what a test may change is a fixture, fresh for each test.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]  # the checkout: Snakefile, config.yaml, workflow/
TINY = ROOT / "tests" / "data" / "tiny_config.yaml"  # the small config of the workflow tests
SNAKEFILE = ROOT / "Snakefile"


# --------------------------------------------------------------------------- dense references
def dense_kernel(y, x, sigma, truncation=None):
    """K[i, j] = exp(-(y_i - x_j)^2 / (2 sigma^2)); zero where |y_i - x_j| > truncation * sigma."""
    y = np.asarray(y, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    d = y[:, None] - x[None, :]
    arg = -(d * d) / (2.0 * sigma * sigma)
    # exp(arg) < 1e-304 is taken as 0 (it is far below round-off of any sum here); this only
    # avoids numpy's slow sub-normal path
    K = np.zeros_like(arg)
    keep = arg > -700.0
    K[keep] = np.exp(arg[keep])
    if truncation is not None:
        K[np.abs(d) > truncation * sigma] = 0.0
    return K


def dense_gauss(y, x, q, sigma, truncation=None):
    """Dense Gauss transform out[k, i] = sum_j K[i, j] q[k, j] (q 1-D or 2-D)."""
    K = dense_kernel(y, x, sigma, truncation)
    q = np.asarray(q, dtype=np.float64)
    return q @ K.T if q.ndim == 2 else K @ q


def dense_transfer_matrix(x, sigma, truncation=None):
    """Symmetrised transfer matrix of Section 4: average of row- and column-normalised W."""
    W = dense_kernel(x, x, sigma, truncation)
    r = W.sum(axis=1)
    rownorm = W / r[:, None]
    colnorm = W / r[None, :]
    return 0.5 * (rownorm + colnorm)


def dense_mass_update(P, m, beta, substeps=1):
    """Eq. 19 applied `substeps` times with beta / substeps: m <- m + b (P m - m rowsum(P))."""
    b = beta / substeps
    rowsum = P.sum(axis=1)
    for _ in range(substeps):
        m = m + b * (P @ m - m * rowsum)
    return m


def gaussian(x, D, t):
    """Exact solution of 1-D diffusion from a unit delta: N(0, 2 D t)."""
    var = 2.0 * D * t
    return np.exp(-x * x / (2.0 * var)) / math.sqrt(2.0 * math.pi * var)


def ensemble_stats(values):
    """(mean, standard error of the mean) of a 1-D sample."""
    v = np.asarray(values, dtype=np.float64)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size))


@contextmanager
def no_runtime_warnings():
    """Turn every RuntimeWarning (overflow, divide by zero, invalid value, ...) into an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
            yield


# --------------------------------------------------------------------------- the workflow
def snakemake_command(
    workdir=None, *args, snakefile=SNAKEFILE, dry_run=False, configfile=None, launcher=("-m", "snakemake")
) -> list[str]:
    """``python -m snakemake -s SNAKEFILE -d WORKDIR -j2 [-n] ARGS --configfile CONFIGFILE``.

    ``snakefile=None`` or ``workdir=None`` leaves out -s or -d: Snakemake then takes the Snakefile
    and config.yaml of the directory it runs in. ``launcher`` replaces ``-m snakemake`` with a
    script that runs Snakemake itself. --configfile comes last: it takes every following word
    as a file."""
    cmd = [sys.executable, *launcher]
    if snakefile is not None:
        cmd += ["-s", str(snakefile)]
    if workdir is not None:
        cmd += ["-d", str(workdir)]
    cmd.append("-j2")
    if dry_run:
        cmd.append("-n")
    cmd += [str(a) for a in args]
    if configfile is not None:
        cmd += ["--configfile", str(configfile)]
    return cmd


def run_snakemake(workdir=None, *args, check=True, cwd=None, env=None, preexec_fn=None, **options):
    """Runs ``snakemake_command(workdir, *args, **options)`` (in ``cwd``, with ``env``) and returns
    the finished process, its output as text; with ``check``, AssertionError unless it succeeded."""
    proc = subprocess.run(
        snakemake_command(workdir, *args, **options),
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        preexec_fn=preexec_fn,
    )
    if check and proc.returncode != 0:
        words = " ".join(map(str, args))
        raise AssertionError(f"snakemake {words} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


# --------------------------------------------------------------------------- fixtures
@pytest.fixture
def rng():
    return np.random.default_rng(20200101)


@pytest.fixture
def tiny_config() -> dict:
    """The tiny config, parsed afresh for each test: a test may edit it."""
    return yaml.safe_load(TINY.read_text())


@pytest.fixture
def workflow_copy(tmp_path) -> Path:
    """A copy of the workflow as a user clones it, at tmp_path / "repo" (returned): Snakefile,
    config.yaml, workflow/ (library, rules, scripts) and the tiny config at tests/data/. A test
    may edit it: Snakemake run with its Snakefile sees the copy's code, not the checkout's."""
    root = tmp_path / "repo"
    shutil.copytree(ROOT / "workflow", root / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("Snakefile", "config.yaml"):
        shutil.copy(ROOT / name, root / name)
    tiny = root / TINY.relative_to(ROOT)
    tiny.parent.mkdir(parents=True)
    shutil.copy(TINY, tiny)
    return root
