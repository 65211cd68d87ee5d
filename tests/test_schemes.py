"""The Scheme records drive the MTPT step: its flags, not the scheme's name, choose the transfer."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from particle_entropy.core import registry
from particle_entropy.core.registry import SCHEME_RECORDS, SCHEMES, Scheme
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models import mtpt
from particle_entropy.numerics import sequential

# What each scheme means, written out here from the module docstring of sequential.py and the
# paper (Eqs. 16-21), not read back from the records.
EXPECTED = {
    "symmetric": dict(sequential=False, compensated=False),
    "compensated": dict(sequential=False, compensated=True),
    "sequential": dict(sequential=True, by_label=True, symnorm=False, clip=True),
    "sequential_sorted": dict(sequential=True, by_label=False, symnorm=False, clip=True),
    "sequential_symnorm": dict(sequential=True, by_label=True, symnorm=True, clip=True),
    "sequential_noclip": dict(sequential=True, by_label=True, symnorm=False, clip=False),
    # the authors' script: their loop, h_SPH with 0.822 where Eq. 26 has 0.82
    "authors": dict(sequential=True, by_label=True, symnorm=False, clip=True, sph_constant=0.822),
}


def test_every_scheme_has_the_flags_it_names():
    assert set(SCHEMES) == set(EXPECTED)
    for name, flags in EXPECTED.items():
        rec = SCHEME_RECORDS[name]
        assert rec.name == name and rec.description
        assert {k: getattr(rec, k) for k in flags} == flags, name


def _state(n=40):
    x = np.linspace(-0.5, 0.5, n)
    m = np.zeros(n)
    m[n // 2] = 1.0
    return x, m, np.arange(n)[::-1].copy()


def _calls(monkeypatch):
    seen = []

    def fake(x, m, sigma, beta, truncation, rng, label=None, symnorm=False, clip=True, exact=False):
        seen.append({"label": label, "symnorm": symnorm, "clip": clip, "exact": exact})
        return m.copy()

    monkeypatch.setattr(sequential, "sequential_transfer", fake)
    return seen


@pytest.mark.parametrize("name", [s for s in SCHEMES if EXPECTED[s]["sequential"]])
def test_sequential_step_passes_the_records_flags(monkeypatch, name):
    seen = _calls(monkeypatch)
    cfg = RunConfig.of(method="mtpt", n=40, truncation=3.0, scheme=name).resolved()
    x, m, label = _state()
    mtpt.step(cfg, x, m, label, 0.1, 1.0, np.random.default_rng(0))
    (call,) = seen
    assert (call["label"] is label) == EXPECTED[name]["by_label"]
    assert call["label"] is None or np.array_equal(call["label"], label)
    assert (call["symnorm"], call["clip"]) == (EXPECTED[name]["symnorm"], EXPECTED[name]["clip"])
    assert call["exact"] is False  # numerics.loop_arithmetic: fused, the default


def test_the_loop_arithmetic_setting_reaches_the_loop(monkeypatch):
    seen = _calls(monkeypatch)
    x, m, label = _state()
    for arithmetic in ("exact", "fused"):
        cfg = RunConfig.of(method="mtpt", n=40, truncation=3.0, scheme="authors", loop_arithmetic=arithmetic).resolved()
        mtpt.step(cfg, x, m, label, 0.1, 1.0, np.random.default_rng(0))
    assert [c["exact"] for c in seen] == [True, False]


def test_a_new_record_needs_no_string_test(monkeypatch):
    """A scheme added only as a record (a name the step never spells) runs with its flags."""
    seen = _calls(monkeypatch)
    new = Scheme(
        "my_loop", "the authors' loop, symmetric weights, no clipping", sequential=True, symnorm=True, clip=False
    )
    monkeypatch.setitem(registry.SCHEME_RECORDS, "my_loop", new)
    cfg = RunConfig.of(method="mtpt", n=40).resolved()
    case = dataclasses.replace(cfg.case)
    object.__setattr__(case, "scheme", "my_loop")  # past Case's check, which knows the shipped names only
    cfg = dataclasses.replace(cfg, case=case)
    x, m, label = _state()
    mtpt.step(cfg, x, m, label, 0.1, 1.0, np.random.default_rng(0))
    assert seen == [{"label": label, "symnorm": True, "clip": False, "exact": False}]


def test_compensated_widens_the_cut_kernel_and_symmetric_does_not():
    x, m, label = _state(200)
    widths = {}
    for name in ("symmetric", "compensated"):
        cfg = RunConfig.of(method="mtpt", n=200, truncation=2.0, scheme=name).resolved()
        widths[name] = mtpt.step(cfg, x, m, label, 0.1, 1.0, np.random.default_rng(0))[3]
    # the variance of a Gaussian cut at 2 widths is 0.7737 of the whole one's (tables of the
    # truncated normal), so the compensated width is 1 / sqrt(0.7737) = 1.1369 times wider
    assert widths["compensated"] / widths["symmetric"] == pytest.approx(1.1369, abs=2e-4)


def test_the_authors_scheme_widens_the_sph_kernel_by_their_constant_only():
    x, m, label = _state(200)
    widths = {}
    for name in ("sequential", "authors"):
        for kernel in ("sph", "collision"):
            cfg = RunConfig.of(method="mtpt", kernel=kernel, n=200, truncation=3.0, scheme=name).resolved()
            widths[name, kernel] = mtpt.kernel_for_step(cfg, 0.1, 10.0)
    assert widths["authors", "sph"][0] / widths["sequential", "sph"][0] == pytest.approx(0.822 / 0.82, rel=1e-15)
    # beta = 2 eta D dt / h^2 (Eq. 20): 0.5 % smaller with the wider kernel
    assert widths["authors", "sph"][1] / widths["sequential", "sph"][1] == pytest.approx((0.82 / 0.822) ** 2, rel=1e-14)
    assert widths["authors", "collision"] == widths["sequential", "collision"]  # no SPH constant in Eq. 17
