"""The Snakemake workflow: config schema, dry runs, a tiny end-to-end run and its properties."""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import ROOT, TINY, run_snakemake, snakemake_command
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from particle_entropy.analysis.rounds import READ_SUFFIX, read_path
from particle_entropy.core.case import CASE_COLUMNS, MODEL_COLUMNS, Case, rows_of
from particle_entropy.core.columns import PLANE_ONLY_COLUMNS, RELEASE_ONLY_COLUMNS
from particle_entropy.core.labels import case_label
from particle_entropy.core.records import TIMING_COLUMNS
from particle_entropy.figures import CASE_FIGURES, FIGURES
from particle_entropy.numerics.compiled import CACHE_ENV
from particle_entropy.pipeline.configcheck import parse
from particle_entropy.pipeline.sweeps import (
    Ensemble,
    case_run_paths,
    figure_ensembles,
    run_path,
)

SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"

# figures.FIGURES, the one list: the default target draws every figure but the mechanism figure
# and the searches, which are their own targets (fig1 ... fig10 and tradeoff: test_settings holds the names)
DEFAULT_FIGURES = [
    f.name for f in FIGURES if f.name not in ("fig9_mechanism", "optimum", "scene", "scenes_peclet")
]  # own targets


def load(path):
    return yaml.safe_load(Path(path).read_text())


def planned_outputs(proc, prefix="results/runs/"):
    """Outputs of the jobs a dry run plans, for one output folder."""
    lines = re.findall(r"^\s*output: (.*)$", proc.stdout + proc.stderr, flags=re.M)
    return sorted({p for line in lines for p in line.split(", ") if p.startswith(prefix)})


# --- schema --------------------------------------------------------------------------------


def test_shipped_config_is_valid():
    validate(load(ROOT / "config.yaml"), str(SCHEMA))


BAD = [
    (("physics", "D"), -1.0, "D"),
    (("physics", "t_final"), 0, "t_final"),
    (("case_defaults", "dt_growth"), 0.9, "dt_growth"),
    (("case_defaults", "scheme"), "parallel", "scheme"),
    (("base_seed",), -3, "base_seed"),
    (("figures", "fig9", "n"), [0, 100], "n"),
    (("figures", "fig5", "cases"), [{"method": "mtpt", "kernel": "collision", "eta": 1.5}], "eta"),
    (("figures", "fig1", "cases"), [{"method": "lbm", "kernel": "bins"}], "method"),
    (("figures", "fig9", "realisations"), 0, "realisations"),
    (("seed_blocks", "size"), 0, "size"),
    (("physics", "dx"), 0.1, "dx"),  # unknown key
]


@pytest.mark.parametrize("keys,value,name", BAD, ids=[b[2] + "=" + str(b[1])[:12] for b in BAD])
def test_bad_config_names_the_key(keys, value, name):
    cfg = load(ROOT / "config.yaml")
    node = cfg
    for k in keys[:-1]:
        node = node[k]
    node[keys[-1]] = value
    with pytest.raises(WorkflowError) as err:
        validate(cfg, str(SCHEMA))
    assert name in str(err.value)


def test_bad_config_stops_before_any_job(tmp_path):
    cfg = load(ROOT / "config.yaml")
    cfg["figures"]["fig9"]["cases"][0]["eta"] = 2
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(cfg, sort_keys=True))
    proc = run_snakemake(tmp_path, dry_run=True, configfile=bad, check=False)
    assert proc.returncode != 0
    out = proc.stdout + proc.stderr
    assert "eta" in out and "maximum" in out and "2" in out
    assert not (tmp_path / "results").exists()


def test_kernel_method_mismatch_is_refused(tmp_path):
    cfg = load(ROOT / "config.yaml")
    cfg["figures"]["fig1"]["cases"][0] = {"method": "pt", "kernel": "sph"}
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(cfg, sort_keys=True))
    proc = run_snakemake(tmp_path, dry_run=True, configfile=bad, check=False)
    assert proc.returncode != 0
    assert "figures.fig1.cases[0].kernel='sph'" in proc.stdout + proc.stderr


def test_nan_in_the_yaml_is_refused_before_any_job(tmp_path):
    text = (ROOT / "config.yaml").read_text().replace("D: 1.0e-3", "D: .nan", 1)
    assert "D: .nan" in text
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    proc = run_snakemake(tmp_path, dry_run=True, configfile=bad, check=False)
    assert proc.returncode != 0
    assert "physics.D=nan is not allowed: a finite number" in proc.stdout + proc.stderr
    assert not (tmp_path / "results").exists()


# --- dry runs on the full config -------------------------------------------------------------


def test_full_dry_run_plans_every_figure(tmp_path):
    proc = run_snakemake(tmp_path, dry_run=True, configfile=ROOT / "config.yaml")
    out = proc.stdout + proc.stderr
    for fig in DEFAULT_FIGURES:
        assert f"figures/{fig}.png" in out, fig
    assert "results/paper_claims.md" in out
    fig9 = planned_outputs(run_snakemake(tmp_path, "figures/fig9.png", dry_run=True, configfile=ROOT / "config.yaml"))
    # 3 models x 2 schemes x (80 + 80 + 60 + 50 + 20 + 6 + 4 seeds in blocks of 20, N <= 30,000)
    assert len(fig9) == 6 * (4 + 4 + 3 + 3 + 1 + 1 + 1)
    assert "figures/fig9_mechanism.png" not in out  # its own target, not part of the paper's run


def test_one_figure_runs_only_its_jobs(tmp_path):
    proc = run_snakemake(tmp_path, "figures/fig8.png", dry_run=True, configfile=ROOT / "config.yaml")
    runs = planned_outputs(proc)
    assert len(runs) == 7
    assert all(r.startswith("results/runs/fd/implicit/") for r in runs)
    assert "results/runs/mtpt" not in proc.stdout and "results/runs/pt" not in proc.stdout


@pytest.mark.parametrize("target", ["crate", "results/ro-crate/ro-crate-metadata.json"])
def test_a_file_where_the_crate_goes_is_refused_in_one_line_before_any_job(tmp_path, target):
    (tmp_path / "results").mkdir()
    (tmp_path / "results/ro-crate").write_text("not a folder\n")
    proc = run_snakemake(tmp_path, target, dry_run=True, check=False, configfile=TINY)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "results/ro-crate is a file, not a folder" in out, out[-1500:]
    assert "Traceback" not in out and "Building DAG" not in out  # refused as the Snakefile is read
    assert run_snakemake(tmp_path, dry_run=True, configfile=TINY).returncode == 0  # other targets are not refused


def test_slurm_profile_parses(tmp_path):
    proc = run_snakemake(
        tmp_path,
        "--profile",
        str(ROOT / "workflow/profiles/slurm"),
        "figures/fig8.png",
        dry_run=True,
        configfile=ROOT / "config.yaml",
    )
    assert len(planned_outputs(proc)) == 7


# --- a tiny end-to-end run --------------------------------------------------------------------


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    work = tmp_path_factory.mktemp("tiny")
    run_snakemake(work, configfile=TINY)
    return work


def test_tiny_run_builds_every_figure(tiny_run):
    for fig in DEFAULT_FIGURES:
        for ext in ("png", "pdf"):
            f = tiny_run / "figures" / f"{fig}.{ext}"
            assert f.exists() and f.stat().st_size > 5000, f


def test_tiny_run_tables_have_documented_columns(tiny_run, tiny_config):
    comic = pd.read_parquet(tiny_run / "results/tables/comic.parquet")
    assert {"label", *CASE_COLUMNS, "time", "COMIC_mean", "COMIC_std", "SSE_mean", "SSE_std", "n_realisations"} <= set(
        comic.columns
    )
    cfg = tiny_config
    # the COMIC table holds every case of Figs. 8 and 9 (written out by hand in EXPECTED_TABLES)
    assert _case_folders(comic) == _expected_folders("fig8") | _expected_folders("fig9")
    minima = pd.read_parquet(tiny_run / "results/tables/comic_minima.parquet")
    assert {"label", *MODEL_COLUMNS, "time", "n_opt", "COMIC_opt", "n_below", "n_above"} <= set(minima.columns)
    for _, m in minima.iterrows():  # the reported optimum really is the smallest mean COMIC of its model
        g = rows_of(comic, Case.from_row(m))
        g = g[g["time"] == m["time"]]
        assert len(g) == len(cfg["figures"]["fig9" if m["method"] == "mtpt" else "fig8"]["n"])
        assert m["COMIC_opt"] == g["COMIC_mean"].min()
    claims = pd.read_parquet(tiny_run / "results/tables/paper_claims.parquet")
    assert {"claim", "paper", "reproduced", "tolerance", "passed"} <= set(claims.columns)
    assert (tiny_run / "results/paper_claims.md").read_text().count("| ") > len(claims)
    run = next((tiny_run / "results/runs/mtpt").rglob("*.parquet"))
    cols = set(pd.read_parquet(run).columns)
    assert {
        "step",
        "time",
        "dt",
        "H_D",
        "H_C",
        "E",
        "SSE",
        "COMIC",
        "mass_total",
        "mass_min",
        "beta",
        "h",
        "substeps",
        "wall_s",
        "seed",
    } <= cols


