"""Expand the workflow config into ensembles (a Case and its realisation count) and their paths.

Every config section that lists cases (each figure, the trade-off sweep) is expanded the same
way: cases x n, dimensions a case leaves unset from ``case_defaults``. Realisation r of a
case is seeded base_seed + r; small-N realisations run in blocks of seeds (one job, one table
with a `seed` column) to amortise job start-up. Each seed's random stream depends only on the
seed, so the blocking never changes a result. Paths hold parameters as written in config, so
file names stay stable. No Snakemake needed: tested directly.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from ..core.case import CASE_DIR, Case, SettingError
from ..core.labels import case_label
from ..core.runconfig import MAX_SEED, RunConfig, first_step
from ..core.settings import PAPER, SETTINGS

RUN_PATTERN = "results/{kind}/" + CASE_DIR + "/seeds~{first}-{last}.parquet"
SUMMARY_PATTERN = "results/tables/cases/" + CASE_DIR + "/r~{nreal}.parquet"
FIGURE_DATA_PATTERN = "results/figures/{fig}.parquet"
PAPER_FIGURES = tuple(f"fig{k}" for k in range(1, 10))  # the case-drawn figures; fig10 is the shear flow
# What each case section's figure reads: single runs of base_seed, final states, its own COMIC
# table, the trade-off table; every other figure reads case summaries (ensemble statistics).
FIGURE_READS = {"fig1": "runs", "fig2": "runs", "fig7": "snapshots", "fig9": "comic", "tradeoff": "tradeoff"}
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


def check_lattice(config: Mapping) -> None:
    """A lattice run needs an odd N and mtpt cases at eta = 1 (random walks leave the lattice)."""
    mech = config.get("mechanism", {})
    if "lattice" not in mech:
        return
    n = mech["lattice"]["n"]
    if int(n) % 2 == 0:
        raise SettingError("mechanism.lattice.n", n, "an odd integer >= 3, so that a particle sits at x = 0")
    for i, spec in enumerate(mech["lattice"].get("cases", [])):
        try:
            case = Case.from_spec(spec, int(n), config.get("case_defaults", {}))
            run_config(case, config)
        except SettingError as e:
            raise SettingError(f"mechanism.lattice.cases[{i}].{e.name}", e.value, e.allowed) from None
    for case in lattice_cases(config):
        if case.method != "mtpt" or case.eta != 1.0:
            raise SettingError(
                "mechanism.lattice",
                case_label(case),
                "mtpt cases at eta = 1 only (random walks would leave the lattice)",
            )


def check_fd_domain(config: Mapping) -> None:
    """Every grid of `mechanism.fd_domain` runs on every length: an even whole number of intervals
    at dx = physics.fd_length / n (fd_domain.grid_intervals), on a domain the plume fits (RunConfig)."""
    spec = config.get("mechanism", {}).get("fd_domain")
    if not spec:
        return
    from ..experiments.fd_domain import grid_intervals

    physics, fd_dt = config["physics"], float(config["time"]["fd_dt"])
    ref = float(physics.get("fd_length", PAPER["fd_length"]))
    settings = {"D": float(physics["D"]), "t_final": float(physics["t_final"]), "dt0": fd_dt}
    for length in spec["lengths"]:  # a domain the plume fits, whatever the grid
        try:
            RunConfig.of(method="fd", kernel="implicit", n=2, fd_length=float(length), **settings).check()
        except SettingError as e:
            raise SettingError("mechanism.fd_domain.lengths", length, e.allowed) from None
    for n in spec["n"]:
        for length in spec["lengths"]:
            try:
                grid_intervals(int(n), float(length), ref)
            except SettingError as e:
                raise SettingError("mechanism.fd_domain.n", n, e.allowed) from None


def realisations_for(spec: Mapping, n: int, config: Mapping) -> int:
    """Realisations of one N in a section: an integer, or the `realisations` table (capped)."""
    r = spec.get("realisations", 1)
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


MAX_REALISATIONS = 10_000  # realisations of one case (schema and hand-written targets): more is a typo


def block_size(ens: Ensemble, config: Mapping) -> int:
    """Seeds in the largest job of an ensemble (``seed_blocks``), without building the blocks."""
    blocks = config.get("seed_blocks", {"size": 1, "max_n": 0})
    size = int(blocks["size"]) if ens.case.n <= int(blocks["max_n"]) else 1
    return min(size, ens.realisations)


def seed_blocks(ens: Ensemble, config: Mapping) -> list[tuple[int, int]]:
    """Inclusive seed ranges of the jobs behind an ensemble: blocks aligned to multiples of the
    block size (config seed_blocks.size, for N <= seed_blocks.max_n; else one seed a job)."""
    blocks = config.get("seed_blocks", {"size": 1, "max_n": 0})
    size = int(blocks["size"]) if ens.case.n <= int(blocks["max_n"]) else 1
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
    out["dt0"] = float(
        first_step(case.method, case.dt_growth, time["dt0"], time["fd_dt"], time.get("fixed_dt", PAPER["fixed_dt"]))
    )
    return out


def run_config(case: Case, config: Mapping, seed: int = 0) -> RunConfig:
    """The checked RunConfig of one realisation of ``case``."""
    return RunConfig.for_case(case, seed=seed, **run_settings(case, config)).resolved()


def check_finite(value, where: str = "") -> None:
    """Every number of the config must be finite: YAML's .nan and .inf pass the schema's
    `number` but no setting means them. SettingError names the key path."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            check_finite(v, f"{where}.{k}" if where else str(k))
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            check_finite(v, f"{where}[{i}]")
    elif isinstance(value, float) and not math.isfinite(value):
        raise SettingError(where, value, "a finite number (YAML .nan and .inf are not settings)")


