"""pipeline/crate.py on synthetic runs: which jobs a crate describes, at which commit they ran,
outputs changed since their job, a person's additions kept across rebuilds, and no write through
a link. The crate of a real run is checked in tests/test_workflow.py."""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import time

import pytest
from conftest import ROOT

from particle_entropy.pipeline.crate import (
    GENERATED,
    METADATA,
    CrateError,
    build_crate,
    crate_folder_problem,
    provenance,
    start_session,
    verify_crate,
)

CONFIG = {"physics": {"D": 0.001}}
TARGETS = ["figures/fig1.png"]


def _git(checkout, *args):
    subprocess.run(
        ["git", "-C", str(checkout), "-c", "user.name=t", "-c", "user.email=t@t", *args],
        check=True,
        capture_output=True,
    )


@pytest.fixture
def checkout(tmp_path):
    """A git checkout holding what the crate takes from one: Snakefile, a rule file and script,
    requirements.lock, CITATION.cff; one commit, clean."""
    root = tmp_path / "checkout"
    (root / "workflow/rules").mkdir(parents=True)
    (root / "workflow/scripts").mkdir()
    (root / "Snakefile").write_text("include: 'workflow/rules/plot.smk'\n")
    (root / "workflow/rules/plot.smk").write_text("rule plot_fig1:\n    script: '../scripts/plot.py'\n")
    (root / "workflow/scripts/plot.py").write_text("print('plot')\n")
    (root / "docs.md").write_text("docs\n")
    for name in ("requirements.lock", "CITATION.cff"):
        shutil.copy(ROOT / name, root / name)
    _git(root, "init", "-q")
    _git(root, "add", ".")
    _git(root, "commit", "-qm", "first")
    return root


def _head(checkout):
    head = subprocess.run(["git", "-C", str(checkout), "rev-parse", "HEAD"], capture_output=True, text=True)
    return head.stdout.strip()


def _job(work, rule, inputs, outputs, start, code="0123456789abcdef"):
    """Write ``outputs`` and Snakemake's record of the job that made them (.snakemake/metadata)."""
    for rel in outputs:
        (work / rel).parent.mkdir(parents=True, exist_ok=True)
        (work / rel).write_text(f"{rel} by {rule}\n")
    end = (work / outputs[0]).stat().st_mtime
    for rel in outputs:
        os.utime(work / rel, (end, end))  # Snakemake records each output's mtime as the job's end
        record = {
            "rule": rule,
            "input": inputs,
            "params": [f"'{code}'"],
            "code": '"../scripts/plot.py"',
            "starttime": start,
            "endtime": end,
            "job_hash": hash((rule, tuple(outputs))),
            "incomplete": False,
        }
        key = base64.urlsafe_b64encode(rel.encode()).decode()
        folder = work / ".snakemake/metadata"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / key).write_text(json.dumps(record))


@pytest.fixture
def run(tmp_path, checkout):
    """A finished run at the checkout's first commit: a simulation, the figure drawn from it, and a
    scene job of a run with another config file, which no target of this config needs."""
    work = tmp_path / "work"
    work.mkdir()
    start_session(checkout, CONFIG, work)
    _job(work, "simulate", [], ["results/runs/a.txt"], time.time())
    _job(work, "plot_fig1", ["results/runs/a.txt"], ["figures/fig1.png", "results/figures/fig1.txt"], time.time())
    start_session(checkout, {"scenes": "other"}, work)
    _job(work, "scene_run", [], ["results/scenes/other/x.txt"], time.time())
    return work


def build(work, checkout, **kw):
    build_crate(work, checkout, CONFIG, ["simulate", "plot_fig1"], targets=TARGETS, **kw)
    return json.loads((work / "results/ro-crate" / METADATA).read_text())


def graph_of(meta):
    return {e["@id"]: e for e in meta["@graph"]}


def actions(graph):
    return {graph[e["instrument"]["@id"]]["name"]: e for e in graph.values() if e["@id"].startswith("#job-")}


