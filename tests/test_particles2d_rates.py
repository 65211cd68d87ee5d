"""Physics of the 2-D particle models that can fail (issue 52 point 5, the particle half): MTPT's and
PT's errors against the exact plume (core/reference2d.py) fall with N at measured rates, their
entropies do not change when the scene is turned, MTPT conserves mass to round-off over many steps
and one exchange at N = 100,000 stays within a stated memory bound.

The scene (one for every test here): a Gaussian source of s.d. 0.1 along each axis at the origin,
carried by v = 0.02 (cos theta, sin theta) [L/T] and spread by D_L = 5e-4, D_T = 5e-5 [L^2/T]
(D_L / D_T = 10, D_L along v) to t = 10 [T], so that the plume's variance grows from 0.01 to 0.02
along the flow and to 0.011 across it and its centre moves by 0.2; theta = 0 and 30 degrees are the
same scene turned. MTPT: N particles uniform on the square [-1, 1]^2 (Omega = 2, dV = Omega^2 / N),
masses the source's density times dV normalised to 1, ten steps of the exchange with eta = 1 (so no
walk; the flow shifts every particle by v dt exactly), scored by m / dV interpolated
(mtpt_concentration_2d) at Reference2D.points(). PT: N particles drawn from the source and walked
to t in one step (exact for uniform v and D), scored by kde_2d with plume_bandwidth_2d of the exact
covariance. The error is the RMS difference at the 15 x 15 points over the exact peak.

The rates quoted were measured with these helpers (mtpt_run, pt_run, slope) over 16 seeds that the
tests do not use; a quoted SE is the standard error of the mean of the 16 per-seed slopes.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from particle_entropy.core.reference2d import Reference2D
from particle_entropy.core.sources2d import Source2D, dispersion_tensor
from particle_entropy.models.walk import walk
from particle_entropy.numerics.particles2d import (
    kde_2d,
    mtpt_concentration_2d,
    mtpt_exchange_2d,
    plume_bandwidth_2d,
)

LIB = Path(__file__).resolve().parents[1] / "workflow" / "lib"

SIDE = 2.0  # Omega [L]: the particles' square [-1, 1]^2 holds the final plume to beyond 5 s.d.
SOURCE = Source2D.of("gaussian", x0=[0.0, 0.0], sd=[0.1, 0.1])
D_L, D_T = 5.0e-4, 5.0e-5  # [L^2/T], D_L / D_T = 10
SPEED = 0.02  # [L/T]
T_FINAL, STEPS = 10.0, 10  # [T]; dt = 1: the exchange kernel's s.d. along the flow sqrt(4 D_L dt) = 0.045
NS = (1000, 2000, 4000, 8000, 16000)
Z = 3.0  # standard errors allowed between two means that should agree


def scene(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """(v, D) of the scene turned by ``theta`` degrees: D_L along v, D_T across it."""
    a = math.radians(theta)
    v = SPEED * np.array([math.cos(a), math.sin(a)])
    return v, dispersion_tensor(v, {"L": D_L, "T": D_T})


def reference(theta: float, t: float = T_FINAL) -> Reference2D:
    v, D = scene(theta)
    return Reference2D(SOURCE, D, v, t)


def rmse_over_peak(c, exact) -> float:
    return math.sqrt(np.mean((c - exact) ** 2)) / exact.max()


def mtpt_run(n: int, seed: int, theta: float, cutoff_sds: float | None = None, D=None, score: bool = True):
    """MTPT of the scene at ``theta`` with N particles -> (error, or nan without ``score``; H_C = -sum
    p ln p; masses; initial total). ``D`` replaces the scene's tensor in the exchange only (a
    deliberately wrong model). ``score=False`` skips the interpolation where only H_C is wanted."""
    v, D_true = scene(theta)
    D_model = D_true if D is None else D
    rng = np.random.default_rng([seed, n])
    x = rng.uniform(-SIDE / 2, SIDE / 2, (n, 2))
    dV = SIDE * SIDE / n
    m = reference(theta, 0.0).density(x) * dV
    m = m / m.sum()
    total = m.sum()
    dt = T_FINAL / STEPS
    kw = {} if cutoff_sds is None else {"cutoff_sds": cutoff_sds}
    for _ in range(STEPS):
        x = x + v * dt  # eta = 1: no walk; uniform flow carried exactly
        m = mtpt_exchange_2d(x, m, D_model, 1.0, dt, **kw).mass
    err = math.nan
    if score:
        ref = reference(theta)
        p = ref.points()
        err = rmse_over_peak(mtpt_concentration_2d(p, x, m, dV), ref.density(p))
    q = m / m.sum()
    q = q[q > 0.0]
    return err, float(-(q * np.log(q)).sum()), m, total


def pt_run(n: int, seed: int, theta: float, entropy: bool = False) -> tuple[float, float]:
    """PT of the scene at ``theta`` with N particles -> (error, H = -(1/N) sum_i ln c(x_i) if
    ``entropy`` else nan): the entropy of the kernel estimate resubstituted at the particles
    themselves (self term included), which sees no grid and so no orientation."""
    v, D = scene(theta)
    rng = np.random.default_rng([seed, n, 1])
    x = walk(SOURCE.positions(n, rng), D[None], T_FINAL, rng, v)
    ref = reference(theta)
    H = plume_bandwidth_2d(n, ref.covariance)
    p = ref.points()
    err = rmse_over_peak(kde_2d(p, x, H), ref.density(p))
    return err, float(-np.mean(np.log(kde_2d(x, x, H)))) if entropy else math.nan


def slope(ns, errors) -> tuple[float, float]:
    """(slope of log mean error against log N, largest residual of that fit); ``errors`` holds one
    sequence of runs' errors per N (as many seeds as wanted)."""
    y = np.log([np.mean(e) for e in errors])
    fit = np.polyfit(np.log(ns), y, 1)
    return float(fit[0]), float(np.abs(y - np.polyval(fit, np.log(ns))).max())


