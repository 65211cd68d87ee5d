"""Ensemble statistics over realisations, COMIC tables and their minima (Figs. 3-6, 8, 9), and a
bootstrap over realisations of where each COMIC minimum lies."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from ..core.case import CASE_COLUMNS, MODEL_COLUMNS, by_model, case_of_table, rows_of
from ..core.io import read_parquet
from ..core.labels import case_label
from ..core.measures import comic
from ..core.registry import CONVENTION_NAMES
from .resampling import BOOTSTRAP_SEED, N_RESAMPLES, argmin_bootstrap, lowest

# why a COMIC (Eq. 43) does not score a model: it is NaN in every scoring table, never -inf, never a minimum
UNSCORED = {
    "zero": "SSE = 0: the model equals the reference at every point (t = 0, or a reference narrower than the "
    "points), COMIC would be -inf",
    "overflow": "SSE not finite: the densities overflowed (a sampling volume dV too small)",
    "volume": "dV not a finite number > 0",
    "realisation": "a realisation's SSE is 0 or not finite",
}


def unscored(sse, dV) -> np.ndarray:
    """Why COMIC (Eq. 43) of each ``sse`` with ``dV`` cannot score a model (UNSCORED), '' where it can."""
    sse = np.asarray(sse, dtype=np.float64)
    dV = np.broadcast_to(np.asarray(dV, dtype=np.float64), sse.shape)
    out = np.full(sse.shape, "", dtype=object)
    out[sse == 0] = UNSCORED["zero"]
    out[~np.isfinite(sse)] = UNSCORED["overflow"]
    out[~(np.isfinite(dV) & (dV > 0))] = UNSCORED["volume"]
    return out


METRICS = ["H_D", "H_C", "H_I", "H_PMF", "E", "SSE", "AIC", "COMIC", "mass_total"]
SUMMARY_COLUMNS = {
    "step": "time-step index",
    "time": "time at the end of the step [T]",
    "n_realisations": "realisations averaged (K)",
    "wall_cum_mean": "wall-clock seconds of one realisation from t = 0 to this step, ensemble mean (differs run "
    "to run) [s]",
    "wall_cum_std": "its standard deviation [s]",
    "work_mean": "ensemble mean of `work` (particle- or node-steps from t = 0, substeps counted)",
    "peak_rss_mb_max": "largest `peak_rss_mb` over the realisations (differs run to run) [MB]",
    "H_D_mean": "ensemble mean of `H_D` (Eq. 2) [nats]",
    "H_C_mean": "ensemble mean of `H_C` (Eqs. 6-7) [nats]",
    "H_I_mean": "ensemble mean of `H_I` (Eq. 3) [nats]",
    "H_PMF_mean": "ensemble mean of `H_PMF` (Section 5.4) [nats]",
    "E_mean": "ensemble mean of the dilution index `E` (Eqs. 8-9) [L]",
    "SSE_mean": "ensemble mean of `SSE` (Eq. 44) [1/L²]",
    "AIC_mean": "ensemble mean of `AIC` (Eq. 41)",
    "COMIC_mean": "ensemble mean of per-realisation `COMIC` (Eq. 43)",
    "mass_total_mean": "ensemble mean of `mass_total`",
    "H_D_std": "ensemble standard deviation of `H_D` [nats]",
    "H_C_std": "ensemble standard deviation of `H_C` [nats]",
    "H_I_std": "ensemble standard deviation of `H_I` [nats]",
    "H_PMF_std": "ensemble standard deviation of `H_PMF` [nats]",
    "E_std": "ensemble standard deviation of `E` [L]",
    "SSE_std": "ensemble standard deviation of `SSE` [1/L²]",
    "AIC_std": "ensemble standard deviation of `AIC`",
    "COMIC_std": "ensemble standard deviation of `COMIC`",
    "mass_total_std": "ensemble standard deviation of `mass_total`",
}


def summarise_files(paths: list[str], out: str) -> int:
    """Summarise the run tables ``paths`` (blocks of seeds of one case) into ``out``; returns
    the number of realisations."""
    from ..core.io import write_parquet

    blocks = pd.concat([read_parquet(p) for p in paths], ignore_index=True)
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
            yield r, {"label": case_label(case, n=False), **case.columns(), "time": float(r["time_requested"])}


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
                **_scored_mean(r),
                "n_realisations": int(r["n_realisations"]),
            }
        )
    df = _sorted(pd.DataFrame(rows))
    # one optimum per model and time, the smallest N among ties, as comic_minima reports it (never unscored)
    best = df[df["COMIC_mean"].notna()].groupby([*MODEL_COLUMNS, "time"])["COMIC_mean"].idxmin()
    df["is_comic_optimum"] = df.index.isin(best.to_numpy())
    return df


def _scored_mean(summary_row) -> dict:
    """COMIC_mean, COMIC_std and COMIC_reason of a summary row: NaN with the reason (UNSCORED) when
    the mean SSE or a realisation's cannot score, never -inf."""
    reason = unscored(summary_row["SSE_mean"], summary_row["dV"]).item()
    if not reason and not np.isfinite(summary_row["COMIC_mean"]):
        reason = UNSCORED["realisation"]
    if reason:
        return {"COMIC_mean": np.nan, "COMIC_std": np.nan, "COMIC_reason": reason}
    return {"COMIC_mean": summary_row["COMIC_mean"], "COMIC_std": summary_row["COMIC_std"], "COMIC_reason": ""}


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
                **_scored_mean(r),
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
        "COMIC_reason",
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
    band 2 ln((SSE_mean -+ SSE_std) / n) - ln dV (-inf below when the std exceeds the mean); all
    three NaN when the mean SSE cannot score (unscored)."""
    if unscored(sse_mean, dV).item():
        return {"COMIC_of_mean_SSE": np.nan, "COMIC_of_mean_SSE_lo": np.nan, "COMIC_of_mean_SSE_hi": np.nan}
    return {
        "COMIC_of_mean_SSE": comic(sse_mean, n, dV),
        "COMIC_of_mean_SSE_lo": comic(max(sse_mean - sse_std, 0.0), n, dV),
        "COMIC_of_mean_SSE_hi": comic(sse_mean + sse_std, n, dV),
    }


def comic_minima(comic: pd.DataFrame, argmin: pd.DataFrame | None = None) -> pd.DataFrame:
    """For each model and time: the N minimising mean COMIC, its COMIC, its neighbours' values,
    the N minimising the COMIC of the mean SSE, and (from ``argmin``, the table of
    ``comic_argmin``) the bootstrap interval and share of both optima (MINIMA_COLUMN_DOCS).
    Without ``argmin`` the bootstrap columns hold their missing values (-1, nan, 0 resamples)."""
    rows = []
    for model, rows_of_model in by_model(comic):
        for time, g in rows_of_model.groupby("time", sort=True):
            row = _minimum(model, time, g.sort_values("n", ignore_index=True))
            rows.append({**row, **_bootstrap_columns(model, time, row, g, argmin)})
    return pd.DataFrame(rows, columns=MINIMA_COLUMNS)


MINIMA_COLUMN_DOCS = {
    "label": "legend label of the model (without N)",
    **{c: f"model column (case.COLUMN_DOCS): {c}" for c in MODEL_COLUMNS},
    "time": "requested time (the COMIC rows are at the nearest recorded step) [T]",
    "time_step": "the recorded step of `n_opt`'s row, the model's own time (its last step for the final time: "
    "t = 1021.1 on the authors' time grid) [T]",
    "n_opt": "N of least mean COMIC, the ensemble mean of per-realisation COMIC (the smallest N among ties)",
    "COMIC_opt": "mean COMIC at `n_opt` (Eq. 43)",
    "COMIC_opt_std": "ensemble standard deviation of COMIC at `n_opt` (ddof = 1; 0 for one realisation)",
    "n_opt_of_mean_SSE": "N of least COMIC of the ensemble-mean SSE, 2 ln(SSE_mean / n_sse) - ln dV (the authors' "
    "convention for Fig. 9)",
    "n_below": "next smaller N of the grid (-1: `n_opt` is the smallest)",
    "COMIC_below": "mean COMIC at `n_below` (NaN if none)",
    "n_above": "next larger N of the grid (-1: `n_opt` is the largest)",
    "COMIC_above": "mean COMIC at `n_above` (NaN if none)",
    "interior": "`n_opt` has a grid neighbour on both sides: the minimum is bracketed",
    "n_opt_ci_lo": "lower end of the 95 % bootstrap percentile interval of the N of least mean COMIC, widened "
    "outward to a grid N (`argmin_bootstrap`; -1: no bootstrap table)",
    "n_opt_ci_hi": "its upper end, a grid N (-1: no bootstrap table)",
    "n_opt_share": "fraction of bootstrap resamples in which `n_opt` has the least mean COMIC (1 when nothing is "
    "resampled; NaN: no bootstrap table)",
    "n_opt_of_mean_SSE_ci_lo": "lower end of the same interval for the N of least COMIC of the mean SSE",
    "n_opt_of_mean_SSE_ci_hi": "its upper end",
    "n_opt_of_mean_SSE_share": "fraction of resamples in which `n_opt_of_mean_SSE` has the least COMIC of the mean SSE",
    "n_resamples": "bootstrap resamples drawn (`N_RESAMPLES`; 0 when every N has one realisation, e.g. FD: the "
    "optimum is then certain and its share 1)",
    "unscored": "the N whose mean COMIC is NaN, never a minimum, with the reason (`COMIC_reason`); empty when "
    "every N scored (every N unscored: `n_opt` -1)",
}
MINIMA_COLUMNS = list(MINIMA_COLUMN_DOCS)


def _minimum(model, time: float, g: pd.DataFrame) -> dict:
    """The minimum of mean COMIC over N (rows ``g`` sorted by N) and its neighbours; an N whose
    COMIC is NaN (unscored) is never the minimum."""
    k, k_sse = lowest(g["COMIC_mean"]), lowest(g["COMIC_of_mean_SSE"])
    below = g.iloc[k - 1] if k > 0 else None
    above = g.iloc[k + 1] if 0 <= k < len(g) - 1 else None
    reasons = g["COMIC_reason"] if "COMIC_reason" in g else pd.Series("", index=g.index)
    at = g.iloc[k] if k >= 0 else pd.Series({"time_step": time, "n": -1, "COMIC_mean": np.nan, "COMIC_std": np.nan})
    return {
        "label": case_label(model),
        **model.columns(),
        "time": time,
        "time_step": float(at["time_step"]) if "time_step" in g else float(time),
        "n_opt": int(at["n"]),
        "COMIC_opt": at["COMIC_mean"],
        "COMIC_opt_std": at["COMIC_std"],
        "n_opt_of_mean_SSE": int(g["n"][k_sse]) if k_sse >= 0 else -1,
        "n_below": int(below["n"]) if below is not None else -1,
        "COMIC_below": below["COMIC_mean"] if below is not None else np.nan,
        "n_above": int(above["n"]) if above is not None else -1,
        "COMIC_above": above["COMIC_mean"] if above is not None else np.nan,
        "interior": below is not None and above is not None,
        "unscored": "; ".join(f"N = {int(n)}: {why}" for n, why in zip(g["n"], reasons) if why),
    }


# --------------------------------------------------------------------------- per-realisation values
REALISATION_COLUMN_DOCS = {
    "label": "legend label of the model (without N)",
    **{c: f"case column (case.COLUMN_DOCS): {c}" for c in CASE_COLUMNS},
    "time": "requested time [T]",
    "time_step": "time of the recorded step nearest to it (`at_times`) [T]",
    "seed": "seed of the realisation",
    "SSE": "SSE of this realisation, Eq. 44 [1/L²]",
    "COMIC": "2 ln(SSE / n_sse) - ln dV of this realisation, Eq. 43",
    "n_sse": "points in `SSE`",
    "dV": "sampling volume [L]",
    "SSE_points": "SSE of this realisation at the 15 measurement points common to all models (the run tables' "
    "`SSE_points`; Section 6, point 1) [1/L²]",
    "COMIC_points": "2 ln(SSE_points / 15) - ln dV of this realisation, Eq. 43 at the measurement points",
    "COMIC_reason": "why `COMIC` is NaN (UNSCORED: SSE = 0, SSE not finite, dV not > 0); empty when it scores",
    "COMIC_points_reason": "why `COMIC_points` is NaN (the same reasons, of `SSE_points`); empty when it scores",
}
REALISATION_COLUMNS = list(REALISATION_COLUMN_DOCS)
# the run-table columns they are read from
RUN_COLUMNS = ["step", "time", "seed", "SSE", "COMIC", "n_sse", "dV", "SSE_points", "COMIC_points", *CASE_COLUMNS]


def read_realisations(paths: list[str], times: list[float]) -> pd.DataFrame:
    """``realisations_table`` of the run tables at ``paths`` (blocks of seeds, any cases)."""
    return realisations_table([read_parquet(p, columns=RUN_COLUMNS) for p in paths], times)


def realisations_table(runs: list[pd.DataFrame], times: list[float]) -> pd.DataFrame:
    """Per-realisation SSE and COMIC, at the model's own and at the measurement points, of every
    case in the run tables ``runs`` (each one case, one or more seeds) at the recorded step
    nearest to each of ``times``: one row per case, time and seed (REALISATION_COLUMN_DOCS). A
    seed read twice counts once."""
    parts = []
    for run in runs:
        case = case_of_table(run)
        for seed, g in run.groupby("seed", sort=True):
            rows = at_times(g.sort_values("step"), times)
            parts.append(
                pd.DataFrame(
                    {
                        "label": case_label(case, n=False),
                        **{c: [v] * len(rows) for c, v in case.columns().items()},
                        "time": rows["time_requested"].to_numpy(dtype=np.float64),
                        "time_step": rows["time"].to_numpy(dtype=np.float64),
                        "seed": int(seed),
                        "SSE": rows["SSE"].to_numpy(dtype=np.float64),
                        "COMIC": rows["COMIC"].to_numpy(dtype=np.float64),
                        "n_sse": rows["n_sse"].to_numpy(dtype=np.int64),
                        "dV": rows["dV"].to_numpy(dtype=np.float64),
                        "SSE_points": rows["SSE_points"].to_numpy(dtype=np.float64),
                        "COMIC_points": rows["COMIC_points"].to_numpy(dtype=np.float64),
                    }
                )
            )
    if not parts:
        return pd.DataFrame(columns=REALISATION_COLUMNS)
    df = pd.concat(parts, ignore_index=True).drop_duplicates([*CASE_COLUMNS, "time", "seed"])
    for column, sse in (("COMIC", "SSE"), ("COMIC_points", "SSE_points")):
        reason = unscored(df[sse], df["dV"])
        df[column] = np.where(reason != "", np.nan, df[column])  # never -inf: never a minimum
        df[f"{column}_reason"] = reason.astype(str)
    parts = [g.sort_values(["time", "n", "seed"]) for _, g in by_model(df)]
    return pd.concat(parts, ignore_index=True)[REALISATION_COLUMNS]


# --------------------------------------------------------------------------- bootstrap of the argmin
# convention -> (its column prefix in the minima table, what is minimised over N)
CONVENTIONS = dict(
    zip(
        CONVENTION_NAMES,  # mean_COMIC, COMIC_of_mean_SSE
        (
            ("n_opt", "mean over realisations of per-realisation COMIC"),
            ("n_opt_of_mean_SSE", "COMIC of the mean SSE over realisations"),
        ),
        strict=True,
    )
)
ARGMIN_COLUMN_DOCS = {
    "label": "legend label of the model (without N)",
    **{c: f"model column (case.COLUMN_DOCS): {c}" for c in MODEL_COLUMNS},
    "time": "requested time [T]",
    "convention": "what is minimised over N: " + " or ".join(f"`{k}` ({what})" for k, (_, what) in CONVENTIONS.items()),
    "n": "one N of the model's grid (particles; FD: intervals)",
    "share": "fraction of resamples whose argmin is this N (the shares of a model, time and convention add up to 1; "
    "without resampling 1 at the point estimate)",
    "n_realisations": "realisations of this N that were resampled (1: held fixed)",
    "n_resamples": "resamples drawn (0: every N has one realisation, nothing to resample)",
    "ci_lo": "lower end of the 95 % interval of the argmin for this model, time and convention, a grid N "
    "(`argmin_bootstrap`; the same on every row of that group)",
    "ci_hi": "its upper end",
}
ARGMIN_COLUMNS = list(ARGMIN_COLUMN_DOCS)


def convention_samples(per_n: list[pd.DataFrame], convention: str) -> tuple[list[np.ndarray], Callable]:
    """What a convention resamples per N and the statistic of the sample means it minimises over
    N (CONVENTIONS): mean_COMIC, per-realisation COMIC and its mean; COMIC_of_mean_SSE,
    per-realisation SSE and Eq. 43 of its mean. ``per_n``: realisations_table rows, one frame per N."""
    if convention == "mean_COMIC":
        return [s["COMIC"].to_numpy() for s in per_n], lambda means: means
    n_sse = np.array([float(s["n_sse"].iloc[0]) for s in per_n])[:, None]
    dV = np.array([float(s["dV"].iloc[0]) for s in per_n])[:, None]

    def of_mean_sse(means):  # Eq. 43 of the mean SSE, NaN where it cannot score (unscored)
        with np.errstate(divide="ignore", invalid="ignore"):
            value = 2.0 * (np.log(means) - np.log(n_sse)) - np.log(dV)
        return np.where(unscored(means, dV) != "", np.nan, value)

    return [s["SSE"].to_numpy() for s in per_n], of_mean_sse


def comic_argmin(
    realisations: pd.DataFrame, n_resamples: int = N_RESAMPLES, seed: int = BOOTSTRAP_SEED
) -> pd.DataFrame:
    """How often each N is the COMIC argmin over bootstrap resamples of the realisations, per
    model, time and convention (mean of per-realisation COMIC; COMIC of the mean SSE, Eq. 43):
    one row per model, time, convention and N (ARGMIN_COLUMN_DOCS), from the table of
    ``realisations_table``. Methods: ``argmin_bootstrap``."""
    rows = []
    for model, of_model in by_model(realisations):
        for time, g in of_model.groupby("time", sort=True):
            per_n = [s for _, s in g.groupby("n", sort=True)]
            ns = [int(s["n"].iloc[0]) for s in per_n]
            for convention in CONVENTIONS:
                samples, value = convention_samples(per_n, convention)
                shares, lo, hi, drawn = argmin_bootstrap(samples, value, n_resamples, seed)
                for n, sample, share in zip(ns, samples, shares):
                    rows.append(
                        {
                            "label": case_label(model),
                            **model.columns(),
                            "time": time,
                            "convention": convention,
                            "n": n,
                            "share": float(share),
                            "n_realisations": len(sample),
                            "n_resamples": drawn,
                            "ci_lo": ns[lo] if lo >= 0 else -1,
                            "ci_hi": ns[hi] if hi >= 0 else -1,
                        }
                    )
    return pd.DataFrame(rows, columns=ARGMIN_COLUMNS)


def _bootstrap_columns(model, time: float, minimum: dict, g: pd.DataFrame, argmin: pd.DataFrame | None) -> dict:
    """The minima table's bootstrap columns of one model and time, from the ``comic_argmin`` table."""
    out = {"n_resamples": 0}
    for convention, (prefix, _) in CONVENTIONS.items():
        out.update({f"{prefix}_ci_lo": -1, f"{prefix}_ci_hi": -1, f"{prefix}_share": np.nan})
        if argmin is None:
            continue
        rows = rows_of(argmin[(argmin["convention"] == convention) & (argmin["time"] == time)], model)
        if sorted(rows["n"]) != sorted(g["n"]):
            raise ValueError(
                f"{case_label(model)}, t = {time:g}: the bootstrap has N = {sorted(rows['n'].tolist())}, "
                f"the COMIC table N = {sorted(g['n'].tolist())}; they must come from the same ensembles"
            )
        if minimum[prefix] < 0:  # no N scored
            continue
        at_opt = rows[rows["n"] == minimum[prefix]].iloc[0]
        out.update(
            {
                f"{prefix}_ci_lo": int(at_opt["ci_lo"]),
                f"{prefix}_ci_hi": int(at_opt["ci_hi"]),
                f"{prefix}_share": float(at_opt["share"]),
                "n_resamples": int(at_opt["n_resamples"]),
            }
        )
    return out
