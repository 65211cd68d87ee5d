"""figures.FIGURES, the one list of figures: each has its module, its drawing function and its
report caption, and the names are the paper's and ours."""

from __future__ import annotations

import importlib

import pytest
from conftest import ROOT

from particle_entropy.figures import BY_NAME, CASE_FIGURES, FIGURES, PAPER_FIGURES, figure_function, figure_options


def test_the_list_names_the_papers_figures_and_ours():
    names = [f.name for f in FIGURES]
    assert names[:10] == [f"fig{k}" for k in range(1, 11)]  # Figs. 1-10 of the paper
    assert set(names[10:]) == {"tradeoff", "fig9_mechanism", "optimum", "scene", "scenes_peclet"}  # ours
    assert len(set(names)) == len(names) and set(BY_NAME) == set(names)
    assert PAPER_FIGURES == tuple(f"fig{k}" for k in range(1, 10))  # drawn from sections of cases
    assert set(CASE_FIGURES) == {*PAPER_FIGURES, "tradeoff"}


@pytest.mark.parametrize("figure", FIGURES, ids=lambda f: f.name)
def test_each_figure_has_its_module_and_caption(figure):
    caption = ROOT / "workflow" / "report" / f"{figure.name}.rst"
    assert caption.exists() and caption.read_text().strip(), caption
    module = importlib.import_module(f"particle_entropy.figures.{figure.name}")
    if figure.draws_cases:
        assert figure_function(figure.name) is getattr(module, figure.name)


def test_every_caption_is_a_figure_or_a_table_page():
    """No caption of a figure that no longer exists."""
    tables = {"comic", "comic_minima", "paper_claims", "workflow"}
    captions = {p.stem for p in (ROOT / "workflow" / "report").glob("*.rst")}
    assert captions == set(BY_NAME) | tables


def test_figure_options_fill_in_their_defaults():
    assert figure_options("fig9", {"cases": [], "n": [30]}) == {"bars": "eq43"}
    assert figure_options("fig9", {"bars": "paper"}) == {"bars": "paper"}
    assert figure_options("fig1", {"bars": "paper"}) == {}  # no options: nothing passed on
