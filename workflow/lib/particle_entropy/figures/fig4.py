"""Fig. 4: ensemble-mean E against time (log-log), collision-kernel MTPT in grey; one panel per N."""

from __future__ import annotations

from .dilution import dilution_figure
from .style import ADAPTIVE, GREY, SPH

PAPER_STYLES = {  # (method, kernel, eta) the paper draws -> its style
    ("pt", "adaptive", 1.0): ADAPTIVE,
    ("mtpt", "sph", 1.0): SPH,
    ("mtpt", "collision", 1.0): {"color": GREY, "marker": "D", "open": True, "zorder": 1},
}


def fig4(tables, cases, *, D: float, t_final: float):
    """Fig. 4: ensemble-mean E against time (log-log), collision-kernel MTPT in grey; one panel per N."""
    return dilution_figure("fig4", tables, cases, PAPER_STYLES, ensemble=True)
