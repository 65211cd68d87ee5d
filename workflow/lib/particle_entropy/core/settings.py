"""The one typed definition of every config setting: key, default, unit, range, meaning.

Each config section is declared once, as a tuple of ``Setting``, and gathered here: the run
settings (``SETTINGS``: physics, time, numerics, case_defaults) and the shear flow's (``SHEAR``)
are declared in core/run_settings.py and core/shear_settings.py, apart, because simulations import
them and a simulation's code hash covers what it imports (tests/test_codeversion.py holds it
unchanged when any other section's declaration changes). Declared here: the keys of every section that lists cases
(``CASE_SECTION``: figures, tradeoff, mechanism sweeps), the figures' drawing options
(``FIGURE_OPTIONS``), seeds and their blocks (``SEEDS``), the COMIC times (``COMIC_TIMES``), the
claims' tolerances (``CLAIMS``), the trade-off sweep (``TRADEOFF``), the mechanism experiments
(``MECHANISM``) and an adaptive search (``SEARCH``), with the caps
they share (``MAX_REALISATIONS``, ``MAX_SEED``, ``MAX_N``, ``SHEAR_MAX_N``). From them come the paper's
defaults (``PAPER``), ``RunConfig``'s, ``ShearConfig``'s and ``Search``'s defaults and range
checks, the CLI's options (cli.py), the typed config that ``configcheck.validate_config``
returns (pipeline/config.py: a pydantic model per section, derived from these tuples), the whole
schema workflow/schemas/config.schema.yaml, which ``python -m particle_entropy.pipeline.schemagen
--write`` writes from those models (tests/test_settings.py fails when the file is stale), and
the column page's descriptions of settings written beside results. Cross-field rules (a strip
inside its domain, a search's budget of at least one round) are checked where the fields meet;
their range is then given in words (``range_text``).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import AfterValidator, Field, StrictInt
from pydantic_core import PydanticCustomError

from .reactions import reaction_kinds_text, reaction_ranges_text, reaction_shape
from .registry import (
    ADVECTION_SCHEMES,
    CONVENTION_NAMES,
    COURANT_LIMIT,
    MEASURE_NAMES,
    METHODS,
)
from .run_settings import (  # noqa: F401  (re-exported: the run settings, declared apart)
    BY_NAME,
    CASE_SETTINGS,
    MAX_SEED,
    NO_DEFAULT,
    PAPER,
    SETTINGS,
    Setting,
    defaults,
)
from .shear_settings import SHEAR, SHEAR_MAX_N  # noqa: F401  (re-exported)
from .sources import source_forms, source_ranges, source_shape
from .sources2d import pair_shape, source_forms_2d, with_pairs

MAX_REALISATIONS = 10_000  # realisations of one case or N: more is a typo, not an ensemble
MAX_N = 10**9  # particles of one 1-D run: 2,500 x the paper's largest, ~400 GB for mass transfer; more is a typo


def _ref(name: str) -> dict:
    """The shape of a value of a shared definition (core/typed.shared builds them: a case, the
    lists of cases and of N, a section of cases), as the schema's $defs name it."""
    return {"$ref": f"#/$defs/{name}"}


# A structured value's shape is a pydantic type made of these (core/typed.py validates by it,
# schemagen writes its schema entry), or, for the shapes built from other declarations, a
# JSON-schema fragment read by core/typed.annotation: a shared definition (_ref), a scene's source
# (a plain dict, which its kind's class checks further, core/sources.py), a scene's candidates (the
# model core/typed.py names by x-model, with the rules between their keys), the shear cases.
def number(**bounds):
    """A real number (an int is one too; not a bool or a string) within ``bounds`` (gt, ge, le)."""
    return Annotated[float, Field(strict=True, **bounds)]


def integer(**bounds):
    """An int (not 1000.0, which would name files n~1000.0), within ``bounds``."""
    return Annotated[StrictInt, Field(**bounds)]


def _unique(values: list) -> list:
    if len(values) != len({repr(float(v)) if isinstance(v, (int, float)) else repr(v) for v in values}):
        raise PydanticCustomError("unique_items", "has non-unique elements")
    return values


UNIQUE = AfterValidator(_unique)  # each item once (250 and 250.0 are one time)


def array(item, *checks, **length):
    """A list of ``item`` with ``length`` (min_length, max_length) and ``checks`` (UNIQUE)."""
    return Annotated[list[item], Field(**length), *checks]


