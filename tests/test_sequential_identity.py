"""The authors' loop against the loop it replaced (tests/sequential_reference.py), on many random
states (clipping acting or not, negative masses, storage in random or position order, tied
positions, symmetric weights, N from 1 to 3,000, cut-offs from 1 to 40 widths) and on whole runs:
its bit-identical form (sequential_kernels._sweep, ``exact=True``) bit for bit, its default fast
form (sequential_kernels._sweep_fma) to round-off; and fastexp.exp_neg against the table form it replaced,
over the whole range of its argument."""

from __future__ import annotations

import numpy as np
import pytest
import sequential_reference as ref
from numba import njit

from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models import simulate
from particle_entropy.numerics import compiled, fastexp, sequential, sequential_kernels


def _state(rng, n, ties, negative, sorted_storage):
    x = np.sort(rng.uniform(-1.0, 1.0, n))
    if ties:
        x = np.round(x, 2)  # many equal positions
    m = rng.exponential(1.0, n) * (rng.random(n) < 0.5)  # many zeros
    if negative:
        m[rng.random(n) < 0.1] *= -1.0
    label = np.arange(n, dtype=np.int64) if sorted_storage else rng.permutation(n).astype(np.int64)
    return x, m, label


def _both(x, m, label, sigma, radius, beta, seed, symnorm, clip):
    a = ref._sweep(x, m.copy(), label, sigma, radius, beta, np.uint64(seed), symnorm, clip)
    b = sequential_kernels._sweep(x, m.copy(), label, sigma, radius, beta, np.uint64(seed), symnorm, clip)
    return a, b


CASES = [
    (n, beta, sigma)
    for n in (1, 2, 3, 5, 64, 65, 300, 3000)
    for beta in (0.5, 1.0, 2.5)
    for sigma in (0.005, 0.05, 0.4)
]


@pytest.mark.parametrize("n, beta, sigma", CASES)
def test_bit_identical_to_the_reference_loop(n, beta, sigma):
    rng = np.random.default_rng([n, int(beta * 10), int(sigma * 1000)])
    clipped = 0
    for trial in range(4):
        ties, negative, sorted_storage = trial == 1, trial == 2, trial == 3
        x, m, label = _state(rng, n, ties, negative, sorted_storage)
        for truncation in (1.0, 3.0) if n * sigma > 100 else (1.0, 3.0, 9.0, 40.0):  # (time)
            for symnorm, clip in ((False, True), (True, True), (False, False)):
                seed = int(rng.integers(0, 2**63))
                a, b = _both(x, m, label, sigma, truncation * sigma, beta, seed, symnorm, clip)
                assert a.tobytes() == b.tobytes(), (trial, truncation, symnorm, clip)
                if clip:
                    noclip = ref._sweep(
                        x, m.copy(), label, sigma, truncation * sigma, beta, np.uint64(seed), symnorm, False
                    )
                    clipped += noclip.tobytes() != a.tobytes()
    if beta > 1.0 and sigma >= 0.05 and n >= 64:
        assert clipped > 0  # the clipping acted in some of these cases, so they test its path


def test_bit_identical_when_every_mass_is_clipped_or_none_is():
    """beta = 10: most exchanges overshoot; beta = 0.5 with positive masses: the clipping never acts,
    and the loop skips it (the proof in _sweep's docstring)."""
    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(-1.0, 1.0, 2000))
    label = rng.permutation(2000).astype(np.int64)
    for beta, m in ((10.0, rng.exponential(1.0, 2000)), (0.5, rng.random(2000) + 0.1)):
        a, b = _both(x, m, label, 0.02, 0.06, beta, 99, False, True)
        assert a.tobytes() == b.tobytes()


# whole runs of every loop scheme, each kernel and eta at least once (both forms are held to them)
LOOP_RUNS = [
    ("sequential", "collision", 1.0),
    ("sequential", "sph", 1.0),
    ("sequential", "collision", 0.5),
    ("sequential_sorted", "collision", 1.0),
    ("sequential_symnorm", "sph", 1.0),
    ("sequential_noclip", "sph", 1.0),
    ("authors", "sph", 1.0),
]


