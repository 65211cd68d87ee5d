"""figures/optimum_<name>.png: an adaptive COMIC search (optimum.py) drawn from its result table.

Mean COMIC +-1 standard error of every visited point on a log N axis (a growth search: log of
dt_growth - 1), coloured by the round that added it and labelled with its realisations; the
bracket of the optimum (light band) and the bootstrap interval of the fitted optimum (dark band)
shaded, a star at the lowest visited mean and a dashed line at the fitted optimum; below the
axes, the runs and core-seconds spent against a full grid sweep resolving the same bracket, and
why it stopped.
"""

from __future__ import annotations

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from .style import BLACK, GREY, VERMILLION, new_figure, style_axes

BRACKET, INTERVAL = "#DCE9F5", "#9DC3E6"  # light and dark blue bands


def _round_colours(rounds) -> dict[int, tuple]:
    """An ordered colour per round (viridis): early rounds dark, late rounds light."""
    rounds = sorted({int(r) for r in rounds})
    cmap = matplotlib.colormaps["viridis"]
    return {r: cmap(0.85 * i / max(len(rounds) - 1, 1)) for i, r in enumerate(rounds)}


def _span(ax, lo: float, hi: float, colour: str) -> None:
    """A vertical band from lo to hi; a single N gets a thin band around it (2 % either side)."""
    if hi <= lo:
        lo, hi = lo / 1.02, hi * 1.02
    ax.axvspan(lo, hi, color=colour, zorder=0, linewidth=0)


def _seconds(s: float) -> str:
    """12,345 or 12.3 or 0.0331: whole seconds when large, three digits when small."""
    return f"{s:,.0f}" if s >= 100 else f"{s:.3g}"


def cost_text(row: pd.Series) -> str:
    """'38 runs, 12.3 core-s measured (9% of a full sweep's ~137 core-s); 4 rounds; stopped: budget
    spent', then on a second line what the budget counted (modelled core-seconds) and, when the
    lowest mean is at an end of the visited values, that the minimum may lie beyond."""
    spent, full = float(row["core_s_spent"]), float(row["full_sweep_core_s"])
    share = f"{spent / full:.0%} of" if full > 0 else "vs"
    first = (
        f"{int(row['runs_spent'])} runs, {_seconds(spent)} core-s measured ({share} a full sweep's "
        f"~{_seconds(full)} core-s); {int(row['rounds'])} round{'s' if int(row['rounds']) != 1 else ''}; "
        f"stopped: {row['reason']}"
    )
    second = []
    if np.isfinite(float(row["cost_s_spent"])):
        budget = float(row["budget_core_s"])
        of = f" of the budget's {_seconds(budget)}" if np.isfinite(budget) else ""
        second.append(f"the cost model counted {_seconds(float(row['cost_s_spent']))} core-s{of}")
    if row["at_end"]:
        name = "dt growth" if row["over"] == "dt_growth" else "N"
        where, side = ("lowest", "below") if row["at_end"] == "low" else ("highest", "above")
        second.append(f"lowest mean at the {where} visited {name}: the minimum may lie {side} it")
    return first + ("\n" + "; ".join(second) if second else "")


def _value(v, growth: bool) -> str:
    return f"{float(v):.4g}" if growth else f"{int(round(float(v))):,}"


def optimum_figure(table: pd.DataFrame):
    """The figure of one finished search (optimum.RESULT_COLUMNS, one row per visited N)."""
    fig, (ax,) = new_figure(1, width=9.0, height=4.6)
    first = table.iloc[0]
    over = str(first["over"])
    t = table.sort_values(over)
    growth = over == "dt_growth"
    x = t[over] - 1.0 if growth else t[over]  # a growth search is drawn over dt_growth - 1 (log axis)
    shift = 1.0 if growth else 0.0
    _span(ax, float(first["bracket_lo"]) - shift, float(first["bracket_hi"]) - shift, BRACKET)
    _span(ax, float(first["ci_lo"]) - shift, float(first["ci_hi"]) - shift, INTERVAL)
    ax.plot(x, t["COMIC_mean"], color=GREY, linewidth=0.8, zorder=1)
    colours = _round_colours(t["round_added"])
    size = 4.0 + 2.0 * np.sqrt(t["realisations"].to_numpy(float))  # marker area grows with realisations
    for (_, row), xv, ms in zip(t.iterrows(), x, size):
        colour = colours[int(row["round_added"])]
        ax.errorbar(
            xv,
            row["COMIC_mean"],
            yerr=row["COMIC_se"] if np.isfinite(row["COMIC_se"]) else None,
            color=colour,
            marker="o",
            markersize=ms,
            markeredgecolor=BLACK,
            markeredgewidth=0.5,
            capsize=2.5,
            zorder=3,
        )
        ax.annotate(
            f"{int(row['realisations'])}",
            (xv, row["COMIC_mean"]),
            textcoords="offset points",
            xytext=(ms / 2 + 3, 2),
            ha="left",
            va="bottom",
            fontsize=7,
            color="0.25",
        )
    best = t[t[over] == first["best"]].iloc[0]
    ax.plot(
        float(best[over]) - shift,
        best["COMIC_mean"],
        marker="*",
        markersize=16,
        color=VERMILLION,
        markeredgecolor=BLACK,
        zorder=4,
    )
    ax.axvline(float(first["optimum"]) - shift, color=VERMILLION, linestyle="--", linewidth=1.0, zorder=2)
    name = "dt growth" if growth else "N"
    handles = [
        Line2D([], [], linestyle="", marker="o", color=c, markeredgecolor=BLACK, label=f"added in round {r}")
        for r, c in colours.items()
    ]
    handles += [
        Line2D(
            [],
            [],
            linestyle="",
            marker="*",
            markersize=12,
            color=VERMILLION,
            markeredgecolor=BLACK,
            label=f"lowest mean: {name} = {_value(first['best'], growth)}",
        ),
        Line2D([], [], color=VERMILLION, linestyle="--", label=f"fitted optimum: {_value(first['optimum'], growth)}"),
        Patch(
            color=INTERVAL,
            label=f"95 % interval: {_value(first['ci_lo'], growth)}–{_value(first['ci_hi'], growth)}",
        ),
        Patch(
            color=BRACKET,
            label=f"bracket: {_value(first['bracket_lo'], growth)}–{_value(first['bracket_hi'], growth)}",
        ),
    ]
    flags = (("SSE at the 15 common points", first["measure"] == "points"), ("dt in dV", bool(first["time_volume"])))
    options = [o for o, on in flags if on]
    options += [] if first["convention"] == "mean_COMIC" else ["COMIC of mean SSE"]
    judged = f"COMIC at t = {float(first['time']):g}" + "".join(f"; {o}" for o in options)
    title = f"{first['search']}: {first['label']}\n{judged}"  # two lines: long names are not clipped
    xlabel = "dt growth − 1 (numbers: realisations)" if growth else "$N$ (numbers: realisations)"
    style_axes(ax, None, title, "COMIC (mean ± 1 s.e.) [nats]", xlabel=xlabel, legend=None)
    # beside the axes: a search's points crowd where the legend would go, around its minimum
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}" if growth else f"{v:,.0f}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    text = cost_text(first)
    fig.text(0.01, 0.005, text, fontsize=8, ha="left", va="bottom", color="0.2")
    bottom = 0.04 * (1 + text.count("\n"))  # room for the text's lines; rect is (left, bottom, width, height)
    fig.get_layout_engine().set(rect=(0, bottom, 1, 1 - bottom))
    return fig
