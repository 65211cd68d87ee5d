"""The numbers README.md and docs/*.md quote (pipeline/prose.py): the shipped pages are current, a
changed constant or result makes them stale, the scene tables render from a small results folder
(rows, rounding, crossover), and a missing, unknown or unclosed marker is reported."""

from __future__ import annotations

import json
import math

import pandas as pd
import pytest
from conftest import ROOT

from particle_entropy.analysis import resampling
from particle_entropy.core.io import write_parquet
from particle_entropy.pipeline import prose
from particle_entropy.pipeline.prose import COMMAND, NUMBERS, check, load, main

REGENERATE = f"run `{COMMAND} --write` from the repository root (or `--from results --write` after a run)"


def test_shipped_pages_are_current():
    problems = check(ROOT, *load(ROOT))
    assert not problems, f"{problems}: {REGENERATE}"
    assert main(["--root", str(ROOT), "--check"]) == 0


def test_numbers_file_is_as_dumped():
    """docs/numbers.json is byte-stable: what dump writes of its own content."""
    text = (ROOT / NUMBERS).read_text(encoding="utf-8")
    assert prose.dump(json.loads(text)) == text


def test_a_changed_constant_is_stale(monkeypatch):
    monkeypatch.setattr(resampling, "N_RESAMPLES", 1999)
    problems = check(ROOT, *load(ROOT))
    assert any("stale" in p and "resampling.N_RESAMPLES" in p for p in problems), problems
    assert all("resampling.CONFIDENCE" not in p for p in problems)  # only the changed name


def test_a_changed_result_is_stale(tmp_path):
    numbers = json.loads((ROOT / NUMBERS).read_text(encoding="utf-8"))
    numbers["crossover"] = [1.0, 2.0]
    changed = tmp_path / "numbers.json"
    changed.write_text(prose.dump(numbers), encoding="utf-8")
    assert any("scenes.crossover" in p for p in check(ROOT, *load(ROOT, changed)))


# ------------------------------------------------------------------ a small synthetic results folder
def scene_rows(scene, peclet, rows, measure="rmse", target=0.1):
    """A scene table as scene_search.result writes it, with the columns prose reads."""
    t = pd.DataFrame(
        rows,
        columns=["candidate", "label", "method", "n", "realisations", "meets", "cost_s", "n_below", "unscored"],
    )
    t["recommended"] = False
    t["comic_best"] = False
    t["stopped"] = "met: every rung below it fails"
    t["scene"], t["peclet"], t["measure"], t["target"] = scene, peclet, measure, target
    flowing = (t["method"] == "fd") & (peclet > 0)
    t["grid_peclet"] = [peclet / n if f else math.nan for n, f in zip(t["n"], flowing)]
    t["courant"] = [0.75 if f else math.nan for f in flowing]
    return t


def mark(t, recommended, comic_best):
    """Set the recommended and COMIC-best rows (by candidate, n)."""
    for column, (c, n) in (("recommended", recommended), ("comic_best", comic_best)):
        t.loc[(t["candidate"] == c) & (t["n"] == n), column] = True
    return t


nan = math.nan
FD, PT = "fd implicit tvd Cr=0.75", "pt adaptive"


