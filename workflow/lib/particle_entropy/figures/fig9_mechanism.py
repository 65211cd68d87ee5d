"""figures/fig9_mechanism.png: why Fig. 9's minima differ between the paper's equations and the
authors' algorithm, and why Fig. 8's fine grids turn up late; controlled experiments drawn.

(a) mean COMIC +-1 std against N for the mechanism sweeps (same seeds, one change at a time);
(b) SSE/N +-1 standard error against N, with each model's noise-free floor f (its run on evenly
    spaced particles, lattice.py) and the N* = a / f where the sampling error a / N meets it,
    COMIC's minimum for SSE/N = a/N + f; grey, the floor the cut kernel's variance deficit alone
    would give (D times kernels.truncated_variance_fraction);
(c) each variant's COMIC minus the equations' COMIC, realisation by realisation (same seeds),
    mean +-1 standard error: a difference outside its error bar is an effect, not noise;
(d) Fig. 8's ln(SSE/N) against time on the paper's FD domain and on a longer one (same dx).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..core.case import Case, rows_of
from ..core.labels import case_label, variant_text
from ..numerics.bandwidths import truncated_variance_fraction
from .fig9 import PAPER_STYLES as FIG9_STYLES
from .style import (
    BLACK,
    BLUE,
    GREEN,
    GREY,
    ORANGE,
    PURPLE,
    SKY,
    VERMILLION,
    Series,
    distinct_models,
    draw,
    mark_no_data,
    n_ticks,
    rows_nearest,
    source_table,
    style_axes,
    styles,
)

FIGURE = "fig9_mechanism"
# one distinct colour per model, in config order (the equations first: the paper's green)
PALETTE = (GREEN, ORANGE, SKY, PURPLE, VERMILLION, BLACK, BLUE)


def truncation_floor(D: float, t: float, fraction: float, omega: float) -> float:
    """SSE/N between N(0, 2Dt) and N(0, 2 fraction D t) sampled at uniform random points of a
    domain Omega: (1/Omega) int (g - g')^2 dx, by the Gaussian product integral."""
    a, b = 2.0 * D * t, 2.0 * fraction * D * t
    cross = 1.0 / math.sqrt(2.0 * math.pi * (a + b))
    return (1.0 / math.sqrt(4.0 * math.pi * a) + 1.0 / math.sqrt(4.0 * math.pi * b) - 2.0 * cross) / omega


def _label(model: Case, equations: Case | None) -> str:
    """A model by what it changes from the paper's equations (a preset by its name)."""
    text = variant_text(model)
    if model == equations:
        return "paper's equations (whole Gaussian)" + (f", {text}" if text else "")
    return text or case_label(model, n=False)


def _comic_series(comic: pd.DataFrame, models, cases, style, equations, t_final) -> list[Series]:
    """Panel (a): mean COMIC +-1 std of every model; panel (b): SSE/N +-1 standard error."""
    out = []
    for model in models:
        g = pd.concat([rows_of(comic, c) for c in cases if c.model == model])
        if g.empty:
            continue
        g = rows_nearest(g, t_final).sort_values("n")
        n = g["n"].to_numpy(float)
        r = g["n_realisations"].to_numpy(int)
        common = dict(
            case=model,
            x_name="N",
            x=n,
            n=n.astype(int),
            time=g["time_step"].to_numpy(float),
            n_realisations=r,
            style=style[model],
        )
        mu = g["COMIC_mean"].to_numpy(float)
        out.append(
            Series(
                "a",
                f"{case_label(model, n=False)}: mean COMIC",
                legend=_label(model, equations),
                y_name="COMIC",
                y=mu,
                y_std=g["COMIC_std"].to_numpy(float),
                kind="errorbar",
                marked=mu == mu.min(),
                **common,
            )
        )
        sse = g["SSE_mean"].to_numpy(float) / n
        se = g["SSE_std"].to_numpy(float) / n / np.sqrt(np.maximum(r, 1))
        out.append(
            Series(
                "b",
                f"{case_label(model, n=False)}: SSE/N",
                legend="_" + _label(model, equations),  # named in panel (a)
                y_name="SSE/N",
                y=sse,
                y_lo=sse - se,
                y_hi=sse + se,
                kind="errorbar",
                **common,
            )
        )
    return out


def _floor_series(floors: pd.DataFrame, comic: pd.DataFrame, models, cases, style, equations, t_final, ns):
    """Panel (b): each model's lattice floor f as a line across the N drawn, labelled with
    N* = a / f, a the median of (SSE/N - f) N over its N from 1,000 to 10,000 (where the sampling
    error behaves as a / N; below, the kernel is not resolved and it falls faster)."""
    if floors.empty or not len(ns):
        return []
    at = rows_nearest(floors, t_final)
    out = []
    lattice_models = list(dict.fromkeys(Case.from_row(r).model for _, r in at.iterrows()))
    for model in lattice_models:
        f = float(rows_of(at, model)["SSE_over_N"].iloc[0])
        text = f"{_label(model, equations)}: floor {f:.2g}"
        if model in models and not comic.empty:
            g = rows_nearest(pd.concat([rows_of(comic, c) for c in cases if c.model == model]), t_final)
            small = g[(g["n"] >= 1000) & (g["n"] <= 10000)]
            if len(small):
                a = float(np.median((small["SSE_mean"] / small["n"] - f) * small["n"]))
                text += f", N* = a/floor ≈ {a / f:,.0f}"
        st = style.get(model, {"color": GREY})
        out.append(
            Series(
                "b",
                f"{case_label(model, n=False)}: lattice floor",
                legend=text,
                case=model,
                x_name="N",
                x=np.array([min(ns), max(ns)], float),
                y_name="SSE/N",
                y=np.array([f, f]),
                time=float(at["time_step"].iloc[0]),
                n_realisations=1,
                style={
                    "color": st.get("color", GREY),
                    "linestyle": (0, (5, 3)) if model in models else "-.",
                    "linewidth": 1.0,
                    "marker": None,
                },
            )
        )
    return out


def _paired_series(realisations: pd.DataFrame, models, style, equations, t_final) -> list[Series]:
    """Panel (c): COMIC(model) - COMIC(equations) per seed and N, mean +-1 standard error."""
    if equations is None or realisations.empty:
        return []
    at = rows_nearest(realisations, t_final)
    base = rows_of(at, equations).set_index(["n", "seed"])["COMIC"]
    out = []
    for model in models:
        if model == equations:
            continue
        mine = rows_of(at, model).set_index(["n", "seed"])["COMIC"]
        diff = (mine - base).dropna()
        if diff.empty:
            continue
        g = diff.groupby(level="n")
        mean, std, count = g.mean(), g.std(ddof=1).fillna(0.0), g.size()
        se = (std / np.sqrt(count)).to_numpy(float)
        n = mean.index.to_numpy(float)
        y = mean.to_numpy(float)
        out.append(
            Series(
                "c",
                f"{case_label(model, n=False)}: COMIC minus the equations' (same seeds)",
                legend=_label(model, equations),
                case=model,
                x_name="N",
                x=n,
                n=n.astype(int),
                y_name="paired COMIC difference",
                y=y,
                y_lo=y - se,
                y_hi=y + se,
                kind="errorbar",
                n_realisations=count.to_numpy(int),
                time=float(at["time"].iloc[0]),
                style=style[model],
            )
        )
    return out


def _fd_series(fd: pd.DataFrame) -> list[Series]:
    """Panel (d): ln(SSE/n) of each FD grid (n = the paper's grid label, dx = L_paper / n) against
    time, on each domain length: solid the paper's, dashed the longer one."""
    if fd.empty:
        return []
    lengths = sorted(fd["fd_length"].unique())
    colours = ["#0072B2", "#009E73", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9"]
    out = []
    for j, n in enumerate(sorted(fd["n"].unique())):
        for k, length in enumerate(lengths):
            g = fd[(fd["n"] == n) & (fd["fd_length"] == length)].sort_values("time")
            line = "-" if k == 0 else ("--" if k == 1 else ":")
            out.append(
                Series(
                    "d",
                    f"FD N = {int(n):,}, domain length {length:g}",
                    case=Case("fd", "implicit", int(n)),
                    x_name="time",
                    x=g["time"].to_numpy(float),
                    y_name="ln(SSE/N)",
                    y=np.log(g["SSE"].to_numpy(float) / n),
                    n_realisations=1,
                    time=g["time"].to_numpy(float),
                    style={"color": colours[j % len(colours)], "linestyle": line, "marker": None},
                )
            )
    return out


def fig9_mechanism(comic, realisations, fd, cases, *, D: float, t_final: float, omega: float, floors=None):
    """The four panels (module docstring) -> (Figure, source data)."""
    models = distinct_models(cases)
    style = {
        m: {**st, "color": PALETTE[k % len(PALETTE)]} for k, (m, st) in enumerate(styles(cases, FIG9_STYLES).items())
    }
    # the reference of panel (c): the first model with the paper's symmetric matrix and whole kernel
    equations = next((m for m in models if m.scheme == "symmetric" and m.truncation is None), None)
    fig = Figure(figsize=(12.5, 10.0), layout="constrained")
    axes = list(fig.subplots(2, 2).ravel())
    out = []
    if comic.empty:
        for ax in axes[:3]:
            mark_no_data(ax, "mechanism COMIC table")
    else:
        main = _comic_series(comic, models, cases, style, equations, t_final)
        paired = _paired_series(realisations, models, style, equations, t_final)
        for s in main + paired:
            draw(axes["abc".index(s.panel)], s)
        out += main + paired
        ns = np.concatenate([s.x for s in main]) if main else []
        time = main[0].time[0] if main else t_final
        style_axes(
            axes[0],
            "a",
            f"COMIC at t = {time:g}, same seeds, one change at a time",
            r"COMIC $= 2\ln(SSE/N) - \ln\Delta V$ (mean ± 1 std)",
            xlabel="number of particles $N$",
            legend=None,
        )
        style_axes(
            axes[1],
            "b",
            "SSE/N falls to each scheme's floor (dashed: even spacing)",
            "SSE/N (mean ± 1 s.e.)",
            xlabel="number of particles $N$",
            logy=True,
            legend=None,
        )
        floor_lines = _floor_series(
            floors if floors is not None else pd.DataFrame(), comic, models, cases, style, equations, t_final, ns
        )
        for s in floor_lines:
            draw(axes[1], s)
        out += floor_lines
        cut = sorted({m.truncation for m in models if m.truncation is not None})
        for k in cut:
            fraction = truncated_variance_fraction(k)
            floor = truncation_floor(D, time, fraction, omega)
            axes[1].axhline(
                floor,
                color=GREY,
                linestyle=":",
                linewidth=1.2,
                label=f"D × {fraction:.4f} alone (cut at {k:g} widths), analytic: {floor:.2g}",
            )
            out.append(
                Series(
                    "b",
                    f"predicted floor, kernel cut at {k:g} widths",
                    None,
                    x_name="N",
                    x=np.array([min(ns), max(ns)], float),
                    y_name="SSE/N",
                    y=np.array([floor, floor]),
                    time=time,
                    style={"color": GREY, "linestyle": ":"},
                )
            )
        style_axes(
            axes[2],
            "c",
            "the same seeds: each change's own effect",
            "COMIC − COMIC of the equations (mean ± 1 s.e.)",
            xlabel="number of particles $N$",
            legend=None,
        )
        axes[2].axhline(0.0, color="black", linewidth=0.8)
        for ax in axes[:3]:
            if len(ns):
                n_ticks(ax, ns)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(loc="lower left" if ax is axes[1] else "best", fontsize=6.5 if ax is axes[1] else 7)
    fd_series = _fd_series(fd)
    for s in fd_series:
        draw(axes[3], s)
    out += fd_series
    if fd_series:
        style_axes(
            axes[3],
            "d",
            "Fig. 8: FD error against time; zero ends at the domain edge",
            r"$\ln(SSE/N)$, N = the paper's grid",
            xlabel="time",
            logx=False,
            legend=None,
        )
        axes[3].plot([], [], color="0.3", linestyle="-", label=f"domain length {sorted(fd['fd_length'].unique())[0]:g}")
        for k, length in enumerate(sorted(fd["fd_length"].unique())[1:], start=1):
            axes[3].plot([], [], color="0.3", linestyle="--" if k == 1 else ":", label=f"domain length {length:g}")
        axes[3].legend(loc="best", fontsize=7, ncol=2)
    else:
        mark_no_data(axes[3], "FD domain experiment")
    return fig, source_table(FIGURE, out)
