"""figures/scenes_peclet.png: where particles overtake grids, in 1-D and in 2-D, drawn from the Peclet
sweeps' table (analysis/scene_search.peclet_table): the counted cost of one run of the cheapest FD candidate and
of the cheapest particle candidate that meet the target, against v L / D; bars from the cost of the
failing resolution below each answer, hollow markers where a family never meets it, the crossover
shaded over the sweep's spacing. Each FD answer is labelled with its scheme, grid Peclet number
|v| dx / D and Courant number |v| dt / dx; a scheme and Courant number every answer of a sweep shares
is said once, in its legend entry."""

from __future__ import annotations

import math

import pandas as pd

from ..analysis.scene_search import FAMILIES, crossover
from ..core.labels import interval
from .style import AUTO_COLOURS, AUTO_MARKERS, new_figure, style_axes


def _scheme(row) -> str:
    """An FD answer's scheme: its label's third word; at rest none."""
    words = str(row.label).split()
    return words[2] if len(words) > 3 else "at rest"


def _fd_numbers(row, shared: str = "") -> str:
    """An FD answer's scheme, grid Peclet and Courant numbers; with ``shared`` (the scheme and Courant
    number every answer of its sweep in a flow has, said once in the legend) its grid Peclet number alone."""
    if not row.grid_peclet > 0:
        return _scheme(row)
    if shared:
        return f"Pe_dx {row.grid_peclet:.3g}"
    return f"{_scheme(row)}\nPe_dx {row.grid_peclet:.3g}, Cr {row.courant:.3g}"


def _shared(rows: pd.DataFrame) -> str:
    """The scheme and Courant number of every FD answer of a sweep in a flow, where they are one, else ''."""
    moving = rows[rows["grid_peclet"] > 0]
    kinds = {(_scheme(r), f"{r.courant:.3g}") for r in moving.itertuples()}
    if len(kinds) != 1:
        return ""
    scheme, courant = kinds.pop()
    return f"{scheme}, Cr {courant}"


LINES = {1: "-", 2: "--"}  # a sweep's dimension -> its lines
NOTE_AT = {1: (4, -10), 2: (4, 5)}  # and its FD labels' offset in points: below the 1-D line, above the 2-D one


def _pe_ticks(x_of: dict) -> tuple[list[float], list[str]]:
    """The x ticks: the decades the sweeps span (two sweeps' Peclet numbers may lie a few percent apart,
    whose own ticks would overlap) and, where a sweep has Pe = 0, "0" where it is drawn."""
    drawn = [x for p, x in x_of.items() if p > 0]
    ticks, labels = [], []
    if len(drawn) != len(x_of):  # Pe = 0 (a Peclet number is never negative)
        ticks, labels = [x_of[0.0]], ["0"]
    if drawn:
        lo, hi = math.floor(math.log10(min(drawn))), math.ceil(math.log10(max(drawn)))
        ticks += [10.0**k for k in range(lo, hi + 1)]
        labels += [f"{10.0**k:,.0f}" if k >= 0 else f"{10.0**k:g}" for k in range(lo, hi + 1)]
    return ticks, labels


SHADES = {1: {"color": "0.88"}, 2: {"facecolor": "none", "edgecolor": "0.55", "hatch": "///", "lw": 0}}


def scenes_peclet(table: pd.DataFrame):
    """figures/scenes_peclet.png: the cost to reach each sweep's accuracy for the best grid and the
    best particle model against the Peclet number, the 1-D sweep in full lines and the 2-D one in
    dashed, each crossover shaded (scene_search.peclet_table)."""
    fig, (ax,) = new_figure(1, width=6.4, height=4.4)
    table = table if "dim" in table else table.assign(dim=1)
    pe = sorted(table["peclet"].unique())
    positive = [p for p in pe if p > 0]
    zero_at = min(positive) / 10 if positive else 1.0  # Pe = 0 drawn a decade left of the first
    x_of = {p: (p if p > 0 else zero_at) for p in pe}
    finite = table["cost_s"].dropna()
    top = finite.max() * 3 if len(finite) else 1.0
    dims = sorted(table["dim"].unique())
    for dim in dims:
        _draw_sweep(ax, table[table["dim"] == dim], dim, x_of, top, named=len(dims) > 1)
        cross = crossover(table, dim)
        if cross is not None:
            where = f"{dim}-D: " if len(dims) > 1 else ""
            ax.axvspan(
                x_of[cross[0]],
                x_of[cross[1]],
                zorder=0,
                label=f"{where}particles overtake the grid: Pe in {interval(*cross)}",
                **SHADES[int(dim)],
            )
    style_axes(
        ax,
        None,
        "Where particles overtake grids",
        "counted cost of one run that meets the target [s]",
        "scene Péclet number |v| L / D (L the FD window; 2-D: D_L)",
        logx=True,
        logy=True,
        legend=None,
    )
    ticks, labels = _pe_ticks(x_of)
    view = ax.get_xlim()  # the decades' ticks do not widen the view
    ax.set_xticks(ticks, labels)
    ax.set_xlim(view)
    ax.minorticks_off()
    ax.legend(fontsize=6, loc="best")
    return fig


def _draw_sweep(ax, table: pd.DataFrame, dim: int, x_of: dict, top: float, named: bool) -> None:
    """One sweep's families: the answers' costs joined by lines of its dimension (LINES), bars down to
    the failing rung below, FD answers labelled (_fd_numbers), hollow markers where none meets it."""
    for i, (family, rows) in enumerate(table.groupby("family", sort=False)):
        colour, marker = AUTO_COLOURS[i], AUTO_MARKERS[i]
        name = f"{dim}-D: {family}" if named else family
        rows = rows.sort_values("peclet")
        x = rows["peclet"].map(x_of)
        met = rows["cost_s"].notna()
        shared = _shared(rows[met]) if family == FAMILIES["fd"] else ""
        lo = (rows["cost_s"] - rows["cost_lo"]).where(rows["cost_lo"].notna(), 0.0)
        ax.errorbar(
            x[met],
            rows.loc[met, "cost_s"],
            yerr=[lo[met].clip(lower=0), 0 * lo[met]],
            color=colour,
            marker=marker,
            mfc=colour if dim == 1 else "white",
            ms=6,
            lw=1.4,
            ls=LINES[int(dim)],
            capsize=2,
            label=f"{name}: {shared}" if shared else name,
        )
        if family == FAMILIES["fd"]:
            for px, row in zip(x[met], rows[met].itertuples()):
                ax.annotate(
                    _fd_numbers(row, shared),
                    (px, row.cost_s),
                    xytext=NOTE_AT[int(dim)],
                    textcoords="offset points",
                    fontsize=6,
                    color=colour,
                )
        if (~met).any():
            ax.plot(
                x[~met],
                [top] * int((~met).sum()),
                ls="none",
                marker=marker,
                ms=9,
                mfc="white",
                mec=colour,
                label=f"{name}: not met within its range",
            )
