"""Legend text of cases, kernels and schemes: presentation only, so no simulation hashes it.

Tables that carry a ``label`` column (summaries, COMIC tables, minima) and the figures import
this module; a simulation job does not (a test in tests/test_workflow.py holds that), so editing a label
redraws figures and rebuilds those tables but reruns no simulation.
"""

from __future__ import annotations

from .case import Case
from .registry import AUTHORS_SPH_CONSTANT, PRESETS

KERNEL_NAMES = {
    "bins": "binned",
    "fixed": "fixed kernel",
    "adaptive": "adaptive kernel",
    "collision": "collision",
    "sph": "SPH",
    "implicit": "implicit",
    "explicit": "explicit",
}
SCHEME_LABELS = {  # legend text of a non-default scheme (registry.SCHEME_RECORDS)
    "sequential": "sequential loop",
    "compensated": "compensated width",
    "sequential_sorted": "sequential loop in position order",
    "sequential_symnorm": "sequential loop, symmetric weights",
    "sequential_noclip": "sequential loop, no clipping",
    "authors": f"sequential loop, SPH constant {AUTHORS_SPH_CONSTANT:g}",
}
PRESET_LABELS = {"authors": "the authors' algorithm"}  # a case whose dimensions are all its preset's


TIME_GRID_LABELS = {"authors": "authors' time grid"}  # legend text of a non-default time grid


def variant_parts(case: Case) -> list[str]:
    """Legend words for the dimensions that differ from the paper's defaults, e.g.
    ['truncation 3', 'sequential loop']."""
    v, parts = case.variant(), []
    if "truncation" in v:
        parts.append(f"truncation {v['truncation']:g}")
    if "dt_growth" in v:
        parts.append("fixed Δt" if v["dt_growth"] == 1.0 else f"Δt growth {v['dt_growth']:g}")
    if "scheme" in v:
        parts.append(SCHEME_LABELS[v["scheme"]])
    if "time_grid" in v:
        parts.append(TIME_GRID_LABELS[v["time_grid"]])
    return parts


def preset_of(case: Case) -> str | None:
    """The preset (registry.PRESETS) whose dimensions are exactly the case's variant, or None."""
    return next((p for p, dims in PRESETS.items() if case.variant() == dims), None)


def variant_text(case: Case) -> str:
    """Legend words for how the case differs from the paper's defaults: its preset's name when it
    is one (registry.PRESETS), else its variant_parts joined ('' for the paper's own)."""
    preset = preset_of(case)
    return PRESET_LABELS[preset] if preset is not None else ", ".join(variant_parts(case))


def case_label(case: Case, n: bool = True) -> str:
    """Legend text, e.g. 'MTPT collision, η=1, truncation 3, sequential loop, N=300'."""
    parts = [f"{case.method.upper()} {KERNEL_NAMES[case.kernel]}"]
    if case.method == "mtpt":
        parts.append(f"η={case.eta:g}")
    variant = variant_text(case)
    parts += [variant] if variant else []
    if n and case.n is not None:
        parts.append(f"N={case.n:,}")
    return ", ".join(parts)


def integer(x: float) -> str:
    """An integer with thousands separators: 16970.56 -> '16,971'."""
    return f"{round(float(x)):,}"


def interval(lo: float, hi: float) -> str:
    """A half-open interval of resolutions or Peclet numbers: (668, 1,243]."""
    return f"({integer(lo)}, {integer(hi)}]"
