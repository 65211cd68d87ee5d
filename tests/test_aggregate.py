"""Ensemble statistics, COMIC tables, minima and the trade-off table (aggregate.py): summaries of three
short real MTPT runs against numpy, and tables of hand-built summaries against hand-found minima; the
per-realisation values behind the COMIC tables, and the bootstrap of the argmin over N against
shares worked out by hand."""

from __future__ import annotations

import contextlib
import math
import warnings

import numpy as np
import pandas as pd
import pytest

from particle_entropy.analysis.aggregate import (
    ARGMIN_COLUMN_DOCS,
    METRICS,
    MINIMA_COLUMN_DOCS,
    MINIMA_COLUMNS,
    REALISATION_COLUMN_DOCS,
    at_times,
    comic_argmin,
    comic_minima,
    comic_of_mean_sse,
    comic_table,
    read_realisations,
    summarise_files,
    summarise_runs,
    tradeoff_table,
)
from particle_entropy.analysis.resampling import BOOTSTRAP_SEED, N_RESAMPLES, argmin_bootstrap
from particle_entropy.core.case import Case
from particle_entropy.core.io import write_parquet
from particle_entropy.core.labels import case_label
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models.simulate import run

SEEDS = (3, 4, 5)


@pytest.fixture(scope="module")
def runs() -> list[pd.DataFrame]:
    """Three realisations of MTPT collision, N = 50, t = 0 ... 2."""
    return [run(RunConfig.of(method="mtpt", kernel="collision", n=50, t_final=2.0, seed=s))[0] for s in SEEDS]


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
        rows = table[table["label"] == case_label(model, n=False)]
        assert len(rows) == 6
        for _, r in rows.iterrows():
            k = {4.8: 0, 20.0: 2}[r["time_step"]]
            assert r["COMIC_mean"] == COMIC[name][int(r["n"])][k]


@pytest.mark.parametrize("variant", VARIANTS, ids=["truncation", "scheme"])
def test_comic_minima_one_per_model_and_time_at_the_hand_argmin(variant):
    minima = comic_minima(comic_table(_summaries(variant), [5.0, 10.0, 20.0]))
    assert len(minima) == 2 * 3
    for model, name in ((PAPER, "paper"), (variant, "variant")):
        rows = minima[minima["label"] == case_label(model)]
        assert len(rows) == 3
        assert all(Case.from_row(r) == model for _, r in rows.iterrows())
        got = dict(zip(rows["time"], rows["n_opt"], strict=True))
        assert got == {5.0: OPT[name][4.8], 10.0: OPT[name][10.0], 20.0: OPT[name][20.0]}
    # neighbours of the paper model's optimum at t = 10 (N = 100): 30 below, 300 above, interior
    r = minima[(minima["label"] == case_label(PAPER)) & (minima["time"] == 10.0)].iloc[0]
    assert (r["n_below"], r["n_above"], bool(r["interior"])) == (30, 300, True)
    assert (r["COMIC_below"], r["COMIC_opt"], r["COMIC_above"]) == (2.0, 1.0, 3.0)
    edge = minima[(minima["label"] == case_label(PAPER)) & (minima["time"] == 5.0)].iloc[0]
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
        rows = marked[marked["label"] == case_label(model, n=False)]
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


