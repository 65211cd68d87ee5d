"""Runs in the plane through the one runner (models/simulate.py with a 2-D source; core/plane.py,
models/plane.py): mass, the exact H_C and E approached, determinism per seed, and 2-D refusals by name."""

import math

import numpy as np
import pytest

from particle_entropy.core.case import SettingError
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.sources2d import dispersion_tensor
from particle_entropy.models.simulate import run

THETA = math.radians(45.0)
V = [0.5 * math.cos(THETA), 0.5 * math.sin(THETA)]
D = dispersion_tensor(V, {"L": 1e-2, "T": 1e-3})
GAUSS = {"kind": "gaussian", "x0": [0.0, 0.0], "sd": [0.1, 0.1]}
PHYSICS = {"source": GAUSS, "v": V, "D": D, "t_final": 2.0, "fd_length": 2.0, "omega": 2.0}


def _cfg(method, **kw):
    case = {
        "fd": {"kernel": "implicit", "n": 64, "courant": 0.5, "advection": "tvd"},
        "mtpt": {"kernel": "collision", "n": 2000, "dt_growth": 1.0, "dt0": 0.1},
        "pt": {"kernel": "adaptive", "n": 2000, "dt_growth": 1.0, "dt0": 0.1},
    }[method]
    return RunConfig.of(method, **{**case, **PHYSICS, **kw})


def _exact_gaussian_entropy(t):
    """ln(2 pi e sqrt(det Sigma)), Sigma = 0.1^2 I + 2 D t: written here from the formula, not the code."""
    sigma = 0.01 * np.eye(2) + 2.0 * t * np.asarray(D)
    return math.log(2.0 * math.pi * math.e * math.sqrt(np.linalg.det(sigma)))


@pytest.mark.parametrize("method", ["fd", "mtpt", "pt"])
def test_a_plane_run_keeps_its_mass_and_reports_the_exact_plume(method):
    table, _ = run(_cfg(method))
    last = table.iloc[-1]
    assert last["time"] == pytest.approx(2.0)
    assert last["E_analytic"] == pytest.approx(math.exp(_exact_gaussian_entropy(2.0)), rel=1e-12)
    assert last["H_C_analytic"] == pytest.approx(_exact_gaussian_entropy(2.0) - math.log(last["dV"]), rel=1e-12)
    if method == "mtpt":  # the exchange moves mass between particles: the total to round-off every step
        assert np.all(np.abs(table["mass_total"] - 1.0) < 1e-13)
    elif method == "pt":
        assert np.all(table["mass_total"] == 1.0)
    else:  # the window holds the plume: what its zero ring absorbs is below the unscored bound
        assert np.all(np.abs(table["mass_total"] - 1.0) < 1e-5)
    assert math.isfinite(last["SSE_points"]) and last["SSE_points"] > 0


def test_fd_tvd_s_entropy_and_points_converge_to_the_exact_plume_at_45_degrees():
    errors, rmse = [], []
    for n in (32, 64, 128):
        last = run(_cfg("fd", n=n))[0].iloc[-1]
        errors.append(abs(last["E"] / last["E_analytic"] - 1.0))
        rmse.append(math.sqrt(last["SSE_points"] / 225))
    assert errors[0] > errors[1] > errors[2] and errors[2] < 0.01
    order = math.log2(rmse[1] / rmse[2])
    assert order > 1.5, rmse  # TVD: about 2 on a smooth plume (fd2d's own tests measure 2.4-2.6)


def test_particles_approach_the_exact_entropy_with_n():
    """MTPT's H_C of its masses against H_C_analytic at N = 500 and 8,000 (3 seeds each): the error falls."""
    gaps = []
    for n in (500, 8000):
        runs = [run(_cfg("mtpt", n=n, seed=s))[0].iloc[-1] for s in range(3)]
        gaps.append(np.mean([abs(r["H_C"] - r["H_C_analytic"]) for r in runs]))
    assert gaps[1] < 0.5 * gaps[0], gaps


