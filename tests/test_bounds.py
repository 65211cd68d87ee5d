"""Finite settings whose arithmetic overflows (a step count, a variance, a grid) and counts that
scale memory are refused before any job, by key (config) or option (CLI), with the allowed
range: never an OverflowError, an IndexError or a job that fails later (issue 33, items 5a, 5b)."""

from __future__ import annotations

import copy
import math
import subprocess
import sys

import pytest
import yaml
from conftest import ROOT

from particle_entropy.core.case import SettingError
from particle_entropy.pipeline.configcheck import check_config

BASE = yaml.safe_load((ROOT / "config.yaml").read_text())

# (section, key, value, what the allowed range must say): the tester's values
OVERFLOWS = [
    ("physics", "t_final", 1.0e308, "a number in (0, "),
    ("time", "dt0", 1.0e-308, "2 D dt0 a normal float"),
    ("physics", "fixed_kernel_time", 1.0e308, "a number in ["),
    ("physics", "fixed_kernel_time", 1.0e-300, "a number in ["),
]


def _allowed_interval(message: str) -> tuple[float, float]:
    """The [low, high] or (0, high] a message gives as the allowed range."""
    inner = message.split("a number in ", 1)[1]
    low, high = inner[1:].split("]", 1)[0].split(", ")
    return float(low), float(high)


@pytest.mark.parametrize("section,key,value,allowed", OVERFLOWS, ids=[f"{o[1]}={o[2]:g}" for o in OVERFLOWS])
def test_overflowing_settings_are_refused_by_key_in_the_config(section, key, value, allowed):
    """Before: t_final 1e308 and dt0 1e-308 raised OverflowError (cannot convert float infinity to
    integer) in check-config and the dry run; fixed_kernel_time 1e308 / 1e-300 were accepted and
    every PT-fixed job then failed building a grid of ~1e154 points."""
    cfg = copy.deepcopy(BASE)
    cfg[section][key] = value
    with pytest.raises(SettingError) as err:
        check_config(cfg)
    message = str(err.value)
    assert message.startswith(f"{section}.{key}={value!r} is not allowed: "), message
    assert allowed in message and "\n" not in message and len(message) < 400, message
    if "a number in" in allowed:  # the range it states holds the paper's value and excludes this one
        low, high = _allowed_interval(message)
        assert low <= BASE[section][key] <= high and not low <= value <= high


def test_the_stated_ranges_are_where_the_arithmetic_holds():
    """The ends of the stated ranges, at the paper's D: a fixed kernel at the top end builds a grid
    within 10^8 points, a first step at the low end has a normal variance, and values just past
    the ends are refused."""
    from particle_entropy.core.runconfig import RunConfig

    def refused(**settings):
        try:
            RunConfig.of(**settings).resolved()
        except SettingError as e:
            return e
        return None

    err = refused(method="pt", kernel="fixed", fixed_kernel_time=1e308)
    low, high = _allowed_interval(str(err))
    for inside in (low * 1.01, high * 0.99):
        assert refused(method="pt", kernel="fixed", fixed_kernel_time=inside) is None
        h = math.sqrt(2 * 1e-3 * inside)  # the kernel's width; its grid holds the 8-sigma plume and 6 h
        plume = 2 * 8 * math.sqrt(2 * 1e-3 * 1000.0)
        assert (plume + 12 * h) / min(0.1, h / 4) <= 1e8
    for outside in (low / 1.1, high * 1.1):
        assert refused(method="pt", kernel="fixed", fixed_kernel_time=outside).name == "fixed_kernel_time"
    assert refused(dt0=1.2e-305) is None  # 2 D dt0 = 2.4e-308, just normal
    assert refused(dt0=1.0e-305).name == "dt0"
    err = refused(t_final=1e308)
    low, high = _allowed_interval(str(err))
    wide = 2.5 * math.sqrt(2 * 1e-3 * high)  # a particle domain that holds the plume at that t_final
    assert refused(t_final=high * 0.99, dt0=high / 100, omega=wide) is None
    assert refused(t_final=high * 1.01, omega=wide).name == "t_final"


