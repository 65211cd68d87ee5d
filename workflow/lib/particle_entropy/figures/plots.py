"""Figures 1-9 of Benson et al. (2020) and the speed-accuracy trade-off, each drawn from the cases it is given.

``FIGURES[name](tables, cases, D=..., t_final=...)`` returns ``(Figure, source data)``: the figure
(not registered with pyplot; ``save_figure`` writes byte-stable PNG and PDF) and a tidy table of
every point it plots (columns in ``SOURCE_COLUMNS``). ``cases`` are a config section's cases x N
in config order; ``tables`` are, one per case in the same order, run tables (fig1, fig2), final
states (fig7) or case summaries (fig3-6, fig8), or one table for all cases (fig9: the COMIC
table; tradeoff: the trade-off table). A table is matched to its case by its case columns.

Styles: ``PAPER_STYLES`` holds, per figure, the (method, kernel, eta) triples the paper draws
and their look. Of the models matching a triple, the one closest to the paper's settings
(fewest ``Case.variant()`` dimensions; the first listed on ties) takes the paper's style;
every other model takes an automatic style (``_auto_styles``): an Okabe-Ito colour the
figure's paper styles do not use, a marker they do not use and a dashed or dotted line (in
fig6 and fig8 colour stands for N, so added models differ by line style and marker only). The
trade-off figure takes colour and marker from the model's family (method, kernel, eta) and the
line style from the dimensions it varies from the paper (``VARIANT_LINES``).
Each figure builds its ``Series`` first and draws them, so its table is what is on the page.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from ..core.case import CASE_COLUMNS, COLUMN_DOCS, Case, case_of_table, rows_of
from ..core.measures import analytic_h_i, settling_time

# Okabe-Ito colour-blind-safe palette (and the paper's grey for Fig. 4's collision kernel)
BLACK, ORANGE, SKY, GREEN, YELLOW, BLUE, VERMILLION, PURPLE = (
    "#000000",
    "#E69F00",
    "#56B4E9",
    "#009E73",
    "#F0E442",
    "#0072B2",
    "#D55E00",
    "#CC79A7",
)
GREY = "#8C8C8C"
AUTO_COLOURS = (ORANGE, SKY, BLUE, PURPLE, GREEN, VERMILLION, YELLOW)  # order in which added cases take them
AUTO_MARKERS = ("v", "P", "X", "h", "<", ">", "p")  # "*" marks minima
AUTO_LINES = ("--", ":", (0, (3, 1, 1, 1, 1, 1)))
ANALYTIC = {"color": BLACK, "linestyle": "--", "linewidth": 1.3, "zorder": 5, "marker": None}
T_LABEL = "time $t$ [T]"
LETTERS = "abcdefghijklmnopqrstuvwxyz"
FIG8_TIME = 250.0  # Fig. 8c compares the grids at this time [T] (nearest recorded step)
PNG_META = {"Software": None}
PDF_META = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}

SOURCE_COLUMNS = {
    "figure": "figure name: fig1 ... fig9, tradeoff or fig9_mechanism",
    "panel": "panel letter as printed ('' for a one-panel figure)",
    "series": "name of the series, unique within a panel: its legend label, except in fig7 (whose legend adds "
    "a line of statistics) and fig9 (the model's label, which is the panel title, then the quantity)",
    **{c: f"case of the point: {COLUMN_DOCS[c]}" for c in CASE_COLUMNS},
    "x_name": "quantity on the x axis (time, x, N, dx, wall_s)",
    "x": "its value",
    "y_name": "quantity on the y axis (H_C, H_D, E, H_PMF, c, ln(SSE/N), COMIC, rmse, ...)",
    "y": "its value (ensemble mean for case summaries)",
    "y_std": "ensemble standard deviation drawn as a +-1 std band or error bar; NaN where none is drawn",
    "y_lo": "lower end of the drawn band or error bar (y - y_std, or fig9's COMIC of SSE_mean - SSE_std; "
    "-inf when that SSE is <= 0); NaN where none is drawn",
    "y_hi": "upper end of the drawn band or error bar; NaN where none is drawn",
    "n_realisations": "realisations behind the point (1: a single run); missing for analytic references",
    "time": "time of the point [T]: x itself against time, else the recorded step drawn",
    "marked": "True where the point is starred: the minimum COMIC over N (fig8c, fig9), the COMIC optimum "
    "(tradeoff); for fig9's argmin-share bars, the N most often the argmin",
}
# Analytic references (and the settling-time line, y NaN) carry method "analytic", n the N they
# depend on (else missing) and missing kernel, eta, truncation, dt_growth and scheme.
REFERENCE_CASE = {
    "method": "analytic",
    "kernel": None,
    "eta": math.nan,
    "truncation": math.nan,
    "dt_growth": math.nan,
    "scheme": None,
}

# ---------------------------------------------------------------- styles
_BINS = {"color": ORANGE, "marker": "s"}
_FIXED = {"color": SKY, "marker": "^"}
_ADAPTIVE = {"color": BLUE, "marker": "o"}
_COLLISION = {"color": GREEN, "marker": "D"}
_SPH = {"color": VERMILLION, "marker": "D"}
_ETA_01 = {"linestyle": "-.", "open": True}
_PT_MTPT = {("pt", "bins", 1.0): _BINS, ("pt", "fixed", 1.0): _FIXED, ("mtpt", "collision", 1.0): _COLLISION}
# figure -> (method, kernel, eta) the paper draws -> its style. Style keys: matplotlib line keywords
# plus "open" (hollow markers) and, for fig7's dots, "size" (x the panel's dot area) and "alpha".
PAPER_STYLES = {
    "fig1": _PT_MTPT,
    "fig2": _PT_MTPT,
    "fig3": {("pt", "adaptive", 1.0): _ADAPTIVE, ("mtpt", "sph", 1.0): _SPH},
    "fig4": {
        ("pt", "adaptive", 1.0): _ADAPTIVE,
        ("mtpt", "sph", 1.0): _SPH,
        ("mtpt", "collision", 1.0): {"color": GREY, "marker": "D", "open": True, "zorder": 1},
    },
    "fig5": {
        ("mtpt", "collision", 1.0): _COLLISION,
        ("mtpt", "collision", 0.1): {**_COLLISION, **_ETA_01},
        ("mtpt", "sph", 1.0): _SPH,
        ("mtpt", "sph", 0.1): {**_SPH, **_ETA_01},
    },
    "fig6": {("mtpt", "collision", 1.0): {"linestyle": "-", "marker": None}},  # colour: N
    "fig7": {
        ("mtpt", "collision", 0.1): {"color": GREEN, "marker": "o", "size": 1, "alpha": 0.6},
        ("pt", "fixed", 1.0): {"color": BLUE, "marker": "o", "open": True, "size": 3},
    },
    "fig8": {("fd", "implicit", 1.0): {"linestyle": "-", "marker": None}},  # colour: N (a, b), measure (c)
    "fig9": {
        ("mtpt", "collision", 1.0): _COLLISION,
        ("mtpt", "sph", 1.0): _SPH,
        ("mtpt", "collision", 0.5): {"color": BLUE, "marker": "o"},
    },
}
RESERVED_COLOURS = {"fig1": (PURPLE,), "fig8": (BLUE, VERMILLION)}  # colours of non-case series
COLOUR_BY_N = ("fig6", "fig8")  # colour encodes N: added models differ by line style and marker
# trade-off: colour and marker by family (method, kernel, eta), line style by the varied dimensions
TRADEOFF_FAMILY = {
    ("fd", "implicit", 1.0): {"color": BLACK, "marker": "o"},
    ("pt", "bins", 1.0): _BINS,
    ("pt", "fixed", 1.0): _FIXED,
    ("pt", "adaptive", 1.0): _ADAPTIVE,
    ("mtpt", "collision", 1.0): _COLLISION,
    ("mtpt", "sph", 1.0): {"color": VERMILLION, "marker": "v"},
    ("mtpt", "collision", 0.5): {"color": PURPLE, "marker": "D", "open": True},
    ("mtpt", "sph", 0.5): {"color": GREY, "marker": "v", "open": True},
}
VARIANT_LINES = {
    (): "-",
    ("truncation",): "--",
    ("dt_growth",): ":",
    ("truncation", "dt_growth"): "-.",
    ("scheme",): (0, (6, 2, 1, 2, 1, 2)),
    ("truncation", "scheme"): (0, (10, 3)),
    ("dt_growth", "scheme"): (0, (1, 1)),
    ("truncation", "dt_growth", "scheme"): (0, (10, 2, 2, 2)),
}  # and hollow markers where the scheme differs
VARIANT_NAMES = {"truncation": "kernel truncation", "dt_growth": "Δt growth", "scheme": "scheme"}


def _triple(case: Case) -> tuple:
    return case.method, case.kernel, round(case.eta, 9)


def distinct_models(cases: list[Case]) -> list[Case]:
    """The distinct models of ``cases`` in the order given."""
    return list(dict.fromkeys(c.model for c in cases))


def _auto_styles(count: int, used: list[dict]) -> list[dict]:
    """``count`` styles whose colour and marker no style in ``used`` has (cycling when they run out)."""
    colours = [c for c in AUTO_COLOURS if c not in {s.get("color") for s in used}] or list(AUTO_COLOURS)
    markers = [m for m in AUTO_MARKERS if m not in {s.get("marker") for s in used}] or list(AUTO_MARKERS)
    return [
        {
            "color": colours[k % len(colours)],
            "marker": markers[k % len(markers)],
            "linestyle": AUTO_LINES[k % len(AUTO_LINES)],
        }
        for k in range(count)
    ]


def styles(figure: str, cases: list[Case]) -> dict[Case, dict]:
    """Style of every model of ``cases``: the paper's where it draws the model, else an automatic one."""
    paper, models = PAPER_STYLES.get(figure, {}), distinct_models(cases)
    out = {}
    for triple, style in paper.items():
        matching = [m for m in models if _triple(m) == triple]
        if matching:
            out[min(matching, key=lambda m: len(m.variant()))] = style
    added = [m for m in models if m not in out]
    used = [*paper.values(), *({"color": c} for c in (BLACK, *RESERVED_COLOURS.get(figure, ())))]
    for model, style in zip(added, _auto_styles(len(added), used), strict=True):
        out[model] = {k: v for k, v in style.items() if not (k == "color" and figure in COLOUR_BY_N)}
    return out


