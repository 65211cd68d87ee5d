"""The one identity of a simulated model: a ``Case`` builds its path and its table columns, and
is rebuilt from a config spec, from wildcards or from a table row (its legend text: labels.py).

A case is every dimension a user may sweep: method, kernel, N, eta, truncation, dt growth,
scheme and time grid. With ``n=None`` it is a *model* (the same case at every N), the key COMIC tables,
minima and figure panels group by. Dimensions that do not apply to a method hold a neutral
value (FD: eta 1, whole kernel, fixed step, symmetric, exact grid; PT: eta 1, whole kernel,
symmetric),
and a config that sets them otherwise is refused.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

from .registry import KERNELS, METHODS, PRESETS, SCHEME_RECORDS, SCHEMES, TIME_GRIDS
from .run_settings import BY_NAME, PAPER

N_MIN = 2  # one particle (or one FD interval) is a delta against itself: SSE 0, COMIC -inf

# Case field -> (wildcard name, path segment); the path of a case is these segments in order.
PATH_SEGMENTS = {
    "method": ("method", "{}"),
    "kernel": ("kernel", "{}"),
    "n": ("n", "n~{}"),
    "eta": ("eta", "eta~{}"),
    "truncation": ("trunc", "trunc~{}"),
    "dt_growth": ("growth", "growth~{}"),
    "scheme": ("scheme", "scheme~{}"),
    "time_grid": ("grid", "grid~{}"),
}
CASE_DIR = "/".join(seg.format("{" + w + "}") for w, seg in PATH_SEGMENTS.values())
MODEL_COLUMNS = ("method", "kernel", "eta", "truncation", "dt_growth", "scheme", "time_grid")
CASE_COLUMNS = ("method", "kernel", "n", "eta", "truncation", "dt_growth", "scheme", "time_grid")
# Which dimensions apply to which method; the others hold NEUTRAL values.
APPLIES = {
    "eta": ("mtpt",),
    "truncation": ("mtpt",),
    "dt_growth": ("pt", "mtpt"),
    "scheme": ("mtpt",),
    "time_grid": ("pt", "mtpt"),  # FD steps always end at t_final
}
NEUTRAL = {"eta": 1.0, "truncation": None, "dt_growth": 1.0, "scheme": "symmetric", "time_grid": "exact"}
DEFAULT = type("Default", (), {"__repr__": lambda self: "DEFAULT"})()  # an unset dimension


class SettingError(ValueError):
    """A setting outside its allowed range; the message names setting, value and range."""

    def __init__(self, name: str, value, allowed: str):
        super().__init__(f"{name}={value!r} is not allowed: {allowed}")
        self.name, self.value, self.allowed = name, value, allowed


def check_range(name, value, lo, hi, open_low=False) -> float:
    """``value`` as a float; SettingError unless it is a finite number with lo <(=) value <= hi."""
    is_number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    v = float(value) if is_number else math.nan
    if not math.isfinite(v) or (v <= lo if open_low else v < lo) or v > hi:
        low = f"> {lo}" if open_low else f">= {lo}"
        high = "finite" if hi == math.inf else f"<= {hi}"
        raise SettingError(name, value, f"a number {low} and {high}")
    return v


NONE = "none"  # None as configs, paths and options write it (truncation: the whole Gaussian)


def from_text(value):
    """The inverse of ``text`` for the word none: 'none' -> None, any other value unchanged."""
    return None if isinstance(value, str) and value.lower() == NONE else value


def text(value) -> str:
    """A value as it appears in a path: 1.0 -> '1', 0.5 -> '0.5', None -> 'none'."""
    if value is None:
        return NONE
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


@dataclass(frozen=True)
class Case:
    """One simulated model at one N (``n=None``: the model at every N)."""

    method: str
    kernel: str
    n: int | None = None
    eta: float = DEFAULT  # DEFAULT: the paper's value where it applies, else the neutral one
    truncation: float | None = DEFAULT
    dt_growth: float = DEFAULT
    scheme: str = DEFAULT
    time_grid: str = DEFAULT

    def __post_init__(self):
        if self.method not in METHODS:
            raise SettingError("method", self.method, f"one of {', '.join(METHODS)}")
        for dim, methods in APPLIES.items():
            if getattr(self, dim) is DEFAULT:
                object.__setattr__(self, dim, PAPER[dim] if self.method in methods else NEUTRAL[dim])
        if self.kernel not in KERNELS[self.method]:
            raise SettingError(
                "kernel", self.kernel, f"for method {self.method}: one of {', '.join(KERNELS[self.method])}"
            )
        if self.n is not None:
            integral = isinstance(self.n, (int, np.integer)) or (isinstance(self.n, float) and self.n.is_integer())
            if isinstance(self.n, bool) or not integral or self.n < N_MIN:
                raise SettingError("n", self.n, f"an integer >= {N_MIN} (one particle scores a perfect COMIC -inf)")
            object.__setattr__(self, "n", int(self.n))
        for dim in ("eta", "truncation", "dt_growth"):  # ranges from their settings (settings.SETTINGS)
            s = BY_NAME[dim]
            if getattr(self, dim) is not None:
                object.__setattr__(self, dim, check_range(dim, getattr(self, dim), s.low, s.high, s.open_low))
        if self.scheme not in SCHEMES:
            raise SettingError("scheme", self.scheme, f"one of {', '.join(SCHEMES)}")
        if SCHEME_RECORDS[self.scheme].compensated and self.truncation is None:
            raise SettingError("scheme", self.scheme, "needs a truncation (a number of kernel widths), not none")
        if self.time_grid not in TIME_GRIDS:
            raise SettingError("time_grid", self.time_grid, f"one of {', '.join(TIME_GRIDS)}")
        for dim, methods in APPLIES.items():
            if self.method not in methods and getattr(self, dim) != NEUTRAL[dim]:
                raise SettingError(
                    dim,
                    getattr(self, dim),
                    f"{dim} applies to method {' and '.join(methods)} only "
                    f"(method {self.method} takes {text(NEUTRAL[dim])})",
                )

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_spec(cls, spec: Mapping, n: int | None = None, defaults: Mapping | None = None) -> Case:
        """A config case ``{method, kernel, preset?, eta?, truncation?, dt_growth?, scheme?,
        time_grid?}`` at ``n``: a dimension it sets, else its preset's (registry.PRESETS), else
        ``defaults`` (config case_defaults), else the paper's."""
        unknown = set(spec) - {"method", "kernel", "preset", *APPLIES}
        if unknown:
            raise SettingError("case key", sorted(unknown)[0], f"one of method, kernel, preset, {', '.join(APPLIES)}")
        method = spec.get("method")
        if method not in METHODS:
            raise SettingError("method", method, f"one of {', '.join(METHODS)}")
        preset = {}
        if "preset" in spec:
            if spec["preset"] not in PRESETS:
                raise SettingError("preset", spec["preset"], f"one of {', '.join(PRESETS)}")
            if method != "mtpt":
                raise SettingError("preset", spec["preset"], "a preset of mtpt cases (the authors' algorithm)")
            preset = PRESETS[spec["preset"]]
        merged = {**{k: PAPER[k] for k in APPLIES}, **(defaults or {}), **preset}
        dims = {}
        for dim, methods in APPLIES.items():
            if dim in spec:
                value = spec[dim]
            else:
                value = merged[dim] if method in methods else NEUTRAL[dim]
            dims[dim] = from_text(value)
        return cls(method=method, kernel=spec.get("kernel"), n=n, **dims)

    @classmethod
    def from_wildcards(cls, w: Mapping) -> Case:
        """The case named by path wildcards (inverse of ``wildcards``)."""
        return cls(
            method=w["method"],
            kernel=w["kernel"],
            n=int(w["n"]) if "n" in w.keys() else None,
            eta=float(w["eta"]),
            truncation=None if from_text(w["trunc"]) is None else float(w["trunc"]),
            dt_growth=float(w["growth"]),
            scheme=w["scheme"],
            time_grid=w["grid"],
        )

    @classmethod
    def from_row(cls, row: Mapping) -> Case:
        """The case of a table row (inverse of ``columns``); without an ``n`` column, a model."""
        trunc = float(row["truncation"])
        n = row["n"] if "n" in row.keys() else None
        return cls(
            method=str(row["method"]),
            kernel=str(row["kernel"]),
            n=None if n is None else int(n),
            eta=float(row["eta"]),
            truncation=None if math.isinf(trunc) else trunc,
            dt_growth=float(row["dt_growth"]),
            scheme=str(row["scheme"]),
            time_grid=str(row["time_grid"]),
        )

    # ------------------------------------------------------------------ representations
    def wildcards(self) -> dict[str, str]:
        """Path text of every dimension, keyed by wildcard name."""
        if self.n is None:
            raise SettingError("n", None, f"an integer: {self} is a model, which has no path")
        return {w: text(getattr(self, f)) for f, (w, _) in PATH_SEGMENTS.items()}

    def path(self) -> str:
        """Folder of this case's files: method/kernel/n~N/eta~E/trunc~T/growth~G/scheme~S/grid~R."""
        return CASE_DIR.format(**self.wildcards())

    def columns(self) -> dict:
        """Typed table columns (truncation: inf for the whole kernel; a model has no n)."""
        cols = {
            "method": self.method,
            "kernel": self.kernel,
            "n": self.n,
            "eta": self.eta,
            "truncation": math.inf if self.truncation is None else self.truncation,
            "dt_growth": self.dt_growth,
            "scheme": self.scheme,
            "time_grid": self.time_grid,
        }
        if self.n is None:
            del cols["n"]
        return cols

    @property
    def model(self) -> Case:
        """The same case at every N."""
        return replace(self, n=None)

    def at(self, n: int) -> Case:
        return replace(self, n=n)

    def variant(self) -> dict:
        """Dimensions that differ from the paper's defaults for this method."""
        out = {}
        for dim in ("truncation", "dt_growth", "scheme", "time_grid"):
            if self.method in APPLIES[dim] and getattr(self, dim) != PAPER[dim]:
                out[dim] = getattr(self, dim)
        return out

    def sort_key(self) -> tuple:
        return (
            METHODS.index(self.method),
            KERNELS[self.method].index(self.kernel),
            -self.eta,
            len(self.variant()),
            math.inf if self.truncation is None else self.truncation,
            self.dt_growth,
            SCHEMES.index(self.scheme),
            TIME_GRIDS.index(self.time_grid),
            self.n or 0,
        )


# ---------------------------------------------------------------------- tables of cases
def case_mask(df: pd.DataFrame, case: Case) -> pd.Series:
    """Rows of ``df`` belonging to ``case`` (a model matches every N)."""
    import pandas as pd  # only tables need it: a simulation job never imports pandas

    mask = pd.Series(True, index=df.index)
    for col, value in case.columns().items():
        mask &= df[col] == value
    return mask


def rows_of(df: pd.DataFrame, case: Case) -> pd.DataFrame:
    return df[case_mask(df, case)]


def models_in(df: pd.DataFrame) -> list[Case]:
    """The distinct models of a table, in the registry's order."""
    keys = df[list(MODEL_COLUMNS)].drop_duplicates()
    return sorted((Case.from_row(r) for _, r in keys.iterrows()), key=Case.sort_key)


def by_model(df: pd.DataFrame) -> Iterator[tuple[Case, pd.DataFrame]]:
    """(model, its rows) for every model of a table."""
    for model in models_in(df):
        yield model, rows_of(df, model)


def case_of_table(df: pd.DataFrame) -> Case:
    """The one case of a run table or case summary."""
    return Case.from_row(df.iloc[0])