def listed(entity, key):
    value = entity.get(key, [])
    return value if isinstance(value, list) else [value]


def test_each_job_names_the_commit_it_ran_at_not_the_one_the_crate_was_built_at(run, checkout):
    """A docs-only commit between the run and the crate: the jobs ran at the first commit, clean."""
    first = _head(checkout)
    (checkout / "docs.md").write_text("docs, edited\n")
    _git(checkout, "commit", "-qam", "docs only")
    second = _head(checkout)
    start_session(checkout, CONFIG, run)  # the crate's own run of jobs, at the new commit
    graph = graph_of(build(run, checkout))
    for action in actions(graph).values():
        assert f"ran at commit {first} (clean)" in action["description"], action
        assert second not in action["description"] and "another config" not in action["description"]
    assert f"commit {second}" in graph["#git"]["value"]  # the workflow's files in the crate are the new ones
    readme = (run / "results/ro-crate/README.md").read_text()
    assert f"commit {first} (clean) (2 jobs)" in readme


def test_a_job_without_a_record_of_its_run_has_no_commit(run, checkout):
    shutil.rmtree(run / ".snakemake/particle_entropy/sessions")
    graph = graph_of(build(run, checkout))
    assert all("commit unknown" in a["description"] for a in actions(graph).values())


def test_a_job_of_a_run_with_another_config_is_not_an_action_of_this_one(run, checkout):
    graph = graph_of(build(run, checkout))
    assert set(actions(graph)) == {"rule simulate", "rule plot_fig1"}
    assert "results/scenes/other/x.txt" not in graph
    assert not (run / "results/ro-crate/results/scenes").exists()


def test_a_scene_outside_the_default_target_counts_where_a_run_of_this_config_made_it(run, checkout):
    start_session(checkout, CONFIG, run)
    _job(run, "plot_scene", [], ["figures/scene_mine.png"], time.time())
    scenes = ["figures/scene_mine.png", "results/scenes/other/x.txt"]
    build_crate(run, checkout, CONFIG, [], targets=TARGETS, optional=scenes)
    graph = graph_of(json.loads((run / "results/ro-crate" / METADATA).read_text()))
    assert set(actions(graph)) == {"rule simulate", "rule plot_fig1", "rule plot_scene"}


def test_a_figure_edited_after_its_job_is_not_described_as_its_output(run, checkout):
    png = run / "figures/fig1.png"
    png.write_text("edited by hand\n")
    graph = graph_of(build(run, checkout))
    plot = actions(graph)["rule plot_fig1"]
    assert {"@id": "figures/fig1.png"} not in listed(plot, "result")
    assert {"@id": "results/figures/fig1.txt"} in listed(plot, "result")
    assert {"@id": "figures/fig1.png"} not in listed(graph["#run"], "result")
    assert "changed since the job plot_fig1 #1 wrote it" in graph["figures/fig1.png"]["description"]
    assert "exampleOfWork" not in graph["figures/fig1.png"]
    assert "figures/fig1.png" in (run / "results/ro-crate/README.md").read_text()
    assert verify_crate(run / "results/ro-crate") == []  # its digest is the edited file's, as it says
    # the job's bytes and time put back (as a rerun of the job would): its output again, the old
    # description not carried over as if a person had written it
    end = (run / "results/figures/fig1.txt").stat().st_mtime
    png.write_text("figures/fig1.png by plot_fig1\n")
    os.utime(png, (end, end))
    graph = graph_of(build(run, checkout))
    assert {"@id": "figures/fig1.png"} in listed(actions(graph)["rule plot_fig1"], "result")
    assert "description" not in graph["figures/fig1.png"]


