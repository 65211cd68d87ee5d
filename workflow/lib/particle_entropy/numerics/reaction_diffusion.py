"""The reference solution of a reactive scene: 1-D reaction-diffusion of A, B and their product C,

    dA/dt = D A_xx - R,   dB/dt = D B_xx - R,   dC/dt = D C_xx + R,

with R = k A B (A + B -> C) or R = lambda A (decay A -> C, B inert), on a uniform fine grid in the
frame that moves with the uniform velocity v, so that no advection term, and none of its numerical
dispersion, enters. Strang splitting (Strang 1968, SIAM J. Numer. Anal. 5: 506-517): half a step of
reaction by the closed-form kinetics (core/reactions), a Crank-Nicolson diffusion step, half a step
of reaction; second order in dt. The grid is cell-centred (finite volumes) with zero-flux (Neumann)
ends on a window the plume never reaches: a uniform B stays uniform and the totals of A + C and of
B + C are conserved to round-off, which every step checks. Crank-Nicolson keeps every value >= 0
while r = D dt / dx^2 <= 1 (the explicit half's diagonal 1 - r >= 0; the implicit half an M-matrix).

``richardson`` extrapolates a quantity from three grids, dx and dt halved each level (Richardson
1911; the observed order as in Roache 1998, Verification and Validation in Computational Science),
where the observed order is near the scheme's (ORDER_BAND), else states the finest grid's value with
a conservative error. ``plan`` states a reference's grids, steps and cost from its physics before
any solve (the box edges on cell faces, ``aligned_grid``; the kinetic steps capped at MAX_WORK), and
``reference`` runs the three grids of a scene and extrapolates its product mass and its
concentrations of A and C at given points."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..core.sources import Box, Source
from .compiled import kernels

# a step's change of a conserved total beyond this many ulps of the totals' magnitude (times sqrt of
# the number of cells) is no round-off
MASS_ULPS = 64.0
# the default window reaches this many final spreads sqrt(2 D t) beyond the sources: exp(-32) there
REACH = 8.0
# the default coarsest grid: this many cells, and a time step with r <= 1/4 (so r <= 1 on the finest
# of three grids) and at most 2 of the fastest reaction times (1/2 on the finest): the kinetics are
# exact within a step, so the step bounds only the splitting error, second order and extrapolated
# with the rest. A Gaussian into a uniform B at k C0 = 20 (D 1e-3, t 50) gave the same product mass
# to 5e-11 at 1/8 and at 2 reaction times, its error estimate 5.2e-6 at both, in 1/15 of the time.
COARSE_CELLS = 400
COARSE_R = 0.25
COARSE_KINETIC = 2.0
# Richardson's extrapolation holds where the observed order is near the scheme's (2): outside this
# band the three grids are not in the asymptotic range (a box edge inside a cell gave 5.06 for a
# value 169 of its stated errors off, issue 50), and the finest grid's value is stated instead
ORDER_BAND = (1.5, 2.5)
# aligned_grid may take up to this factor more cells than asked to put the sources' edges on faces
ALIGN_SLACK = 1.25
# a reference's work, its steps times (cells + STEP_CELLS) summed over its three grids, is kept within
# MAX_WORK (the kinetic rule capped, r's never). Measured (solve, this machine): a step costs
# 1.35e-7 s a cell plus 1.4e-4 s (its array calls), 1.5e-4 s a step at 100 cells, 1.0e-3 s at 6,400;
# so a step counts STEP_CELLS cells more, and MAX_WORK is ~4 s
SECONDS_PER_CELL_STEP = 1.35e-7
STEP_CELLS = 1000
MAX_WORK = 3.0e7


@dataclass(frozen=True)
class Fields:
    """A solve's result: cell centres x (in the moving frame), the concentrations a, b, c at t_final,
    the grid's dx, dt and number of steps, and the total masses (integral of A, B, C dx) at ``times``
    (``masses[i]`` = (M_A, M_B, M_C) at times[i])."""

    x: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    dx: float
    dt: float
    n_steps: int
    times: np.ndarray
    masses: np.ndarray

    @property
    def product_mass(self) -> float:
        """M_C = sum c dx at t_final [M]."""
        return float(self.c.sum() * self.dx)


def cell_centres(lo: float, hi: float, n: int) -> tuple[np.ndarray, float]:
    """The centres lo + (i + 1/2) dx, i = 0..n-1, of n cells of width dx = (hi - lo) / n [L]."""
    dx = (hi - lo) / n
    return lo + dx * (np.arange(n) + 0.5), dx


class CrankNicolson:
    """One Crank-Nicolson step of c_t = D c_xx with zero-flux ends on n cells,
    (I - r/2 A) c^{n+1} = (I + r/2 A) c^n, r = D dt / dx^2, A the Neumann Laplacian (rows (1, -2, 1),
    end rows (-1, 1)); factorised once by LAPACK's dgttrf, solved by thomas.gt_solve (subnormals
    flushed). The columns of A sum to 0: the step conserves sum c to round-off."""

    def __init__(self, n: int, r: float):
        from scipy.linalg import lapack

        if n < 2:
            raise ValueError(f"a diffusion grid needs at least 2 cells, got {n}")
        self.r = float(r)
        h = 0.5 * self.r
        d = np.full(n, 1.0 + 2.0 * h)
        d[0] = d[-1] = 1.0 + h
        self._factors = lapack.dgttrf(np.full(n - 1, -h), d, np.full(n - 1, -h))
        if self._factors[-1] != 0:
            raise ValueError(f"the Crank-Nicolson matrix is singular (dgttrf info {self._factors[-1]})")

    def explicit(self, c: np.ndarray) -> np.ndarray:
        """(I + r/2 A) c: c plus r/2 times the Neumann second difference."""
        lap = np.empty_like(c)
        lap[1:-1] = c[:-2] - 2.0 * c[1:-1] + c[2:]
        lap[0] = c[1] - c[0]
        lap[-1] = c[-2] - c[-1]
        return c + 0.5 * self.r * lap

    def step(self, c: np.ndarray) -> np.ndarray:
        """c after one step dt."""
        dl, d, du, du2, ipiv, _ = self._factors
        return kernels().gt_solve(dl, d, du, du2, ipiv, self.explicit(c))


def _check_totals(before: tuple[float, float], after: tuple[float, float], size: float, n: int, step: int) -> None:
    """ArithmeticError unless the conserved totals (A + C, and B + C or B) did not change beyond round-off."""
    tol = MASS_ULPS * np.finfo(np.float64).eps * size * math.sqrt(n)
    for name, b, a in zip(("A + C", "B (+ C)"), before, after):
        if not abs(a - b) <= tol:
            raise ArithmeticError(
                f"reaction-diffusion step {step} changed the total of {name}: {b:.17g} -> {a:.17g}, "
                f"beyond round-off {tol:.3g}"
            )


def solve(x, a0, b0, D: float, reaction, t_final: float, n_steps: int, times=()) -> Fields:
    """A, B, C at t_final of dA/dt = D A_xx - R, dB/dt = D B_xx - R, dC/dt = D C_xx + R from
    concentrations a0, b0 (C = 0; b0 may be a float) on uniform cells centred at x, in n_steps
    Strang steps (reaction dt/2, Crank-Nicolson dt, reaction dt/2), with the total masses at
    ``times`` (each a multiple of dt); every value stays >= 0 while D dt / dx^2 <= 1."""
    x = np.asarray(x, dtype=np.float64)
    a = np.array(a0, dtype=np.float64)
    b = np.array(b0, dtype=np.float64) * np.ones_like(a)
    if x.ndim != 1 or x.size < 2 or a.shape != x.shape:
        raise ValueError("x and a0 must be 1-D arrays of the same length, at least 2 cells")
    dx = float(x[1] - x[0])
    if not (dx > 0 and np.allclose(np.diff(x), dx, rtol=1e-9, atol=0.0)):
        raise ValueError("the cells must be uniform and increasing")
    if np.any(a < 0) or np.any(b < 0):
        raise ValueError("initial concentrations must be >= 0")
    if not (n_steps >= 1 and t_final > 0):
        raise ValueError(f"need n_steps >= 1 and t_final > 0, got {n_steps}, {t_final}")
    dt = t_final / n_steps
    times = np.asarray(times, dtype=np.float64)
    at_step = np.rint(times / dt).astype(np.int64)
    if np.any(np.abs(at_step * dt - times) > 1e-9 * max(dt, 1.0)) or np.any((at_step < 0) | (at_step > n_steps)):
        raise ValueError(f"each requested time must be a multiple of dt = {dt!r} in [0, t_final]")
    c = np.zeros_like(a)
    diffuse = CrankNicolson(a.size, D * dt / dx**2)
    masses = np.empty((times.size, 3))

    def record(step):
        for i in np.flatnonzero(at_step == step):
            masses[i] = a.sum() * dx, b.sum() * dx, c.sum() * dx

    def half_reaction():
        nonlocal a, b, c
        a, b, made = reaction.react(a, b, 0.5 * dt)
        c = c + made

    def conserved():
        return float(a.sum() + c.sum()), float(b.sum() + (c.sum() if reaction.CONSUMES_B else 0.0))

    record(0)
    totals = conserved()
    size = float(a.sum() + b.sum())
    for step in range(1, n_steps + 1):
        half_reaction()
        a, b, c = diffuse.step(a), diffuse.step(b), diffuse.step(c)
        half_reaction()
        now = conserved()
        _check_totals(totals, now, size, a.size, step)
        totals = now
        record(step)
    return Fields(x, a, b, c, dx, dt, int(n_steps), times, masses)


@dataclass(frozen=True)
class Richardson:
    """A quantity extrapolated from three grids refined by ``ratio``: the ``value``, the ``error``
    estimate of it, the observed ``order`` p, whether p lies in ORDER_BAND (``asymptotic``: only then
    is the value extrapolated) and the three grids' ``values`` (coarse, medium, fine). Arrays where
    the quantity is one."""

    value: np.ndarray | float
    error: np.ndarray | float
    order: np.ndarray | float
    values: tuple
    asymptotic: np.ndarray | bool = True


def richardson(coarse, medium, fine, ratio: float = 2.0) -> Richardson:
    """Richardson extrapolation from three grids: p = ln((f_1 - f_2) / (f_2 - f_3)) / ln(ratio); where
    p lies in ORDER_BAND (asymptotic), f = f_3 + (f_3 - f_2) / (ratio^p - 1), error |f_3 - f_2| /
    (ratio^p - 1). Elsewhere the grids are not in the asymptotic range and the value is f_3: its
    error |f_3 - f_2| / min(1, ratio^p - 1) where the differences shrink (p > 0), and
    max(|f_1 - f_2|, |f_2 - f_3|) where they change sign or do not shrink (p NaN)."""
    f1, f2, f3 = (np.asarray(f, dtype=np.float64) for f in (coarse, medium, fine))
    d12, d23 = f1 - f2, f2 - f3
    lo, hi = ORDER_BAND
    with np.errstate(divide="ignore", invalid="ignore"):
        q = d12 / d23
        monotone = np.isfinite(q) & (q > 1.0)
        p = np.where(monotone, np.log(np.where(monotone, q, 2.0)) / math.log(ratio), np.nan)
        asymptotic = monotone & (p >= lo) & (p <= hi)
        gain = np.where(monotone, ratio**p - 1.0, 1.0)
        value = np.where(asymptotic, f3 - d23 / gain, f3)
        slow = np.abs(d23) / np.minimum(gain, 1.0)
        error = np.where(asymptotic, np.abs(d23) / gain, np.where(monotone, slow, np.maximum(np.abs(d12), np.abs(d23))))
    exact = (d12 == 0.0) & (d23 == 0.0)  # every grid the same (a decay's mass): exact, nothing to extrapolate
    asymptotic = asymptotic | exact

    def out(z):
        return z.item() if z.ndim == 0 else z

    return Richardson(out(value), out(error), out(p), (out(f1), out(f2), out(f3)), out(asymptotic))


@dataclass(frozen=True)
class ReactiveReference:
    """A reactive scene's reference at t_final: the product mass M_C and the concentrations of A and
    C at the points (lab frame), each a Richardson over the three grids, the finest grid's Fields, the
    seconds each grid's solve took, and the Plan it ran."""

    product_mass: Richardson
    a_points: Richardson
    c_points: Richardson
    fine: Fields
    seconds: tuple[float, ...]
    plan: Plan | None = None


