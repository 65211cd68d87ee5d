"""Numbers in prose, rendered: the spots of README.md and docs/*.md that quote a code constant or a
result, filled from their one source (as showyourwork's variables are).

A spot is marked in the Markdown: inline ``<!-- value NAME -->2000<!-- /value -->``, or a block
(a table) between the lines ``<!-- table NAME -->`` and ``<!-- /table -->``. Code constants
(``code_values``: the bootstrap's resamples and confidence, the scene search's tolerances, the
config file caps, the transfer tolerance) are read from the modules that use them. Results (the
scene table, the Peclet sweep, its crossover) are read from docs/numbers.json, a small committed
file that ``numbers_from_tables`` writes from the scene tables (results/scenes/<name>.parquet): the
workflow's rule ``scene_numbers`` writes the same file as results/scenes_numbers.json.

    python -m particle_entropy.pipeline.prose --check                  # exit 1 while a spot is stale
    python -m particle_entropy.pipeline.prose --write                  # render the spots in place
    python -m particle_entropy.pipeline.prose --from results --write   # docs/numbers.json from a run, then render

Every name must be marked somewhere and every marker must name a known value, so a spot cannot
be dropped or misspelt unnoticed. A marker right after a backtick is quoted, as in `<!-- value X -->`,
and left alone.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import pandas as pd

from ..analysis import resampling, scene_search
from ..analysis.optimum import SEARCH_DEFAULTS
from ..core.labels import integer, interval
from ..core.registry import FGT_TOLERANCE, MEASUREMENT_POINTS
from ..core.runconfig import GRID_SPACING, MAX_GRID_POINTS
from ..core.settings import REACTIVE_COST, SCENE, SCENE_MIN_MARGIN, defaults
from ..core.timegrid import MAX_STEPS
from ..scenes import scene
from ..scenes.scene import sweep_of
from . import configcheck, joblogs

PAGES = ("README.md", "docs/*.md")  # where spots may be marked (globs under the repository root)
NUMBERS = "docs/numbers.json"
COMMAND = ".venv/bin/python -m particle_entropy.pipeline.prose"
INLINE = re.compile(r"(?<!`)<!-- value (?P<name>[\w.-]+) -->(?P<text>.*?)<!-- /value -->", re.S)
BLOCK = re.compile(r"^<!-- table (?P<name>[\w.-]+) -->\n(?P<text>.*?)^<!-- /table -->$", re.S | re.M)
OPENERS = re.compile(r"(?<!`)<!-- (?P<kind>value|table) (?P<name>[\w.-]+) -->")
CLOSERS = {"value": "<!-- /value -->", "table": "<!-- /table -->"}
SIGNIFICANT = 2  # significant digits of a counted cost [s]
ABBREVIATED = {"fd": "FD", "pt": "PT", "mtpt": "MTPT"}
PARTICLES = ("pt", "mtpt")
SEARCH_KEYS = ("width", "realisations", "max_realisations", "initial_points", "start_points")  # quoted defaults


# ------------------------------------------------------------------------------ formatting
def seconds(x: float) -> str:
    """A counted cost to SIGNIFICANT digits, without an exponent below 1e4: 0.000356 -> '0.00036'."""
    return f"{float(x):.{SIGNIFICANT}g}"


def power(x: float) -> str:
    """A small tolerance as the prose writes it: 0.001 -> '1e-3', 2.5e-12 -> '2.5e-12'."""
    mantissa, exponent = f"{float(x):e}".split("e")
    return f"{float(mantissa):g}e{int(exponent)}"


def exponent(n: int) -> str:
    """A power of ten as 10^k (100_000_000 -> '10^8'), any other integer with separators."""
    k = round(math.log10(n)) if n > 0 else 0
    return f"10^{k}" if n == 10**k else integer(n)


def percent(x: float) -> str:
    """A fraction as a percentage: 0.95 -> '95 %'."""
    return f"{100 * float(x):g} %"


def model(label: str) -> str:
    """A candidate's label with its method abbreviated as in prose: 'pt adaptive' -> 'PT adaptive'."""
    method, _, rest = label.partition(" ")
    return f"{ABBREVIATED.get(method, method)} {rest}".strip()


