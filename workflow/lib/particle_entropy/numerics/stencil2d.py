"""The compiled matrix-free solve of the 2-D finite differences (models/fd2d.py): the 9-point
constant stencil's product with an interior array (its ring of zeros dropped), a symmetric
Gauss-Seidel sweep as preconditioner, and BiCGSTAB (van der Vorst 1992) right-preconditioned by it.
The stencil is a (3, 3) array w[di + 1, dj + 1] of the step matrix's weights, identity included;
arrays are the interior (mx, my) flattened, node k = i my + j. Every loop is written out, one pass
each, no temporaries. Only numba-compiled code lives here (see numerics/compiled.py)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _add_row(y, x, a, b, c):
    """y[j] += a x[j - 1] + b x[j] + c x[j + 1] along one row, x beyond its ends taken as 0."""
    my = y.size
    for j in range(my - 2):
        y[j + 1] += a * x[j] + b * x[j + 1] + c * x[j + 2]
    if my > 1:
        y[0] += b * x[0] + c * x[1]
        y[my - 1] += a * x[my - 2] + b * x[my - 1]
    else:
        y[0] += b * x[0]


@njit(cache=True)
def _row(w, x, y, i, mx, my):
    """Row i of y = A x in place (A the stencil w, nodes beyond the interior's edge taken as 0)."""
    yr = y[i * my : (i + 1) * my]
    yr[:] = 0.0
    for di in range(-1, 2):
        k = i + di
        if 0 <= k < mx:
            _add_row(yr, x[k * my : (k + 1) * my], w[di + 1, 0], w[di + 1, 1], w[di + 1, 2])


@njit(cache=True)
def apply(w, x, y, mx, my):
    """y = A x in place (A the stencil w on the flattened interior (mx, my))."""
    for i in range(mx):
        _row(w, x, y, i, mx, my)


@njit(cache=True)
def stencil_apply(w, x):
    """A x: the 9-point stencil w on the interior x (mx, my), nodes beyond its edge taken as 0."""
    mx, my = x.shape
    y = np.empty(mx * my)
    apply(w, np.ascontiguousarray(x).ravel(), y, mx, my)
    return y.reshape(mx, my)


@njit(cache=True)
def _recur(z, c, direction):
    """z[j] -= c z[j - direction] in place along one row, in that direction, four nodes a step:
    each block's own recurrence q first, then z = q + (-c)^k z_before, so that the chain of
    dependent multiply-adds from block to block is one long."""
    my = z.size
    c2, c3, c4 = c * c, -c * c * c, c * c * c * c
    start = 0 if direction > 0 else my - 1
    prev = 0.0
    for k in range(my // 4):
        j0 = start + 4 * k * direction
        j1, j2, j3 = j0 + direction, j0 + 2 * direction, j0 + 3 * direction
        q0 = z[j0]
        q1 = z[j1] - c * q0
        q2 = z[j2] - c * q1
        q3 = z[j3] - c * q2
        z[j0] = q0 - c * prev
        z[j1] = q1 + c2 * prev
        z[j2] = q2 + c3 * prev
        prev = q3 + c4 * prev
        z[j3] = prev
    for j in range(4 * (my // 4), my):
        at = start + j * direction
        prev = z[at] - c * prev
        z[at] = prev


@njit(cache=True)
def _sgs(w, r, z, mx, my):
    """z = M^-1 r, M = (D + L) D^-1 (D + U): the symmetric Gauss-Seidel splitting of the stencil in
    node order, one forward sweep and one backward; each row takes its neighbour row's terms in one
    pass, then its own recurrence, carried in a register."""
    inv = 1.0 / w[1, 1]
    left, right = w[1, 0] * inv, w[1, 2] * inv
    for i in range(mx):  # (D + L) z = r
        zr = z[i * my : (i + 1) * my]
        for j in range(my):
            zr[j] = r[i * my + j] * inv
        if i > 0:
            _add_row(zr, z[(i - 1) * my : i * my], -w[0, 0] * inv, -w[0, 1] * inv, -w[0, 2] * inv)
        _recur(zr, left, 1)
    for i in range(mx - 1, -1, -1):  # (D + U) z' = D z
        zr = z[i * my : (i + 1) * my]
        if i < mx - 1:
            _add_row(zr, z[(i + 1) * my : (i + 2) * my], -w[2, 0] * inv, -w[2, 1] * inv, -w[2, 2] * inv)
        _recur(zr, right, -1)


# the vector passes may reassociate their sums (fastmath "reassoc"): a sum's order is then the
# compiler's, fixed for a build, and the passes vectorise; the stencil and the sweeps keep IEEE order
VECTOR = {"reassoc", "contract"}


@njit(cache=True, fastmath=VECTOR)
def _dot(a, b):
    """a . b."""
    s = 0.0
    for k in range(a.size):
        s += a[k] * b[k]
    return s


@njit(cache=True, fastmath=VECTOR)
def _minus(b, y):
    """y = b - y in place -> ||y||."""
    s = 0.0
    for k in range(y.size):
        y[k] = b[k] - y[k]
        s += y[k] * y[k]
    return math.sqrt(s)


@njit(cache=True, fastmath=VECTOR)
def _direction(p, r, v, beta, omega):
    """p = r + beta (p - omega v) in place."""
    for k in range(p.size):
        p[k] = r[k] + beta * (p[k] - omega * v[k])


@njit(cache=True, fastmath=VECTOR)
def _half_step(s, r, v, alpha):
    """s = r - alpha v in place -> ||s||."""
    ss = 0.0
    for k in range(s.size):
        s[k] = r[k] - alpha * v[k]
        ss += s[k] * s[k]
    return math.sqrt(ss)


@njit(cache=True, fastmath=VECTOR)
def _step_pair(t, s):
    """(t . s, t . t)."""
    ts, tt = 0.0, 0.0
    for k in range(t.size):
        ts += t[k] * s[k]
        tt += t[k] * t[k]
    return ts, tt


@njit(cache=True, fastmath=VECTOR)
def _update(x, r, ph, sh, s, t, rhat, alpha, omega):
    """x += alpha ph + omega sh, r = s - omega t in place -> (||r||, rhat . r)."""
    rr, rho = 0.0, 0.0
    for k in range(x.size):
        x[k] += alpha * ph[k] + omega * sh[k]
        r[k] = s[k] - omega * t[k]
        rr += r[k] * r[k]
        rho += rhat[k] * r[k]
    return math.sqrt(rr), rho


@njit(cache=True)
def _residual(w, b, x, r, mx, my):
    """r = b - A x in place -> ||r||."""
    apply(w, x, r, mx, my)
    return _minus(b, r)


@njit(cache=True)
def _bicgstab_pass(w, b, x, tol, budget, mx, my, work, fresh):
    """BiCGSTAB iterations on A x = b from x (updated in place) until ||b - A x|| <= tol by its
    recurrence, a breakdown, or ``budget`` iterations -> iterations taken. ``work``: 8 vectors;
    ``fresh``: x is 0 and b is not."""
    r, rhat, p, v, ph, sh, s, t = work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7]
    if fresh:  # x = 0 (b != 0): the residual is b, no product needed, and b is the shadow residual
        r[:] = b
        rhat = b
    elif _residual(w, b, x, r, mx, my) <= tol:
        return 0
    else:
        rhat[:] = r
    rho = alpha = omega = 1.0
    rho_new = _dot(rhat, r)
    for it in range(1, budget + 1):
        if rho_new == 0.0 or omega == 0.0:
            return it
        beta = (rho_new / rho) * (alpha / omega)
        rho = rho_new
        if it == 1:
            p[:] = r
        else:
            _direction(p, r, v, beta, omega)
        _sgs(w, p, ph, mx, my)
        apply(w, ph, v, mx, my)
        alpha = rho / _dot(rhat, v)
        if _half_step(s, r, v, alpha) <= tol:
            x += alpha * ph
            return it
        _sgs(w, s, sh, mx, my)
        apply(w, sh, t, mx, my)
        ts, tt = _step_pair(t, s)
        omega = ts / tt if tt > 0.0 else 0.0
        rr, rho_new = _update(x, r, ph, sh, s, t, rhat, alpha, omega)
        if rr <= tol:
            return it
    return budget


@njit(cache=True)
def bicgstab(w, b, rtol, max_iterations, work):
    """x (mx, my) with ||b - A x|| <= rtol ||b|| (the true residual, recomputed), A the stencil w and
    b (mx, my), by BiCGSTAB right-preconditioned by symmetric Gauss-Seidel, restarted from its iterate
    where the recurrence's residual drifted or broke down -> (x, iterations, ||b - A x|| / ||b||); the
    last above rtol when ``max_iterations`` did not reach it. ``work``: (8, mx my), scratch."""
    mx, my = b.shape
    flat = np.ascontiguousarray(b).ravel()
    x = np.zeros(mx * my)
    scale = math.sqrt(_dot(flat, flat))
    if scale == 0.0:
        return x.reshape(mx, my), 0, 0.0
    tol, done = rtol * scale, 0
    while True:
        done += _bicgstab_pass(w, flat, x, tol, max_iterations - done, mx, my, work, done == 0)
        residual = _residual(w, flat, x, work[0], mx, my) / scale
        if residual <= rtol or done >= max_iterations:
            return x.reshape(mx, my), done, residual
