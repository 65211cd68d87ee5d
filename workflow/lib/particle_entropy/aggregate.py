"""Ensemble statistics over realisations, COMIC tables and their minima (Figs. 3-6, 8, 9)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .case import CASE_COLUMNS, MODEL_COLUMNS, by_model, case_of_table
from .measures import comic

METRICS = ["H_D", "H_C", "H_I", "H_PMF", "E", "SSE", "AIC", "COMIC", "mass_total"]
SUMMARY_COLUMNS = {
    "step": "time-step index",
    "time": "time [T]",
    "n_realisations": "number of realisations averaged",
    "wall_cum_mean": "wall seconds of one realisation from t = 0 to this step, ensemble mean (varies run to run)",
    "wall_cum_std": "its standard deviation",
    "work_mean": "particle-steps (FD: node-steps) from t = 0 to this step, incl. substeps, ensemble mean",
    "peak_rss_mb_max": "largest peak resident memory of a realisation's process so far [MB] (varies run to run)",
    **{f"{m}_mean": f"ensemble mean of {m}" for m in METRICS},
    **{f"{m}_std": f"ensemble standard deviation of {m} (ddof = 1; 0 for one realisation)" for m in METRICS},
}


def summarise_files(paths: list[str], out: str) -> int:
    """Summarise the run tables ``paths`` (blocks of seeds of one case) into ``out``; returns
    the number of realisations."""
    from .io import write_parquet

    blocks = pd.concat([pd.read_parquet(p) for p in paths], ignore_index=True)
    runs = [g for _, g in blocks.groupby("seed", sort=True)]
    write_parquet(summarise_runs(runs), out)
    return len(runs)


def summarise_runs(runs: list[pd.DataFrame]) -> pd.DataFrame:
    """Per-step ensemble mean and standard deviation of every metric over realisations of one case."""
    if not runs:
        raise ValueError("no realisations to summarise")
    steps = [r["step"].to_numpy() for r in runs]
    if any(len(s) != len(steps[0]) or np.any(s != steps[0]) for s in steps):
        raise ValueError("realisations of one case must share their time steps")
    first = runs[0]
    out = {"step": first["step"].to_numpy(), "time": first["time"].to_numpy(), "n_realisations": len(runs)}
    for m in METRICS:
        v = np.stack([r[m].to_numpy(dtype=np.float64) for r in runs])
        with np.errstate(invalid="ignore"):  # -inf at t = 0 stays -inf, its std is nan -> 0
            out[f"{m}_mean"] = v.mean(axis=0)
            std = v.std(axis=0, ddof=1) if len(runs) > 1 else np.zeros(v.shape[1])
        out[f"{m}_std"] = np.where(np.isfinite(std), std, 0.0)
    out["work_mean"] = np.stack([r["work"].to_numpy(dtype=np.float64) for r in runs]).mean(axis=0)
    out["peak_rss_mb_max"] = np.stack([r["peak_rss_mb"].to_numpy(dtype=np.float64) for r in runs]).max(axis=0)
    wall = np.stack([np.cumsum(r["wall_s"].to_numpy(dtype=np.float64)) for r in runs])
    out["wall_cum_mean"] = wall.mean(axis=0)
    out["wall_cum_std"] = wall.std(axis=0, ddof=1) if len(runs) > 1 else np.zeros(wall.shape[1])
    df = pd.DataFrame(out)
    for c in ["H_C_analytic", "E_analytic", "dV", "n_sse", "settled"]:
        df[c] = first[c].to_numpy()
    for c, v in {**case_of_table(first).columns(), "D": first["D"].iloc[0]}.items():
        df[c] = v
    return df


def _case_rows(summaries: list[pd.DataFrame], times: list[float]):
    """(summary row, its label and case columns, time) for every summary at every requested time."""
    for s in summaries:
        case = case_of_table(s)
        for _, r in at_times(s, times).iterrows():
            yield r, {"label": case.label(n=False), **case.columns(), "time": float(r["time_requested"])}


def tradeoff_table(summaries: list[pd.DataFrame], times: list[float]) -> pd.DataFrame:
    """Cost (wall time) beside error (RMSE, H_C and E errors) and COMIC per model, N and time."""
    rows = []
    for r, case in _case_rows(summaries, times):
        rows.append(
            {
                **case,
                "wall_s": r["wall_cum_mean"],
                "wall_s_std": r["wall_cum_std"],
                "work": r["work_mean"],
                "peak_rss_mb": r["peak_rss_mb_max"],
                "rmse": float(np.sqrt(r["SSE_mean"] / r["n_sse"])),
                "H_C_error": r["H_C_mean"] - r["H_C_analytic"],
                "E_rel_error": r["E_mean"] / r["E_analytic"] - 1.0,
                "COMIC_mean": r["COMIC_mean"],
                "COMIC_std": r["COMIC_std"],
                "n_realisations": int(r["n_realisations"]),
            }
        )
    df = _sorted(pd.DataFrame(rows))
    # one optimum per model and time, the smallest N among ties, as comic_minima reports it
    best = df.groupby([*MODEL_COLUMNS, "time"])["COMIC_mean"].idxmin()
    df["is_comic_optimum"] = df.index.isin(best.to_numpy())
    return df


def at_times(summary: pd.DataFrame, times: list[float]) -> pd.DataFrame:
    """Rows of ``summary`` nearest to each requested time (one row per time)."""
    t = summary["time"].to_numpy()
    idx = [int(np.argmin(np.abs(t - x))) for x in times]
    rows = summary.iloc[idx].copy()
    rows["time_requested"] = list(times)
    return rows


def comic_table(summaries: list[pd.DataFrame], times: list[float]) -> pd.DataFrame:
    """COMIC and SSE statistics per model, N and requested time (results/tables/comic.parquet)."""
    rows = []
    for r, case in _case_rows(summaries, times):
        rows.append(
            {
                **case,
                "time_step": float(r["time"]),
                "COMIC_mean": r["COMIC_mean"],
                "COMIC_std": r["COMIC_std"],
                **comic_of_mean_sse(r["SSE_mean"], r["SSE_std"], int(r["n_sse"]), float(r["dV"])),
                "SSE_mean": r["SSE_mean"],
                "SSE_std": r["SSE_std"],
                "n_realisations": int(r["n_realisations"]),
            }
        )
    cols = [
        "label",
        *CASE_COLUMNS,
        "time",
        "time_step",
        "COMIC_mean",
        "COMIC_std",
        "COMIC_of_mean_SSE",
        "COMIC_of_mean_SSE_lo",
        "COMIC_of_mean_SSE_hi",
        "SSE_mean",
        "SSE_std",
        "n_realisations",
    ]
    return _sorted(pd.DataFrame(rows, columns=cols))


def _sorted(df: pd.DataFrame) -> pd.DataFrame:
    """Rows ordered by model (registry order), time and N."""
    if df.empty:
        return df
    parts = [g.sort_values(["time", "n"]) for _, g in by_model(df)]
    return pd.concat(parts, ignore_index=True)


def comic_of_mean_sse(sse_mean: float, sse_std: float, n: int, dV: float) -> dict:
    """COMIC of the ensemble-mean SSE (Eq. 43), as the authors' code plots Fig. 9, with the
    band 2 ln((SSE_mean -+ SSE_std) / n) - ln dV (-inf below when the std exceeds the mean)."""
    return {
        "COMIC_of_mean_SSE": comic(sse_mean, n, dV),
        "COMIC_of_mean_SSE_lo": comic(max(sse_mean - sse_std, 0.0), n, dV),
        "COMIC_of_mean_SSE_hi": comic(sse_mean + sse_std, n, dV),
    }


def comic_minima(comic: pd.DataFrame) -> pd.DataFrame:
    """For each model and time: the N minimising mean COMIC, its COMIC, and its neighbours' values."""
    rows = []
    for model, rows_of_model in by_model(comic):
        for time, g in rows_of_model.groupby("time", sort=True):
            rows.append(_minimum(model, time, g.sort_values("n", ignore_index=True)))
    return pd.DataFrame(rows, columns=MINIMA_COLUMNS)