def tradeoff_styles(cases: list[Case]) -> dict[Case, dict]:
    """Trade-off styles: family colour and marker, line style by the dimensions varied from the paper."""
    models = distinct_models(cases)
    unknown = list(dict.fromkeys(_triple(m) for m in models if _triple(m) not in TRADEOFF_FAMILY))
    auto = _auto_styles(len(unknown), list(TRADEOFF_FAMILY.values()))
    family = {**TRADEOFF_FAMILY, **dict(zip(unknown, auto, strict=True))}
    out, seen = {}, {}
    for m in models:
        base, keys = family[_triple(m)], tuple(m.variant())
        repeat = seen[_triple(m), keys] = seen.get((_triple(m), keys), -1) + 1
        style = {**base, "linestyle": VARIANT_LINES[keys], **({"open": True} if "scheme" in keys else {})}
        if repeat:  # same family and same varied dimensions, other values: another marker, hollow
            markers = [k for k in AUTO_MARKERS if k != base["marker"]]
            style.update(marker=markers[(repeat - 1) % len(markers)], open=True)
        out[m] = style
    return out


# ---------------------------------------------------------------- series: the data, then the drawing
@dataclass
class Series:
    """One legend entry's points on one panel; ``case`` None for an analytic reference."""

    panel: str
    label: str
    case: Case | None
    x_name: str
    x: np.ndarray
    y_name: str
    y: np.ndarray
    style: dict = field(default_factory=dict)
    kind: str = "line"  # line (with a band where y_std is given), errorbar, scatter, bar or vline
    y_std: np.ndarray | None = None
    y_lo: np.ndarray | None = None
    y_hi: np.ndarray | None = None
    n: object = None  # per-point N where the case is a model; the N an analytic reference depends on
    n_realisations: object = None
    time: object = math.nan
    marked: object = False
    markevery: int = 1
    legend: str | None = None  # legend text where it is not the label

    def __post_init__(self):
        for name in ("x", "y", "y_std", "y_lo", "y_hi"):
            if getattr(self, name) is not None:
                setattr(self, name, np.asarray(getattr(self, name), float))
        for name in ("n", "n_realisations", "time", "marked"):  # per-point values as arrays, not indexed Series
            if isinstance(getattr(self, name), (pd.Series, list, tuple)):
                setattr(self, name, np.asarray(getattr(self, name)))
        if self.y_std is not None:
            self.y_lo = self.y - self.y_std if self.y_lo is None else self.y_lo
            self.y_hi = self.y + self.y_std if self.y_hi is None else self.y_hi

    def table(self, figure: str) -> pd.DataFrame:
        case = self.case.columns() if self.case is not None else REFERENCE_CASE
        n = self.n if self.n is not None else (self.case.n if self.case is not None else None)
        nan = np.full(len(self.x), np.nan)
        cols = {
            "figure": figure,
            "panel": self.panel,
            "series": self.label,
            **{c: case.get(c) for c in CASE_COLUMNS if c != "n"},
            "n": n,
            "x_name": self.x_name,
            "x": self.x,
            "y_name": self.y_name,
            "y": self.y,
            "y_std": nan if self.y_std is None else self.y_std,
            "y_lo": nan if self.y_lo is None else self.y_lo,
            "y_hi": nan if self.y_hi is None else self.y_hi,
            "n_realisations": self.n_realisations,
            "time": self.time,
            "marked": self.marked,
        }
        return pd.DataFrame(cols, index=range(len(self.x)))


