"""Figures draw exactly the cases they are given, in paper or automatic styles, and return the data they plot.

Tables are synthetic (known values, the columns the workflow writes) except where a test runs
tiny real simulations; assertions read the returned source data and the Line2D objects, not pixels.
"""

from __future__ import annotations

import math
import zlib

import matplotlib
import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import ROOT

from particle_entropy.core.labels import case_label

matplotlib.use("Agg")

from particle_entropy.analysis.aggregate import METRICS  # noqa: E402
from particle_entropy.core.case import CASE_COLUMNS, MODEL_COLUMNS, Case, rows_of  # noqa: E402
from particle_entropy.core.runconfig import RunConfig  # noqa: E402
from particle_entropy.figures import (  # noqa: E402
    CASE_FIGURES,
    fig1,
    fig5,
    fig9,
    fig10,
    figure_function,
    style,
    tradeoff,
)
from particle_entropy.models.simulate import run  # noqa: E402

CONFIG = yaml.safe_load((ROOT / "config.yaml").read_text())
NS = (30, 100)
T = np.array([0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0])
KW = {"D": 1e-3, "t_final": 20.0}
ADDED = Case("mtpt", "collision", eta=0.25, truncation=3)  # a model the paper does not draw


def paper_cases(fig: str, ns=NS, extra: tuple[Case, ...] = ()) -> list[Case]:
    """The cases of a config section (cases x N, config order), plus ``extra`` models at each N."""
    section = CONFIG["tradeoff"] if fig == "tradeoff" else CONFIG["figures"][fig]
    models = [Case.from_spec(spec, None, CONFIG["case_defaults"]) for spec in section["cases"]] + list(extra)
    return [m.at(n) for m in models for n in ns]


def _rng(case: Case) -> np.random.Generator:
    return np.random.default_rng(zlib.crc32(repr(case).encode()))


def _common(df: pd.DataFrame, case: Case) -> pd.DataFrame:
    """Analytic columns (tables over time), dV, D and the case columns."""
    domain = 12.0 if case.method == "fd" else 10.0
    if "time" in df:
        t = df["time"].to_numpy()
        with np.errstate(divide="ignore"):
            df["H_C_analytic"] = -math.log(domain / case.n) + 0.5 * np.log(4 * np.pi * 1e-3 * t) + 0.5
        df["E_analytic"] = np.sqrt(4 * np.pi * np.e * 1e-3 * t)
    df["dV"], df["D"] = domain / case.n, 1e-3
    for col, value in case.columns().items():
        df[col] = value
    return df


def summary(case: Case, realisations: int = 3) -> pd.DataFrame:
    """A case summary with random positive ensemble means (known arrays) and stds."""
    rng = _rng(case)
    df = pd.DataFrame({"step": np.arange(T.size), "time": T, "n_realisations": realisations})
    for m in METRICS:
        df[f"{m}_mean"] = rng.uniform(0.1, 2.0, T.size)
        df[f"{m}_std"] = rng.uniform(0.0, 0.1, T.size)
    return _common(df, case)


def run_table(case: Case) -> pd.DataFrame:
    """A single-run table with random positive measures."""
    rng = _rng(case)
    df = pd.DataFrame({"step": np.arange(T.size), "time": T})
    for m in METRICS:
        df[m] = rng.uniform(0.1, 2.0, T.size)
    return _common(df, case)


def state(case: Case) -> pd.DataFrame:
    x = np.linspace(-1.0, 1.0, case.n)
    df = pd.DataFrame({"x": x, "c": np.exp(-(x**2) / 0.08) / np.sqrt(0.08 * np.pi), "mass": 1.0 / case.n})
    return _common(df, case)


