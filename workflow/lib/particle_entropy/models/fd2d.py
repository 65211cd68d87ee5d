"""Finite differences for 2-D advection-dispersion with a full dispersion tensor (issue 52, point 3):
the 1-D model of fd.py on a grid of (nx + 1) x (ny + 1) nodes, its boundary ring held at zero and
its interior, an (nx - 1, ny - 1) array indexed [i, j] with x along axis 0, solved.

Dispersion is backward Euler with the whole tensor D: the 9-point stencil of div(D grad c), whose
cross term d/dx(Dxy dc/dy) + d/dy(Dxy dc/dx) = 2 Dxy c_xy is taken on the diagonal along Dxy's sign
by the positive 7-point form wherever |Dxy| dx <= Dxx dy and |Dxy| dy <= Dyy dx (``cross_stencil``: the
matrix stays an M-matrix and a plume stays non-negative), else by central differences on the four
corner nodes. Advection is implicit upwind or central in the same matrix (as fd.AdvectionSolver),
or Leonard's explicit ULTIMATE-QUICKEST (tvd), split by direction, x then y, each line by fd.advect_tvd,
then the dispersion solve (Lie splitting, as fd.TVDSolver; the two directions' shifts commute, so
splitting them costs no order), at a Courant number max(|vx| dt / dx, |vy| dt / dy) <= 1.

The implicit step solves the backward-Euler system A c' = c, A = I + dt (v . grad_h - div_h D grad_h),
by one of two solves of the same system (Solver's ``method``):

- "lu": one sparse LU (SuperLU, scipy.sparse.linalg.splu, minimum-degree ordering of A^T + A: the
  matrix's pattern is symmetric, and that ordering fills half what COLAMD does), built once per step
  size and reused every step. Exact for any tensor and flow; its price is memory and time at large n:
  the triangular solves read about 10^8 factor entries at 1,024^2 nodes.
- "krylov": BiCGSTAB (numerics/stencil2d.py, compiled) on the constant 9-point stencil, matrix-free,
  right-preconditioned by a symmetric Gauss-Seidel sweep, iterated until the true relative residual
  ||c - A c'|| / ||c|| is at most RTOL = 1e-13: O(N) a step, no factorisation, eight vectors of
  scratch. A is the identity plus dt times the operator, diagonally dominant at a Courant-limited
  step's dt D / dx^2, so it takes 2-4 iterations there; more as dt D / dx^2 grows (measured on
  512^2 nodes at Courant 0.1-1, every scheme: 2-7 at dt D_L / dx^2 = 0.1, 4-5 at 1, 13-15 at 10,
  52-59 at 100, none within 400 at 1e3). A solve not within RTOL in MAX_ITERATIONS = 40, or whose
  answer fails the mass balance, is replaced by the LU's (factorised then), for that step and every
  later one (``fallbacks`` counts them): the step is never other than the LU's to round-off. Measured
  against the LU (tests): at most 2e-13 of the field's largest value.
- "auto" (the default): the LU below KRYLOV_FROM_UNKNOWNS = 2^16 interior unknowns, i.e. up to
  256 x 256 nodes, the Krylov solve from there. The measured crossover is lower (a step of either
  takes 0.1-0.5 ms at 64^2 nodes, central's the same; from 128^2 the Krylov step is 1.5-3x faster),
  but below 2^16 the LU costs at most about 0.6 s and 230 MB, and every grid of tests/test_fd2d.py
  (and each number measured there) keeps its LU's bits.

Not ADI: ADI splits the operator into x and y sweeps; the cross term fits neither, so ADI schemes
with a mixed derivative (Douglas, Craig-Sneyd, Hundsdorfer-Verwer) take it explicitly, which bounds
the step by the cross term's stability and makes the step no longer the backward-Euler step whose
mass balance fd.py checks. benchmarks/fd2d_step.py measures both solves, at commits f1d6810 and
dbef296 (the same solve) on one core of an "Intel(R) Xeon(R) Processor" (lscpu's name), with others'
jobs running (load average 3.5-7 on its 2 CPUs): CPU ms a step (Krylov iterations) for upwind /
central / tvd, tvd's explicit advection included, the range over the two runs:

    nodes      LU: factorise, peak     LU ms a step          Krylov: peak   Krylov ms a step
    256^2      0.3-0.6 s, 154-232 MB   7.5-11 / 9 / 11       169-172 MB     1.8 (2) / 3.0-3.2 (4) / 2.7-2.9 (2)
    512^2      2.2-3.9 s, 458-465 MB   49 / 48-49 / 54-57    188-196 MB     8.2 (2) / 11-12 (3) / 15 (2)
    1024^2     17-25 s, 1.8 GB         222 / 215-224 / 239-241  257-286 MB     40-43 (2) / 57-62 (3) / 57-59 (2)

so at 1,024^2 the Krylov step takes a quarter of the LU's CPU time, with no factorisation and a
seventh of its memory: upwind meets the 60 ms target, central and tvd are at it (tvd's line-by-line
advection took 28-32 ms of wall time of its step). Wall times there were longer on the loaded machine:
Krylov 43-66 / 83-85 / 83-85 ms, LU 303-362 ms; an earlier run at load 3.3-4.5 (commit f8c539f,
before the sweeps took four nodes a block) gave 49 / 62 / 63 ms against the LU's 218-241 ms.

Every step balances its mass as in 1-D (fd.check_balance): the interior's mass falls by the flux into
the zero boundary ring, computed from the stencil's entries that reach the ring (not from the
sparse matrix), else MassError. Negative concentrations (implicit central, or a cross term larger than
the diagonal terms allow) are the scheme's own: never clipped, each step's smallest value and the first
step that went below zero are kept on the solver (Step)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.registry import COURANT_SLACK
from ..numerics.compiled import kernels
from . import fd
from .conservation import MassError

SCHEMES = ("upwind", "central", "tvd")
METHODS = ("auto", "lu", "krylov")
# "auto" takes the LU below this many interior unknowns (255 x 255 nodes and fewer: every grid of
# tests/test_fd2d.py, bit for bit as before), the Krylov solve from it on
KRYLOV_FROM_UNKNOWNS = 2**16
RTOL = 1e-13  # the Krylov solve's true relative residual ||c - A c'|| / ||c||
MAX_ITERATIONS = 40  # BiCGSTAB iterations before the step falls back to the LU


def courant_number(v, dx: float, dy: float, dt: float) -> float:
    """max(|vx| dt / dx, |vy| dt / dy): the cells the plume crosses in a step along either axis [-]."""
    return max(abs(float(v[0])) * dt / dx, abs(float(v[1])) * dt / dy)


def step_for_courant(courant: float, v, dx: float, dy: float) -> float:
    """The step dt at which courant_number is ``courant`` [T]."""
    rate = max(abs(float(v[0])) / dx, abs(float(v[1])) / dy)
    if not rate > 0.0:
        raise ValueError("courant needs a flow: v = 0 crosses no cell")
    return courant / rate


@dataclass(frozen=True)
class Grid:
    """Nodes (x0 + i dx, y0 + j dy), i = 0..nx, j = 0..ny; the boundary ring held at zero."""

    x0: float
    y0: float
    dx: float
    dy: float
    nx: int
    ny: int

    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """The node coordinates along x (nx + 1) and along y (ny + 1) [L]."""
        return self.x0 + self.dx * np.arange(self.nx + 1), self.y0 + self.dy * np.arange(self.ny + 1)

    def interior(self) -> tuple[np.ndarray, np.ndarray]:
        """The interior nodes' x and y, each of shape (nx - 1, ny - 1) [L]."""
        x, y = self.nodes()
        return np.meshgrid(x[1:-1], y[1:-1], indexing="ij")