def target(measure: str, value: float) -> str:
    """A scene's target in words: RMSE <= 0.1, H_C within 0.01 nats, E within 1 %, product within 2 %."""
    if measure == "product":
        return f"product mass within {percent(value)}"
    if measure == "product_rmse":
        return f"RMSE of C_C <= {value:g}"
    if measure == "entropy":
        return f"H_C within {value:g} nats"
    if measure == "dilution":
        return f"E within {percent(value)}"
    return f"RMSE <= {value:g}"


# ------------------------------------------------------------------------------ code constants
def code_values() -> dict[str, str]:
    """The constants quoted in prose, each from the module that uses it."""
    d = defaults(SCENE)
    cost = ", ".join(f"{ABBREVIATED[m]} {a:.3g} s a step + {b:.3g} s a unit" for m, (a, b) in d["cost"].items())
    factors = ", ".join(
        f"{ABBREVIATED[m]} {a:.3g} on the steps, {b:.3g} on the work" for m, (a, b) in REACTIVE_COST.items()
    )
    return {
        "scenes.physics": f"{power(d['D'])}, {d['v']:g}, {d['t_final']:g}",
        "scenes.margin": f"{d['margin']:g}",
        "scenes.realisations": str(d["realisations"]),
        "scenes.cost": cost,
        "settings.REACTIVE_COST": factors,
        "scene.MAX_BLOCKS": str(scene.MAX_BLOCKS),
        "settings.SCENE_MIN_MARGIN": f"{SCENE_MIN_MARGIN:.3g}",
        "registry.MEASUREMENT_POINTS": str(MEASUREMENT_POINTS),
        "registry.FGT_TOLERANCE": power(FGT_TOLERANCE),
        "resampling.N_RESAMPLES": str(resampling.N_RESAMPLES),
        "resampling.CONFIDENCE": percent(resampling.CONFIDENCE),
        "scene_search.NEGATIVE_TOLERANCE": power(scene_search.NEGATIVE_TOLERANCE),
        "scene_search.MASS_LOSS_MAX": power(scene_search.MASS_LOSS_MAX),
        "configcheck.MAX_CONFIG_BYTES": f"{configcheck.MAX_CONFIG_BYTES / 1e6:g} MB",
        "configcheck.MAX_VALUES": integer(configcheck.MAX_VALUES),
        "configcheck.MAX_DEPTH": str(configcheck.MAX_DEPTH),
        "timegrid.MAX_STEPS": integer(MAX_STEPS),
        "runconfig.MAX_GRID_POINTS": exponent(MAX_GRID_POINTS),
        "runconfig.GRID_SPACING": f"{GRID_SPACING:g}",
        "joblogs.TAIL_LINES": str(joblogs.TAIL_LINES),
        **{f"optimum.{key}": f"{SEARCH_DEFAULTS[key]:g}" for key in SEARCH_KEYS},
    }


# ------------------------------------------------------------------------------ results -> numbers
def _reasons(rows: pd.DataFrame) -> list[str]:
    """Why a candidate's rungs went unscored, each reason once, without its particulars:
    'negative concentrations from step 1 (t = 0.01): minimum ...' -> 'negative concentrations'."""
    heads = [re.split(r" from step |:", str(u))[0].strip() for u in rows["unscored"] if str(u)]
    return list(dict.fromkeys(h for h in heads if h))