def _first_step_key(case: Case) -> str:
    """The config key of a case's first step (runconfig.first_step)."""
    if case.method == "fd":
        return "time.fd_dt"
    return "time.fixed_dt" if case.dt_growth == 1.0 else "time.dt0"


# RunConfig settings that come from a shared config key, not from the case: a SettingError about
# them names that key (and the case it fails for)
SHARED_KEYS = {s.name: s.key for s in SETTINGS if s.section in ("physics", "numerics")}
SHARED_KEYS["dt0"] = _first_step_key


def check_seeds(config: Mapping) -> None:
    """Realisation r of every case uses seed base_seed + r, stored as int64 in every table (an
    adaptive search's seeds, up to its max_realisations: check_search)."""
    base = int(config["base_seed"])
    counts = [e.realisations for s in case_sections(config).values() for e in spec_ensembles(s, config)]
    _check_seed_count(base, max(counts, default=1))


def _check_seed_count(base: int, most: int) -> None:
    if base + most - 1 > MAX_SEED:
        raise SettingError(
            "base_seed",
            base,
            f"an integer in [0, {MAX_SEED - most + 1}]: seeds run to base_seed + {most - 1} and are stored as int64",
        )


def check_shear(config: Mapping) -> None:
    """Every shear case must build a valid ShearConfig (strip inside the domain, whole steps, ...)."""
    if "shear" not in config:
        return
    from ..experiments.shear2d import ShearConfig

    settings = {k: v for k, v in config["shear"].items() if k != "cases"}
    for case in config["shear"]["cases"]:
        try:
            ShearConfig(case=case, **settings)
        except SettingError as e:
            raise SettingError(f"shear.{e.name}", e.value, f"{e.allowed} (shear case {case})") from None


class Searches(Mapping):
    """The adaptive COMIC searches of config `optimum` (optimum.Search) by name, each built and
    checked (check_search) when it is first used: a search that no requested target needs
    cannot block a run, as when a small config is layered over config.yaml's searches."""

    def __init__(self, config: Mapping, available: float | None = None):
        self._config, self._available, self._built = config, available, {}
        self._names = list(config.get("optimum", {}) or {})

    def __getitem__(self, name: str):
        if name not in self._names:
            raise KeyError(name)
        if name not in self._built:
            self._built[name] = check_search(name, self._config, self._available)
        return self._built[name]

    def __iter__(self):
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


