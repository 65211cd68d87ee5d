"""Where a search round's tables lie (the search engine's, analysis/search.py): its plan, and beside it
what it read of the runs of the plan before. Free of pandas, so that the workflow's parse imports it."""

from __future__ import annotations

READ_SUFFIX = ".read.parquet"  # what a round read, beside its plan


def read_path(plan_path: str) -> str:
    """Where a round that keeps its reads (AdaptiveSearch.KEEPS_READS) writes what it read of the runs of
    the plan before its own: beside its plan, ``round~<k>.parquet`` -> ``round~<k>.read.parquet``."""
    if not plan_path.endswith(".parquet"):
        raise ValueError(f"a plan's path ends in .parquet: {plan_path}")
    return plan_path.removesuffix(".parquet") + READ_SUFFIX
