"""Fig. 6: ensemble-mean PMF entropy H_PMF against time, colour by N, with the analytic H_I(t)."""

from __future__ import annotations

import numpy as np

from ..core.measures import analytic_h_i
from .style import (
    ANALYTIC,
    Series,
    by_case,
    colours_by_n,
    curve,
    draw,
    mark_missing,
    new_figure,
    runs_text,
    source_table,
    style_axes,
    styles,
)

PAPER_STYLES = {("mtpt", "collision", 1.0): {"linestyle": "-", "marker": None}}  # colour: N


def fig6(tables, cases, *, D: float, t_final: float):
    """Fig. 6: ensemble-mean H_PMF = H_D + ln(Omega/N) against time, colour by N, with the analytic H_I(t)."""
    found, style = by_case(tables), styles(cases, PAPER_STYLES, colour_is_n=True)
    have = sorted((c for c in cases if c in found), key=lambda c: c.n)
    colour = colours_by_n(c.n for c in have)
    series = [curve("", c, found[c], "H_PMF", {**style[c.model], "color": colour[c.n]}, band=False) for c in have]
    if series:
        t = np.unique(np.concatenate([s.x for s in series]))
        h_i = [analytic_h_i(D, x) for x in t]
        series.append(
            Series("", r"analytic $H_I=\ln\sqrt{4\pi D t}+1/2$", None, "time", t, "H_I", h_i, style=ANALYTIC, time=t)
        )
    fig, (ax,) = new_figure(1, width=7.0, height=4.8)
    for s in series:
        draw(ax, s)
    mark_missing(ax, [c for c in cases if c not in found], bool(series))
    style_axes(
        ax,
        None,
        f"PMF entropy, ensemble means ({runs_text(series)})",
        r"$H_{PMF}=H_D+\ln(\Omega/N)$ [nats]",
        legend="upper left",
    )
    return fig, source_table("fig6", series)