def test_summary_averages_its_realisations(tiny_run):
    summary_file = next((tiny_run / "results/tables/cases/mtpt/collision").rglob("r~3.parquet"))
    summary = pd.read_parquet(summary_file)
    runs_dir = Path(str(summary_file.parent).replace("tables/cases", "runs"))
    runs = pd.concat([pd.read_parquet(p) for p in runs_dir.glob("seeds~*.parquet")])
    assert sorted(runs["seed"].unique()) == [0, 1, 2]
    expected = runs.groupby("step")["COMIC"].mean().to_numpy()
    last = len(summary) - 1
    assert summary["n_realisations"].iloc[0] == 3
    assert summary["COMIC_mean"].iloc[last] == pytest.approx(expected[last], rel=1e-12)


def test_new_sweep_value_adds_only_its_jobs(tiny_run, tmp_path, tiny_config):
    cfg = tiny_config
    cfg["figures"]["fig9"]["n"] = cfg["figures"]["fig9"]["n"] + [400]
    cfg["realisations"].append({"n": 400, "count": 2})
    new = tmp_path / "more.yaml"
    new.write_text(yaml.safe_dump(cfg, sort_keys=True))
    proc = run_snakemake(tiny_run, dry_run=True, configfile=new)
    runs = planned_outputs(proc)
    assert runs and all("/n~400/" in r for r in runs)
    models = len(cfg["figures"]["fig9"]["cases"])
    assert len(runs) == models * 2  # each Fig. 9 model x 2 seeds, one seed a job (N = 400 > seed_blocks.max_n)
    figs = set(planned_outputs(proc, prefix="figures/"))
    assert figs == {"figures/fig9.png", "figures/fig9.pdf"}


def test_more_seeds_add_only_new_blocks(tiny_run, tmp_path, tiny_config):
    cfg = tiny_config
    cfg["realisations"] = [dict(e, count=e["count"] + 2) if e["n"] == 200 else e for e in cfg["realisations"]]
    new = tmp_path / "seeds.yaml"
    new.write_text(yaml.safe_dump(cfg, sort_keys=True))
    runs = planned_outputs(run_snakemake(tiny_run, dry_run=True, configfile=new))
    assert runs and all("/n~200/" in r for r in runs)
    assert all(not r.endswith("seeds~0-0.parquet") and not r.endswith("seeds~1-1.parquet") for r in runs)


# --- a figure target pulls only its own simulations ------------------------------------------


# What each figure target of tests/data/tiny_config.yaml plans in an empty directory, written
# out by hand from that file, not from the library (layout: docs/running.md "Output layout"; seeds:
# docs/architecture.md "Seeds"): results/{runs|snapshots}/<case>/seeds~A-B.parquet.
# - <case> is method/kernel/n~N/eta~E/trunc~T/growth~G/scheme~S/grid~R. What a case leaves unset
#   comes from case_defaults (eta 1, truncation none, dt_growth 1.3), else the paper's (scheme
#   symmetric, time grid exact); `preset: authors` is truncation 3, scheme authors, grid authors.
#   FD takes eta 1, truncation none, growth 1 whatever the defaults.
BINS = "pt/bins/n~{n}/eta~1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
FIXED = "pt/fixed/n~{n}/eta~1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
ADAPTIVE = "pt/adaptive/n~{n}/eta~1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
COLLISION_1 = "mtpt/collision/n~{n}/eta~1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
COLLISION_05 = "mtpt/collision/n~{n}/eta~0.5/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
COLLISION_01 = "mtpt/collision/n~{n}/eta~0.1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
COLLISION_025_CUT = "mtpt/collision/n~{n}/eta~0.25/trunc~3/growth~1.3/scheme~symmetric/grid~exact"
COLLISION_1_CUT = "mtpt/collision/n~{n}/eta~1/trunc~3/growth~1.3/scheme~symmetric/grid~exact"
COLLISION_1_CUT_SEQUENTIAL = "mtpt/collision/n~{n}/eta~1/trunc~3/growth~1.3/scheme~sequential/grid~exact"
SPH_1 = "mtpt/sph/n~{n}/eta~1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
SPH_01 = "mtpt/sph/n~{n}/eta~0.1/trunc~none/growth~1.3/scheme~symmetric/grid~exact"
SPH_AUTHORS = "mtpt/sph/n~{n}/eta~1/trunc~3/growth~1.3/scheme~authors/grid~authors"
FD = "fd/implicit/n~{n}/eta~1/trunc~none/growth~1/scheme~symmetric/grid~exact"
# - Seeds A-B of each N. Realisation r has seed base_seed + r = r. `realisations: 1` is seed 0,
#   and FD runs once; `ensemble` is the `realisations` count of N (30: 3, 60: 3, 100: 2, 200: 2),
#   capped at max_realisations. For N <= seed_blocks.max_n = 60, seeds run seed_blocks.size = 2
#   to a job, in blocks starting at 0, 2, ...; above it, one seed a job.
SEED_0 = {30: ["0-0"], 100: ["0-0"]}  # n [30, 100], one realisation
CAPPED_AT_2 = {30: ["0-1"], 100: ["0-0", "1-1"]}  # n [30, 100]: 3 -> 2 seeds, one block; 2 seeds, two jobs
FIG6_SEEDS = {30: ["0-1"], 60: ["0-1"], 100: ["0-0", "1-1"], 200: ["0-0", "1-1"]}  # each capped at 2
FIG8_SEEDS = {30: ["0-0"], 60: ["0-0"], 100: ["0-0"], 200: ["0-0"]}  # FD: once
FIG9_SEEDS = {30: ["0-1", "2-2"], 60: ["0-1", "2-2"], 100: ["0-0", "1-1"], 200: ["0-0", "1-1"]}  # 3, 3, 2, 2: no cap
TRADEOFF_SEEDS = {30: ["0-1"], 60: ["0-1"]}  # capped at 2 (3 -> 2 both)
TRADEOFF_FD_SEEDS = {30: ["0-0"], 60: ["0-0"]}


def _tables(kind, cases, seeds):
    return {f"results/{kind}/{c.format(n=n)}/seeds~{s}.parquet" for c in cases for n, ss in seeds.items() for s in ss}


# - Figs. 1 and 2 read the run of seed 0 of each case; Fig. 7 final states (results/snapshots/),
#   no per-step table; every other figure the runs of its ensembles (counts: cases x tables of a case).
EXPECTED_TABLES = {  # figure: (its run tables, its snapshot tables)
    "fig1": (_tables("runs", [BINS, FIXED, COLLISION_1], SEED_0), set()),  # 3 x 2
    "fig2": (_tables("runs", [BINS, FIXED, COLLISION_1], SEED_0), set()),  # 3 x 2
    "fig3": (_tables("runs", [ADAPTIVE, SPH_1], CAPPED_AT_2), set()),  # 2 x 3
    "fig4": (_tables("runs", [ADAPTIVE, SPH_1, COLLISION_1], CAPPED_AT_2), set()),  # 3 x 3
    "fig5": (  # 5 x 3
        _tables("runs", [COLLISION_1, COLLISION_01, SPH_1, SPH_01, COLLISION_025_CUT], CAPPED_AT_2),
        set(),
    ),
    "fig6": (_tables("runs", [COLLISION_1], FIG6_SEEDS), set()),  # 1 x 6
    "fig7": (set(), _tables("snapshots", [COLLISION_01, FIXED], SEED_0)),  # 2 x 2 snapshots
    "fig8": (_tables("runs", [FD], FIG8_SEEDS), set()),  # 1 x 4
    "fig9": (  # 6 x 8
        _tables(
            "runs",
            [COLLISION_1, SPH_1, COLLISION_05, COLLISION_1_CUT, COLLISION_1_CUT_SEQUENTIAL, SPH_AUTHORS],
            FIG9_SEEDS,
        ),
        set(),
    ),
    "tradeoff": (  # 1 x 2 + 4 x 2
        _tables("runs", [FD], TRADEOFF_FD_SEEDS)
        | _tables("runs", [ADAPTIVE, COLLISION_1, COLLISION_1_CUT, COLLISION_1_CUT_SEQUENTIAL], TRADEOFF_SEEDS),
        set(),
    ),
}


def _expected_folders(fig):
    """The case folders of a figure's hand-written tables (EXPECTED_TABLES), one per case and N."""
    runs, snapshots = EXPECTED_TABLES[fig]
    return {p.split("/", 2)[2].rsplit("/", 1)[0] for p in runs | snapshots}


def _case_folders(table):
    """The case folders of a table's rows (Case.path of each method, kernel, N and dimensions)."""
    return {Case.from_row(r).path() for _, r in table[list(CASE_COLUMNS)].drop_duplicates().iterrows()}


@pytest.mark.parametrize("fig", list(EXPECTED_TABLES))
def test_each_figure_target_plans_only_its_runs(fig, tmp_path):
    runs, snapshots = EXPECTED_TABLES[fig]
    proc = run_snakemake(tmp_path, f"figures/{fig}.png", dry_run=True, configfile=TINY)
    assert set(planned_outputs(proc)) == runs
    # particle snapshots only where a figure plots them
    assert set(planned_outputs(proc, prefix="results/snapshots/")) == snapshots
    assert planned_outputs(proc, prefix="results/shear/") == []