def candidate_summary(rows: pd.DataFrame) -> dict:
    """One candidate of a scene table: its label and method, and its answer (the smallest rung that
    meets the target, the failing rung below it, its counted cost and realisations) or, when it
    meets it nowhere, the top rung run and why rungs went unscored."""
    rows = rows.sort_values("n")
    first = rows.iloc[0]
    out = {"candidate": int(first["candidate"]), "label": str(first["label"]), "method": str(first["method"])}
    meets = rows[rows["meets"]]
    if len(meets):
        best = meets.iloc[0]
        below = float(best["n_below"])
        out["answer"] = {
            "n": int(best["n"]),
            "n_below": int(below) if math.isfinite(below) else None,
            "cost_s": float(best["cost_s"]),
            "realisations": int(best["realisations"]),
        }
        holds = best.get("holds_at_half_step")
        if holds is False:  # it misses the target at half its step: the answer depends on its step
            out["answer"]["half_step_error"] = float(best["half_step_error"])
    else:
        run = rows[rows["realisations"] > 0]
        out["answer"] = None
        out["top_n"] = int(run["n"].max()) if len(run) else None
        out["reasons"] = _reasons(rows)
        out["stopped"] = str(first["stopped"])
    out["recommended"] = bool(rows["recommended"].any())
    return out


def scene_summary(table: pd.DataFrame) -> dict:
    """A finished scene (scene_search.result): its Peclet number, target, every searched candidate
    (an at-rest twin repeats another's runs and is left out) and the COMIC-best rung."""
    first = table.iloc[0]
    own = table[~table["stopped"].astype(str).str.startswith("the same runs as")]
    best = table[table["comic_best"]]
    return {
        "scene": str(first["scene"]),
        "peclet": float(first["peclet"]),
        "measure": str(first["measure"]),
        "target": float(first["target"]),
        "candidates": [candidate_summary(rows) for _, rows in own.groupby("candidate", sort=True)],
        "comic_best": {"label": str(best.iloc[0]["label"]), "n": int(best.iloc[0]["n"])} if len(best) else None,
    }


def _best(summary: dict, methods: Sequence[str]) -> dict | None:
    """The cheapest answer among a scene's candidates of these methods (None: none meets the target)."""
    met = [c for c in summary["candidates"] if c["method"] in methods and c["answer"]]
    met = [c for c in met if "half_step_error" not in c["answer"]]  # an answer that depends on its step
    return min(met, key=lambda c: c["answer"]["cost_s"], default=None)


def _finite(x) -> float | None:
    """A float for JSON: None for NaN (an FD rung at rest has no grid Peclet or Courant number)."""
    return float(x) if math.isfinite(float(x)) else None


def _crossover(tables: list[pd.DataFrame], dim: int = 1) -> list[float] | None:
    found = scene_search.crossover(scene_search.peclet_table(tables), dim) if tables else None
    return list(found) if found else None


def numbers_from_tables(tables: Sequence[pd.DataFrame]) -> dict:
    """The numbers prose quotes, from finished scene tables: the user's scenes by name, each Peclet
    sweep's (scenes/scene.SWEEPS: `sweep` in 1-D, `sweep2d`) by Peclet number with the best grid and
    particle answer of each, and its crossover; in 1-D also against the implicit schemes alone (no tvd)."""
    tables = sorted(tables, key=lambda t: str(t["scene"].iloc[0]))
    dims = [(sweep_of(str(t["scene"].iloc[0])) or (None, 0))[1] for t in tables]
    user = [t for t, d in zip(tables, dims) if not d]
    out = {"scenes": [scene_summary(t) for t in user]}
    for dim, key in ((1, "sweep"), (2, "sweep2d")):
        sweep = sorted((t for t, d in zip(tables, dims) if d == dim), key=lambda t: float(t["peclet"].iloc[0]))
        if dim == 2 and not sweep:
            continue  # a config without a 2-D sweep: its numbers, as before
        out[key] = [_sweep_row(t) for t in sweep]
        out["crossover" if dim == 1 else "crossover2d"] = _crossover(sweep, dim)
        if dim == 1:
            implicit = [t[~t["label"].str.contains(" tvd ", regex=False)] for t in sweep]
            out["crossover_implicit"] = _crossover(implicit, dim)
    return out


