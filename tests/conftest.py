"""Shared references, paths and fixtures for the particle_entropy test suite.

Every reference here is built from the paper's formulas with plain dense numpy, independently
of the library code it is compared with. Paths are module constants, imported as
``from conftest import ROOT, TINY`` (pytest puts tests/ on sys.path), so that module-level code
such as parametrize lists can use them; what a test may change is a fixture, fresh for each test.
"""

from __future__ import annotations

import math
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]  # the checkout: Snakefile, config.yaml, workflow/
TINY = ROOT / "tests" / "data" / "tiny_config.yaml"  # the small config of the workflow tests


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


# --------------------------------------------------------------------------- fixtures
@pytest.fixture
def rng():
    return np.random.default_rng(20200101)


@pytest.fixture
def tiny_config() -> dict:
    """The tiny config, parsed afresh for each test: a test may edit it."""
    return yaml.safe_load(TINY.read_text())
