"""Fig. 1: single-realisation H_C of each case against time, H (= H_D) of PT and the analytic H_C."""

from __future__ import annotations

import numpy as np

from ..core.labels import case_label
from ..core.measures import settling_time
from .style import (
    PT_MTPT,
    PURPLE,
    Series,
    by_case,
    curve,
    draw,
    mark_missing,
    new_figure,
    panels_by_n,
    reference,
    source_table,
    style_axes,
    styles,
)

PAPER_STYLES = PT_MTPT  # (method, kernel, eta) the paper draws -> its style
RESERVED_COLOURS = (PURPLE,)  # PT's H_D


def fig1(tables, cases, *, D: float, t_final: float):
    """Fig. 1: single-realisation H_C of each case, H (= H_D) of PT and the analytic H_C; one panel per N."""
    found, style, out = by_case(tables), styles(cases, PAPER_STYLES, RESERVED_COLOURS), []
    panels = panels_by_n(cases)
    fig, axes = new_figure(len(panels))
    for ax, (letter, n, at_n) in zip(axes, panels, strict=True):
        have = [c for c in at_n if c in found]
        series = [curve(letter, c, found[c], "H_C", style[c.model], label=f"$H_C$, {case_label(c)}") for c in have]
        pt = [c for c in have if c.method == "pt"][:1]
        series += [
            curve(
                letter,
                c,
                found[c],
                "H_D",
                {"color": PURPLE, "linestyle": ":", "linewidth": 2.0, "marker": None},
                label=f"$H$ ($H_D$) of PT = ln N, N={n:,}",
            )
            for c in pt
        ]
        if have:
            ref = found[have[0]]
            series.append(reference(letter, f"$H_C$ analytic (Eq. 14), N={n:,}", ref, "H_C_analytic", n=n))
            t_settle = settling_time(float(ref["dV"].iloc[0]), float(ref["D"].iloc[0] if "D" in ref else D))
            if series[0].x.size and t_settle > series[0].x.min():  # only inside the plotted range
                series.append(
                    Series(
                        letter,
                        r"settling time $\Delta V^2/(4\pi e D)$",
                        None,
                        "time",
                        [t_settle],
                        "settling time",
                        [np.nan],
                        kind="vline",
                        n=n,
                        time=t_settle,
                        style={"color": "0.5", "linewidth": 0.8, "linestyle": "-."},
                    )
                )
        for s in series:
            draw(ax, s)
        mark_missing(ax, [c for c in at_n if c not in found], bool(series))
        if series:
            ax.set_ylim(bottom=max(ax.get_ylim()[0], -3.0))
        style_axes(ax, letter, f"N = {n:,}", "entropy $H$, $H_C$ [nats]", legend="lower right")
        out += series
    return fig, source_table("fig1", out)