def at_points(points, x: np.ndarray, c: np.ndarray) -> np.ndarray:
    """c at ``points`` by 4-point Lagrange (cubic) interpolation on the uniform cells x: error
    O(dx^4), below the solve's O(dx^2), so that it does not blur Richardson's observed order (linear
    interpolation's error s (1 - s) dx^2 c'' / 2 jumps with the point's place s in its cell)."""
    points = np.asarray(points, dtype=np.float64)
    dx = x[1] - x[0]
    u = (points - x[0]) / dx
    i = np.clip(np.floor(u).astype(np.int64) - 1, 0, x.size - 4)  # the stencil i .. i + 3
    s = u - i  # the point's place on the stencil's nodes 0, 1, 2, 3
    w = np.stack(
        [
            -(s - 1) * (s - 2) * (s - 3) / 6,
            s * (s - 2) * (s - 3) / 2,
            -s * (s - 1) * (s - 3) / 2,
            s * (s - 1) * (s - 2) / 6,
        ]
    )
    return np.sum(w * c[i[None, :] + np.arange(4)[:, None]], axis=0)


def window(sources, D: float, t_final: float) -> tuple[float, float]:
    """(lo, hi) reaching REACH final spreads sqrt(2 D t_final) beyond every source's half width [L]."""
    reach = REACH * math.sqrt(2.0 * D * t_final)
    lo = min(s.centre - s.half_width for s in sources) - reach
    hi = max(s.centre + s.half_width for s in sources) + reach
    return lo, hi