TIMES = array(number(ge=0), UNIQUE, min_length=1)  # times of a run, each once [T]


# ------------------------------------------------------------------------------ sections of cases
# The keys of every section that lists cases: each figure under `figures`, `tradeoff` and each
# sweep of `mechanism` (the cases, the N and the realisations of each N).
REALISATIONS_DOC = f'an integer in [1, {MAX_REALISATIONS:,}], or "ensemble" for the `realisations` table'
CASE_SECTION = (
    Setting(
        "cases",
        "<section>.cases",
        NO_DEFAULT,
        "the models drawn: method, kernel and the dimensions that differ from case_defaults",
        kind="shape",
        shape=_ref("cases"),
        range_text="a list of cases",
        required=True,
    ),
    Setting(
        "n",
        "<section>.n",
        NO_DEFAULT,
        "particle numbers (FD: intervals)",
        kind="shape",
        shape=_ref("ns"),
        range_text="a list of integers >= 2",
        required=True,
    ),
    Setting(
        "realisations",
        "<section>.realisations",
        1,
        "realisations of each N",
        kind="shape",
        shape=_ref("realisations"),
        range_text=REALISATIONS_DOC,
    ),
    Setting(
        "max_realisations",
        "<section>.max_realisations",
        NO_DEFAULT,
        "cap on the ensemble realisations of each N",
        kind="integer",
        low=1,
        high=MAX_REALISATIONS,
    ),
)
REALISATIONS_ENTRY = (  # one row of the top-level `realisations` table
    Setting("n", "realisations[].n", NO_DEFAULT, "particle number N", kind="integer", low=1, required=True),
    Setting(
        "count",
        "realisations[].count",
        NO_DEFAULT,
        "realisations of this N",
        kind="integer",
        low=1,
        high=MAX_REALISATIONS,
        required=True,
    ),
)
FIGURE_OPTIONS = (  # drawing options a config may set beside a figure's cases
    Setting(
        "bars",
        "figures.fig9.bars",
        "eq43",
        "bars about the COMIC of the mean SSE: eq43 = Eq. 43 applied to SSE_mean -+ SSE_std; paper = "
        "ln(SSE_mean -+ SSE_std) - ln(SSE_mean), as the authors' script draws them (lower end unbounded where "
        "std >= mean)",
        choices=("eq43", "paper"),
    ),
)
TRADEOFF = (
    Setting(
        "times",
        "tradeoff.times",
        NO_DEFAULT,
        "times at which cost and error are tabulated (nearest step)",
        "T",
        kind="shape",
        shape=TIMES,
        range_text="times in [0, physics.t_final], each once",
        required=True,
    ),
)
MECHANISM = (
    Setting(
        "sweeps",
        "mechanism.sweeps",
        NO_DEFAULT,
        "case sweeps, each cases x n like a figure; a case in two sweeps or in Fig. 9 shares its runs",
        kind="shape",
        shape={"type": "array", "minItems": 1, "items": _ref("case_section")},
        range_text="a list of case sections",
        required=True,
    ),
    Setting(
        "n",
        "mechanism.lattice.n",
        NO_DEFAULT,
        "particles on the lattice (a particle at x = 0; the memory check may refuse fewer)",
        kind="integer",
        low=3,
        high=MAX_N,
        range_text=f"an odd integer in [3, {MAX_N:,}]",
        required=True,
    ),
    Setting(
        "cases",
        "mechanism.lattice.cases",
        NO_DEFAULT,
        "extra cases drawn as floors only, besides every mechanism model",
        kind="shape",
        shape=_ref("cases"),
        range_text="a list of mtpt cases at eta = 1",
    ),
    Setting(
        "n",
        "mechanism.fd_domain.n",
        NO_DEFAULT,
        "FD grids, as intervals on the paper's domain: dx = physics.fd_length / n",
        kind="shape",
        shape=_ref("ns"),
        range_text="even whole numbers of intervals on every length",
        required=True,
    ),
    Setting(
        "lengths",
        "mechanism.fd_domain.lengths",
        NO_DEFAULT,
        "domain lengths, the first the paper's",
        "L",
        kind="shape",
        shape=array(number(gt=0), min_length=1),
        range_text="lengths > 0 that hold the plume",
        required=True,
    ),
)
# what each object of these sections holds (the schema's description of the object itself)
SECTION_DOCS = {
    "figures": "The cases of each figure (figures.FIGURES: fig1 ... fig9; fig10 is the shear section).",
    "<section>": "Cases x n: the models drawn, the N and the realisations of each N.",
    "realisations[]": "One N and its number of realisations.",
    "seed_blocks": "Blocks of seeds run by one job (results do not depend on the blocking).",
    "claims": "Tolerances for judging the paper's claims.",
    "tradeoff": "Speed-accuracy sweep: cases x n like a figure, plus the times to tabulate.",
    "mechanism": "Controlled experiments behind figures/fig9_mechanism.png (its own target): case sweeps at "
    "shared seeds, and the Fig. 8 domain experiment.",
    "mechanism.lattice": "Noise-free SSE floors: every mechanism model (and these extra cases) run on evenly "
    "spaced particles (eta = 1 only).",
    "mechanism.fd_domain": "Fig. 8's late error: implicit FD at these grids (n = fd_length_paper / dx) on domains "
    "of these lengths, same dx.",
    "shear": "Fig. 10 (Appendix B): 2-D shear flow v_x = y - y^2, D = diag(alpha_L v_x, alpha_T v_x).",
    "optimum": "Adaptive searches for the N minimising mean COMIC (its own target: snakemake -j2 optimum; "
    "results/optimum/<name>.parquet, figures/optimum_<name>.png), one per key (letters, digits, _).",
    "scenes": "Problems of your own (scenes/scene.py, docs/scenes.md; its own target: snakemake -j2 "
    "scenes): for each, the cheapest model that reaches an accuracy, and the COMIC-best, one per key.",
    "scenes.<name>": "One scene: D, v, a source, the observation time, the domains, the candidate models and "
    "the accuracy to reach.",
    "scenes.<name>.target": "The accuracy every candidate is held to at t_final.",
    "scenes_peclet": "Where particles overtake grids: one scene (`base`) at each velocity of `v`, searched as "
    "scenes peclet-0, peclet-1, ... (names no scene of `scenes` can have) and drawn as "
    "figures/scenes_peclet.png (its own target).",
    "scenes_peclet2d": "Where particles overtake grids in 2-D: one 2-D scene (`base`) at each speed of `v` along the "
    "direction `angle`, searched as scenes peclet2d-0, peclet2d-1, ... and drawn on figures/scenes_peclet.png "
    "beside the 1-D sweep.",
    "optimum.<name>": "One search: a model, the time COMIC is judged at, an N range and a budget (runs, "
    "core-seconds or both).",
}

