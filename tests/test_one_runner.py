"""The one runner (models/simulate.py) against the runs of the three runners before it (issue 51):
every shipped scene's candidates, conservative and reactive, at their low rungs and short times,
and their half-step twins, give the same bytes as the code at 5399db0 (measured cost columns left
out), each at its scene's v, every float's mantissa rounded to 40 bits so that they hold on any CPU
(ROUNDED). The digests in tests/data/runs_before_one_runner.json were made by that code; the rounded
ones from tables whose exact digests are its own."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from particle_entropy.core.records import TIMING_COLUMNS
from particle_entropy.models.simulate import run_seeds_arrow
from particle_entropy.scenes import reference as reactive
from particle_entropy.scenes.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
FROZEN = json.loads((ROOT / "tests" / "data" / "runs_before_one_runner.json").read_text())
BEFORE = FROZEN["digests"]  # the exact bytes, on the CPU that made them
# the same, each float's mantissa rounded to MANTISSA_BITS: numba compiles its fastmath kernels for this CPU,
# and LLVM's code for another (an AMD EPYC against the Intel Xeon that made them) sums a measure in another
# order: front[5]'s SSE_points 4e-16 apart. Rounded, the digests are one on both.
MANTISSA_BITS = 40
ROUNDED = FROZEN["digests_40bit"]
# each shipped scene at a short t_final (its runs' cost, not its physics, is what the test keeps small)
SHORT = {
    "paper": 300.0,
    "carried": 2.0,
    "spill": 20.0,
    "narrow": 100.0,
    "front": 5.0,
    "well_mixed": 5.0,
    "carried_reaction": 5.0,
}
VARIANTS = {name: (name, {"t_final": t}) for name, t in SHORT.items()}
VARIANTS["spill_decay"] = (
    "spill",
    {"t_final": 20.0, "reaction": {"kind": "decay", "rate": 0.02}, "target": {"measure": "rmse", "value": 0.01}},
)
VARIANTS["carried_decay"] = (
    "carried_reaction",
    {"t_final": 5.0, "reaction": {"kind": "decay", "rate": 0.05}, "target": {"measure": "product", "value": 0.01}},
)


def _digest(table, bits: int | None = None) -> str:
    """sha256[:16] of a run table's columns, names and bytes, the measured cost columns left out; ``bits``
    given, each float's mantissa rounded to that many bits first (_rounded)."""
    t = table.drop([c for c in TIMING_COLUMNS if c in table.column_names])
    h = hashlib.sha256()
    for name in t.column_names:
        col = t.column(name).to_numpy(zero_copy_only=False)
        if bits is not None and col.dtype.kind == "f":
            col = _rounded(col, bits)
        h.update(name.encode())
        h.update(repr(col.tolist()).encode() if col.dtype == object else np.ascontiguousarray(col).tobytes())
    return h.hexdigest()[:16]


def _rounded(col: np.ndarray, bits: int) -> np.ndarray:
    """Each value's binary mantissa rounded to ``bits`` bits (NaN and inf kept)."""
    mantissa, exponent = np.frexp(col.astype(np.float64))
    return np.ldexp(np.round(mantissa * 2.0**bits) / 2.0**bits, exponent)


def _stub_reference(scene: Scene) -> dict:
    """A reference to judge the last step against (its values matter only as numbers to compare)."""
    pts = reactive.points(scene)
    return {"points": pts, "a_points": 0.5 + 0.0 * pts, "c_points": 0.25 + 0.0 * pts, "product_mass": 0.1}


def _runs():
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    for name, (base, override) in VARIANTS.items():
        scene = Scene.from_config(name, {**config["scenes"][base], **override}, config.get("case_defaults", {}))
        for i, cand in enumerate(scene.candidates):
            n = cand.ladder()[1 if cand.case.method == "fd" else 0]
            for half in (False, True):
                yield f"{name}[{i}]{'/2' if half else ''}@{n}", scene, scene.half_step(cand) if half else cand, n


RUNS = list(_runs())


def test_every_frozen_run_is_listed():
    assert sorted(key for key, *_ in RUNS) == sorted(BEFORE) == sorted(ROUNDED) and len(BEFORE) == 78


