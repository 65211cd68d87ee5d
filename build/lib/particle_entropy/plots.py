"""Figures 1-9 of Benson et al. (2020) drawn from run tables, case summaries, states and the COMIC table.

Every ``figN`` takes pandas DataFrames and returns a matplotlib Figure (not registered with pyplot);
``save_figure`` writes it as byte-stable PNG and PDF. Tables may be run tables (column ``X``) or
case summaries (column ``X_mean``, with ``X_std`` drawn as a shaded band).
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

# Okabe-Ito colour-blind-safe palette
BLUE, VERMILLION, GREEN, ORANGE, SKY, PURPLE, GREY = (
    "#0072B2", "#D55E00", "#009E73", "#E69F00", "#56B4E9", "#CC79A7", "#8C8C8C")
ANALYTIC = {"color": "black", "linestyle": "--", "linewidth": 1.3, "zorder": 5}
NAMES = {"bins": "binned", "fixed": "fixed kernel", "adaptive": "adaptive kernel",
         "collision": "collision", "sph": "SPH", "implicit": "implicit"}
# line style of each model: (method, kernel) -> matplotlib keywords
STYLE = {
    ("pt", "bins"): {"color": ORANGE, "marker": "s"},
    ("pt", "fixed"): {"color": SKY, "marker": "^"},
    ("pt", "adaptive"): {"color": BLUE, "marker": "o"},
    ("mtpt", "collision"): {"color": GREEN, "marker": "D"},
    ("mtpt", "sph"): {"color": VERMILLION, "marker": "D"},
}
T_LABEL = "time $t$ [T]"
PNG_META = {"Software": None}
PDF_META = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}


# ---------------------------------------------------------------- helpers


def save_figure(fig: Figure, png_path, pdf_path) -> None:
    """Write ``fig`` as PNG and PDF (150 dpi, no time stamps or versions: byte-stable) and close it."""
    for path, meta in ((png_path, PNG_META), (pdf_path, PDF_META)):
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=150, metadata=meta)
    import matplotlib.pyplot as plt  # only to release figures a caller made through pyplot

    plt.close(fig)


def _figure(ncols: int, width: float = 5.2, height: float = 4.0, nrows: int = 1):
    """A constrained-layout figure with a flat list of axes."""
    fig = Figure(figsize=(width * ncols, height * nrows), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    return fig, list(axes)


def _style(ax, letter: str | None, title: str, ylabel: str, xlabel: str = T_LABEL,
           logx: bool = True, logy: bool = False, legend: str | None = "best") -> None:
    """Shared look: panel letter and title, labels, log axes, light grid, legend."""
    ax.set_title(f"({letter}) {title}" if letter else title, loc="left", fontsize=11)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.grid(True, which="major", color="0.9", linewidth=0.8)
    ax.set_axisbelow(True)
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(loc=legend, fontsize=8, framealpha=0.9)


def _case(df: pd.DataFrame) -> dict:
    return {k: df[k].iloc[0] for k in ("method", "kernel", "n", "eta") if k in df.columns}


def _label(df: pd.DataFrame) -> str:
    """Legend text: method, kernel, eta (MTPT), N and realisations, e.g. 'MTPT SPH, η=1, N=300 (5 runs)'."""
    c = _case(df)
    text = f"{c['method'].upper()} {NAMES.get(c['kernel'], c['kernel'])}"
    if c["method"] == "mtpt":
        text += f", η={c['eta']:g}"
    text += f", N={int(c['n']):,}"
    return text + (f" ({int(df['n_realisations'].iloc[0])} runs)" if "n_realisations" in df.columns else "")


def _select(tables, method=None, kernel=None, eta=None, n=None) -> list[pd.DataFrame]:
    """Tables whose case columns match the given values (None: any)."""
    out = []
    for df in tables:
        c = _case(df)
        if ((method is None or c["method"] == method) and (kernel is None or c["kernel"] == kernel)
                and (eta is None or math.isclose(float(c["eta"]), eta)) and (n is None or int(c["n"]) == n)):
            out.append(df)
    return out


def _ns(tables, descending: bool = False) -> list[int]:
    return sorted({int(df["n"].iloc[0]) for df in tables}, reverse=descending)


def _col(df: pd.DataFrame, name: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Values of ``name`` (``name_mean`` in a summary) and its ensemble std (None in a run table)."""
    if f"{name}_mean" in df.columns:
        return df[f"{name}_mean"].to_numpy(float), df[f"{name}_std"].to_numpy(float)
    return df[name].to_numpy(float), None