@pytest.mark.parametrize("record", [True, False], ids=["with the last build's record", "without"])
def test_a_rebuild_keeps_an_author_and_a_file_a_person_added(run, checkout, record):
    crate = run / "results/ro-crate"
    build(run, checkout)
    meta = json.loads((crate / METADATA).read_text())
    graph = graph_of(meta)
    person = {"@id": "https://orcid.org/0000-0002-1825-0097", "@type": "Person", "name": "Josiah Carberry"}
    note = {"@id": "notes/readme-extra.txt", "@type": "File", "name": "a note"}
    meta["@graph"] += [person, note]
    graph["./"]["author"] = {"@id": person["@id"]}
    graph["./"]["hasPart"].append({"@id": note["@id"]})
    (crate / METADATA).write_text(json.dumps(meta))
    (crate / "notes").mkdir()
    (crate / "notes/readme-extra.txt").write_text("extra\n")
    if not record:
        (run / GENERATED).unlink()
    graph = graph_of(build(run, checkout))
    assert graph[person["@id"]] == person
    assert graph["./"]["author"] == {"@id": person["@id"]}
    assert {"@id": note["@id"]} in graph["./"]["hasPart"]
    assert {"@id": "figures/fig1.png"} in graph["./"]["hasPart"]  # the workflow's own parts too
    assert (crate / "notes/readme-extra.txt").read_text() == "extra\n"
    assert len([e for e in graph.values() if e["@id"] == person["@id"]]) == 1


def test_a_rebuild_refuses_metadata_that_does_not_parse(run, checkout):
    build(run, checkout)
    (run / "results/ro-crate" / METADATA).write_text('{"@graph": [')
    with pytest.raises(CrateError, match="does not parse"):
        build(run, checkout)


def test_a_linked_folder_in_the_crate_is_replaced_not_written_through(run, checkout, tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "fig1.png").write_text("someone else's figure\n")
    crate = run / "results/ro-crate"
    crate.mkdir(parents=True)
    (crate / "figures").symlink_to(outside)
    (crate / "README.md").symlink_to(outside / "fig1.png")
    build(run, checkout)
    assert (outside / "fig1.png").read_text() == "someone else's figure\n"
    assert sorted(p.name for p in outside.iterdir()) == ["fig1.png"]
    assert (
        not (crate / "figures").is_symlink()
        and (crate / "figures/fig1.png").read_text() == (run / "figures/fig1.png").read_text()
    )
    assert not (crate / "README.md").is_symlink()


def test_a_crate_folder_that_cannot_hold_it_is_refused_in_one_line(run, checkout, tmp_path):
    (run / "results").mkdir(exist_ok=True)
    (run / "results/ro-crate").write_text("a file\n")
    problem = crate_folder_problem(run)
    assert problem.startswith("results/ro-crate is a file, not a folder") and "\n" not in problem
    with pytest.raises(CrateError, match="is a file, not a folder"):
        build(run, checkout)
    (run / "results/ro-crate").unlink()
    (run / "results/ro-crate").symlink_to(tmp_path)
    assert "outside results/" in crate_folder_problem(run)
    with pytest.raises(CrateError, match="outside results/"):
        build(run, checkout)
    (run / "results/ro-crate").unlink()
    (run / "results/ro-crate").mkdir()
    (run / "results/ro-crate" / METADATA).symlink_to(tmp_path / "elsewhere.json")
    assert "is a link" in crate_folder_problem(run)


def test_the_report_names_the_commit_a_figure_was_drawn_at(run, checkout, monkeypatch):
    """The report's label of a figure (crate.provenance): its job's commit, not the checkout's now."""
    first = _head(checkout)
    (checkout / "docs.md").write_text("docs, edited\n")
    _git(checkout, "commit", "-qam", "docs only")
    monkeypatch.chdir(run)
    labels = provenance("figures/fig1.png", "plot_fig1", "m.py", "results/figures/fig1.txt", CONFIG, checkout)
    assert labels["commit"] == first[:12]
    shutil.rmtree(run / ".snakemake/metadata")  # no record of the figure's job: the checkout now, marked so
    labels = provenance("figures/fig1.png", "plot_fig1", "m.py", "results/figures/fig1.txt", CONFIG, checkout)
    assert labels["commit"] == _head(checkout)[:12] + " (the checkout now: no record of its run)"