def _sweep_row(t: pd.DataFrame) -> dict:
    """A sweep scene's row: its Peclet number, target, best grid and particle answers, which is cheaper."""
    s = scene_summary(t)
    grid, particles = _best(s, ("fd",)), _best(s, PARTICLES)
    cheaper = particles is not None and (grid is None or particles["answer"]["cost_s"] < grid["answer"]["cost_s"])
    fd_row = t[(t["label"] == grid["label"]) & (t["n"] == grid["answer"]["n"])].iloc[0] if grid else None
    return {
        "scene": s["scene"],
        "peclet": s["peclet"],
        "measure": s["measure"],
        "target": s["target"],
        "grid": grid,
        "grid_peclet": _finite(fd_row["grid_peclet"]) if fd_row is not None else None,
        "courant": _finite(fd_row["courant"]) if fd_row is not None else None,
        "particles": particles,
        "particles_cheaper": cheaper,
    }


def numbers_from_results(results: str | Path) -> dict:
    """numbers_from_tables over every scene table in ``results``/scenes."""
    from ..core.io import read_parquet

    return numbers_from_tables([read_parquet(p) for p in sorted(Path(results, "scenes").glob("*.parquet"))])


def dump(numbers: Mapping) -> str:
    """The numbers file's text: sorted keys, two-space indent, a final newline (byte-stable)."""
    return json.dumps(numbers, indent=2, sort_keys=True, allow_nan=False) + "\n"


# ------------------------------------------------------------------------------ results -> prose
def _answer(c: Mapping, with_label: bool = True) -> str:
    """'PT adaptive, N in (668, 1,243], 0.016 s (16 realisations)'; unmet: 'not met up to n = ...'."""
    symbol = "N" if c["method"] in PARTICLES else "n"
    name = f"{model(c['label'])}, " if with_label else ""
    a = c["answer"]
    if a is None:
        why = f" ({', '.join(c['reasons'])})" if c.get("reasons") else ""
        top = f" up to {symbol} = {integer(c['top_n'])}" if c.get("top_n") else f" ({c['stopped']})"
        return f"{name}not met{top}{why}"
    runs = f" ({a['realisations']} realisations)" if c["method"] in PARTICLES else ""
    below = a["n_below"]
    rungs = f"{symbol} = {integer(a['n'])}" if below is None else f"{symbol} in {interval(below, a['n'])}"
    step = ""
    if "half_step_error" in a:
        step = f", but not at half its step (error {a['half_step_error']:.2g} there): depends on its step"
    return f"{name}{rungs}, {seconds(a['cost_s'])} s{runs}{step}"


def scene_table(numbers: Mapping) -> str:
    """The scene table of docs/scenes.md: per scene its Peclet number, target, the cheapest candidate that
    meets it, every other candidate's answer and the COMIC-best rung."""
    lines = [
        "| scene | Péclet v L / D | target at t_final | cheapest that meets it (interval of n, counted cost a run) "
        "| the other candidates | COMIC-best at the common points |",
        "|---|---:|---|---|---|---|",
    ]
    for s in numbers["scenes"]:
        chosen = [c for c in s["candidates"] if c["recommended"]]
        others = [c for c in s["candidates"] if not c["recommended"]]
        cheapest = _answer(chosen[0]) if chosen else "none"
        rest = "; ".join(_answer(c) for c in others) or "–"
        best = s["comic_best"]
        comic = f"{model(best['label'])}, n = {integer(best['n'])}" if best else "–"
        lines.append(
            f"| `{s['scene']}` | {integer(s['peclet'])} | {target(s['measure'], s['target'])} | {cheapest} "
            f"| {rest} | {comic} |"
        )
    return "\n".join(lines) + "\n"


