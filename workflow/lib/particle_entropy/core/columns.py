"""What the columns of the run tables mean: presentation only, so no simulation hashes it.

Human-readable meanings of the case columns (``case.CASE_COLUMNS``) and of the per-step run
table (``records.COLUMNS``), one description per column with its unit as a trailing ``[...]``.
They are read only to write docs/columns.md (pipeline/columnsdoc.py), to describe the figures'
source data (figures/style.py) and by tests. A simulation or shear job must not import this
module (tests/test_columnsdoc.py holds that), so editing a description rewrites the page and
redraws the figures but reruns no simulation. What identity and behaviour need stays in the
code: ``case.CASE_COLUMNS`` and ``records.COLUMNS``, which orders a run table's columns and
which these dicts follow key for key, in the same order.
"""

from __future__ import annotations

from .registry import SCHEME_DOCS

CASE_COLUMN_DOCS = {  # case.CASE_COLUMNS
    "method": "`pt` (random-walk particle tracking), `mtpt` (mass-transfer particle tracking) or `fd` (implicit or "
    "explicit finite differences); in figure source data also `analytic` for a reference curve",
    "kernel": "`pt`: `bins`, `fixed` or `adaptive` (how the density is reconstructed); `mtpt`: `collision` (Eq. 17) "
    "or `sph` (Eqs. 20, 21, 26); `fd`: `implicit` or `explicit` (time scheme)",
    "n": "number of particles; for FD the number of grid intervals (the grid has N + 1 nodes)",
    "eta": "fraction of D carried by mass transfer, the rest by random walks (MTPT); 1 for PT and FD",
    "truncation": "MTPT transfer kernel cut at this many kernel widths; `inf` for the whole Gaussian (PT and FD "
    "always `inf`) [kernel widths]",
    "dt_growth": "time-step growth factor dt_(k+1) / dt_k; 1 is a fixed step (FD always 1)",
    "scheme": "how MTPT transfers mass: "
    + "; ".join(f"`{k}` ({v})" for k, v in SCHEME_DOCS.items())
    + "; PT and FD always `symmetric`",
    "time_grid": "particle time grid: `exact` (the last step shortened to end at t_final) or `authors` (whole "
    "growing steps while t < t_final, as the authors' code); FD always `exact`",
}
# per-step columns only a 2-D run writes (models/simulate.py's plane runners): a 1-D table keeps its bytes
PLANE_ONLY_COLUMNS = ("neighbours",)
# per-step columns only a run with a continuous release writes (RunConfig.release): others keep their bytes
RELEASE_ONLY_COLUMNS = ("mass_released", "mass_outflow")

