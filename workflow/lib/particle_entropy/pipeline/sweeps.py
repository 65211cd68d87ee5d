"""Expand the workflow config into ensembles (a Case and its realisation count) and their paths.

Every config section that lists cases (each figure, the trade-off sweep) is expanded the same
way: cases x n, dimensions a case leaves unset from ``case_defaults``. Realisation r of a
case is seeded base_seed + r; small-N realisations run in blocks of seeds (one job, one table
with a `seed` column) to amortise job start-up. Each seed's random stream depends only on the
seed, so the blocking never changes a result. Paths hold parameters as written in config, so
file names stay stable. No Snakemake needed: tested directly.

The planning reads the typed config (``cfg``: pipeline/config.py's Config, parsed once, its
defaults filled in by its models; a section of cases is its ``CaseSection``). The run settings
(``run_settings``, ``run_config``) read the mapping as written: they are the simulate jobs'
``settings`` param, a rerun trigger, and check values that no parse has yet refused.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ..core.case import CASE_DIR, Case, SettingError
from ..core.runconfig import RunConfig, first_step
from ..core.settings import PAPER, SETTINGS

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


def case_sections(cfg) -> dict:
    """Every config section that lists cases, by name: each figure, `tradeoff`, and each sweep of
    `mechanism` (the controlled experiments behind figures/fig9_mechanism.png): Config.case_sections."""
    return cfg.case_sections()


def mechanism_ensembles(cfg) -> list[Ensemble]:
    """Every ensemble of the mechanism sweeps, each once (cases shared with Fig. 9 share its runs)."""
    sweeps = cfg.mechanism.sweeps if cfg.mechanism is not None else []
    return list(dict.fromkeys(e for spec in sweeps for e in spec_ensembles(spec, cfg)))


def spec_case(spec, n: int | None, cfg) -> Case:
    """The Case of one typed case spec (a CaseSpec: the keys it sets) at ``n``, case_defaults applied."""
    return Case.from_spec(spec.model_dump(exclude_unset=True), n, cfg.case_defaults.model_dump())


def lattice_cases(cfg) -> list[Case]:
    """The cases of the noise-free floors (lattice.py): every mechanism model and the extra
    `mechanism.lattice.cases`, at N = `mechanism.lattice.n`, each once."""
    lattice = cfg.mechanism.lattice if cfg.mechanism is not None else None
    if lattice is None:
        return []
    models = [e.case.model for e in mechanism_ensembles(cfg)]
    models += [spec_case(c, None, cfg) for c in lattice.cases or []]
    return [m.at(lattice.n) for m in dict.fromkeys(models)]


def realisations_for(spec, n: int, cfg) -> int:
    """Realisations of one N in a section (a CaseSection): an integer, or the `realisations` table
    (capped by its max_realisations)."""
    r = spec.realisations
    if r == "ensemble":
        table = {e.n: e.count for e in cfg.realisations}
        if n not in table:
            raise SettingError(
                "n",
                n,
                "a particle number listed in `realisations` (the section uses "
                f"realisations: ensemble); add {{n: {n}, count: ...}} there",
            )
        r = table[n]
        if spec.max_realisations is not None:
            r = min(r, spec.max_realisations)
    return r


def spec_ensembles(spec, cfg) -> list[Ensemble]:
    """Every case of a section (a CaseSection: its cases x its n), each once, with realisation
    counts; FD, being deterministic, runs once whatever the ensemble size."""
    out = []
    for c in spec.cases:
        for n in spec.n:
            case = spec_case(c, n, cfg)
            out.append(Ensemble(case, 1 if case.method == "fd" else realisations_for(spec, n, cfg)))
    return list(dict.fromkeys(out))  # a case listed twice (or written two ways) is drawn once


def figure_ensembles(cfg, fig: str) -> list[Ensemble]:
    return spec_ensembles(getattr(cfg.figures, fig), cfg)


def _block(ens: Ensemble, cfg) -> int:
    """Seeds a job of ``ens`` runs: seed_blocks.size up to N = seed_blocks.max_n, else one."""
    blocks = cfg.seed_blocks
    return blocks.size if ens.case.n <= blocks.max_n else 1


def block_size(ens: Ensemble, cfg) -> int:
    """Seeds in the largest job of an ensemble (``seed_blocks``), without building the blocks."""
    return min(_block(ens, cfg), ens.realisations)


def seed_blocks(ens: Ensemble, cfg) -> list[tuple[int, int]]:
    """Inclusive seed ranges of the jobs behind an ensemble: blocks aligned to multiples of the
    block size (config seed_blocks.size, for N <= seed_blocks.max_n; else one seed a job)."""
    size = _block(ens, cfg)
    base, count = cfg.base_seed, ens.realisations
    return [(base + r, base + min(r + size, count) - 1) for r in range(0, count, size)]


def case_run_paths(ens: Ensemble, cfg) -> list[str]:
    """Every run table behind an ensemble."""
    return [run_path(ens.case, a, b) for a, b in seed_blocks(ens, cfg)]


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