@dataclass(frozen=True)
class Step:
    """What one step did: the mass per cell area it sent into the zero ring, and its smallest value."""

    outflow: float
    smallest: float


def _operator(D, v, dx: float, dy: float, dt: float, scheme: str) -> dict[tuple[int, int], float]:
    """The stencil of dt (v . grad - div D grad) on a node: offset (di, dj) -> weight. Dispersion's
    5-point part, its cross term 2 Dxy c_xy (``cross_stencil``), and the advection term: upwind's
    one-sided or central's centred difference ("tvd": none, advection is explicit)."""
    D = np.asarray(D, dtype=float)
    if D.shape != (2, 2) or not abs(D[0, 1] - D[1, 0]) <= 1e-12 * np.abs(D).max():
        raise ValueError(f"D must be a symmetric 2 x 2 tensor, got {D.tolist()}")
    rx, ry = D[0, 0] * dt / dx**2, D[1, 1] * dt / dy**2
    s = {(0, 0): 2.0 * rx + 2.0 * ry, (-1, 0): -rx, (1, 0): -rx, (0, -1): -ry, (0, 1): -ry}
    for offset, w in cross_stencil(D, dx, dy, dt).items():
        s[offset] = s.get(offset, 0.0) + w
    for axis, p in ((0, float(v[0]) * dt / dx), (1, float(v[1]) * dt / dy)):
        back, ahead = ((-1, 0), (1, 0)) if axis == 0 else ((0, -1), (0, 1))
        if scheme == "upwind":
            s[(0, 0)] += abs(p)
            s[back] -= max(p, 0.0)
            s[ahead] += min(p, 0.0)
        elif scheme == "central":
            s[back] -= 0.5 * p
            s[ahead] += 0.5 * p
        elif scheme != "tvd":
            raise ValueError(f"advection scheme {scheme!r}: one of {', '.join(SCHEMES)}")
    return s