def test_fig10_target_runs_only_the_shear_cases(tmp_path):
    proc = run_snakemake(tmp_path, "figures/fig10.png", dry_run=True, configfile=TINY)
    assert planned_outputs(proc) == []
    shear = planned_outputs(proc, prefix="results/shear/")
    assert sorted(shear) == sorted(
        f"results/shear/{c}/seed~0/{f}.parquet" for c in ("rw_nodrift", "rw_drift", "mt") for f in ("steps", "state")
    )


# --- a killed run resumes to the same tables ----------------------------------------------------


def test_sigkill_then_rerun_gives_identical_tables(tiny_run, tmp_path):
    import os
    import signal
    import time

    target = "results/tables/comic.parquet"
    cmd = snakemake_command(tmp_path, target, configfile=TINY)
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 120
    while time.time() < deadline and len(list((tmp_path / "results").rglob("*.parquet"))) < 6:
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)  # no clean-up: jobs die mid-write or mid-run
    proc.wait()
    assert not (tmp_path / target).exists(), "the run finished before it could be killed"
    again = run_snakemake(tmp_path, target, configfile=TINY, check=False)  # the killed run's lock is still there
    assert again.returncode != 0 and "--unlock" in again.stdout + again.stderr
    run_snakemake(tmp_path, "--unlock", configfile=TINY)  # README: after a kill -9, unlock, then the same command
    run_snakemake(tmp_path, target, configfile=TINY)
    assert (tmp_path / target).read_bytes() == (tiny_run / target).read_bytes()
    for new in (tmp_path / "results/runs").rglob("*.parquet"):
        old = tiny_run / new.relative_to(tmp_path)
        a, b = (pd.read_parquet(p).drop(columns=["wall_s", "peak_rss_mb"]) for p in (new, old))
        pd.testing.assert_frame_equal(a, b)
    assert not list((tmp_path / "results").rglob("*.tmp"))  # no half-written file left behind


def test_report_holds_every_figure_with_its_caption(tiny_run):
    run_snakemake(tiny_run, "--report", "report.html", configfile=TINY)
    html = (tiny_run / "report.html").read_text(errors="replace")
    assert len(html) > 100_000
    for fig in DEFAULT_FIGURES:
        assert f"{fig}.png" in html, fig
    assert "Reproduces" in html
    # each figure says where it came from: commit, config digest, rule, module, source table and digest
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    for fig in DEFAULT_FIGURES:
        data = f"results/figures/{fig}.parquet"
        recorded = (tiny_run / (data + ".sha256")).read_text().split()[0]
        entry = re.search(r'"labels": \{"figure": "' + fig + r'"[^}]*\}', html)
        assert entry, fig
        labels = json.loads(entry.group(0)[len('"labels": ') :])
        assert labels["commit"].startswith(commit[:12]) and labels["rule"] == f"plot_{fig}", labels
        assert labels["module"] == f"workflow/lib/particle_entropy/figures/{fig}.py"
        assert (ROOT / labels["module"]).is_file()
        assert labels["source data"] == data and labels["source sha256"] == recorded[:16]
        assert re.fullmatch(r"[0-9a-f]{16}", labels["config sha256"])


def test_the_crate_of_a_run_is_valid_and_holds_what_made_each_figure(tiny_run_copy):
    """`snakemake crate` writes a Provenance Run Crate that the RO-Crate validator accepts (its
    REQUIRED checks), whose every file has the digest it records, and whose actions trace each figure
    to its rule and inputs; a crate with a missing file or a wrong digest is caught."""
    from crate_validation import validate_crate

    from particle_entropy.pipeline.crate import METADATA, verify_crate
    from particle_entropy.pipeline.verify import DIGESTS, cached_digests, corrupt_tables, file_sha256, stamp

    def listed(entity, key):  # RO-Crate 1.1 writes one value without brackets
        value = entity.get(key, [])
        return value if isinstance(value, list) else [value]

    work = tiny_run_copy
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True)
    commit = head.stdout.strip()
    run_snakemake(work, "crate", configfile=TINY)
    crate = work / "results/ro-crate"
    graph = {e["@id"]: e for e in json.loads((crate / METADATA).read_text())["@graph"]}
    assert validate_crate(crate) == []
    assert verify_crate(crate) == []
    for fig in DEFAULT_FIGURES:
        png = f"figures/{fig}.png"
        assert graph[png]["sha256"] == file_sha256(work / png)
        made = [e for e in graph.values() if e.get("@type") == "CreateAction" and {"@id": png} in listed(e, "result")]
        (action,) = [e for e in made if e["@id"] != "#run"]  # the job; the run's action lists every figure
        assert graph[action["instrument"]["@id"]]["name"] == f"rule plot_{fig}"
        assert {"@id": f"results/figures/{fig}.parquet"} in listed(action, "result")
        # its code hash, and the commit it ran at as its run recorded it (the tiny run's, this checkout's)
        ran = r"code hash [0-9a-f]{16}; ran at commit [0-9a-f]{40} \((clean|dirty: .*)\)"
        assert re.fullmatch(ran, action["description"]), action["description"]
        assert f"ran at commit {commit}" in action["description"]
    assert graph["config-as-run.yaml"]["sha256"] == file_sha256(crate / "config-as-run.yaml")
    assert graph["https://doi.org/10.1016/j.advwatres.2020.103509"]["@type"] == "ScholarlyArticle"
    assert (crate / "requirements.lock").read_bytes() == (ROOT / "requirements.lock").read_bytes()
    assert "commit " in graph["#git"]["value"]
    assert "SHA-256 " + graph["config-as-run.yaml"]["sha256"] in (crate / "README.md").read_text()
    tools = [e for e in graph.values() if str(e["@id"]).startswith("#rule-plot_")]
    assert tools and all(re.fullmatch(r"[0-9a-f]{16}", t["softwareVersion"]) for t in tools)  # the code hash
    # an author added by hand, as docs/deposit.md says, and a figure edited by hand since its job
    meta = json.loads((crate / METADATA).read_text())
    meta["@graph"].append({"@id": "https://orcid.org/0000-0002-1825-0097", "@type": "Person", "name": "J. Carberry"})
    next(e for e in meta["@graph"] if e["@id"] == "./")["author"] = {"@id": "https://orcid.org/0000-0002-1825-0097"}
    (crate / METADATA).write_text(json.dumps(meta))
    with (work / "figures/fig2.png").open("ab") as f:
        f.write(b"an edit")
    # the crate read no table the check had read, and the next check reads none again: the cache's
    # entries of the linked tables carry their new ctime; and the check skips the crate's links
    run_snakemake(work, "crate", "--forcerun", "crate", configfile=TINY)  # a rebuild keeps the links that hold
    assert "0 tables hashed" in (work / "logs/crate.log").read_text()
    graph = {e["@id"]: e for e in json.loads((crate / METADATA).read_text())["@graph"]}
    assert graph["./"]["author"] == {"@id": "https://orcid.org/0000-0002-1825-0097"}  # kept
    assert graph["https://orcid.org/0000-0002-1825-0097"]["name"] == "J. Carberry"
    made = [e for e in graph.values() if {"@id": "figures/fig2.png"} in listed(e, "result")]
    assert made == [] and "changed since the job plot_fig2" in graph["figures/fig2.png"]["description"]
    assert validate_crate(crate) == [] and verify_crate(crate) == []
    cache = cached_digests(work / DIGESTS)
    linked = [k for k in cache if (crate / "results" / k).is_file()]
    assert len(linked) > 50 and all(cache[k][:4] == stamp((work / "results" / k).stat()) for k in linked)
    assert not [p for p in corrupt_tables(work / "results") if "ro-crate" in str(p)]
    # a wrong digest, then a missing file
    table = crate / "results/figures/fig1.parquet"
    table.unlink()
    table.write_bytes(b"PAR1 not the table PAR1")
    assert verify_crate(crate) == ["results/figures/fig1.parquet: its SHA-256 differs from the crate's record"]
    table.unlink()
    assert verify_crate(crate) == ["results/figures/fig1.parquet: missing"]
    assert validate_crate(crate) != []  # the validator too: a data entity that is not there


# --- every case a section lists is drawn and tabulated, and cases stay apart -------------------

PLOTTED = list(CASE_FIGURES)  # the figures drawn from the cases of their section


def _cases_in(table):
    """The simulated cases a table holds (rows of analytic references left out)."""
    sims = table[table["method"].isin(["pt", "mtpt", "fd"])]
    return {Case.from_row(r) for _, r in sims[list(CASE_COLUMNS)].drop_duplicates().iterrows()}


@pytest.mark.parametrize("fig", PLOTTED)
def test_each_figure_writes_the_data_of_exactly_its_cases(tiny_run, fig):
    data = pd.read_parquet(tiny_run / f"results/figures/{fig}.parquet")
    assert {"series", *CASE_COLUMNS, "x", "y"} <= set(data.columns)
    assert {c.path() for c in _cases_in(data)} == _expected_folders(fig)  # EXPECTED_TABLES, by hand


