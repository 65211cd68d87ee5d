"""Expand the workflow config into ensembles (a Case and its realisation count) and their paths.

Every config section that lists cases (each figure, the trade-off sweep) is expanded the same
way: cases x n, dimensions a case leaves unset from ``case_defaults``. Realisation r of a
case is seeded base_seed + r; small-N realisations run in blocks of seeds (one job, one table
with a `seed` column) to amortise job start-up. Each seed's random stream depends only on the
seed, so the blocking never changes a result. Paths hold parameters as written in config, so
file names stay stable. No Snakemake needed: tested directly.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ..core.case import CASE_DIR, Case, SettingError
from ..core.runconfig import RunConfig, first_step
from ..core.settings import BY_KEY, PAPER, SETTINGS

RUN_PATTERN = "results/{kind}/" + CASE_DIR + "/seeds~{first}-{last}.parquet"
SUMMARY_PATTERN = "results/tables/cases/" + CASE_DIR + "/r~{nreal}.parquet"
FIGURE_DATA_PATTERN = "results/figures/{fig}.parquet"
# config.physics / config.time keys -> RunConfig settings shared by every case
PHYSICS = tuple(s.name for s in SETTINGS if s.section == "physics")  # D, t_final, omega, ...
NUMERICS = tuple(s.name for s in SETTINGS if s.section == "numerics")  # transfer_method, _tolerance


@dataclass(frozen=True)
class Ensemble:
    """A case and the number of realisations a figure or table averages."""

    case: Case
    realisations: int

    @classmethod
    def from_wildcards(cls, w: Mapping) -> Ensemble:
        return cls(Case.from_wildcards(w), int(w["nreal"]))

    def summary_path(self) -> str:
        return SUMMARY_PATTERN.format(nreal=self.realisations, **self.case.wildcards())


def run_path(case: Case, first: int, last: int | None = None, kind: str = "runs") -> str:
    """Table of seeds first..last of ``case`` (kind: runs = per-step tables, snapshots = final states)."""
    return RUN_PATTERN.format(kind=kind, first=first, last=first if last is None else last, **case.wildcards())


def case_sections(config: Mapping) -> dict[str, Mapping]:
    """Every config section that lists cases, by name: each figure, `tradeoff`, and each sweep of
    `mechanism` (the controlled experiments behind figures/fig9_mechanism.png)."""
    out = {f"figures.{fig}": spec for fig, spec in config.get("figures", {}).items()}
    if "tradeoff" in config:
        out["tradeoff"] = config["tradeoff"]
    for i, spec in enumerate(config.get("mechanism", {}).get("sweeps", [])):
        out[f"mechanism.sweeps[{i}]"] = spec
    return out


def mechanism_ensembles(config: Mapping) -> list[Ensemble]:
    """Every ensemble of the mechanism sweeps, each once (cases shared with Fig. 9 share its runs)."""
    sweeps = config.get("mechanism", {}).get("sweeps", [])
    return list(dict.fromkeys(e for spec in sweeps for e in spec_ensembles(spec, config)))


def lattice_cases(config: Mapping) -> list[Case]:
    """The cases of the noise-free floors (lattice.py): every mechanism model and the extra
    `mechanism.lattice.cases`, at N = `mechanism.lattice.n`, each once."""
    mech = config.get("mechanism", {})
    if "lattice" not in mech:
        return []
    n = int(mech["lattice"]["n"])
    models = [e.case.model for e in mechanism_ensembles(config)]
    defaults = config.get("case_defaults", {})
    models += [Case.from_spec(c, None, defaults) for c in mech["lattice"].get("cases", [])]
    return [m.at(n) for m in dict.fromkeys(models)]


def realisations_for(spec: Mapping, n: int, config: Mapping) -> int:
    """Realisations of one N in a section: an integer, or the `realisations` table (capped)."""
    r = spec.get("realisations", BY_KEY["<section>.realisations"].default)
    if r == "ensemble":
        table = {int(e["n"]): int(e["count"]) for e in config["realisations"]}
        if n not in table:
            raise SettingError(
                "n",
                n,
                "a particle number listed in `realisations` (the section uses "
                f"realisations: ensemble); add {{n: {n}, count: ...}} there",
            )
        r = table[n]
        if "max_realisations" in spec:
            r = min(r, int(spec["max_realisations"]))
    return int(r)


def spec_ensembles(spec: Mapping, config: Mapping) -> list[Ensemble]:
    """Every case of a section (its cases x its n), each once, with realisation counts; FD, being
    deterministic, runs once whatever the ensemble size."""
    defaults = config.get("case_defaults", {})
    out = []
    for c in spec["cases"]:
        for n in spec["n"]:
            case = Case.from_spec(c, int(n), defaults)
            out.append(Ensemble(case, 1 if case.method == "fd" else realisations_for(spec, int(n), config)))
    return list(dict.fromkeys(out))  # a case listed twice (or written two ways) is drawn once


def figure_ensembles(config: Mapping, fig: str) -> list[Ensemble]:
    return spec_ensembles(config["figures"][fig], config)


def _block(ens: Ensemble, config: Mapping) -> int:
    """Seeds a job of ``ens`` runs: seed_blocks.size up to N = seed_blocks.max_n, else one (a config
    without seed_blocks, as a library caller's may be: one seed a job)."""
    blocks = config.get("seed_blocks")
    return int(blocks["size"]) if blocks and ens.case.n <= int(blocks["max_n"]) else 1


def block_size(ens: Ensemble, config: Mapping) -> int:
    """Seeds in the largest job of an ensemble (``seed_blocks``), without building the blocks."""
    return min(_block(ens, config), ens.realisations)


def seed_blocks(ens: Ensemble, config: Mapping) -> list[tuple[int, int]]:
    """Inclusive seed ranges of the jobs behind an ensemble: blocks aligned to multiples of the
    block size (config seed_blocks.size, for N <= seed_blocks.max_n; else one seed a job)."""
    size = _block(ens, config)
    base, count = int(config["base_seed"]), ens.realisations
    return [(base + r, base + min(r + size, count) - 1) for r in range(0, count, size)]


def case_run_paths(ens: Ensemble, config: Mapping) -> list[str]:
    """Every run table behind an ensemble."""
    return [run_path(ens.case, a, b) for a, b in seed_blocks(ens, config)]


def run_settings(case: Case, config: Mapping) -> dict:
    """Physics and numerics of a run of ``case`` from config (its first step by first_step)."""
    physics, time, numerics = config["physics"], config["time"], config.get("numerics", {})
    out = {k: float(physics.get(k, PAPER[k])) for k in PHYSICS}
    out.update({k: numerics.get(k, PAPER[k]) for k in NUMERICS})
    out["dt0"] = first_step(case.method, case.dt_growth, time)
    return out


def run_config(case: Case, config: Mapping, seed: int = 0) -> RunConfig:
    """The checked RunConfig of one realisation of ``case``."""
    return RunConfig.for_case(case, seed=seed, **run_settings(case, config)).resolved()
