"""figures/scene_<name>.png: one scene's answer, drawn from its table (analysis/scene_search.py).

(a) the error at t_final against the counted cost for every candidate (each visited resolution a
point with its 95 % interval), the target as a line (the budget, if any, dotted), the recommended
candidate and resolution starred; (b) COMIC at the common measurement points against resolution for
every candidate, the COMIC-best ringed; for a reactive scene instead the product's mass against
time: the reference, the recommended model and each candidate's finest visited rung (mean over
seeds). Unscored runs (negative concentrations) are drawn hollow and named below. A rung without
an error (NaN: not run, as when the reference cannot judge the target) or at error 0 has no place
on the log axis: it is not drawn, and panel (a) says how many are missing. A 2-D scene's figure adds
(c) the exact concentration at t_final and (d) the recommended model's, one grid and one set of levels
(figures/scene_maps.py); a 1-D scene's is drawn as before. A 2-D scene with a release draws in (b) instead
the concentration along the plume's axis: the exact plume, the recommended model and each FD candidate's
best rung (figures/scene_profile.py), as the MT3DMS manual compares its schemes.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .style import AUTO_COLOURS, AUTO_MARKERS, BLACK, new_figure, style_axes

MEASURE_LABEL = {
    "rmse": "concentration RMSE at the points [1/L]",
    "entropy": r"$|H_C - H_C^{exact}|$ [nats]",
    "dilution": r"$|E / E^{exact} - 1|$",
    "product": r"$|M_C / M_C^{ref} - 1|$, the product's mass",
    "product_rmse": "product's concentration RMSE at the points [1/L]",
}


def scene(table: pd.DataFrame, maps=None, profile=None):
    """The figure of one scene's table; of a 2-D scene with ``maps``, (scene, its ModelRun or None),
    panels a and b above the exact and the model's maps (figures/scene_maps.py); with ``profile``, the
    ModelRuns of a 2-D release scene's axis (figures/scene_profile.profile_runs), panel b draws them
    along the plume's axis (drawn: the figure's ``profile`` attribute, a scene_profile.Profile)."""
    if maps is None:
        fig, (ax, bx) = new_figure(2, width=5.4, height=5.6)
    else:
        fig, (ax, bx) = _with_maps(*maps)
    name, measure, target = table["scene"].iloc[0], table["measure"].iloc[0], table["target"].iloc[0]
    labels = list(dict.fromkeys(table["label"]))
    colours = {label: AUTO_COLOURS[i % len(AUTO_COLOURS)] for i, label in enumerate(labels)}
    reactive = "product_series" in table
    drawable = _on_log_axes(table)
    for i, label in enumerate(labels):
        every = table[table["label"] == label].sort_values("n")
        rows = every[drawable[every.index]]  # a NaN or zero error has no place on the log axis
        colour, marker = colours[label], AUTO_MARKERS[i % len(AUTO_MARKERS)]
        scored = rows["unscored"] == ""
        err = np.vstack([rows["error_mean"] - rows["error_lo"], rows["error_hi"] - rows["error_mean"]])
        ax.errorbar(
            rows["cost_s"],
            rows["error_mean"],
            yerr=np.clip(err, 0, None),
            color=colour,
            marker=marker,
            ms=5,
            lw=1.2,
            capsize=2,
            label=label,
            mfc=colour,
        )
        if (~scored).any():
            ax.plot(
                rows.loc[~scored, "cost_s"],
                rows.loc[~scored, "error_mean"],
                ls="none",
                marker=marker,
                ms=9,
                mfc="white",
                mec=colour,
            )
        if reactive:
            top = every[every["product_series"].map(len) > 0].tail(1)
            for _, r in top.iterrows():
                bx.plot(
                    r["series_times"],
                    r["product_series"],
                    color=colour,
                    lw=1.0,
                    ls=":",
                    label=f"{label}, n = {r['n']:,}",
                )
            continue
        if profile is not None:
            continue
        scored = every["unscored"] == ""
        bx.plot(
            every.loc[scored, "n"],
            every.loc[scored, "COMIC_points"],
            color=colour,
            marker=marker,
            ms=5,
            lw=1.2,
            label=label,
        )
    ax.axhline(target, color=BLACK, ls="--", lw=1.0, label=f"target {target:g}")
    budget = float(table["budget"].iloc[0]) if "budget" in table else np.inf
    if np.isfinite(budget):
        ax.axvline(budget, color=BLACK, ls=":", lw=1.0, label=f"budget {budget:g} s a run")
    best = table[table["recommended"]]
    if len(best) and drawable[best.index[0]]:
        r = best.iloc[0]
        ax.plot(
            [r["cost_s"]],
            [r["error_mean"]],
            marker="*",
            ms=16,
            color=BLACK,
            ls="none",
            label=f"cheapest meeting it: {r['label']}, n = {r['n']:,}",
        )
    comic = table[table["comic_best"]]
    if reactive:
        _product_panel(bx, table, best)
    elif profile is not None:
        from .scene_profile import draw_profile

        fig.profile = draw_profile(bx, maps[0], profile, colours)
    elif len(comic):
        r = comic.iloc[0]
        bx.plot(
            [r["n"]],
            [r["COMIC_points"]],
            marker="o",
            ms=14,
            mfc="none",
            mec=BLACK,
            ls="none",
            label=f"COMIC-best: {r['label']}, n = {r['n']:,}",
        )
    _say_what_is_not_drawn(ax, table, drawable, target)  # before the log scales: limits they can take
    label = MEASURE_LABEL[measure]
    if maps is not None:  # a 2-D scene's concentrations are per area
        label = label.replace("[1/L]", "[1/L²]")
    style_axes(ax, "a", f"scene {name}: error against cost", label, "counted cost of one run [s]", logx=True)
    ax.set_yscale("log")
    if not reactive and profile is None:
        style_axes(
            bx,
            "b",
            "COMIC at the common measurement points",
            "COMIC (Eq. 43) at the points",
            "resolution n (particles; FD intervals)",
            logx=True,
        )
    for axes in (ax, bx):  # below the axes, where no legend covers a point (the recommended star)
        axes.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=1, frameon=False)
    notes = sorted({f"{lab}: {why}" for lab, why in zip(table["label"], table["unscored"]) if why})
    if not len(best):
        closest = table[(table["unscored"] == "") & np.isfinite(table["error_upper95"])]
        closest = closest.sort_values("error_upper95").head(1)
        if len(closest):
            c = closest.iloc[0]
            notes.insert(
                0,
                f"No candidate meets the target; closest: {c['label']} at n = {c['n']:,} "
                f"(upper 95 % bound {c['error_upper95']:.3g})",
            )
    if notes:
        text = "\n".join(notes[:4])
        fig.text(0.01, 0.005, text, fontsize=8, ha="left", va="bottom", color="0.2")
        bottom = 0.045 * (1 + text.count("\n"))  # room for the notes; rect is (left, bottom, width, height)
        fig.get_layout_engine().set(rect=(0, bottom, 1, 1 - bottom))
    return fig


def _with_maps(scene, run):
    """A figure whose top holds panels a and b as in 1-D and whose bottom the two maps, as wide as
    the plume over the map grid is (equal aspect), with one colour bar -> (figure, (a, b))."""
    from matplotlib.figure import Figure

    from .scene_maps import draw_maps, map_grid

    x, y = map_grid(scene.reference)
    aspect = float(np.clip((y[-1] - y[0]) / (x[-1] - x[0]), 0.25, 1.2))
    low = 4.6 * aspect + 1.1  # a map 4.6 in wide, its title and labels
    fig = Figure(figsize=(10.8, 5.6 + low), layout="constrained")
    top, bottom = fig.subfigures(2, 1, height_ratios=[5.6, low])
    ax, bx = top.subplots(1, 2)
    cx, dx, cax = bottom.subplots(1, 3, width_ratios=[1, 1, 0.04])
    draw_maps((cx, dx), cax, scene, run)
    return fig, (ax, bx)


def _on_log_axes(table: pd.DataFrame) -> pd.Series:
    """Which rows panel (a) can place: a finite error above 0 at a finite cost above 0."""
    err, cost = table["error_mean"].astype(float), table["cost_s"].astype(float)
    return np.isfinite(err) & (err > 0) & np.isfinite(cost) & (cost > 0)


def _say_what_is_not_drawn(ax, table: pd.DataFrame, drawable: pd.Series, target: float) -> None:
    """Name in panel (a) the rungs it cannot draw (a NaN or zero error); with none drawn, keep a
    log axis about the target line (matplotlib cannot log-scale an axis with no positive value)."""
    missing = int((~drawable).sum())
    if not missing:
        return
    err = table["error_mean"].astype(float)
    nan, zero = int((~np.isfinite(err)).sum()), int((err == 0).sum())
    parts = [f"{nan} without an error (NaN)" if nan else "", f"{zero} at error 0" if zero else ""]
    rest = missing - nan - zero
    parts.append(f"{rest} at no positive cost" if rest else "")
    what = " and ".join(p for p in parts if p)
    lead = "No point drawn" if missing == len(table) else f"Not drawn: {missing} of {len(table)} rungs"
    text = f"{lead}: {what}" if missing == len(table) else f"{lead}, {what}"
    if missing == len(table):
        text += "\n(the notes below say why)" if (table["unscored"] != "").any() else ""
        low = target if np.isfinite(target) and target > 0 else 1.0
        ax.set_ylim(low / 10, low * 10)
        cost = table["cost_s"].astype(float)
        cost = cost[np.isfinite(cost) & (cost > 0)]
        ax.set_xlim(*((cost.min() / 3, cost.max() * 3) if len(cost) else (1e-4, 1.0)))
    y = 0.8 if missing == len(table) else 0.97  # above the target line, which sits mid-axis when none is drawn
    ax.text(0.5, y, text, transform=ax.transAxes, ha="center", va="top", fontsize=8, color="0.2")


def _product_panel(bx, table: pd.DataFrame, best: pd.DataFrame) -> None:
    """Panel b of a reactive scene: the product's mass against time, the reference (its Richardson
    error estimate in the legend) and the recommended model's mean over its seeds."""
    first = table.iloc[0]
    bx.plot(
        first["series_times"],
        first["reference_series"],
        color=BLACK,
        lw=2.2,
        label=f"reference ({first['reference_product']:.6g} +- {first['reference_error']:.2g} at t_final)",
    )
    if len(best) and len(best.iloc[0]["product_series"]):
        r = best.iloc[0]
        bx.plot(
            r["series_times"],
            r["product_series"],
            color=BLACK,
            lw=1.2,
            ls="--",
            marker="*",
            markevery=8,
            label=f"recommended: {r['label']}, n = {r['n']:,}",
        )
    style_axes(bx, "b", "the product's mass over time", r"product mass $M_C$", "time [T]")