RECORD_COLUMN_DOCS = {  # records.COLUMNS
    "step": "time-step index, 0 = initial condition",
    "time": "time at the end of the step [T]",
    "dt": "size of the step (0 for step 0) [T]",
    "H_D": "discrete entropy of the normalised masses, Eq. 2. PT: ln N for equal masses (Eq. 13); MTPT: of the "
    "particle masses; FD: of the node masses c dx [nats]",
    "H_C": "consistent entropy with sampling volume `dV`, Eqs. 6-7. PT: of the reconstructed density; MTPT and "
    "FD: equal to `H_D` (each particle or node carries volume dV) [nats]",
    "H_I": "inconsistent entropy, Eq. 3: PT the integral of -f ln f of the reconstruction; MTPT and FD "
    "`H_C` + ln dV [nats]",
    "H_PMF": "H_D + ln(Ω / N), Section 5.4 (FD: the FD domain length in place of Ω) [nats]",
    "E": "dilution index dV exp(H_C), Eqs. 8-9 (0 when H_C is -inf) [L]",
    "H_C_analytic": "H_C of the exact Gaussian at this time with the same dV, Eq. 14; -inf at t = 0 [nats]",
    "E_analytic": "dilution index of the exact Gaussian, sqrt(4 π e D t) (Eq. 14 into Eq. 8) [L]",
    "SSE": "sum of squared errors against the Gaussian sampled at the same points and normalised to unit mass, "
    "Eq. 44. PT: over the reconstruction points (bin centres or the kernel's evaluation grid); MTPT: the "
    "particles' m / dV at the particles; FD: every node [1/L²]",
    "n_sse": "number of points in `SSE`: PT the reconstruction points (varies with the realisation for kernels), "
    "MTPT N, FD N + 1 nodes",
    "AIC": "2 ln(SSE / n_sse), Eq. 41 with k = 0 (-inf for SSE = 0)",
    "COMIC": "2 ln(SSE / n_sse) - ln dV, Eq. 43",
    "SSE_points": "SSE, Eq. 44, at the m = 15 measurement points common to every case and seed (Section 6, "
    '"Four important points regarding the COMIC", point 1): uniform on the paper\'s FD domain [-6, 6], drawn '
    "once from `numpy.random.default_rng(registry.MEASUREMENT_SEED)` and sorted (`measures.measurement_points`). "
    "The model's concentration is linearly interpolated to each point, 0 outside the model's points: FD the "
    "nodal c; MTPT m / dV between the sorted particles (0 outside the particle cloud); PT the reconstruction "
    "`SSE` uses (bin centres, or the fixed or adaptive kernel's evaluation grid). The reference is the exact "
    "Gaussian density of variance 2 D t at the point: sampled at a point like `SSE`'s, but not rescaled to unit "
    "mass on the model's points, so every model meets the same values. At t = 0, as for `SSE`, the reference is "
    "the delta put on the model point nearest x = 0 (height 1 / dV), interpolated like the model "
    "(`measures.sse_points`) [1/L²]",
    "COMIC_points": "2 ln(SSE_points / 15) - ln dV, Eq. 43 at the measurement points, same dV as `COMIC` (-inf for "
    "SSE_points = 0)",
    "dV": "sampling volume: Ω / N for particles, dx for FD; in 2-D an area: Ω² / N, dx dy, PT's estimate's cell [L]",
    "mass_total": "total mass held (1 at t = 0; PT always 1). With a continuous release: the mass held, 0 at "
    "t = 0; PT's is m_p times the particles released by then, within m_p / 2 of `mass_released`",
    "mass_min": "smallest particle or node mass (PT: 1/N; with a release m_p, NaN while none is released)",
    "mass_released": "with a continuous release only: the mass released by this time, q times the overlap of "
    "[0, t] with [t0, t1] (models/release_step.py); FD's `mass_total` + `mass_outflow` and MTPT's `mass_total` "
    "equal it to round-off. A release run's entropies are NaN while it holds no mass. Its scores against "
    "the exact plume (core/released.py: quadrature in age; `SSE`, `COMIC`, `SSE_points`, `COMIC_points`, "
    "`H_C_analytic`, `E_analytic`) are on its last row only, at t_final, NaN before: `H_C_analytic` and "
    "`E_analytic` of the plume normalised to unit mass, the SSEs of the concentration of the mass released "
    "(PT's estimate times its particles' mass) [M²/L²]; NaN where the exact concentration is infinite (a 2-D "
    "point source still releasing, at its point)",
    "mass_outflow": "with a continuous release only: the mass that has left the FD window through its end nodes "
    "(2-D: its boundary ring) by this time, the sum of each step's flux into them as its mass balance counts it "
    "(0 for particles)",
    "beta": "mass-transfer coefficient of the step: 1/2 for the collision kernel, 2 η D dt / h² for SPH (Eq. 20); "
    "0 for PT, FD and steps without transfer",
    "h": "width of the step's kernel: MTPT the transfer kernel's standard deviation (collision sqrt(4 η D dt), "
    "Eq. 17; SPH h_SPH, Eq. 26, of the plume's variance; for `compensated` the widened width); PT the bin width "
    "Ω/N (Eq. 11), the fixed kernel sqrt(2 D t_fix) or h_DE (Eq. 23) of the plume's variance (the source's plus "
    "2 D t: 0 at t = 0 for a point); FD dx [L]; in 2-D the same along the plume's major axis (MTPT sqrt(4 η D_L "
    "dt), PT the square root of H's largest eigenvalue)",
    "neighbours": "2-D MTPT: the step's partners within the exchange's cut-off per particle (2 pairs / N)",
    "substeps": "mass-transfer substeps the step was split into to keep masses non-negative (1: not split; PT and "
    "FD 1)",
    "settled": "t > dV² / (4 π e D): from here on the analytic H_C is meaningful (Section 3); in 2-D the exact "
    "plume's E above dV",
    "work": "particle-steps (FD node-steps, N + 1 nodes) from t = 0 to this step, substeps counted",
    "wall_s": "wall-clock seconds spent in this step (differs between identical runs) [s]",
    "peak_rss_mb": "peak resident memory of the process so far (differs between machines and runs; getrusage's "
    "ru_maxrss, which Linux carries over exec: at least the peak of the process that started the job) [MB]",
}