def _curve(ax, df: pd.DataFrame, name: str, label: str, logy: bool = False, band: bool = True,
           markevery: int = 8, **style) -> None:
    """Plot ``name`` vs time for t > 0 and finite values (positive on log y), with a ±1 std band."""
    t = df["time"].to_numpy(float)
    y, sd = _col(df, name)
    ok = (t > 0) & np.isfinite(y) & ((y > 0) if logy else True)
    hollow = style.pop("open", False)
    style = {"linewidth": 1.4, "markersize": 4.5, "markevery": markevery, **style}
    if hollow and style.get("marker"):
        style["markerfacecolor"] = "white"
    line, = ax.plot(t[ok], y[ok], label=label, **style)
    if band and sd is not None and np.any(sd[ok] > 0):
        lo, hi = y[ok] - sd[ok], y[ok] + sd[ok]
        if logy:
            lo = np.where(lo > 0, lo, np.nan)  # no band below zero on a log axis
        ax.fill_between(t[ok], lo, hi, color=line.get_color(), alpha=0.2, linewidth=0)


def _model_style(df: pd.DataFrame, **override) -> dict:
    c = _case(df)
    return {**STYLE.get((c["method"], c["kernel"]), {"color": GREY, "marker": "."}), **override}


def _analytic(ax, df: pd.DataFrame, name: str, label: str, logy: bool = False) -> None:
    _curve(ax, df, name, label, logy=logy, band=False, marker=None, **ANALYTIC)


def _nearest(df: pd.DataFrame, time: float) -> pd.DataFrame:
    """Rows at the time nearest ``time``."""
    t = df["time"].to_numpy(float)
    return df[t == t[np.argmin(np.abs(t - time))]]


