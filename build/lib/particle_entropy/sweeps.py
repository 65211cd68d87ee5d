"""Expand the workflow config into cases and run paths (no Snakemake needed; tested directly).

A case is one model setting (method, kernel, N, eta, truncation, dt growth) with the number
of realisations a figure averages; its runs are realisations r = 0 .. count-1, seeded
base_seed + r. Small-N realisations are run in blocks of seeds (one job, one table with a
`seed` column) to amortise job start-up; each seed's random stream depends only on the seed,
so the blocking never changes a result. Paths hold parameters as written in config, so file
names stay stable.
"""

from __future__ import annotations

RUN_DIR = "{method}/{kernel}/n~{n}/eta~{eta}/trunc~{trunc}/growth~{growth}"
RUN_PATTERN = "results/{kind}/" + RUN_DIR + "/seeds~{first}-{last}.parquet"
SUMMARY_PATTERN = "results/tables/cases/" + RUN_DIR + "/r~{nreal}.parquet"


def _text(value) -> str:
    """A config value as it appears in a file name: 1 -> '1', 0.5 -> '0.5', 'none' -> 'none'."""
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


def realisations_for(spec: dict, n: int, config: dict) -> int:
    """Realisations of one N in a figure: an integer, or the `realisations` table (capped)."""
    r = spec.get("realisations", 1)
    if r == "ensemble":
        table = {int(e["n"]): int(e["count"]) for e in config["realisations"]}
        if n not in table:
            raise ValueError(f"figure uses realisations: ensemble but realisations has no entry for n={n}")
        r = table[n]
        if "max_realisations" in spec:
            r = min(r, int(spec["max_realisations"]))
    return int(r)


def figure_cases(config: dict, fig: str) -> list[dict]:
    """Every case of a figure, with wildcard values as strings and its realisation count."""
    return spec_cases(config["figures"][fig], config)


def spec_cases(spec: dict, config: dict) -> list[dict]:
    """Every case of a sweep spec (cases x n), with wildcard values as strings."""
    defaults = config.get("case_defaults", {})
    cases = []
    for c in spec["cases"]:
        fd = c["method"] == "fd"
        for n in spec["n"]:
            cases.append({
                "method": c["method"],
                "kernel": c["kernel"],
                "n": str(int(n)),
                "eta": _text(c.get("eta", 1 if fd else defaults.get("eta", 1))),
                "trunc": _text(c.get("truncation", "none" if fd else defaults.get("truncation", "none"))),
                "growth": _text(c.get("dt_growth", 1 if fd else defaults.get("dt_growth", config["time"]["dt_growth"]))),
                # FD is deterministic: one realisation whatever the ensemble size
                "nreal": "1" if fd else str(realisations_for(spec, int(n), config)),
            })
    return cases


def seed_blocks(case: dict, config: dict) -> list[tuple[int, int]]:
    """Inclusive seed ranges of the jobs behind a case: blocks aligned to multiples of the
    block size (config seed_blocks.size, for N <= seed_blocks.max_n; else one seed a job)."""
    blocks = config.get("seed_blocks", {"size": 1, "max_n": 0})
    size = int(blocks["size"]) if int(case["n"]) <= int(blocks["max_n"]) else 1
    base, count = int(config["base_seed"]), int(case["nreal"])
    return [(base + r, base + min(r + size, count) - 1) for r in range(0, count, size)]


def run_path(case: dict, first: int, last: int | None = None, kind: str = "runs") -> str:
    """Table of seeds first..last of ``case`` (kind: runs = per-step tables, snapshots = final states)."""
    return RUN_PATTERN.format(kind=kind, first=first, last=first if last is None else last, **case)


def case_run_paths(case: dict, config: dict) -> list[str]:
    """Every run table behind a case."""
    return [run_path(case, a, b) for a, b in seed_blocks(case, config)]


def summary_path(case: dict) -> str:
    return SUMMARY_PATTERN.format(**case)


def case_runs(wildcards, config: dict) -> list[str]:
    """Run tables behind one case summary (wildcards: a case plus its realisation count)."""
    return case_run_paths({k: wildcards[k] for k in ("method", "kernel", "n", "eta", "trunc", "growth", "nreal")}, config)


def check_sweeps(config: dict) -> None:
    """Semantic checks the JSON schema cannot express; the message names the key and value."""
    allowed = {"pt": {"bins", "fixed", "adaptive"}, "mtpt": {"collision", "sph"}, "fd": {"implicit", "explicit"}}
    for fig, spec in config["figures"].items():
        for i, c in enumerate(spec["cases"]):
            if c["kernel"] not in allowed[c["method"]]:
                raise ValueError(
                    f"figures.{fig}.cases[{i}].kernel={c['kernel']!r} is not allowed for method "
                    f"{c['method']!r}: one of {sorted(allowed[c['method']])}"
                )
            if c["method"] == "fd":
                for n in spec["n"]:
                    if int(n) % 2:
                        raise ValueError(f"figures.{fig}.n={n} is not allowed for fd: an even number of intervals")
        for n in spec["n"]:
            realisations_for(spec, int(n), config)
