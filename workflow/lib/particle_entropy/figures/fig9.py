"""Fig. 9: ensemble COMIC against N per kernel and eta, every scheme side by side, minima starred,
and below each panel how often each N is the argmin when the realisations are resampled."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..analysis.judging import paper_bars
from ..core.case import Case, rows_of
from ..core.labels import case_label, variant_text
from ..core.settings import BY_KEY
from .style import (
    BLUE,
    COLLISION,
    GREY,
    LETTERS,
    SPH,
    Series,
    distinct_models,
    draw,
    fit_titles,
    mark_missing,
    mark_no_data,
    n_ticks,
    rows_nearest,
    source_table,
    style_axes,
    styles,
)

PAPER_STYLES = {
    ("mtpt", "collision", 1.0): COLLISION,
    ("mtpt", "sph", 1.0): SPH,
    ("mtpt", "collision", 0.5): {"color": BLUE, "marker": "o"},
}


def _family(case: Case) -> tuple:
    """A Fig. 9 panel: the model without its truncation and scheme (every scheme side by side)."""
    return case.method, case.kernel, round(case.eta, 9), case.dt_growth


def _scheme_text(model: Case) -> str:
    """How a model differs from the paper's equations, for a Fig. 9 legend (a preset by its name)."""
    return variant_text(model) or "paper's equations (whole Gaussian)"


# the bars about the COMIC of the mean SSE (config figures.fig9.bars): eq43, Eq. 43 applied to
# SSE_mean -+ SSE_std; paper, ln(SSE_mean -+ SSE_std) - ln(SSE_mean) as the authors' script draws them
BARS = BY_KEY["figures.fig9.bars"].choices


