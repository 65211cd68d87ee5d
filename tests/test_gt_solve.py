"""The compiled tridiagonal solve of FD in a flow (numerics/thomas.gt_solve) is LAPACK's dgttrs,
operation for operation, with subnormal results flushed to zero."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import lapack

from particle_entropy.numerics.compiled import kernels
from particle_entropy.numerics.thomas import SMALLEST_NORMAL


def _factors(n: int, r: float, p: float, scheme: str):
    if scheme == "upwind":
        lower, diag, upper = -r - max(p, 0.0), 1.0 + 2.0 * r + abs(p), -r + min(p, 0.0)
    else:
        lower, diag, upper = -r - 0.5 * p, 1.0 + 2.0 * r, -r + 0.5 * p
    return lapack.dgttrf(np.full(n - 1, lower), np.full(n, diag), np.full(n - 1, upper))


@pytest.mark.parametrize("scheme", ["upwind", "central"])
@pytest.mark.parametrize("r, p", [(0.3, 0.2), (0.4, 6.4), (2.0, -9.0), (1e-3, 0.75), (50.0, 1.0)])
def test_the_solve_gives_dgttrs_bits_on_normal_data(scheme, r, p):
    """Random right-hand sides (no subnormal anywhere): the same bytes as dgttrs, row interchanges
    included (central at |p| > 1 + 2 r is not diagonally dominant: dgttrf pivots)."""
    rng = np.random.default_rng(11)
    for n in (3, 17, 1001):
        f = _factors(n, r, p, scheme)
        b = rng.standard_normal(n)
        want, info = lapack.dgttrs(*f[:5], b)
        assert info == 0
        assert kernels().gt_solve(*f[:5], b).tobytes() == want.tobytes()
    if scheme == "central" and abs(r + 0.5 * p) > 1 + 2 * r:  # |lower| > diagonal: dgttrf swaps rows
        assert (f[4] != np.arange(1, n + 1)).any()  # so the pivoting path ran


def test_a_decaying_tail_is_flushed_not_carried_on_subnormals():
    """Implicit upwind at Courant 6.4 (the carried scene's dt = 0.01 at 65,536 nodes): dgttrs ends a
    block's forward sweep on the smallest subnormal, 5e-324, which the factor 0.83 rounds back to
    itself for the rest of the grid, and leaves hundreds of subnormals in its solution; the compiled
    solve has none, and every value above 2^53 of the smallest normal is dgttrs' own."""
    n = 65535
    f = _factors(n, 0.41, 6.44, "upwind")
    b = np.zeros(n)
    b[30000:30100] = 1.0
    want = lapack.dgttrs(*f[:5], b)[0]
    got = kernels().gt_solve(*f[:5], b)
    subnormal = (want != 0) & (np.abs(want) < SMALLEST_NORMAL)
    assert subnormal.sum() > 100
    assert not ((got != 0) & (np.abs(got) < SMALLEST_NORMAL)).any()
    big = np.abs(want) >= SMALLEST_NORMAL * 2.0**53
    assert got[big].tobytes() == want[big].tobytes() and big.sum() > 1000
    assert np.abs(got - want).max() < SMALLEST_NORMAL * 2.0**53