def sweep_table(numbers: Mapping, key: str = "sweep") -> str:
    """A Peclet sweep of docs/scenes.md (``key``: sweep, sweep2d): per Peclet number the cheapest grid
    and particle answers."""
    lines = [
        "| Pe | best grid: scheme, n, grid Péclet, Courant, counted cost | best particles: N, counted cost | cheaper |",
        "|---:|---|---|---|",
    ]
    for r in numbers[key]:
        g, p = r["grid"], r["particles"]
        grid = "none meets it"
        if g:
            flow = (
                f", grid Péclet {r['grid_peclet']:.2g}, Courant {r['courant']:.2g}"
                if r["grid_peclet"] is not None
                else ""
            )
            grid = f"{model(g['label'])}, n = {integer(g['answer']['n'])}{flow}, {seconds(g['answer']['cost_s'])} s"
        particles = _answer(p) if p else "none meets it"
        lines.append(
            f"| {integer(r['peclet'])} | {grid} | {particles} | {'particles' if r['particles_cheaper'] else 'grid'} |"
        )
    return "\n".join(lines) + "\n"


def result_values(numbers: Mapping) -> dict[str, str]:
    """The inline numbers of the results: the crossovers and the sweep's target."""
    out = {}
    for key in ("crossover", "crossover_implicit", *(("crossover2d",) if "sweep2d" in numbers else ())):
        found = numbers.get(key)
        out[f"scenes.{key}"] = interval(*found) if found else "none in the sweep"
    for key in ("sweep", "sweep2d"):
        sweep = numbers.get(key) or []
        if sweep:
            out[f"scenes.{key}_target"] = target(sweep[0]["measure"], sweep[0]["target"])
    ratio = orientation_cost(numbers)
    if ratio is not None:
        out["scenes.orientation_cost"] = f"{ratio:.2g}"
    out.update(benchmark_answers(numbers))
    return out


ORIENTED = ("plume2d", "oblique")  # the shipped 2-D pair: one plume along the grid and at 45 degrees to it


def orientation_cost(numbers: Mapping) -> float | None:
    """The counted cost of oblique's answer over plume2d's (ORIENTED): what carrying the same plume at
    45 degrees to the grid costs the cheapest model; None unless both scenes have an answer."""
    cost = {}
    for s in numbers.get("scenes", []):
        chosen = [c for c in s["candidates"] if c["recommended"]]
        if s["scene"] in ORIENTED and chosen:
            cost[s["scene"]] = chosen[0]["answer"]["cost_s"]
    return cost[ORIENTED[1]] / cost[ORIENTED[0]] if len(cost) == 2 else None


BENCHMARKS = ("mt3dms_p03", "mt3dms_p04")  # MT3DMS's example problems 3 and 4, whose answers the README quotes


def benchmark_answers(numbers: Mapping) -> dict[str, str]:
    """Each BENCHMARKS scene's target and answer, as the README quotes them: 'E within 2 %' and 'FD implicit
    tvd Cr=0.75, n in (64, 128], 0.073 s' (the cheapest candidate that meets it, or 'no candidate'); none
    for a scene the numbers do not hold."""
    out = {}
    for s in numbers.get("scenes", []):
        if s["scene"] in BENCHMARKS:
            chosen = [c for c in s["candidates"] if c["recommended"]]
            out[f"scenes.{s['scene']}.target"] = target(s["measure"], s["target"])
            out[f"scenes.{s['scene']}.answer"] = _answer(chosen[0]) if chosen else "no candidate"
    return out


def result_blocks(numbers: Mapping) -> dict[str, str]:
    """The tables of the results."""
    out = {"scenes.table": scene_table(numbers), "scenes.sweep": sweep_table(numbers)}
    if numbers.get("sweep2d"):
        out["scenes.sweep2d"] = sweep_table(numbers, "sweep2d")
    return out


