"""2-D shear flow with spatially variable, anisotropic dispersion (Appendix B, Fig. 10).

Domain 0 < x < length (periodic in x), 0 < y < 1 (walls). Velocity v_y = 0,
v_x = y - y^2 (Poiseuille, zero at both walls) and dispersion tensor
D(y) = diag(alpha_L v_x, alpha_T v_x), so D -> 0 at the walls. A strip
strip_lo < x < strip_hi carries concentration 1 / (strip_hi - strip_lo) (mass 1), spread in
equal shares over the particles that start inside it. Three ways to disperse it, each on top
of advection by v_x (with periodic wrap in x):

``rw_nodrift``  random walks dX = v dt + B sqrt(2 dt) xi, B B^T = D(X), no drift term;
``rw_drift``    the same plus the Ito drift div D = (0, alpha_T (1 - 2y)) (Eq. 1 of the paper's
                Introduction: particles must be pseudo-advected by v + div D);
``mt``          no random walk: masses exchange by Eq. 16 with the collision kernel of Eq. 17
                written with the pair-averaged tensor D_ij = (D_i + D_j) / 2.

Walkers reflect at the walls (y -> -y below 0, 2 - y above 1). This module keeps only the flow
(``velocity``, ``dispersion``), the walls and the run; the steps are the shared ones of every
model: the walk of models/walk.py on (N, 2) positions, the pairs of numerics/neighbours.py and the
transfer of numerics/pair_transfer.py with per-particle tensors.

The tables before these steps were shared (commit 5399db0): the walks are the same bits, since
``walk`` draws xi as one (2, N) array, x's row first, as the shear's own walk did, and adds v dt,
the step and the drift in its order (tests/test_shear2d.py holds them to frozen values). ``mt``
is not the same bits, and cannot be while the transfer is the shared one: its pair tensor is
(D_i + D_j)/2 of each particle's tensor, whose entries round as 0.5 (alpha v_i + alpha v_j)
rather than alpha (v_i + v_j)/2, its weights keep the factor 1/sqrt(alpha_L alpha_T) that the
old weights dropped, and its exponent sums dx^2/D_xx + dy^2/D_yy per pair. The positions of
``mt`` take no random draws after the start, so the difference stays round-off: the same pairs
and substeps, and, over the paper's 500 steps, masses, mean y and wall fractions within 4e-16 of
the old ones (a test holds a small run to frozen values, relative 1e-12).

Units: lengths [L], times [T], masses dimensionless (total 1). What the columns of the result
tables mean is in pipeline/columnsdoc.py (``SHEAR_STEP_COLUMNS``, ``SHEAR_STATE_COLUMNS``), which
the shear job does not import, so editing a description does not rerun it.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..core.records import Recorder
from ..core.registry import SHEAR_CASES
from ..core.run_settings import defaults
from ..core.runconfig import SettingError, check_range, check_setting
from ..core.shear_settings import SHEAR
from ..core.timegrid import MAX_STEPS
from ..numerics.neighbours import pairs_within
from .walk import walk

if TYPE_CHECKING:
    import pandas as pd

WALL_BAND = 0.05  # width of the near-wall band of ``wall_fraction`` [L]
V_MAX = 0.25  # max of y - y^2 on [0, 1] [L/T]
KERNEL_TOL = 1e-16  # neglected kernel weights are below this fraction of a self weight
# a step's dispersion, sqrt(2 alpha v_max dt) (its standard deviation where v_x is largest), may be at
# most this fraction of the room it moves in: the channel's width 1 in y, the periodic length in x. The
# Ito-Euler walk (and the drift alpha_T (1 - 2y) dt, at most alpha_T dt, smaller still) assumes that D
# changes little over a step; D_yy = alpha_T v_x goes from 0 at a wall to its largest at y = 1/2, so a
# step must be well below the channel. The paper's is 0.022 (alpha_T = 1e-3, dt = 1): a tenth allows
# alpha_T dt <= 0.02, 20 times it. A step as wide as the channel folds every walker onto a wall.
STEP_FRACTION = 0.1
PERIODIC_X = np.array([1.0, 0.0])  # times length: the periods of x and y (0: y is walled, not periodic)


SHEAR_DEFAULTS = defaults(SHEAR)  # settings.SHEAR: each field's default, range and meaning


@dataclass(frozen=True)
class ShearConfig:
    """One shear run: a case of SHEAR_CASES and the settings of config `shear` (settings.SHEAR)."""

    case: str = "mt"
    n: int = SHEAR_DEFAULTS["n"]  # particles, uniform over the whole domain
    length: float = SHEAR_DEFAULTS["length"]  # periodic domain length in x [L]
    strip_lo: float = SHEAR_DEFAULTS["strip_lo"]  # initial strip strip_lo < x < strip_hi [L]
    strip_hi: float = SHEAR_DEFAULTS["strip_hi"]
    alpha_L: float = SHEAR_DEFAULTS["alpha_L"]  # longitudinal dispersivity [L]
    alpha_T: float = SHEAR_DEFAULTS["alpha_T"]  # transverse dispersivity [L]
    dt: float = SHEAR_DEFAULTS["dt"]  # [T]
    t_final: float = SHEAR_DEFAULTS["t_final"]  # [T]
    beta: float = SHEAR_DEFAULTS["beta"]  # mass-transfer coefficient of Eq. 16
    seed: int = SHEAR_DEFAULTS["seed"]

    def __post_init__(self):
        self.check()

    def check(self) -> None:
        """Raise SettingError naming the first setting outside its allowed range (settings.SHEAR),
        then the rules between them: the strip inside the domain, whole steps, the kernel in the box."""
        if self.case not in SHEAR_CASES:
            raise SettingError("case", self.case, f"one of {', '.join(SHEAR_CASES)}")
        for s in SHEAR:
            if s.name != "cases":
                check_setting(s, getattr(self, s.name))
        check_range("strip_lo", self.strip_lo, 0.0, self.length)
        check_range("strip_hi", self.strip_hi, self.strip_lo, self.length, open_low=True)
        steps = self.t_final / self.dt
        if abs(steps - round(steps)) > 1e-9 * max(1.0, steps):
            raise SettingError("t_final", self.t_final, f"a whole number of steps dt={self.dt!r}")
        if steps > MAX_STEPS:
            raise SettingError(
                "dt", self.dt, f"at most {MAX_STEPS:,} steps to t_final: dt >= {self.t_final / MAX_STEPS:.3g}"
            )
        for name, room in (("alpha_T", 1.0), ("alpha_L", self.length)):
            alpha = getattr(self, name)
            limit = (STEP_FRACTION * room) ** 2 / (2.0 * V_MAX * self.dt)
            if alpha > limit:
                where = "the channel's width 1" if name == "alpha_T" else f"length = {self.length:g}"
                raise SettingError(
                    name,
                    alpha,
                    f"a number in [0, {limit:.6g}] for dt = {self.dt:g}: a step's dispersion sqrt(2 {name} v_max dt) "
                    f"(v_max = {V_MAX:g}) at most {STEP_FRACTION:g} x {where}",
                )
        if self.case == "mt" and self.length / math.sqrt(self.alpha_L) <= 2.0 * kernel_cutoff(self):
            # the minimum-image distance in x is only exact while the kernel fits in half the box
            raise SettingError(
                "length",
                self.length,
                f"for mt > 2 sqrt(alpha_L) kernel_cutoff = {2.0 * math.sqrt(self.alpha_L) * kernel_cutoff(self):.4g}",
            )

    @property
    def n_steps(self) -> int:
        return int(round(self.t_final / self.dt))

    def rng(self) -> np.random.Generator:
        """Generator keyed by (seed, case); no global state."""
        ss = np.random.SeedSequence(entropy=int(self.seed), spawn_key=(zlib.crc32(self.case.encode()),))
        return np.random.default_rng(ss)

    def case_columns(self) -> dict:
        """The case parameters written beside every row of the step table."""
        d = asdict(self)
        return {"case": d.pop("case"), "seed": int(d.pop("seed")), **{k: v for k, v in d.items()}}


# ---------------------------------------------------------------- flow and dispersion


def velocity(y: np.ndarray) -> np.ndarray:
    """Poiseuille velocity v_x = y - y^2 (Appendix B) [L/T], clipped at 0 against round-off."""
    return np.maximum(y - y * y, 0.0)


def dispersion(y: np.ndarray, cfg: ShearConfig) -> np.ndarray:
    """D(y) = diag(alpha_L v_x, alpha_T v_x) of each particle as (N, 2) diagonals [L^2/T]."""
    return velocity(y)[:, None] * np.array([cfg.alpha_L, cfg.alpha_T])


def initial_state(cfg: ShearConfig, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Uniform positions (N, 2) over the domain; mass 1 shared equally by the particles in the strip."""
    x = rng.uniform(0.0, cfg.length, cfg.n)
    y = rng.uniform(0.0, 1.0, cfg.n)
    inside = (x > cfg.strip_lo) & (x < cfg.strip_hi)
    m = np.zeros(cfg.n)
    if inside.any():
        m[inside] = 1.0 / inside.sum()
    return np.column_stack([x, y]), m