def source_table(figure: str, series: list[Series]) -> pd.DataFrame:
    """The tidy source data of a figure: its series' points, columns as in ``SOURCE_COLUMNS``."""
    parts = [s.table(figure) for s in series if len(s.x)]
    df = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(SOURCE_COLUMNS))
    df = df[list(SOURCE_COLUMNS)]
    for col in ("n", "n_realisations"):
        df[col] = pd.to_numeric(df[col], errors="coerce").astype("Int64")
    for col in ("eta", "truncation", "dt_growth", "x", "y", "y_std", "y_lo", "y_hi", "time"):
        df[col] = df[col].astype(float)
    df["marked"] = df["marked"].astype(bool)
    return df


def _line_kw(style: dict) -> dict:
    kw = {
        "linewidth": 1.4,
        "markersize": 4.5,
        "linestyle": "-",
        **{k: v for k, v in style.items() if k not in ("open", "size", "dodge", "width")},
    }
    if style.get("open") and kw.get("marker"):
        kw["markerfacecolor"] = "white"
    return kw


def draw(ax, s: Series, logy: bool = False, dot: float = 8.0) -> None:
    """Draw one series: a line with its +-1 std band, error bars, a scatter (dots of area ``dot``
    x its size) or a vertical line."""
    label = s.legend or s.label
    if s.kind == "vline":
        ax.axvline(s.x[0], label=label, **s.style)
    elif s.kind == "scatter":
        st = s.style
        colour = st.get("color", GREY)
        ax.scatter(
            s.x,
            s.y,
            s=dot * st.get("size", 2),
            marker=st.get("marker", "o"),
            alpha=st.get("alpha", 1.0),
            facecolors="none" if st.get("open") else colour,
            edgecolors=colour,
            linewidths=0.7 if st.get("open") else 0,
            zorder=3 if st.get("open") else 2,
            rasterized=True,
            label=label,
        )
    elif s.kind == "bar":  # on a log x axis: bars as wide as a fraction of their x, dodged by a factor
        st = s.style
        colour = st.get("color", GREY)
        x = s.x * st.get("dodge", 1.0)
        ax.bar(
            x,
            s.y,
            width=x * st.get("width", 0.2),
            color="white" if st.get("open") else colour,
            edgecolor=colour,
            hatch="///" if st.get("open") else None,
            linewidth=0.8,
            label=label,
        )
    elif s.kind == "errorbar":
        lo = np.where(np.isfinite(s.y_lo), s.y_lo, s.y - 3.0)  # -inf (std >= mean SSE): a long lower bar
        kw = {**_line_kw(s.style), "markersize": 5}
        ax.errorbar(s.x * s.style.get("dodge", 1.0), s.y, yerr=[s.y - lo, s.y_hi - s.y], capsize=3, label=label, **kw)
    else:
        (line,) = ax.plot(s.x, s.y, label=label, markevery=s.markevery, **_line_kw(s.style))
        if s.y_std is not None and np.any(s.y_std > 0):
            lo = np.where(s.y_lo > 0, s.y_lo, np.nan) if logy else s.y_lo  # no band below zero on log y
            ax.fill_between(s.x, lo, s.y_hi, color=line.get_color(), alpha=0.2, linewidth=0)


# ---------------------------------------------------------------- tables to series
def by_case(tables: list[pd.DataFrame]) -> dict[Case, pd.DataFrame]:
    """Each non-empty table keyed by the case its columns name."""
    return {case_of_table(df): df for df in tables if len(df)}