def test_step_counts_are_exact_where_the_ratio_overflows():
    from particle_entropy.core.timegrid import MAX_STEPS, max_first_step, step_count

    assert step_count(1e308, 1e-2, 1.0) > 10**309  # t_final / dt0 = inf as a float: no OverflowError
    # the smallest n with dt0 (g^n - 1) / (g - 1) >= t_final, g^n >= 5e308 + 1: in logs, as 5e308 overflows
    n = step_count(1e308, 1e-2, 1.05)
    log_target = math.log(5.0) + 308 * math.log(10.0)
    assert (n - 1) * math.log(1.05) < log_target <= n * math.log(1.05)
    assert max_first_step(1000.0, 1.05) == 0.0  # 1.05^(10^7) overflows: every float dt0 fits
    assert max_first_step(1000.0, 1.0) == 1000.0 / MAX_STEPS


CLI_OVERFLOWS = [
    (["--t-final", "1e308"], "--t-final"),
    (["--dt0", "1e-308"], "--dt0"),
    (["--method", "pt", "--kernel", "fixed", "--fixed-kernel-time", "1e308"], "--fixed-kernel-time"),
    (["--method", "pt", "--kernel", "fixed", "--fixed-kernel-time", "1e-300"], "--fixed-kernel-time"),
]


def test_overflowing_options_exit_2_naming_the_option(tmp_path):
    """Before: --t-final 1e308 and --dt0 1e-308 ended in an OverflowError traceback, and
    --fixed-kernel-time 1e308 (pt fixed) in 'ValueError: Maximum allowed size exceeded'."""
    runs = []
    for i, (args, option) in enumerate(CLI_OVERFLOWS):
        out = tmp_path / f"out{i}.parquet"
        cmd = [sys.executable, "-m", "particle_entropy", "simulate", "--n", "20", *args, "--out", str(out), "--quiet"]
        runs.append((subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True), option, args[-1]))
    for proc, option, value in runs:
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 2, err[-2000:]
        assert "Traceback" not in err
        line = err.strip().splitlines()[-1]
        assert f"error: {option}: " in line and f"={float(value)!r} is not allowed: a number" in line, line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "n,available,expected",
    [
        (2**63 + 1, None, "an odd integer in [3, 1,000,000,000]"),  # the schema, even where memory is not checked
        (200_000_001, 8e9, "an N whose job fits in this machine's memory"),  # mtpt: ~400 B a particle, ~80 GB
    ],
    ids=["2^63+1 schema", "2e8 memory"],
)
def test_the_lattice_size_is_bounded_by_the_schema_and_memory(n, available, expected):
    """Before: n = 200000001 passed the schema and the memory check (the floors job was not
    counted) and 2^63+1 died in the job with an IndexError."""
    cfg = copy.deepcopy(BASE)
    cfg["mechanism"]["lattice"]["n"] = n
    with pytest.raises(SettingError) as err:
        check_config(cfg, available=available)
    assert str(err.value).startswith(f"mechanism.lattice.n={n} is not allowed: ") and expected in str(err.value)
    check_config(BASE, available=8e9)  # the shipped lattice (3,001) fits


def test_fig9_titles_lie_inside_the_figure_with_seven_models():
    """Before: with seven models, panel (e)'s title ran past the figure's right edge. Every
    title's drawn extent (and its wrapped lines) now lies inside its panel and the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from test_plots import draw

    from particle_entropy.core.case import Case

    families = [
        ("collision", 1.0, 1.05),
        ("sph", 1.0, 1.05),
        ("collision", 0.333333333, 1.0123456789),  # panel (e): the longest label, in the right column
        ("collision", 0.25, 1.0123),
        ("sph", 0.75, 1.0125),
        ("collision", 0.125, 1.001),
        ("sph", 0.5, 1.2),
    ]
    cases = [Case("mtpt", k, n, eta=e, dt_growth=g) for k, e, g in families for n in (30, 100, 300)]
    figure, _ = draw("fig9", cases)
    FigureCanvasAgg(figure).draw()
    renderer, page = figure.canvas.get_renderer(), figure.bbox
    titles = [(ax, t) for ax in figure.axes if ax.get_visible() for t in (ax.title, ax._left_title) if t.get_text()]
    assert len(titles) == 14  # a COMIC panel and a share panel per model
    for ax, title in titles:
        box, room = title.get_window_extent(renderer), ax.get_window_extent(renderer)
        inside = page.x0 - 0.5 <= box.x0 and box.x1 <= page.x1 + 0.5 and page.y0 <= box.y0 and box.y1 <= page.y1
        assert inside and box.x1 <= room.x1 + 0.5, (title.get_text(), box, room, page)
    assert any("\n" in t.get_text() for _, t in titles)  # the long ones were wrapped, not dropped
