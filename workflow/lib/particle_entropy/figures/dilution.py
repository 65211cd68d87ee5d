"""The drawing Figs. 2, 4 and 5 share: the dilution index E against time (log-log), one panel per
N, with the analytic E. Each figure's module (fig2, fig4, fig5) gives its cases and paper styles."""

from __future__ import annotations

from .style import (
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


def dilution_figure(figure: str, tables, cases, paper_styles: dict, ensemble: bool):
    """Dilution index E against time (log-log), one panel per N (descending), with the analytic E."""
    found, style, out = by_case(tables), styles(cases, paper_styles), []
    panels = panels_by_n(cases, descending=True)
    fig, axes = new_figure(len(panels))
    for ax, (letter, n, at_n) in zip(axes, panels, strict=True):
        have = [c for c in at_n if c in found]
        series = [curve(letter, c, found[c], "E", style[c.model], logy=True) for c in have]
        if have:
            series.append(reference(letter, r"analytic $\sqrt{4\pi e D t}$", found[have[0]], "E_analytic", logy=True))
        for s in series:
            draw(ax, s, logy=True)
        mark_missing(ax, [c for c in at_n if c not in found], bool(series))
        title = f"N = {n:,}" + (f" (ensemble mean ± 1 std, {runs_text(series)})" if ensemble else "")
        style_axes(ax, letter, title, "dilution index $E$ [L]", logy=True, legend="upper left")
        out += series
    return fig, source_table(figure, out)
