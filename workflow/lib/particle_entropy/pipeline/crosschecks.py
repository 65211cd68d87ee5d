"""The rules between config sections and runs, checked before any job runs, on the typed config
(pipeline/config.py; the rules a section can see alone are its model's validators): every number
finite, every case of every section a valid run, ensemble sizes for every N, seeds within int64,
the lattice and FD-domain experiments, the shear cases, the adaptive searches (each when a target
first uses it: `Searches`) and, where jobs run locally, every job within memory. Each refusal is a
SettingError naming the key path, the value and the allowed range.

Each check takes the config as the workflow holds it (a mapping: a run's settings are read from it
as written by sweeps.run_config, and the searches and scenes are built from it by
analysis/optimum.py and scenes/scene.py) and plans the case sections and reads its own values
from the typed config, given or parsed here."""

from __future__ import annotations

from collections.abc import Mapping

from ..core.case import Case, SettingError
from ..core.labels import case_label
from ..core.runconfig import FD_MIN_INTERVALS, MAX_SEED, RunConfig, first_step_key
from ..core.settings import SETTINGS
from ..core.typed import check_finite
from .config import Config, parse
from .memory import estimate_mb, shear_memory_mb
from .sweeps import (
    Ensemble,
    block_size,
    lattice_cases,
    realisations_for,
    run_config,
    spec_case,
    spec_ensembles,
)


def check_lattice(config: Mapping, typed: Config | None = None) -> None:
    """A lattice run needs mtpt cases at eta = 1 (random walks leave the lattice) that run (its odd
    N: the Lattice model)."""
    cfg = typed or parse(config)
    lattice = cfg.mechanism.lattice if cfg.mechanism else None
    if lattice is None:
        return
    for i, spec in enumerate(lattice.cases or []):
        try:
            case = spec_case(spec, lattice.n, cfg)
            run_config(case, config)
        except SettingError as e:
            raise SettingError(f"mechanism.lattice.cases[{i}].{e.name}", e.value, e.allowed) from None
    for case in lattice_cases(cfg):
        if case.method != "mtpt" or case.eta != 1.0:
            raise SettingError(
                "mechanism.lattice",
                case_label(case),
                "mtpt cases at eta = 1 only (random walks would leave the lattice)",
            )


def check_fd_domain(config: Mapping, typed: Config | None = None) -> None:
    """Every grid of `mechanism.fd_domain` runs on every length: an even whole number of intervals
    at dx = physics.fd_length / n (fd_domain.grid_intervals), on a domain the plume fits (RunConfig)."""
    cfg = typed or parse(config)
    spec = cfg.mechanism.fd_domain if cfg.mechanism else None
    if spec is None:
        return
    from ..experiments.fd_domain import grid_intervals

    ref = cfg.physics.fd_length
    settings = {"D": cfg.physics.D, "t_final": cfg.physics.t_final, "dt0": cfg.time.fd_dt}
    raw = config["mechanism"]["fd_domain"]  # the values as written, for the messages
    for length, written in zip(spec.lengths, raw["lengths"]):  # a domain the plume fits, whatever the grid
        try:
            run = RunConfig.of(method="fd", kernel="implicit", n=FD_MIN_INTERVALS, fd_length=length, **settings)
            run.check_domain()
        except SettingError as e:
            raise SettingError("mechanism.fd_domain.lengths", written, e.allowed) from None
    for n in spec.n:  # each grid as it runs: a dx that resolves the plume
        for length, written in zip(spec.lengths, raw["lengths"]):
            try:
                n_int = grid_intervals(n, length, ref)
                RunConfig.of(method="fd", kernel="implicit", n=n_int, fd_length=length, **settings).check()
            except SettingError as e:
                key, value = ("lengths", written) if e.name == "fd_length" else ("n", n)
                raise SettingError(f"mechanism.fd_domain.{key}", value, e.allowed) from None


# RunConfig settings that come from a shared config key, not from the case: a SettingError about
# them names that key (and the case it fails for); the first step's key depends on the case
SHARED_KEYS = {s.name: s.key for s in SETTINGS if s.section in ("physics", "numerics")}
SHARED_KEYS["dt0"] = lambda case: "time." + first_step_key(case.method, case.dt_growth)


def check_seeds(config: Mapping, typed: Config | None = None) -> None:
    """Realisation r of every case uses seed base_seed + r, stored as int64 in every table (an
    adaptive search's seeds, up to its max_realisations: check_search)."""
    cfg = typed or parse(config)
    counts = [e.realisations for s in cfg.case_sections().values() for e in spec_ensembles(s, cfg)]
    _check_seed_count(cfg.base_seed, max(counts, default=1))


def _check_seed_count(base: int, most: int) -> None:
    if base + most - 1 > MAX_SEED:
        raise SettingError(
            "base_seed",
            base,
            f"an integer in [0, {MAX_SEED - most + 1}]: seeds run to base_seed + {most - 1} and are stored as int64",
        )


def _check_max_realisations(key: str, most: int, base: int) -> None:
    """_check_seed_count for a search that runs seeds up to base + ``most`` - 1, named by its own
    ``key`` (an optimum search's or a scene's max_realisations), which sets how far they run."""
    try:
        _check_seed_count(base, most)
    except SettingError:
        raise SettingError(
            key,
            most,
            f"an integer <= {MAX_SEED - base + 1} with base_seed = {base} (seeds run to base_seed + "
            "max_realisations - 1 and are stored as int64), or a lower base_seed",
        ) from None


