"""Particle pairs within a cut-off distance in scaled coordinates, in d dimensions, for MTPT's kernels."""

from __future__ import annotations

import numpy as np


def scaled_points(points, scale=None, period=None) -> tuple[np.ndarray, np.ndarray | None]:
    """(N, d) coordinates s_k = x_k scale_k, the periodic directions wrapped into [0, period_k scale_k),
    and the box of those periods in scaled units (0 for a direction without one; None when no
    direction has one). ``points`` is (N,) for d = 1 or (N, d); ``scale`` and ``period`` are
    scalars or (d,); a period of None or 0 leaves its direction open."""
    pts = np.asarray(points, dtype=np.float64)
    pts = pts[:, None] if pts.ndim == 1 else pts
    d = pts.shape[1]
    scale = np.ones(d) if scale is None else np.broadcast_to(np.asarray(scale, dtype=np.float64), (d,))
    pts = pts * scale
    if period is None:
        return pts, None
    period = np.broadcast_to(np.array(period, dtype=object), (d,))
    box = np.array([0.0 if p is None else float(p) for p in period]) * scale
    if not np.any(box > 0):
        return pts, None
    for k in np.flatnonzero(box > 0):
        col = np.mod(pts[:, k], box[k])
        pts[:, k] = np.where(col >= box[k], 0.0, col)  # round-off may land on the edge; the tree needs [0, box)
    return pts, box


def pairs_within(points, cutoff: float, scale=None, period=None) -> np.ndarray:
    """Every pair (i, j), i < j, whose scaled distance |(x_i - x_j) * scale| (the minimum image along
    periodic directions) is at most ``cutoff``: an (n_pairs, 2) int64 array, in the k-d tree's order.

    scipy's cKDTree on ``scaled_points``; its box of 0 leaves a direction open, so one tree serves
    a channel periodic in x with walls in y. With d = 1 these are the pairs a window over the
    sorted positions finds. Periodic directions need cutoff < period * scale / 2 for each pair to
    be found once, by its nearest image.
    """
    from scipy.spatial import cKDTree

    pts, box = scaled_points(points, scale, period)
    pairs = cKDTree(pts, boxsize=box).query_pairs(cutoff, output_type="ndarray")
    return pairs.reshape(-1, 2).astype(np.int64, copy=False)
