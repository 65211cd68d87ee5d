"""The closed-form kinetics of core/reactions.py against independent solutions: the ODE integrated
by scipy, the textbook C0 / (1 + k C0 t), the exponential decay and the limits of the exact step."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from particle_entropy.core.reactions import bimolecular_reacted, bimolecular_step, decay_factor, well_mixed


@pytest.mark.parametrize(("a", "b", "k", "dt"), [(1.0, 0.5, 2.0, 0.7), (0.3, 2.0, 1.0, 3.0), (1.0, 1.0, 5.0, 0.2)])
def test_bimolecular_step_solves_the_rate_equations(a, b, k, dt):
    sol = solve_ivp(lambda t, y: [-k * y[0] * y[1], -k * y[0] * y[1]], (0, dt), [a, b], rtol=1e-12, atol=1e-14)
    r = float(bimolecular_reacted(a, b, k, dt))
    assert r == pytest.approx(a - sol.y[0, -1], rel=1e-9)
    assert r == pytest.approx(b - sol.y[1, -1], rel=1e-9)


def test_equal_concentrations_give_the_well_mixed_law():
    t = np.array([0.0, 0.1, 1.0, 10.0, 1e6])
    a, b = well_mixed(2.0, 2.0, 0.5, t)
    np.testing.assert_allclose(a, 2.0 / (1.0 + 0.5 * 2.0 * t), rtol=1e-14)
    np.testing.assert_array_equal(a, b)


def test_nearly_equal_concentrations_are_continuous_across_the_series():
    # d k dt straddles the switch to the series: no jump beyond round-off
    r = bimolecular_reacted(1.0 + np.array([0.0, 1e-7, 2e-5, 1e-4]), 1.0, 1.0, 0.5)
    exact = 0.5 / 1.5
    np.testing.assert_allclose(r, exact, rtol=1e-4)
    assert np.all(np.diff(r) >= 0)


def test_no_mass_goes_negative_and_the_scarce_species_runs_out():
    rng = np.random.default_rng(1)
    a, b = rng.exponential(size=10_000), rng.exponential(size=10_000)
    for dt in (1e-12, 1.0, 1e3, 1e300):
        r = bimolecular_reacted(a, b, 3.0, dt)
        assert np.all(r >= 0) and np.all(r <= np.minimum(a, b))
    np.testing.assert_allclose(bimolecular_reacted(a, b, 3.0, 1e300), np.minimum(a, b), rtol=1e-15)


def test_step_conserves_each_pair_and_matches_the_reacted_amount():
    rng = np.random.default_rng(2)
    a, b = rng.exponential(size=1000), rng.exponential(size=1000)
    a2, b2 = bimolecular_step(a, b, 2.0, 0.3)
    r = bimolecular_reacted(a, b, 2.0, 0.3)
    np.testing.assert_allclose(a - a2, r, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(b - b2, r, rtol=1e-12, atol=1e-15)
    assert np.all(a2 >= 0) and np.all(b2 >= 0)


def test_small_steps_react_k_a_b_dt():
    assert float(bimolecular_reacted(2.0, 3.0, 0.5, 1e-9)) == pytest.approx(0.5 * 2 * 3 * 1e-9, rel=1e-8)


def test_decay_factor_is_the_exponential():
    assert decay_factor(0.3, 2.0) == pytest.approx(math.exp(-0.6), rel=1e-15)
    assert decay_factor(0.0, 5.0) == 1.0


def test_reaction_kinds_account_for_every_mass():
    from particle_entropy.core.reactions import REACTIONS, Bimolecular, Decay, Production

    a, b = np.array([0.0, 0.5, 2.0, 1e-9]), np.array([1.0, 0.5, 0.1, 3.0])
    a1, b1, made = Bimolecular(4.0).react(a, b, 0.3)
    np.testing.assert_allclose(a1 + made, a, rtol=1e-15)
    np.testing.assert_allclose(b1 + made, b, rtol=1e-15)
    a1, b1, made = Decay(2.0).react(a, b, 0.3)
    np.testing.assert_allclose(a1, a * math.exp(-0.6), rtol=1e-15)
    np.testing.assert_allclose(a1 + made, a, rtol=1e-15)
    np.testing.assert_array_equal(b1, b)
    assert REACTIONS == {"decay": Decay, "bimolecular": Bimolecular, "production": Production}
    with pytest.raises(ValueError):
        Decay(-1.0)


@pytest.mark.parametrize("x", [1e-10, 1e-200, 1e-300])
def test_small_moved_masses_keep_their_digits(x):
    # issue 50: a product of 1e-300 must not vanish as m - m exp(-x), nor as m_B - m_B'.
    # Independent values: the series of each exact amount to second order, the next term far below 1e-12
    from particle_entropy.core.reactions import Bimolecular, Decay

    m = np.array([0.25, 1.0, 3.0])
    _, _, moved = Decay(x).on_masses(m, m, 1.0, 1.0)
    np.testing.assert_allclose(moved, m * x * (1.0 - x / 2.0), rtol=1e-12)
    mb = np.array([0.5, 0.5, 2.0])
    na, nb, made = Bimolecular(x).on_masses(m, mb, 0.1, 2.0)
    kappa = x * 2.0 / 0.1  # k dt / dV; the series of the exact r to second order in it
    np.testing.assert_allclose(made, m * mb * kappa * (1.0 - (m + mb) * kappa / 2.0), rtol=1e-12)
    assert np.all(na <= m) and np.all(nb <= mb)


def test_a_round_off_negative_residue_takes_no_part_in_the_reaction():
    # an FD scheme carrying B as its departure from a background leaves -1e-18 where B is used up:
    # it must react as 0 (no negative product, A untouched there) and be carried through unchanged
    from particle_entropy.core.reactions import Bimolecular

    a, b = np.array([1.0, 1.0]), np.array([-1.7e-18, 0.5])
    na, nb, made = Bimolecular(100.0).on_masses(a, b, 1.0, 0.1)
    assert na[0] == 1.0 and nb[0] == -1.7e-18 and made[0] == 0.0
    assert made[1] > 0.0 and na[1] + made[1] == pytest.approx(1.0, rel=1e-15)


def test_no_caller_branches_on_a_reaction_kind_s_name():
    """Issue 51: a kind carries its own rules (core/reactions.py), so no other module compares a value with
    a kind's name (``reaction.kind == "decay"``, a dict keyed by kind names, ``in ("decay", ...)``)."""
    import ast
    from pathlib import Path

    from particle_entropy.core.reactions import REACTIONS

    lib = Path(__file__).resolve().parents[1] / "workflow" / "lib" / "particle_entropy"
    found = []
    for path in lib.rglob("*.py"):
        if path.relative_to(lib).as_posix() == "core/reactions.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare):
                values = [node.left, *node.comparators]
            elif isinstance(node, ast.Dict):
                values = [k for k in node.keys if k is not None]
            else:
                continue
            names = [v.value for v in values if isinstance(v, ast.Constant) and v.value in REACTIONS]
            names += [
                e.value
                for v in values
                if isinstance(v, (ast.Tuple, ast.List, ast.Set))
                for e in v.elts
                if isinstance(e, ast.Constant) and e.value in REACTIONS
            ]
            if names:
                found.append(f"{path.relative_to(lib)}:{node.lineno} {names}")
    assert not found, found