def _no_data(ax, what: str) -> None:
    ax.text(0.5, 0.5, f"no data:\n{what}", transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax.set_xticks([])
    ax.set_yticks([])


# ---------------------------------------------------------------- figures


def fig1(runs: list[pd.DataFrame]) -> Figure:
    """Fig. 1: single-realisation H (=H_D of PT) and H_C vs time; one panel per N (ascending)."""
    ns = _ns(runs)
    fig, axes = _figure(len(ns))
    for letter, ax, n in zip("abcdefgh", axes, ns):
        for sel in (("pt", "bins"), ("pt", "fixed"), ("mtpt", "collision", 1.0)):
            for df in _select(runs, *sel, n=n)[:1]:
                _curve(ax, df, "H_C", f"$H_C$, {_label(df)}", **_model_style(df))
        pt = _select(runs, "pt", n=n)
        if pt:
            _curve(ax, pt[0], "H_D", f"$H$ ($H_D$) of PT = ln N, N={n:,}", color=PURPLE, linestyle=":",
                   linewidth=2.0, marker=None)
        ref = _select(runs, n=n)[0]
        _analytic(ax, ref, "H_C_analytic", f"$H_C$ analytic (Eq. 14), N={n:,}")
        t_settle = ref["dV"].iloc[0] ** 2 / (4 * np.pi * np.e * ref["D"].iloc[0]) if "D" in ref else 0.0
        if t_settle > ref.loc[ref["time"] > 0, "time"].min():  # draw only inside the plotted range
            ax.axvline(t_settle, color="0.5", linewidth=0.8, linestyle="-.",
                       label=r"settling time $\Delta V^2/(4\pi e D)$")
        ax.set_ylim(bottom=max(ax.get_ylim()[0], -3.0))
        _style(ax, letter, f"N = {n:,}", "entropy $H$, $H_C$ [nats]", legend="lower right")
    return fig


def fig2(runs: list[pd.DataFrame]) -> Figure:
    """Fig. 2: single-realisation dilution index E vs time (log-log); one panel per N (descending)."""
    ns = _ns(runs, descending=True)
    fig, axes = _figure(len(ns))
    for letter, ax, n in zip("abcdefgh", axes, ns):
        for sel in (("pt", "bins"), ("pt", "fixed"), ("mtpt", "collision", 1.0)):
            for df in _select(runs, *sel, n=n)[:1]:
                _curve(ax, df, "E", _label(df), logy=True, **_model_style(df))
        _analytic(ax, _select(runs, n=n)[0], "E_analytic", r"analytic $\sqrt{4\pi e D t}$", logy=True)
        _style(ax, letter, f"N = {n:,}", "dilution index $E$ [L]", logy=True, legend="upper left")
    return fig


def fig3(summaries: list[pd.DataFrame]) -> Figure:
    """Fig. 3: ensemble-mean H_C vs time, adaptive-kernel PT and SPH MTPT (eta=1), both N on one axes."""
    fig, (ax,) = _figure(1, width=7.0, height=4.8)
    ns = _ns(summaries, descending=True)
    for i, n in enumerate(ns):
        for sel in (("pt", "adaptive"), ("mtpt", "sph", 1.0)):
            for df in _select(summaries, *sel, n=n)[:1]:
                _curve(ax, df, "H_C", _label(df), **_model_style(df, open=i > 0))
        _analytic(ax, _select(summaries, n=n)[0], "H_C_analytic", f"analytic $H_C$, N={n:,}")
    ax.set_ylim(bottom=max(ax.get_ylim()[0], -3.0))
    _style(ax, None, "ensemble means ± 1 std",
           "consistent entropy $H_C$ [nats]", legend="lower right")
    return fig


def fig4(summaries: list[pd.DataFrame]) -> Figure:
    """Fig. 4: ensemble-mean E vs time (log-log): adaptive PT, SPH MTPT, collision MTPT in grey."""
    ns = _ns(summaries, descending=True)
    fig, axes = _figure(len(ns))
    for letter, ax, n in zip("abcdefgh", axes, ns):
        sel = [(("pt", "adaptive"), {}), (("mtpt", "sph", 1.0), {}),
               (("mtpt", "collision", 1.0), {"color": GREY, "open": True, "zorder": 1})]
        for case, over in sel:
            for df in _select(summaries, *case, n=n)[:1]:
                _curve(ax, df, "E", _label(df), logy=True, **_model_style(df, **over))
        _analytic(ax, _select(summaries, n=n)[0], "E_analytic", r"analytic $\sqrt{4\pi e D t}$", logy=True)
        _style(ax, letter, f"N = {n:,} (ensemble mean ± 1 std)", "dilution index $E$ [L]", logy=True,
               legend="upper left")
    return fig


def fig5(summaries: list[pd.DataFrame]) -> Figure:
    """Fig. 5: ensemble-mean E vs time for MTPT collision and SPH at eta = 1 and 0.1 (log-log)."""
    ns = _ns(summaries, descending=True)
    fig, axes = _figure(len(ns))
    for letter, ax, n in zip("abcdefgh", axes, ns):
        for kernel in ("collision", "sph"):
            for eta, over in ((1.0, {}), (0.1, {"linestyle": "-.", "open": True})):
                for df in _select(summaries, "mtpt", kernel, eta, n)[:1]:
                    _curve(ax, df, "E", _label(df), logy=True, **_model_style(df, **over))
        _analytic(ax, _select(summaries, n=n)[0], "E_analytic", r"analytic $\sqrt{4\pi e D t}$", logy=True)
        _style(ax, letter, f"N = {n:,} (ensemble mean ± 1 std)", "dilution index $E$ [L]", logy=True,
               legend="upper left")
    return fig


def fig6(summaries: list[pd.DataFrame], D: float = 1e-3) -> Figure:
    """Fig. 6: ensemble-mean H_PMF = H_D + ln(Omega/N) vs time for each N, with the analytic H_I(t)."""
    fig, (ax,) = _figure(1, width=7.0, height=4.8)
    ordered = sorted(summaries, key=lambda df: int(df["n"].iloc[0]))
    cmap = matplotlib.colormaps["viridis"]
    for i, df in enumerate(ordered):
        colour = cmap(0.85 * i / max(len(ordered) - 1, 1))
        _curve(ax, df, "H_PMF", _label(df), band=False, color=colour, marker=None)
    if ordered:
        if "D" in ordered[0].columns:
            D = float(ordered[0]["D"].iloc[0])
        t = np.unique(np.concatenate([df["time"].to_numpy(float) for df in ordered]))
        t = t[t > 0]
        ax.plot(t, np.log(np.sqrt(4 * np.pi * D * t)) + 0.5, label=r"analytic $H_I=\ln\sqrt{4\pi D t}+1/2$",
                **ANALYTIC)
    _style(ax, None, "PMF entropy, MTPT ensemble means", r"$H_{PMF}=H_D+\ln(\Omega/N)$ [nats]",
           legend="upper left")
    return fig


def fig7(states: list[pd.DataFrame], D: float = 1e-3, t: float = 1000.0) -> Figure:
    """Fig. 7: concentrations at t = 1000 (MTPT collision eta=0.1, fixed-kernel PT) and their spread."""
    ns = _ns(states, descending=True)
    fig, axes = _figure(len(ns), width=5.6, height=5.2)
    var = 2 * D * t
    gauss = lambda x: np.exp(-x**2 / (2 * var)) / np.sqrt(2 * np.pi * var)  # noqa: E731
    for letter, ax, n in zip("abcdefgh", axes, ns):
        dot = 2 if n >= 10000 else 8  # dense clouds need small dots
        sel = [(("mtpt", "collision", 0.1), dict(s=dot, color=GREEN, alpha=0.6, linewidths=0, zorder=2)),
               (("pt", "fixed"), dict(s=3 * dot, facecolors="none", edgecolors=BLUE, linewidths=0.7, zorder=3))]
        xs = [np.array([-5.0, 5.0])]
        for case, kw in sel:
            for df in _select(states, *case, n=n)[:1]:
                x, c, m = (df[k].to_numpy(float) for k in ("x", "c", "mass"))
                msd = np.mean((c - gauss(x)) ** 2)
                mean = np.sum(m * x) / np.sum(m)
                spread = np.sum(m * (x - mean) ** 2) / np.sum(m)
                label = f"{_label(df)}\n  mean sq. dev. from analytic {msd:.2g} L⁻², plume variance {spread:.2f} L²"
                ax.scatter(x, c, rasterized=True, label=label, **kw)
                xs.append(x)
        grid = np.linspace(min(map(np.min, xs)), max(map(np.max, xs)), 801)
        ax.plot(grid, gauss(grid), label=f"analytic Gaussian, variance $2Dt$ = {var:.2f} L²", **ANALYTIC)
        _style(ax, letter, f"N = {n:,}, t = {t:g}", "concentration $c$ [L⁻¹]", xlabel="position $x$ [L]",
               logx=False, legend=None)
        leg = ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=8, frameon=False)
        for handle in leg.legend_handles:  # same legend marker size whatever the dot size
            if hasattr(handle, "set_sizes"):
                handle.set_sizes([20])
    return fig


