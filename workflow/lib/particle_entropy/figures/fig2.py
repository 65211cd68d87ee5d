"""Fig. 2: single-realisation dilution index E of each case against time (log-log); one panel per N."""

from __future__ import annotations

from .dilution import dilution_figure
from .style import PT_MTPT

PAPER_STYLES = PT_MTPT  # (method, kernel, eta) the paper draws -> its style


def fig2(tables, cases, *, D: float, t_final: float):
    """Fig. 2: single-realisation dilution index E of each case against time (log-log); one panel per N."""
    return dilution_figure("fig2", tables, cases, PAPER_STYLES, ensemble=False)