def reflect(y: np.ndarray) -> np.ndarray:
    """Fold y into [0, 1] by mirror reflection at the walls y = 0 and y = 1."""
    y = np.mod(y, 2.0)
    return np.where(y > 1.0, 2.0 - y, y)


def walls(pos: np.ndarray, cfg: ShearConfig) -> np.ndarray:
    """Positions (N, 2) wrapped into 0 <= x < length and reflected into 0 <= y <= 1."""
    return np.column_stack([np.mod(pos[:, 0], cfg.length), reflect(pos[:, 1])])


def random_walk_step(pos, cfg: ShearConfig, rng: np.random.Generator, drift: bool) -> np.ndarray:
    """One Ito-Euler step dX = (v + [div D]) dt + B sqrt(2 dt) xi of ``walk.walk`` with B B^T = D(y),
    then the walls.

    div D = (0, alpha_T (1 - 2y)) for D = diag(alpha_L v_x(y), alpha_T v_x(y)); B is finite
    (zero) at the walls, so no NaN arises there.
    """
    y = pos[:, 1]
    v = np.column_stack([velocity(y), np.zeros(y.size)])
    a = np.column_stack([np.zeros(y.size), cfg.alpha_T * (1.0 - 2.0 * y)]) if drift else None
    return walls(walk(pos, dispersion(y, cfg), cfg.dt, rng, v, a), cfg)