def fig8(summaries: list[pd.DataFrame], time_c: float = 250.0) -> Figure:
    """Fig. 8: FD fitness, (a) ln(SSE/N) and (b) COMIC vs time per grid, (c) both vs dx at t = time_c."""
    ordered = sorted(summaries, key=lambda df: int(df["n"].iloc[0]))
    fig, axes = _figure(3, width=4.6, height=4.0)
    cmap = matplotlib.colormaps["viridis"]
    rows = []
    for i, df in enumerate(ordered):
        colour = cmap(0.85 * i / max(len(ordered) - 1, 1))
        n, dx = int(df["n"].iloc[0]), float(df["dV"].iloc[0])
        half = df.assign(lnSSE=_col(df, "AIC")[0] / 2)
        label = f"Δx = {dx:.2g} (N = {n:,})"
        _curve(axes[0], half, "lnSSE", label, band=False, color=colour, marker=None)
        _curve(axes[1], df, "COMIC", label, band=False, color=colour, marker=None)
        row = _nearest(half, time_c).iloc[0]
        rows.append((dx, row["lnSSE"], _col(_nearest(df, time_c), "COMIC")[0][0], row["time"]))
    _style(axes[0], "a", "log-likelihood", r"$\ln(SSE/N)$ = AIC/2", legend="lower left")
    _style(axes[1], "b", "computational information criterion",
           r"COMIC $= 2\ln(SSE/N) - \ln\Delta x$", legend="lower left")
    if rows:
        dx, lnsse, comic, tc = map(np.array, zip(*sorted(rows)))
        ax = axes[2]
        ax.plot(dx, lnsse, "o-", color=BLUE, label=r"$\ln(SSE/N)$")
        ax.plot(dx, comic, "s-", color=VERMILLION, label=r"COMIC")
        k = int(np.argmin(comic))
        ax.plot(dx[k], comic[k], "*", color="black", markersize=14, zorder=6,
                label=f"min COMIC: Δx = {dx[k]:.2g} (N = {12 / dx[k]:,.0f})")
        _style(ax, "c", f"both measures at t = {tc[0]:g}", "fitness [nats]",
               xlabel=r"grid spacing $\Delta x$ [L]", legend="upper left")
    else:
        _no_data(axes[2], "FD summaries")
    return fig