def mtpt_errors(theta: float, seeds: tuple[int, ...], ns: tuple[int, ...] = NS) -> np.ndarray:
    return np.array([[mtpt_run(n, s, theta)[0] for s in seeds] for n in ns])


# ---------------------------------------------------------------- MTPT: the error's rate in N


def test_mtpt_error_falls_with_n_at_the_measured_rate():
    """Measured over 16 seeds (1000-1015) and N = 1,000 .. 16,000 at the default 6 s.d. cut-off:
    the slope of log mean RMSE against log N is -0.453 (theta = 0) and -0.456 (30 degrees); the
    per-seed slopes' mean -0.435 +- 0.040 and -0.441 +- 0.039 (SE; their s.d. 0.16). The error is
    sampling noise of the random layout (its s.d. between seeds is 15-50 % of the mean) and the
    exchange's under-dispersion 1 / (1 + n_K), n_K the particles a kernel holds (proportional to N),
    so neither a dt floor nor a fixed bias stops it here (over 8 other seeds the slope to N = 32,000
    is -0.50 and -0.49, the slow test below). Here 8 seeds at N <= 4,000, 6 at 8,000 and
    4 at 16,000 (the small runs are cheap and the noisiest): measured slope -0.49 (theta = 0) and
    -0.50 (30), largest residual of the fit 0.17 and 0.11. The slope of such a set scatters by
    ~0.08, so the band [-0.75, -0.2] lies 3 of those around -0.45 and excludes 0 (no convergence).
    The fit is asserted stable: no mean more than 0.3 (in log) off the fitted line, the error at
    16,000 below half that at 1,000, and the two orientations' slopes (same layouts) within 0.2.
    ~15 s on an idle two-core Xeon, 34 s at load 4 under pytest's two workers."""
    seeds = {1000: 8, 2000: 8, 4000: 8, 8000: 6, 16000: 4}
    slopes = []
    for theta in (0.0, 30.0):
        err = [[mtpt_run(n, s, theta)[0] for s in range(seeds[n])] for n in NS]
        b, worst = slope(NS, err)
        means = [np.mean(e) for e in err]
        assert -0.75 < b < -0.2, (theta, b, means)
        assert worst < 0.3, (theta, worst, means)
        assert means[-1] < 0.5 * means[0], means
        slopes.append(b)
    assert abs(slopes[0] - slopes[1]) < 0.2, slopes


@pytest.mark.slow
def test_mtpt_error_rate_with_more_seeds_and_n_to_32000():
    """Eight seeds and N up to 32,000 (about 2 minutes unloaded, 3.5 loaded): the slope of the means
    within 0.15 of the measured -0.45, and the per-seed slopes' mean within 3 of their standard
    errors of it."""
    ns = NS + (32000,)
    seeds = tuple(range(100, 108))
    for theta in (0.0, 30.0):
        err = mtpt_errors(theta, seeds, ns)
        b, _ = slope(ns, err)
        assert abs(b + 0.45) < 0.15, (theta, b, err.mean(axis=1))
        per_seed = np.array([np.polyfit(np.log(ns), np.log(err[:, k]), 1)[0] for k in range(len(seeds))])
        se = per_seed.std(ddof=1) / math.sqrt(len(seeds))
        assert abs(per_seed.mean() + 0.45) < max(Z * se, 0.05), (theta, per_seed)