# ---------------------------------------------------------------- mass transfer


def kernel_cutoff(cfg: ShearConfig, v_max: float = V_MAX) -> float:
    """Cut-off s_c in scaled distance s^2 = dx^2/alpha_L + dy^2/alpha_T for the kernel of Eq. 17.

    The pair's D_ij = vbar diag(alpha_L, alpha_T) with vbar = (v_i + v_j)/2 >= v_i/2 gives
    W_ij / W_ii = (v_i / vbar) exp(-s^2 / (8 vbar dt)) (numerics/pair_transfer.py), so a pair
    beyond s_c has W_ij / W_ii <= 2 exp(-s_c^2 / (8 v_max dt)) = KERNEL_TOL, and each neglected
    P_ij is below 1e-16 of the row and column sums it is normalised by.
    """
    return math.sqrt(8.0 * v_max * cfg.dt * math.log(2.0 / KERNEL_TOL))


def transfer_directions(cfg: ShearConfig) -> int:
    """The directions the transfer acts in: x and y, or x alone when alpha_T = 0 (the kernel is then
    a delta in y, and a pair exchanges only at equal y)."""
    return 2 if cfg.alpha_T > 0 else 1


def neighbour_pairs(pos, cfg: ShearConfig, cutoff: float) -> np.ndarray:
    """Pairs (i, j), i < j, with scaled distance <= cutoff, periodic in x: an (n_pairs, 2) array
    (numerics/neighbours.py on (x/sqrt(alpha_L), y/sqrt(alpha_T)), x alone when alpha_T = 0)."""
    d = transfer_directions(cfg)
    scale = 1.0 / np.sqrt([cfg.alpha_L, cfg.alpha_T][:d])
    return pairs_within(pos[:, :d], cutoff, scale=scale, period=PERIODIC_X[:d] * cfg.length)


