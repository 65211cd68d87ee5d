"""Experiment: noise-driven segregation of A + B -> C in 1-D, the mean concentration's late-time
decay c_A ~ t^(-1/4) (Ovchinnikov & Zeldovich 1978; Toussaint & Wilczek 1983; Paster, Bolster &
Benson 2014, J. Comput. Phys. 263, 91) after an early well-mixed c_A = C0 / (1 + k C0 t).

    python benchmarks/segregation.py --method pt --seeds 16 --workers 2
    python benchmarks/segregation.py --method mtpt --seeds 8 --workers 2 --length 1500 --t-end 1000

A and B start well mixed with the noise of finite particle numbers, equal totals C0 L:

- pt: na = nb = n0 L particles of mass m_p = C0 / n0 at independent uniform positions on the
  periodic domain [0, L) (as Benson & Meerschaert 2008 and Paster et al. 2014 start them);
- mtpt: 2 n0 L particles uniform on [0, L) with reflecting walls, half of them (at random)
  carrying only A, half only B, at mass 2 C0 dV = m_p (so the noise of A - B per length, 2 m_p
  C0, is PT's); the means are taken over the interior, a wall's reach (3 sqrt(8 D t_end)) in from
  each end.

Steps: dt0 while growth t < dt0, then dt = growth t (geometric; growth 0.01 by default). Output: the
mean c_A(t) over seeds; the slope of log <c_A> against log t over the late window, with a 95 %
bootstrap interval over seeds (scipy.stats.bootstrap, resampling whole runs), and the early ratio
<c_A> / (C0 / (1 + k C0 t)).
The segregation theory's late law, for white-noise initial A - B of strength 2 m_p C0, is
c_A ~ sqrt(m_p C0 / pi) (8 pi D t)^(-1/4) (E|U| / 2 of the diffused difference U = A - B), so the
crossover from t^-1 is near t* = (sqrt(pi / (m_p C0)) (8 pi D)^(1/4) / k)^(4/3).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.core.reactions import well_mixed  # noqa: E402
from particle_entropy.models import reactive as R  # noqa: E402


def run_one(args: dict) -> tuple[np.ndarray, np.ndarray, float]:
    """(times, c_A, seconds) of one seeded run."""
    a = argparse.Namespace(**args)
    rng = np.random.default_rng(a.seed)
    dts = R.time_steps(a.t_end, a.dt0, a.growth)
    start = time.perf_counter()
    if a.method == "pt":
        n = round(a.n0 * a.length)
        t, ca, _ = R.run_pt(n, n, R.Bimolecular(a.k), a.c0, a.D, a.length, dts, rng)
    else:
        n = 2 * round(a.n0 * a.length)
        x, m = R.mtpt_uniform_labels(n, a.length, a.c0, rng)
        wall = 3.0 * math.sqrt(8.0 * a.D * a.t_end)
        t, ca, _, _, _ = R.run_mtpt(
            x, m, R.Bimolecular(a.k), a.length / n, a.D, a.eta, dts, rng, domain=(0.0, a.length),
            window=(wall, a.length - wall),
        )  # fmt: skip
    return t, ca, time.perf_counter() - start


def slope(t: np.ndarray, c: np.ndarray, lo: float, hi: float) -> float:
    """Least-squares slope of log c against log t over lo <= t <= hi."""
    w = (t >= lo) & (t <= hi) & (c > 0)
    return float(np.polyfit(np.log(t[w]), np.log(c[w]), 1)[0])


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--method", choices=("pt", "mtpt"), default="pt")
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--n0", type=float, default=10.0, help="particles of each species per unit length")
    p.add_argument("--length", type=float, default=11_000.0, help="domain length L")
    p.add_argument("--D", type=float, default=1.0)
    p.add_argument("--k", type=float, default=1.0)
    p.add_argument("--c0", type=float, default=1.0)
    p.add_argument("--eta", type=float, default=0.5, help="MTPT's share of D by mass transfer")
    p.add_argument("--dt0", type=float, default=0.01)
    p.add_argument("--growth", type=float, default=0.01, help="dt = growth t once above dt0")
    p.add_argument("--t-end", type=float, default=1e4)
    p.add_argument("--late", type=float, nargs=2, default=None, help="late window (default 10 t* .. t_end)")
    a = p.parse_args(argv)
    m_p = a.c0 / a.n0
    t_star = (math.sqrt(math.pi / (m_p * a.c0)) * (8 * math.pi * a.D) ** 0.25 / a.k) ** (4 / 3)
    late = a.late or (10 * t_star, a.t_end)
    dts = R.time_steps(a.t_end, a.dt0, a.growth)
    print(
        f"{a.method}: n0 = {a.n0:g} per species per length (m_p = {m_p:g}), L = {a.length:g}, D = {a.D:g}, "
        f"k = {a.k:g}, C0 = {a.c0:g}, eta = {a.eta:g} (mtpt), dt0 = {a.dt0:g}, dt = {a.growth:g} t, "
        f"{dts.size} steps to t = {a.t_end:g} (largest dt {dts.max():.4g}, PT P(0) <= "
        f"{R.max_pair_probability(a.k, m_p, a.D, dts.max()):.3f}); sqrt(8 D t_end) / L = "
        f"{math.sqrt(8 * a.D * a.t_end) / a.length:.3g}; t* = {t_star:.4g}; late window {late[0]:.4g} .. {late[1]:.4g}"
    )
    jobs = [dict(vars(a), seed=s) for s in range(a.seeds)]
    wall = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        runs = list(pool.map(run_one, jobs))
    wall = time.perf_counter() - wall
    t = runs[0][0]
    c = np.array([r[1] for r in runs])
    secs = [r[2] for r in runs]

    def mean_slope(idx, axis=-1):
        return slope(t, c[np.asarray(idx, dtype=int)].mean(axis=0), *late)

    est = mean_slope(np.arange(a.seeds))
    per_seed = [slope(t, ci, *late) for ci in c]
    ci = stats.bootstrap(
        (np.arange(a.seeds),), mean_slope, vectorized=False, n_resamples=2000, random_state=0
    ).confidence_interval  # fmt: skip
    wm = well_mixed(a.c0, a.c0, a.k, t)[0]
    mean = c.mean(axis=0)
    print(f"run time: {np.mean(secs):.1f} s a run (min {min(secs):.1f}, max {max(secs):.1f}), {wall:.1f} s wall")
    print(
        f"late slope of log <c_A> vs log t: {est:.4f}, 95% bootstrap CI [{ci.low:.4f}, {ci.high:.4f}] "
        f"over {a.seeds} seeds; per-seed slopes {np.mean(per_seed):.4f} +- {np.std(per_seed, ddof=1):.4f} (sd)"
    )
    print("t          <c_A>       s.e.        well-mixed  ratio  theory t^-1/4 law")
    law = math.sqrt(m_p * a.c0 / math.pi) * (8 * math.pi * a.D * t) ** -0.25
    se = c.std(axis=0, ddof=1) / math.sqrt(a.seeds)
    for target in (0.1, 0.3, 1, 3, 10, 30, 100, 300, 1000, 3000, 1e4, 3e4, 1e5):
        if target > a.t_end:
            break
        i = int(np.argmin(np.abs(t - target)))
        print(f"{t[i]:<10.4g} {mean[i]:<11.5g} {se[i]:<11.3g} {wm[i]:<11.5g} {mean[i] / wm[i]:<6.3f} {law[i]:.5g}")
    early = (0.5 / (a.k * a.c0), 5 / (a.k * a.c0))
    print(
        f"early slope over t = {early[0]:g} .. {early[1]:g}: {slope(t, mean, *early):.4f} "
        f"(the well-mixed law's own: {slope(t, wm, *early):.4f})"
    )
    for lo, hi in ((late[0], math.sqrt(late[0] * late[1])), (math.sqrt(late[0] * late[1]), late[1])):
        print(f"slope over {lo:.4g} .. {hi:.4g}: {slope(t, mean, lo, hi):.4f}")


if __name__ == "__main__":
    main()