MINIMA_COLUMNS = [
    "label",
    *MODEL_COLUMNS,
    "time",
    "n_opt",
    "COMIC_opt",
    "COMIC_opt_std",
    "n_opt_of_mean_SSE",
    "n_below",
    "COMIC_below",
    "n_above",
    "COMIC_above",
    "interior",
]


def _minimum(model, time: float, g: pd.DataFrame) -> dict:
    """The minimum of mean COMIC over N (rows ``g`` sorted by N) and its neighbours."""
    k = int(np.argmin(g["COMIC_mean"].to_numpy()))
    below = g.iloc[k - 1] if k > 0 else None
    above = g.iloc[k + 1] if k + 1 < len(g) else None
    return {
        "label": model.label(),
        **model.columns(),
        "time": time,
        "n_opt": int(g["n"][k]),
        "COMIC_opt": g["COMIC_mean"][k],
        "COMIC_opt_std": g["COMIC_std"][k],
        "n_opt_of_mean_SSE": int(g["n"][int(np.argmin(g["COMIC_of_mean_SSE"].to_numpy()))]),
        "n_below": int(below["n"]) if below is not None else -1,
        "COMIC_below": below["COMIC_mean"] if below is not None else np.nan,
        "n_above": int(above["n"]) if above is not None else -1,
        "COMIC_above": above["COMIC_mean"] if above is not None else np.nan,
        "interior": below is not None and above is not None,
    }