# --------------------------------------------------------------------------- per-realisation values
def test_realisations_are_the_runs_at_the_nearest_step_and_average_to_the_summary(runs, tmp_path):
    write_parquet(pd.concat(runs[:2], ignore_index=True), tmp_path / "seeds~3-4.parquet")
    write_parquet(runs[2], tmp_path / "seeds~5-5.parquet")
    paths = [str(tmp_path / "seeds~5-5.parquet"), str(tmp_path / "seeds~3-4.parquet")]
    times = [0.7, 2.0]
    table = read_realisations(paths + paths[:1], times)  # a block read twice: its seed counts once
    assert list(table.columns) == list(REALISATION_COLUMN_DOCS)
    assert len(table) == len(SEEDS) * len(times)
    assert table["seed"].tolist() == [3, 4, 5, 3, 4, 5] and table["time"].tolist() == [0.7] * 3 + [2.0] * 3
    t = runs[0]["time"].to_numpy()
    for requested, step_time in zip(times, (t[np.argmin(np.abs(t - 0.7))], t[-1]), strict=True):
        rows = table[table["time"] == requested]
        assert (rows["time_step"] == step_time).all()
        for seed, run_ in zip(SEEDS, runs, strict=True):
            r = rows[rows["seed"] == seed].iloc[0]
            want = run_[run_["time"] == step_time].iloc[0]
            assert (r["SSE"], r["COMIC"], r["n_sse"], r["dV"], r["SSE_points"], r["COMIC_points"]) == (
                want["SSE"],
                want["COMIC"],
                want["n_sse"],
                want["dV"],
                want["SSE_points"],
                want["COMIC_points"],
            )
        # the per-seed values average to the ensemble mean of the COMIC table
        comic = comic_table([summarise_runs(runs)], [requested]).iloc[0]
        assert rows["COMIC"].mean() == pytest.approx(comic["COMIC_mean"], rel=1e-13)
        assert rows["COMIC"].std(ddof=1) == pytest.approx(comic["COMIC_std"], rel=1e-10)
        assert Case.from_row(rows.iloc[0]) == Case("mtpt", "collision", 50)


# --------------------------------------------------------------------------- bootstrap of the argmin
def _realisations(values: dict[Case, list[float]], time: float = 10.0, sse: dict | None = None) -> pd.DataFrame:
    """A realisations table: per case (with N) its per-seed COMIC (and SSE; default e^COMIC),
    n_sse = N, dV = 10 / N."""
    rows = []
    for case, comic in values.items():
        for seed, c in enumerate(comic):
            s = sse[case][seed] if sse else math.exp(c)
            rows.append(
                {
                    "label": case_label(case, n=False),
                    **case.columns(),
                    "time": time,
                    "time_step": time,
                    "seed": seed,
                    "SSE": s,
                    "COMIC": c,
                    "n_sse": case.n,
                    "dV": 10.0 / case.n,
                }
            )
    return pd.DataFrame(rows)


def _shares(argmin: pd.DataFrame, convention: str = "mean_COMIC") -> dict[int, float]:
    rows = argmin[argmin["convention"] == convention]
    return dict(zip(rows["n"], rows["share"], strict=True))


