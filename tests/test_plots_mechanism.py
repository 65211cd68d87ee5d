"""The mechanism figure: its predicted floor against a numerical integral, paired differences
computed realisation by realisation, and the FD panel's values."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad

matplotlib.use("Agg")

from particle_entropy.core.case import Case, rows_of  # noqa: E402
from particle_entropy.figures.fig9_mechanism import fig9_mechanism, truncation_floor  # noqa: E402
from particle_entropy.numerics.bandwidths import truncated_variance_fraction  # noqa: E402

EQUATIONS = Case("mtpt", "collision", eta=1.0)
CUT = Case("mtpt", "collision", eta=1.0, truncation=3.0)
NS = (100, 300)


@pytest.mark.parametrize(("t", "fraction"), [(1000.0, truncated_variance_fraction(3.0)), (50.0, 0.8)])
def test_floor_is_the_integrated_squared_difference_of_the_two_gaussians(t, fraction):
    D, omega = 1e-3, 10.0
    g = lambda x, var: math.exp(-0.5 * x * x / var) / math.sqrt(2 * math.pi * var)
    integral, _ = quad(lambda x: (g(x, 2 * D * t) - g(x, 2 * fraction * D * t)) ** 2, -50, 50, limit=200)
    assert truncation_floor(D, t, fraction, omega) == pytest.approx(integral / omega, rel=1e-8)
    assert truncation_floor(D, t, 1.0, omega) == pytest.approx(0.0, abs=1e-15)


def _tables():
    rng = np.random.default_rng(0)
    comic, real = [], []
    for model, shift in ((EQUATIONS, 0.0), (CUT, 0.7)):
        for n in NS:
            values = -10.0 + shift + rng.normal(0, 0.3, 5)
            for seed, v in enumerate(values):
                real.append({**model.at(n).columns(), "time": 20.0, "time_step": 19.9, "seed": seed, "COMIC": v})
            comic.append(
                {
                    **model.at(n).columns(),
                    "time": 20.0,
                    "time_step": 19.9,
                    "COMIC_mean": values.mean(),
                    "COMIC_std": values.std(ddof=1),
                    "SSE_mean": 0.5 * n,
                    "SSE_std": 0.1 * n,
                    "n_realisations": 5,
                }
            )
    fd = pd.DataFrame(
        [
            {"n": 100, "fd_length": L, "time": t, "SSE": 1e-3 * t * (2 if L == 12 else 1)}
            for L in (12.0, 24.0)
            for t in (5.0, 10.0, 20.0)
        ]
    )
    return pd.DataFrame(comic), pd.DataFrame(real), fd


def test_paired_differences_are_means_over_the_same_seeds():
    comic, real, fd = _tables()
    cases = [m.at(n) for m in (EQUATIONS, CUT) for n in NS]
    _, data = fig9_mechanism(comic, real, fd, cases, D=1e-3, t_final=20.0, omega=10.0)
    c = rows_of(data[data["panel"] == "c"], CUT).sort_values("x")
    for n, row in zip(NS, c.itertuples(), strict=True):
        a = rows_of(real, CUT.at(n)).sort_values("seed")["COMIC"].to_numpy()
        b = rows_of(real, EQUATIONS.at(n)).sort_values("seed")["COMIC"].to_numpy()
        d = a - b
        assert row.y == pytest.approx(d.mean())
        assert row.y_hi - row.y == pytest.approx(d.std(ddof=1) / math.sqrt(d.size))
    assert rows_of(data[data["panel"] == "c"], EQUATIONS).empty  # the reference is not drawn against itself


def test_sse_panel_uses_standard_errors_and_the_fd_panel_ln_sse_over_n():
    comic, real, fd = _tables()
    cases = [m.at(n) for m in (EQUATIONS, CUT) for n in NS]
    _, data = fig9_mechanism(comic, real, fd, cases, D=1e-3, t_final=20.0, omega=10.0)
    b = data[(data["panel"] == "b") & (data["method"] == "mtpt")]
    assert np.allclose(b["y"], 0.5) and np.allclose(b["y_hi"] - b["y"], 0.1 / math.sqrt(5))
    floor = data[(data["panel"] == "b") & (data["method"] == "analytic")]
    assert np.allclose(
        floor["y"], truncation_floor(1e-3, 19.9, truncated_variance_fraction(3.0), 10.0)
    )  # recorded step
    d = data[data["panel"] == "d"].sort_values(["series", "x"])
    assert set(d["series"]) == {"FD N = 100, domain length 12", "FD N = 100, domain length 24"}
    short = d[d["series"].str.endswith("12")]
    np.testing.assert_allclose(short["y"], np.log(2e-3 * short["x"].to_numpy() / 100))


def test_floors_are_drawn_with_n_star_where_sampling_error_meets_them():
    rows, floors = [], []
    for model, f in ((EQUATIONS, 1e-6), (CUT, 8e-6)):
        for n in (1000, 3000):
            # SSE/N = a / N + f with a = 0.04: the figure's N* must be a / f
            rows.append(
                {
                    **model.at(n).columns(),
                    "time": 20.0,
                    "time_step": 19.9,
                    "COMIC_mean": -10.0,
                    "COMIC_std": 0.1,
                    "SSE_mean": (0.04 / n + f) * n,
                    "SSE_std": 0.0,
                    "n_realisations": 5,
                }
            )
        floors.append({**model.at(3001).columns(), "time": 20.0, "time_step": 19.9, "SSE_over_N": f})
    cases = [m.at(n) for m in (EQUATIONS, CUT) for n in (1000, 3000)]
    figure, data = fig9_mechanism(
        pd.DataFrame(rows),
        pd.DataFrame(),
        pd.DataFrame(),
        cases,
        D=1e-3,
        t_final=20.0,
        omega=10.0,
        floors=pd.DataFrame(floors),
    )
    lines = data[data["series"].str.endswith("lattice floor")]
    assert sorted(lines.groupby("series")["y"].first()) == [1e-6, 8e-6]
    texts = [t.get_text() for t in figure.axes[1].get_legend().get_texts()]
    assert any("N* = a/floor ≈ 40,000" in t for t in texts) and any("N* = a/floor ≈ 5,000" in t for t in texts)
