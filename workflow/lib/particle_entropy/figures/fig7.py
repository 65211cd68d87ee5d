"""Fig. 7: final concentrations at the particles against x and the analytic Gaussian; one panel per N."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..core.labels import case_label
from .style import (
    ANALYTIC,
    BLUE,
    GREEN,
    Series,
    by_case,
    draw,
    mark_missing,
    new_figure,
    panels_by_n,
    source_table,
    style_axes,
    styles,
)

# dots: "size" x the panel's dot area, "alpha"; "open" hollow
PAPER_STYLES = {
    ("mtpt", "collision", 0.1): {"color": GREEN, "marker": "o", "size": 1, "alpha": 0.6},
    ("pt", "fixed", 1.0): {"color": BLUE, "marker": "o", "open": True, "size": 3},
}


def _plume_note(label: str, df: pd.DataFrame, gauss) -> str:
    """Fig. 7 legend text: the label, the mean squared deviation from the analytic profile and the plume variance."""
    x, c, m = (df[k].to_numpy(float) for k in ("x", "c", "mass"))
    mean = np.sum(m * x) / np.sum(m)
    spread = np.sum(m * (x - mean) ** 2) / np.sum(m)
    msd = np.mean((c - gauss(x)) ** 2)
    return f"{label}\n  mean sq. dev. from analytic {msd:.2g} L⁻², plume variance {spread:.2f} L²"


def fig7(tables, cases, *, D: float, t_final: float):
    """Fig. 7: final concentrations at the particles against x and the analytic Gaussian; one panel per N."""
    found, style, out = by_case(tables), styles(cases, PAPER_STYLES), []
    var = 2 * D * t_final
    gauss = lambda x: np.exp(-(x**2) / (2 * var)) / np.sqrt(2 * np.pi * var)
    panels = panels_by_n(cases, descending=True)
    fig, axes = new_figure(len(panels), width=5.6, height=5.2)
    for ax, (letter, n, at_n) in zip(axes, panels, strict=True):
        have = [c for c in at_n if c in found]
        dot = 2 if n >= 10000 else 8  # dense clouds need small dots
        series = []
        for c in have:
            series.append(
                Series(
                    letter,
                    case_label(c),
                    c,
                    "x",
                    found[c]["x"],
                    "c",
                    found[c]["c"],
                    kind="scatter",
                    style=style[c.model],
                    n_realisations=1,
                    time=t_final,
                    legend=_plume_note(case_label(c), found[c], gauss),
                )
            )
            draw(ax, series[-1], dot=dot)
        if series:
            lo, hi = min(-5.0, *(s.x.min() for s in series)), max(5.0, *(s.x.max() for s in series))
            grid = np.linspace(lo, hi, 801)
            series.append(
                Series(
                    letter,
                    f"analytic Gaussian, variance $2Dt$ = {var:.2f} L²",
                    None,
                    "x",
                    grid,
                    "c",
                    gauss(grid),
                    style=ANALYTIC,
                    time=t_final,
                )
            )
            draw(ax, series[-1])
        mark_missing(ax, [c for c in at_n if c not in found], bool(series))
        style_axes(
            ax,
            letter,
            f"N = {n:,}, t = {t_final:g}",
            "concentration $c$ [L⁻¹]",
            xlabel="position $x$ [L]",
            logx=False,
            legend=None,
        )
        if series:
            leg = ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=8, frameon=False)
            for handle in leg.legend_handles:  # same legend marker size whatever the dot size
                if hasattr(handle, "set_sizes"):
                    handle.set_sizes([20])
        out += series
    return fig, source_table("fig7", out)
