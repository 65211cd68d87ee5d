"""Ensemble statistics, COMIC tables, minima and the trade-off table (aggregate.py): summaries of three
short real MTPT runs against numpy, and tables of hand-built summaries against hand-found minima."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from particle_entropy.aggregate import (
    METRICS,
    at_times,
    comic_minima,
    comic_of_mean_sse,
    comic_table,
    summarise_files,
    summarise_runs,
    tradeoff_table,
)
from particle_entropy.case import Case
from particle_entropy.io import write_parquet
from particle_entropy.runconfig import RunConfig
from particle_entropy.simulate import run

SEEDS = (3, 4, 5)


@pytest.fixture(scope="module")
def runs() -> list[pd.DataFrame]:
    """Three realisations of MTPT collision, N = 50, t = 0 ... 2."""
    return [run(RunConfig(method="mtpt", kernel="collision", n=50, t_final=2.0, seed=s))[0] for s in SEEDS]


# --------------------------------------------------------------------------- summarise_runs
def test_summary_means_and_stds_are_numpys(runs):
    s = summarise_runs(runs)
    assert len(s) == len(runs[0]) and (s["n_realisations"] == 3).all()
    np.testing.assert_array_equal(s["step"], runs[0]["step"])
    np.testing.assert_array_equal(s["time"], runs[0]["time"])
    spread = 0
    for m in METRICS:
        v = np.stack([r[m].to_numpy(dtype=float) for r in runs])
        finite = np.isfinite(v).all(axis=0)
        np.testing.assert_allclose(s[f"{m}_mean"].to_numpy()[finite], v[:, finite].mean(axis=0), rtol=1e-13, atol=0)
        np.testing.assert_allclose(
            s[f"{m}_std"].to_numpy()[finite], v[:, finite].std(axis=0, ddof=1), rtol=1e-12, atol=1e-300
        )
        # three identical -inf values (a zero SSE, t = 0): mean -inf, no spread
        same_inf = np.isneginf(v).all(axis=0)
        assert np.isneginf(s[f"{m}_mean"].to_numpy()[same_inf]).all()
        assert (s[f"{m}_std"].to_numpy()[same_inf] == 0).all()
        spread += int((s[f"{m}_std"].to_numpy()[finite] > 0).sum())
    assert spread > 0  # the seeds really differ, so the std check is not vacuous


def test_summary_cost_columns_and_case(runs):
    s = summarise_runs(runs)
    wall = np.stack([np.cumsum(r["wall_s"].to_numpy()) for r in runs])
    np.testing.assert_allclose(s["wall_cum_mean"], wall.mean(axis=0), rtol=1e-13)
    np.testing.assert_allclose(s["wall_cum_std"], wall.std(axis=0, ddof=1), rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(s["work_mean"], np.mean([r["work"] for r in runs], axis=0))
    np.testing.assert_allclose(s["peak_rss_mb_max"], np.max([r["peak_rss_mb"] for r in runs], axis=0))
    assert s["work_mean"].iloc[-1] == 50 * runs[0]["substeps"].iloc[1:].sum()  # deterministic for N = 50
    row = s.iloc[0]
    assert Case.from_row(row) == Case("mtpt", "collision", 50) and row["D"] == 1e-3


def test_summary_of_one_realisation_has_zero_std(runs):
    s = summarise_runs(runs[:1])
    assert (s["n_realisations"] == 1).all()
    for m in METRICS:
        assert (s[f"{m}_std"] == 0).all()
    np.testing.assert_array_equal(s["H_C_mean"], runs[0]["H_C"])


def test_summary_refuses_different_step_grids(runs):
    with pytest.raises(ValueError):
        summarise_runs([runs[0], runs[1].iloc[:-1]])
    shifted = runs[1].copy()
    shifted["step"] = shifted["step"] + 1
    with pytest.raises(ValueError):
        summarise_runs([runs[0], shifted])
    with pytest.raises(ValueError):
        summarise_runs([])


def test_summarise_files_of_seed_blocks_equals_summarise_runs(runs, tmp_path):
    write_parquet(pd.concat(runs[:2], ignore_index=True), tmp_path / "seeds~3-4.parquet")
    write_parquet(runs[2], tmp_path / "seeds~5-5.parquet")
    out = tmp_path / "summary" / "r~3.parquet"
    # listed out of seed order: the summary still averages seed by seed
    assert summarise_files([str(tmp_path / "seeds~5-5.parquet"), str(tmp_path / "seeds~3-4.parquet")], str(out)) == 3
    pd.testing.assert_frame_equal(pd.read_parquet(out), summarise_runs(runs), check_exact=False, rtol=1e-14)


# --------------------------------------------------------------------------- hand-built summaries
TIMES = np.array([0.0, 4.8, 10.0, 20.0])
NS = (30, 100, 300)


def _summary(case: Case, comic: list[float], sse: list[float], sse_std: float = 0.0) -> pd.DataFrame:
    """A case summary at TIMES: COMIC_mean and SSE_mean per time, everything else fixed."""
    k = len(TIMES)
    df = pd.DataFrame(
        {
            "step": np.arange(k),
            "time": TIMES,
            "n_realisations": 4,
            "COMIC_mean": comic,
            "COMIC_std": 0.1,
            "SSE_mean": sse,
            "SSE_std": sse_std,
            "n_sse": case.n,
            "dV": 10.0 / case.n,
            "H_C_mean": 1.0,
            "H_C_analytic": 0.75,
            "E_mean": 3.0,
            "E_analytic": 2.0,
            "wall_cum_mean": np.arange(k) * 0.1,
            "wall_cum_std": 0.01,
            "work_mean": 5.0,
            "peak_rss_mb_max": 100.0,
        }
    )
    for c, v in {**case.columns(), "D": 1e-3}.items():
        df[c] = v
    return df


PAPER = Case("mtpt", "collision", eta=1.0)
VARIANTS = [Case("mtpt", "collision", truncation=3), Case("mtpt", "collision", scheme="sequential")]
# COMIC_mean[model][n] at TIMES[1:] (4.8, 10, 20); minima by hand:
#   paper:   t=4.8 -> 30, t=10 -> 100, t=20 -> 300;   variant: t=4.8 -> 300, t=10 -> 30, t=20 -> 100
COMIC = {
    "paper": {30: [-1.0, 2.0, 5.0], 100: [0.0, 1.0, 4.0], 300: [1.0, 3.0, 3.0]},
    "variant": {30: [2.0, -2.0, 6.0], 100: [1.5, 0.0, 2.5], 300: [0.5, 1.0, 2.6]},
}
OPT = {"paper": {4.8: 30, 10.0: 100, 20.0: 300}, "variant": {4.8: 300, 10.0: 30, 20.0: 100}}


def _summaries(variant: Case) -> list[pd.DataFrame]:
    out = []
    for name, model in (("paper", PAPER), ("variant", variant)):
        for n in NS:
            comic = [5.0, *COMIC[name][n]]
            sse = [0.5 * n, 0.2 * n, 0.1 * n, 0.05 * n]
            out.append(_summary(model.at(n), comic, sse))
    return out


def test_at_times_picks_nearest_rows():
    s = pd.DataFrame({"time": [0.0, 1.0, 2.5, 4.0, 10.0], "v": range(5)})
    rows = at_times(s, [2.0, 3.9, 100.0, 0.0])
    assert list(rows["v"]) == [2, 3, 4, 0]
    assert list(rows["time_requested"]) == [2.0, 3.9, 100.0, 0.0]


@pytest.mark.parametrize("variant", VARIANTS, ids=["truncation", "scheme"])
def test_comic_table_keeps_models_apart(variant):
    table = comic_table(_summaries(variant), [5.0, 20.0])
    assert len(table) == 2 * len(NS) * 2
    assert table["label"].nunique() == 2
    assert set(table["time"]) == {5.0, 20.0} and set(table["time_step"]) == {4.8, 20.0}
    for model, name in ((PAPER, "paper"), (variant, "variant")):
        rows = table[table["label"] == model.label(n=False)]
        assert len(rows) == 6
        for _, r in rows.iterrows():
            k = {4.8: 0, 20.0: 2}[r["time_step"]]
            assert r["COMIC_mean"] == COMIC[name][int(r["n"])][k]


@pytest.mark.parametrize("variant", VARIANTS, ids=["truncation", "scheme"])
def test_comic_minima_one_per_model_and_time_at_the_hand_argmin(variant):
    minima = comic_minima(comic_table(_summaries(variant), [5.0, 10.0, 20.0]))
    assert len(minima) == 2 * 3
    for model, name in ((PAPER, "paper"), (variant, "variant")):
        rows = minima[minima["label"] == model.label()]
        assert len(rows) == 3
        assert all(Case.from_row(r) == model for _, r in rows.iterrows())
        got = dict(zip(rows["time"], rows["n_opt"], strict=True))
        assert got == {5.0: OPT[name][4.8], 10.0: OPT[name][10.0], 20.0: OPT[name][20.0]}
    # neighbours of the paper model's optimum at t = 10 (N = 100): 30 below, 300 above, interior
    r = minima[(minima["label"] == PAPER.label()) & (minima["time"] == 10.0)].iloc[0]
    assert (r["n_below"], r["n_above"], bool(r["interior"])) == (30, 300, True)
    assert (r["COMIC_below"], r["COMIC_opt"], r["COMIC_above"]) == (2.0, 1.0, 3.0)
    edge = minima[(minima["label"] == PAPER.label()) & (minima["time"] == 5.0)].iloc[0]
    assert (edge["n_below"], bool(edge["interior"])) == (-1, False)


def test_comic_of_mean_sse_is_eq_43():
    sse, std, n, dV = 0.3, 0.1, 50, 0.2
    got = comic_of_mean_sse(sse, std, n, dV)
    assert got["COMIC_of_mean_SSE"] == pytest.approx(2 * math.log(sse / n) - math.log(dV), rel=1e-14)
    assert got["COMIC_of_mean_SSE_lo"] == pytest.approx(2 * math.log((sse - std) / n) - math.log(dV), rel=1e-14)
    assert got["COMIC_of_mean_SSE_hi"] == pytest.approx(2 * math.log((sse + std) / n) - math.log(dV), rel=1e-14)
    for big in (0.3, 0.5):  # std >= mean: the band reaches SSE = 0
        low = comic_of_mean_sse(sse, big, n, dV)["COMIC_of_mean_SSE_lo"]
        assert low == -math.inf


def test_comic_table_carries_comic_of_mean_sse():
    table = comic_table(_summaries(VARIANTS[0]), [10.0])
    for _, r in table.iterrows():
        n = int(r["n"])
        sse = 0.1 * n  # at t = 10
        assert r["SSE_mean"] == sse
        assert r["COMIC_of_mean_SSE"] == pytest.approx(2 * math.log(sse / n) - math.log(10.0 / n), rel=1e-13)


# --------------------------------------------------------------------------- trade-off table
@pytest.mark.parametrize("variant", VARIANTS, ids=["truncation", "scheme"])
def test_tradeoff_marks_one_optimum_per_model_and_time(variant):
    table = tradeoff_table(_summaries(variant), [5.0, 10.0, 20.0])
    assert len(table) == 2 * 3 * 3
    marked = table[table["is_comic_optimum"]]
    assert len(marked) == 2 * 3
    assert marked.groupby(["label", "time"]).size().eq(1).all()
    for model, name in ((PAPER, "paper"), (variant, "variant")):
        rows = marked[marked["label"] == model.label(n=False)]
        assert dict(zip(rows["time"], rows["n"], strict=True)) == {
            5.0: OPT[name][4.8],
            10.0: OPT[name][10.0],
            20.0: OPT[name][20.0],
        }


def test_tradeoff_errors_and_costs():
    table = tradeoff_table(_summaries(VARIANTS[0]), [10.0])
    for _, r in table.iterrows():
        n = int(r["n"])
        assert r["rmse"] == pytest.approx(math.sqrt(0.1 * n / n), rel=1e-14)  # sqrt(SSE_mean / n_sse)
        assert r["H_C_error"] == pytest.approx(0.25) and r["E_rel_error"] == pytest.approx(0.5)
        assert r["wall_s"] == pytest.approx(0.2) and r["n_realisations"] == 4


def test_tied_comic_marks_one_optimum_the_smallest_n_as_comic_minima_does():
    model = Case("mtpt", "collision")
    summaries = [_summary(model.at(n), [5.0, 1.0, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0]) for n in NS]  # every N ties
    marked = tradeoff_table(summaries, [10.0]).query("is_comic_optimum")
    assert marked["n"].tolist() == [min(NS)]
    assert comic_minima(comic_table(summaries, [10.0]))["n_opt"].tolist() == [min(NS)]