def test_the_default_cut_off_leaves_the_error_unchanged_below_its_noise():
    """The exchange's default 6 s.d. (particles2d.EXCHANGE_CUTOFF_SIGMAS) against the untruncated
    9: the same runs' RMSE differ by less than 1e-5 of it. Measured at N = 16,000 over 8 seeds
    (1000-1007, theta = 30): RMSE 0.019244 (SE between seeds 0.0014) at 6, 7, 8 and 9 s.d.; the
    paired change from 9 at most 8.9e-9 (6 s.d.), 1.6e-11 (7) and 1.0e-14 (8), each step dropping
    exp(-k^2 / 2) of the kernel (1.5e-8 at 6). Here N = 4,000, two seeds: the test fails at a
    cut-off that cuts into the kernel (3 s.d. drops 1.1 % of it and moves the RMSE by 0.9-4.7 %;
    6 s.d. moves it by 1.2e-7 and 6.8e-8 of it)."""
    for seed in (0, 1):
        e6 = mtpt_run(4000, seed, 30.0)[0]
        e9 = mtpt_run(4000, seed, 30.0, cutoff_sds=9.0)[0]
        assert abs(e6 - e9) < 1e-5 * e9, (seed, e6, e9)
        e3 = mtpt_run(4000, seed, 30.0, cutoff_sds=3.0)[0]
        assert abs(e3 - e9) > 1e-5 * e9, (seed, e3, e9)  # the comparison can see a cut into the kernel


# ---------------------------------------------------------------- PT: the error's rate in N


def test_pt_error_falls_with_n_at_the_measured_rate():
    """With H = N^(-1/3) Sigma the RMS error falls as N^(-1/3) in theory (bias and variance of the
    AMISE-optimal bandwidth). Measured over 16 seeds (1000-1015) and N = 1,000 .. 16,000: slope
    of the means -0.323 (theta = 0) and -0.328 (30 degrees), the per-seed slopes' mean -0.318 +-
    0.017 and -0.323 +- 0.020 (SE; their s.d. 0.07-0.08). Eight seeds here (SE ~0.03): the band
    [-0.45, -0.2] excludes 0; the two orientations within 0.15 and no mean 0.15 (in log) off the
    line (measured at most 0.03)."""
    seeds = range(8)
    slopes = []
    for theta in (0.0, 30.0):
        err = np.array([[pt_run(n, s, theta)[0] for s in seeds] for n in NS])
        b, worst = slope(NS, err)
        assert -0.45 < b < -0.2, (theta, b, err.mean(axis=1))
        assert worst < 0.15, (theta, worst)
        slopes.append(b)
    assert abs(slopes[0] - slopes[1]) < 0.15, slopes


@pytest.mark.slow
def test_pt_error_rate_over_n_to_256000_is_minus_a_third():
    """Twelve seeds, N = 1,000 .. 256,000 (~15 s): the slope within 0.06 of -1/3. Measured -0.323
    (theta = 0) and -0.322 (30 degrees); per-seed slopes -0.322 +- 0.007 and -0.321 +- 0.005 (SE)."""
    ns = (1000, 4000, 16000, 64000, 256000)
    for theta in (0.0, 30.0):
        err = np.array([[pt_run(n, s, theta)[0] for s in range(200, 212)] for n in ns])
        b, _ = slope(ns, err)
        assert abs(b + 1.0 / 3.0) < 0.06, (theta, b, err.mean(axis=1))


# ---------------------------------------------------------------- rotation invariance of the entropy


def differ_within_noise(a, b, z: float = Z) -> tuple[bool, float, float]:
    """Whether two independent samples' means differ by at most z standard errors of the difference."""
    a, b = np.asarray(a), np.asarray(b)
    se = math.sqrt(a.var(ddof=1) / a.size + b.var(ddof=1) / b.size)
    return abs(a.mean() - b.mean()) <= z * se, float(a.mean() - b.mean()), se


def test_mtpt_entropy_is_the_same_for_the_scene_turned_by_30_degrees():
    """H_C = -sum p ln p, p = m / sum m (dV = Omega^2 / N shared by both scenes), at N = 4,000 over
    twelve seeds each, the turned scene on other seeds than the plain one (independent layouts):
    the means within 3 SE. Measured with these seeds: H_C 5.452 (s.d. 0.063 between seeds: the
    random layout under a plume that covers ~250 particles) plain, 5.408 (s.d. 0.076) turned, the
    difference 0.044 with SE 0.029 (1.5 SE). The statistic sees a wrong orientation: on the turned
    scene's own layouts, an exchange blind to D's off-diagonal entry (det diag D = 1.7 det D at 30
    degrees) raises H_C by 0.060 +- 0.004 (paired over the 12 seeds); asserted above 3 of its SE."""
    n, seeds = 4000, 12
    plain = np.array([mtpt_run(n, s, 0.0, score=False)[1] for s in range(300, 300 + seeds)])
    turned = np.array([mtpt_run(n, s, 30.0, score=False)[1] for s in range(400, 400 + seeds)])
    ok, diff, se = differ_within_noise(plain, turned)
    assert ok, (diff, se)
    assert se < 0.05, se  # sharp enough to mean something: 3 SE is 15 % of the dilution index
    _, D = scene(30.0)
    blind = np.array([mtpt_run(n, s, 30.0, D=np.diag(np.diag(D)), score=False)[1] for s in range(400, 400 + seeds)])
    gain = blind - turned
    assert gain.mean() > Z * gain.std(ddof=1) / math.sqrt(seeds), gain


