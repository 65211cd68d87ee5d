"""Fig. 10 (Appendix B): shear flow dispersed by random walks (with and without div D drift) or mass transfer.

``fig10`` takes the final particle tables of ``shear2d.run_shear`` (columns x, y, mass, case,
seed) and returns ``(Figure, source data)``: the figure (save it with ``style.save_figure``,
byte-stable PNG/PDF) and a tidy table of what it plots, columns in ``SOURCE_COLUMNS``.
"""

from __future__ import annotations

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.figure import Figure

from ..core.registry import SHEAR_CASES
from ..models.shear2d import WALL_BAND
from .style import save_figure  # noqa: F401  (re-exported for the Fig. 10 script)

TITLES = {
    "rw_nodrift": "random walk, no drift correction",
    "rw_drift": "random walk with grad.D drift",
    "mt": "mass transfer only",
}
MASS_FLOOR = 1e-6  # the paper shows only particles with mass > 1e-6
# plasma without its pale-yellow end, so the equal (largest) walker masses stay visible on white
MASS_CMAP = ListedColormap(matplotlib.colormaps["plasma"](np.linspace(0.0, 0.8, 256)), name="plasma_08")
N_BINS = 20  # y bins of width 0.05 = WALL_BAND, so the outer bins are the wall bands
SOURCE_COLUMNS = {
    "figure": "`fig10`",
    "panel": f"a-c: particles with mass > {MASS_FLOOR:g} coloured by mass; d-f: mass against y",
    "series": "the case's title (a-c), or the legend label of the histogram or line (d-f)",
    "case": "shear case: " + ", ".join(f"`{c}`" for c in SHEAR_CASES),
    "seed": "seed of the realisation",
    "n": "particles in the run, massless ones included",
    "x_name": "`x` (a-c), `y bin centre` (histograms) or `y` (the uniform-density line)",
    "x": "its value [L]",
    "y_name": "`y` (a-c); `mass density`, `walker density` or `density` (d-f)",
    "y": "its value: position y in a-c; in d-f the mass (or walker count) per unit y, normalised to integrate to 1 "
    "over 0 < y < 1 [L in a-c, 1/L in d-f]",
    "mass": f"particle mass, the colour of a-c (only particles with mass > {MASS_FLOOR:g} are drawn); NaN in d-f",
}


def _plume_xlim(x: np.ndarray, length: float = 400.0) -> tuple[float, float]:
    """x-limits around the shown particles (no wrap handling needed while the plume spans < length)."""
    if x.size == 0:
        return 0.0, length
    lo, hi = float(x.min()), float(x.max())
    pad = 0.05 * max(hi - lo, 1.0)
    return lo - pad, hi + pad


def _rows(panel: str, series: str, df: pd.DataFrame, x_name: str, x, y_name: str, y, mass=np.nan) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "figure": "fig10",
            "panel": panel,
            "series": series,
            "case": df["case"].iloc[0],
            "seed": int(df["seed"].iloc[0]),
            "n": len(df),
            "x_name": x_name,
            "x": np.asarray(x, float),
            "y_name": y_name,
            "y": np.asarray(y, float),
            "mass": mass,
        }
    )


def source_data(states: list[pd.DataFrame]) -> pd.DataFrame:
    """What Fig. 10 plots: every particle with mass > MASS_FLOOR (a-c) and the y histograms (d-f)."""
    by_case = {df["case"].iloc[0]: df for df in states if len(df)}
    edges = np.linspace(0.0, 1.0, N_BINS + 1)
    mid = 0.5 * (edges[1:] + edges[:-1])
    parts = []
    for k, case in enumerate(c for c in SHEAR_CASES if c in by_case):
        df = by_case[case]
        s = df[df["mass"].to_numpy(float) > MASS_FLOOR]
        title, n = TITLES.get(case, case), len(df)
        parts.append(_rows("abc"[k], title, df, "x", s["x"], "y", s["y"], s["mass"].to_numpy(float)))
        m = s["mass"].to_numpy(float)
        dens, _ = np.histogram(s["y"].to_numpy(float), bins=edges, weights=m)
        dens = dens / (m.sum() * np.diff(edges)) if m.sum() > 0 else dens
        label = ("mass-carrying walkers (equal masses)" if case != "mt" else "particle mass") + f", N = {n:,}"
        parts.append(_rows("def"[k], label, df, "y bin centre", mid, "mass density", dens))
        if case != "mt":  # all walkers, massless ones included: the same physics with 20x the count
            all_d, _ = np.histogram(df["y"].to_numpy(float), bins=edges, density=True)
            parts.append(_rows("def"[k], f"all {n:,} walkers", df, "y bin centre", mid, "walker density", all_d))
        parts.append(_rows("def"[k], "uniform in $y$", df, "y", [0.0, 1.0], "density", [1.0, 1.0]))
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(SOURCE_COLUMNS))