def fig9(comic: pd.DataFrame, time: float = 1000.0) -> Figure:
    """Fig. 9: ensemble COMIC ± 1 std vs N for three MTPT models at t = 1000, minimum marked."""
    models = [("a", "mtpt collision eta=1", GREEN, "D"), ("b", "mtpt sph eta=1", VERMILLION, "D"),
              ("c", "mtpt collision eta=0.5", BLUE, "o")]
    fig, axes = _figure(3, width=4.6, height=4.0)
    for ax, (letter, model, colour, marker) in zip(axes, models):
        g = comic[comic["model"] == model]
        title = model.replace("mtpt", "MTPT").replace("eta", "η").replace("sph", "SPH")
        if g.empty:
            _style(ax, letter, title, "COMIC", xlabel="number of particles $N$")
            _no_data(ax, model)
            continue
        g = _nearest(g, time).sort_values("n")
        n, mu, sd = (g[k].to_numpy(float) for k in ("n", "COMIC_mean", "COMIC_std"))
        ax.errorbar(n, mu, yerr=sd, color=colour, marker=marker, markersize=5, capsize=3,
                    label="ensemble mean ± 1 std", zorder=3)
        if "COMIC_of_mean_SSE" in g:
            ce, lo, hi = (g[k].to_numpy(float) for k in ("COMIC_of_mean_SSE", "COMIC_of_mean_SSE_lo",
                                                         "COMIC_of_mean_SSE_hi"))
            lo = np.where(np.isfinite(lo), lo, ce - 3.0)  # std >= mean: draw a long lower bar
            ax.errorbar(n * 1.06, ce, yerr=[ce - lo, hi - ce], color=colour, marker=marker, mfc="white",
                        markersize=5, capsize=2, alpha=0.7, linestyle=":",
                        label="COMIC of ensemble-mean SSE (authors' code)", zorder=2)
        k = int(np.argmin(mu))
        ax.plot(n[k], mu[k], "*", color="black", markersize=14, zorder=6, label=f"minimum: N = {int(n[k]):,}")
        for ni, top, r in zip(n, mu + sd, g["n_realisations"]):
            ax.annotate(f"{int(r)}", (ni, top), textcoords="offset points", xytext=(0, 3), ha="center",
                        fontsize=7, color="0.35")
        ax.plot([], [], " ", label="numbers: realisations")
        ax.margins(x=0.08, y=0.12)
        _style(ax, letter, f"{title}, t = {g['time'].iloc[0]:g}", r"COMIC $= 2\ln(SSE/N) - \ln\Delta V$",
               xlabel="number of particles $N$", legend=None)
        ax.legend(loc="best", fontsize=7)
    return fig



# colour and marker of each trade-off model family (model name without its trunc= / growth= variant)
TRADEOFF_FAMILY = {
    "fd": {"color": "black", "marker": "o"},
    "pt bins": STYLE[("pt", "bins")],
    "pt fixed": STYLE[("pt", "fixed")],
    "pt adaptive": STYLE[("pt", "adaptive")],
    "mtpt collision eta=1": STYLE[("mtpt", "collision")],
    "mtpt sph eta=1": {**STYLE[("mtpt", "sph")], "marker": "v"},
    "mtpt collision eta=0.5": {"color": PURPLE, "marker": "D", "markerfacecolor": "white"},
    "mtpt sph eta=0.5": {"color": GREY, "marker": "v", "markerfacecolor": "white"},
}
# line style of each variant: (truncated, time-step growth) -> linestyle
TRADEOFF_VARIANT = {(False, False): ("-", "baseline"), (True, False): ("--", "truncated kernel (trunc=)"),
                    (False, True): (":", "Δt growth variant (growth=)"), (True, True): ("-.", "truncated and Δt growth")}