# ------------------------------------------------------------------------------ seeds, times, claims
SEEDS = (
    Setting(
        "base_seed",
        "base_seed",
        0,
        "realisation r of every case uses seed base_seed + r",
        kind="integer",
        low=0,
        high=MAX_SEED,
        range_text="an integer >= 0 whose seeds stay within int64 (base_seed + realisations - 1 <= 2^63 - 1)",
        required=True,
    ),
    Setting("size", "seed_blocks.size", 20, "seeds per job for N <= max_n", kind="integer", low=1, required=True),
    Setting(
        "max_n",
        "seed_blocks.max_n",
        30_000,
        "largest N run in blocks; larger N run one seed a job",
        kind="integer",
        low=0,
        required=True,
    ),
)
COMIC_TIMES = (
    Setting(
        "comic_times",
        "comic_times",
        NO_DEFAULT,
        "times at which COMIC tables and minima are reported (nearest step)",
        "T",
        kind="shape",
        shape=TIMES,
        range_text="times in [0, physics.t_final], each once",
        required=True,
    ),
)
_RANGE = array(number(), min_length=2, max_length=2)
CLAIMS = (  # the tolerances the paper's claims are judged at (analysis/claims.py); the paper's own
    Setting(
        "fd_optimum_nodes",
        "claims.fd_optimum_nodes",
        [1000, 10000],
        "allowed range of the FD COMIC optimum N, met at half the COMIC times or more",
        kind="shape",
        shape=_RANGE,
        range_text="[low, high] with low <= high",
    ),
    Setting(
        "collision_eta1_optimum",
        "claims.collision_eta1_optimum",
        [1000, 10000],
        "allowed range of the collision eta = 1 optimum N at the last COMIC time",
        kind="shape",
        shape=_RANGE,
        range_text="[low, high] with low <= high",
    ),
    Setting(
        "collision_eta05_optimum",
        "claims.collision_eta05_optimum",
        [100, 1000],
        "allowed range of the collision eta = 0.5 optimum N at the last COMIC time",
        kind="shape",
        shape=_RANGE,
        range_text="[low, high] with low <= high",
    ),
    Setting(
        "sph_flat_min_n",
        "claims.sph_flat_min_n",
        100,
        "SPH COMIC is roughly flat when, for every N >= this, |mean(N) - mean(N_opt)| <= sqrt(std(N)^2 + "
        "std(N_opt)^2) (within the +-1 std error bars of the minimum)",
        kind="integer",
        low=1,
    ),
    Setting(
        "adaptive_pt_hc_tolerance",
        "claims.adaptive_pt_hc_tolerance",
        0.05,
        "allowed |H_C - analytic| of adaptive-kernel PT at t = 1000",
        "nats",
        low=0.0,
    ),
)