def test_an_added_case_is_drawn_from_its_summary(tiny_run, tiny_config):
    cfg = tiny_config
    spec = {"method": "mtpt", "kernel": "collision", "eta": 0.25, "truncation": 3}
    assert spec in cfg["figures"]["fig5"]["cases"]  # the tiny config's added case
    added = Case.from_spec(spec, 100, cfg["case_defaults"])
    summary = pd.read_parquet(tiny_run / Ensemble(added, 2).summary_path())
    rows = rows_of(pd.read_parquet(tiny_run / "results/figures/fig5.parquet"), added)
    assert len(rows) > 10 and rows["series"].nunique() == 1
    plotted = summary.set_index("time").loc[rows["x"].to_numpy(), "E_mean"].to_numpy()
    np.testing.assert_array_equal(rows["y"].to_numpy(), plotted)  # the figure shows the summary's values


def test_cases_differing_in_one_dimension_stay_apart_in_every_table(tiny_run, tiny_config):
    cfg = tiny_config
    base = Case.from_spec({"method": "mtpt", "kernel": "collision", "eta": 1}, None, cfg["case_defaults"])
    truncated = replace(base, truncation=3.0)
    sequential = replace(truncated, scheme="sequential")
    models = (base, truncated, sequential)
    tables = {
        name: pd.read_parquet(tiny_run / f"results/tables/{name}.parquet")
        for name in ("comic", "comic_minima", "tradeoff")
    }
    tables["fig9"] = pd.read_parquet(tiny_run / "results/figures/fig9.parquet")
    for name, table in tables.items():
        parts = [rows_of(table, m) for m in models]
        assert all(len(p) for p in parts), name
        assert sum(map(len, parts)) == len(pd.concat(parts).drop_duplicates()), name  # no row in two models
        assert len({p["label" if "label" in p else "series"].iloc[0] for p in parts}) == 3, name
    comic = tables["comic"]
    at = lambda m: rows_of(comic, m).sort_values(["time", "n"])["COMIC_mean"].to_numpy()
    assert not np.array_equal(at(truncated), at(sequential))  # the scheme changes the numbers
    claims = pd.read_parquet(tiny_run / "results/tables/paper_claims.parquet")
    for m in models:  # each model gets its own Fig. 9 claims
        assert claims["claim"].str.startswith(case_label(m) + ": COMIC minimum").sum() == 2, case_label(m)


def test_mechanism_target_shares_runs_and_draws_the_controlled_experiments(tiny_run, tiny_config):
    cfg = tiny_config
    proc = run_snakemake(tiny_run, "figures/fig9_mechanism.png", dry_run=True, configfile=TINY)
    planned = [e for e in re.findall(r"wildcards: (.*)", proc.stdout) if "scheme=" in e]
    # the equations and the sequential loop are Fig. 9's cases: already run, never planned again
    assert planned and not any("trunc=none" in e and "scheme=symmetric" in e for e in planned)
    assert not any("scheme=sequential," in e or e.endswith("scheme=sequential") for e in planned)
    run_snakemake(tiny_run, "figures/fig9_mechanism.png", configfile=TINY)
    assert (tiny_run / "figures/fig9_mechanism.png").stat().st_size > 5000
    data = pd.read_parquet(tiny_run / "results/figures/fig9_mechanism.parquet")
    assert set(data["panel"]) == set("abcd")
    # (c): each variant minus the equations at the same seeds, from the per-seed table
    real = pd.read_parquet(tiny_run / "results/tables/mechanism/comic_realisations.parquet")
    real = real[real["time"] == real["time"].max()]
    base = Case.from_spec({"method": "mtpt", "kernel": "collision", "eta": 1}, None, cfg["case_defaults"])
    cut = replace(base, truncation=3.0)
    diff = rows_of(real, cut).set_index(["n", "seed"])["COMIC"] - rows_of(real, base).set_index(["n", "seed"])["COMIC"]
    drawn = rows_of(data[data["panel"] == "c"], cut).sort_values("x")
    np.testing.assert_allclose(drawn["y"].to_numpy(), diff.groupby(level="n").mean().to_numpy())
    fd = data[data["panel"] == "d"]
    assert fd["series"].str.contains("domain length 24").any() and fd["series"].str.contains("domain length 12").any()


def test_sequential_scheme_runs_the_authors_loop(tiny_run):
    runs = list(
        (tiny_run / "results/runs/mtpt/collision").glob(
            "n~100/eta~1/trunc~3/growth~*/scheme~sequential/grid~*/*.parquet"
        )
    )
    assert runs
    table = pd.read_parquet(runs[0])
    assert set(table["scheme"]) == {"sequential"} and set(table["truncation"]) == {3.0}


# --- code edits rerun exactly what they change -------------------------------------------------


def _planned_rules(proc):
    return set(re.findall(r"^\s*(?:local)?rule (\w+):", proc.stdout + proc.stderr, flags=re.M)) - {"all"}


@pytest.fixture
def tiny_run_copy(tiny_run, tmp_path):
    """A copy of the finished tiny run (its report left out), for dry runs of an edited workflow_copy."""
    work = tmp_path / "work"
    shutil.copytree(tiny_run, work, ignore=shutil.ignore_patterns("report.html"))
    return work


def test_code_edits_rerun_only_the_rules_that_use_that_code(workflow_copy, tiny_run_copy):
    src, work = workflow_copy, tiny_run_copy  # the library of src is edited

    def plan():
        proc = run_snakemake(work, snakefile=src / "Snakefile", dry_run=True, configfile=TINY)
        return _planned_rules(proc), proc

    assert plan()[0] == set()  # the same code in another place: nothing to do
    lib = src / "workflow/lib/particle_entropy"
    for module, expected in [
        ("figures/style.py", lambda r: r.startswith("plot_")),
        # legend text: the tables with a label column and the figures, never a simulation
        ("core/labels.py", lambda r: not r.startswith("simulate") and r not in ("fd_domain", "mechanism_floors")),
        ("core/columns.py", lambda r: not r.startswith("simulate")),  # column meanings: figures, never a simulation
        ("numerics/mass_transfer.py", None),
    ]:
        original = (lib / module).read_text()
        (lib / module).write_text(original + "\n# an edit\n")
        rules, proc = plan()
        if expected is not None:
            assert rules and all(expected(r) for r in rules), rules
        else:  # mass transfer: MTPT simulations and what reads them, never a PT or FD run
            sims = planned_outputs(proc)
            assert sims and all(p.startswith("results/runs/mtpt/") for p in sims)
            assert planned_outputs(proc, "results/snapshots/") == sorted(
                str(p.relative_to(work)) for p in (work / "results/snapshots/mtpt").rglob("*.parquet")
            )
            assert "simulate_shear" not in rules and "plot_fig10" not in rules
        (lib / module).write_text(original)  # identical content again (a newer mtime): nothing to do
        assert plan()[0] == set(), module


def test_a_config_without_shear_or_tradeoff_plans_without_them(tmp_path, tiny_config):
    cfg = tiny_config
    del cfg["shear"], cfg["tradeoff"]
    path = tmp_path / "lean.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=True))
    proc = run_snakemake(tmp_path, dry_run=True, configfile=path)
    assert "figures/fig9.png" in proc.stdout and "fig10" not in proc.stdout and "tradeoff" not in proc.stdout


# --- corrupt tables are found before use and rebuilt ------------------------------------------


def test_a_truncated_run_table_is_set_aside_and_rebuilt(tiny_run, tiny_config):
    cfg = parse(tiny_config)
    run = tiny_run / case_run_paths(figure_ensembles(cfg, "fig9")[0], cfg)[0]  # a table Fig. 9 reads
    good = run.read_bytes()
    before = pd.read_parquet(run).drop(columns=list(TIMING_COLUMNS))
    summaries = sorted((tiny_run / "results/tables/cases").rglob("*.parquet"))
    run.write_bytes(good[:100])  # truncate -s 100
    proc = run_snakemake(tiny_run, configfile=TINY)
    assert f"corrupt table results/{run.relative_to(tiny_run / 'results')}" in proc.stderr
    pd.testing.assert_frame_equal(pd.read_parquet(run).drop(columns=list(TIMING_COLUMNS)), before)  # rebuilt
    assert (run.parent / (run.name + ".corrupt")).exists()
    assert all(s.exists() for s in summaries)  # no good table was lost on the way
    again = run_snakemake(tiny_run, dry_run=True, configfile=TINY)
    assert "Nothing to be done" in again.stdout + again.stderr


def test_a_dry_run_only_looks_at_a_truncated_table(tiny_run, tiny_config):
    cfg = parse(tiny_config)
    run = tiny_run / case_run_paths(figure_ensembles(cfg, "fig9")[-1], cfg)[-1]
    good = run.read_bytes()
    run.write_bytes(good[:100])
    files = {p: p.stat().st_mtime_ns for p in (tiny_run / "results").rglob("*") if p.is_file()}
    run_snakemake(tiny_run, dry_run=True, configfile=TINY)
    assert run.read_bytes() == good[:100]  # not moved, not repaired
    assert not (run.parent / (run.name + ".corrupt")).exists()
    assert {p: p.stat().st_mtime_ns for p in (tiny_run / "results").rglob("*") if p.is_file()} == files
    proc = run_snakemake(tiny_run, configfile=TINY)  # the run checks, sets aside and rebuilds
    assert f"corrupt table results/{run.relative_to(tiny_run / 'results')}" in proc.stderr
    assert pd.read_parquet(run).shape[0] > 0


