"""What scoring a run with a continuous release against its exact plume costs (issue 53; core/released.py).

    python benchmarks/release_scores.py [--repeats 3]

Per time t, the exact plume (core/release.py: Gauss-Legendre quadrature in age) is built once and gives
a row's scores: H_I and E (its adaptive spatial rule), the density at the 15 measurement points and at
the model's own points (FD's nodes). This prints, on one core:

- 1-D, for a point, a Gaussian and a box releasing into a flow (q 0.5 from 0 to 2, v 1, D 0.05, seen at
  t = 1, 2 and 4): the cost of one t's exact plume (H_I, then the density at FD's 201 nodes and at the
  15 points), beside the median step of the FD run it scores (n 200, tvd, Courant 0.5) without it;
- 2-D, for MT3DMS problem 3's and 4's well (a point, v 1 along x and at 45 degrees, D_L 2, D_T 0.2,
  t 365 and 1,000): H_I (the tensor rule) and the density at the 15 x 15 lattice;
- a whole 1-D FD run scored as runs are (at its last row, the plume built by simulate.warm_up before
  the timed steps): its steps' wall time, the warm-up's and the last row's.

Each timing is the median of --repeats fresh builds (exact_plume's cache cleared before each).
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_name] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

LIB = Path(__file__).resolve().parents[1] / "workflow" / "lib"
sys.path.insert(0, str(LIB))
from machine import cpu  # noqa: E402

from particle_entropy.core import released  # noqa: E402
from particle_entropy.core.release import Release  # noqa: E402
from particle_entropy.core.runconfig import RunConfig  # noqa: E402
from particle_entropy.core.sources import Source  # noqa: E402
from particle_entropy.core.sources2d import Source2D, dispersion_tensor  # noqa: E402
from particle_entropy.models import fd  # noqa: E402
from particle_entropy.models.simulate import run, warm_release  # noqa: E402

LINE = {"t_final": 4.0, "D": 0.05, "v": 1.0, "release": Release(0.5, 0.0, 2.0)}
FD = {"kernel": "implicit", "n": 200, "courant": 0.5, "advection": "tvd", "fd_length": 8.0}
SOURCES = {
    "point": Source.of("point", x0=0.0),
    "gaussian": Source.of("gaussian", x0=0.0, sd=0.1),
    "box": Source.of("box", a=-0.2, b=0.2),
}


def _median(f, repeats: int) -> float:
    """The median wall time of f() over ``repeats`` calls, exact_plume's cache cleared before each [s]."""
    times = []
    for _ in range(repeats):
        released.exact_plume.cache_clear()
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def line(repeats: int) -> None:
    print("1-D: one t's exact plume [ms] against the FD step it would score")
    for kind, source in SOURCES.items():
        cfg = RunConfig.of("fd", **FD, **LINE, source=source).resolved()
        x, _ = fd.grid(cfg)
        table, _ = run(cfg)
        step = float(np.median(table["wall_s"].to_numpy()[1:-1]))
        for t in (1.0, 2.0, 4.0):
            plume = released.ReleasedPlume(source, cfg.D, cfg.v, t, cfg.release, cfg.t_final)
            points = cfg.points(t)
            entropy = _median(plume.entropy, repeats)
            nodes = _median(lambda p=plume, q=x: p.density(q), repeats)
            at = _median(lambda p=plume, q=points: p.density(q), repeats)
            print(
                f"  {kind:9s} t = {t:g}: H_I {1e3 * entropy:7.1f}, nodes ({x.size}) {1e3 * nodes:6.1f}, "
                f"15 points {1e3 * at:5.1f};  FD step {1e3 * step:.3f} ms: scoring a row costs "
                f"{(entropy + nodes + at) / step:,.0f} steps"
            )


def plane(repeats: int) -> None:
    print("2-D: MT3DMS problem 3's and 4's well, one t's exact plume [s]")
    source = Source2D.of("point", x0=[0.0, 0.0])
    for degrees in (0, 45):
        theta = math.radians(degrees)
        v = (math.cos(theta), math.sin(theta))
        D = dispersion_tensor(v, {"L": 2.0, "T": 0.2})
        for t in (365.0, 1000.0):
            plume = released.ReleasedPlume2D(source, D, v, t, Release(10.0, 0.0), 1000.0)
            points = plume.points()
            entropy = _median(plume.entropy, repeats)
            at = _median(lambda p=plume, q=points: p.density(q), repeats)
            print(f"  {degrees:2d} degrees, t = {t:g}: H_I {entropy:.3f}, 225 points {at:.3f}")


def scored_run(repeats: int) -> None:
    print("A 1-D FD run (point source) as runs are scored: its last row only, the plume built before the steps")
    cfg = RunConfig.of("fd", **FD, **LINE, source=SOURCES["point"]).resolved()
    warm = _median(lambda: warm_release(cfg), repeats)
    released.exact_plume.cache_clear()
    table, _ = run(cfg)
    wall = table["wall_s"].to_numpy()
    print(
        f"  {len(table) - 1} steps: {1e3 * wall[1:].sum():.1f} ms in the steps (median "
        f"{1e3 * np.median(wall[1:]):.3f} ms, the scored last row {1e3 * wall[-1]:.3f} ms); warm-up {1e3 * warm:.0f} ms"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"machine: {cpu()}; load average {os.getloadavg()[0]:.2f}")
    line(args.repeats)
    plane(args.repeats)
    scored_run(args.repeats)
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