def fig10(states: list[pd.DataFrame]) -> tuple[Figure, pd.DataFrame]:
    """Fig. 10: (a-c) positions of particles with mass > 1e-6 coloured by mass; (d-f) mass against y."""
    data = source_data(states)
    order = list(dict.fromkeys(data["case"]))
    fig = Figure(figsize=(5.0 * max(len(order), 1), 7.6), layout="constrained")
    axes = fig.subplots(2, max(len(order), 1), squeeze=False, gridspec_kw={"height_ratios": [1.25, 1.0]})
    dots = data[data["panel"].isin(list("abc"))]
    norm = LogNorm(vmin=MASS_FLOOR, vmax=float(max(dots["mass"].max(), MASS_FLOOR * 10) if len(dots) else 1.0))
    edges = np.linspace(0.0, 1.0, N_BINS + 1)
    sc, hist_max = None, 1.0
    for k, case in enumerate(order):
        s, run = dots[dots["case"] == case], data[data["case"] == case].iloc[0]
        n, seed, title = int(run["n"]), int(run["seed"]), TITLES.get(case, case)
        ax = axes[0, k]
        sc = ax.scatter(s["x"], s["y"], c=s["mass"], s=3, linewidths=0, cmap=MASS_CMAP, norm=norm, rasterized=True)
        ax.set_xlim(*_plume_xlim(s["x"].to_numpy(float)))
        ax.set_ylim(0.0, 1.0)
        ax.set_title(f"({'abc'[k]}) {title}", loc="left", fontsize=11)
        ax.set_xlabel("position along the flow $x$ [L]")
        ax.set_ylabel("lateral position $y$ [L]")
        ax.text(
            0.02,
            0.02,
            f"N = {n:,}, seed {seed}\n{len(s):,} particles with mass > {MASS_FLOOR:g}",
            transform=ax.transAxes,
            fontsize=8,
            va="bottom",
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1.5},
        )

        ax = axes[1, k]
        for series, g in data[data["panel"] == "def"[k]].groupby("series", sort=False):
            y = g["y"].to_numpy(float)
            if g["y_name"].iloc[0] == "mass density":
                ax.stairs(y, edges, fill=True, color="#009E73" if case == "mt" else "#0072B2", alpha=0.55, label=series)
            elif g["y_name"].iloc[0] == "walker density":
                ax.stairs(y, edges, color="#D55E00", linewidth=1.2, label=series)
            else:
                ax.axhline(y[0], color="black", linestyle="--", linewidth=1.2, label=series)
            hist_max = max(hist_max, float(y.max()))
        for lo, hi in ((0.0, WALL_BAND), (1.0 - WALL_BAND, 1.0)):
            ax.axvspan(lo, hi, color="0.85", zorder=0, linewidth=0)
        ax.set_title(f"({'def'[k]}) {title}", loc="left", fontsize=11)
        ax.set_xlabel("lateral position $y$ [L] (grey: within 0.05 of a wall)")
        ax.set_ylabel("mass per unit $y$ (normalised)")
        ax.set_xlim(0.0, 1.0)
        ax.legend(loc="upper center", fontsize=8, framealpha=0.9)
    for ax in axes[1]:
        ax.set_ylim(0.0, 1.3 * hist_max)
    if sc is not None:
        fig.colorbar(sc, ax=list(axes[0]), label="particle mass", shrink=0.9, pad=0.01)
    return fig, data