def _column(df: pd.DataFrame, name: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Values of ``name`` (``name_mean`` in a summary) and its ensemble std (None in a run table)."""
    if f"{name}_mean" in df.columns:
        return df[f"{name}_mean"].to_numpy(float), df[f"{name}_std"].to_numpy(float)
    return df[name].to_numpy(float), None


def _realisations(df: pd.DataFrame) -> int:
    return int(df["n_realisations"].iloc[0]) if "n_realisations" in df.columns else 1


def curve(
    panel: str,
    case: Case | None,
    df: pd.DataFrame,
    name: str,
    style: dict,
    label: str | None = None,
    logy: bool = False,
    band: bool = True,
    n=None,
) -> Series:
    """``name`` against time for t > 0 and finite values (positive on log y), with its std where drawn."""
    t = df["time"].to_numpy(float)
    y, sd = _column(df, name)
    ok = (t > 0) & np.isfinite(y) & ((y > 0) if logy else True)
    return Series(
        panel,
        label or case.label(),
        case,
        "time",
        t[ok],
        name,
        y[ok],
        style=style,
        y_std=sd[ok] if band and sd is not None else None,
        n=n,
        time=t[ok],
        markevery=8,
        n_realisations=None if case is None else _realisations(df),
    )


def reference(panel: str, label: str, df: pd.DataFrame, name: str, logy: bool = False, n=None) -> Series:
    """An analytic curve from a table column (e.g. H_C_analytic, y_name H_C), dashed black."""
    s = curve(panel, None, df, name, ANALYTIC, label=label, logy=logy, band=False, n=n)
    s.y_name = name.removesuffix("_analytic")
    return s


def panels_by_n(cases: list[Case], descending: bool = False) -> list[tuple[str, int, list[Case]]]:
    """(letter, N, cases at N) for one panel per N."""
    ns = sorted({c.n for c in cases}, reverse=descending)
    return [(letter, n, [c for c in cases if c.n == n]) for letter, n in zip(LETTERS, ns, strict=False)]


# ---------------------------------------------------------------- axes helpers
def save_figure(fig: Figure, png_path, pdf_path) -> None:
    """Write ``fig`` as PNG and PDF (150 dpi, no time stamps or versions: byte-stable) and close it."""
    for path, meta in ((png_path, PNG_META), (pdf_path, PDF_META)):
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=150, metadata=meta)
    import matplotlib.pyplot as plt  # only to release figures a caller made through pyplot

    plt.close(fig)


def new_figure(ncols: int, width: float = 5.2, height: float = 4.0, nrows: int = 1):
    """A constrained-layout figure with a flat list of axes."""
    fig = Figure(figsize=(width * max(ncols, 1), height * nrows), layout="constrained")
    return fig, list(fig.subplots(nrows, max(ncols, 1), squeeze=False).ravel())


def style_axes(
    ax,
    letter: str | None,
    title: str,
    ylabel: str,
    xlabel: str = T_LABEL,
    logx: bool = True,
    logy: bool = False,
    legend: str | None = "best",
) -> None:
    """Shared look: panel letter and title, labels, log axes, light grid, legend."""
    ax.set_title(f"({letter}) {title}" if letter else title, loc="left", fontsize=11)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.grid(True, which="major", color="0.9", linewidth=0.8)
    ax.set_axisbelow(True)
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(loc=legend, fontsize=8, framealpha=0.9)


def mark_no_data(ax, what: str) -> None:
    ax.text(0.5, 0.5, f"no data:\n{what}", transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax.set_xticks([])
    ax.set_yticks([])


def _missing(ax, cases: list[Case], drawn: bool) -> None:
    """Name the cases without a table: the whole panel when nothing else is drawn, else a footnote."""
    if not cases:
        return
    names = "\n".join(c.label() for c in cases)
    if not drawn:
        mark_no_data(ax, names)
    else:
        ax.text(
            0.99, 0.01, f"no data: {names}", transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="0.4"
        )


def _runs(series: list[Series]) -> str:
    """'20 runs' or '2-20 runs' over the case series of a panel."""
    counts = sorted({int(s.n_realisations) for s in series if s.case is not None and s.n_realisations})
    if not counts:
        return "no runs"
    return f"{counts[0]} runs" if len(counts) == 1 else f"{counts[0]}–{counts[-1]} runs"


def n_ticks(ax, ns) -> None:
    """Ticks at the N drawn, labelled 30, 1,000, ... (no crowded minor labels on a log axis)."""
    ns = sorted({int(n) for n in ns})
    ax.set_xticks(ns, [f"{n:,}" for n in ns], fontsize=8)
    ax.xaxis.set_minor_formatter(NullFormatter())


def _colour_by_n(ns) -> dict[int, tuple]:
    ns = sorted(set(ns))
    cmap = matplotlib.colormaps["viridis"]
    return {n: cmap(0.85 * i / max(len(ns) - 1, 1)) for i, n in enumerate(ns)}


# ---------------------------------------------------------------- figures
def fig1(tables, cases, *, D: float, t_final: float):
    """Fig. 1: single-realisation H_C of each case, H (= H_D) of PT and the analytic H_C; one panel per N."""
    found, style, out = by_case(tables), styles("fig1", cases), []
    panels = panels_by_n(cases)
    fig, axes = new_figure(len(panels))
    for ax, (letter, n, at_n) in zip(axes, panels, strict=True):
        have = [c for c in at_n if c in found]
        series = [curve(letter, c, found[c], "H_C", style[c.model], label=f"$H_C$, {c.label()}") for c in have]
        pt = [c for c in have if c.method == "pt"][:1]
        series += [
            curve(
                letter,
                c,
                found[c],
                "H_D",
                {"color": PURPLE, "linestyle": ":", "linewidth": 2.0, "marker": None},
                label=f"$H$ ($H_D$) of PT = ln N, N={n:,}",
            )
            for c in pt
        ]
        if have:
            ref = found[have[0]]
            series.append(reference(letter, f"$H_C$ analytic (Eq. 14), N={n:,}", ref, "H_C_analytic", n=n))
            t_settle = settling_time(float(ref["dV"].iloc[0]), float(ref["D"].iloc[0] if "D" in ref else D))
            if series[0].x.size and t_settle > series[0].x.min():  # only inside the plotted range
                series.append(
                    Series(
                        letter,
                        r"settling time $\Delta V^2/(4\pi e D)$",
                        None,
                        "time",
                        [t_settle],
                        "settling time",
                        [np.nan],
                        kind="vline",
                        n=n,
                        time=t_settle,
                        style={"color": "0.5", "linewidth": 0.8, "linestyle": "-."},
                    )
                )
        for s in series:
            draw(ax, s)
        _missing(ax, [c for c in at_n if c not in found], bool(series))
        if series:
            ax.set_ylim(bottom=max(ax.get_ylim()[0], -3.0))
        style_axes(ax, letter, f"N = {n:,}", "entropy $H$, $H_C$ [nats]", legend="lower right")
        out += series
    return fig, source_table("fig1", out)


def _dilution(figure: str, tables, cases, ensemble: bool):
    """Dilution index E against time (log-log), one panel per N (descending), with the analytic E."""
    found, style, out = by_case(tables), styles(figure, cases), []
    panels = panels_by_n(cases, descending=True)
    fig, axes = new_figure(len(panels))
    for ax, (letter, n, at_n) in zip(axes, panels, strict=True):
        have = [c for c in at_n if c in found]
        series = [curve(letter, c, found[c], "E", style[c.model], logy=True) for c in have]
        if have:
            series.append(reference(letter, r"analytic $\sqrt{4\pi e D t}$", found[have[0]], "E_analytic", logy=True))
        for s in series:
            draw(ax, s, logy=True)
        _missing(ax, [c for c in at_n if c not in found], bool(series))
        title = f"N = {n:,}" + (f" (ensemble mean ± 1 std, {_runs(series)})" if ensemble else "")
        style_axes(ax, letter, title, "dilution index $E$ [L]", logy=True, legend="upper left")
        out += series
    return fig, source_table(figure, out)


def fig2(tables, cases, *, D: float, t_final: float):
    """Fig. 2: single-realisation dilution index E of each case against time (log-log); one panel per N."""
    return _dilution("fig2", tables, cases, ensemble=False)


def fig3(tables, cases, *, D: float, t_final: float):
    """Fig. 3: ensemble-mean H_C against time, every case and N on one axes (hollow markers: smaller N)."""
    found, style, series = by_case(tables), styles("fig3", cases), []
    fig, (ax,) = new_figure(1, width=7.0, height=4.8)
    for i, (_, n, at_n) in enumerate(panels_by_n(cases, descending=True)):
        have = [c for c in at_n if c in found]
        series += [
            curve("", c, found[c], "H_C", {**style[c.model], "open": i > 0 or style[c.model].get("open")}) for c in have
        ]
        if have:
            series.append(reference("", f"analytic $H_C$, N={n:,}", found[have[0]], "H_C_analytic", n=n))
    for s in series:
        draw(ax, s)
    _missing(ax, [c for c in cases if c not in found], bool(series))
    if series:
        ax.set_ylim(bottom=max(ax.get_ylim()[0], -3.0))
    style_axes(ax, None, f"ensemble means ± 1 std, {_runs(series)}", "consistent entropy $H_C$ [nats]", legend="lower right")
    return fig, source_table("fig3", series)


def fig4(tables, cases, *, D: float, t_final: float):
    """Fig. 4: ensemble-mean E against time (log-log), collision-kernel MTPT in grey; one panel per N."""
    return _dilution("fig4", tables, cases, ensemble=True)


def fig5(tables, cases, *, D: float, t_final: float):
    """Fig. 5: ensemble-mean E against time (log-log) for MTPT at eta = 1 and 0.1; one panel per N."""
    return _dilution("fig5", tables, cases, ensemble=True)


def fig6(tables, cases, *, D: float, t_final: float):
    """Fig. 6: ensemble-mean H_PMF = H_D + ln(Omega/N) against time, colour by N, with the analytic H_I(t)."""
    found, style = by_case(tables), styles("fig6", cases)
    have = sorted((c for c in cases if c in found), key=lambda c: c.n)
    colour = _colour_by_n(c.n for c in have)
    series = [curve("", c, found[c], "H_PMF", {**style[c.model], "color": colour[c.n]}, band=False) for c in have]
    if series:
        t = np.unique(np.concatenate([s.x for s in series]))
        h_i = [analytic_h_i(D, x) for x in t]
        series.append(
            Series("", r"analytic $H_I=\ln\sqrt{4\pi D t}+1/2$", None, "time", t, "H_I", h_i, style=ANALYTIC, time=t)
        )
    fig, (ax,) = new_figure(1, width=7.0, height=4.8)
    for s in series:
        draw(ax, s)
    _missing(ax, [c for c in cases if c not in found], bool(series))
    style_axes(
        ax,
        None,
        f"PMF entropy, ensemble means ({_runs(series)})",
        r"$H_{PMF}=H_D+\ln(\Omega/N)$ [nats]",
        legend="upper left",
    )
    return fig, source_table("fig6", series)


def _plume_note(label: str, df: pd.DataFrame, gauss) -> str:
    """Fig. 7 legend text: the label, the mean squared deviation from the analytic profile and the plume variance."""
    x, c, m = (df[k].to_numpy(float) for k in ("x", "c", "mass"))
    mean = np.sum(m * x) / np.sum(m)
    spread = np.sum(m * (x - mean) ** 2) / np.sum(m)
    msd = np.mean((c - gauss(x)) ** 2)
    return f"{label}\n  mean sq. dev. from analytic {msd:.2g} L⁻², plume variance {spread:.2f} L²"


def fig7(tables, cases, *, D: float, t_final: float):
    """Fig. 7: final concentrations at the particles against x and the analytic Gaussian; one panel per N."""
    found, style, out = by_case(tables), styles("fig7", cases), []
    var = 2 * D * t_final
    gauss = lambda x: np.exp(-(x**2) / (2 * var)) / np.sqrt(2 * np.pi * var)
    panels = panels_by_n(cases, descending=True)
    fig, axes = new_figure(len(panels), width=5.6, height=5.2)
    for ax, (letter, n, at_n) in zip(axes, panels, strict=True):
        have = [c for c in at_n if c in found]
        dot = 2 if n >= 10000 else 8  # dense clouds need small dots
        series = []
        for c in have:
            series.append(
                Series(
                    letter,
                    c.label(),
                    c,
                    "x",
                    found[c]["x"],
                    "c",
                    found[c]["c"],
                    kind="scatter",
                    style=style[c.model],
                    n_realisations=1,
                    time=t_final,
                    legend=_plume_note(c.label(), found[c], gauss),
                )
            )
            draw(ax, series[-1], dot=dot)
        if series:
            lo, hi = min(-5.0, *(s.x.min() for s in series)), max(5.0, *(s.x.max() for s in series))
            grid = np.linspace(lo, hi, 801)
            series.append(
                Series(
                    letter,
                    f"analytic Gaussian, variance $2Dt$ = {var:.2f} L²",
                    None,
                    "x",
                    grid,
                    "c",
                    gauss(grid),
                    style=ANALYTIC,
                    time=t_final,
                )
            )
            draw(ax, series[-1])
        _missing(ax, [c for c in at_n if c not in found], bool(series))
        style_axes(
            ax,
            letter,
            f"N = {n:,}, t = {t_final:g}",
            "concentration $c$ [L⁻¹]",
            xlabel="position $x$ [L]",
            logx=False,
            legend=None,
        )
        if series:
            leg = ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=8, frameon=False)
            for handle in leg.legend_handles:  # same legend marker size whatever the dot size
                if hasattr(handle, "set_sizes"):
                    handle.set_sizes([20])
        out += series
    return fig, source_table("fig7", out)


def rows_nearest(df: pd.DataFrame, time: float, column: str = "time") -> pd.DataFrame:
    """Rows at the time nearest ``time``."""
    t = df[column].to_numpy(float)
    return df[t == t[np.argmin(np.abs(t - time))]]


def _fig8_measures(model: Case, multi: bool, style: dict, cases, found) -> list[Series]:
    """Fig. 8c: ln(SSE/N) and COMIC of one model's grids against dx at the step nearest FIG8_TIME."""
    have = sorted((c for c in cases if c.model == model and c in found), key=lambda c: c.n)
    if not have:
        return []
    rows = pd.DataFrame([rows_nearest(found[c], FIG8_TIME).iloc[0] for c in have])
    comic = _column(rows, "COMIC")[0]
    common = dict(
        case=model,
        x_name="dx",
        x=rows["dV"],
        n=[c.n for c in have],
        time=rows["time"],
        n_realisations=[_realisations(found[c]) for c in have],
    )
    prefix = f"{model.label(n=False)}: " if multi else ""
    return [
        Series(
            "c",
            prefix + r"$\ln(SSE/N)$",
            y_name="ln(SSE/N)",
            y=_column(rows, "AIC")[0] / 2,
            style={**style, "color": BLUE, "marker": style.get("marker") or "o"},
            **common,
        ),
        Series(
            "c",
            prefix + "COMIC",
            y_name="COMIC",
            y=comic,
            marked=comic == comic.min(),
            style={**style, "color": VERMILLION, "marker": style.get("marker") or "s"},
            **common,
        ),
    ]


def fig8(tables, cases, *, D: float, t_final: float):
    """Fig. 8: FD fitness, (a) ln(SSE/N) and (b) COMIC against time per grid, (c) both against dx."""
    found, style, models = by_case(tables), styles("fig8", cases), distinct_models(cases)
    have = sorted((c for c in cases if c in found), key=lambda c: (c.n, models.index(c.model)))
    colour, multi, series = _colour_by_n(c.n for c in have), len(models) > 1, []
    for c in have:
        dx = float(found[c]["dV"].iloc[0])
        label = (f"{c.model.label(n=False)}, " if multi else "") + f"Δx = {dx:.2g} (N = {c.n:,})"
        half = found[c].assign(**{"ln(SSE/N)": _column(found[c], "AIC")[0] / 2})
        st = {**style[c.model], "color": colour[c.n]}
        series.append(curve("a", c, half, "ln(SSE/N)", st, label=label, band=False))
        series.append(curve("b", c, found[c], "COMIC", st, label=label, band=False))
    for model in models:
        series += _fig8_measures(model, multi, style[model], cases, found)
    fig, axes = new_figure(3, width=4.6, height=4.0)
    for ax, letter in zip(axes, "abc", strict=True):
        for s in (s for s in series if s.panel == letter):
            draw(ax, s)
        _missing(ax, [c for c in cases if c not in found], any(s.panel == letter for s in series))
    style_axes(axes[0], "a", "log-likelihood", r"$\ln(SSE/N)$ = AIC/2", legend="lower left")
    style_axes(
        axes[1], "b", "computational information criterion", r"COMIC $= 2\ln(SSE/N) - \ln\Delta x$", legend="lower left"
    )
    for s in (s for s in series if s.panel == "c" and s.y_name == "COMIC"):
        k = int(np.argmax(s.marked))
        axes[2].plot(
            s.x[k],
            s.y[k],
            "*",
            color="black",
            markersize=14,
            zorder=6,
            label=f"min COMIC: Δx = {s.x[k]:.2g} (N = {s.n[k]:,})",
        )
    tc = next((s.time[0] for s in series if s.panel == "c"), FIG8_TIME)
    style_axes(
        axes[2],
        "c",
        f"both measures at t = {tc:g}",
        "fitness [nats]",
        xlabel=r"grid spacing $\Delta x$ [L]",
        legend="upper left",
    )
    return fig, source_table("fig8", series)


def _family(case: Case) -> tuple:
    """A Fig. 9 panel: the model without its truncation and scheme (every scheme side by side)."""
    return case.method, case.kernel, round(case.eta, 9), case.dt_growth


def _scheme_text(model: Case) -> str:
    """How a model differs from the paper's equations, for a Fig. 9 legend."""
    return ", ".join(model.variant_parts()) or "paper's equations (whole Gaussian)"


def _fig9_panel(letter: str, model: Case, g: pd.DataFrame, style: dict, dodge: float) -> list[Series]:
    """Fig. 9 series of one model: mean COMIC +-1 std, and the COMIC of the mean SSE (dotted)."""
    n, mu, sd = (g[k].to_numpy(float) for k in ("n", "COMIC_mean", "COMIC_std"))
    common = dict(
        case=model,
        x_name="N",
        x=n,
        n=g["n"].to_numpy(int),
        time=g["time_step"].to_numpy(float),
        n_realisations=g["n_realisations"].to_numpy(int),
    )
    line = "--" if style.get("linestyle") == ":" else style.get("linestyle", "-")  # dotted: the mean-SSE series
    name, short = model.label(n=False), _scheme_text(model)
    return [
        Series(
            letter,
            f"{name}: mean COMIC",
            legend=f"{short}: mean ± 1 std",
            y_name="COMIC",
            y=mu,
            y_std=sd,
            kind="errorbar",
            marked=mu == mu.min(),
            style={**style, "linestyle": line, "zorder": 3, "dodge": dodge},
            **common,
        ),
        Series(
            letter,
            f"{name}: COMIC of ensemble-mean SSE",
            legend=f"{short}: COMIC of mean SSE",
            y_name="COMIC of mean SSE",
            y=g["COMIC_of_mean_SSE"],
            y_lo=g["COMIC_of_mean_SSE_lo"].to_numpy(float),
            y_hi=g["COMIC_of_mean_SSE_hi"].to_numpy(float),
            kind="errorbar",
            style={**style, "open": True, "linestyle": ":", "alpha": 0.7, "zorder": 2, "dodge": dodge * 1.04},
            **common,
        ),
    ]


def _argmin_series(letter: str, model: Case, shares: pd.DataFrame, style: dict, dodge: float, width: float):
    """How often each N is the argmin of mean COMIC when realisations are resampled (bars)."""
    g = shares.sort_values("n")
    return Series(
        letter,
        f"{model.label(n=False)}: argmin share",
        legend=_scheme_text(model),
        case=model,
        x_name="N",
        x=g["n"].to_numpy(float),
        n=g["n"].to_numpy(int),
        y_name="share of resamples with this argmin",
        y=g["share"].to_numpy(float),
        n_realisations=g["n_realisations"].to_numpy(int),
        time=g["time"].to_numpy(float),
        marked=g["share"].to_numpy(float) == g["share"].max(),
        kind="bar",
        style={"color": style.get("color", GREY), "dodge": dodge, "width": width, "open": style.get("open", False)},
    )


def _minimum_text(row: pd.Series) -> str:
    """'N_opt 3,000, 95% CI 1,000-3,000 (81%)' from a comic_minima row."""
    if row["n_resamples"] <= 0:
        return f"N_opt {int(row['n_opt']):,} (no resampling)"
    lo, hi = int(row["n_opt_ci_lo"]), int(row["n_opt_ci_hi"])
    ci = f"{lo:,}" if lo == hi else f"{lo:,}–{hi:,}"
    return f"N_opt {int(row['n_opt']):,}, 95% CI {ci} ({row['n_opt_share']:.0%})"


def fig9(tables, cases, *, D: float, t_final: float):
    """Fig. 9: ensemble COMIC +-1 std against N at the time nearest t_final, one panel per kernel
    and eta with every scheme side by side, minima starred; below each, how often each N is the
    argmin when the realisations are resampled (bootstrap), with the minimum's 95% interval."""
    empty = pd.DataFrame()
    comic, minima, argmin = (list(tables) + [empty] * 3)[:3]
    style, models = styles("fig9", cases), distinct_models(cases)
    families = list(dict.fromkeys(_family(m) for m in models))
    ncols = min(max(len(families), 1), 3)
    rows = max(math.ceil(len(families) / 3), 1)
    fig = Figure(figsize=(5.0 * ncols, 6.2 * rows), layout="constrained")
    grid = fig.subplots(2 * rows, ncols, squeeze=False, gridspec_kw={"height_ratios": [3.0, 1.2] * rows})
    tops = [grid[2 * (k // ncols), k % ncols] for k in range(rows * ncols)]
    bottoms = [grid[2 * (k // ncols) + 1, k % ncols] for k in range(rows * ncols)]
    out, letters = [], iter(LETTERS)
    for family, ax, bar_ax in zip(families, tops, bottoms, strict=False):
        letter, bar_letter = next(letters), None
        mine = [m for m in models if _family(m) == family]
        title = Case(family[0], family[1], eta=family[2], dt_growth=family[3]).label(n=False)
        drawn, notes = [], []
        for k, model in enumerate(mine):
            g = pd.concat([rows_of(comic, c) for c in cases if c.model == model]) if len(comic) else empty
            _missing(ax, [c for c in cases if c.model == model and (g.empty or c.n not in set(g["n"]))], drawn=True)
            if g.empty:
                continue
            g = rows_nearest(g, t_final).sort_values("n")
            dodge = 1.0 + 0.1 * (k - (len(mine) - 1) / 2)
            series = _fig9_panel(letter, model, g, style[model], dodge)
            for s in series:
                draw(ax, s)
            mean = series[0]
            kmin = int(np.argmax(mean.marked))
            ax.plot(
                mean.x[kmin] * dodge,
                mean.y[kmin],
                "*",
                color=style[model].get("color", "black"),
                markeredgecolor="black",
                markersize=15,
                zorder=6,
            )
            for ni, top, r in zip(mean.x, mean.y_hi, mean.n_realisations, strict=True):
                ax.annotate(
                    f"{int(r)}",
                    (ni * dodge, top),
                    textcoords="offset points",
                    xytext=(0, 3),
                    ha="center",
                    fontsize=7,
                    color=style[model].get("color", "0.35"),
                )
            out += series
            drawn.append(mean)
            time = float(g["time"].iloc[0])
            mrow = rows_of(minima, model) if len(minima) else empty
            mrow = mrow[mrow["time"] == time] if len(mrow) else mrow
            if len(mrow):
                notes.append((_minimum_text(mrow.iloc[0]), style[model].get("color", "black")))
            shares = rows_of(argmin, model) if len(argmin) else empty
            if len(shares):
                shares = shares[(shares["time"] == time) & (shares["convention"] == "mean_COMIC")]
            if len(shares):
                bar_letter = bar_letter or next(letters)
                width = 0.8 / max(len(mine), 1)
                bar = _argmin_series(
                    bar_letter, model, shares, style[model], 1.0 + width * 0.3 * (k - (len(mine) - 1) / 2), width * 0.3
                )
                draw(bar_ax, bar)
                out.append(bar)
        if not drawn:
            style_axes(ax, letter, title, "COMIC", xlabel="number of particles $N$", legend=None)
            mark_no_data(ax, title)
            bar_ax.set_visible(False)
            continue
        ax.plot([], [], "*", color="0.5", markeredgecolor="black", markersize=11, label="minimum of mean COMIC")
        ax.plot([], [], " ", label="numbers: realisations")
        ax.margins(x=0.08, y=0.12)
        style_axes(
            ax,
            letter,
            f"{title}, t = {drawn[0].time[0]:g}",
            r"COMIC $= 2\ln(SSE/N) - \ln\Delta V$",
            xlabel="",
            legend=None,
        )
        n_ticks(ax, np.concatenate([s.x for s in drawn]))
        ax.legend(loc="best", fontsize=7)
        if bar_letter is None:
            bar_ax.set_visible(False)
            continue
        style_axes(
            bar_ax,
            bar_letter,
            "argmin over N, realisations resampled",
            "share of resamples",
            xlabel="number of particles $N$",
            legend=None,
        )
        bar_ax.set_xlim(ax.get_xlim())
        bar_ax.set_ylim(0, 1.35)
        n_ticks(bar_ax, np.concatenate([s.x for s in drawn]))
        for j, (text, colour) in enumerate(notes):
            bar_ax.text(
                0.02, 0.95 - 0.16 * j, text, transform=bar_ax.transAxes, ha="left", va="top", fontsize=7, color=colour
            )
    for ax, bar_ax in list(zip(tops, bottoms, strict=True))[len(families) :]:
        ax.set_visible(False)
        bar_ax.set_visible(False)
    return fig, source_table("fig9", out)


def _tradeoff_series(at: pd.DataFrame, letters: tuple[str, str], cases, style) -> list[Series]:
    """Trade-off series at one time: RMSE against wall time (left) and N (right) of each model."""
    out = []
    for model in distinct_models(cases):
        g = pd.concat([rows_of(at, c) for c in cases if c.model == model]).sort_values("n")
        g = g[np.isfinite(g["rmse"]) & np.isfinite(g["wall_s"]) & (g["rmse"] > 0) & (g["wall_s"] > 0)]
        common = dict(
            case=model,
            y_name="rmse",
            y=g["rmse"],
            n=g["n"].to_numpy(int),
            time=g["time"].to_numpy(float),
            n_realisations=g["n_realisations"].to_numpy(int),
            style=style[model],
            marked=g["is_comic_optimum"].to_numpy(bool),
        )
        out += [
            Series(letters[0], model.label(n=False), x_name="wall_s", x=g["wall_s"], **common),
            Series(letters[1], model.label(n=False), x_name="N", x=g["n"], **common),
        ]
    return out


def _one_two_five(axis) -> None:
    """Log axis labelled at 1, 2, 5 x 10^k in plain numbers, minor ticks unlabelled."""
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _tradeoff_axes(ax, letter: str, time: float, xlabel: str) -> None:
    style_axes(ax, letter, f"t = {time:g}", "concentration RMSE sqrt(SSE/n) [1/L]", xlabel=xlabel, logy=True, legend=None)
    # labelled 1-2-5 error levels with light horizontal lines: read off the cheapest model per error
    _one_two_five(ax.yaxis)
    ax.grid(True, which="minor", axis="y", color="0.95", linewidth=0.6)


def _variant_text(keys: tuple) -> str:
    return "paper settings" if not keys else "differs in " + " and ".join(VARIANT_NAMES[k] for k in keys)


def tradeoff(tables, cases, *, D: float, t_final: float):
    """Speed-accuracy trade-off: RMSE against wall time and N per model and time, COMIC optimum starred."""
    table = tables[0] if tables else pd.DataFrame()
    style = tradeoff_styles(cases)
    rows = pd.concat([rows_of(table, c) for c in cases]) if len(table) else table
    times = sorted(rows["time"].unique()) if len(rows) else []
    fig = Figure(figsize=(11.5, 4.3 * max(len(times), 1)), layout="constrained")
    axes = fig.subplots(max(len(times), 1), 2, squeeze=False)
    xlabels = ("wall time per realisation [s]", "number of particles or FD intervals N")
    if not times:
        for ax, xlabel in zip(axes[0], xlabels, strict=True):
            style_axes(ax, None, "speed-accuracy trade-off", "RMSE", xlabel=xlabel, logx=False, legend=None)
            mark_no_data(ax, "trade-off table rows of these cases")
        return fig, source_table("tradeoff", [])
    series, handles = [], {}
    for i, (row, time) in enumerate(zip(axes, times, strict=True)):
        at = _tradeoff_series(rows[rows["time"] == time], tuple(LETTERS[2 * i : 2 * i + 2]), cases, style)
        for s in at:
            if not len(s.x):
                continue
            ax = row[0] if s.x_name == "wall_s" else row[1]
            draw(ax, s)
            handles.setdefault(s.label, ax.get_lines()[-1])
            star = s.marked
            ax.plot(
                s.x[star],
                s.y[star],
                "*",
                color=s.style["color"],
                markeredgecolor="black",
                markeredgewidth=0.8,
                markersize=13,
                zorder=6,
            )
        series += at
        row[1].sharey(row[0])  # one error scale per row: read across at a target error
        for ax, letter, xlabel in zip(row, LETTERS[2 * i : 2 * i + 2], xlabels, strict=True):
            _tradeoff_axes(ax, letter, time, xlabel)
        row[1].set_ylabel("")
        _one_two_five(row[0].xaxis)
        n_ticks(row[1], [n for s in at for n in np.atleast_1d(s.n)])
    star = Line2D(
        [],
        [],
        linestyle="none",
        marker="*",
        markersize=13,
        color="white",
        markeredgecolor="black",
        markeredgewidth=0.8,
        label="COMIC optimum (lowest mean COMIC)",
    )
    keys = dict.fromkeys(tuple(m.variant()) for m in distinct_models(cases))
    key = [
        Line2D(
            [],
            [],
            color="0.3",
            linestyle=VARIANT_LINES[k],
            marker="o" if "scheme" in k else None,
            markerfacecolor="white",
            label=_variant_text(k),
        )
        for k in keys
    ]
    fig.legend(
        handles=[*handles.values(), star, *key], loc="outside right center", fontsize=8, frameon=False, handlelength=3.0
    )
    return fig, source_table("tradeoff", series)


FIGURES = {
    "fig1": fig1,
    "fig2": fig2,
    "fig3": fig3,
    "fig4": fig4,
    "fig5": fig5,
    "fig6": fig6,
    "fig7": fig7,
    "fig8": fig8,
    "fig9": fig9,
    "tradeoff": tradeoff,
}
