"""How a reactive answer moves with the time step, per method, at fixed resolution (issue 50 point 8).

    python benchmarks/reactive_step.py [--scene carried_reaction|front] [--only fd-tvd fd-upwind mtpt pt]
        [--seeds mtpt=16 pt=16] [--n mtpt=4000] [--halvings mtpt=3] [--growths 1.05 1.02 1.01 1.005]
        [--fixed 0.1]

Scenes: ``carried_reaction`` is issue 50's carried reaction (written out here so that the benchmark
stays put if the config moves): a Gaussian A (x0 0, sd 0.02) carried by v 0.5 with D 1e-4 to t_final
50 through a uniform B of 0.3, A + B -> C at k 2, target product_rmse 0.005. ``front`` is the shipped
scene of config.yaml (--config): boxes of A and B side by side, carried 10 L, target |product| 0.02.
The candidates are the benchmark's own, each at one resolution (--n KEY=N; defaults below, the FD
ones the rung each scene recommends): FD TVD at Courant 0.75 and FD upwind at Courant 0.5 (n), MTPT
collision eta 1 and PT adaptive (N), MTPT at the default dt_growth (run_settings.DT_GROWTH), PT at 1.01.

Steps: each candidate runs at its own step and at that step halved --halvings times (KEY=COUNT),
as Scene.half_step halves it: FD's Courant number; a particle's dt0 and growth - 1, which halves
dt_n = dt0 g^n = dt0 + (g - 1) t at every time. A particle may instead run the growths of
--growths (dt0 kept, as issue 50 varied it), or a fixed step (dt_growth 1) of --fixed DT0 halved
--halvings times. Every step of a candidate runs the same seeds (base seed 0, 1, ...), so the
change a halving makes is measured paired, seed by seed.

Measured on each run's last row (models/simulate.run_arrow, judged against the scene's
reference, scenes/reference.compute): the signed product error mass_C / M_C,ref - 1, the
product's RMSE at the scene's points sqrt(SSE_points_C / points), and the scene's own measure
(|product error| or that RMSE). Printed, per step: the step in force at t_final / 2, the mean of
each over seeds with its 95 % t interval (its half-width is the noise floor of that mean), whether
the scene's measure meets the target (upper bound of that interval <= target); per halving: the
paired mean change with its 95 % t interval, * where it exceeds the noise (the interval excludes
0); per three successive steps of one ratio: the observed order p of the product error's change,
e(h) = e_0 + a h^p, with a paired percentile bootstrap interval over seeds
(analysis.step_error.observed_order). Single process.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow" / "lib"))
from particle_entropy.analysis.step_error import mean_interval, observed_order  # noqa: E402
from particle_entropy.core.timegrid import time_steps  # noqa: E402
from particle_entropy.models import simulate  # noqa: E402
from particle_entropy.pipeline.configcheck import load_yaml  # noqa: E402
from particle_entropy.scenes import reference as reactive  # noqa: E402
from particle_entropy.scenes.scene import Candidate, Scene  # noqa: E402

CARRIED = {
    "D": 1.0e-4,
    "v": 0.5,
    "t_final": 50.0,
    "source": {"kind": "gaussian", "x0": 0.0, "sd": 0.02},
    "reaction": {"kind": "bimolecular", "k": 2.0, "B": {"uniform": 0.3}},
    "target": {"measure": "product_rmse", "value": 0.005},
    "max_realisations": 16,
}
CANDIDATES = {  # key -> the candidate as a scene's config writes it (n_range only bounds a scene's ladder)
    "fd-tvd": {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [64, 16384]},
    "fd-upwind": {"method": "fd", "kernel": "implicit", "advection": "upwind", "courant": 0.5, "n_range": [64, 16384]},
    "mtpt": {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [30, 16000]},
    "pt": {"method": "pt", "kernel": "adaptive", "dt_growth": 1.01, "n_range": [300, 16000]},
}
# each scene's resolutions: FD at the rung the scene recommends (carried_reaction: TVD n = 2,048,
# MTPT N = 2,312, its answer; front: TVD n = 1,024), the rest where their runs take about a second
RESOLUTION = {
    "carried_reaction": {"fd-tvd": 2048, "fd-upwind": 2048, "mtpt": 2312, "pt": 4000},
    "front": {"fd-tvd": 1024, "fd-upwind": 1024, "mtpt": 4000, "pt": 4000},
}
SEEDS = {"fd-tvd": 1, "fd-upwind": 1, "mtpt": 16, "pt": 16}  # FD is deterministic: one run
HALVINGS = {"fd-tvd": 2, "fd-upwind": 2, "mtpt": 3, "pt": 2}


@dataclass
class Level:
    """One step of a candidate: its label, steps, the step at t_final / 2 and the per-seed measures."""

    label: str
    steps: int
    dt_mid: float
    product: np.ndarray  # mass_C / M_C,ref - 1
    rmse: np.ndarray  # sqrt(SSE_points_C / points)
    cpu: float


def scene_of(name: str, config: Path) -> Scene:
    """The scene's physics and target (carried_reaction: CARRIED; else config.yaml's scene) with every
    benchmark candidate."""
    spec = dict(CARRIED) if name == "carried_reaction" else dict(load_yaml(config)["scenes"][name])
    spec["candidates"] = list(CANDIDATES.values())
    return Scene.from_config(name, spec)


def steps_of(scene: Scene, cand: Candidate, args, halvings: int) -> list[Candidate]:
    """The candidate at each step it runs: Scene.half_step's halvings, or a particle's --growths or --fixed."""
    if cand.case.method != "fd" and args.growths:
        return [replace(cand, case=replace(cand.case, dt_growth=g)) for g in args.growths]
    if cand.case.method != "fd" and args.fixed:
        cand = replace(cand, dt0=args.fixed, case=replace(cand.case, dt_growth=1.0))
    out = [cand]
    for _ in range(halvings):
        out.append(scene.half_step(out[-1]))
    return out


def run_level(scene: Scene, cand: Candidate, n: int, seeds: list[int], ref: dict) -> Level:
    """Every seed of one candidate at resolution n -> its measures."""
    product, rmse, cpu = [], [], 0.0
    points = len(ref["points"])
    cfg = scene.run_config(cand, n)
    dts = time_steps(cfg.t_final, cfg.dt0, cfg.dt_growth, cfg.time_grid)
    dt_mid = float(dts[np.searchsorted(np.cumsum(dts), 0.5 * cfg.t_final)])
    for seed in seeds:
        cfg = scene.run_config(cand, n, seed=seed)
        start = time.process_time()
        table, _ = simulate.run_arrow(cfg, reference=ref)
        last = table.slice(table.num_rows - 1).to_pylist()[0]
        cpu += time.process_time() - start
        product.append(last["mass_C"] / ref["product_mass"] - 1.0)
        rmse.append(math.sqrt(last["SSE_points_C"] / points))
    return Level(step_text(cfg, cand), dts.size, dt_mid, np.array(product), np.array(rmse), cpu)


def step_text(cfg, cand: Candidate) -> str:
    """The candidate's step as set: FD's Courant number, a particle's dt0 and growth."""
    if cand.case.method == "fd":
        return f"courant {cand.courant:g}"
    return f"dt0 {cfg.dt0:.4g} growth {cfg.dt_growth:.6g}"


