"""Particles in 2-D (numerics/particles2d.py): MTPT's exchange with Eq. 17 written with a uniform
tensor, PT's kernel reconstruction with a plume-shaped bandwidth matrix, MTPT's concentration at
points, and both models' invariance under a rotation of the scene. References are written here from
the equations: a dense P of Eqs. 16-18 on a few hundred particles and the exact 2-D Gaussian."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from particle_entropy.models.walk import walk
from particle_entropy.numerics.particles2d import (
    kde_2d,
    mtpt_concentration_2d,
    mtpt_exchange_2d,
    plume_bandwidth_2d,
)

Z = 4.0  # standard errors allowed for a statistical comparison (two-sided 6e-5 by chance)


def rotation(degrees: float) -> np.ndarray:
    a = math.radians(degrees)
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def oblique(major: float, minor: float, degrees: float) -> np.ndarray:
    """R diag(major, minor) R^T: a tensor whose axes are turned by ``degrees``."""
    R = rotation(degrees)
    return R @ np.diag([major, minor]) @ R.T


D_OBLIQUE = oblique(1.0, 0.25, 30.0)  # [L^2/T]
IDENTITY = np.eye(2)  # the scene not turned


def gaussian_2d(p, mean, cov) -> np.ndarray:
    """The bivariate normal density at points (M, 2), written from its formula."""
    y = np.asarray(p) - mean
    q = np.einsum("ni,ij,nj->n", y, np.linalg.inv(cov), y)
    return np.exp(-0.5 * q) / (2.0 * math.pi * math.sqrt(np.linalg.det(cov)))


def weighted_covariance(x, m) -> np.ndarray:
    mu = m @ x / m.sum()
    y = x - mu
    return (y.T * m) @ y / m.sum()


def gaussian_masses(x, mean, cov) -> np.ndarray:
    m = gaussian_2d(x, mean, cov)
    return m / m.sum()


# ---------------------------------------------------------------- the exchange


def dense_exchange(x, m, D, eta, dt, substeps):
    """Eq. 16 with beta = 1/2 and the full Eq. 17, W_ij = exp(-r^T (eta D)^-1 r / (8 dt)) /
    sqrt(det(8 pi eta D dt)) (i = j included), P = (W / rowsum + W / colsum) / 2 (Eq. 18), applied
    in ``substeps`` equal parts of beta; ``m`` (species, N)."""
    A = eta * D
    r = x[:, None, :] - x[None, :, :]
    q = np.einsum("ija,ab,ijb->ij", r, np.linalg.inv(A), r)
    W = np.exp(-q / (8.0 * dt)) / math.sqrt(np.linalg.det(8.0 * math.pi * A * dt))
    P = 0.5 * (W / W.sum(1)[:, None] + W / W.sum(0)[None, :])
    b = 0.5 / substeps
    for _ in range(substeps):
        m = m + b * (m @ P.T - m * P.sum(1))
    return m


def test_exchange_equals_a_dense_reference_with_an_oblique_tensor():
    rng = np.random.default_rng(1)
    x = rng.uniform(-1.0, 1.0, (300, 2)) * [1.0, 0.5]
    m = rng.uniform(0.0, 1.0, (3, 300))
    eta, dt = 0.7, 2.0e-3  # kernel sd along the major axis sqrt(4 eta dt) = 0.075, ~1.5 spacings
    got, substeps, neighbours = mtpt_exchange_2d(x, m, D_OBLIQUE, eta, dt)
    want = dense_exchange(x, m, D_OBLIQUE, eta, dt, substeps)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert np.abs(got - m).max() > 1e-3  # the exchange did move mass
    single, substeps_1, _ = mtpt_exchange_2d(x, m[1], D_OBLIQUE, eta, dt)
    assert substeps_1 == substeps
    np.testing.assert_array_equal(single, got[1])  # each species by the same P
    assert 0.0 < neighbours < 299.0


@pytest.mark.parametrize("species", [1, 3])
def test_exchange_conserves_each_species_mass_to_round_off(species):
    rng = np.random.default_rng(2)
    x = rng.uniform(-1.0, 1.0, (5000, 2))
    m = rng.exponential(1.0, (species, 5000)) * (rng.uniform(size=5000) < 0.2)  # many empty particles
    before = m.sum(axis=1)
    got = m
    for _ in range(3):
        got, _, _ = mtpt_exchange_2d(x, got, oblique(1.0, 0.05, -50.0), 1.0, 5.0e-4)
    assert got.shape == m.shape and got.min() >= 0.0
    np.testing.assert_allclose(got.sum(axis=1), before, rtol=2e-15 * math.sqrt(5000), atol=0.0)
    assert np.abs(got - m).max() > 0.1  # not conserved by doing nothing


def test_exchange_spreads_masses_by_two_eta_D_dt_per_step():
    """A Gaussian cloud of masses on uniform random particles gains covariance 2 eta D dt f a step,
    off-diagonal included. f = 1 - 1/(1 + n_K) is the share of each row of P off its own particle:
    W's self term (1) against the n_K = rho 2 pi sqrt(det(4 eta D dt)) particles a kernel holds
    (its sum of weights over a uniform density rho): 0.938 here. Over 5 other seeds the entries'
    measured f had mean 0.97 and s.d. 0.035 between seeds (the particles' random positions), so
    the band is 0.12 of the largest entry, 3.4 s.d.; it still fails for an isotropic kernel (the
    off-diagonal entry is 0.4 of the largest), for D in place of eta D (x 1.25) or beta = 1 (x 2)."""
    rng = np.random.default_rng(3)
    n, side = 20000, 2.0
    x = rng.uniform(-side / 2, side / 2, (n, 2))
    m = gaussian_masses(x, np.zeros(2), np.array([[0.03, 0.005], [0.005, 0.02]]))
    eta, dt, steps = 0.8, 3.0e-4, 2
    got = m
    for _ in range(steps):
        got, substeps, neighbours = mtpt_exchange_2d(x, got, D_OBLIQUE, eta, dt, cutoff_sds=6.0)
    gain = (weighted_covariance(x, got) - weighted_covariance(x, m)) / steps
    n_kernel = n / side**2 * 2.0 * math.pi * math.sqrt(np.linalg.det(4.0 * eta * D_OBLIQUE * dt))
    want = 2.0 * eta * D_OBLIQUE * dt * (1.0 - 1.0 / (1.0 + n_kernel))
    assert np.abs(gain - want).max() < 0.12 * np.abs(want).max(), (gain, want)
    assert substeps == 1 and neighbours > 50.0


def test_exchange_builds_no_dense_matrix():
    """N = 20,000: a dense P would take 3.2 GB. The pairs (16 bytes each), the weights (8) and the
    whitened positions are what the exchange allocates through numpy: its peak increase stays
    below 40 bytes a pair plus 200 bytes a particle (the compiled loop's arrays are outside numpy's
    allocator and the k-d tree's in C++: the benchmark reports peak RSS)."""
    rng = np.random.default_rng(4)
    n = 20000
    x = rng.uniform(-1.0, 1.0, (n, 2))
    m = rng.uniform(size=n)
    mtpt_exchange_2d(x[:50], m[:50], D_OBLIQUE, 1.0, 2.5e-4)  # load the compiled loops first
    tracemalloc.start()
    _, _, neighbours = mtpt_exchange_2d(x, m, D_OBLIQUE, 1.0, 2.5e-4)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    pairs = neighbours * n / 2.0
    assert peak < 40.0 * pairs + 200.0 * n, (peak, pairs)
    assert peak < 0.05 * 8.0 * n * n


def test_zero_eta_leaves_the_masses_and_bad_tensors_are_refused():
    x = np.random.default_rng(5).uniform(size=(10, 2))
    m = np.arange(10.0)
    got, substeps, neighbours = mtpt_exchange_2d(x, m, D_OBLIQUE, 0.0, 1.0)
    np.testing.assert_array_equal(got, m)
    assert (substeps, neighbours) == (1, 0.0)
    for bad in (np.diag([1.0, -1.0]), np.array([[1.0, 0.2], [0.0, 1.0]]), np.eye(3)):
        with pytest.raises(ValueError):
            mtpt_exchange_2d(x, m, bad, 1.0, 1.0)


# ---------------------------------------------------------------- the walk (what tests/test_walk.py lacks)


def test_tensor_walk_with_velocity_has_mean_v_dt_and_covariance_two_D_dt():
    """tests/test_walk.py checks the tensor's covariance without v and the mean with a scalar D;
    here both at once: steps of a full tensor and a velocity, each statistic within Z standard errors."""
    n, dt, v = 200_000, 0.05, np.array([0.8, -0.3])
    steps = walk(np.zeros((n, 2)), np.broadcast_to(D_OBLIQUE, (n, 2, 2)), dt, np.random.default_rng(6), v)
    S = 2.0 * D_OBLIQUE * dt
    assert np.all(np.abs(steps.mean(axis=0) - v * dt) < Z * np.sqrt(np.diag(S) / n))
    y = steps - v * dt
    se = np.sqrt((np.outer(np.diag(S), np.diag(S)) + S**2) / n)  # Var(y_a y_b) of a Gaussian
    assert np.all(np.abs(y.T @ y / n - S) < Z * se)


# ---------------------------------------------------------------- PT: the kernel reconstruction


def pt_plume(n, seed, x0, v, D, t):
    """N particles from a point x0 walked to time t in one step (exact for uniform v and D)."""
    start = np.broadcast_to(x0, (n, 2))
    return walk(start, np.broadcast_to(D, (n, 2, 2)), t, np.random.default_rng(seed), v)


def plume_points(centre, cov, k: int = 13, reach: float = 2.5) -> np.ndarray:
    """A k x k lattice of points over +- reach standard deviations of the plume, in its own axes."""
    g = np.linspace(-reach, reach, k)
    u = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    return centre + u @ np.linalg.cholesky(cov).T


def pt_error(n, seed, R=IDENTITY):
    """RMS error of the PT reconstruction at the plume's points against the exact Gaussian, over its
    peak, of the scene (x0, v, D, t) turned by R."""
    x0, v, D, t = np.array([0.3, -0.2]), np.array([1.0, 0.5]), D_OBLIQUE * 0.01, 1.0
    p = plume_points(x0 + v * t, 2.0 * D * t) @ R.T
    x0, v, D = R @ x0, R @ v, R @ D @ R.T
    cov = 2.0 * D * t
    x = pt_plume(n, seed, x0, v, D, t)
    exact = gaussian_2d(p, x0 + v * t, cov)
    c = kde_2d(p, x, plume_bandwidth_2d(n, cov))
    return math.sqrt(np.mean((c - exact) ** 2)) / exact.max()


def test_kde_integrates_to_one_and_equals_the_direct_sum():
    rng = np.random.default_rng(7)
    x = rng.multivariate_normal([0.5, 0.0], D_OBLIQUE, 2000)
    H = plume_bandwidth_2d(2000, D_OBLIQUE)
    g = np.linspace(-6.0, 7.0, 261)
    p = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    c = kde_2d(p, x, H, chunk_pairs=20_000)  # many chunks
    assert abs(c.sum() * (g[1] - g[0]) ** 2 - 1.0) < 1e-6
    some = p[::997]
    r = (some[:, None, :] - x[None, :, :]).reshape(-1, 2)
    direct = gaussian_2d(r, np.zeros(2), H).reshape(len(some), -1).mean(axis=1)
    # the cut-off drops terms below exp(-81/2) = 2.6e-18 of the kernel peak, 1 / (2 pi sqrt(det H))
    peak = 1.0 / (2.0 * math.pi * math.sqrt(np.linalg.det(H)))
    np.testing.assert_allclose(kde_2d(some, x, H), direct, rtol=1e-12, atol=3e-18 * peak)
    assert np.count_nonzero(direct > 1e-3 * c.max()) > 3  # some points inside the plume


def test_plume_bandwidth_is_n_to_the_minus_one_third_of_the_covariance():
    """Eq. 22 with d = 2 for a Gaussian plume: h^6 = d / ((2 sqrt(pi))^2 N int (lap f)^2) with
    int (lap f)^2 = d (d + 2) / (2^(d + 2) pi^(d / 2)) = 1 / (2 pi) for the standard normal."""
    lap = 2 * 4 / (2**4 * math.pi)
    n = 5000
    h = (2.0 / (4.0 * math.pi * n * lap)) ** (1.0 / 6.0)
    np.testing.assert_allclose(plume_bandwidth_2d(n, D_OBLIQUE), h * h * D_OBLIQUE, rtol=1e-14)


SEEDS = (11, 12, 13)
NS = (1000, 4000, 16000)


def test_kde_error_shrinks_with_n_at_the_amise_rate():
    """With H = N^(-1/3) Sigma the mean integrated squared error falls as N^(-2/3) (bias^2 and
    variance both, Silverman 1986 Sect. 4.3), so the RMS error as N^(-1/3). The slope of log error
    against log N over N = 1e3, 4e3, 16e3 (three seeds each) is asserted in [-0.5, -0.2]: at these N
    the points' error is a sum of a few hundred correlated terms, and the slope of three seeds
    scattered by about 0.04 between draws of seeds; the band excludes both no convergence (0) and
    Monte Carlo's -1/2 without bias."""
    err = np.array([[pt_error(n, s) for s in SEEDS] for n in NS])
    means = err.mean(axis=1)
    assert np.all(np.diff(means) < 0.0), means
    slope = np.polyfit(np.log(NS), np.log(means), 1)[0]
    assert -0.5 < slope < -0.2, (slope, means)


def test_kde_error_rate_over_more_n_and_seeds_is_minus_a_third():
    """Ten seeds and N up to 64,000 (2 s): the slope within 0.08 of -1/3, two s.d. of a three-seed
    slope (0.04, above) and more than that of a ten-seed one."""
    ns = (1000, 4000, 16000, 64000)
    err = np.array([[pt_error(n, s) for s in range(20, 30)] for n in ns])
    slope = np.polyfit(np.log(ns), np.log(err.mean(axis=1)), 1)[0]
    assert abs(slope + 1.0 / 3.0) < 0.08, (slope, err.mean(axis=1))


# ---------------------------------------------------------------- rotation invariance


def test_kde_of_turned_particles_is_the_same_to_round_off():
    R = rotation(30.0)
    x = np.random.default_rng(8).multivariate_normal([0.0, 0.0], D_OBLIQUE, 3000)
    H = plume_bandwidth_2d(3000, D_OBLIQUE)
    p = plume_points(np.zeros(2), D_OBLIQUE)
    np.testing.assert_allclose(kde_2d(p @ R.T, x @ R.T, R @ H @ R.T), kde_2d(p, x, H), rtol=1e-10)


def within_noise(a, b) -> tuple[bool, float, float]:
    """Whether two samples' means differ by at most Z standard errors of the difference."""
    a, b = np.asarray(a), np.asarray(b)
    se = math.sqrt(a.var(ddof=1) / a.size + b.var(ddof=1) / b.size)
    return abs(a.mean() - b.mean()) <= Z * se, a.mean() - b.mean(), se


def test_pt_error_is_the_same_for_the_scene_turned_by_30_degrees():
    seeds = range(40, 48)
    plain = [pt_error(4000, s) for s in seeds]
    turned = [pt_error(4000, s, rotation(30.0)) for s in seeds]
    ok, diff, se = within_noise(plain, turned)
    assert ok, (diff, se)
    assert not np.allclose(plain, turned)  # the walks are new draws, not the same ones turned


def mtpt_scene(n, seed, eta, R=IDENTITY, steps=4):
    """MTPT of a Gaussian source (mean x0, covariance S0) on N uniform particles over a square turned
    by R, carried by v, with dispersion D (all turned by R): the walk with (1 - eta) D, the exchange
    with eta D. -> (RMS error at the plume's points over its peak, H_D = -sum m ln m)."""
    rng = np.random.default_rng(seed)
    side, dt = 2.0, 2.5e-4
    x = rng.uniform(-side / 2, side / 2, (n, 2)) @ R.T
    x0, v, D = R @ [0.1, 0.05], R @ [0.4, -0.2], R @ D_OBLIQUE @ R.T
    S0 = R @ np.array([[0.03, 0.004], [0.004, 0.015]]) @ R.T
    m = gaussian_masses(x, x0, S0)
    for _ in range(steps):
        if eta < 1.0:
            x = walk(x, np.broadcast_to((1.0 - eta) * D, (n, 2, 2)), dt, rng, v)
        else:
            x = x + v * dt
        m, _, _ = mtpt_exchange_2d(x, m, D, eta, dt)
    t = steps * dt
    cov = S0 + 2.0 * D * t
    plain_cov = R.T @ cov @ R
    p = plume_points(R.T @ (x0 + v * t), plain_cov, k=9, reach=2.0) @ R.T  # the plain scene's points, turned
    exact = gaussian_2d(p, x0 + v * t, cov)
    c = mtpt_concentration_2d(p, x, m, side * side / n)
    pos = m[m > 0.0]
    return math.sqrt(np.mean((c - exact) ** 2)) / exact.max(), float(-(pos * np.log(pos)).sum())


def test_mtpt_by_exchange_alone_is_the_same_turned_to_round_off():
    """eta = 1: no walk, so the turned scene's particles are the plain scene's turned, and the
    exchange, which sees only r^T D^-1 r, gives the same masses."""
    plain = mtpt_scene(3000, 50, 1.0)
    turned = mtpt_scene(3000, 50, 1.0, rotation(30.0))
    np.testing.assert_allclose(turned, plain, rtol=1e-9)


def test_mtpt_error_and_entropy_are_the_same_turned_within_noise():
    seeds = range(60, 66)
    plain = np.array([mtpt_scene(3000, s, 0.5) for s in seeds])
    turned = np.array([mtpt_scene(3000, s, 0.5, rotation(30.0)) for s in seeds])
    for k, name in enumerate(("error", "H_D")):
        ok, diff, se = within_noise(plain[:, k], turned[:, k])
        assert ok, (name, diff, se)
    assert not np.allclose(plain[:, 1], turned[:, 1], rtol=1e-9)  # new walks, not the same ones


def test_mtpt_concentration_is_masses_over_dV_and_zero_outside():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    m = np.array([[1.0, 2.0, 3.0, 4.0], [0.0, 0.0, 0.0, 8.0]])
    p = np.array([[0.0, 0.0], [0.5, 0.5], [2.0, 2.0]])
    got = mtpt_concentration_2d(p, x, m, 0.25)
    np.testing.assert_allclose(got[0], [4.0, 10.0, 0.0])  # centre: the mean of the corners (either diagonal)
    np.testing.assert_allclose(got[1, [0, 2]], [0.0, 0.0])


def test_the_concentration_at_points_equals_scipy_s_linear_interpolation_on_the_same_triangles():
    """Our closed-form point location against scipy's LinearNDInterpolator (its own find_simplex):
    random points inside, outside and on particles, one species and two."""
    from scipy.interpolate import LinearNDInterpolator

    rng = np.random.default_rng(52)
    x = rng.random((3000, 2)) * 2.0 - 1.0
    m = rng.random(3000)
    p = np.vstack([rng.random((400, 2)) * 2.4 - 1.2, x[:20]])  # some outside the hull, some on vertices
    want = LinearNDInterpolator(x, m / 0.5, fill_value=0.0)(p)
    assert np.any(want == 0.0) and np.any(want > 0.0)
    assert np.allclose(mtpt_concentration_2d(p, x, m, 0.5), want, rtol=0, atol=1e-12)
    both = mtpt_concentration_2d(p, x, np.vstack([m, 3.0 * m]), 0.5)
    assert both.shape == (2, p.shape[0]) and np.allclose(both[1], 3.0 * want, rtol=0, atol=1e-12)
