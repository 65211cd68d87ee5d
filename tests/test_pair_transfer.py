"""MTPT's transfer on a pair list with pair-averaged tensors (numerics/pair_transfer.py): Eqs. 16-18
with Eq. 17 in d dimensions against a dense N x N reference written from the equations."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from conftest import no_runtime_warnings

from particle_entropy.numerics import pair_transfer as pt
from particle_entropy.numerics.neighbours import pairs_within


def random_tensors(rng, n: int, d: int) -> np.ndarray:
    """n symmetric positive definite d x d tensors of varied size and orientation."""
    a = rng.normal(size=(n, d, d))
    return np.einsum("nij,nkj->nik", a, a) + 0.1 * np.eye(d)


def dense_reference(points, tensors, m, beta, dt, period):
    """Eq. 16 with P = (W / rowsum + W / colsum) / 2 (Eq. 18) and the full Eq. 17,
    W_ij = exp(-r^T D_ij^-1 r / (8 dt)) / sqrt(det(8 pi D_ij dt)), D_ij = (D_i + D_j) / 2."""
    n, d = points.shape
    W = np.empty((n, n))
    for i, j in itertools.product(range(n), repeat=2):
        dij = 0.5 * (tensors[i] + tensors[j])
        r = points[i] - points[j]
        for k, p in enumerate(period):
            if p:
                r[k] -= p * np.round(r[k] / p)
        W[i, j] = np.exp(-r @ np.linalg.solve(dij, r) / (8 * dt)) / np.sqrt(np.linalg.det(8 * np.pi * dt * dij))
    P = 0.5 * (W / W.sum(1)[:, None] + W / W.sum(0)[None, :])
    np.fill_diagonal(P, 0.0)
    return m + beta * (P @ m - m * P.sum(1))


def all_pairs(n: int) -> np.ndarray:
    return np.array([(i, j) for i in range(n) for j in range(i + 1, n)], dtype=np.int64)


@pytest.mark.parametrize("d, period", [(1, (None,)), (2, (None, None)), (2, (3.0, None)), (3, (2.0, None, 2.0))])
@pytest.mark.parametrize("form", ["tensors", "diagonals"])
def test_transfer_equals_the_dense_reference(d, period, form):
    rng = np.random.default_rng(d)
    n = 60
    box = np.array([p or 3.0 for p in period])
    points = rng.uniform(0.0, 1.0, (n, d)) * box
    tensors = random_tensors(rng, n, d) * 0.05
    if form == "diagonals":
        tensors = np.einsum("nii->ni", tensors)  # the diagonals alone: another set of tensors
        full = np.zeros((n, d, d))
        full[:, np.arange(d), np.arange(d)] = tensors
    else:
        full = tensors
    m = rng.uniform(0.0, 1.0, n) * (points[:, 0] < box[0] / 2)
    m /= m.sum()
    got, substeps, c_max = pt.tensor_transfer(points, tensors, all_pairs(n), m, 0.5, 0.7, period)
    want = dense_reference(points, full, m, 0.5, 0.7, period)
    assert substeps == 1 and c_max < 1.0
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-16)
    assert np.abs(got - m).max() > 1e-3  # something moved


def test_diagonal_and_full_tensors_give_the_same_weights():
    rng = np.random.default_rng(4)
    points = rng.uniform(0.0, 2.0, (200, 2))
    diag = rng.uniform(0.01, 0.2, (200, 2))
    full = np.zeros((200, 2, 2))
    full[:, 0, 0], full[:, 1, 1] = diag[:, 0], diag[:, 1]
    pairs = all_pairs(200)
    by_diagonals = pt.pair_weights(points, diag, pairs, 1.0, (2.0, None))
    np.testing.assert_allclose(by_diagonals, pt.pair_weights(points, full, pairs, 1.0, (2.0, None)), rtol=1e-13)
    np.testing.assert_allclose(pt.self_weights(diag), pt.self_weights(full), rtol=1e-13)
    np.testing.assert_allclose(pt.self_weights(diag), 1.0 / np.sqrt(diag.prod(axis=1)), rtol=1e-15)


def test_transfer_conserves_mass_to_round_off():
    """5,000 particles in 2-D with random tensors, cut-off pairs, 20 steps: the total stays 1 to
    round-off (each step adds P_ij (m_j - m_i) to i and takes it from j) and no mass goes negative."""
    rng = np.random.default_rng(6)
    n = 5000
    points = rng.uniform(0.0, 10.0, (n, 2))
    tensors = random_tensors(rng, n, 2) * 0.01
    pairs = pairs_within(points, 1.0, period=(10.0, None))
    m = rng.exponential(size=n)
    m /= m.sum()
    for _ in range(20):
        m, substeps, _ = pt.tensor_transfer(points, tensors, pairs, m, 1.0, 1.0, (10.0, None))
        assert abs(m.sum() - 1.0) < 50 * np.finfo(float).eps
    assert m.min() >= 0.0


def test_large_beta_is_split_into_substeps():
    """beta * max_i sum_j P_ij > 1 splits the step so masses stay non-negative; the result equals the
    same number of steps of beta / substeps."""
    points = np.array([[0.0], [0.01], [0.02]])
    tensors = np.full((3, 1), 1.0)
    pairs = all_pairs(3)
    m = np.array([1.0, 0.0, 0.0])
    got, substeps, c_max = pt.tensor_transfer(points, tensors, pairs, m, 5.0, 1.0)
    assert substeps == math.ceil(c_max) > 1
    want = m
    for _ in range(substeps):
        want, one, _ = pt.tensor_transfer(points, tensors, pairs, want, 5.0 / substeps, 1.0)
        assert one == 1
    np.testing.assert_allclose(got, want, rtol=1e-14)
    assert got.min() >= 0.0


def test_singular_tensors_are_deltas():
    """D_i = 0 makes W_ii infinite, a pair with D_ij = 0 has W_ij = 0: two zero-D particles never
    exchange with each other; one with D = 0 still exchanges with a partner of finite D_ij."""
    points = np.array([[0.0, 0.0], [0.1, 0.0], [5.0, 0.0], [5.1, 0.0]])
    tensors = np.zeros((4, 2, 2))
    tensors[3] = np.eye(2) * 0.1
    m = np.array([1.0, 0.0, 1.0, 0.0])
    with no_runtime_warnings():
        w_self = pt.self_weights(tensors)
        w = pt.pair_weights(points, tensors, all_pairs(4), 1.0)
        got, _, _ = pt.transfer(all_pairs(4), w, w_self, m, 0.5)
    assert np.all(np.isinf(w_self[:3])) and np.isfinite(w_self[3])
    assert w[0] == 0.0  # pair (0, 1): both D = 0
    np.testing.assert_array_equal(got[:2], m[:2])  # isolated from each other, too far from 3
    assert 0.0 < got[3] < 1.0 and got[2] + got[3] == pytest.approx(1.0, abs=1e-15)


def test_bad_tensor_shapes_are_refused():
    with pytest.raises(ValueError):
        pt.pair_weights(np.zeros((3, 2)), np.ones((3, 3)), all_pairs(3), 1.0)