def fmt(mean: float, half: float, scale: float = 100.0, digits: int = 2) -> str:
    """mean +- half in percent (scale 100) or as is."""
    body = f"{mean * scale:+.{digits}f}"
    return body if math.isnan(half) else f"{body} ± {half * scale:.{digits}f}"


def pairs(values: list[str], kind=int) -> dict:
    """KEY=VALUE words -> {key: kind(value)} (keys of CANDIDATES)."""
    out = {}
    for word in values:
        key, _, value = word.partition("=")
        if key not in CANDIDATES or not value:
            raise SystemExit(f"expected KEY=VALUE with KEY one of {', '.join(CANDIDATES)}, got {word!r}")
        out[key] = kind(value)
    return out


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", choices=tuple(RESOLUTION), default="carried_reaction")
    p.add_argument("--config", type=Path, default=ROOT / "config.yaml")
    p.add_argument("--only", nargs="*", choices=tuple(CANDIDATES), default=tuple(CANDIDATES))
    p.add_argument("--n", nargs="*", default=[], metavar="KEY=N", help="resolutions")
    p.add_argument("--seeds", nargs="*", default=[], metavar="KEY=S", help="seeds of each step")
    p.add_argument("--halvings", nargs="*", default=[], metavar="KEY=H", help="halvings of each step")
    p.add_argument("--growths", type=float, nargs="*", default=[], help="particles: these dt_growth, dt0 kept")
    p.add_argument("--fixed", type=float, default=None, help="particles: a fixed step dt0 = FIXED, halved")
    p.add_argument("--base-seed", type=int, default=0)
    args = p.parse_args(argv)

    scene = scene_of(args.scene, args.config)
    t0 = time.process_time()
    ref = reactive.compute(reactive.physics(scene))
    for key in ("points", "c_points"):
        ref[key] = np.asarray(ref[key], dtype=np.float64)
    print(
        f"{scene.name}: reference M_C = {ref['product_mass']:.6g} ({time.process_time() - t0:.1f} s CPU);"
        f" target {scene.measure} <= {scene.value:g}",
        flush=True,
    )
    resolution = {**RESOLUTION[scene.name], **pairs(args.n)}
    n_seeds = {**SEEDS, **pairs(args.seeds)}
    halvings = {**HALVINGS, **pairs(args.halvings)}

    head = f"{'model':9s} {'N':>5s} {'step':28s} {'steps':>6s} {'dt(t/2)':>8s} {'seeds':>5s}"
    print(f"\n{head} {'product error [%]':>18s} {'product_rmse [1e-3]':>20s} {'meets':>5s} {'CPU s/run':>9s}")
    results = {}
    for key, cand in zip(CANDIDATES, scene.candidates):
        if key not in args.only:
            continue
        n = resolution[key]
        seeds = [args.base_seed + i for i in range(n_seeds[key])]
        levels = []
        for c in steps_of(scene, cand, args, halvings[key]):
            level = run_level(scene, c, n, seeds, ref)
            measure = np.abs(level.product) if scene.measure == "product" else level.rmse
            mean, half = mean_interval(measure)
            meets = "yes" if mean + (0.0 if math.isnan(half) else half) <= scene.value else "no"
            levels.append(level)
            print(
                f"{key:9s} {n:5d} {level.label:28s} {level.steps:6d} {level.dt_mid:8.4g} {len(seeds):5d}"
                f" {fmt(*mean_interval(level.product)):>18s} {fmt(*mean_interval(level.rmse), scale=1e3):>20s}"
                f" {meets:>5s} {level.cpu / len(seeds):9.2f}",
                flush=True,
            )
        results[key] = levels

    print("\nPaired change per refinement (finer - coarser, same seeds; 95 % t interval; * : beyond the noise)")
    print(
        f"{'model':9s} {'N':>5s} {'dt(t/2) from -> to':22s} {'d product error [%]':>22s} {'d product_rmse [1e-3]':>24s}"
    )
    for key, levels in results.items():
        for lo, hi in zip(levels, levels[1:]):
            cells = []
            for attr, scale in (("product", 100.0), ("rmse", 1e3)):
                mean, half = mean_interval(getattr(hi, attr) - getattr(lo, attr))
                beyond = "" if math.isnan(half) else ("*" if abs(mean) > half else " ")
                cells.append(fmt(mean, half, scale) + beyond)
            step = f"{lo.dt_mid:.4g} -> {hi.dt_mid:.4g}"
            print(f"{key:9s} {resolution[key]:5d} {step:22s} {cells[0]:>22s} {cells[1]:>24s}")

    print("\nObserved order of the product error's change, e = e_0 + a dt^p (three steps of one ratio r)")
    for key, levels in results.items():
        for a, b, c in zip(levels, levels[1:], levels[2:]):
            r1, r2 = a.dt_mid / b.dt_mid, b.dt_mid / c.dt_mid
            if abs(r1 / r2 - 1.0) > 0.05:
                continue  # unequal ratios: p is not read from three points
            r = math.sqrt(r1 * r2)
            o = observed_order(a.product, b.product, c.product, ratio=r)
            bounds = "" if math.isnan(o.lo) else f" [{o.lo:.2f}, {o.hi:.2f}]"
            steps = f"dt(t/2) {a.dt_mid:.4g} / {b.dt_mid:.4g} / {c.dt_mid:.4g}, r {r:.3g}"
            print(f"{key:9s} {resolution[key]:5d} {steps}: p = {o.p:.2f}{bounds}")


if __name__ == "__main__":
    main()