# ------------------------------------------------------------------------------ an adaptive search
SEARCH = (  # one entry of `optimum`; Search's fields (analysis/optimum.py)
    Setting(
        "case",
        "optimum.<name>.case",
        NO_DEFAULT,
        "the searched model (unset dimensions from case_defaults)",
        kind="shape",
        shape=_ref("case"),
        range_text="a case",
        required=True,
    ),
    Setting(
        "time",
        "optimum.<name>.time",
        NO_DEFAULT,
        "time at which COMIC is judged (nearest recorded step)",
        "T",
        0.0,
        open_low=True,
        range_text="a number in (0, physics.t_final]",
        required=True,
    ),
    Setting(
        "n_range",
        "optimum.<name>.n_range",
        NO_DEFAULT,
        "[low, high]: the N searched (particles; FD intervals)",
        kind="shape",
        shape=array(integer(ge=1), min_length=2, max_length=2),
        range_text="integers with 1 <= low < high (FD: low >= 2)",
    ),
    Setting(
        "growth_range",
        "optimum.<name>.growth_range",
        NO_DEFAULT,
        "[low, high]: search the time-step growth factor instead of N (pt, mtpt), at the N given by `n`, "
        "in log(dt_growth - 1)",
        kind="shape",
        shape=array(number(gt=1), min_length=2, max_length=2),
        range_text="numbers with 1 < low < high",
    ),
    Setting("n", "optimum.<name>.n", NO_DEFAULT, "the N at which a growth_range search runs", kind="integer", low=1),
    Setting(
        "budget_runs",
        "optimum.<name>.budget_runs",
        NO_DEFAULT,
        "most runs (realisations x N) the search may start",
        kind="integer",
        low=1,
        range_text="an integer >= the first round's start_points x realisations",
    ),
    Setting(
        "budget_core_s",
        "optimum.<name>.budget_core_s",
        NO_DEFAULT,
        "most core-seconds the search may spend, counted by its cost model (`cost`), never measured, so the "
        "search takes the same path on every machine; round 0 always runs",
        "s",
        0.0,
        open_low=True,
        range_text="a number > 0; needs `cost`",
    ),
    Setting(
        "cost",
        "optimum.<name>.cost",
        NO_DEFAULT,
        "the cost model: [[searched value (N or dt_growth), seconds per run], ...], interpolated in log-log; "
        "calibrated once on a quiet machine by benchmarks/calibrate_search_costs.py",
        kind="shape",
        shape=array(array(number(gt=0), min_length=2, max_length=2), min_length=1, max_length=1000),
        range_text="pairs of numbers > 0 at distinct values",
    ),
    Setting(
        "width",
        "optimum.<name>.width",
        10.0,
        "stop when the bracket of the optimum is no wider than this ratio high / low N (growth: of dt_growth - 1)",
        low=1.0,
        open_low=True,
        range_text="a number in (1.1, the range's own ratio]",
    ),
    Setting(
        "initial_points",
        "optimum.<name>.initial_points",
        7,
        "points of the coarse grid over the whole range (even in log N; 7 over 30-30,000 = half decades)",
        kind="integer",
        low=3,
        range_text="an integer in [3, 1 + 2 ln(high / low) / ln(width)]: two coarse steps at least width wide",
    ),
    Setting(
        "start_points",
        "optimum.<name>.start_points",
        3,
        "round 0 runs the lowest this many coarse points; later rounds walk up the coarse grid only while the "
        "minimum may lie higher",
        kind="integer",
        low=3,
        range_text="an integer in [3, initial_points]",
    ),
    Setting(
        "measure",
        "optimum.<name>.measure",
        "own",
        "where SSE is taken: own = at the model's own points (particles, nodes; Eq. 44), points = at the "
        "measurement points common to every model (the paper's section 6, point 1; columns SSE_points, "
        "COMIC_points)",
        choices=MEASURE_NAMES,
    ),
    Setting(
        "time_volume",
        "optimum.<name>.time_volume",
        False,
        "count the time step in the sampling volume (the paper's section 6, point 3): COMIC - ln(mean dt), "
        "mean dt = time / steps taken to reach it",
        kind="boolean",
    ),
    Setting(
        "realisations",
        "optimum.<name>.realisations",
        4,
        "realisations of each newly visited N (FD: always 1)",
        kind="integer",
        low=1,
    ),
    Setting(
        "max_realisations",
        "optimum.<name>.max_realisations",
        64,
        "most realisations of one N (replication doubles them up to this)",
        kind="integer",
        low=1,
        high=MAX_REALISATIONS,
        range_text=f"an integer in [realisations, {MAX_REALISATIONS:,}]",
    ),
    Setting(
        "convention",
        "optimum.<name>.convention",
        "mean_COMIC",
        "what is minimised over N: mean_COMIC = the mean over realisations of per-realisation COMIC; "
        "COMIC_of_mean_SSE = COMIC (Eq. 43) of the mean SSE",
        choices=CONVENTION_NAMES,
    ),
)