def comic_table(cases: list[Case], times=(5.0, 20.0)) -> pd.DataFrame:
    rows = []
    for c in cases:
        rng = _rng(c)
        for t in times:
            mu, sd = rng.uniform(-10, -5), rng.uniform(0.1, 1.0)
            rows.append(
                {
                    "label": case_label(c, n=False),
                    **c.columns(),
                    "time": t,
                    "time_step": t - 0.1,
                    "COMIC_mean": mu,
                    "COMIC_std": sd,
                    "COMIC_of_mean_SSE": mu + 0.5,
                    "COMIC_of_mean_SSE_lo": -math.inf,
                    "COMIC_of_mean_SSE_hi": mu + 1.0,
                    "SSE_mean": 0.1,
                    "SSE_std": 0.2,
                    "n_realisations": 3,
                }
            )
    return pd.DataFrame(rows)


def argmin_and_minima(comic: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Synthetic bootstrap tables for a COMIC table: per model and time, the N of least mean COMIC
    is the argmin of 70 % of resamples and the next N of 30 % (the last N: the one before)."""
    shares, minima = [], []
    model_cols = list(MODEL_COLUMNS)
    for key, g in comic.groupby([*model_cols, "time"]):
        g = g.sort_values("n").reset_index(drop=True)
        k = int(np.argmin(g["COMIC_mean"].to_numpy()))
        other = k + 1 if k + 1 < len(g) else k - 1
        model = dict(zip([*model_cols, "time"], key, strict=True))
        for j, row in g.iterrows():
            share = 0.7 if j == k else (0.3 if j == other else 0.0)
            shares.append(
                {**model, "convention": "mean_COMIC", "n": int(row["n"]), "share": share, "n_realisations": 3}
            )
        lo, hi = sorted((int(g["n"][k]), int(g["n"][other])))
        minima.append(
            {
                **model,
                "n_opt": int(g["n"][k]),
                "n_opt_ci_lo": lo,
                "n_opt_ci_hi": hi,
                "n_opt_share": 0.7,
                "n_resamples": 2000,
            }
        )
    return pd.DataFrame(shares), pd.DataFrame(minima)


def tradeoff_table(cases: list[Case], times=(5.0, 20.0)) -> pd.DataFrame:
    rows = []
    for c in cases:
        rng = _rng(c)
        for t in times:
            rows.append(
                {
                    "label": case_label(c, n=False),
                    **c.columns(),
                    "time": t,
                    "wall_s": rng.uniform(0.01, 1),
                    "wall_s_std": 0.001,
                    "rmse": rng.uniform(0.01, 1),
                    "rmse_std": 0.01,
                    "COMIC_mean": rng.uniform(-10, -5),
                    "COMIC_std": 0.5,
                    "n_realisations": 2,
                }
            )
    df = pd.DataFrame(rows)
    keys = [*MODEL_COLUMNS, "time"]
    df["is_comic_optimum"] = df["COMIC_mean"] == df.groupby(keys)["COMIC_mean"].transform("min")
    return df


def inputs(fig: str, cases: list[Case]) -> list[pd.DataFrame]:
    """What plot_figure.py reads for ``fig``: one table per case, or one table for all cases."""
    if fig == "fig9":
        comic = comic_table(cases)
        argmin, minima = argmin_and_minima(comic)
        return [comic, minima, argmin]
    if fig == "tradeoff":
        return [tradeoff_table(cases)]
    make = {"fig1": run_table, "fig2": run_table, "fig7": state}.get(fig, summary)
    return [make(c) for c in cases]


def draw(fig: str, cases: list[Case], tables=None):
    figure, data = figure_function(fig)(inputs(fig, cases) if tables is None else tables, cases, **KW)
    return figure, data


def case_of(row) -> Case:
    return Case.from_row(row)


def hex_of(colour) -> str:
    return matplotlib.colors.to_hex(colour)


def line_styles(ax) -> dict[str, tuple]:
    """(colour, marker, line style, marker face) of every labelled Line2D of an axes, by label."""
    return {
        ln.get_label(): (hex_of(ln.get_color()), ln.get_marker(), ln.get_linestyle(), str(ln.get_markerfacecolor()))
        for ln in ax.get_lines()
        if not ln.get_label().startswith("_")
    }


FIGURE_NAMES = list(CASE_FIGURES)


# ------------------------------------------------------------------ every figure
@pytest.mark.parametrize("fig", FIGURE_NAMES)
def test_every_figure_returns_its_cases_and_only_them(fig):
    cases = paper_cases(fig)
    tables = inputs(fig, cases)
    if fig in ("fig9", "tradeoff"):  # rows of a model not in the section must not be drawn
        tables = [pd.concat([tables[0], inputs(fig, [Case("mtpt", "sph", n, eta=0.3) for n in NS])[0]])]
    figure, data = draw(fig, cases, tables)
    assert list(data.columns) == list(style.SOURCE_COLUMNS)
    assert len(data) > 0 and set(data["figure"]) == {fig}
    drawn = data[data["method"] != "analytic"]
    assert {case_of(r) for _, r in drawn.drop_duplicates(list(CASE_COLUMNS)).iterrows()} == set(cases)
    assert data.groupby(["panel", "series", "x_name", "y_name"]).ngroups == data.groupby(["panel", "series"]).ngroups


@pytest.mark.parametrize("fig", [f for f in FIGURE_NAMES if f != "fig7"])
def test_an_added_model_has_a_style_of_its_own_in_every_panel(fig):
    extra = Case("fd", "explicit") if fig == "fig8" else Case("pt", "adaptive", dt_growth=1.01)
    extra = ADDED if fig in ("fig5", "fig6", "fig9") else extra
    figure, data = draw(fig, paper_cases(fig, extra=(extra,)))
    added = data[
        (data["method"] == extra.method)
        & (data["kernel"] == extra.kernel)
        & (data["eta"] == extra.eta)
        & (data["dt_growth"] == extra.dt_growth)
    ]
    assert len(added) > 0
    for ax in figure.axes:
        styles = line_styles(ax)
        mine = {label: st for label, st in styles.items() if label in set(added["series"])}
        others = {st for label, st in styles.items() if label not in mine}
        assert all(st not in others for st in mine.values()), (ax.get_title(), mine, others)


def test_fig5_added_case_data_and_paper_colours():
    cases = paper_cases("fig5", extra=(ADDED,))
    tables = inputs("fig5", cases)
    figure, data = draw("fig5", cases, tables)
    for case, table in zip(cases, tables, strict=True):
        rows = rows_of(data, case)
        plotted = table[table["time"] > 0]
        assert np.allclose(rows["y"], plotted["E_mean"]) and np.allclose(rows["x"], plotted["time"])
        assert np.allclose(rows["y_std"], plotted["E_std"]) and (rows["n_realisations"] == 3).all()
        assert set(rows["series"]) == {case_label(case)} and set(rows["y_name"]) == {"E"}
    added = data[data["eta"] == 0.25]
    assert set(added["truncation"]) == {3.0} and set(added["n"]) == set(NS)
    for ax, n in zip(figure.axes, sorted(NS, reverse=True), strict=True):
        styles = line_styles(ax)
        colour = {(c.kernel, c.eta): styles[case_label(c)][0] for c in cases if c.n == n}
        assert colour["collision", 1.0] == colour["collision", 0.1] == hex_of(style.GREEN)
        assert colour["sph", 1.0] == colour["sph", 0.1] == hex_of(style.VERMILLION)
        assert colour["collision", 0.25] not in map(hex_of, (style.GREEN, style.VERMILLION, style.BLACK))


def test_analytic_references_are_marked_as_such():
    _, data = draw("fig1", paper_cases("fig1"))
    ref = data[data["method"] == "analytic"]
    assert {"H_C", "settling time"} <= set(ref["y_name"])
    assert ref[["kernel", "scheme"]].isna().all().all() and ref["eta"].isna().all()
    assert set(ref["n"].dropna()) == set(NS) and ref["n_realisations"].isna().all()


def test_a_case_without_a_table_is_marked_no_data():
    cases = paper_cases("fig5")
    tables = [t for c, t in zip(cases, inputs("fig5", cases), strict=True) if c.kernel != "sph" or c.n != 30]
    figure, data = draw("fig5", cases, tables)
    assert not ((data["kernel"] == "sph") & (data["n"] == 30)).any()
    texts = [t.get_text() for ax in figure.axes for t in ax.texts]
    assert any(t.startswith("no data") and "SPH" in t for t in texts)
    _, empty = draw("fig9", paper_cases("fig9"), [comic_table([])])
    assert empty.empty and list(empty.columns) == list(style.SOURCE_COLUMNS)


# ------------------------------------------------------------------ styles
def test_paper_style_goes_to_the_case_closest_to_the_paper():
    base, truncated = Case("mtpt", "collision", eta=1.0), Case("mtpt", "collision", eta=1.0, truncation=3)
    looks = style.styles([truncated.at(30), base.at(30)], fig9.PAPER_STYLES)
    assert looks[base] == fig9.PAPER_STYLES[("mtpt", "collision", 1.0)]
    assert looks[truncated]["color"] not in (style.GREEN, style.VERMILLION, style.BLUE)


def test_automatic_styles_stay_distinct_and_off_the_paper_palette():
    added = [
        Case("mtpt", kernel, eta=eta, truncation=tr)
        for kernel in ("collision", "sph")
        for eta in (0.2, 0.3, 0.4)
        for tr in (None, 3)
    ]
    looks = style.styles(paper_cases("fig5", extra=tuple(added)), fig5.PAPER_STYLES)
    kinds = [(s["color"], s.get("marker"), s.get("linestyle", "-"), bool(s.get("open"))) for s in looks.values()]
    assert len(set(kinds)) == len(kinds)
    assert all(looks[m]["color"] not in (style.GREEN, style.VERMILLION) for m in added)


def test_scheme_variants_are_side_by_side_in_fig9_and_apart_in_tradeoff():
    symmetric = Case("mtpt", "collision", eta=1.0, truncation=3)
    sequential = Case("mtpt", "collision", eta=1.0, truncation=3, scheme="sequential")
    cases = [m.at(n) for m in (symmetric, sequential) for n in NS]
    _, data = draw("fig9", cases)
    # one panel of COMIC (a) and one of argmin shares (b), both schemes in each
    assert data.groupby("panel")["scheme"].agg(set).to_dict() == {
        "a": {"symmetric", "sequential"},
        "b": {"symmetric", "sequential"},
    }
    assert data.groupby("series")["scheme"].nunique().eq(1).all() and data["series"].nunique() == 6
    figure, data = draw("tradeoff", cases)
    assert data.groupby("panel")["series"].nunique().eq(2).all()
    assert set(data["series"]) == {case_label(symmetric, n=False), case_label(sequential, n=False)}
    styles = line_styles(figure.axes[0])
    assert styles[case_label(symmetric, n=False)] != styles[case_label(sequential, n=False)]
    variant = tradeoff.tradeoff_styles(cases)
    assert variant[symmetric]["linestyle"] == tradeoff.VARIANT_LINES[("truncation",)]
    assert variant[sequential]["linestyle"] == tradeoff.VARIANT_LINES[("truncation", "scheme")]


# ------------------------------------------------------------------ fig9, tradeoff, fig7, fig10
def test_fig9_error_bars_are_comic_std_at_the_time_nearest_t_final():
    cases = paper_cases("fig9", ns=(30, 100, 300), extra=(ADDED,))
    comic = comic_table(cases)
    argmin, minima = argmin_and_minima(comic)
    figure, data = draw("fig9", cases, [comic, minima, argmin])
    # three families: the paper's three, the added collision eta = 0.25 model its own panel; each
    # COMIC panel has its argmin panel below
    titles = sorted(ax.get_title(loc="left")[:3] for ax in figure.axes if ax.get_visible())
    assert titles == [f"({c})" for c in "abcdefgh"]
    mean = data[data["y_name"] == "COMIC"]
    for case in cases:
        row = rows_of(comic, case).query("time == 20.0").iloc[0]
        got = rows_of(mean, case).iloc[0]
        assert got["y"] == row["COMIC_mean"] and got["y_std"] == row["COMIC_std"]
        assert got["y_hi"] == pytest.approx(row["COMIC_mean"] + row["COMIC_std"])
        assert got["time"] == pytest.approx(19.9)
    for _, g in mean.groupby(["panel", "series"]):  # each model's own minimum, several models a panel
        assert g.loc[g["marked"], "y"].tolist() == [g["y"].min()]
    assert mean.groupby("panel")["series"].nunique().max() == 2  # the equations beside the authors' loop
    of_mean = data[data["y_name"] == "COMIC of mean SSE"]
    assert set(mean["series"]) == {f"{case_label(m, n=False)}: mean COMIC" for m in {c.model for c in cases}}
    assert np.isneginf(of_mean["y_lo"]).all() and of_mean["y_std"].isna().all()


def test_fig9_draws_the_argmin_shares_and_names_each_minimum_with_its_interval():
    cases = paper_cases("fig9", ns=(30, 100, 300))
    comic = comic_table(cases)
    argmin, minima = argmin_and_minima(comic)
    figure, data = draw("fig9", cases, [comic, minima, argmin])
    bars = data[data["y_name"] == "share of resamples with this argmin"]
    expected = argmin[argmin["time"] == 20.0]
    merged = bars.merge(expected, on=[*MODEL_COLUMNS, "n"])
    assert len(merged) == len(bars) == len(expected) and np.allclose(merged["y"], merged["share"])
    texts = [t.get_text() for ax in figure.axes for t in ax.texts]
    for _, m in minima[minima["time"] == 20.0].iterrows():
        lo, hi = int(m["n_opt_ci_lo"]), int(m["n_opt_ci_hi"])
        assert f"N_opt {int(m['n_opt']):,}, 95% CI {lo:,}–{hi:,} (70%)" in texts


def test_tradeoff_plots_rmse_against_wall_time_and_n_with_the_optimum_marked():
    cases = paper_cases("tradeoff", ns=(100, 300))
    table = tradeoff_table(cases)
    _, data = draw("tradeoff", cases, [table])
    assert set(data["panel"]) == set("abcd") and set(data["x_name"]) == {"wall_s", "N"}
    merged = data.merge(table, on=[*CASE_COLUMNS, "time"], suffixes=("", "_table"))
    assert len(merged) == len(data) and np.allclose(merged["y"], merged["rmse"])
    assert (merged["marked"] == merged["is_comic_optimum"]).all()


def test_fig7_plots_every_particle():
    cases = paper_cases("fig7")
    _, data = draw("fig7", cases)
    for case in cases:
        rows = rows_of(data, case)
        assert len(rows) == case.n and set(rows["x_name"]) == {"x"} and set(rows["y_name"]) == {"c"}


def test_fig1_and_fig6_from_tiny_real_runs():
    cases = [Case(m, k, 30, dt_growth=1.3) for m, k in (("pt", "bins"), ("pt", "fixed"), ("mtpt", "collision"))]
    runs = [run(RunConfig.for_case(c, t_final=2.0))[0] for c in cases]
    figure, data = fig1.fig1(runs, cases, D=1e-3, t_final=2.0)
    h_c = data[(data["y_name"] == "H_C") & (data["method"] != "analytic")]
    assert len(h_c) == sum(((r["time"] > 0) & np.isfinite(r["H_C"])).sum() for r in runs)
    h_d = data[data["y_name"] == "H_D"]
    assert np.allclose(h_d["y"], math.log(30)) and set(h_d["kernel"]) == {"bins"}


def test_fig10_returns_the_particles_it_draws():
    rng = np.random.default_rng(0)
    states = [
        pd.DataFrame(
            {
                "x": rng.uniform(90, 110, 200),
                "y": rng.uniform(0, 1, 200),
                "mass": np.where(np.arange(200) < 150, 1 / 150, 1e-9),
                "case": case,
                "seed": 0,
            }
        )
        for case in ("mt", "rw_drift", "rw_nodrift")
    ]
    figure, data = fig10.fig10(states)
    assert list(data.columns) == list(fig10.SOURCE_COLUMNS)
    dots = data[data["panel"].isin(list("abc"))]
    assert dots.groupby("panel")["case"].first().to_dict() == {"a": "rw_nodrift", "b": "rw_drift", "c": "mt"}
    assert (dots.groupby("case").size() == 150).all() and (dots["mass"] > fig10.MASS_FLOOR).all()
    hist = data[(data["panel"] == "f") & (data["y_name"] == "mass density")]
    assert len(hist) == fig10.N_BINS and np.sum(hist["y"]) / fig10.N_BINS == pytest.approx(1.0)


def test_save_figure_is_byte_stable(tmp_path):
    outputs = []
    for k in range(2):
        figure, _ = draw("fig5", paper_cases("fig5"))
        style.save_figure(figure, tmp_path / f"{k}.png", tmp_path / f"{k}.pdf")
        outputs.append([(tmp_path / f"{k}.{ext}").read_bytes() for ext in ("png", "pdf")])
    assert outputs[0] == outputs[1]


def _consistent_comic(cases: list[Case], ratios: dict[int, float]) -> pd.DataFrame:
    """A COMIC table whose mean-SSE columns follow Eq. 43 (aggregate.comic_of_mean_sse); SSE std =
    ratio x mean per N."""
    from particle_entropy.analysis.aggregate import comic_of_mean_sse

    rows = []
    for c in cases:
        sse, std = 1e-4 * c.n**-0.5, 1e-4 * c.n**-0.5 * ratios[c.n]
        rows.append(
            {"label": case_label(c, n=False), **c.columns(), "time": 20.0, "time_step": 19.9}
            | {"COMIC_mean": -9.0 - math.log(c.n), "COMIC_std": 0.3, "SSE_mean": sse, "SSE_std": std}
            | comic_of_mean_sse(sse, std, c.n, 10.0 / c.n)
            | {"n_realisations": 3}
        )
    return pd.DataFrame(rows)


def test_fig9_draws_the_papers_bars_at_half_eq43s_width_when_asked():
    ratios = {30: 1.5, 100: 0.6, 300: 0.2}  # std > mean at N = 30: the lower bar is unbounded either way
    cases = [Case("mtpt", "sph", n) for n in ratios]
    comic = _consistent_comic(cases, ratios)
    _, eq43 = draw("fig9", cases, [comic])
    figure, paper = figure_function("fig9")([comic], cases, **KW, bars="paper")
    pick = lambda d: {k: v.to_numpy() for k, v in d[d["y_name"] == "COMIC of mean SSE"].sort_values("n").items()}
    eq43, paper = pick(eq43), pick(paper)
    assert (paper["y"] == eq43["y"]).all()
    r = np.array([ratios[n] for n in paper["n"]])
    # Eq. 43: 2 ln(SSE (1 +- r)) - ...: twice the script's ln(SSE +- std) - ln(SSE) about the same point
    assert eq43["y_hi"] - eq43["y"] == pytest.approx(2 * (paper["y_hi"] - paper["y"]), rel=1e-12)
    assert paper["y_hi"] - paper["y"] == pytest.approx(np.log1p(r), rel=1e-12)
    assert paper["y_lo"][1:] - paper["y"][1:] == pytest.approx(np.log(1 - r[1:]), rel=1e-12)
    assert np.isneginf(paper["y_lo"][0]) and np.isneginf(eq43["y_lo"][0])
    legends = [t.get_text() for ax in figure.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert any("COMIC of mean SSE, the paper's bars" in t for t in legends)
    with pytest.raises(ValueError, match=r"figures.fig9.bars = 'nosuch': expected one of eq43, paper"):
        figure_function("fig9")([comic], cases, **KW, bars="nosuch")