@pytest.mark.parametrize("method", ["fd", "mtpt", "pt"])
def test_a_plane_run_is_the_same_bytes_for_the_same_seed(method):
    a, b = (run(_cfg(method, seed=7))[0].drop(columns=["wall_s", "peak_rss_mb"]) for _ in range(2))
    assert a.equals(b)


@pytest.mark.parametrize(
    "method, change, name",
    [
        ("fd", {"v": [1.0, 0.0, 0.0]}, "v"),
        ("fd", {"D": [[1e-3, 2e-3], [2e-3, 1e-3]]}, "D"),  # not positive definite
        ("fd", {"D": [[math.nan, 0.0], [0.0, 1e-3]]}, "D"),
        ("fd", {"fd_length": 0.5}, "fd_length"),  # the plume outgrows the window
        ("mtpt", {"omega": 0.5}, "omega"),
        ("mtpt", {"kernel": "sph"}, "kernel"),
        ("mtpt", {"scheme": "sequential"}, "scheme"),
        ("pt", {"kernel": "bins"}, "kernel"),
        ("fd", {"kernel": "explicit"}, "kernel"),
        ("fd", {"courant": 1.5}, "courant"),  # tvd beyond Courant 1 on the faster axis
        ("fd", {"n": 4096}, "n"),  # over the memory a run may take
        ("mtpt", {"reaction": {"kind": "decay", "rate": 0.1}}, "reaction"),
    ],
)
def test_a_bad_plane_setting_is_refused_by_name(method, change, name):
    with pytest.raises(SettingError) as err:
        _cfg(method, **change).resolved()
    assert err.value.name == name


def test_an_fd_rung_over_the_memory_bound_names_its_grid_and_bytes():
    with pytest.raises(SettingError) as err:
        _cfg("fd", n=4096).resolved()
    assert "4,096 x 4,096" in err.value.allowed and "bytes" in err.value.allowed


@pytest.mark.parametrize("method, n", [("fd", 256), ("mtpt", 8000), ("pt", 32000)])
def test_a_plane_run_s_memory_estimate_bounds_its_peak(method, n):
    """memory.estimate_bytes of a 2-D run (the job's mem_mb) against the peak resident memory of the run
    alone in a fresh process: above it, and not more than 4 times it. The peak is the process's VmHWM,
    not getrusage's ru_maxrss (the table's peak_rss_mb), which Linux carries over exec from the forking
    parent: under pytest's workers every run read 1.16 GB."""
    import json
    import subprocess
    import sys

    from particle_entropy.pipeline.memory import estimate_bytes

    cfg = _cfg(method, n=n).resolved()
    code = (
        "import json, sys\n"
        "from particle_entropy.core.runconfig import RunConfig\n"
        "from particle_entropy.models.simulate import run\n"
        f"cfg = RunConfig.of({method!r}, **json.loads(sys.argv[1]))\n"
        "run(cfg)\n"
        "print([line.split()[1] for line in open('/proc/self/status') if line.startswith('VmHWM')][0])\n"
    )
    case = {"fd": {"kernel": "implicit", "courant": 0.5, "advection": "tvd"}}.get(
        method, {"kernel": "collision" if method == "mtpt" else "adaptive", "dt_growth": 1.0, "dt0": 0.1}
    )
    settings = {**case, **PHYSICS, "D": np.asarray(D).tolist(), "n": n}
    out = subprocess.run([sys.executable, "-c", code, json.dumps(settings)], capture_output=True, text=True, check=True)
    peak = float(out.stdout.strip().splitlines()[-1]) * 2**10  # VmHWM is in kB
    estimate = estimate_bytes(cfg)
    assert peak < estimate < 4.0 * peak, (peak / 2**20, estimate / 2**20)


def test_a_plane_mtpt_run_writes_the_columns_only_2d_runs_have():
    from particle_entropy.core.columns import PLANE_ONLY_COLUMNS

    table, _ = run(_cfg("mtpt", n=500))
    assert set(PLANE_ONLY_COLUMNS) <= set(table.columns)
    assert table["neighbours"].iloc[-1] > 1.0  # partners within the cut-off at the last step
    assert "neighbours" not in run(RunConfig.of("mtpt", "collision", 50, t_final=1.0))[0].columns  # 1-D: none