def test_set_aside_derived_tables_are_rebuilt_by_the_next_run(tiny_run):
    # Snakemake reruns no job for a missing output when the output a target asked for exists: a
    # figure's source data beside its PNG, a section's bootstrap table beside its COMIC table
    derived = [
        tiny_run / "results/figures/fig4.parquet",
        tiny_run / "results/tables/comic_realisations.parquet",
        tiny_run / "results/tables/fig9/comic_argmin.parquet",
    ]
    before = {p: p.read_bytes() for p in derived}
    for p in derived:
        p.write_bytes(before[p][:100])
    proc = run_snakemake(tiny_run, configfile=TINY)
    for p in derived:
        assert f"corrupt table {p.relative_to(tiny_run)}" in proc.stderr
        assert p.read_bytes() == before[p], p  # rebuilt, byte for byte
    again = run_snakemake(tiny_run, dry_run=True, configfile=TINY)
    assert "Nothing to be done" in again.stdout + again.stderr


def test_a_run_refused_by_a_lock_changes_no_table_and_unlock_always_works(tiny_run, tiny_config):
    cfg = parse(tiny_config)
    run = tiny_run / case_run_paths(figure_ensembles(cfg, "fig9")[0], cfg)[0]
    good = run.read_bytes()
    run.write_bytes(good[:100])
    other = tiny_run / case_run_paths(figure_ensembles(cfg, "fig3")[0], cfg)[0]
    record = other.with_name(other.name + ".sha256")
    record.unlink()
    record.mkdir()  # a checksum file that is a folder: treated as missing, never a crash
    locks = tiny_run / ".snakemake" / "locks"  # another run holds the lock (Snakemake's file format)
    locks.mkdir(parents=True, exist_ok=True)
    outputs = [p.relative_to(tiny_run).as_posix() for p in (tiny_run / "results").rglob("*.parquet")]
    (locks / "0.output.lock").write_text("\n".join(outputs) + "\n")
    files = {p: p.stat().st_mtime_ns for p in (tiny_run / "results").rglob("*") if p.is_file()}
    run_snakemake(tiny_run, configfile=TINY, check=False)
    assert run.read_bytes() == good[:100]  # not set aside: no file under results/ added, moved or changed
    assert {p: p.stat().st_mtime_ns for p in (tiny_run / "results").rglob("*") if p.is_file()} == files
    unlock = run_snakemake(tiny_run, "--unlock", configfile=TINY, check=False)
    assert unlock.returncode == 0, unlock.stderr[-2000:]
    assert not (locks.exists() and any(locks.iterdir())) and run.read_bytes() == good[:100]  # only looked
    proc = run_snakemake(tiny_run, configfile=TINY)  # the lock gone: checked, set aside, rebuilt
    assert f"corrupt table {run.relative_to(tiny_run)}" in proc.stderr and pd.read_parquet(run).shape[0] > 0
    assert f"corrupt table {other.relative_to(tiny_run)}" not in proc.stderr  # read whole: sound
    record.rmdir()  # the module's run as it was, for the tests after this one
    record.write_text(f"{hashlib.sha256(other.read_bytes()).hexdigest()}  {other.name}\n")


def test_another_cases_run_table_in_its_place_is_set_aside_and_rebuilt(tiny_run, tiny_config):
    cfg = parse(tiny_config)
    ensembles = figure_ensembles(cfg, "fig9")
    here, there = (tiny_run / case_run_paths(e, cfg)[0] for e in (ensembles[0], ensembles[1]))
    assert pd.read_parquet(here)["n"].iloc[0] != pd.read_parquet(there)["n"].iloc[0] or here.parent != there.parent
    before = pd.read_parquet(here).drop(columns=list(TIMING_COLUMNS))
    for suffix in ("", ".sha256"):  # a valid table and its matching checksum: whole, but the wrong case
        Path(str(here) + suffix).write_bytes(Path(str(there) + suffix).read_bytes())
    (here.parent / (here.name + ".sha256")).write_text((there.parent / (there.name + ".sha256")).read_text())
    proc = run_snakemake(tiny_run, configfile=TINY)
    assert f"corrupt table {here.relative_to(tiny_run)}" in proc.stderr and "another case's table" in proc.stderr
    pd.testing.assert_frame_equal(pd.read_parquet(here).drop(columns=list(TIMING_COLUMNS)), before)


# --- two runs, a failing job, a full disk ---------------------------------------------------


def test_a_second_run_in_the_same_directory_is_refused_and_the_first_completes(tiny_run, tmp_path):
    import time

    target = "results/figures/fig8.parquet"  # FD only: a short run, long enough to be running still
    cmd = snakemake_command(tmp_path, target, configfile=TINY)
    first = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    locks = tmp_path / ".snakemake" / "locks"
    deadline = time.time() + 120
    while time.time() < deadline and not (locks.exists() and any(locks.iterdir())):
        time.sleep(0.1)
    second = run_snakemake(tmp_path, target, configfile=TINY, check=False)
    out, _ = first.communicate(timeout=600)
    assert second.returncode != 0 and "cannot be locked" in second.stdout + second.stderr
    assert first.returncode == 0, out[-3000:]
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / target), pd.read_parquet(tiny_run / target))


