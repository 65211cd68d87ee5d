"""Speed-accuracy trade-off: RMSE against wall time and N per model and time, COMIC optimum starred.

Colour and marker come from the model's family (method, kernel, eta), the line style from the
dimensions it varies from the paper (``VARIANT_LINES``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from ..core.case import Case, rows_of
from ..core.labels import case_label
from .style import (
    ADAPTIVE,
    AUTO_MARKERS,
    BINS,
    BLACK,
    COLLISION,
    FIXED,
    GREY,
    LETTERS,
    PURPLE,
    VERMILLION,
    Series,
    auto_styles,
    distinct_models,
    draw,
    mark_no_data,
    model_triple,
    n_ticks,
    source_table,
    style_axes,
)

# trade-off: colour and marker by family (method, kernel, eta), line style by the varied dimensions
TRADEOFF_FAMILY = {
    ("fd", "implicit", 1.0): {"color": BLACK, "marker": "o"},
    ("pt", "bins", 1.0): BINS,
    ("pt", "fixed", 1.0): FIXED,
    ("pt", "adaptive", 1.0): ADAPTIVE,
    ("mtpt", "collision", 1.0): COLLISION,
    ("mtpt", "sph", 1.0): {"color": VERMILLION, "marker": "v"},
    ("mtpt", "collision", 0.5): {"color": PURPLE, "marker": "D", "open": True},
    ("mtpt", "sph", 0.5): {"color": GREY, "marker": "v", "open": True},
}
VARIANT_LINES = {
    (): "-",
    ("truncation",): "--",
    ("dt_growth",): ":",
    ("truncation", "dt_growth"): "-.",
    ("scheme",): (0, (6, 2, 1, 2, 1, 2)),
    ("truncation", "scheme"): (0, (10, 3)),
    ("dt_growth", "scheme"): (0, (1, 1)),
    ("truncation", "dt_growth", "scheme"): (0, (10, 2, 2, 2)),
}  # and hollow markers where the scheme differs
VARIANT_NAMES = {"truncation": "kernel truncation", "dt_growth": "Δt growth", "scheme": "scheme"}


def tradeoff_styles(cases: list[Case]) -> dict[Case, dict]:
    """Trade-off styles: family colour and marker, line style by the dimensions varied from the paper."""
    models = distinct_models(cases)
    unknown = list(dict.fromkeys(model_triple(m) for m in models if model_triple(m) not in TRADEOFF_FAMILY))
    auto = auto_styles(len(unknown), list(TRADEOFF_FAMILY.values()))
    family = {**TRADEOFF_FAMILY, **dict(zip(unknown, auto, strict=True))}
    out, seen = {}, {}
    for m in models:
        # the time grid varies no line: an authors'-grid model takes another marker (the repeat below)
        base, keys = family[model_triple(m)], tuple(k for k in m.variant() if k != "time_grid")
        repeat = seen[model_triple(m), keys] = seen.get((model_triple(m), keys), -1) + 1
        style = {**base, "linestyle": VARIANT_LINES[keys], **({"open": True} if "scheme" in keys else {})}
        if repeat:  # same family and same varied dimensions, other values: another marker, hollow
            markers = [k for k in AUTO_MARKERS if k != base["marker"]]
            style.update(marker=markers[(repeat - 1) % len(markers)], open=True)
        out[m] = style
    return out


def _tradeoff_series(at: pd.DataFrame, letters: tuple[str, str], cases, style) -> list[Series]:
    """Trade-off series at one time: RMSE against wall time (left) and N (right) of each model."""
    out = []
    for model in distinct_models(cases):
        g = pd.concat([rows_of(at, c) for c in cases if c.model == model]).sort_values("n")
        g = g[np.isfinite(g["rmse"]) & np.isfinite(g["wall_s"]) & (g["rmse"] > 0) & (g["wall_s"] > 0)]
        common = dict(
            case=model,
            y_name="rmse",
            y=g["rmse"],
            n=g["n"].to_numpy(int),
            time=g["time"].to_numpy(float),
            n_realisations=g["n_realisations"].to_numpy(int),
            style=style[model],
            marked=g["is_comic_optimum"].to_numpy(bool),
        )
        out += [
            Series(letters[0], case_label(model, n=False), x_name="wall_s", x=g["wall_s"], **common),
            Series(letters[1], case_label(model, n=False), x_name="N", x=g["n"], **common),
        ]
    return out


def _one_two_five(axis) -> None:
    """Log axis labelled at 1, 2, 5 x 10^k in plain numbers, minor ticks unlabelled."""
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _tradeoff_axes(ax, letter: str, time: float, xlabel: str) -> None:
    style_axes(
        ax, letter, f"t = {time:g}", "concentration RMSE sqrt(SSE/n) [1/L]", xlabel=xlabel, logy=True, legend=None
    )
    # labelled 1-2-5 error levels with light horizontal lines: read off the cheapest model per error
    _one_two_five(ax.yaxis)
    ax.grid(True, which="minor", axis="y", color="0.95", linewidth=0.6)


def _variant_text(keys: tuple) -> str:
    return "paper settings" if not keys else "differs in " + " and ".join(VARIANT_NAMES[k] for k in keys)


def tradeoff(tables, cases, *, D: float, t_final: float):
    """Speed-accuracy trade-off: RMSE against wall time and N per model and time, COMIC optimum starred."""
    table = tables[0] if tables else pd.DataFrame()
    style = tradeoff_styles(cases)
    rows = pd.concat([rows_of(table, c) for c in cases]) if len(table) else table
    times = sorted(rows["time"].unique()) if len(rows) else []
    fig = Figure(figsize=(11.5, 4.3 * max(len(times), 1)), layout="constrained")
    axes = fig.subplots(max(len(times), 1), 2, squeeze=False)
    xlabels = ("wall time per realisation [s]", "number of particles or FD intervals N")
    if not times:
        for ax, xlabel in zip(axes[0], xlabels, strict=True):
            style_axes(ax, None, "speed-accuracy trade-off", "RMSE", xlabel=xlabel, logx=False, legend=None)
            mark_no_data(ax, "trade-off table rows of these cases")
        return fig, source_table("tradeoff", [])
    series, handles = [], {}
    for i, (row, time) in enumerate(zip(axes, times, strict=True)):
        at = _tradeoff_series(rows[rows["time"] == time], tuple(LETTERS[2 * i : 2 * i + 2]), cases, style)
        for s in at:
            if not len(s.x):
                continue
            ax = row[0] if s.x_name == "wall_s" else row[1]
            draw(ax, s)
            handles.setdefault(s.label, ax.get_lines()[-1])
            star = s.marked
            ax.plot(
                s.x[star],
                s.y[star],
                "*",
                color=s.style["color"],
                markeredgecolor="black",
                markeredgewidth=0.8,
                markersize=13,
                zorder=6,
            )
        series += at
        row[1].sharey(row[0])  # one error scale per row: read across at a target error
        for ax, letter, xlabel in zip(row, LETTERS[2 * i : 2 * i + 2], xlabels, strict=True):
            _tradeoff_axes(ax, letter, time, xlabel)
        row[1].set_ylabel("")
        _one_two_five(row[0].xaxis)
        n_ticks(row[1], [n for s in at for n in np.atleast_1d(s.n)])
    star = Line2D(
        [],
        [],
        linestyle="none",
        marker="*",
        markersize=13,
        color="white",
        markeredgecolor="black",
        markeredgewidth=0.8,
        label="COMIC optimum (lowest mean COMIC)",
    )
    keys = dict.fromkeys(tuple(m.variant()) for m in distinct_models(cases))
    key = [
        Line2D(
            [],
            [],
            color="0.3",
            linestyle=VARIANT_LINES[k],
            marker="o" if "scheme" in k else None,
            markerfacecolor="white",
            label=_variant_text(k),
        )
        for k in keys
    ]
    fig.legend(
        handles=[*handles.values(), star, *key], loc="outside right center", fontsize=8, frameon=False, handlelength=3.0
    )
    return fig, source_table("tradeoff", series)
