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


SMALLEST_NORMAL = 2.2250738585072014e-308  # 2^-1022: below it a double is subnormal


@njit(cache=True)
def gt_solve(dl, d, du, du2, ipiv, b):
    """x of A x = b from LAPACK dgttrf's LU factors of a tridiagonal A (dl multipliers, d and du, du2
    the rows of U, ipiv the 1-based row interchanges): dgttrs' forward and backward sweeps operation
    for operation, each result below 2^-1022 in magnitude set to 0. A decaying tail otherwise ends on
    the smallest subnormal, which a factor above 1/2 rounds back to itself node after node, and every
    operation on a subnormal costs about a hundred cycles (dgttrs: 4.5 ms for 65,535 nodes, 0.7 ms
    flushed). A flushed value is below 2^-1022 of a unit mass: every normal result is dgttrs' own."""
    n = b.shape[0]
    x = b.copy()
    for i in range(n - 1):  # L: the row interchanges and multipliers
        if ipiv[i] == i + 1:
            y = x[i + 1] - dl[i] * x[i]
        else:
            t = x[i]
            x[i] = x[i + 1]
            y = t - dl[i] * x[i]
        x[i + 1] = y if abs(y) >= SMALLEST_NORMAL else 0.0
    y = x[n - 1] / d[n - 1]
    x[n - 1] = y if abs(y) >= SMALLEST_NORMAL else 0.0
    if n > 1:
        y = (x[n - 2] - du[n - 2] * x[n - 1]) / d[n - 2]
        x[n - 2] = y if abs(y) >= SMALLEST_NORMAL else 0.0
    for i in range(n - 3, -1, -1):  # U: two superdiagonals
        y = (x[i] - du[i] * x[i + 1] - du2[i] * x[i + 2]) / d[i]
        x[i] = y if abs(y) >= SMALLEST_NORMAL else 0.0
    return x


@njit(cache=True)
def tvd_advect(c, p):
    """models/fd.advect_tvd_numpy compiled, operation for operation (the same bits): one explicit
    ULTIMATE-QUICKEST step at Courant number p, faces upstream of the flow's sign -> (c', the mass per
    dx that leaves through the two end faces)."""
    m = c.shape[0]
    cr = abs(p)
    ahead = np.empty(m + 4)  # the nodes along the flow, two zero ghosts each side
    ahead[:2] = 0.0
    ahead[m + 2 :] = 0.0
    for i in range(m):
        ahead[i + 2] = c[i] if p > 0 else c[m - 1 - i]
    half_rest, curve_weight = 0.5 * (1.0 - cr), (1.0 - cr * cr) / 6.0
    faces = np.empty(m + 1)
    for k in range(m + 1):
        up, centre, down = ahead[k], ahead[k + 1], ahead[k + 2]
        curv = down - 2.0 * centre + up
        face = centre + half_rest * (down - centre) - curve_weight * curv
        delta = down - up
        reach = up + (centre - up) / cr
        far = min(down, reach) if delta > 0.0 else max(down, reach)
        held = min(max(face, min(centre, far)), max(centre, far))
        faces[k] = held if abs(curv) < abs(delta) else centre
    out = np.empty(m)
    for i in range(m):
        value = ahead[i + 2] - cr * (faces[i + 1] - faces[i])
        out[i if p > 0 else m - 1 - i] = value
    return out, cr * (faces[m] - faces[0])