def positive_cross(D, dx: float, dy: float) -> bool:
    """Whether the cross term fits the positive 7-point form (``cross_stencil``): |Dxy| dx <= Dxx dy and
    |Dxy| dy <= Dyy dx, so that every neighbour's weight keeps its sign."""
    D = np.asarray(D, dtype=float)
    a = abs(0.5 * (D[0, 1] + D[1, 0]))
    return a * dx <= D[0, 0] * dy and a * dy <= D[1, 1] * dx


def cross_stencil(D, dx: float, dy: float, dt: float) -> dict[tuple[int, int], float]:
    """The stencil of -dt 2 Dxy c_xy, second order either way. Where ``positive_cross`` holds, the
    positive 7-point form on the diagonal along Dxy's sign: 2 c_xy h^2 = c(i+1, j+1) + c(i-1, j-1) +
    2 c - c(i +- 1, j) - c(i, j +- 1) for Dxy > 0 (the anti-diagonal for Dxy < 0), whose neighbour
    weights keep the signs of the 5-point part's, so that backward Euler keeps an M-matrix and a
    plume stays non-negative (a point at 45 degrees, D_L = 10 D_T: every scheme went negative at its
    first step with the corner form). Otherwise the central difference on the four corners, whose
    two opposite corners carry negative weights (a scheme's negatives are then its own, reported)."""
    D = np.asarray(D, dtype=float)
    dxy = 0.5 * (D[0, 1] + D[1, 0])
    if dxy == 0.0:
        return {}
    if not positive_cross(D, dx, dy):
        r = dxy * dt / (2.0 * dx * dy)  # 2 Dxy dt / (4 dx dy)
        return {(1, 1): -r, (-1, -1): -r, (1, -1): r, (-1, 1): r}
    a = abs(dxy) * dt / (dx * dy)
    diagonal = ((1, 1), (-1, -1)) if dxy > 0 else ((1, -1), (-1, 1))
    out = {(0, 0): -2.0 * a, (1, 0): a, (-1, 0): a, (0, 1): a, (0, -1): a}
    out.update({d: -a for d in diagonal})
    return out


def _matrix(stencil: dict[tuple[int, int], float], mx: int, my: int):
    """I + the stencil on the mx x my interior (node k = i my + j), the ring's entries dropped."""
    import scipy.sparse as sp

    def shift(m: int, d: int):
        return sp.eye(m, k=d, format="csr")

    a = sp.identity(mx * my, format="csr")
    for (di, dj), w in stencil.items():
        if w != 0.0:
            a = a + w * sp.kron(shift(mx, di), shift(my, dj), format="csr")
    return a.tocsc()


def _weights(stencil: dict[tuple[int, int], float]) -> np.ndarray:
    """The step matrix's stencil as a (3, 3) array w[di + 1, dj + 1], the identity included [-]."""
    w = np.zeros((3, 3))
    w[1, 1] = 1.0
    for (di, dj), s in stencil.items():
        w[di + 1, dj + 1] += s
    return w