# ------------------------------------------------------------------------------ scenes
# One entry of `scenes` (scenes/scene.py): a problem of the user's own, its exact reference
# (core/reference.py), the candidate models and the accuracy they must reach.
SCENE_MEASURES = ("rmse", "entropy", "dilution", "product", "product_rmse")
# a scene is judged at t_final, so its runs take the exact time grid, whose last step ends there:
# the authors' grid (whole growing steps while t < t_final) would judge them later (t = 51.6 for 50)
SCENE_TIME_GRID_TEXT = "exact (a scene is judged at t_final; the authors' grid steps past it)"
SOURCE_SHAPE = with_pairs(source_shape())  # the kinds of core/sources.py and core/sources2d.py
# A scene's source may let its mass out over time instead of all at t = 0 (core/release.py's Release:
# rate q from t0 until t1); the rules between these keys and t_final are core/typed.py's (Release, _Scene).
RELEASE_SHAPE = {
    "type": "object",
    "x-model": "Release",  # core/typed.py's, with the rule: until after from, each number finite
    "additionalProperties": False,
    "required": ["rate"],
    "properties": {
        "rate": {
            "type": "number",
            "exclusiveMinimum": 0,
            "description": "q, the mass released per unit time [M/T]; a number > 0 and finite",
        },
        "from": {
            "type": "number",
            "minimum": 0,
            "description": "t0, when the release starts [T]; a number >= 0 and < t_final (default 0)",
        },
        "until": {
            "oneOf": [{"type": "number", "minimum": 0}, {"type": "null"}],
            "description": "t1, when it stops [T]; a number > from, or absent (null): it releases up to t_final",
        },
    },
}
# a scene's own source: a kind and, optionally, its release (B's plume in a reaction takes none)
SCENE_SOURCE_SHAPE = {**SOURCE_SHAPE, "properties": {**SOURCE_SHAPE["properties"], "release": RELEASE_SHAPE}}
# a 2-D scene's dispersion (core/sources2d.dispersion_tensor): along and across the flow, or along the axes
DISPERSION_2D_SHAPE = {
    "type": "object",
    "x-model": "Dispersion",  # core/typed.py's, with the rule: both of L, T or both of x, y
    "additionalProperties": False,
    "properties": {k: {"type": "number", "exclusiveMinimum": 0} for k in ("L", "T", "x", "y")},
    "oneOf": [{"required": ["L", "T"]}, {"required": ["x", "y"]}],
}
CANDIDATE_SHAPE = {
    "type": "array",
    "minItems": 1,
    "items": {
        "type": "object",
        "x-model": "Candidate",  # core/typed.py's, with the rules between these keys
        "additionalProperties": False,
        "required": ["method", "kernel"],
        "properties": {
            "method": _ref("method"),
            "kernel": _ref("kernel"),
            "eta": _ref("eta"),
            "truncation": _ref("truncation"),
            "dt_growth": _ref("dt_growth"),
            "scheme": _ref("scheme"),
            "advection": {
                "type": "string",
                "enum": list(ADVECTION_SCHEMES),
                "description": f"FD's advection scheme in a flow; one of {', '.join(ADVECTION_SCHEMES)}",
            },
            "fd_dt": {
                "type": "number",
                "exclusiveMinimum": 0,
                "description": "FD's step, fixed in time [T]; a number > 0",
            },
            "courant": {
                "type": "number",
                "exclusiveMinimum": 0,
                "description": "FD's step in a flow as its Courant number |v| dt / dx; a number > 0 ("
                + ", ".join(f"<= {limit:g} for {scheme}" for scheme, limit in COURANT_LIMIT.items())
                + ")",
            },
            "n_range": {
                "type": "array",
                "items": {"type": "integer", "minimum": 2},
                "minItems": 2,
                "maxItems": 2,
                "description": "the resolutions searched: [low, high], integers with 2 <= low < high (FD: even)",
            },
            "ladder": {
                "type": "array",
                "items": {"type": "integer", "minimum": 2},
                "minItems": 2,
                "description": "the resolutions searched, written out: at least two integers >= 2, ascending "
                "(instead of n_range)",
            },
            "time_grid": {"type": "string", "enum": ["exact"], "description": SCENE_TIME_GRID_TEXT},
            "dt0": {
                "type": "number",
                "exclusiveMinimum": 0,
                "description": "a particle candidate's first time step, instead of `time.dt0` (with dt_growth 1 a "
                "fixed step) [T]; a number > 0",
            },
        },
        "oneOf": [{"required": ["n_range"]}, {"required": ["ladder"]}],
    },
}
# A scene's reach around its plume at t_final, in sqrt(4 D t_final): the paper's fd_length [-6, 6]
# at t = 1000, whose 15 measurement points span it and whose zero ends absorb 2 erfc(3) = 4.4e-5 of
# the mass by then. A scene's points span its plume this far, and its FD window reaches at least as far.
SCENE_REACH = 3.0
SCENE_MIN_MARGIN = SCENE_REACH * math.sqrt(2.0)  # the same in the margin's unit sqrt(2 D t_final): 4.24
SCENE = (
    Setting(
        "D",
        "scenes.<name>.D",
        1e-3,
        "dispersion coefficient; in 2-D the tensor {L: D_L, T: D_T} along and across the flow (D = D_T I + "
        "(D_L - D_T) v v^T / |v|^2), or {x: Dx, y: Dy} along the axes (at v = 0 this one)",
        "L^2/T",
        kind="shape",
        shape={"oneOf": [{"type": "number", "exclusiveMinimum": 0}, DISPERSION_2D_SHAPE]},
        range_text="a number > 0 (1-D), or {L, T} or {x, y}, each a number > 0 (2-D)",
    ),
    Setting(
        "v",
        "scenes.<name>.v",
        0.0,
        "uniform velocity; [vx, vy] in 2-D",
        "L/T",
        kind="shape",
        shape={"oneOf": [{"type": "number"}, pair_shape()]},
        range_text="a finite number (1-D) or a pair [vx, vy] of finite numbers (2-D)",
    ),
    Setting("t_final", "scenes.<name>.t_final", 1000.0, "observation time", "T", 0.0, open_low=True),
    Setting(
        "source",
        "scenes.<name>.source",
        {"kind": "point", "x0": 0.0},
        f"the initial plume, unit mass: {source_forms()}; in 2-D the same with pairs: {source_forms_2d()}; any "
        "kind may add release: {rate: q, from: t0, until: t1}, its mass let out at q per unit time from t0 until "
        "t1 (absent or null: up to t_final) instead of all at t = 0",
        kind="shape",
        shape=SCENE_SOURCE_SHAPE,
        range_text=f"{source_ranges()}; a release's rate > 0, 0 <= from < t_final, until > from (none in a reactive "
        "scene)",
    ),
    Setting(
        "reaction",
        "scenes.<name>.reaction",
        NO_DEFAULT,
        f"a reaction of the source's species A (core/reactions.py): {reaction_kinds_text()}; absent: a "
        "conservative plume",
        kind="shape",
        shape=reaction_shape(SOURCE_SHAPE),
        range_text=reaction_ranges_text(),
    ),
    Setting(
        "margin",
        "scenes.<name>.margin",
        6.0,
        "the domains follow as the source's extent plus this many sqrt(2 D t_final) on either side: the "
        "particles' Omega and the FD window (the FD grid adds the path v t_final)",
        low=SCENE_MIN_MARGIN,
        high=100.0,
        range_text=f"a number in [3 sqrt 2 = {SCENE_MIN_MARGIN:.6g}, 100]: the window must reach 3 sqrt(4 D t_final) "
        "beyond the source, as the paper's [-6, 6] at t = 1000 (its zero ends absorb 2 erfc(3) = 4.4e-5 of the "
        "mass by then); a narrower one loses the plume through them",
    ),
    Setting("omega", "scenes.<name>.omega", NO_DEFAULT, "particle domain (instead of margin)", "L", 0.0, open_low=True),
    Setting(
        "fd_length",
        "scenes.<name>.fd_length",
        NO_DEFAULT,
        "FD window around the plume (instead of margin); the grid adds the path v t_final",
        "L",
        0.0,
        open_low=True,
        range_text="a number >= the source's extent + 2 x 3 sqrt(4 D t_final), the paper's reach (its [-6, 6] at "
        "t = 1000)",
    ),
    Setting(
        "measure",
        "scenes.<name>.target.measure",
        "rmse",
        "the error judged at t_final: rmse = concentration RMSE at the common measurement points (of A in a "
        "reactive scene) [1/L]; entropy = |H_C - its exact value| [nats]; dilution = |E / E_exact - 1|; product "
        "= |M_C / M_C,ref - 1|, the product's mass, and product_rmse = the RMSE of the product's concentration C_C at "
        "the points [1/L] (reactive scenes only)",
        choices=SCENE_MEASURES,
    ),
    Setting(
        "value",
        "scenes.<name>.target.value",
        NO_DEFAULT,
        "the accuracy to reach: the mean error's one-sided 95 % upper bound at most this",
        "-",
        0.0,
        open_low=True,
        required=True,
    ),
    Setting(
        "realisations",
        "scenes.<name>.realisations",
        8,
        "realisations at each visited resolution of a particle candidate (FD runs once)",
        kind="integer",
        low=2,
        high=MAX_REALISATIONS,
    ),
    Setting(
        "max_realisations",
        "scenes.<name>.max_realisations",
        NO_DEFAULT,
        "the most realisations of a particle rung: one whose 95 % interval straddles the target (lower bound "
        "below it, upper bound above) gets another seed block of `realisations` until it falls on one side or "
        "reaches this many (default 4 x realisations: the bound's half-width halves, and a rung costs at most "
        "what the rung two above it costs at `realisations`)",
        kind="integer",
        low=2,
        high=MAX_REALISATIONS,
        range_text=f"a multiple of realisations in [realisations, {MAX_REALISATIONS:,}] (default 4 x realisations)",
    ),
    Setting(
        "cost",
        "scenes.<name>.cost",
        {"fd": [3.85e-5, 1.72e-8], "pt": [7.99e-5, 3.71e-8], "mtpt": [8.37e-5, 2.02e-7]},
        "the cost model of a run, by method: [seconds a time step, seconds a unit of work] (work = node- or "
        "particle-steps); counted, never timed, so the answer is the same on every machine (fitted by "
        "benchmarks/calibrate_scene_costs.py to 88 runs of the shipped scenes, Intel Xeon, 2026-12-03; a 2-D scene's "
        "default is settings.PLANE_COST, fitted to 2-D runs); a reactive "
        "scene's run: its steps' part and its work's part times its method's factor (settings.REACTIVE_COST)",
        "s",
        kind="shape",
        shape=dict[Literal[METHODS], array(number(ge=0), min_length=2, max_length=2)],
        range_text="per method fd, pt, mtpt: [seconds a step, seconds a unit of work], numbers >= 0",
    ),
    Setting(
        "budget",
        "scenes.<name>.budget",
        NO_DEFAULT,
        "the most a run may cost, counted by `cost` before it runs: rungs above it are not run, and a "
        "candidate that meets the target only above it does not meet it (none: no limit)",
        "s",
        0.0,
        open_low=True,
    ),
    Setting(
        "candidates",
        "scenes.<name>.candidates",
        NO_DEFAULT,
        "the models to compare: method, kernel and case dimensions, n_range [low, high] (particles or FD "
        f"intervals) or a ladder of its own [n1, n2, ...]; FD candidates may set advection "
        f"({', '.join(ADVECTION_SCHEMES)}) and a step fixed in time, fd_dt, or, in a flow, one that follows the "
        "grid, courant (dt = courant dx / |v|, > 0; "
        + ", ".join(f"<= {limit:g} for {scheme}" for scheme, limit in COURANT_LIMIT.items())
        + "; at v = 0 fd_dt is used)",
        kind="shape",
        shape=CANDIDATE_SHAPE,
        range_text="a list of models, each with 2 <= n_range low < high, or a ladder of ascending integers >= 2",
        required=True,
    ),
)

