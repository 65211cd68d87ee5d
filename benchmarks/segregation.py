"""Experiment: noise-driven segregation of A + B -> C in 1-D, the mean concentration's late-time
decay c_A ~ t^(-1/4) (Ovchinnikov & Zeldovich 1978; Toussaint & Wilczek 1983; Paster, Bolster &
Benson 2014, J. Comput. Phys. 263, 91) after an early well-mixed c_A = C0 / (1 + k C0 t).

    python benchmarks/segregation.py --method pt --seeds 16 --workers 2
    python benchmarks/segregation.py --method mtpt --seeds 8 --workers 2 --length 1500 --t-end 1000

A and B start well mixed with the noise of finite particle numbers, equal totals C0 L; the runs
(PT on a periodic domain, MTPT between reflecting walls) are particle_entropy.experiments.segregation's,
the slope and its interval analysis.segregation's, as tests/test_segregation.py (pytest -m slow) uses
them. Steps: dt0 while growth t < dt0, then dt = growth t (geometric; growth 0.01 by default).
Output: the mean c_A(t) over seeds; the slope of log <c_A> against log t over the late window, with a
95 % bootstrap interval over seeds (scipy.stats.bootstrap, resampling whole runs), and the early
ratio <c_A> / (C0 / (1 + k C0 t)).
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

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.analysis.segregation import loglog_slope, slope_interval, well_mixed_ratio  # noqa: E402
from particle_entropy.core.reactions import well_mixed  # noqa: E402
from particle_entropy.experiments import segregation as S  # noqa: E402
from particle_entropy.models import reaction_step as R  # noqa: E402


def run_one(job: tuple[S.Segregation, int]) -> tuple[np.ndarray, np.ndarray, float]:
    """(times, c_A, seconds) of one seeded run."""
    setup, seed = job
    start = time.perf_counter()
    t, ca = S.run_seed(setup, seed)
    return t, ca, time.perf_counter() - start


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
    setup = S.Segregation(a.method, a.n0, a.length, a.D, a.k, a.c0, a.eta, a.dt0, a.growth, a.t_end)
    m_p = setup.m_p
    t_star = S.crossover_time(m_p, a.c0, a.D, a.k)
    late = a.late or (10 * t_star, a.t_end)
    dts = setup.steps()
    print(
        f"{a.method}: n0 = {a.n0:g} per species per length (m_p = {m_p:g}), L = {a.length:g}, D = {a.D:g}, "
        f"k = {a.k:g}, C0 = {a.c0:g}, eta = {a.eta:g} (mtpt), dt0 = {a.dt0:g}, dt = {a.growth:g} t, "
        f"{dts.size} steps to t = {a.t_end:g} (largest dt {dts.max():.4g}, PT P(0) <= "
        f"{R.max_pair_probability(a.k, m_p, a.D, dts.max()):.3f}); sqrt(8 D t_end) / L = "
        f"{math.sqrt(8 * a.D * a.t_end) / a.length:.3g}; t* = {t_star:.4g}; late window {late[0]:.4g} .. {late[1]:.4g}"
    )
    jobs = [(setup, s) for s in range(a.seeds)]
    wall = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        runs = list(pool.map(run_one, jobs))
    wall = time.perf_counter() - wall
    t = runs[0][0]
    c = np.array([r[1] for r in runs])
    secs = [r[2] for r in runs]
    fit = slope_interval(t, c, *late)
    per_seed = [loglog_slope(t, ci, *late) for ci in c]
    wm = well_mixed(a.c0, a.c0, a.k, t)[0]
    ratio = well_mixed_ratio(t, c, a.c0, a.k)
    mean = c.mean(axis=0)
    print(f"run time: {np.mean(secs):.1f} s a run (min {min(secs):.1f}, max {max(secs):.1f}), {wall:.1f} s wall")
    print(
        f"late slope of log <c_A> vs log t: {fit.estimate:.4f}, 95% bootstrap CI [{fit.low:.4f}, {fit.high:.4f}] "
        f"over {a.seeds} seeds; per-seed slopes {np.mean(per_seed):.4f} +- {np.std(per_seed, ddof=1):.4f} (sd)"
    )
    print("t          <c_A>       s.e.        well-mixed  ratio  theory t^-1/4 law")
    law = S.late_law(t, m_p, a.c0, a.D)
    se = c.std(axis=0, ddof=1) / math.sqrt(a.seeds)
    for target in (0.1, 0.3, 1, 3, 10, 30, 100, 300, 1000, 3000, 1e4, 3e4, 1e5):
        if target > a.t_end:
            break
        i = int(np.argmin(np.abs(t - target)))
        print(f"{t[i]:<10.4g} {mean[i]:<11.5g} {se[i]:<11.3g} {wm[i]:<11.5g} {ratio[i]:<6.3f} {law[i]:.5g}")
    early = (0.5 / (a.k * a.c0), 5 / (a.k * a.c0))
    print(
        f"early slope over t = {early[0]:g} .. {early[1]:g}: {loglog_slope(t, mean, *early):.4f} "
        f"(the well-mixed law's own: {loglog_slope(t, wm, *early):.4f})"
    )
    for lo, hi in ((late[0], math.sqrt(late[0] * late[1])), (math.sqrt(late[0] * late[1]), late[1])):
        print(f"slope over {lo:.4g} .. {hi:.4g}: {loglog_slope(t, mean, lo, hi):.4f}")


if __name__ == "__main__":
    main()