def optimum_searches(config: Mapping, available: float | None = None) -> Searches:
    """The adaptive COMIC searches of config `optimum`, by name, checked when used (Searches)."""
    return Searches(config, available)


def optimum_largest_jobs(search) -> list[Ensemble]:
    """A search's largest possible simulation jobs: both ends of its range (the top N; the
    smallest growth, most steps) with the most seeds one block can hold (the first round's
    realisations, or a doubling up to max_realisations)."""
    seeds = 1 if search.fd else max(search.initial_realisations, search.max_realisations // 2)
    return [Ensemble(search.case_at(x), seeds) for x in search.grid(2)]


# measured on one mt transfer step (N = 20,000 and 80,000): 16-18 B a pair in numpy arrays, about
# 35 B a pair of resident memory with the KD tree's; rounded up, as memory.py's per-particle bytes
SHEAR_PAIR_BYTES = 64.0
SHEAR_PARTICLE_BYTES = 400.0


def shear_n(config: Mapping) -> int:
    """The shear section's particle count (ShearConfig's default when the section leaves it out)."""
    from ..experiments.shear2d import ShearConfig

    return config["shear"].get("n", ShearConfig.n)


def shear_memory_mb(config: Mapping) -> int:
    """Estimated peak memory of the largest shear job (Fig. 10), in MB, by arithmetic: the base of
    every run (memory.BASE_BYTES), its particles' arrays and, for mass transfer, its neighbour pairs:
    N^2 / 2 x the kernel's share of the domain, pi s_c^2 / (L / sqrt(alpha_L) / sqrt(alpha_T)) in
    scaled distance (2 s_c / (L / sqrt(alpha_L)) for alpha_T = 0; shear2d.kernel_cutoff)."""
    from ..core.memory import BASE_BYTES
    from ..experiments.shear2d import ShearConfig, kernel_cutoff

    shear = config["shear"]
    n = float(shear_n(config))
    need = BASE_BYTES + SHEAR_PARTICLE_BYTES * n
    if "mt" in shear["cases"]:
        cfg = ShearConfig(case="mt", **{k: v for k, v in shear.items() if k not in ("cases", "n")})
        cut, width = kernel_cutoff(cfg), cfg.length / math.sqrt(cfg.alpha_L)
        share = math.pi * cut**2 / (width / math.sqrt(cfg.alpha_T)) if cfg.alpha_T > 0 else 2.0 * cut / width
        need += SHEAR_PAIR_BYTES * n * n / 2.0 * min(share, 1.0)
    return int(need / 2**20) + 1


def check_memory(config: Mapping, available: float) -> None:
    """Every simulation job of the case sections must fit in ``available`` bytes (memory.estimate_mb
    of its seed block; the shear jobs: shear_memory_mb; an adaptive search's jobs: check_search)."""
    jobs = [
        (f"{name}.n", ens, block_size(ens, config))
        for name, spec in case_sections(config).items()
        for ens in spec_ensembles(spec, config)
    ]
    _check_jobs_fit(jobs, config, available)
    if "shear" in config:
        need = shear_memory_mb(config) * 2**20
        if need > available:
            raise SettingError(
                "shear.n",
                shear_n(config),
                f"an N whose shear job fits in this machine's memory: it needs about {need / 1e9:.3g} GB, "
                f"{available / 1e9:.1f} GB are available (or run it on a cluster)",
            )


def _check_jobs_fit(jobs, config: Mapping, available: float) -> None:
    """SettingError naming the key of the first (key, ensemble, seeds) job that needs more memory."""
    from ..core.memory import estimate_mb

    for key, ens, runs in jobs:
        need = estimate_mb(run_config(ens.case, config), runs) * 2**20
        if need > available:
            raise SettingError(
                key,
                ens.case.n,
                f"an N whose job fits in this machine's memory: {case_label(ens.case)} needs about "
                f"{need / 1e9:.1f} GB, {available / 1e9:.1f} GB are available (or run it on a cluster)",
            )


def _case_error(e: SettingError, where: str, case: Case) -> SettingError:
    """A SettingError of one case's run, named by its config key: a shared setting (time.dt0, ...)
    names that key and the case, any other the case's own key under ``where``."""
    if e.name in SHARED_KEYS:
        key = SHARED_KEYS[e.name](case) if callable(SHARED_KEYS[e.name]) else SHARED_KEYS[e.name]
        return SettingError(key, e.value, f"{e.allowed} (for {where}, {case_label(case)})")
    return SettingError(f"{where}.{e.name}", e.value, e.allowed)


def check_search(name: str, config: Mapping, available: float | None = None):
    """The adaptive search ``optimum.<name>`` (optimum.Search), refused unless it can run: a model
    that exists, a range with room for a minimum, a budget of at least its first round, a time
    within t_final (optimum.Search.check), runs valid at both ends of its range, its seeds within
    int64 and (given ``available`` bytes) its largest jobs within memory."""
    from ..analysis.optimum import Search

    search = Search.from_config(name, config["optimum"][name], config)
    where = f"optimum.{name}"
    key = "growth_range" if search.over == "dt_growth" else "n_range"
    for x in search.grid(2):  # the range's ends (FD: even)
        case = search.case_at(x)
        try:
            run_config(case, config)
        except SettingError as e:
            if e.name in ("n", "dt_growth"):
                raise SettingError(f"{where}.{key}", [search.lo, search.hi], e.allowed) from None
            raise _case_error(e, f"{where}.case", case) from None
    _check_seed_count(int(config["base_seed"]), search.max_realisations)
    if available is not None:
        _check_jobs_fit(
            [(f"{where}.{key}", e, e.realisations) for e in optimum_largest_jobs(search)], config, available
        )
    return search


def check_optimum(config: Mapping, available: float | None = None) -> None:
    """Every adaptive search of config `optimum` (check_search): what check-config judges, since
    it does not know which targets will be asked for."""
    for name in config.get("optimum", {}) or {}:
        check_search(name, config, available)


def check_sweeps(config: Mapping) -> None:
    """Checks the JSON schema cannot express, before any job runs: every number finite, every
    case of every section must build a valid run (kernel for its method, dimensions that apply,
    FD grids, explicit FD stability, an ensemble size for each N). The message names the
    section, key and value."""
    check_finite(config)
    seen: dict[int, int] = {}
    for i, entry in enumerate(config.get("realisations", [])):
        n = int(entry["n"])
        if n in seen:
            raise SettingError(f"realisations[{i}].n", n, f"each N once (also at realisations[{seen[n]}])")
        seen[n] = i
    for key, value in config.get("claims", {}).items():
        if isinstance(value, (list, tuple)) and len(value) == 2 and value[0] > value[1]:
            raise SettingError(f"claims.{key}", list(value), "a range [low, high] with low <= high")
    for name, spec in case_sections(config).items():
        for i, c in enumerate(spec["cases"]):
            where = f"{name}.cases[{i}]"
            case = None
            try:
                for n in spec["n"]:
                    case = Case.from_spec(c, int(n), config.get("case_defaults", {}))
                    run_config(case, config)
            except SettingError as e:
                raise _case_error(e, where, case) from None  # a shared setting names its key and the case
        particles = any(c.get("method") != "fd" for c in spec["cases"])  # FD runs once whatever the ensemble
        for n in spec["n"] if particles else []:
            try:
                realisations_for(spec, int(n), config)
            except SettingError as e:
                raise SettingError(f"{name}.n", n, e.allowed) from None
    check_lattice(config)
    check_fd_domain(config)
    check_seeds(config)
    check_shear(config)  # the optimum searches are checked when a target uses them (Searches)
    t_final = float(config["physics"]["t_final"])
    for key, times in (
        ("comic_times", config.get("comic_times", [])),
        ("tradeoff.times", config.get("tradeoff", {}).get("times", [])),
    ):
        for t in times:
            if not (math.isfinite(float(t)) and 0 <= float(t) <= t_final):
                raise SettingError(key, t, f"a time in [0, physics.t_final = {t_final:g}]")
