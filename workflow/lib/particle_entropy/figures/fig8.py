"""Fig. 8: FD fitness, (a) ln(SSE/N) and (b) COMIC against time per grid, (c) both against dx."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..core.case import Case
from ..core.labels import case_label
from .style import (
    BLUE,
    VERMILLION,
    Series,
    by_case,
    colours_by_n,
    curve,
    distinct_models,
    draw,
    mark_missing,
    mean_and_std,
    new_figure,
    realisations_of,
    rows_nearest,
    source_table,
    style_axes,
    styles,
)

PAPER_STYLES = {("fd", "implicit", 1.0): {"linestyle": "-", "marker": None}}  # colour: N (a, b), measure (c)
RESERVED_COLOURS = (BLUE, VERMILLION)  # panel c's two measures
FIG8_TIME = 250.0  # Fig. 8c compares the grids at this time [T] (nearest recorded step)


def _fig8_measures(model: Case, multi: bool, style: dict, cases, found) -> list[Series]:
    """Fig. 8c: ln(SSE/N) and COMIC of one model's grids against dx at the step nearest FIG8_TIME."""
    have = sorted((c for c in cases if c.model == model and c in found), key=lambda c: c.n)
    if not have:
        return []
    rows = pd.DataFrame([rows_nearest(found[c], FIG8_TIME).iloc[0] for c in have])
    comic = mean_and_std(rows, "COMIC")[0]
    common = dict(
        case=model,
        x_name="dx",
        x=rows["dV"],
        n=[c.n for c in have],
        time=rows["time"],
        n_realisations=[realisations_of(found[c]) for c in have],
    )
    prefix = f"{case_label(model, n=False)}: " if multi else ""
    return [
        Series(
            "c",
            prefix + r"$\ln(SSE/N)$",
            y_name="ln(SSE/N)",
            y=mean_and_std(rows, "AIC")[0] / 2,
            style={**style, "color": BLUE, "marker": style.get("marker") or "o"},
            **common,
        ),
        Series(
            "c",
            prefix + "COMIC",
            y_name="COMIC",
            y=comic,
            marked=comic == comic.min(),
            style={**style, "color": VERMILLION, "marker": style.get("marker") or "s"},
            **common,
        ),
    ]


def fig8(tables, cases, *, D: float, t_final: float):
    """Fig. 8: FD fitness, (a) ln(SSE/N) and (b) COMIC against time per grid, (c) both against dx."""
    found, style, models = (
        by_case(tables),
        styles(cases, PAPER_STYLES, RESERVED_COLOURS, colour_is_n=True),
        distinct_models(cases),
    )
    have = sorted((c for c in cases if c in found), key=lambda c: (c.n, models.index(c.model)))
    colour, multi, series = colours_by_n(c.n for c in have), len(models) > 1, []
    for c in have:
        dx = float(found[c]["dV"].iloc[0])
        label = (f"{case_label(c.model, n=False)}, " if multi else "") + f"Δx = {dx:.2g} (N = {c.n:,})"
        half = found[c].assign(**{"ln(SSE/N)": mean_and_std(found[c], "AIC")[0] / 2})
        st = {**style[c.model], "color": colour[c.n]}
        series.append(curve("a", c, half, "ln(SSE/N)", st, label=label, band=False))
        series.append(curve("b", c, found[c], "COMIC", st, label=label, band=False))
    for model in models:
        series += _fig8_measures(model, multi, style[model], cases, found)
    fig, axes = new_figure(3, width=4.6, height=4.0)
    for ax, letter in zip(axes, "abc", strict=True):
        for s in (s for s in series if s.panel == letter):
            draw(ax, s)
        mark_missing(ax, [c for c in cases if c not in found], any(s.panel == letter for s in series))
    style_axes(axes[0], "a", "log-likelihood", r"$\ln(SSE/N)$ = AIC/2", legend="lower left")
    style_axes(
        axes[1], "b", "computational information criterion", r"COMIC $= 2\ln(SSE/N) - \ln\Delta x$", legend="lower left"
    )
    for s in (s for s in series if s.panel == "c" and s.y_name == "COMIC"):
        k = int(np.argmax(s.marked))
        axes[2].plot(
            s.x[k],
            s.y[k],
            "*",
            color="black",
            markersize=14,
            zorder=6,
            label=f"min COMIC: Δx = {s.x[k]:.2g} (N = {s.n[k]:,})",
        )
    tc = next((s.time[0] for s in series if s.panel == "c"), FIG8_TIME)
    style_axes(
        axes[2],
        "c",
        f"both measures at t = {tc:g}",
        "fitness [nats]",
        xlabel=r"grid spacing $\Delta x$ [L]",
        legend="upper left",
    )
    return fig, source_table("fig8", series)