@contextlib.contextmanager
def _no_warnings():
    """A context in which any warning is an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


MODEL = Case("mtpt", "collision")
NOISE = np.random.default_rng(7).normal(size=(4, 30))  # 30 realisations of 4 N, standard normal


def test_a_clearly_lower_n_is_the_argmin_of_nearly_every_resample():
    # N = 1000 sits 3 nats below its neighbours, each realisation spread by 0.5 nats
    centre = {300: 1.0, 1000: -2.0, 3000: 1.0, 10000: 2.0}
    values = {MODEL.at(n): list(c + 0.5 * NOISE[k]) for k, (n, c) in enumerate(centre.items())}
    argmin = comic_argmin(_realisations(values))
    assert list(argmin.columns) == list(ARGMIN_COLUMN_DOCS)
    assert len(argmin) == 2 * 4 and set(argmin["convention"]) == {"mean_COMIC", "COMIC_of_mean_SSE"}
    assert (argmin["n_resamples"] == N_RESAMPLES).all() and N_RESAMPLES == 2000
    assert (argmin["n_realisations"] == 30).all()
    for convention in ("mean_COMIC", "COMIC_of_mean_SSE"):
        shares = _shares(argmin, convention)
        assert shares[1000] > 0.99 and sum(shares.values()) == pytest.approx(1.0, abs=1e-12)
        rows = argmin[argmin["convention"] == convention]
        assert (rows["ci_lo"] == 1000).all() and (rows["ci_hi"] == 1000).all()


def test_two_n_with_the_same_distribution_share_the_argmin_and_the_interval():
    same = list(NOISE[0])
    values = {MODEL.at(100): same, MODEL.at(300): same, MODEL.at(1000): list(5.0 + NOISE[1])}
    argmin = comic_argmin(_realisations(values))
    shares = _shares(argmin)
    assert 0.42 < shares[100] < 0.58 and 0.42 < shares[300] < 0.58  # 1/2 each, +- 5 binomial sd
    assert shares[1000] == 0.0
    rows = argmin[argmin["convention"] == "mean_COMIC"]
    assert (rows["ci_lo"] == 100).all() and (rows["ci_hi"] == 300).all()


def test_a_single_realisation_is_held_fixed():
    # N = 300 has one realisation, 0.5; N = 100 has two, -1 and 1. A resample of N = 100 has mean
    # -1, 0 or 1 with probabilities 1/4, 1/2, 1/4: N = 300 is the argmin only at mean 1 (1/4).
    values = {MODEL.at(100): [-1.0, 1.0], MODEL.at(300): [0.5]}
    with _no_warnings():
        argmin = comic_argmin(_realisations(values))
    shares = _shares(argmin)
    assert shares[300] == pytest.approx(0.25, abs=0.04) and shares[100] == pytest.approx(0.75, abs=0.04)
    assert argmin.set_index(["convention", "n"]).loc[("mean_COMIC", 300), "n_realisations"] == 1


def test_fd_single_realisations_give_the_point_estimate_with_share_one():
    fd = Case("fd", "implicit")
    # COMIC = 2 ln(SSE / N) - ln(10 / N) with the same SSE at every N: largest N is smallest
    ns = (30, 100, 300, 1000)
    comic = {fd.at(n): [2 * math.log(0.01 / n) - math.log(10.0 / n)] for n in ns}
    sse = {fd.at(n): [0.01] for n in ns}
    with _no_warnings():
        argmin = comic_argmin(_realisations(comic, sse=sse))
    assert (argmin["n_resamples"] == 0).all()
    for convention in ("mean_COMIC", "COMIC_of_mean_SSE"):
        assert _shares(argmin, convention) == {30: 0.0, 100: 0.0, 300: 0.0, 1000: 1.0}
        rows = argmin[argmin["convention"] == convention]
        assert (rows["ci_lo"] == 1000).all() and (rows["ci_hi"] == 1000).all()


def test_identical_realisations_give_a_degenerate_distribution_without_warnings():
    values = {MODEL.at(100): [1.0, 1.0, 1.0], MODEL.at(300): [0.0, 0.0, 0.0], MODEL.at(1000): [2.0, 2.0]}
    with _no_warnings():
        argmin = comic_argmin(_realisations(values))
    for convention in ("mean_COMIC", "COMIC_of_mean_SSE"):
        assert _shares(argmin, convention) == {100: 0.0, 300: 1.0, 1000: 0.0}
        rows = argmin[argmin["convention"] == convention]
        assert (rows["ci_lo"] == 300).all() and (rows["ci_hi"] == 300).all() and (rows["n_resamples"] == 2000).all()


def test_the_two_conventions_resample_what_they_minimise():
    # n_sse = 1 and dV = 1 in both N, so COMIC = 2 ln SSE. N = 100: SSE 1 always. N = 300: SSE
    # 0.01 three times and 10 once. Mean of COMIC at 300 is < 0 unless a resample draws 10 three
    # or four times, P = 4 (1/4)^3 (3/4) + (1/4)^4 = 0.0508; the COMIC of the mean SSE is < 0
    # only if it never draws 10, P = (3/4)^4 = 0.3164.
    sse = {MODEL.at(100): [1.0] * 4, MODEL.at(300): [0.01, 0.01, 0.01, 10.0]}
    comic = {c: [2 * math.log(s) for s in v] for c, v in sse.items()}
    table = _realisations(comic, sse=sse).assign(n_sse=1, dV=1.0)
    argmin = comic_argmin(table)
    assert _shares(argmin, "mean_COMIC")[300] == pytest.approx(1 - 0.0508, abs=0.025)
    assert _shares(argmin, "COMIC_of_mean_SSE")[300] == pytest.approx(0.3164, abs=0.05)


def test_the_bootstrap_is_byte_identical_between_calls(tmp_path):
    values = {MODEL.at(n): list(0.3 * NOISE[k]) for k, n in enumerate((100, 300, 1000, 3000))}
    table = _realisations(values)
    a, b = comic_argmin(table), comic_argmin(table.copy())
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    write_parquet(a, tmp_path / "a.parquet")
    write_parquet(b, tmp_path / "b.parquet")
    assert (tmp_path / "a.parquet").read_bytes() == (tmp_path / "b.parquet").read_bytes()
    assert 0.0 < _shares(a)[100] < 1.0  # the shares are not trivially 0 or 1: the resamples matter
    other = comic_argmin(table, seed=BOOTSTRAP_SEED + 1)
    assert not other["share"].equals(a["share"])  # a different seed gives different resamples


def test_argmin_bootstrap_interval_is_the_percentile_interval_widened_to_grid_points():
    # index 0 when both draws are 0 (P = 1/4), else index 1: both tails hold mass, so [0, 1]
    samples = [np.array([0.0, 1.0]), np.array([0.45, 0.45])]
    shares, lo, hi, drawn = argmin_bootstrap(samples)
    assert drawn == N_RESAMPLES and shares[0] == pytest.approx(0.25, abs=0.04)
    assert (lo, hi) == (0, 1)
    # index 0 only when all four draws are 0, P = 1/256, below the 2.5th percentile: index 1 alone
    samples = [np.array([0.0, 1.0, 1.0, 1.0]), np.array([0.2, 0.2])]
    shares, lo, hi, _ = argmin_bootstrap(samples)
    assert 0.0 < shares[0] < 0.025 and (lo, hi) == (1, 1)


def test_minima_carry_the_bootstrap_interval_and_share():
    variant = VARIANTS[1]
    summaries = _summaries(variant)
    comic = comic_table(summaries, [5.0, 10.0, 20.0])
    # realisations scattered +-0.01 around each summary's COMIC and SSE means
    rows = []
    for s in summaries:
        case = Case.from_row(s.iloc[0])
        for time, k in ((5.0, 1), (10.0, 2), (20.0, 3)):
            c, e = s["COMIC_mean"][k], s["SSE_mean"][k]
            for seed, d in enumerate((-0.01, 0.01, 0.0)):
                rows.append(
                    {"label": case_label(case, n=False), **case.columns(), "time": time, "time_step": s["time"][k]}
                    | {"seed": seed, "SSE": e * (1 + d), "COMIC": c + d, "n_sse": case.n, "dV": 10.0 / case.n}
                )
    argmin = comic_argmin(pd.DataFrame(rows))
    minima = comic_minima(comic, argmin)
    assert list(minima.columns) == MINIMA_COLUMNS == list(MINIMA_COLUMN_DOCS)
    assert len(minima) == 6 and (minima["n_resamples"] == N_RESAMPLES).all()
    for prefix in ("n_opt", "n_opt_of_mean_SSE"):
        assert (minima[f"{prefix}_ci_lo"] == minima[prefix]).all()
        assert (minima[f"{prefix}_ci_hi"] == minima[prefix]).all()
        assert (minima[f"{prefix}_share"] == 1.0).all()
    assert (minima["n_opt_of_mean_SSE"] == 30).all()  # 2 ln(SSE / n) - ln(10 / n) = 2 ln 0.1k + ln(n / 10)
    # without a bootstrap table: the same minima, bootstrap columns missing
    bare = comic_minima(comic)
    pd.testing.assert_frame_equal(bare[MINIMA_COLUMNS[:13]], minima[MINIMA_COLUMNS[:13]])
    assert (bare["n_opt_ci_lo"] == -1).all() and bare["n_opt_share"].isna().all() and (bare["n_resamples"] == 0).all()
    # a bootstrap missing one N of the COMIC table is refused
    with pytest.raises(ValueError, match="same ensembles"):
        comic_minima(comic, argmin[argmin["n"] != 300])


# --------------------------------------------------------------------------- unscored COMIC (issue 23)
def test_a_zero_or_overflowed_sse_is_unscored_never_minus_inf():
    """Eq. 43 of SSE = 0 is -inf and won every minimum (N = 1, t_final 1e-300); an overflowed SSE
    (omega 1e-300) is inf. Both are NaN with their reason, in every scoring table."""
    from particle_entropy.analysis.aggregate import UNSCORED, unscored

    got = unscored([0.0, np.inf, np.nan, 1e-3, 1e-3], [1.0, 1.0, 1.0, 0.0, 1.0])
    assert list(got) == [UNSCORED["zero"], UNSCORED["overflow"], UNSCORED["overflow"], UNSCORED["volume"], ""]
    assert all(np.isnan(v) for v in comic_of_mean_sse(0.0, 0.0, 10, 1.0).values())


def test_an_n_with_zero_sse_is_never_the_comic_minimum():
    summaries = _summaries(VARIANTS[0])
    degenerate = _summary(PAPER.at(2), [5.0, -np.inf, -np.inf, -np.inf], [1.0, 0.0, 0.0, 0.0])
    table = comic_table([*summaries, degenerate], TIMES[1:])
    rows = table[table["n"] == 2]
    assert rows["COMIC_mean"].isna().all() and rows["COMIC_of_mean_SSE"].isna().all()
    assert (rows["COMIC_reason"].str.startswith("SSE = 0")).all()
    assert not np.isinf(table[["COMIC_mean", "COMIC_of_mean_SSE"]].to_numpy(float)).any()
    minima = comic_minima(table)
    paper = minima[minima["label"] == case_label(PAPER)]
    assert dict(zip(paper["time"], paper["n_opt"])) == OPT["paper"]  # as without N = 2
    assert (paper["n_opt_of_mean_SSE"] != 2).all()
    assert paper["unscored"].str.startswith("N = 2: SSE = 0").all()
    assert (minima.loc[minima["label"] != case_label(PAPER), "unscored"] == "").all()
    trade = tradeoff_table([*summaries, degenerate], TIMES[1:])
    assert not trade.loc[trade["n"] == 2, "is_comic_optimum"].any()


def test_a_model_with_no_scored_n_has_no_minimum():
    table = comic_table(
        [_summary(PAPER.at(n), [0.0, -np.inf, -np.inf, -np.inf], [1.0, 0.0, 0.0, 0.0]) for n in NS], [10.0]
    )
    minima = comic_minima(table)
    assert minima["n_opt"].tolist() == [-1] and minima["n_opt_of_mean_SSE"].tolist() == [-1]
    assert np.isnan(minima["COMIC_opt"]).all()


def test_an_unscored_realisation_is_never_the_bootstrap_argmin():
    """Per-realisation COMIC -inf (SSE = 0) at one N: that N is NaN in the realisations table and
    takes no share of the argmin, under either convention."""
    from particle_entropy.analysis.aggregate import realisations_table

    values = {MODEL.at(300): [1.0, 1.2, 0.8, 1.1], MODEL.at(1000): [2.0, 2.1, 1.9, 2.2]}
    table = _realisations(values)
    frames = []
    for case, g in table.groupby("n"):
        run_like = g.assign(step=0, SSE_points=g["SSE"], COMIC_points=g["COMIC"]).drop(columns=["label", "time_step"])
        if case == 300:
            run_like = run_like.assign(SSE=0.0, COMIC=-np.inf, SSE_points=0.0, COMIC_points=-np.inf)
        frames.append(run_like)
    real = realisations_table(frames, [10.0])
    at300 = real[real["n"] == 300]
    assert at300["COMIC"].isna().all() and at300["COMIC_points"].isna().all()
    assert (at300["COMIC_reason"] == at300["COMIC_points_reason"]).all() and at300["COMIC_reason"].str.startswith(
        "SSE = 0"
    ).all()
    assert (real.loc[real["n"] == 1000, "COMIC_reason"] == "").all()
    argmin = comic_argmin(real, n_resamples=200)
    for convention in ("mean_COMIC", "COMIC_of_mean_SSE"):
        assert _shares(argmin, convention) == {300: 0.0, 1000: 1.0}