def choose_method(method: str, shape: tuple[int, int]) -> str:
    """ "lu" or "krylov": ``method`` itself, or for "auto" the LU below KRYLOV_FROM_UNKNOWNS unknowns."""
    if method not in METHODS:
        raise ValueError(f"solve method {method!r}: one of {', '.join(METHODS)}")
    if method != "auto":
        return method
    return "lu" if shape[0] * shape[1] < KRYLOV_FROM_UNKNOWNS else "krylov"


def _ring_weights(stencil: dict[tuple[int, int], float], mx: int, my: int) -> np.ndarray:
    """w (mx, my): the mass per cell area that a unit value at an interior node sends into the ring
    in one step, by the stencil's entries on the ring's nodes (those the interior matrix drops).
    Nonzero on the interior's edge nodes only."""
    i, j = np.meshgrid(np.arange(1, mx + 1), np.arange(1, my + 1), indexing="ij")
    w = np.zeros((mx, my))
    for (di, dj), s in stencil.items():
        # the ring node b = k - (di, dj) sees k through the weight s
        bi, bj = i - di, j - dj
        w -= s * ((bi == 0) | (bi == mx + 1) | (bj == 0) | (bj == my + 1))
    return w


def _edge_sum(w: np.ndarray, c: np.ndarray) -> float:
    """sum(w c) over the edge nodes of the interior, where w lives."""
    total = float(w[0] @ c[0])
    if c.shape[0] > 1:
        total += float(w[-1] @ c[-1])
        total += float(w[1:-1, 0] @ c[1:-1, 0])
        if c.shape[1] > 1:
            total += float(w[1:-1, -1] @ c[1:-1, -1])
    return total