def transfer_step(pos, m, cfg: ShearConfig, cutoff: float | None = None):
    """One step of Eq. 16 by numerics/pair_transfer.py, Eq. 17 with D_ij = (D_i + D_j)/2 of the
    particles' D(y) over the pairs within ``cutoff``: Returns (m, substeps, max_offdiag_beta, n_pairs).

    A particle on a wall (v_i = 0, D_i = 0) has an infinite self weight, so it exchanges only
    through the column-normalised half of P, with partners of finite D_ij; without such partners
    it is isolated. With alpha_T = 0 the pairs at dy != 0 get weight 0.
    """
    from ..numerics import pair_transfer as pt  # numba: loaded by the jobs that step, not by plots

    if cutoff is None:
        cutoff = kernel_cutoff(cfg)
    d = transfer_directions(cfg)
    pairs = neighbour_pairs(pos, cfg, cutoff)
    tensors = dispersion(pos[:, 1], cfg)[:, :d]  # per-particle diagonals
    w = pt.pair_weights(pos[:, :d], tensors, pairs, cfg.dt, period=PERIODIC_X[:d] * cfg.length)
    if d == 1:
        w[pos[pairs[:, 0], 1] != pos[pairs[:, 1], 1]] = 0.0
    m, substeps, c_max = pt.transfer(pairs, w, pt.self_weights(tensors), m, cfg.beta)
    return m, substeps, c_max, int(pairs.shape[0])


# ---------------------------------------------------------------- driver


def wall_fraction(y: np.ndarray, weights: np.ndarray | None = None) -> float:
    """Fraction of particles (or of ``weights``) within WALL_BAND of y = 0 or y = 1."""
    near = (y < WALL_BAND) | (y > 1.0 - WALL_BAND)
    if weights is None:
        return float(near.mean())
    return float(weights[near].sum() / weights.sum())


def run_shear(
    cfg: ShearConfig,
    progress: Callable[[str], None] | None = None,
    init: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Run one case of Appendix B to t_final; returns (per-step table, final particle table).

    ``init`` = (x, y, mass) replaces the random initial condition (tests, constructed cases).
    """
    cfg.check()
    rng = cfg.rng()
    if init is None:
        pos, m = initial_state(cfg, rng)
    else:
        x, y, m = (np.array(a, dtype=np.float64, copy=True) for a in init)
        if not (np.all((y >= 0) & (y <= 1)) and np.all(m >= 0) and x.shape == y.shape == m.shape):
            raise SettingError("init", "(x, y, mass)", "equal-length arrays with 0 <= y <= 1 and mass >= 0")
        pos = np.column_stack([np.mod(x, cfg.length), y])
    is_mt = cfg.case == "mt"
    cutoff = kernel_cutoff(cfg) if is_mt else math.nan
    rec = Recorder(cfg.case_columns(), cfg.n_steps, progress)

    def record(step, substeps=0, c_max=0.0, n_pairs=0):
        y = np.ascontiguousarray(pos[:, 1])
        if is_mt:
            total = m.sum()
            mean_y = float(np.dot(m, y) / total) if total > 0 else math.nan
            wf = wall_fraction(y, m) if total > 0 else math.nan
        else:
            mean_y, wf = float(y.mean()), wall_fraction(y)
        rec.add(
            step=step,
            time=step * cfg.dt,
            mass_total=float(m.sum()),
            mass_min=float(m.min()),
            wall_fraction=wf,
            mean_y=mean_y,
            substeps=substeps,
            max_offdiag_beta=c_max,
            n_pairs=n_pairs,
        )

    record(0)
    for step in range(1, cfg.n_steps + 1):
        if is_mt:
            pos[:, 0] = np.mod(pos[:, 0] + velocity(pos[:, 1]) * cfg.dt, cfg.length)
            m, substeps, c_max, n_pairs = transfer_step(pos, m, cfg, cutoff)
            record(step, substeps, c_max, n_pairs)
        else:
            pos = random_walk_step(pos, cfg, rng, drift=cfg.case == "rw_drift")
            record(step)
    steps = rec.table().to_pandas()
    import pandas as pd  # here: the workflow's parse imports this module to check the shear section

    state = pd.DataFrame({"x": pos[:, 0], "y": pos[:, 1], "mass": m, "case": cfg.case, "seed": int(cfg.seed)})
    return steps, state