def _tradeoff_family(model: str) -> str:
    import re

    return re.sub(r"\s+(trunc|growth)=\S+", "", model).strip()


def _tradeoff_label(model: str) -> str:
    """Legend text of a model, e.g. 'mtpt sph eta=1 trunc=3' -> 'MTPT SPH, η=1, truncation 3'."""
    words = model.split()
    text = " ".join(w.upper() if w in ("fd", "pt", "mtpt") else NAMES.get(w, w) for w in words if "=" not in w)
    extras = [w.replace("eta=", "η=").replace("trunc=", "truncation ").replace("growth=", "Δt growth ×")
              for w in words if "=" in w]
    return ", ".join([text, *extras])


def tradeoff(table: pd.DataFrame) -> Figure:
    """Speed-accuracy trade-off: error against cost and N, COMIC optimum starred."""
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogLocator

    times = sorted(table["time"].unique()) if len(table) else []
    fig = Figure(figsize=(11.5, 4.3 * max(len(times), 1)), layout="constrained")
    axes = fig.subplots(max(len(times), 1), 2, squeeze=False)
    ylabel = "concentration RMSE sqrt(SSE/n) [1/L]"
    xlabels = ("wall time per realisation [s]", "number of particles or FD intervals N")
    if not times:
        for ax, xlabel in zip(axes[0], xlabels):
            _style(ax, None, "speed-accuracy trade-off", ylabel, xlabel=xlabel, logx=False, legend=None)
            _no_data(ax, "tradeoff table")
        return fig
    families = dict(TRADEOFF_FAMILY)
    spare = [BLUE, VERMILLION, GREEN, ORANGE, SKY, PURPLE]
    for family in dict.fromkeys(map(_tradeoff_family, sorted(table["model"].unique()))):
        if family not in families:  # unforeseen family: a hollow cross in the next palette colour
            families[family] = {"color": spare.pop(0) if spare else GREY, "marker": "X", "markerfacecolor": "white"}
    rank = {f: i for i, f in enumerate(families)}  # legend order: FD, PT, MTPT, then unforeseen families
    models = sorted(table["model"].unique(), key=lambda m: (rank[_tradeoff_family(m)], m))
    handles, variants = {}, set()
    letters = iter("abcdefghijklmnopqrstuvwxyz")
    for row, time in zip(axes, times):
        at = table[table["time"] == time]
        for model in models:
            g = at[at["model"] == model].sort_values("n")
            g = g[np.isfinite(g["rmse"]) & np.isfinite(g["wall_s"]) & (g["rmse"] > 0) & (g["wall_s"] > 0)]
            if g.empty:
                continue
            variant = (" trunc=" in model, " growth=" in model)
            variants.add(variant)
            style = {**families[_tradeoff_family(model)], "linestyle": TRADEOFF_VARIANT[variant][0]}
            best = g[g["is_comic_optimum"].astype(bool)]
            for ax, x in zip(row, ("wall_s", "n")):
                line, = ax.plot(g[x], g["rmse"], label=_tradeoff_label(model), linewidth=1.4, markersize=4.5,
                                **style)
                ax.plot(best[x], best["rmse"], "*", color=style["color"], markeredgecolor="black",
                        markeredgewidth=0.8, markersize=13, zorder=6)
            handles.setdefault(line.get_label(), line)
        row[1].sharey(row[0])  # same error scale in both panels of a row: read across at a target error
        for ax, xlabel in zip(row, xlabels):
            _style(ax, next(letters), f"t = {time:g}", ylabel, xlabel=xlabel, logy=True, legend=None)
            # labelled 1-2-5 error levels with light horizontal lines: read off the cheapest model per error
            ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
            ax.grid(True, which="minor", axis="y", color="0.95", linewidth=0.6)
        row[1].set_ylabel("")  # shared with the left panel
    star = Line2D([], [], linestyle="none", marker="*", markersize=13, color="white", markeredgecolor="black",
                  markeredgewidth=0.8, label="COMIC optimum (lowest mean COMIC)")
    key = [Line2D([], [], color="0.3", linestyle=ls, label=text)
           for v, (ls, text) in TRADEOFF_VARIANT.items() if v in variants]
    fig.legend(handles=[*handles.values(), star, *key], loc="outside right center", fontsize=8, frameon=False,
               handlelength=3.0)
    return fig