class Solver:
    """One step dt of 2-D advection-dispersion on the interior (nx - 1, ny - 1), built once per step:
    backward Euler (I + dt (v . grad_h - div_h D grad_h)) c' = c with upwind or central advection
    in the matrix, or (tvd) fd.advect_tvd along x then along y, then the dispersion solve."""

    def __init__(
        self,
        D,
        v,
        dx: float,
        dy: float,
        dt: float,
        shape: tuple[int, int],
        scheme: str,
        method: str = "auto",
        rtol: float = RTOL,
        max_iterations: int = MAX_ITERATIONS,
    ):
        self.D, self.v = np.array(D, dtype=float), np.array(v, dtype=float)
        self.dx, self.dy, self.dt, self.shape, self.scheme = float(dx), float(dy), float(dt), tuple(shape), scheme
        self.courant = courant_number(self.v, self.dx, self.dy, self.dt)
        if scheme == "tvd" and not self.courant <= 1.0 + COURANT_SLACK:
            raise ValueError(f"tvd advection at courant number {self.courant:.17g}: at most 1")
        # the Courant number along each axis, within round-off of 1 taken as 1 (fd.TVDSolver's rule)
        self.p = tuple(max(-1.0, min(1.0, self.v[a] * self.dt / h)) for a, h in ((0, self.dx), (1, self.dy)))
        self._stencil = _operator(self.D, self.v, self.dx, self.dy, self.dt, scheme)
        self._ring = _ring_weights(self._stencil, *self.shape)
        self._scale = 1.0 + sum(abs(w) for w in self._stencil.values())  # the matrix's largest row sum
        self.method = choose_method(method, self.shape)
        self.rtol, self.max_iterations = float(rtol), int(max_iterations)
        self.factorisation_seconds, self.setup_seconds = 0.0, 0.0  # wall times, for benchmarks
        self._lu = None
        start = time.perf_counter()
        if self.method == "lu":
            self._factorise()
        else:
            self._w = _weights(self._stencil)
            self._work = np.empty((8, self.shape[0] * self.shape[1]))  # BiCGSTAB's vectors
        self.setup_seconds = time.perf_counter() - start
        self.iterations, self.fallbacks = 0, 0  # the last Krylov solve's; steps that took the LU instead
        self.steps, self.smallest, self.first_negative, self.last = 0, math.inf, None, None

    @cached_property
    def matrix(self):
        """The step matrix I + dt (v . grad_h - div_h D grad_h), sparse (CSC), built when first asked for."""
        return _matrix(self._stencil, *self.shape)

    def _factorise(self) -> None:
        """The sparse LU of ``matrix`` (SuperLU, minimum degree on A^T + A), timed."""
        from scipy.sparse.linalg import splu

        start = time.perf_counter()
        self._lu = splu(self.matrix, permc_spec="MMD_AT_PLUS_A")
        self.factorisation_seconds = time.perf_counter() - start

    def _krylov(self, c: np.ndarray) -> np.ndarray | None:
        """The matrix's solve by BiCGSTAB (numerics/stencil2d) to ``rtol``, or None where it did not
        get there in ``max_iterations``."""
        out, self.iterations, residual = kernels().bicgstab(
            self._w, np.ascontiguousarray(c), self.rtol, self.max_iterations, self._work
        )
        return out if residual <= self.rtol else None

    def implicit(self, c: np.ndarray) -> tuple[np.ndarray, float]:
        """The backward-Euler solve of ``c`` and its outflow, mass balanced (else MassError): by the
        Krylov solve, or the LU where that did not converge or balance (from then on, every step)."""
        if self.method == "krylov":
            out = self._krylov(c)
            if out is not None:
                outflow = self.outflow(out)
                try:
                    fd.check_balance(c, out, outflow, self._scale)
                    return out, outflow
                except MassError:
                    pass
            self.method, self.fallbacks = "lu", self.fallbacks + 1
        if self._lu is None:
            self._factorise()
        out = self._lu.solve(c.ravel()).reshape(self.shape)
        outflow = self.outflow(out)
        fd.check_balance(c, out, outflow, self._scale)
        return out, outflow

    def outflow(self, c: np.ndarray) -> float:
        """The mass per cell area the implicit solution ``c`` sent into the zero ring this step."""
        return _edge_sum(self._ring, c)

    def advect(self, c: np.ndarray) -> tuple[np.ndarray, float]:
        """tvd's explicit substep: every line along x, then every line along y, by fd.advect_tvd, each
        sweep's mass balanced against the flux through the ring -> (c*, the mass that left)."""
        left = 0.0
        for axis, p in enumerate(self.p):
            if p == 0.0:
                continue
            lines = np.ascontiguousarray(c.T if axis == 0 else c)  # each row one line along the axis
            out = np.empty_like(lines)
            flux = 0.0
            for k, line in enumerate(lines):
                out[k], through = fd.advect_tvd(line, p)
                flux += through
            out = out.T if axis == 0 else out
            fd.check_balance(c, out, flux, 1.0 + 4.0 * abs(p))
            c, left = out, left + flux
        return c, left

    def step(self, c_interior: np.ndarray) -> tuple[np.ndarray, Step]:
        """One step of the interior -> (the new interior, Step); MassError if the mass does not balance."""
        c = np.asarray(c_interior, dtype=float)
        if c.shape != self.shape:
            raise ValueError(f"interior of shape {c.shape}, the solver's is {self.shape}")
        left = 0.0
        if self.scheme == "tvd":
            c, left = self.advect(c)
        out, outflow = self.implicit(c)
        smallest = float(out.min())
        self.steps += 1
        self.smallest = min(self.smallest, smallest)
        if smallest < 0.0 and self.first_negative is None:
            self.first_negative = self.steps
        self.last = Step(left + outflow, smallest)
        return out, self.last

    def solve(self, c_interior: np.ndarray) -> np.ndarray:
        """The new interior after one step (fd.py's solver interface); the step's Step in ``last``."""
        return self.step(c_interior)[0]

    @property
    def last_outflow(self) -> float:
        """The mass per cell area the last step sent into the ring (fd.py's solvers' ``last_outflow``)."""
        return self.last.outflow


def solver(D, v, grid: Grid, dt: float, scheme: str, method: str = "auto", **options) -> Solver:
    """The solver of one step dt on ``grid``'s interior (``method`` and ``options``: Solver's)."""
    return Solver(D, v, grid.dx, grid.dy, dt, (grid.nx - 1, grid.ny - 1), scheme, method, **options)


def step_whole(solve: Solver, c: np.ndarray) -> Step:
    """One step of the whole node array ``c`` (nx + 1, ny + 1) in place, its ring held."""
    c[1:-1, 1:-1], done = solve.step(c[1:-1, 1:-1])
    return done