def test_a_rounded_digest_holds_round_off_and_sees_a_change():
    """Rounded to 40 bits, a float 4e-16 apart hashes alike; one 1e-10 apart does not."""
    import pyarrow as pa

    x = np.array([0.123456789012345, 7.5e-3, np.nan, np.inf])
    digest = _digest(pa.table({"SSE_points": x}), MANTISSA_BITS)
    assert _digest(pa.table({"SSE_points": x * (1 + 4e-16)}), MANTISSA_BITS) == digest
    assert _digest(pa.table({"SSE_points": x * (1 + 1e-10)}), MANTISSA_BITS) != digest


@pytest.mark.parametrize("key, scene, cand, n", RUNS, ids=[r[0] for r in RUNS])
def test_a_run_has_the_bytes_of_the_runners_before(key, scene, cand, n):
    seeds = [0] if cand.case.method == "fd" else [0, 1]
    ref = None if scene.reaction is None else _stub_reference(scene)
    # at the scene's own v, as the runners before ran it (a particle's jobs now run it at rest: test_rest_frame.py)
    table = run_seeds_arrow(scene.run_config(cand, n, carried=True), seeds, reference=ref)
    assert _digest(table, MANTISSA_BITS) == ROUNDED[key]


class _Doubling:
    """A stand-in FD solver whose step doubles the interior it is given (to see which nodes it gets)."""

    def solve(self, interior):
        return 2.0 * interior


@pytest.mark.parametrize("shape", [(2, 7), (3, 5, 6)])
def test_fd_transport_solves_each_species_interior_and_holds_the_boundary(shape):
    from particle_entropy.models import fd

    rows = np.arange(np.prod(shape), dtype=float).reshape(shape) + 1.0
    before = rows.copy()
    fd.transport(_Doubling(), rows)
    inner = (slice(None), *(slice(1, -1),) * (len(shape) - 1))
    np.testing.assert_array_equal(rows[inner], 2.0 * before[inner])
    edge = np.ones(shape, dtype=bool)
    edge[inner] = False
    np.testing.assert_array_equal(rows[edge], before[edge])


def test_particle_steps_take_positions_in_two_dimensions():
    """The PT and MTPT walks move (N, 2) positions by a tensor D: mean v dt, covariance 2 D dt, the order
    (and each particle's masses) kept; 1-D runs sort."""
    from particle_entropy.models import mtpt, pt

    n, dt = 200_000, 0.5
    D = np.array([[2.0, 0.6], [0.6, 0.5]])
    v = np.array([1.0, -2.0])
    x0 = np.zeros((n, 2))
    (x,) = pt.step([x0], D[None], dt, np.random.default_rng(1), v)  # one tensor for all: (1, d, d)
    assert x.shape == (n, 2)
    _assert_covariance(x - v * dt, 2.0 * D * dt)
    assert np.all(np.abs(x.mean(axis=0) - v * dt) < 5.0 * np.sqrt(np.diag(2.0 * D * dt) / n))
    m = np.vstack([np.arange(n, dtype=float), -np.arange(n, dtype=float)])
    label = np.arange(n)
    y, m2, label2 = mtpt.walk(x, m, label, 0.5 * D[None], dt, np.random.default_rng(2))
    np.testing.assert_array_equal(label2, label)  # no re-sort in 2-D: each particle keeps its masses
    np.testing.assert_array_equal(m2, m)
    _assert_covariance(y - x, 2.0 * (0.5 * D) * dt)
    (z,) = pt.step([np.array([3.0, 1.0, 2.0])], 0.0, dt, np.random.default_rng(0))
    np.testing.assert_array_equal(z, [1.0, 2.0, 3.0])  # 1-D: sorted for the reconstructions


def _assert_covariance(steps: np.ndarray, expected: np.ndarray) -> None:
    """The sample covariance of ``steps`` (n, d) is ``expected`` within 5 standard errors of each entry,
    sqrt((S_ii S_jj + S_ij^2) / n) for Gaussian steps."""
    n = steps.shape[0]
    se = np.sqrt((np.outer(np.diag(expected), np.diag(expected)) + expected**2) / n)
    assert np.all(np.abs(np.cov(steps.T) - expected) < 5.0 * se)