def edges(source: Source) -> tuple[float, ...]:
    """Where the source's concentration jumps: a box's ends a and b; none for the smooth kinds [L]."""
    return (float(source.a), float(source.b)) if isinstance(source, Box) else ()


def aligned_grid(sources, D: float, t_final: float, n_cells: int = COARSE_CELLS) -> tuple[float, float, int]:
    """(lo, hi, n): about n_cells cells of width dx <= that of ``window``'s n_cells, covering it, with
    every source edge on a cell face, lo + j dx: then on the faces of every grid refined by 2, whose
    cell masses then converge at second order (an edge inside a cell puts a first-order, grid-dependent
    error into the initial masses). Without edges, or where no dx within ALIGN_SLACK n_cells cells puts
    them all on faces (incommensurate ends), ``window`` itself."""
    lo0, hi0 = window(sources, D, t_final)
    cuts = sorted({e for s in sources for e in edges(s)})
    if not cuts:
        return lo0, hi0, n_cells
    dx0, span = (hi0 - lo0) / n_cells, cuts[-1] - cuts[0]
    least = max(1, math.ceil(span / dx0 * (1.0 - 1e-12)))
    for m in range(least, math.floor(ALIGN_SLACK * least) + 2):  # m cells between the outermost edges
        dx = span / m if span > 0 else dx0
        units = [(e - cuts[0]) / dx for e in cuts]
        if all(abs(u - round(u)) <= 1e-9 * max(1.0, u) for u in units):
            below = math.ceil((cuts[0] - lo0) / dx * (1.0 - 1e-12))
            above = math.ceil((hi0 - cuts[-1]) / dx * (1.0 - 1e-12))
            n = below + m + above
            if n <= ALIGN_SLACK * n_cells:
                lo = cuts[0] - below * dx
                return lo, lo + n * dx, n
    return lo0, hi0, n_cells