def _mean_sse_bars(g: pd.DataFrame, bars: str) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper ends of the bars about the COMIC of the mean SSE (-inf: std >= mean)."""
    if bars == "paper":
        return paper_bars(g["COMIC_of_mean_SSE"], g["SSE_mean"], g["SSE_std"])
    return g["COMIC_of_mean_SSE_lo"].to_numpy(float), g["COMIC_of_mean_SSE_hi"].to_numpy(float)


def _fig9_panel(letter: str, model: Case, g: pd.DataFrame, style: dict, dodge: float, bars: str) -> list[Series]:
    """Fig. 9 series of one model: mean COMIC +-1 std, and the COMIC of the mean SSE (dotted) with
    the ``bars`` of BARS."""
    n, mu, sd = (g[k].to_numpy(float) for k in ("n", "COMIC_mean", "COMIC_std"))
    common = dict(
        case=model,
        x_name="N",
        x=n,
        n=g["n"].to_numpy(int),
        time=g["time_step"].to_numpy(float),
        n_realisations=g["n_realisations"].to_numpy(int),
    )
    line = "--" if style.get("linestyle") == ":" else style.get("linestyle", "-")  # dotted: the mean-SSE series
    name, short = case_label(model, n=False), _scheme_text(model)
    lo, hi = _mean_sse_bars(g, bars)
    sse_legend = f"{short}: COMIC of mean SSE" + (", the paper's bars" if bars == "paper" else "")
    return [
        Series(
            letter,
            f"{name}: mean COMIC",
            legend=f"{short}: mean ± 1 std",
            y_name="COMIC",
            y=mu,
            y_std=sd,
            kind="errorbar",
            marked=mu == mu.min(),
            style={**style, "linestyle": line, "zorder": 3, "dodge": dodge},
            **common,
        ),
        Series(
            letter,
            f"{name}: COMIC of ensemble-mean SSE",
            legend=sse_legend,
            y_name="COMIC of mean SSE",
            y=g["COMIC_of_mean_SSE"],
            y_lo=lo,
            y_hi=hi,
            kind="errorbar",
            style={**style, "open": True, "linestyle": ":", "alpha": 0.7, "zorder": 2, "dodge": dodge * 1.04},
            **common,
        ),
    ]


def _argmin_series(letter: str, model: Case, shares: pd.DataFrame, style: dict, dodge: float, width: float):
    """How often each N is the argmin of mean COMIC when realisations are resampled (bars)."""
    g = shares.sort_values("n")
    return Series(
        letter,
        f"{case_label(model, n=False)}: argmin share",
        legend=_scheme_text(model),
        case=model,
        x_name="N",
        x=g["n"].to_numpy(float),
        n=g["n"].to_numpy(int),
        y_name="share of resamples with this argmin",
        y=g["share"].to_numpy(float),
        n_realisations=g["n_realisations"].to_numpy(int),
        time=g["time"].to_numpy(float),
        marked=g["share"].to_numpy(float) == g["share"].max(),
        kind="bar",
        style={"color": style.get("color", GREY), "dodge": dodge, "width": width, "open": style.get("open", False)},
    )


def _minimum_text(row: pd.Series) -> str:
    """'N_opt 3,000, 95% CI 1,000-3,000 (81%)' from a comic_minima row."""
    if row["n_resamples"] <= 0:
        return f"N_opt {int(row['n_opt']):,} (no resampling)"
    lo, hi = int(row["n_opt_ci_lo"]), int(row["n_opt_ci_hi"])
    ci = f"{lo:,}" if lo == hi else f"{lo:,}–{hi:,}"
    return f"N_opt {int(row['n_opt']):,}, 95% CI {ci} ({row['n_opt_share']:.0%})"


def fig9(tables, cases, *, D: float, t_final: float, bars: str = "eq43"):
    """Fig. 9: ensemble COMIC +-1 std against N at the time nearest t_final, one panel per kernel
    and eta with every scheme side by side, minima starred; below each, how often each N is the
    argmin when the realisations are resampled (bootstrap), with the minimum's 95% interval. The
    COMIC of the mean SSE carries the ``bars`` of BARS (``paper``: as the published panels)."""
    if bars not in BARS:
        raise ValueError(f"figures.fig9.bars = {bars!r}: expected one of {', '.join(BARS)}")
    empty = pd.DataFrame()
    comic, minima, argmin = (list(tables) + [empty] * 3)[:3]
    style, models = styles(cases, PAPER_STYLES), distinct_models(cases)
    families = list(dict.fromkeys(_family(m) for m in models))
    ncols = min(max(len(families), 1), 3)
    rows = max(math.ceil(len(families) / 3), 1)
    fig = Figure(figsize=(5.0 * ncols, 6.2 * rows), layout="constrained")
    grid = fig.subplots(2 * rows, ncols, squeeze=False, gridspec_kw={"height_ratios": [3.0, 1.2] * rows})
    tops = [grid[2 * (k // ncols), k % ncols] for k in range(rows * ncols)]
    bottoms = [grid[2 * (k // ncols) + 1, k % ncols] for k in range(rows * ncols)]
    out, letters = [], iter(LETTERS)
    for family, ax, bar_ax in zip(families, tops, bottoms, strict=False):
        letter, bar_letter = next(letters), None
        mine = [m for m in models if _family(m) == family]
        title = case_label(Case(family[0], family[1], eta=family[2], dt_growth=family[3]), n=False)
        drawn, notes = [], []
        for k, model in enumerate(mine):
            g = pd.concat([rows_of(comic, c) for c in cases if c.model == model]) if len(comic) else empty
            mark_missing(ax, [c for c in cases if c.model == model and (g.empty or c.n not in set(g["n"]))], drawn=True)
            if g.empty:
                continue
            g = rows_nearest(g, t_final).sort_values("n")
            dodge = 1.0 + 0.1 * (k - (len(mine) - 1) / 2)
            series = _fig9_panel(letter, model, g, style[model], dodge, bars)
            for s in series:
                draw(ax, s)
            mean = series[0]
            kmin = int(np.argmax(mean.marked))
            ax.plot(
                mean.x[kmin] * dodge,
                mean.y[kmin],
                "*",
                color=style[model].get("color", "black"),
                markeredgecolor="black",
                markersize=15,
                zorder=6,
            )
            for ni, top, r in zip(mean.x, mean.y_hi, mean.n_realisations, strict=True):
                ax.annotate(
                    f"{int(r)}",
                    (ni * dodge, top),
                    textcoords="offset points",
                    xytext=(0, 3),
                    ha="center",
                    fontsize=7,
                    color=style[model].get("color", "0.35"),
                )
            out += series
            drawn.append(mean)
            time = float(g["time"].iloc[0])
            mrow = rows_of(minima, model) if len(minima) else empty
            mrow = mrow[mrow["time"] == time] if len(mrow) else mrow
            if len(mrow):
                notes.append((_minimum_text(mrow.iloc[0]), style[model].get("color", "black")))
            shares = rows_of(argmin, model) if len(argmin) else empty
            if len(shares):
                shares = shares[(shares["time"] == time) & (shares["convention"] == "mean_COMIC")]
            if len(shares):
                bar_letter = bar_letter or next(letters)
                width = 0.8 / max(len(mine), 1)
                bar = _argmin_series(
                    bar_letter, model, shares, style[model], 1.0 + width * 0.3 * (k - (len(mine) - 1) / 2), width * 0.3
                )
                draw(bar_ax, bar)
                out.append(bar)
        if not drawn:
            style_axes(ax, letter, title, "COMIC", xlabel="number of particles $N$", legend=None)
            mark_no_data(ax, title)
            bar_ax.set_visible(False)
            continue
        ax.plot([], [], "*", color="0.5", markeredgecolor="black", markersize=11, label="minimum of mean COMIC")
        ax.plot([], [], " ", label="numbers: realisations")
        ax.margins(x=0.08, y=0.12)
        style_axes(
            ax,
            letter,
            f"{title}, t = {drawn[0].time[0]:g}",
            r"COMIC $= 2\ln(SSE/N) - \ln\Delta V$",
            xlabel="",
            legend=None,
        )
        n_ticks(ax, np.concatenate([s.x for s in drawn]))
        ax.legend(loc="best", fontsize=7)
        if bar_letter is None:
            bar_ax.set_visible(False)
            continue
        style_axes(
            bar_ax,
            bar_letter,
            "argmin over N, realisations resampled",
            "share of resamples",
            xlabel="number of particles $N$",
            legend=None,
        )
        bar_ax.set_xlim(ax.get_xlim())
        bar_ax.set_ylim(0, 1.35)
        n_ticks(bar_ax, np.concatenate([s.x for s in drawn]))
        for j, (text, colour) in enumerate(notes):
            bar_ax.text(
                0.02, 0.95 - 0.16 * j, text, transform=bar_ax.transAxes, ha="left", va="top", fontsize=7, color=colour
            )
    for ax, bar_ax in list(zip(tops, bottoms, strict=True))[len(families) :]:
        ax.set_visible(False)
        bar_ax.set_visible(False)
    fit_titles(fig)  # seven families' titles with their time ran past the panel's edge
    return fig, source_table("fig9", out)