@pytest.fixture
def results(tmp_path):
    """Two user scenes (one where FD fails everywhere) and a two-point Peclet sweep."""
    folder = tmp_path / "results"
    tables = {
        "flow": mark(
            scene_rows(
                "flow",
                16970.56,
                [
                    [0, FD, "fd", 1000, 1, False, 0.073, nan, "mass lost through the window's ends: 0.002 of 1"],
                    [0, FD, "fd", 2000, 1, True, 1.8473, 1000.0, ""],
                    [1, PT, "pt", 668, 32, False, 0.0134, nan, ""],
                    [1, PT, "pt", 1243, 16, True, 0.015649, 668.0, ""],
                ],
            ),
            (1, 1243),
            (0, 2000),
        ),
        "rest": mark(
            scene_rows(
                "rest",
                0.0,
                [
                    [0, "fd implicit dt=5", "fd", 16, 1, True, 0.0077581, nan, ""],
                    [
                        1,
                        PT,
                        "pt",
                        8000,
                        8,
                        False,
                        0.3,
                        nan,
                        "negative concentrations from step 1 (t = 1): minimum -0.1",
                    ],
                ],
                measure="dilution",
                target=0.01,
            ),
            (0, 16),
            (0, 16),
        ),
        "peclet-0": scene_rows(
            "peclet-0", 0.0, [[0, FD, "fd", 64, 1, True, 0.004, nan, ""], [1, PT, "pt", 100, 8, True, 0.05, nan, ""]]
        ),
        "peclet-1": scene_rows(
            "peclet-1",
            5091.2,
            [[0, FD, "fd", 2048, 1, True, 0.19, 1024.0, ""], [1, PT, "pt", 100, 8, True, 0.05, nan, ""]],
        ),
    }
    for name, t in tables.items():
        write_parquet(t, folder / "scenes" / f"{name}.parquet")
    return folder


def test_scene_table_from_results(results):
    numbers = prose.numbers_from_results(results)
    lines = prose.scene_table(numbers).splitlines()
    assert len(lines) == 2 + 2  # header, rule, a row per user scene (the sweep's are apart), by name
    flow, rest = lines[2], lines[3]
    assert flow.startswith(
        "| `flow` | 16,971 | RMSE <= 0.1 | PT adaptive, N in (668, 1,243], 0.016 s (16 realisations) |"
    )
    assert "| FD implicit tvd Cr=0.75, n in (1,000, 2,000], 1.8 s |" in flow
    assert flow.endswith("| FD implicit tvd Cr=0.75, n = 2,000 |")
    assert rest.startswith(
        "| `rest` | 0 | E within 1 % | FD implicit dt=5, n = 16, 0.0078 s |"
    )  # met at its lowest rung
    assert "PT adaptive, not met up to N = 8,000 (negative concentrations)" in rest


def test_sweep_and_crossover_from_results(results):
    numbers = prose.numbers_from_results(results)
    rows = prose.sweep_table(numbers).splitlines()[2:]
    assert [r.split(" | ")[-1] for r in rows] == ["grid |", "particles |"]
    assert rows[1].startswith("| 5,091 | FD implicit tvd Cr=0.75, n = 2,048, grid Péclet 2.5, Courant 0.75, 0.19 s |")
    values = prose.result_values(numbers)
    assert values["scenes.crossover"] == "(0, 5,091]"
    assert values["scenes.crossover_implicit"] == "none in the sweep"  # no grid left: particles always win
    assert values["scenes.sweep_target"] == "RMSE <= 0.1"


PAGE = """Resamples: <!-- value resampling.N_RESAMPLES -->7<!-- /value -->.

<!-- table scenes.table -->
old
<!-- /table -->
"""


def test_write_then_check_a_page(results, tmp_path, monkeypatch):
    """--from results --write fills a page's spots; --check then passes, and fails once one is edited."""
    root = tmp_path / "repo"
    (root / "docs").mkdir(parents=True)
    page = root / "README.md"
    page.write_text(PAGE, encoding="utf-8")
    monkeypatch.setattr(prose, "code_values", lambda: {"resampling.N_RESAMPLES": "2000"})
    monkeypatch.setattr(prose, "result_values", lambda numbers: {})
    monkeypatch.setattr(prose, "result_blocks", lambda numbers: {"scenes.table": prose.scene_table(numbers)})
    assert main(["--root", str(root), "--from", str(results), "--write"]) == 0
    text = page.read_text(encoding="utf-8")
    assert "-->2000<!--" in text and "| `flow` | 16,971 |" in text and "old" not in text
    assert main(["--root", str(root), "--check"]) == 0
    assert main(["--root", str(root), "--from", str(results), "--check"]) == 0
    page.write_text(text.replace("16,971", "17,000"), encoding="utf-8")
    assert main(["--root", str(root), "--check"]) == 1