# ------------------------------------------------------------------------------ marked spots
def render(text: str, values: Mapping[str, str], blocks: Mapping[str, str]) -> tuple[str, list[str]]:
    """``text`` with every marked spot filled, and its problems: a marker naming no known value, or
    one never closed."""
    problems = []
    for m in OPENERS.finditer(text):
        kind, name = m["kind"], m["name"]
        known = values if kind == "value" else blocks
        if name not in known:
            problems.append(f"line {text.count(chr(10), 0, m.start()) + 1}: no {kind} named {name!r}")
        if text.find(CLOSERS[kind], m.end()) < 0:
            problems.append(f"line {text.count(chr(10), 0, m.start()) + 1}: {kind} {name!r} is never closed")

    def fill(known: Mapping[str, str], kind: str) -> Callable[[re.Match], str]:
        def sub(m: re.Match) -> str:
            body = known.get(m["name"], m["text"])
            if kind == "value":
                return f"<!-- value {m['name']} -->{body}<!-- /value -->"
            return f"<!-- table {m['name']} -->\n{body}<!-- /table -->"

        return sub

    text = BLOCK.sub(fill(blocks, "table"), text)
    return INLINE.sub(fill(values, "value"), text), problems


def marked(text: str) -> set[str]:
    """The names marked in ``text``."""
    return {m["name"] for m in OPENERS.finditer(text)}


def pages(root: Path) -> list[Path]:
    return sorted({p for pattern in PAGES for p in root.glob(pattern)})


def load(root: Path, numbers_path: Path | None = None) -> tuple[dict[str, str], dict[str, str]]:
    """Every known value and block: the code's constants and the committed numbers' results."""
    numbers = json.loads((numbers_path or root / NUMBERS).read_text(encoding="utf-8"))
    return {**code_values(), **result_values(numbers)}, result_blocks(numbers)


def check(root: Path, values: Mapping[str, str], blocks: Mapping[str, str], write: bool = False) -> list[str]:
    """Problems of the marked pages under ``root`` (empty: every spot is current): a stale spot, a
    bad marker, a known name marked nowhere. With ``write``, stale spots are rendered in place."""
    problems, seen = [], set()
    for path in pages(root):
        text = path.read_text(encoding="utf-8")
        new, bad = render(text, values, blocks)
        rel = path.relative_to(root)
        problems += [f"{rel}: {b}" for b in bad]
        seen |= marked(text)
        if new != text:
            if write:
                path.write_text(new, encoding="utf-8")
            else:
                stale = sorted({m["name"] for m in OPENERS.finditer(text)} - _current(text, new))
                problems.append(f"{rel}: stale: {', '.join(stale)}")
    problems += [f"no marker for {name}" for name in sorted((set(values) | set(blocks)) - seen)]
    return problems


def _current(old: str, new: str) -> set[str]:
    """The names whose spots ``render`` left unchanged (old and new texts of one page)."""

    def spots(text: str) -> dict[str, list[str]]:
        found: dict[str, list[str]] = {}
        for m in [*INLINE.finditer(text), *BLOCK.finditer(text)]:
            found.setdefault(m["name"], []).append(m["text"])
        return found

    a, b = spots(old), spots(new)
    return {name for name in a if a[name] == b.get(name)}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m particle_entropy.pipeline.prose",
        description="Render the numbers quoted in README.md and docs/*.md from the code and docs/numbers.json.",
    )
    parser.add_argument("--root", default=".", help="the repository root (default: .)")
    parser.add_argument("--numbers", help=f"the numbers file (default: ROOT/{NUMBERS})")
    parser.add_argument("--from", dest="results", help="a results folder: write the numbers file from its scene tables")
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="render every marked spot in place")
    mode.add_argument("--check", action="store_true", help="exit 1 while a marked spot differs from its rendering")
    args = parser.parse_args(argv)
    root = Path(args.root)
    numbers_path = Path(args.numbers) if args.numbers else root / NUMBERS
    if args.results:
        fresh = dump(numbers_from_results(args.results))
        if args.write:
            numbers_path.write_text(fresh, encoding="utf-8")
        elif numbers_path.read_text(encoding="utf-8") != fresh:
            print(f"{numbers_path} differs from the scene tables of {args.results}", file=sys.stderr)
            return 1
    problems = check(root, *load(root, numbers_path), write=args.write)
    for p in problems:
        print(p, file=sys.stderr)
    if problems and not args.write:
        print(f"run `{COMMAND} --write` from the repository root to render them", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    raise SystemExit(main())
