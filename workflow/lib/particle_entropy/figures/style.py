"""The figures' shared toolkit: palette, styles, ``Series``, drawing, axes and byte-stable saving.

A figure function ``fig(tables, cases, D=..., t_final=...)`` (one module per figure family,
``FIGURES`` in ``figures/__init__.py``) builds its ``Series`` first and draws them, so the
tidy table ``source_table`` returns (columns in ``SOURCE_COLUMNS``) is what is on the page;
``save_figure`` writes byte-stable PNG and PDF.

Styles: a figure module's ``PAPER_STYLES`` maps the (method, kernel, eta) triples the paper draws
to their look (matplotlib line keywords plus "open" for hollow markers and, for fig7's dots,
"size", x the panel's dot area, and "alpha"). Of the models matching a triple, the one closest to
the paper's settings (fewest ``Case.variant()`` dimensions; the first listed on ties) takes the
paper's style; every other model takes an automatic style (``auto_styles``): an Okabe-Ito colour
the figure's paper styles do not use, a marker they do not use and a dashed or dotted line
(where colour stands for N, fig6 and fig8, added models differ by line style and marker only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.ticker import NullFormatter

from ..core.case import CASE_COLUMNS, Case, case_of_table
from ..core.columns import CASE_COLUMN_DOCS
from ..core.labels import case_label

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
PNG_META = {"Software": None}
PDF_META = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}

SOURCE_COLUMNS = {
    "figure": "figure name: `fig1` ... `fig9`, `tradeoff` or `fig9_mechanism`",
    "panel": "panel letter as printed (empty for a one-panel figure)",
    "series": "series name, unique within a panel: its legend label, except in fig7 (the legend adds a line of "
    "statistics) and fig9 (the model's label, which is the panel title, then the quantity)",
    **{c: f"case of the point: {CASE_COLUMN_DOCS[c]}" for c in CASE_COLUMNS},
    "x_name": "quantity on the x axis, which gives `x` its unit: `time` [T], `x` (position) [L], `dx` [L], "
    "`wall_s` [s], `N` (particles; FD intervals; no unit)",
    "x": "its value [per `x_name`]",
    "y_name": "quantity on the y axis, which gives `y` its unit: `H_C`, `H_D`, `H_I`, `H_PMF` [nats], `E` [L], `c` "
    "[1/L], `rmse` [1/L], `SSE/N` [1/L²]; no unit for `ln(SSE/N)`, `COMIC`, `COMIC of mean SSE`, `paired COMIC "
    "difference` and `share of resamples with this argmin`",
    "y": "its value (the ensemble mean where the figure draws a summary) [per `y_name`]",
    "y_std": "ensemble standard deviation drawn as a ±1 std band or error bar; NaN where none is drawn [per `y_name`]",
    "y_lo": "lower end of the drawn band or error bar (y - y_std, or as listed per figure, e.g. fig9's COMIC of "
    "SSE_mean - SSE_std, -inf when that SSE is <= 0); NaN where none is drawn [per `y_name`]",
    "y_hi": "upper end of the drawn band or error bar; NaN where none is drawn [per `y_name`]",
    "n_realisations": "realisations behind the point (1: a single run); missing for analytic references",
    "time": "time of the point: x itself when x is time; else the recorded step drawn (fig8c, fig9's top panels, "
    "fig9_mechanism a and b), the requested COMIC or trade-off time (fig9's bars, fig9_mechanism c, tradeoff) or "
    "t_final (fig7) [T]",
    "marked": "the point is starred: least mean COMIC over N (fig8c, fig9, fig9_mechanism a), the COMIC optimum "
    "(tradeoff), the most frequent argmin (fig9's bars)",
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
# the looks of the paper's models, shared by the figures that draw them
BINS = {"color": ORANGE, "marker": "s"}
FIXED = {"color": SKY, "marker": "^"}
ADAPTIVE = {"color": BLUE, "marker": "o"}
COLLISION = {"color": GREEN, "marker": "D"}
SPH = {"color": VERMILLION, "marker": "D"}
ETA_01 = {"linestyle": "-.", "open": True}
PT_MTPT = {("pt", "bins", 1.0): BINS, ("pt", "fixed", 1.0): FIXED, ("mtpt", "collision", 1.0): COLLISION}


def model_triple(case: Case) -> tuple:
    """The key of ``PAPER_STYLES``: (method, kernel, eta rounded)."""
    return case.method, case.kernel, round(case.eta, 9)


def distinct_models(cases: list[Case]) -> list[Case]:
    """The distinct models of ``cases`` in the order given."""
    return list(dict.fromkeys(c.model for c in cases))


def auto_styles(count: int, used: list[dict]) -> list[dict]:
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


def styles(cases: list[Case], paper: dict, reserved: tuple = (), colour_is_n: bool = False) -> dict[Case, dict]:
    """Style of every model of ``cases``: the paper's (``paper``, a figure's ``PAPER_STYLES``) where it
    draws the model, else an automatic one whose colour is none of ``paper``'s, black or ``reserved``
    (the colours of the figure's other series); no automatic colour where ``colour_is_n``."""
    models = distinct_models(cases)
    out = {}
    for triple, style in paper.items():
        matching = [m for m in models if model_triple(m) == triple]
        if matching:
            out[min(matching, key=lambda m: len(m.variant()))] = style
    added = [m for m in models if m not in out]
    used = [*paper.values(), *({"color": c} for c in (BLACK, *reserved))]
    for model, style in zip(added, auto_styles(len(added), used), strict=True):
        out[model] = {k: v for k, v in style.items() if not (k == "color" and colour_is_n)}
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


def mean_and_std(df: pd.DataFrame, name: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Values of ``name`` (``name_mean`` in a summary) and its ensemble std (None in a run table)."""
    if f"{name}_mean" in df.columns:
        return df[f"{name}_mean"].to_numpy(float), df[f"{name}_std"].to_numpy(float)
    return df[name].to_numpy(float), None


def realisations_of(df: pd.DataFrame) -> int:
    """Realisations behind a table (1: a single run)."""
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
    y, sd = mean_and_std(df, name)
    ok = (t > 0) & np.isfinite(y) & ((y > 0) if logy else True)
    return Series(
        panel,
        label or case_label(case),
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
        n_realisations=None if case is None else realisations_of(df),
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


def rows_nearest(df: pd.DataFrame, time: float, column: str = "time") -> pd.DataFrame:
    """Rows at the time nearest ``time``."""
    t = df[column].to_numpy(float)
    return df[t == t[np.argmin(np.abs(t - time))]]


# ---------------------------------------------------------------- axes helpers
def save_figure(fig: Figure, png_path, pdf_path) -> None:
    """Write ``fig`` as PNG and PDF (150 dpi, no time stamps or versions: byte-stable) and close it."""
    fit_titles(fig)
    for path, meta in ((png_path, PNG_META), (pdf_path, PDF_META)):
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=150, metadata=meta)
    import matplotlib.pyplot as plt  # only to release figures a caller made through pyplot

    plt.close(fig)


MIN_TITLE_SIZE = 7.0  # points: a title shrinks no further, once wrapped


def _titles(ax) -> list:
    """The title texts of ``ax`` that hold text (left, centre, right)."""
    texts = [getattr(ax, "_left_title", None), ax.title, getattr(ax, "_right_title", None)]
    return [t for t in texts if t is not None and t.get_text()]


def _overhang(title, ax, renderer) -> float:
    """How far (pixels) a drawn title reaches past its axes' or the figure's sides; 0 if inside."""
    box, room, page = title.get_window_extent(renderer), ax.get_window_extent(renderer), ax.figure.bbox
    left, right = max(room.x0, page.x0), min(room.x1, page.x1)
    return max(0.0, left - box.x0, box.x1 - right)


def fit_titles(fig: Figure, rounds: int = 4) -> None:
    """Make every panel title fit its panel, measured on the drawn text: a title wider than its
    axes is wrapped at its commas or spaces (as many lines as its width needs), then shrunk down to
    MIN_TITLE_SIZE points; the figure is drawn again after each change (constrained layout moves
    the axes)."""
    import textwrap

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    for _ in range(rounds):
        fig.canvas.draw()
        renderer, changed = fig.canvas.get_renderer(), False
        for ax in fig.axes:
            if not ax.get_visible():
                continue
            for title in _titles(ax):
                box = title.get_window_extent(renderer)
                over = _overhang(title, ax, renderer)
                if over <= 0.5:
                    continue
                text = " ".join(title.get_text().split("\n"))
                share = max((box.width - over) / box.width, 0.1)
                lines = max(max(len(line) for line in title.get_text().split("\n")), 1)
                width = max(int(lines * share) - 1, 8)
                wrapped = textwrap.fill(text, width=width, break_long_words=False)
                if wrapped != title.get_text():
                    title.set_text(wrapped)
                elif title.get_fontsize() > MIN_TITLE_SIZE:
                    title.set_fontsize(max(title.get_fontsize() * max(share, 0.8), MIN_TITLE_SIZE))
                else:
                    continue
                changed = True
        if not changed:
            return


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
    """An empty panel that says what it lacks."""
    ax.text(0.5, 0.5, f"no data:\n{what}", transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax.set_xticks([])
    ax.set_yticks([])


def mark_missing(ax, cases: list[Case], drawn: bool) -> None:
    """Name the cases without a table: the whole panel when nothing else is drawn, else a footnote."""
    if not cases:
        return
    names = "\n".join(case_label(c) for c in cases)
    if not drawn:
        mark_no_data(ax, names)
    else:
        ax.text(
            0.99, 0.01, f"no data: {names}", transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="0.4"
        )


def runs_text(series: list[Series]) -> str:
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


def colours_by_n(ns) -> dict[int, tuple]:
    """A viridis colour per N, dark to light as N grows (where colour stands for N)."""
    ns = sorted(set(ns))
    cmap = matplotlib.colormaps["viridis"]
    return {n: cmap(0.85 * i / max(len(ns) - 1, 1)) for i, n in enumerate(ns)}
