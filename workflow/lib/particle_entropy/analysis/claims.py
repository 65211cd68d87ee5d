"""The paper's quantitative claims next to the reproduced values, each judged pass or fail."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..core.case import Case, by_model, case_of_table
from ..core.labels import case_label, preset_of
from ..core.registry import SCHEME_DOCS


def _near(df: pd.DataFrame, t: float) -> pd.Series:
    return df.iloc[int(np.argmin(np.abs(df["time"].to_numpy() - t)))]


def _pick(tables, case: Case) -> pd.DataFrame:
    """The table of ``case`` (a run table or case summary)."""
    for df in tables:
        if case_of_table(df) == case:
            return df
    raise KeyError(f"no table for {case_label(case)}")


COLUMNS = ("claim", "paper", "reproduced", "tolerance", "passed")  # of the claims table


def _claim(claim, paper, reproduced, tolerance, passed):
    return dict(zip(COLUMNS, (claim, paper, reproduced, tolerance, bool(passed))))


def claims_table(rows: list[dict]) -> pd.DataFrame:
    """The claims table; with no claim to judge (no figure the claims draw on) it is empty, with its columns."""
    return pd.DataFrame(rows, columns=list(COLUMNS)).astype({"passed": bool})


EARLY = (0.1, 10.0)  # "early times": after the settling time of N >= 300, well before t = 1000


def _early_gap(run: pd.DataFrame) -> float:
    """Mean H_C - analytic H_C over the early window."""
    w = run[(run["time"] >= EARLY[0]) & (run["time"] <= EARLY[1])]
    return float((w["H_C"] - w["H_C_analytic"]).mean())


def single_run_claims(runs: list[pd.DataFrame], defaults: dict | None = None) -> list[dict]:
    """Claims read off the single realisations of Figs. 1-2 (the paper's cases, unset
    dimensions from ``defaults``, config case_defaults)."""
    out = []
    paper = lambda method, kernel, n: Case.from_spec({"method": method, "kernel": kernel}, n, defaults)
    for n in sorted({int(r["n"].iloc[0]) for r in runs}):
        try:
            pt, mt, fx = (
                _pick(runs, paper(m, k, n)) for m, k in (("pt", "bins"), ("mtpt", "collision"), ("pt", "fixed"))
            )
        except KeyError:
            continue
        out.append(
            _claim(
                f"classical PT has H_D = ln N at t = 0 (N={n})",
                f"{math.log(n):.6f}",
                f"{pt['H_D'].iloc[0]:.6f}",
                "1e-12",
                abs(pt["H_D"].iloc[0] - math.log(n)) < 1e-12,
            )
        )
        out.append(
            _claim(
                f"MTPT represents the delta exactly, H_D(0) = 0 (N={n})",
                "0",
                f"{mt['H_D'].iloc[0]:.3g}",
                "exact",
                mt["H_D"].iloc[0] == 0.0,
            )
        )
        early, late = _near(pt, 1.0), _near(pt, 1000.0)
        e_err, l_err = abs(early.H_C - early.H_C_analytic), abs(late.H_C - late.H_C_analytic)
        out.append(
            _claim(
                f"binned PT matches H_C early, diverges late (N={n})",
                "error(t=1000) > error(t=1)",
                f"|dH_C| {e_err:.3f} at t=1, {l_err:.3f} at t=1000",
                "late > early",
                l_err > e_err,
            )
        )
        d_fx, d_mt = _early_gap(fx), _early_gap(mt)
        out.append(
            _claim(
                f"fixed-kernel PT over-estimates early mixing (N={n})",
                f"H_C > analytic for {EARLY[0]:g} <= t <= {EARLY[1]:g}",
                f"mean {d_fx:+.3f} nats",
                "> 0",
                d_fx > 0,
            )
        )
        out.append(
            _claim(
                f"MTPT collision under-estimates early entropy (N={n})",
                f"H_C < analytic for {EARLY[0]:g} <= t <= {EARLY[1]:g}",
                f"mean {d_mt:+.3f} nats",
                "< 0",
                d_mt < 0,
            )
        )
    ns = sorted({int(r["n"].iloc[0]) for r in runs})
    mtpt = {n: df for n in ns for df in runs if case_of_table(df) == paper("mtpt", "collision", n)}
    ns = sorted(mtpt)
    if len(ns) >= 2:
        errs = {n: abs(_near(mtpt[n], 10.0).pipe(lambda r: r.E / r.E_analytic - 1)) for n in ns}
        out.append(
            _claim(
                "MTPT collision converges faster for larger N",
                "relative E error at t = 10 falls with N",
                ", ".join(f"N={n}: {errs[n]:.3f}" for n in ns),
                "monotone",
                errs[ns[-1]] < errs[ns[0]],
            )
        )
    return out


def ensemble_claims(summaries: list[pd.DataFrame], tol_hc: float, defaults: dict | None = None) -> list[dict]:
    """Claims of Figs. 3 and 5 from ensemble means."""
    out = []
    for s in {case_of_table(s): s for s in summaries}.values():
        case = case_of_table(s)
        if case.method == "pt" and case.kernel == "adaptive":
            last = _near(s, 1000.0)
            d = last.H_C_mean - last.H_C_analytic
            out.append(
                _claim(
                    f"adaptive-kernel PT matches analytic H_C ({case_label(case)})",
                    "close at t = 1000",
                    f"{d:+.4f} nats ({int(last.n_realisations)} realisations)",
                    f"{tol_hc} nats",
                    abs(d) <= tol_hc,
                )
            )
    ns = sorted({int(s["n"].iloc[0]) for s in summaries if s["method"].iloc[0] == "mtpt"})
    for n in ns:
        try:
            change = {}
            for k in ("collision", "sph"):
                spec = {"method": "mtpt", "kernel": k}
                e1 = _near(_pick(summaries, Case.from_spec({**spec, "eta": 1.0}, n, defaults)), 1000.0).E_mean
                e01 = _near(_pick(summaries, Case.from_spec({**spec, "eta": 0.1}, n, defaults)), 1000.0).E_mean
                change[k] = abs(math.log(e01 / e1))
        except KeyError:
            continue
        out.append(
            _claim(
                f"eta = 0.1 changes collision little, SPH much (N={n})",
                "|d ln E| sph > collision",
                f"collision {change['collision']:.3f}, sph {change['sph']:.3f}",
                "sph > 2 x collision",
                change["sph"] > 2 * change["collision"],
            )
        )
    return out


def _model_words(model: Case) -> tuple[str, str]:
    """How a Fig. 9 row names its model, and the verb phrase of its result: the paper's figure
    came from the authors' loop (kernel cut at 3 widths); the paper's equations are the symmetric
    matrix with the whole Gaussian (Eqs. 16-21); other models by their scheme (registry.SCHEME_DOCS)."""
    cut = f", kernel cut at {model.truncation:g} widths" if model.truncation is not None else ""
    if model.scheme == "symmetric" and model.truncation is None:
        return "the paper's Eqs. 16-21, whole Gaussian", "the equations give"
    if preset_of(model) == "authors":
        return "the authors' algorithm (their loop, SPH constant, kernel cut at 3 widths, time grid)", (
            "the authors' algorithm gives"
        )
    if model.scheme == "sequential":
        return f"the authors' sequential loop{cut}", "the authors' algorithm gives"
    return f"{SCHEME_DOCS[model.scheme]}{cut}", "this variant gives"


def _optimum_text(row: pd.Series, prefix: str) -> str:
    """An optimum with its bootstrap interval and share, e.g. '3000 (95% CI 1000-3000; argmin in
    81% of 2000 resamples)'."""
    n_opt, resamples = int(row[prefix]), int(row.get("n_resamples", 0))
    lo, hi, share = row.get(f"{prefix}_ci_lo", -1), row.get(f"{prefix}_ci_hi", -1), row.get(f"{prefix}_share")
    if resamples > 0:
        return f"{n_opt} (95% CI {int(lo)}-{int(hi)}; argmin in {share:.0%} of {resamples} resamples)"
    if share is not None and share == 1.0:
        return f"{n_opt} (one realisation per N: nothing to resample)"
    return str(n_opt)


