"""The figures: the shared toolkit (`style`: palette, styles, series, drawing, byte-stable saving;
`dilution`: the drawing Figs. 2, 4 and 5 share) and one module per figure, named for it: the
function ``<name>`` of ``figures/<name>.py`` draws ``figures/<name>.png`` (the adaptive searches'
``figures/optimum_<search>.png``: ``optimum.optimum_figure``; the scenes' ``figures/scene_<name>.png``:
``scene.scene``). ``FIGURES`` is the one list of
figures; the rules, the report's captions (``workflow/report/<name>.rst``), the column page and the
tests read it. A plot script imports only its figure's module and the workflow hashes only its
code, so editing one figure redraws that figure alone. Imports from `core`, `numerics`, `models`,
`experiments` and `analysis`; never from `pipeline`."""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from ..core.settings import FIGURE_OPTIONS


@dataclass(frozen=True)
class Figure:
    """One figure: ``name`` is its module, its target ``figures/<name>.png`` and its caption
    ``workflow/report/<name>.rst``; ``section`` the config section that lists what it draws;
    ``reads`` what its rule reads (runs, snapshots, summaries, comic, tradeoff, shear, mechanism,
    search, scene); ``category`` its heading in the report."""

    name: str
    section: str
    reads: str
    category: str = "Figures"

    @property
    def draws_cases(self) -> bool:
        """Drawn by the shared plot rule from the cases its section lists (figures.<name>, tradeoff)."""
        return self.reads in ("runs", "snapshots", "summaries", "comic", "tradeoff")


FIGURES = (
    Figure("fig1", "figures.fig1", "runs"),
    Figure("fig2", "figures.fig2", "runs"),
    Figure("fig3", "figures.fig3", "summaries"),
    Figure("fig4", "figures.fig4", "summaries"),
    Figure("fig5", "figures.fig5", "summaries"),
    Figure("fig6", "figures.fig6", "summaries"),
    Figure("fig7", "figures.fig7", "snapshots"),
    Figure("fig8", "figures.fig8", "summaries"),
    Figure("fig9", "figures.fig9", "comic"),
    Figure("fig10", "shear", "shear"),
    Figure("tradeoff", "tradeoff", "tradeoff", "Speed and accuracy"),
    Figure("fig9_mechanism", "mechanism", "mechanism", "Mechanism"),
    Figure("optimum", "optimum", "search", "Optimum search"),
    Figure("scene", "scenes", "scene", "Scenes"),
    Figure("scenes_peclet", "scenes_peclet", "scene", "Scenes"),
)
BY_NAME = {f.name: f for f in FIGURES}
PAPER_FIGURES = tuple(f.name for f in FIGURES if f.section.startswith("figures."))  # fig1 ... fig9
CASE_FIGURES = tuple(f.name for f in FIGURES if f.draws_cases)  # the shared plot rule's figures


def figure_options(name: str, section: dict) -> dict:
    """The drawing options of figure ``name`` from its config section, defaults filled in
    (settings.FIGURE_OPTIONS)."""
    return {s.name: section.get(s.name, s.default) for s in FIGURE_OPTIONS if s.section == f"figures.{name}"}


def figure_function(name: str):
    """The function drawing figure ``name``, ``(tables, cases, D=..., t_final=..., **options) ->
    (Figure, source data)``, options from ``figure_options``; imports only its module."""
    return getattr(importlib.import_module(f"{__name__}.{name}"), name)
