"""The compiled Thomas algorithm of the implicit finite differences (models/fd.py): LU factors of
the constant tridiagonal (-r, 1 + 2r, -r) and the solve with them. Only numba-compiled code
lives here (see numerics/compiled.py)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def thomas_factor(n: int, r: float):
    """LU factors of the constant tridiagonal (-r, 1 + 2r, -r) (Thomas algorithm)."""
    inv_piv = np.empty(n)
    upper = np.empty(n)
    piv = 1.0 + 2.0 * r
    inv_piv[0] = 1.0 / piv
    upper[0] = -r * inv_piv[0]
    for i in range(1, n):
        piv = 1.0 + 2.0 * r + r * upper[i - 1]
        inv_piv[i] = 1.0 / piv
        upper[i] = -r * inv_piv[i]
    return inv_piv, upper


@njit(cache=True)
def thomas_solve(inv_piv, upper, r, d):
    n = d.shape[0]
    y = np.empty(n)
    y[0] = d[0] * inv_piv[0]
    for i in range(1, n):
        y[i] = (d[i] + r * y[i - 1]) * inv_piv[i]
    for i in range(n - 2, -1, -1):
        y[i] -= upper[i] * y[i + 1]
    return y
