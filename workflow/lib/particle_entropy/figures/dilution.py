"""Figs. 2, 4 and 5: the dilution index E against time (log-log), one panel per N, with the analytic E.

One drawing, three case lists and three sets of paper styles: single realisations of PT and MTPT
(fig2), ensembles of adaptive-kernel PT and MTPT (fig4) and of MTPT at eta = 1 and 0.1 (fig5).
"""

from __future__ import annotations

from .style import (
    ADAPTIVE,
    COLLISION,
    ETA_01,
    GREY,
    PT_MTPT,
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

# figure -> (method, kernel, eta) the paper draws -> its style
PAPER_STYLES = {
    "fig2": PT_MTPT,
    "fig4": {
        ("pt", "adaptive", 1.0): ADAPTIVE,
        ("mtpt", "sph", 1.0): SPH,
        ("mtpt", "collision", 1.0): {"color": GREY, "marker": "D", "open": True, "zorder": 1},
    },
    "fig5": {
        ("mtpt", "collision", 1.0): COLLISION,
        ("mtpt", "collision", 0.1): {**COLLISION, **ETA_01},
        ("mtpt", "sph", 1.0): SPH,
        ("mtpt", "sph", 0.1): {**SPH, **ETA_01},
    },
}


def _dilution(figure: str, tables, cases, ensemble: bool):
    """Dilution index E against time (log-log), one panel per N (descending), with the analytic E."""
    found, style, out = by_case(tables), styles(cases, PAPER_STYLES[figure]), []
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


def fig2(tables, cases, *, D: float, t_final: float):
    """Fig. 2: single-realisation dilution index E of each case against time (log-log); one panel per N."""
    return _dilution("fig2", tables, cases, ensemble=False)


def fig4(tables, cases, *, D: float, t_final: float):
    """Fig. 4: ensemble-mean E against time (log-log), collision-kernel MTPT in grey; one panel per N."""
    return _dilution("fig4", tables, cases, ensemble=True)


def fig5(tables, cases, *, D: float, t_final: float):
    """Fig. 5: ensemble-mean E against time (log-log) for MTPT at eta = 1 and 0.1; one panel per N."""
    return _dilution("fig5", tables, cases, ensemble=True)
