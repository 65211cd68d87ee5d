"""Fig. 3: ensemble-mean H_C against time, every case and N on one axes, with the analytic H_C."""

from __future__ import annotations

from .style import (
    ADAPTIVE,
    SPH,
    by_case,
    curve,
    draw,
    mark_missing,
    new_figure,
    panels_by_n,
    reference,
    runs_text,
    source_table,
    style_axes,
    styles,
)

PAPER_STYLES = {("pt", "adaptive", 1.0): ADAPTIVE, ("mtpt", "sph", 1.0): SPH}


def fig3(tables, cases, *, D: float, t_final: float):
    """Fig. 3: ensemble-mean H_C against time, every case and N on one axes (hollow markers: smaller N)."""
    found, style, series = by_case(tables), styles(cases, PAPER_STYLES), []
    fig, (ax,) = new_figure(1, width=7.0, height=4.8)
    for i, (_, n, at_n) in enumerate(panels_by_n(cases, descending=True)):
        have = [c for c in at_n if c in found]
        series += [
            curve("", c, found[c], "H_C", {**style[c.model], "open": i > 0 or style[c.model].get("open")}) for c in have
        ]
        if have:
            series.append(reference("", f"analytic $H_C$, N={n:,}", found[have[0]], "H_C_analytic", n=n))
    for s in series:
        draw(ax, s)
    mark_missing(ax, [c for c in cases if c not in found], bool(series))
    if series:
        ax.set_ylim(bottom=max(ax.get_ylim()[0], -3.0))
    style_axes(
        ax,
        None,
        f"ensemble means ± 1 std, {runs_text(series)}",
        "consistent entropy $H_C$ [nats]",
        legend="lower right",
    )
    return fig, source_table("fig3", series)
