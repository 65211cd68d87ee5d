"""The figures: the shared toolkit (`style`: palette, styles, series, drawing, byte-stable saving)
and one module per figure family of the paper (`fig1`, `dilution` for Figs. 2, 4 and 5, `fig3`,
`fig6`, `fig7`, `fig8`, `fig9`, `tradeoff`), the mechanism figure (`plots_mechanism`), the optimum
searches (`plots_optimum`) and the shear flow (`plots_shear`). `FIGURE_MODULES` names the module
that draws each paper figure: the plot script imports only that one and the workflow hashes only
its code, so editing one figure redraws that figure alone. Imports from `core`, `numerics`,
`experiments` and `analysis`; never from `pipeline`."""

from __future__ import annotations

import importlib

# figure -> the module (of this package) whose function of the figure's name draws it
FIGURE_MODULES = {
    "fig1": "fig1",
    "fig2": "dilution",
    "fig3": "fig3",
    "fig4": "dilution",
    "fig5": "dilution",
    "fig6": "fig6",
    "fig7": "fig7",
    "fig8": "fig8",
    "fig9": "fig9",
    "tradeoff": "tradeoff",
}


# figure -> {config key under figures.<fig>: (its choices, the default)}: drawing options a config
# may set beside a figure's cases (the schema lists the same, tests/test_figure_options.py)
FIGURE_OPTIONS = {
    "fig9": {"bars": (("eq43", "paper"), "eq43")},
}


def figure_options(name: str, section: dict) -> dict:
    """The drawing options of figure ``name`` from its config section, defaults filled in."""
    return {key: section.get(key, default) for key, (_, default) in FIGURE_OPTIONS.get(name, {}).items()}


def figure_function(name: str):
    """The function drawing figure ``name``, ``(tables, cases, D=..., t_final=..., **options) ->
    (Figure, source data)``, options from ``figure_options``; imports only its module."""
    return getattr(importlib.import_module(f"{__name__}.{FIGURE_MODULES[name]}"), name)