# A reactive scene's run (models/simulate.py with its reaction) against its transport's, which `cost` prices: per
# method, the factors on the counted cost's step part and work part, [x seconds a step, x seconds a
# unit of work] (Scene.cost_model). MTPT moves three species through the transfer matrix and reacts
# every particle; PT pairs A with B (Benson & Meerschaert) but draws no per-step measures; FD
# solves A, B and C and reacts every node (reactive / conservative 1.17, range 0.95-1.46). Fitted by
# benchmarks/reactive_cost.py (nnls, relative) to the 40 rungs of the shipped reactive scenes, each
# run beside its conservative run, CPU seconds, AMD EPYC, 2 vCPU, 2026-12-04, at 9049350: `python
# benchmarks/reactive_cost.py`. Factors, not seconds, so a scene's own `cost` carries over.
REACTIVE_COST = {"fd": (1.08, 1.45), "mtpt": (0.902, 1.58), "pt": (0.474, 2.64)}
# A 2-D scene's default cost model, per method [seconds a step, seconds a unit of work]: work is FD's
# (n + 1)^2 node-steps and the particles' N particle-steps (core/runcost.units_per_step). Fitted by
# `python benchmarks/calibrate_scene_costs.py --max-s 10 plume2d oblique` (24 runs at 6 sd MTPT cut-off,
# after kde_2d's bounded chunks; Intel Xeon, 2 vCPU, load 0.2; measured / fitted: medians 0.97-1.09, worst
# 1.33-2.07, the worst FD's n = 32 run, 0.02 s of overhead).
PLANE_COST = {"fd": (7.27e-4, 1.02e-7), "mtpt": (0.0, 9.89e-7), "pt": (1.57e-3, 4.57e-7)}