@pytest.mark.parametrize("scheme, kernel, eta", LOOP_RUNS)
def test_whole_runs_bit_identical(monkeypatch, scheme, kernel, eta):
    """A run with `numerics.loop_arithmetic: exact` is the reference loop's, bit for bit."""
    cfg = RunConfig.of(
        method="mtpt",
        kernel=kernel,
        n=400,
        eta=eta,
        truncation=3.0,
        scheme=scheme,
        t_final=50.0,
        seed=3,
        loop_arithmetic="exact",
    )
    _, new = simulate.run(cfg, want_state=True)
    monkeypatch.setattr(compiled.kernels(), "_sweep", ref._sweep)  # what sequential_transfer calls
    _, old = simulate.run(cfg, want_state=True)
    assert new["mass"].to_numpy().tobytes() == old["mass"].to_numpy().tobytes()
    assert new["x"].to_numpy().tobytes() == old["x"].to_numpy().tobytes()


# ---------------------------------------------------------------- the fast form, to round-off
def _assert_round_off(a, b, m):
    """Every mass within 1e-12 of the total (|m|) mass of the reference's, the total within 1e-13."""
    total = max(np.abs(m).sum(), 1e-300)
    assert np.max(np.abs(a - b), initial=0.0) <= 1e-12 * total
    assert abs(a.sum() - b.sum()) <= 1e-13 * total


@pytest.mark.parametrize("n, beta, sigma", CASES)
def test_fast_form_equal_to_the_reference_loop_to_round_off(n, beta, sigma):
    """The identity states of the bit-identical test, the fast form; with positive masses and
    beta < 2 (where it uses the fused chain) its mass is conserved to 1e-13 too."""
    rng = np.random.default_rng([n, int(beta * 10), int(sigma * 1000)])
    for trial in range(4):
        ties, negative, sorted_storage = trial == 1, trial == 2, trial == 3
        x, m, label = _state(rng, n, ties, negative, sorted_storage)
        for truncation in (1.0, 3.0) if n * sigma > 100 else (1.0, 3.0, 9.0, 40.0):
            for symnorm, clip in ((False, True), (True, True), (False, False)):
                seed = int(rng.integers(0, 2**63))
                args = (label, sigma, truncation * sigma, beta, np.uint64(seed), symnorm, clip)
                a, b = ref._sweep(x, m.copy(), *args), sequential_kernels._sweep_fma(x, m.copy(), *args)
                _assert_round_off(a, b, m)
                if beta < 2.0 and not negative:
                    assert abs(b.sum() - m.sum()) <= 1e-13 * max(m.sum(), 1e-300)


def test_fast_form_when_every_mass_is_clipped_or_none_is():
    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(-1.0, 1.0, 2000))
    label = rng.permutation(2000).astype(np.int64)
    for beta, m in ((10.0, rng.exponential(1.0, 2000)), (0.5, rng.random(2000) + 0.1), (1.9, rng.random(2000))):
        args = (label, 0.02, 0.06, beta, np.uint64(99), False, True)
        _assert_round_off(ref._sweep(x, m.copy(), *args), sequential_kernels._sweep_fma(x, m.copy(), *args), m)


def test_fast_form_is_the_default_and_exact_selects_the_bit_identical_one():
    rng = np.random.default_rng(8)
    x = np.sort(rng.uniform(-1.0, 1.0, 500))
    m, label = rng.random(500), rng.permutation(500).astype(np.int64)
    out = {}
    for exact in (False, True):
        out[exact] = sequential.sequential_transfer(x, m, 0.02, 0.5, 3.0, np.random.default_rng(1), label, exact=exact)
    seed = np.uint64(np.random.default_rng(1).integers(0, 2**63))
    args = (label, 0.02, 0.06, 0.5, seed, False, True)  # (a sweep writes into the masses it is given)
    assert out[True].tobytes() == ref._sweep(x, m.copy(), *args).tobytes()
    assert out[False].tobytes() == sequential_kernels._sweep_fma(x, m.copy(), *args).tobytes()
    assert out[False].tobytes() != out[True].tobytes()  # (the check above is sharp)