def test_missing_unknown_and_unclosed_markers():
    values, blocks = {"a": "1", "b": "2"}, {}
    text = "<!-- value a -->1<!-- /value --> <!-- value c -->3<!-- /value --> <!-- value b -->2"
    _, problems = prose.render(text, values, blocks)
    assert any("no value named 'c'" in p for p in problems)
    assert any("'b' is never closed" in p for p in problems)
    assert prose.render("`<!-- value X -->`", values, blocks) == ("`<!-- value X -->`", [])  # quoted


def test_a_missing_marker_is_reported(tmp_path):
    (tmp_path / "README.md").write_text("<!-- value a -->1<!-- /value -->\n", encoding="utf-8")
    problems = check(tmp_path, {"a": "1", "b": "2"}, {"t": "| x |\n"})
    assert problems == ["no marker for b", "no marker for t"]


def test_formats():
    assert [prose.seconds(x) for x in (0.000356, 0.0077581, 0.0157, 1.8473, 6.8801)] == [
        "0.00036",
        "0.0078",
        "0.016",
        "1.8",
        "6.9",
    ]
    assert prose.integer(16970.56) == "16,971" and prose.interval(508.9, 5091.2) == "(509, 5,091]"
    assert prose.power(1e-3) == "1e-3" and prose.power(2.5e-12) == "2.5e-12"
    assert prose.exponent(10**8) == "10^8" and prose.exponent(12345) == "12,345"
    assert prose.percent(0.95) == "95 %" and prose.target("entropy", 0.01) == "H_C within 0.01 nats"
    assert prose.model("mtpt collision eta=1") == "MTPT collision eta=1"


def test_the_2d_sweep_has_its_own_rows_crossover_and_target(results):
    """The 2-D sweep (peclet2d-<k>) is tabulated apart from the 1-D one, with its own crossover: here
    the grid wins at Pe 170 and particles at 679, while the 1-D sweep's crossover stays (0, 5,091]."""
    for k, (pe, fd_cost) in enumerate(((169.7, 0.04), (678.8, 13.0))):
        t = scene_rows(
            f"peclet2d-{k}",
            pe,
            [
                [0, FD, "fd", 64 * 4**k, 1, True, fd_cost, 32.0 * 4**k, ""],
                [1, PT, "pt", 16000, 8, True, 1.5, 8000.0, ""],
            ],
            target=0.2,
        )
        write_parquet(t, results / "scenes" / f"peclet2d-{k}.parquet")
    numbers = prose.numbers_from_results(results)
    assert [r["scene"] for r in numbers["sweep"]] == ["peclet-0", "peclet-1"]
    assert [r["scene"] for r in numbers["sweep2d"]] == ["peclet2d-0", "peclet2d-1"]
    assert [r["scene"] for r in numbers["scenes"]] == ["flow", "rest"]  # neither sweep among the user's
    values = prose.result_values(numbers)
    assert values["scenes.crossover"] == "(0, 5,091]"
    assert values["scenes.crossover2d"] == "(170, 679]"
    assert values["scenes.sweep2d_target"] == "RMSE <= 0.2"
    rows = prose.result_blocks(numbers)["scenes.sweep2d"].splitlines()[2:]
    assert [r.split(" | ")[-1] for r in rows] == ["grid |", "particles |"]
    assert rows[1].startswith("| 679 | FD implicit tvd Cr=0.75, n = 256, grid Péclet")


def test_numbers_without_a_2d_sweep_name_no_2d_values(results):
    """A config without scenes_peclet2d: no 2-D key in the numbers, so no page needs its markers."""
    numbers = prose.numbers_from_results(results)
    assert "sweep2d" not in numbers and "crossover2d" not in numbers
    assert not {k for k in prose.result_values(numbers) if "2d" in k}
    assert "scenes.sweep2d" not in prose.result_blocks(numbers)