def initial_fields(x: np.ndarray, dx: float, source_a: Source, mass_a: float, b) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) on cells at x: mass_a of source_a as cell masses over dx (Source.masses); B the same
    for ``b`` = (Source, mass), or the uniform concentration ``b`` = C0."""
    a = mass_a * source_a.masses(x, dx) / dx
    if isinstance(b, tuple):
        source_b, mass_b = b
        return a, mass_b * source_b.masses(x, dx) / dx
    return a, np.full_like(x, float(b))


@dataclass(frozen=True)
class Plan:
    """What a reference will run, known before it runs: the window [lo, hi], the coarsest grid's
    cells and steps (each finer grid doubles both), the steps that r <= COARSE_R and the kinetic rule
    asked for (``by_r``, ``by_kinetics``), and whether the sources' edges sit on cell faces."""

    lo: float
    hi: float
    n_cells: int
    n_steps: int
    by_r: float
    by_kinetics: float
    aligned: bool

    @property
    def work(self) -> int:
        """Cell-steps over the three grids, each step counting STEP_CELLS more: sum of s_l (n_l + STEP_CELLS)."""
        return sum(self.n_steps * 2**level * (self.n_cells * 2**level + STEP_CELLS) for level in range(3))

    @property
    def seconds(self) -> float:
        """The solve's estimated time: work times SECONDS_PER_CELL_STEP [s]."""
        return self.work * SECONDS_PER_CELL_STEP

    @property
    def capped(self) -> bool:
        """Whether the kinetic rule asked for more steps than MAX_WORK allows (Richardson's error
        estimate then carries the splitting error the cap leaves)."""
        return self.by_kinetics > self.n_steps

    def describe(self) -> str:
        """The plan in words: cells, steps, work and estimated seconds on the finest of three grids."""
        return (
            f"{4 * self.n_cells:,} cells x {4 * self.n_steps:,} steps on the finest of three grids, "
            f"{self.work:.3g} cell-steps in all, ~{self.seconds:.3g} s"
        )