def test_two_clones_whose_results_link_to_one_folder_do_not_both_run(tmp_path):
    """Snakemake's lock is per working directory: clone b ran beside clone a in the results both
    link to. Now b stops before any job, naming the run that holds results/ (runlock.py)."""
    import os
    import sys

    shared = tmp_path / "shared"
    for clone in ("a", "b"):
        (tmp_path / clone).mkdir()
        (tmp_path / clone / "results").symlink_to(shared, target_is_directory=True)
    holder = (
        "import sys; from particle_entropy.pipeline.runlock import hold; hold('results'); print('held', flush=True)"
    )
    holder += "; sys.stdin.read()"  # until the test closes the pipe
    first = subprocess.Popen(
        [sys.executable, "-c", holder], cwd=tmp_path / "a", stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert first.stdout.readline().strip() == "held"
        second = run_snakemake(tmp_path / "b", "figures/fig8.png", configfile=TINY, check=False)
    finally:
        first.stdin.close()
        first.wait(timeout=30)
    assert second.returncode != 0 and "Traceback" not in second.stderr
    assert f"results/ ({shared}) is in use by another run (pid {first.pid} on " in second.stderr
    assert sorted(os.listdir(shared)) == [".run.lock"]  # no job ran, no kernels built
    again = run_snakemake(tmp_path / "b", "--unlock", configfile=TINY, check=False)  # looks only: no lock taken
    assert again.returncode == 0, again.stderr[-2000:]


def test_a_read_only_home_is_no_obstacle(tmp_path):
    """Snakemake made ~/.cache/snakemake/source-cache before reading the Snakefile, so a HOME that
    cannot be written (here a file, which stops root too) ended every command in its traceback. The
    default profile keeps that cache in Snakemake's own temporary folder (shared-fs-usage)."""
    import os

    home = tmp_path / "home"
    home.write_text("not a folder")
    env = {k: v for k, v in os.environ.items() if k not in ("XDG_CACHE_HOME", "XDG_CONFIG_HOME")} | {"HOME": str(home)}
    proc = run_snakemake(tmp_path, "figures/fig8.png", dry_run=True, configfile=TINY, env=env, check=False)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert "simulate" in proc.stdout  # the plan was made


def test_a_failed_job_on_a_full_disk_is_named_on_the_terminal(tmp_path):
    import os
    import resource

    def small_files():  # a 100 kB file-size limit: writing the figure fails, as on a full disk
        resource.setrlimit(resource.RLIMIT_FSIZE, (100 * 1024, 100 * 1024))

    env = {**os.environ, "PARTICLE_ENTROPY_MIN_FREE_MB": "1e12"}  # and every disk looks nearly full
    target = "figures/fig8.png"
    run_snakemake(tmp_path, target, configfile=TINY)  # kernels compiled: numba's cache needs no room now
    (tmp_path / target).unlink()  # the figure alone is made again, under the limit
    full = run_snakemake(tmp_path, target, configfile=TINY, env=env, preexec_fn=small_files, check=False)
    assert full.returncode != 0 and "Error in rule plot_fig8" in full.stdout + full.stderr
    assert "No space left on device? The file system holding" in full.stderr
    assert "rerun the same command" in full.stderr
    run_snakemake(tmp_path, target, configfile=TINY, env=env)  # room again: it completes
    assert (tmp_path / "figures" / "fig8.png").stat().st_size > 100 * 1024


def test_a_config_without_figures_judges_no_claim(tmp_path, tiny_config):
    cfg = tiny_config
    cfg["figures"] = {}
    for key in ("shear", "tradeoff", "mechanism"):
        del cfg[key]
    path = tmp_path / "none.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=True))
    run_snakemake(tmp_path, configfile=path)
    assert "No claim judged" in (tmp_path / "results/paper_claims.md").read_text()
    assert list(pd.read_parquet(tmp_path / "results/tables/paper_claims.parquet").columns) == [
        "claim",
        "paper",
        "reproduced",
        "tolerance",
        "passed",
        "as_drawn",
        "passed_as_drawn",
        "test",
        "passed_test",
    ]


def test_a_short_message_for_a_misspelt_key(tmp_path):
    text = (ROOT / "config.yaml").read_text().replace("physics:", "physic:", 1)
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    proc = run_snakemake(tmp_path, dry_run=True, configfile=bad, check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "did you mean physics?" in out
    assert len(out.splitlines()) < 12  # not the whole schema and config around the one useful line


def test_a_yaml_error_in_config_yaml_names_its_line(tmp_path):
    (tmp_path / "config.yaml").write_text((ROOT / "config.yaml").read_text() + "\nshear: {n: 10\n")
    proc = run_snakemake(tmp_path, dry_run=True, check=False)
    assert proc.returncode != 0 and "config.yaml: not valid YAML at line" in proc.stdout + proc.stderr


# a yte template whose condition runs a command when Snakemake renders it
TEMPLATE = '__use_yte__: true\n?if __import__("pathlib").Path("{mark}").touch() is None:\n  extra: 1\n'


def test_a_template_in_config_yaml_is_refused_before_it_runs(tmp_path):
    mark = tmp_path / "ran"
    (tmp_path / "config.yaml").write_text((ROOT / "config.yaml").read_text() + "\n" + TEMPLATE.format(mark=mark))
    proc = run_snakemake(tmp_path, dry_run=True, check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "config.yaml: line" in out and "__use_yte__ makes Snakemake run" in out
    assert not mark.exists()  # checked before Snakemake loads it: the code never ran


def test_a_template_configfile_is_refused_though_snakemake_ran_it(tmp_path):
    mark, template = tmp_path / "ran", tmp_path / "template.yaml"
    template.write_text(TEMPLATE.format(mark=mark))
    proc = run_snakemake(tmp_path, dry_run=True, configfile=template, check=False)
    assert proc.returncode != 0 and "template.yaml: line 1: __use_yte__" in proc.stdout + proc.stderr
    # Snakemake loads a --configfile before the Snakefile: the README says it is trusted as code
    assert mark.exists()
    assert "trust a `--configfile`" in (ROOT / "README.md").read_text()


def test_nested_command_line_overrides_of_numbers_and_lists_work(tmp_path):
    ok = run_snakemake(tmp_path, "--config", "physics={D: 0.002}", "comic_times=[5, 20]", dry_run=True, configfile=TINY)
    assert "physics.D" not in ok.stdout + ok.stderr
    bad = run_snakemake(tmp_path, "--config", "physics={D: -1}", dry_run=True, configfile=TINY, check=False)
    assert bad.returncode != 0 and "physics.D=-1 is not allowed" in bad.stdout + bad.stderr


CASE_PATH = "mtpt/collision/n~100/eta~1/trunc~none/growth~1.05/scheme~symmetric/grid~exact"


@pytest.mark.parametrize(
    "target,expected",
    [
        (f"results/runs/{CASE_PATH}/seeds~5-2.parquet", "seeds~5-2: first <= last"),
        (f"results/runs/{CASE_PATH}/seeds~0-99999999999.parquet", "at most 10,000 seeds"),
        (f"results/tables/cases/{CASE_PATH}/r~0.parquet", "r~0: an ensemble of at least 1"),
        (f"results/runs/{CASE_PATH.replace('eta~1/', 'eta~1e/')}/seeds~0-1.parquet", "expected results/{kind}/"),
        (f"results/runs/{CASE_PATH.replace('n~100', 'n~1')}/seeds~0-1.parquet", "n=1 is not allowed"),
        ("figures/optimum_nosuch.png", "no optimum search 'nosuch' in config optimum: one of"),
    ],
    ids=["seeds reversed", "seeds huge", "r 0", "eta 1e", "n 1", "unknown search"],
)
def test_a_hand_written_target_that_names_no_valid_run_is_refused_by_its_pattern(tmp_path, target, expected):
    proc = run_snakemake(tmp_path, target, dry_run=True, configfile=ROOT / "config.yaml", check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "WorkflowError" in out and expected in out, out[-1500:]
    assert not (tmp_path / "results").exists()


# --- docs/columns.md: every column of every derived table is documented ----------------------

COLUMN_DOCS_PAGE = ROOT / "docs" / "columns.md"


def _path_regex(pattern):
    """A table path of docs/columns.md as a regex: `<case>` is a case folder (several segments),
    any other `<...>` one segment."""
    parts = re.split(r"(<[^>]+>)", pattern)
    body = "".join(".+" if p == "<case>" else "[^/]+" if p.startswith("<") else re.escape(p) for p in parts)
    return re.compile(body)


def _column_doc_sections():
    """(heading, [(path pattern, regex)], documented columns) for every `## ` section of
    docs/columns.md whose heading names `results/...` tables. Documented columns are the
    backticked names in the first cell of the rows of a table headed `| column |`."""
    sections = []
    for block in re.split(r"^(?=## )", COLUMN_DOCS_PAGE.read_text(), flags=re.M):
        if not block.startswith("## "):
            continue
        heading = block.splitlines()[0]
        paths = [p for p in re.findall(r"`([^`]+)`", heading) if p.startswith("results/")]
        if not paths:
            continue
        columns, in_table = set(), False
        for line in block.splitlines()[1:]:
            if not line.lstrip().startswith("|"):
                in_table = False
                continue
            first = line.strip().strip("|").split("|")[0].strip()
            if first == "column":
                in_table = True
            elif in_table and set(first) - set("-: "):
                columns |= set(re.findall(r"`([^`]+)`", first))
        sections.append((heading, [(p, _path_regex(p)) for p in paths], columns))
    return sections


def _section_of(rel, sections):
    """The section of a table: the one whose path matches it with the fewest placeholders."""
    hits = [(p.count("<"), s) for s in sections for p, rx in s[1] if rx.fullmatch(rel)]
    assert hits, f"{rel}: no section of docs/columns.md names this table"
    fewest = min(h[0] for h in hits)
    best = {s[0]: s for k, s in hits if k == fewest}
    assert len(best) == 1, f"{rel}: claimed by several sections: {sorted(best)}"
    return next(iter(best.values()))


def test_every_derived_table_column_is_documented(tiny_run):
    import pyarrow.parquet as pq

    if not (tiny_run / "results/figures/fig9_mechanism.parquet").exists():  # the mechanism tables too
        run_snakemake(tiny_run, "figures/fig9_mechanism.png", configfile=TINY)
    if not (tiny_run / "results/optimum").exists():  # and the optimum searches' plans and results
        run_snakemake(tiny_run, "optimum", configfile=TINY)
    sections = _column_doc_sections()
    tables = sorted((tiny_run / "results").rglob("*.parquet"))
    found = {}  # section heading -> {table: its columns}
    for path in tables:
        rel = path.relative_to(tiny_run).as_posix()
        heading, _, documented = _section_of(rel, sections)
        columns = [c for c in pq.read_schema(path).names if not c.startswith("__index_level_")]
        missing = [c for c in columns if c not in documented]
        assert not missing, f"{rel}: columns not documented under '{heading}': {missing}"
        found.setdefault(heading, {})[rel] = set(columns)
    for kind in ("results/tables/cases/", "results/runs/", "results/snapshots/", "results/shear/"):
        assert any(rel.startswith(kind) for cols in found.values() for rel in cols), kind
    for name in ("mechanism/floors", "mechanism/fd_domain", "mechanism/comic_minima", "fig9/comic"):
        assert (tiny_run / f"results/tables/{name}.parquet").exists(), name
    # no section without a table, and no documented column that no table of its section has
    for heading, _, documented in sections:
        if heading == SCENE_SECTION:  # the tiny run builds no scene: test_a_scene_is_searched_... checks it
            continue
        assert heading in found, f"'{heading}': no table of the tiny run matches it"
        # no 2-D run and no release here: test_plane_runs and test_release_models hold their tables to them
        stale = documented - set().union(*found[heading].values()) - set(PLANE_ONLY_COLUMNS) - set(RELEASE_ONLY_COLUMNS)
        assert not stale, f"'{heading}' documents columns no such table has: {sorted(stale)}"
    # the main tables, file by file: what the page says they hold, each of them holds
    for name in ("comic", "comic_minima"):
        rel = f"results/tables/{name}.parquet"
        documented = _section_of(rel, sections)[2]
        for copy in (rel, f"results/tables/fig9/{name}.parquet", f"results/tables/mechanism/{name}.parquet"):
            absent = documented - found[_section_of(copy, sections)[0]][copy]
            assert not absent, f"{copy}: documented but absent: {sorted(absent)}"


def test_optimum_search_runs_round_by_round_on_the_tiny_config(tiny_run, tiny_config):
    from particle_entropy.analysis.optimum import REASONS, RESULT_COLUMNS, Search

    cfg = tiny_config
    run_snakemake(tiny_run, "optimum", configfile=TINY)
    for name, spec in cfg["optimum"].items():
        search = Search.from_config(name, spec, cfg)
        for ext in ("png", "pdf"):
            assert (tiny_run / f"figures/optimum_{name}.{ext}").stat().st_size > 5000
        table = pd.read_parquet(tiny_run / f"results/optimum/{name}.parquet")
        assert list(table.columns) == RESULT_COLUMNS
        row = table.iloc[0]
        assert row["runs_spent"] <= spec["budget_runs"] and row["reason"] in REASONS, row
        assert search.lo <= row["optimum"] <= search.hi and row["over"] == search.over
        assert row["bracket_lo"] <= row["ci_lo"] <= row["ci_hi"] <= row["bracket_hi"]
        assert row["bracket_lo"] <= row["optimum"] <= row["bracket_hi"]
        assert row["rounds"] >= 2, "the tiny searches refine at least once"  # the checkpoint chain ran
        for k in range(int(row["rounds"])):
            assert (tiny_run / f"results/optimum/{name}/round~{k}.parquet").exists(), k
        plan = pd.read_parquet(tiny_run / f"results/optimum/{name}/round~{int(row['rounds'])}.parquet")
        assert plan["done"].all() and sorted(set(plan[search.over])) == sorted(table[search.over])
        assert int(table["realisations"].sum()) == int(row["runs_spent"])
        for r in plan.itertuples():  # every block is an ordinary simulation table
            assert (tiny_run / run_path(search.case_at(getattr(r, search.over)), r.first, r.last)).exists(), r
    proc = run_snakemake(tiny_run, "optimum", dry_run=True, configfile=TINY)
    assert "Nothing to be done" in proc.stdout + proc.stderr


def test_a_figure_edit_redraws_only_that_figure(workflow_copy, tiny_run_copy):
    from particle_entropy.figures import CASE_FIGURES

    src, work = workflow_copy, tiny_run_copy  # copies: the library edited, the finished run
    plan = lambda: run_snakemake(work, snakefile=src / "Snakefile", dry_run=True, configfile=TINY)
    assert _planned_rules(plan()) == set()  # the same code in another place: nothing to do
    figures = src / "workflow/lib/particle_entropy/figures"
    every_figure = {f"plot_{fig}" for fig in CASE_FIGURES}
    for module, expected in [
        ("fig7.py", lambda rules: rules == {"plot_fig7"}),
        ("dilution.py", lambda rules: rules == {"plot_fig2", "plot_fig4", "plot_fig5"}),
        ("style.py", lambda rules: every_figure <= rules and all(r.startswith("plot_") for r in rules)),
    ]:
        original = (figures / module).read_text()
        (figures / module).write_text(original + "# an edit\n")
        proc = plan()
        assert expected(_planned_rules(proc)), (module, sorted(_planned_rules(proc)))
        assert planned_outputs(proc) == [], module  # no simulation
        (figures / module).write_text(original)
    # a rules file: the summaries hash summarise.smk, which holds their rule alone, so an edit to
    # the other aggregation rules reruns none of them
    rules = src / "workflow/rules"
    for name, expected in [
        ("aggregate.smk", lambda planned: planned == set()),
        (
            "summarise.smk",
            lambda planned: "summarise_case" in planned and not any(r.startswith("simulate") for r in planned),
        ),
    ]:
        original = (rules / name).read_text()
        (rules / name).write_text(original + "# an edit\n")
        proc = plan()
        assert expected(_planned_rules(proc)), (name, sorted(_planned_rules(proc)))
        (rules / name).write_text(original)


# --- what parsing imports -----------------------------------------------------------------------

# Runs Snakemake with every `import pandas` / `import scipy` statement recorded by the file that
# runs it (sys.modules alone cannot tell: Snakemake's SLURM executor plugin imports pandas itself).
RECORD_IMPORTS = """
import atexit, builtins, json, runpy, sys
root, out = sys.argv.pop(1), sys.argv.pop(1)
found, real = set(), builtins.__import__

def record(name, globals=None, locals=None, fromlist=(), level=0):
    where = sys._getframe(1).f_code.co_filename.removeprefix(root)
    if level == 0 and name.partition(".")[0] in ("pandas", "scipy") and where.startswith(("Snakefile", "workflow/")):
        found.add(where)
    return real(name, globals, locals, fromlist, level)

builtins.__import__ = record
atexit.register(lambda: open(out, "w").write(json.dumps({"by": sorted(found), "scipy": "scipy" in sys.modules})))
sys.argv[0] = "snakemake"
runpy.run_module("snakemake", run_name="__main__")
"""


def test_parsing_the_workflow_imports_neither_scipy_nor_pandas(tmp_path):
    import json

    out = tmp_path / "imports.json"
    launcher = ("-c", RECORD_IMPORTS, f"{ROOT}/", str(out))
    run_snakemake(tmp_path / "work", dry_run=True, configfile=TINY, launcher=launcher)  # AssertionError if it fails
    seen = json.loads(out.read_text())
    assert not seen["scipy"]
    assert not [f for f in seen["by"] if not f.startswith("workflow/lib/")]  # Snakefile, rules, scripts: none
    # nor the library: config sections are checked without tables (Snakemake's SLURM plugin
    # imports pandas itself, which the floor in docs/speed.md measures)
    assert not seen["by"], seen["by"]


def test_a_run_keeps_every_table_digest_and_still_finds_a_truncated_table(tiny_run, tiny_config):
    import json

    digests = tiny_run / ".snakemake" / "particle_entropy" / "table_digests.json"
    for _ in range(2):  # nothing to do; the parse checks every table (the second reads none settled before)
        proc = run_snakemake(tiny_run, configfile=TINY)
        assert "Nothing to be done" in proc.stdout + proc.stderr
    tables = {p.relative_to(tiny_run / "results").as_posix() for p in (tiny_run / "results").rglob("*.parquet")}
    assert set(json.loads(digests.read_text())["tables"]) == tables
    kept = digests.stat().st_mtime_ns
    run_snakemake(tiny_run, configfile=TINY)
    assert digests.stat().st_mtime_ns == kept  # nothing changed, nothing rewritten
    cfg = parse(tiny_config)
    run = tiny_run / case_run_paths(figure_ensembles(cfg, "fig3")[0], cfg)[0]
    run.write_bytes(run.read_bytes()[:100])  # in place: the same inode
    proc = run_snakemake(tiny_run, configfile=TINY)
    assert f"corrupt table results/{run.relative_to(tiny_run / 'results')}" in proc.stderr
    assert pd.read_parquet(run).shape[0] > 0 and (run.parent / (run.name + ".corrupt")).exists()


SCENE_CONFIG = ROOT / "tests" / "data" / "scene_config.yaml"
SCENE_SECTION = "## Scene results: `results/scenes/<name>.parquet`"  # its heading in docs/columns.md


def _scene_overlay(tmp_path, name: str, **changes) -> Path:
    """tests/data/scene_config.yaml with the scene `carried` changed, written to tmp_path / name."""
    cfg = yaml.safe_load(SCENE_CONFIG.read_text())
    for key, value in changes.items():
        node = cfg["scenes"]["carried"]
        *path, last = key.split(".")
        for part in path:
            node = node[part]
        node[last] = value
    out = tmp_path / name
    out.write_text(yaml.safe_dump(cfg))
    return out


def test_a_scene_is_searched_recommended_and_drawn(tmp_path):
    from particle_entropy.analysis.scene_search import plan_paths
    from particle_entropy.scenes.scene import Scene

    work = tmp_path / "scenes"
    # from an empty kernel cache: the first job compiles the kernels, and a run exiting 0 has made
    # every target (issue 39: a compile job with an ancient output once hid the jobs after it)
    empty_cache = {**os.environ, CACHE_ENV: str(tmp_path / "kernel-cache")}
    run_snakemake(work, "scenes", "--configfile", TINY, SCENE_CONFIG, env=empty_cache)
    assert (tmp_path / "kernel-cache").is_dir()  # the kernels were built in this run, not copied
    table = pd.read_parquet(work / "results/scenes/carried.parquet")
    heading, _, documented = _section_of("results/scenes/carried.parquet", _column_doc_sections())
    assert heading == SCENE_SECTION and set(table.columns) == documented  # docs/columns.md says what it holds
    assert table["recommended"].sum() == 1 and table["comic_best"].sum() == 1
    best = table[table["recommended"]].iloc[0]
    assert best["meets"] and best["unscored"] == "" and best["error_upper95"] <= 0.02
    coarse = table[(table["label"].str.contains("central")) & (table["n"] == 16)].iloc[0]
    assert (
        coarse["unscored"].startswith("negative concentrations from step ")
        and "grid Peclet 2.68 > 2" in coarse["unscored"]
    )
    assert not coarse["meets"] and np.isnan(coarse["COMIC_points"])
    stops = ("met: every rung below it fails", "met at n_range's low end", "not met within n_range")
    for label, rows in table.groupby("label"):  # each candidate met above failing rungs, or nowhere
        assert rows["stopped"].iloc[0] in stops, label
    ladder = (
        Scene.from_config("carried", yaml.safe_load(SCENE_CONFIG.read_text())["scenes"]["carried"])
        .candidates[int(best["candidate"])]
        .ladder()
    )
    mine = table[table["candidate"] == best["candidate"]]
    assert {n for n in ladder if n < best["n"]} <= set(mine["n"])  # every rung below the answer run
    assert not mine[mine["n"] < best["n"]]["meets"].any()
    assert (work / "figures/scene_carried.png").stat().st_size > 5000
    numbers = json.loads((work / "results/scenes_numbers.json").read_text())  # what the README quotes
    (quoted,) = numbers["scenes"]
    chosen = [c for c in quoted["candidates"] if c["recommended"]]
    assert quoted["scene"] == "carried" and chosen[0]["answer"]["n"] == best["n"] and not numbers["sweep"]
    rounds = (work / "results/scenes/carried").glob("round~*.parquet")
    plans = sorted((p for p in rounds if not p.name.endswith(READ_SUFFIX)), key=lambda p: int(p.stem.split("~")[1]))
    last = pd.read_parquet(plans[-1])
    assert last["done"].all() and len(plans) >= 3
    read = pd.read_parquet(read_path(str(plans[-1])))  # what the last round read: every run of the finished plan
    assert len(read) == int((last["last"] - last["first"] + 1).sum()) and len(read) > 0
    spec = yaml.safe_load(SCENE_CONFIG.read_text())["scenes"]["carried"]
    scene = Scene.from_config("carried", spec, yaml.safe_load(TINY.read_text()).get("case_defaults"))
    assert all((work / p).exists() for p in plan_paths(scene, last))  # every run an ordinary table
    # a new target reruns no simulation; a new velocity reruns the scene's runs
    target = _scene_overlay(tmp_path, "target.yaml", **{"target.value": 0.05})
    proc = run_snakemake(work, "scenes", "-n", "--configfile", TINY, target)
    planned = _planned_rules(proc) | set(re.findall(r"^\s*(?:local)?checkpoint (\w+):", proc.stdout, flags=re.M))
    assert "simulate_scene" not in planned and "scene_round" in planned
    before = {p.name for p in (work / "results/scenes").iterdir() if p.is_dir() and p.name != "carried"}
    faster = _scene_overlay(tmp_path, "v.yaml", v=0.02)
    proc = run_snakemake(work, "scenes", "--configfile", TINY, faster)
    after = {p.name for p in (work / "results/scenes").iterdir() if p.is_dir() and p.name != "carried"}
    # FD upwind and FD central: new identities; the particles' runs are computed at rest, shared across v
    assert len(after - before) == 2 and before <= after
    assert "simulate_scene" in _planned_rules(proc)


def test_a_bad_scene_value_is_refused_before_any_job_naming_its_key(tmp_path):
    bad = _scene_overlay(tmp_path, "bad.yaml", **{"source": {"kind": "gaussian", "x0": 0.0, "sd": -1.0}})
    proc = run_snakemake(tmp_path / "w", "scenes", "-n", "--configfile", TINY, bad, check=False)
    assert proc.returncode != 0
    assert "scenes.carried.source.sd" in proc.stdout + proc.stderr
    wide = _scene_overlay(tmp_path, "wide.yaml", omega=0.5, source={"kind": "box", "a": -1.0, "b": 1.0})
    proc = run_snakemake(tmp_path / "w2", "scenes", "-n", "--configfile", TINY, wide, check=False)
    assert proc.returncode != 0 and "scenes.carried.omega" in proc.stdout + proc.stderr
    assert not (tmp_path / "w2" / "results").exists()


def test_a_run_table_decayed_on_the_disk_fails_its_reader_then_is_set_aside_and_rebuilt(tiny_run, tiny_config):
    import json
    import os

    import pyarrow.parquet as pq

    cfg = parse(tiny_config)
    ensemble = figure_ensembles(cfg, "fig3")[0]
    run = tiny_run / case_run_paths(ensemble, cfg)[0]
    rel = run.relative_to(tiny_run).as_posix()
    before = pd.read_parquet(run).drop(columns=list(TIMING_COLUMNS))
    run_snakemake(tiny_run, configfile=TINY)  # the digest cache vouches for every settled table
    digests = tiny_run / ".snakemake" / "particle_entropy" / "table_digests.json"
    meta = pq.ParquetFile(run).metadata.row_group(0)
    column = max((meta.column(i) for i in range(meta.num_columns)), key=lambda c: c.total_compressed_size)
    pos = (column.dictionary_page_offset or column.data_page_offset) + column.total_compressed_size // 2
    st = run.stat()
    with open(run, "r+b") as f:  # one bit in a data page, in place; the mtime put back
        f.seek(pos)
        byte = f.read(1)[0]
        f.seek(pos)
        f.write(bytes([byte ^ 0x10]))
    os.utime(run, ns=(st.st_atime_ns, st.st_mtime_ns))
    entries = json.loads(digests.read_text())  # decay on the disk moves no stamp: the cache still vouches
    now = run.stat()
    entries["tables"][run.relative_to(tiny_run / "results").as_posix()][:4] = [
        now.st_size,
        now.st_mtime_ns,
        now.st_ino,
        now.st_ctime_ns,
    ]
    digests.write_text(json.dumps(entries))
    summary = tiny_run / ensemble.summary_path()
    for path in (summary, summary.with_name(summary.name + ".sha256")):
        path.unlink()  # its summary, asked for, is made again from the run table
    failed = run_snakemake(tiny_run, summary.relative_to(tiny_run), configfile=TINY, check=False)
    assert failed.returncode != 0 and f"corrupt table {rel}: " in failed.stdout + failed.stderr
    assert "Error in rule summarise_case" in failed.stdout + failed.stderr
    again = run_snakemake(tiny_run, configfile=TINY)  # set aside and rebuilt, then the summary
    assert f"corrupt table {rel}: its SHA-256" in again.stderr
    pd.testing.assert_frame_equal(pd.read_parquet(run).drop(columns=list(TIMING_COLUMNS)), before)
    assert summary.exists()


def test_user_scenes_named_peclet_are_their_own_and_the_sweep_draws_only_its_scenes(tmp_path):
    """Issue 39, point 6: scenes.peclet_0 was replaced by the sweep's scene, peclet_mine was drawn in
    figures/scenes_peclet.png and a scene named peclet never ran (its table was the sweep's)."""
    scene = yaml.safe_load(SCENE_CONFIG.read_text())["scenes"]["carried"]
    base = {k: v for k, v in scene.items() if k != "v"}
    overlay = tmp_path / "peclet_names.yaml"
    overlay.write_text(
        yaml.safe_dump(
            {
                "scenes": {"peclet": scene, "peclet_0": {**scene, "v": 0.02}, "peclet_mine": scene},
                "scenes_peclet": {"base": base, "v": [0.0, 0.01]},
            }
        )
    )
    work = tmp_path / "w"
    sweep = planned_outputs(
        run_snakemake(work, "figures/scenes_peclet.png", "--configfile", TINY, overlay, dry_run=True),
        "results/scenes/",
    )
    rounds = {p.split("/")[2] for p in sweep if "/round~" in p}
    assert rounds and not rounds & {"peclet", "peclet_0", "peclet_mine"}, rounds
    mine = planned_outputs(
        run_snakemake(work, "figures/scene_peclet.png", "--configfile", TINY, overlay, dry_run=True),
        "results/scenes/",
    )
    assert "results/scenes/peclet/round~0.parquet" in mine, mine


DECAY_SCENE = {
    "scenes": {
        "decay": {
            "D": 1.0e-3,
            "v": 0.01,
            "t_final": 20.0,
            "source": {"kind": "point", "x0": 0.0},
            "reaction": {"kind": "decay", "rate": 0.02},
            "target": {"measure": "rmse", "value": 0.05},
            "realisations": 2,
            "candidates": [  # one, two rungs: every file the point is about, in few jobs
                {"method": "fd", "kernel": "implicit", "advection": "upwind", "fd_dt": 0.5, "n_range": [16, 32]},
            ],
        }
    }
}


def test_a_bad_reference_and_a_corrupt_scene_table_are_rebuilt_by_the_same_scenes_run(tmp_path):
    """Issue 50 (10): another scene's valid reference copied over a decay scene's was used (rc 0,
    errors 0.331 where 2.4e-5 was true), and a corrupt scene table was set aside but not rebuilt by
    `snakemake scenes` (rc 0, the table missing). Both are now set aside and rebuilt in one run."""
    from particle_entropy.scenes import reference as reactive

    work, config = tmp_path / "work", tmp_path / "decay.yaml"
    config.write_text(yaml.safe_dump(DECAY_SCENE))
    run_snakemake(work, "scenes", "--configfile", TINY, config)
    table = work / "results/scenes/decay.parquet"
    (reference,) = (work / "results/scenes/references").glob("*.json")
    before, good = pd.read_parquet(table), reference.read_bytes()
    physics = json.loads(good)["physics"]
    other = tmp_path / "other.json"
    reactive.write({**physics, "reaction": {"kind": "decay", "rate": 0.05}}, str(other))
    shutil.copy(other, reference)  # another scene's valid reference in its place
    table.write_bytes(table.read_bytes()[:100])  # a scene table cut short
    proc = run_snakemake(work, "scenes", "--configfile", TINY, config)
    out = proc.stdout + proc.stderr
    assert f"corrupt reference {reference.relative_to(work)}: its digest" in out
    assert "corrupt table results/scenes/decay.parquet" in out
    assert {"scene_reference", "scene_table"} <= _planned_rules(proc)
    assert reference.read_bytes() == good and reactive.problem(reference) is None
    pd.testing.assert_frame_equal(pd.read_parquet(table), before)