@pytest.mark.parametrize("scheme, kernel, eta", LOOP_RUNS)
def test_whole_runs_of_the_fast_form_within_round_off(monkeypatch, scheme, kernel, eta):
    """The default (fast) form against the reference loop over whole runs: COMIC within 1e-9 at
    every step, masses within 1e-12 of the total, mass conserved alike."""
    cfg = RunConfig.of(
        method="mtpt", kernel=kernel, n=400, eta=eta, truncation=3.0, scheme=scheme, t_final=50.0, seed=3
    )
    new_table, new = simulate.run(cfg, want_state=True)
    monkeypatch.setattr(compiled.kernels(), "_sweep_fma", ref._sweep)  # what sequential_transfer calls
    old_table, old = simulate.run(cfg, want_state=True)
    assert new["x"].to_numpy().tobytes() == old["x"].to_numpy().tobytes()
    np.testing.assert_allclose(new_table["COMIC"], old_table["COMIC"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(new_table["mass_total"], old_table["mass_total"], rtol=0, atol=1e-13)
    assert np.max(np.abs(new["mass"].to_numpy() - old["mass"].to_numpy())) <= 1e-12
    assert new["mass"].to_numpy().tobytes() != old["mass"].to_numpy().tobytes()  # two forms ran


@njit(cache=True)
def _exp_both(a):
    new = np.empty_like(a)
    near = np.empty_like(a)
    old = np.empty_like(a)
    for i in range(a.size):
        new[i] = fastexp.exp_neg(a[i])
        near[i] = fastexp.exp_neg_near(min(a[i], fastexp.EXP_NEAR_MAX))
        old[i] = ref._exp_neg(a[i])
    return new, near, old


def test_exp_neg_bit_identical_to_the_table_form():
    rng = np.random.default_rng(11)
    a = np.concatenate(
        [
            np.linspace(0.0, 50.0, 100001),
            rng.uniform(0.0, 1200.0, 100000),
            np.arange(0.0, 1200.0, 0.125),  # k and k + 1/2 multiples of ln 2 and their neighbours
            np.arange(0, 1700) * np.log(2.0) / 2.0,
            [0.0, 1e-300, 700.0, 744.4, 745.1, 745.2, 760.0, 762.5, 800.0, 1e6],  # (the table form read
            # outside its table from a ~ 6.4e18 on, where int(a / ln 2) overflows)
        ]
    )
    new, near, old = _exp_both(a)
    assert new.tobytes() == old.tobytes()
    inside = a <= fastexp.EXP_NEAR_MAX
    assert near[inside].tobytes() == old[inside].tobytes()
    assert np.count_nonzero((old > 0) & (old < np.finfo(float).tiny)) > 0  # subnormal results were tested


@pytest.mark.parametrize("compiled_path", [True, False])
def test_partners_compacted_in_window_order(monkeypatch, compiled_path):
    """_compact gives the window offsets of the labels above i, in order, on windows of every
    length mod 16: compiled (vector compress blocks of 16 where this CPU has AVX-512, the scalar
    loop elsewhere) and the scalar loop run by Python."""
    compact = sequential_kernels._compact
    if not compiled_path:  # the global is read at each call of the Python function
        monkeypatch.setattr(sequential_kernels, "_VECTOR_COMPRESS", False)
        compact = sequential_kernels._compact.py_func
    rng = np.random.default_rng(5)
    checked = 0
    for length in [0, 1, 15, 16, 17, 31, 32, 33, 100, 257, 390]:
        for lo in (0, 3):
            ls = rng.permutation(400)[: lo + length + 5].astype(np.int64)
            i = int(rng.integers(0, 400))
            part = np.full(ls.size + 16, 999_999, np.uint32)
            cnt = compact(i, ls, lo, lo + length, part)
            expected = np.flatnonzero(ls[lo : lo + length] > i)
            assert cnt == expected.size
            assert part[:cnt].tolist() == expected.tolist()
            checked += cnt
    assert checked > 400  # partners, not only empty windows