SCENES_PECLET = (
    Setting(
        "base",
        "scenes_peclet.base",
        NO_DEFAULT,
        "a scene without its v (the keys of scenes.<name>); each velocity of `v` makes one scene of it",
        kind="shape",
        shape=dict,
        range_text="a scene (scenes.<name>) without v",
        required=True,
    ),
    Setting(
        "v",
        "scenes_peclet.v",
        NO_DEFAULT,
        "the velocities, ascending; the Peclet number of each is v L / D (L: the base's FD window)",
        "L/T",
        kind="shape",
        shape=array(number(ge=0), min_length=2),
        range_text="at least two numbers >= 0, ascending",
        required=True,
    ),
)

SCENES_PECLET2D = (
    Setting(
        "base",
        "scenes_peclet2d.base",
        NO_DEFAULT,
        "a 2-D scene without its v (the keys of scenes.<name>, D as {L, T}); each speed of `v` makes one scene of it",
        kind="shape",
        shape=dict,
        range_text="a 2-D scene (scenes.<name>) without v",
        required=True,
    ),
    Setting(
        "v",
        "scenes_peclet2d.v",
        NO_DEFAULT,
        "the speeds |v|, ascending; the Peclet number of each is |v| L / D_L (L: the base's FD window)",
        "L/T",
        kind="shape",
        shape=array(number(gt=0), min_length=2),
        range_text="at least two numbers > 0, ascending (D_L and D_T act along and across a flow)",
        required=True,
    ),
    Setting(
        "angle",
        "scenes_peclet2d.angle",
        0.0,
        "the flow's direction, counter-clockwise from the grid's x axis: v = |v| (cos angle, sin angle)",
        "degrees",
        low=-180.0,
        high=180.0,
    ),
)

DECLARED = (
    *SETTINGS,
    *SEEDS,
    *COMIC_TIMES,
    *CLAIMS,
    *CASE_SECTION,
    *REALISATIONS_ENTRY,
    *FIGURE_OPTIONS,
    *TRADEOFF,
    *SCENE,
    *SCENES_PECLET,
    *SCENES_PECLET2D,
    *MECHANISM,
    *SHEAR,
    *SEARCH,
)
BY_KEY = {s.key: s for s in DECLARED}  # every declared setting by its config key
