"""Pairs within a cut-off in scaled coordinates (numerics/neighbours.py), against brute force and,
in 1-D, a window over the sorted positions."""

from __future__ import annotations

import numpy as np
import pytest

from particle_entropy.numerics.neighbours import pairs_within


def brute_force(points, cutoff, scale, period) -> set[tuple[int, int]]:
    """Every i < j with |(x_i - x_j) scale| <= cutoff, the minimum image along a periodic direction."""
    pts = np.asarray(points, dtype=float).reshape(len(points), -1)
    out = set()
    for i in range(len(pts)):
        for j in range(i + 1, len(pts)):
            diff = np.abs(pts[i] - pts[j])
            for k, p in enumerate(period):
                if p:
                    diff[k] = np.abs(diff[k] - p * np.round(diff[k] / p))
            if np.sqrt(np.sum((diff * scale) ** 2)) <= cutoff:
                out.add((i, j))
    return out


def sorted_window(x, cutoff) -> set[tuple[int, int]]:
    """1-D, open: for each sorted position, the later ones up to x + cutoff."""
    order = np.argsort(x, kind="stable")
    xs = x[order]
    hi = np.searchsorted(xs, xs + cutoff, side="right")
    return {tuple(sorted((int(order[a]), int(order[b])))) for a in range(x.size) for b in range(a + 1, hi[a])}


def as_set(pairs: np.ndarray) -> set[tuple[int, int]]:
    assert pairs.dtype == np.int64 and pairs.ndim == 2 and pairs.shape[1] == 2
    assert np.all(pairs[:, 0] < pairs[:, 1])
    found = {tuple(map(int, p)) for p in pairs}
    assert len(found) == len(pairs)  # each pair once
    return found


@pytest.mark.parametrize("periodic", [False, True])
def test_one_d_pairs_are_brute_force_and_the_sorted_window(periodic):
    rng = np.random.default_rng(1)
    x = rng.uniform(0.0, 10.0, 300)
    period = (10.0,) if periodic else (None,)
    got = as_set(pairs_within(x, 0.2, scale=2.0, period=period))
    want = brute_force(x, 0.2, np.array([2.0]), period)
    assert got == want and len(want) > 100
    if not periodic:
        assert got == sorted_window(x, 0.1)  # scale 2: the cut-off is 0.1 in x
    else:  # the periodic search also pairs across x = 0 = 10
        assert any(abs(x[i] - x[j]) > 5 for i, j in got)


@pytest.mark.parametrize("period", [(None, None), (6.0, None), (None, 1.0), (6.0, 1.0)])
def test_two_d_pairs_are_brute_force(period):
    rng = np.random.default_rng(2)
    pts = np.column_stack([rng.uniform(0.0, 6.0, 400), rng.uniform(0.0, 1.0, 400)])
    scale = np.array([1.0, 5.0])  # anisotropic: y counts five times x
    got = as_set(pairs_within(pts, 0.4, scale=scale, period=period))
    want = brute_force(pts, 0.4, scale, period)
    assert got == want and len(want) > 200
    crosses = {k: any(abs(pts[i, k] - pts[j, k]) * scale[k] > 0.4 for i, j in got) for k in (0, 1)}
    assert crosses == {0: period[0] is not None, 1: period[1] is not None}  # a wrap only where periodic


def test_positions_outside_the_box_are_wrapped():
    """Positions a whole period away and a round-off below 0 (which np.mod sends onto the box's edge)
    pair as their images in [0, period) do."""
    x = np.array([-1e-18, 0.05, 10.02, 29.97])
    got = as_set(pairs_within(x, 0.1, period=10.0))
    assert got == {(0, 1), (0, 2), (1, 2), (0, 3), (1, 3), (2, 3)}


def test_no_points_and_no_pairs():
    assert pairs_within(np.empty((0, 2)), 1.0).shape == (0, 2)
    assert pairs_within(np.array([0.0, 5.0]), 1.0).shape == (0, 2)
