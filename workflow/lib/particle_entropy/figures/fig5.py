"""Fig. 5: ensemble-mean E against time (log-log) for MTPT at eta = 1 and 0.1; one panel per N."""

from __future__ import annotations

from .dilution import dilution_figure
from .style import COLLISION, ETA_01, SPH

PAPER_STYLES = {  # (method, kernel, eta) the paper draws -> its style
    ("mtpt", "collision", 1.0): COLLISION,
    ("mtpt", "collision", 0.1): {**COLLISION, **ETA_01},
    ("mtpt", "sph", 1.0): SPH,
    ("mtpt", "sph", 0.1): {**SPH, **ETA_01},
}


def fig5(tables, cases, *, D: float, t_final: float):
    """Fig. 5: ensemble-mean E against time (log-log) for MTPT at eta = 1 and 0.1; one panel per N."""
    return dilution_figure("fig5", tables, cases, PAPER_STYLES, ensemble=True)
