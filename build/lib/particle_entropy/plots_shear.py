"""Fig. 10 (Appendix B): shear flow dispersed by random walks (with and without div D drift) or mass transfer.

``fig10`` takes the final particle tables of ``shear2d.run_shear`` (columns x, y, mass, case,
seed) and returns a matplotlib Figure; save it with ``plots.save_figure`` (byte-stable PNG/PDF).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import matplotlib
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.figure import Figure

from .plots import save_figure  # noqa: F401  (re-exported for the Fig. 10 script)
from .shear2d import CASES, WALL_BAND

TITLES = {
    "rw_nodrift": "random walk, no drift correction",
    "rw_drift": "random walk with grad.D drift",
    "mt": "mass transfer only",
}
MASS_FLOOR = 1e-6  # the paper shows only particles with mass > 1e-6
# plasma without its pale-yellow end, so the equal (largest) walker masses stay visible on white
MASS_CMAP = ListedColormap(matplotlib.colormaps["plasma"](np.linspace(0.0, 0.8, 256)), name="plasma_08")
N_BINS = 20  # y bins of width 0.05 = WALL_BAND, so the outer bins are the wall bands


def _plume_xlim(x: np.ndarray, length: float = 400.0) -> tuple[float, float]:
    """x-limits around the shown particles (no wrap handling needed while the plume spans < length)."""
    if x.size == 0:
        return 0.0, length
    lo, hi = float(x.min()), float(x.max())
    pad = 0.05 * max(hi - lo, 1.0)
    return lo - pad, hi + pad


def fig10(states: list[pd.DataFrame]) -> Figure:
    """Fig. 10: (a-c) positions of particles with mass > 1e-6 coloured by mass; (d-f) mass against y."""
    by_case = {df["case"].iloc[0]: df for df in states}
    order = [c for c in CASES if c in by_case]
    fig = Figure(figsize=(5.0 * len(order), 7.6), layout="constrained")
    axes = fig.subplots(2, len(order), squeeze=False, gridspec_kw={"height_ratios": [1.25, 1.0]})
    shown = {c: by_case[c][by_case[c]["mass"].to_numpy(float) > MASS_FLOOR] for c in order}
    m_all = np.concatenate([s["mass"].to_numpy(float) for s in shown.values()] + [np.array([MASS_FLOOR * 10])])
    norm = LogNorm(vmin=MASS_FLOOR, vmax=float(m_all.max()))
    edges = np.linspace(0.0, 1.0, N_BINS + 1)
    hist_max = 1.0
    sc = None
    for k, case in enumerate(order):
        df, s = by_case[case], shown[case]
        n, n_mass = len(df), len(s)
        seed = int(df["seed"].iloc[0])
        ax = axes[0, k]
        sc = ax.scatter(s["x"], s["y"], c=s["mass"], s=3, linewidths=0, cmap=MASS_CMAP, norm=norm, rasterized=True)
        ax.set_xlim(*_plume_xlim(s["x"].to_numpy(float)))
        ax.set_ylim(0.0, 1.0)
        ax.set_title(f"({'abc'[k]}) {TITLES.get(case, case)}", loc="left", fontsize=11)
        ax.set_xlabel("position along the flow $x$ [L]")
        ax.set_ylabel("lateral position $y$ [L]")
        ax.text(0.02, 0.02, f"N = {n:,}, seed {seed}\n{n_mass:,} particles with mass > {MASS_FLOOR:g}",
                transform=ax.transAxes, fontsize=8, va="bottom",
                bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1.5})

        ax = axes[1, k]
        y, m = s["y"].to_numpy(float), s["mass"].to_numpy(float)
        dens, _ = np.histogram(y, bins=edges, weights=m)
        dens = dens / (m.sum() * np.diff(edges)) if m.sum() > 0 else dens
        label = ("mass-carrying walkers (equal masses)" if case != "mt" else "particle mass") + f", N = {n:,}"
        ax.stairs(dens, edges, fill=True, color="#009E73" if case == "mt" else "#0072B2", alpha=0.55, label=label)
        if case != "mt":  # all walkers, massless ones included: the same physics with 20x the count
            all_d, _ = np.histogram(df["y"].to_numpy(float), bins=edges, density=True)
            ax.stairs(all_d, edges, color="#D55E00", linewidth=1.2, label=f"all {n:,} walkers")
            hist_max = max(hist_max, float(all_d.max()))
        hist_max = max(hist_max, float(dens.max()))
        ax.axhline(1.0, color="black", linestyle="--", linewidth=1.2, label="uniform in $y$")
        for lo, hi in ((0.0, WALL_BAND), (1.0 - WALL_BAND, 1.0)):
            ax.axvspan(lo, hi, color="0.85", zorder=0, linewidth=0)
        ax.set_title(f"({'def'[k]}) {TITLES.get(case, case)}", loc="left", fontsize=11)
        ax.set_xlabel("lateral position $y$ [L] (grey: within 0.05 of a wall)")
        ax.set_ylabel("mass per unit $y$ (normalised)")
        ax.set_xlim(0.0, 1.0)
        ax.legend(loc="upper center", fontsize=8, framealpha=0.9)
    for ax in axes[1]:
        ax.set_ylim(0.0, 1.3 * hist_max)
    if sc is not None:
        fig.colorbar(sc, ax=list(axes[0]), label="particle mass", shrink=0.9, pad=0.01)
    return fig