def test_pt_entropy_is_the_same_for_the_scene_turned_by_30_degrees():
    """PT's H = -(1/N) sum ln c_KDE(x_i) at N = 4,000 over eight seeds each: the means within 3 SE.
    Measured: -1.3886 plain, -1.3851 turned, difference -0.0035 with SE 0.0056 (0.6 SE). The
    statistic is sharp enough to see the plume: it differs from the exact H_I = ln(2 pi e sqrt(det
    Sigma)) = -1.3731 by less than 0.05 nats (measured 0.016: the kernel's smoothing, the self term)."""
    n = 4000
    plain = [pt_run(n, s, 0.0, entropy=True)[1] for s in range(500, 508)]
    turned = [pt_run(n, s, 30.0, entropy=True)[1] for s in range(600, 608)]
    ok, diff, se = differ_within_noise(plain, turned)
    assert ok, (diff, se)
    assert abs(np.mean(plain) - reference(0.0).h_i()) < 0.05, (np.mean(plain), reference(0.0).h_i())


# ---------------------------------------------------------------- mass and memory


def test_mtpt_conserves_mass_to_round_off_over_many_steps():
    """200 steps with a walk (eta = 0.5: the particles move, so P changes every step) at N = 3,000:
    the total within 1e-13 of its start (Eq. 16 with a symmetric P moves mass, never makes it; measured
    2.1e-16), while the masses have moved far (sum |m - m0| = 1.2 of the total) and stay non-negative."""
    _, D = scene(30.0)
    v, _ = scene(30.0)
    n, eta, dt = 3000, 0.5, 0.5
    rng = np.random.default_rng(700)
    x = rng.uniform(-SIDE / 2, SIDE / 2, (n, 2))
    m0 = reference(30.0, 0.0).density(x) * SIDE * SIDE / n
    m = m0.copy()
    for _ in range(200):
        x = walk(x, ((1.0 - eta) * D)[None], dt, rng, v)
        m = mtpt_exchange_2d(x, m, D, eta, dt).mass
    assert abs(m.sum() - m0.sum()) < 1e-13 * m0.sum(), (m.sum() - m0.sum()) / m0.sum()
    assert m.min() >= 0.0
    assert np.abs(m - m0).sum() > 0.5 * m0.sum()  # half of the mass has changed particles


MEMORY_SCRIPT = """
import json, resource, sys, tracemalloc
import numpy as np
sys.path.insert(0, sys.argv[1])
from particle_entropy.numerics.particles2d import mtpt_exchange_2d
a = np.radians(30.0)
R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
n, D = 100_000, R @ np.diag([1.0e-3, 2.5e-4]) @ R.T  # benchmarks/mtpt2d_step.py's tensor
rng = np.random.default_rng(800)
x = rng.uniform(-5.0, 5.0, (n, 2))
m = np.exp(-0.5 * (x**2).sum(axis=1))
mtpt_exchange_2d(x[:200], m[:200], D, 0.5, 1.0)  # numba's loops compiled before the baseline
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
tracemalloc.start()
res = mtpt_exchange_2d(x, m, D, 0.5, 1.0)
traced = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"base_kb": base, "peak_kb": peak, "traced": traced, "neighbours": res.mean_neighbours}))
"""


def test_one_exchange_at_n_100000_stays_under_300_mb():
    """One exchange of the benchmark's scene (eta = 0.5, dt = 1, N = 100,000, the default cut-off) in
    a process of its own: its peak RSS (ru_maxrss) rises by less than 300 MB over the warmed-up
    process, and numpy's traced peak stays below 40 bytes a pair plus 200 a particle. Measured at 6
    s.d. (111 neighbours a particle, 5.6e6 pairs): a rise of 177 MB (33 bytes a pair; 385 MB at 9
    s.d.) and 91 MB traced (17 bytes a pair); a dense N x N P would take 80 GB. ~3.5 s, mostly
    imports and numba, so not marked slow."""
    out = subprocess.run([sys.executable, "-c", MEMORY_SCRIPT, str(LIB)], check=True, capture_output=True, text=True)
    r = json.loads(out.stdout)
    n = 100_000
    pairs = r["neighbours"] * n / 2.0
    rise_mb = (r["peak_kb"] - r["base_kb"]) / 1024.0
    assert rise_mb < 300.0, r
    assert r["traced"] < 40.0 * pairs + 200.0 * n, r
    assert r["neighbours"] > 50.0, r  # the step did find its pairs