def flatness(rows: pd.DataFrame, min_n: int) -> dict:
    """Is mean COMIC flat over N >= ``min_n``? ``rows``: one model at one time (COMIC table rows).
    N_opt minimises mean COMIC over every N; N is within the error bars of the minimum when
    |mean(N) - mean(N_opt)| <= sqrt(std(N)^2 + std(N_opt)^2), std being the +-1 standard
    deviation bars of the figure. Flat when every N >= ``min_n`` is; reports the largest ratio
    |difference| / combined std (0 at N_opt; inf for a difference without bars) and its N."""
    g = rows.sort_values("n")
    k = int(np.argmin(g["COMIC_mean"].to_numpy()))
    opt = g.iloc[k]
    judged = g[g["n"] >= min_n]
    diff = np.abs(judged["COMIC_mean"].to_numpy() - opt["COMIC_mean"])
    bars = np.sqrt(judged["COMIC_std"].to_numpy() ** 2 + opt["COMIC_std"] ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(diff == 0, 0.0, diff / bars)
    if len(ratio) == 0:
        return {"flat": False, "n_opt": int(opt["n"]), "ratio": math.nan, "n_worst": -1}
    w = int(np.argmax(ratio))
    return {
        "flat": bool(np.all(ratio <= 1.0)),
        "n_opt": int(opt["n"]),
        "ratio": float(ratio[w]),
        "n_worst": int(judged["n"].iloc[w]),
    }


def comic_claims(minima: pd.DataFrame, comic: pd.DataFrame, tol: dict) -> list[dict]:
    """COMIC optima of FD (Fig. 8) and the MTPT models (Fig. 9), each claim judged for every
    model of its kind in the tables (a truncated or sequential variant gets its own row). A
    Fig. 9 row names its scheme and gives the optimum with its bootstrap interval and share
    (aggregate.comic_argmin); it passes when the optimum lies in the config range. SPH is
    "roughly flat" when every N >= claims.sph_flat_min_n lies within the error bars of the
    minimum (``flatness``)."""
    out = []
    for model, fd in by_model(minima[minima["method"] == "fd"]):
        lo, hi = tol["fd_optimum_nodes"]
        inside = (fd["n_opt"] >= lo) & (fd["n_opt"] <= hi)
        out.append(
            _claim(
                f"{case_label(model)}: COMIC minimal near 3000 nodes at almost every time",
                "~3000",
                ", ".join(f"t={t:g}: {n}" for t, n in zip(fd["time"], fd["n_opt"])),
                f"N_opt in [{lo}, {hi}]",
                inside.mean() >= 0.5,
            )
        )
    final = minima[minima["time"] == minima["time"].max()]
    mtpt = final[final["method"] == "mtpt"]
    for kernel, eta, key, paper in [
        ("collision", 1.0, "collision_eta1_optimum", "~3000 (1000-10,000)"),
        ("collision", 0.5, "collision_eta05_optimum", "~300"),
    ]:
        for model, rows in by_model(mtpt[(mtpt["kernel"] == kernel) & (mtpt["eta"] == eta)]):
            lo, hi = tol[key]
            row = rows.iloc[0]
            for col, how in [("n_opt", "mean of COMIC"), ("n_opt_of_mean_SSE", "COMIC of mean SSE")]:
                n_opt = int(row[col])
                out.append(
                    _claim(
                        f"{case_label(model)}: COMIC minimum at t = {row['time']:g} ({how}; {_model_words(model)[0]})",
                        f"{paper}, the authors' code",
                        f"{_model_words(model)[1]} {_optimum_text(row, col)}",
                        f"N_opt in [{lo}, {hi}]",
                        lo <= n_opt <= hi,
                    )
                )
    last = comic[(comic["time"] == comic["time"].max()) & (comic["method"] == "mtpt")]
    for model, sph in by_model(last[(last["kernel"] == "sph") & (last["eta"] == 1.0)]):
        min_n = int(tol["sph_flat_min_n"])
        f = flatness(sph, min_n)
        out.append(
            _claim(
                f"{case_label(model)}: COMIC roughly flat for N >= {min_n} ({_model_words(model)[0]})",
                "flat, worse only for N < 100",
                f"largest distance from the minimum {f['ratio']:.2f} combined std, at N={f['n_worst']} "
                f"(N_opt={f['n_opt']}, t = {sph['time'].iloc[0]:g})",
                f"<= 1 combined std, sqrt(std(N)^2 + std(N_opt)^2), for every N >= {min_n}",
                f["flat"],
            )
        )
    return out


def to_markdown(claims: pd.DataFrame) -> str:
    """A referee-friendly table of the claims."""
    lines = [
        "# Paper claims: reproduced values",
        "",
        f"{int(claims['passed'].sum())} of {len(claims)} claims pass."
        if len(claims)
        else "No claim judged: the config draws none of the figures the claims are about "
        "(fig1, fig3, fig5, fig8, fig9).",
        "",
        "| claim | paper | reproduced | tolerance | result |",
        "|---|---|---|---|---|",
    ]
    cell = lambda v: str(v).replace("|", "\\|")  # a '|' inside a cell (|dH_C|) would split it
    for _, c in claims.iterrows():
        cells = [cell(c.claim), cell(c.paper), cell(c.reproduced), cell(c.tolerance), "pass" if c.passed else "FAIL"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
