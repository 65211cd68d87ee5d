"""The random-walk step of the Ito equation (models/walk.py): the 1-D walk of Section 2 to the bit,
and in d dimensions the covariance 2 D dt and the mean (v + a) dt of a step."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import no_runtime_warnings

from particle_entropy.models.walk import walk

N = 200_000  # steps in the statistical checks
Z = 5.0  # their tolerance in standard errors (a fixed seed: a pass is reproducible)


@pytest.mark.parametrize("v", [0.0, 0.3, -1.5])
def test_one_d_walk_is_the_formula_to_the_bit(v):
    """d = 1 with a scalar D draws standard_normal(N) and adds sqrt(2 D dt) xi, after v dt when v != 0."""
    x = np.random.default_rng(1).uniform(-3.0, 3.0, 1000)
    D, dt = 0.37, 0.013
    got = walk(x, D, dt, np.random.default_rng(9), v)
    xi = np.random.default_rng(9).standard_normal(x.size)
    step = math.sqrt(2.0 * D * dt) * xi
    want = x + step if v == 0.0 else (x + v * dt) + step
    np.testing.assert_array_equal(got, want)
    # an (N, 1) column of the same positions takes the same draws and the same step
    np.testing.assert_array_equal(walk(x[:, None], D, dt, np.random.default_rng(9), v)[:, 0], want)


def test_one_d_walk_per_particle_D():
    x = np.zeros(5)
    D = np.array([0.0, 1.0, 2.0, 0.5, 4.0])
    got = walk(x, D, 0.1, np.random.default_rng(3))
    xi = np.random.default_rng(3).standard_normal(5)
    np.testing.assert_array_equal(got, np.sqrt(0.2 * D) * xi)
    assert got[0] == 0.0


def test_two_d_draws_one_row_per_direction():
    """The x components take the first N normals, y the next N: a shear walk's order."""
    pos = np.zeros((4, 2))
    got = walk(pos, np.array([1.0, 4.0]), 0.5, np.random.default_rng(5))
    xi = np.random.default_rng(5).standard_normal((2, 4))
    np.testing.assert_array_equal(got[:, 0], xi[0])
    np.testing.assert_array_equal(got[:, 1], 2.0 * xi[1])


def _check_covariance(steps: np.ndarray, want: np.ndarray) -> None:
    """Sample covariance of zero-mean Gaussian steps within Z standard errors of ``want``:
    Var(X_a X_b) = S_aa S_bb + S_ab^2."""
    n = steps.shape[0]
    got = steps.T @ steps / n
    se = np.sqrt((np.outer(np.diag(want), np.diag(want)) + want**2) / n)
    assert np.all(np.abs(got - want) < Z * se), (got, want, se)


def test_two_d_tensor_walk_has_covariance_two_D_dt():
    D = np.array([[2.0, 0.6], [0.6, 0.5]])
    dt = 0.01
    steps = walk(np.zeros((N, 2)), np.broadcast_to(D, (N, 2, 2)), dt, np.random.default_rng(11))
    _check_covariance(steps, 2.0 * D * dt)
    assert abs(np.corrcoef(steps.T)[0, 1] - 0.6 / math.sqrt(2.0 * 0.5)) < 0.01  # the tensor's own correlation


def test_three_d_per_particle_tensors_each_give_their_covariance():
    """Half the particles carry one tensor, half another (one of them singular): each half's steps
    have covariance 2 D dt of its own tensor."""
    a = np.array([[1.0, 0.2, -0.3], [0.2, 0.8, 0.1], [-0.3, 0.1, 0.6]])
    b = np.array([[0.3, 0.3, 0.0], [0.3, 0.3, 0.0], [0.0, 0.0, 2.0]])  # rank 2: no step along (1, -1, 0)
    tensors = np.concatenate([np.broadcast_to(a, (N, 3, 3)), np.broadcast_to(b, (N, 3, 3))])
    with no_runtime_warnings():
        steps = walk(np.zeros((2 * N, 3)), tensors, 0.5, np.random.default_rng(12))
    _check_covariance(steps[:N], a)
    _check_covariance(steps[N:], b)
    assert np.abs(steps[N:, 0] - steps[N:, 1]).max() < 1e-12


@pytest.mark.parametrize("form", ["scalar", "diagonal", "per-particle diagonals"])
def test_diagonal_forms_have_covariance_two_D_dt(form):
    diag = np.array([0.4, 3.0])
    D = {"scalar": 0.4, "diagonal": diag, "per-particle diagonals": np.broadcast_to(diag, (N, 2))}[form]
    want = 2.0 * np.diag([0.4, 0.4] if form == "scalar" else diag)
    _check_covariance(walk(np.zeros((N, 2)), D, 1.0, np.random.default_rng(13)), want)


def test_velocity_and_drift_move_the_mean():
    """Mean step (v + a) dt within Z standard errors sqrt(2 D dt / N)."""
    v, a, D, dt = np.array([1.0, -2.0]), np.array([0.0, 0.5]), 0.2, 0.1
    steps = walk(np.zeros((N, 2)), D, dt, np.random.default_rng(14), v, np.broadcast_to(a, (N, 2)))
    assert np.all(np.abs(steps.mean(axis=0) - (v + a) * dt) < Z * math.sqrt(2.0 * D * dt / N))


def test_zero_tensor_stays_put():
    with no_runtime_warnings():
        got = walk(np.ones((3, 2)), np.zeros((3, 2, 2)), 1.0, np.random.default_rng(0))
    np.testing.assert_array_equal(got, np.ones((3, 2)))


@pytest.mark.parametrize(
    "x, D",
    [
        (np.zeros((4, 2)), np.ones((4, 3, 3))),  # tensor of another d
        (np.zeros((4, 2)), np.ones(3)),  # diagonal of another d
        (np.zeros((4, 2)), np.ones((5, 2))),  # diagonals of another N
        (np.zeros((2, 2, 2)), 1.0),  # positions neither (N,) nor (N, d)
    ],
)
def test_shapes_that_do_not_fit_are_refused(x, D):
    with pytest.raises(ValueError):
        walk(x, D, 1.0, np.random.default_rng(0))