class CostError(ValueError):
    """A reference whose plan exceeds the work it may take (MAX_WORK), refused before it runs."""

    def __init__(self, plan: Plan, max_work: float):
        self.plan, self.max_work = plan, max_work
        super().__init__(
            f"the reference would take {plan.describe()}, above the bound of {max_work:.3g} cell-steps "
            f"(~{max_work * SECONDS_PER_CELL_STEP:.3g} s)"
        )


def plan(
    source_a: Source,
    b,
    D: float,
    reaction,
    t_final: float,
    *,
    mass_a: float = 1.0,
    bounds: tuple[float, float] | None = None,
    n_cells: int = COARSE_CELLS,
    n_steps: int | None = None,
    max_work: float | None = None,
) -> Plan:
    """The plan of ``reference`` with the same arguments, from the physics alone (no solve). Its
    window is ``bounds`` on n_cells, else ``aligned_grid``; its steps, unless given, make r <= COARSE_R
    and dt <= COARSE_KINETIC fastest reaction times on the coarsest grid, the kinetic rule capped so
    that the work stays within max_work (default MAX_WORK; the kinetics are exact within a step, so the kinetic rule
    bounds only the splitting error, which Richardson's estimate then states); r's rule is never cut."""
    max_work = MAX_WORK if max_work is None else max_work
    sources = [source_a] + ([b[0]] if isinstance(b, tuple) else [])
    if bounds is not None:
        lo, hi = bounds
    else:
        lo, hi, n_cells = aligned_grid(sources, D, t_final, n_cells)
    x, dx = cell_centres(lo, hi, n_cells)
    cuts = [e for s in sources for e in edges(s)]
    aligned = all(abs((e - lo) / dx - round((e - lo) / dx)) <= 1e-9 * max(1.0, abs(e - lo) / dx) for e in cuts)
    a0, b0 = initial_fields(x, dx, source_a, mass_a, b)
    by_r = D * t_final / (COARSE_R * dx * dx)
    by_kinetics = t_final * reaction.fastest_rate(a0, b0) / COARSE_KINETIC
    if n_steps is None:
        per_step = sum(2**level * (n_cells * 2**level + STEP_CELLS) for level in range(3))
        allowed = max(1.0, math.floor(max_work / per_step))
        n_steps = max(1, math.ceil(max(by_r, min(by_kinetics, allowed))))
    return Plan(float(lo), float(hi), int(n_cells), int(n_steps), float(by_r), float(by_kinetics), aligned)


def reference(
    source_a: Source,
    b,
    D: float,
    reaction,
    t_final: float,
    points=(),
    *,
    mass_a: float = 1.0,
    v: float = 0.0,
    bounds: tuple[float, float] | None = None,
    n_cells: int = COARSE_CELLS,
    n_steps: int | None = None,
    times_per_run: int = 0,
    max_work: float | None = None,
) -> ReactiveReference:
    """The reference of a reactive scene at t_final: ``solve`` on the ``plan``'s grids, n, 2 n and 4 n
    cells (s, 2 s and 4 s steps), each quantity extrapolated by ``richardson``; A from mass_a of
    source_a, B from ``b`` as in initial_fields, points in the lab frame (the grid moves with v),
    concentrations interpolated by ``at_points``. CostError, before any step, where the plan's work
    exceeds max_work. ``times_per_run`` > 0 records the masses at that many equal times in
    (0, t_final] on every grid (the fine one's in ``fine.masses``)."""
    how = plan(
        source_a,
        b,
        D,
        reaction,
        t_final,
        mass_a=mass_a,
        bounds=bounds,
        n_cells=n_cells,
        n_steps=n_steps,
        max_work=max_work,
    )
    max_work = MAX_WORK if max_work is None else max_work
    if how.work > max_work:
        raise CostError(how, max_work)
    points = np.asarray(points, dtype=np.float64) - v * t_final
    runs, seconds = [], []
    for level in range(3):
        x, dx = cell_centres(how.lo, how.hi, how.n_cells * 2**level)
        a0, b0 = initial_fields(x, dx, source_a, mass_a, b)
        start = time.perf_counter()
        steps = how.n_steps * 2**level
        times = t_final / steps * np.linspace(0, steps, times_per_run + 1)[1:].round() if times_per_run else ()
        runs.append(solve(x, a0, b0, D, reaction, t_final, steps, times))
        seconds.append(time.perf_counter() - start)
    mass = richardson(*(f.product_mass for f in runs))
    a_pts = richardson(*(at_points(points, f.x, f.a) for f in runs))
    c_pts = richardson(*(at_points(points, f.x, f.c) for f in runs))
    return ReactiveReference(mass, a_pts, c_pts, runs[-1], tuple(seconds), how)