def check_shear(config: Mapping, typed: Config | None = None) -> None:
    """Every shear case must build a valid ShearConfig (strip inside the domain, whole steps, ...)."""
    shear = (typed or parse(config)).shear
    if shear is None:
        return
    from ..models.shear2d import ShearConfig

    settings = shear.model_dump(exclude={"cases"})
    for case in shear.cases:
        try:
            ShearConfig(case=case, **settings)
        except SettingError as e:  # named with the value as the config wrote it
            written = config["shear"].get(e.name, e.value)
            raise SettingError(f"shear.{e.name}", written, f"{e.allowed} (shear case {case})") from None


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


def check_memory(config: Mapping, available: float, typed: Config | None = None) -> None:
    """Every simulation job of the case sections must fit in ``available`` bytes (memory.estimate_mb
    of its seed block; each run of the lattice floors; the shear jobs: shear_memory_mb; an adaptive
    search's jobs: check_search)."""
    cfg = typed or parse(config)
    jobs = [
        (f"{name}.n", ens, block_size(ens, cfg))
        for name, spec in cfg.case_sections().items()
        for ens in spec_ensembles(spec, cfg)
    ]
    # the floors job runs its lattice cases one after another in one process: each must fit
    jobs += [("mechanism.lattice.n", Ensemble(case, 1), 1) for case in lattice_cases(cfg)]
    _check_jobs_fit(jobs, config, available)
    shear = cfg.shear
    if shear is not None:
        need = shear_memory_mb(shear) * 2**20
        if need > available:
            raise SettingError(
                "shear.n",
                shear.n,
                f"an N whose shear job fits in this machine's memory: it needs about {need / 1e9:.3g} GB, "
                f"{available / 1e9:.1f} GB are available (or run it on a cluster)",
            )


def _check_jobs_fit(jobs, config: Mapping, available: float) -> None:
    """SettingError naming the key of the first (key, ensemble, seeds) job that needs more memory."""
    for key, ens, runs in jobs:
        need = estimate_mb(run_config(ens.case, config), runs) * 2**20
        if need > available:
            raise SettingError(
                key,
                ens.case.n,
                f"an N whose job fits in this machine's memory: {case_label(ens.case)} needs about "
                f"{need / 1e9:.1f} GB, {available / 1e9:.1f} GB are available (or run it on a cluster)",
            )


def check_scene(scene, base_seed: int, available: float | None) -> None:
    """A scene's further checks when first used: its seeds, base_seed + max_realisations - 1 at most,
    fit int64 (SettingError naming scenes.<name>.max_realisations, which sets how far they run), and
    its jobs fit in memory (check_scene_memory; ``available`` None: not checked)."""
    most = max(1 if c.case.method == "fd" else scene.max_realisations for c in scene.candidates)
    _check_max_realisations(scene.key("max_realisations"), most, int(base_seed))
    if available is not None:
        check_scene_memory(scene, available)


def check_scene_memory(scene, available: float) -> None:
    """Every job a scene may run must fit in ``available`` bytes: each candidate's top resolution
    with its realisations in one process (memory.estimate_mb); SettingError naming its n_range (or
    ladder), under <sweep>.base for a scene of a Peclet sweep."""
    for i, c in enumerate(scene.candidates):
        runs = 1 if c.case.method == "fd" else scene.realisations
        need = estimate_mb(scene.run_config(c, c.n_hi), runs) * 2**20
        if need > available:
            raise SettingError(
                scene.key(f"candidates[{i}].{'ladder' if c.rungs else 'n_range'}"),
                list(c.rungs) if c.rungs else [c.n_lo, c.n_hi],
                f"a range whose top job fits in this machine's memory: {c.label} at n = {c.n_hi:,} with "
                f"{runs} realisations needs about {need / 1e9:.1f} GB, {available / 1e9:.1f} GB are available",
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
    _check_max_realisations(f"{where}.max_realisations", search.max_realisations, int(config["base_seed"]))
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


def check_sweeps(config: Mapping, typed: Config | None = None) -> None:
    """Checks between sections and runs, before any job runs: every number finite, every case of
    every section must build a valid run (kernel for its method, dimensions that apply, FD grids,
    explicit FD stability, an ensemble size for each N), the lattice, the FD domains, the seeds and
    the shear cases. ``typed``: the config's typed form (validate_config), else parsed here. The
    message names the section, key and value."""
    check_finite(config)  # first: a config not yet parsed (common.smk) has its .nan named so
    cfg = typed or parse(config)
    for name, spec in cfg.case_sections().items():
        for i, c in enumerate(spec.cases):
            where = f"{name}.cases[{i}]"
            case = None
            try:
                for n in spec.n:
                    case = spec_case(c, n, cfg)
                    run_config(case, config)
            except SettingError as e:
                raise _case_error(e, where, case) from None  # a shared setting names its key and the case
        particles = any(c.method != "fd" for c in spec.cases)  # FD runs once whatever the ensemble
        for n in spec.n if particles else []:
            try:
                realisations_for(spec, n, cfg)
            except SettingError as e:
                raise SettingError(f"{name}.n", n, e.allowed) from None
    check_lattice(config, cfg)
    check_fd_domain(config, cfg)
    check_seeds(config, cfg)
    check_shear(config, cfg)  # the optimum searches are checked when a target uses them (Searches)
    t_final = cfg.physics.t_final
    written = {"comic_times": config["comic_times"], "tradeoff.times": config.get("tradeoff", {}).get("times", [])}
    times = [("comic_times", cfg.comic_times), ("tradeoff.times", cfg.tradeoff.times if cfg.tradeoff else [])]
    for key, values in times:
        for t, as_written in zip(values, written[key]):
            if not 0 <= t <= t_final:
                raise SettingError(key, as_written, f"a time in [0, physics.t_final = {t_final:g}]")
