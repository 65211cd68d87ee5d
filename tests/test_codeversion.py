"""Content hashes of library code (codeversion.py): the import closure of a fake package in tmp_path,
exclusions, a hash that follows content (not modification times) of exactly the modules reached, and
the closures the simulation rules use on the real package."""

from __future__ import annotations

import os

import pytest
from conftest import ROOT

from particle_entropy.pipeline.codeversion import closure, code_version, imports, modules, script_code, script_imports

SCRIPTS = ROOT / "workflow" / "scripts"

MODULES = {
    "a": "from .b import f\n\n\ndef g():\n    return f()\n",
    "b": "from . import c\n\n\ndef f():\n    return c.X\n",
    "c": "X = 1\n",
    "d": "import os\n\nY = 2\n",
}


@pytest.fixture
def pkg(tmp_path):
    root = tmp_path / "fakepkg"
    root.mkdir()
    (root / "__init__.py").write_text("")
    for name, src in MODULES.items():
        (root / f"{name}.py").write_text(src)
    imports.cache_clear()
    modules.cache_clear()
    yield root
    imports.cache_clear()
    modules.cache_clear()


def _rewrite(path, text):
    path.write_text(text)
    imports.cache_clear()
    modules.cache_clear()


def test_imports_reads_relative_imports(pkg):
    assert imports("a", pkg) == frozenset({"b"})
    assert imports("b", pkg) == frozenset({"c"})
    assert imports("c", pkg) == frozenset()
    assert imports("d", pkg) == frozenset()  # `import os` is not a package module


def test_closure_follows_imports_transitively(pkg):
    assert closure(["a"], package=pkg) == ["a", "b", "c"]
    assert closure(["b"], package=pkg) == ["b", "c"]
    assert closure(["a", "d"], package=pkg) == ["a", "b", "c", "d"]


def test_exclude_cuts_a_branch(pkg):
    assert closure(["a"], exclude={"b"}, package=pkg) == ["a"]
    assert closure(["a"], exclude={"c"}, package=pkg) == ["a", "b"]
    assert closure(["a", "d"], exclude={"a"}, package=pkg) == ["d"]


def test_code_version_follows_content_of_the_closure(pkg):
    v0 = code_version("a", package=pkg)
    assert len(v0) == 16 and int(v0, 16) >= 0
    _rewrite(pkg / "c.py", "X = 2\n")
    v1 = code_version("a", package=pkg)
    assert v1 != v0
    _rewrite(pkg / "c.py", MODULES["c"])  # content restored: the old hash
    assert code_version("a", package=pkg) == v0


def test_touch_or_identical_rewrite_changes_nothing(pkg):
    v0 = code_version("a", package=pkg)
    c = pkg / "c.py"
    st = c.stat()
    os.utime(c, ns=(st.st_atime_ns + 10**10, st.st_mtime_ns + 10**10))
    assert code_version("a", package=pkg) == v0
    _rewrite(c, MODULES["c"])
    assert code_version("a", package=pkg) == v0


def test_unrelated_module_does_not_change_the_hash(pkg):
    v0 = code_version("a", package=pkg)
    _rewrite(pkg / "d.py", "Y = 3\n")
    assert code_version("a", package=pkg) == v0
    assert code_version("d", package=pkg) != code_version("a", package=pkg)


def test_excluded_branch_does_not_change_the_hash(pkg):
    v0 = code_version("a", exclude={"b"}, package=pkg)
    _rewrite(pkg / "c.py", "X = 5\n")
    assert code_version("a", exclude={"b"}, package=pkg) == v0
    assert code_version("a", package=pkg) != code_version("a", exclude={"b"}, package=pkg)


def test_a_new_import_is_followed(pkg):
    v0 = code_version("a", package=pkg)
    _rewrite(pkg / "c.py", "from .d import Y\n\nX = Y\n")
    assert closure(["a"], package=pkg) == ["a", "b", "c", "d"]
    v1 = code_version("a", package=pkg)
    assert v1 != v0
    _rewrite(pkg / "d.py", "import os\n\nY = 4\n")
    assert code_version("a", package=pkg) != v1  # d is now reached, so its content counts


def test_extra_files_are_hashed(pkg, tmp_path):
    script = tmp_path / "script.py"
    script.write_text("print(1)\n")
    v0 = code_version("a", files=[str(script)], package=pkg)
    assert v0 != code_version("a", package=pkg)
    script.write_text("print(2)\n")
    assert code_version("a", files=[str(script)], package=pkg) != v0


# --------------------------------------------------------------------------- the real package
def test_modules_of_one_file_name_in_two_subpackages_are_two_modules(tmp_path):
    """Keys are dotted names, so file names need not be unique: sub/x.py and other/x.py, each
    reached by its own relative import, up and down the tree."""
    root = tmp_path / "deep"
    for sub_, src in {"sub": "from ..other import x as y\n\nA = y.B\n", "other": "B = 1\n"}.items():
        (root / sub_).mkdir(parents=True)
        (root / sub_ / "__init__.py").write_text("")
        (root / sub_ / "x.py").write_text(src)
    (root / "__init__.py").write_text("")
    (root / "top.py").write_text("from .sub.x import A\n")
    modules.cache_clear()
    imports.cache_clear()
    try:
        assert set(modules(root)) == {"sub.x", "other.x", "top"}
        assert imports("top", root) == frozenset({"sub.x"})
        assert imports("sub.x", root) == frozenset({"other.x"})  # not itself: the other package's x
        assert closure(["top"], package=root) == ["other.x", "sub.x", "top"]
        v0 = code_version("top", package=root)
        (root / "other" / "x.py").write_text("B = 2\n")
        modules.cache_clear()
        imports.cache_clear()
        assert code_version("top", package=root) != v0  # reached through sub.x
    finally:
        modules.cache_clear()
        imports.cache_clear()


def test_fd_simulation_closure_leaves_out_the_particle_code():
    mods = closure(["models.simulate", "models.fd"], exclude={"models.pt", "models.mtpt"})
    assert {"models.simulate", "models.fd", "core.case"} <= set(mods)
    assert "numerics.gauss" not in mods and "numerics.mass_transfer" not in mods
    assert "models.pt" not in mods and "models.mtpt" not in mods


def test_mtpt_simulation_closure_holds_mass_transfer():
    mods = closure(["models.simulate", "models.mtpt"], exclude={"models.pt", "models.fd"})
    assert {"models.simulate", "models.mtpt", "numerics.mass_transfer", "numerics.fastexp"} <= set(mods)
    assert "models.pt" not in mods and "models.fd" not in mods
    assert code_version("models.simulate", "models.mtpt", exclude={"models.pt", "models.fd"}) != code_version(
        "models.simulate", "models.fd", exclude={"models.pt", "models.mtpt"}
    )


def test_library_path_is_exported_first_and_once(monkeypatch, tmp_path):
    import os

    from particle_entropy.pipeline.codeversion import export_library_path

    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(["/elsewhere", str(tmp_path)]))
    export_library_path(tmp_path)
    export_library_path(tmp_path)  # a job re-parsing the Snakefile exports it again
    assert os.environ["PYTHONPATH"].split(os.pathsep) == [str(tmp_path), "/elsewhere"]


# --------------------------------------------------------------------------- sections apart
def _edit(path, old, new):
    text = path.read_text()
    assert old in text, f"{old!r} not in {path.name}: the test edits a declaration that moved"
    _rewrite(path, text.replace(old, new, 1))


@pytest.fixture
def library(tmp_path):
    """A copy of the real package, to edit declarations in."""
    import shutil

    from particle_entropy.pipeline.codeversion import PACKAGE

    root = tmp_path / "particle_entropy"
    shutil.copytree(PACKAGE, root, ignore=shutil.ignore_patterns("__pycache__"))
    imports.cache_clear()
    modules.cache_clear()
    yield root
    imports.cache_clear()
    modules.cache_clear()


def _simulation_hashes(root):
    from particle_entropy.core.registry import METHODS
    from particle_entropy.pipeline.codeversion import simulation_code

    hashes = {m: simulation_code(m, METHODS, SCRIPTS / "simulate.py", package=root) for m in METHODS}
    return hashes | {"shear": script_code(SCRIPTS / "shear2d.py", package=root)}


def test_simulation_code_holds_no_other_section(library):
    """A simulation imports the run settings (core/run_settings.py) and the shear flow's, never
    core/settings.py, which declares every other section."""
    from particle_entropy.core.registry import METHODS

    simulation_entries = script_imports(SCRIPTS / "simulate.py", library)
    shear_entries = script_imports(SCRIPTS / "shear2d.py", library)
    for method in METHODS:
        others = {f"models.{m}" for m in METHODS if m != method}
        mods = closure([*simulation_entries, f"models.{method}"], exclude=others, package=library)
        assert "core.run_settings" in mods and "core.settings" not in mods
        assert not any(m.split(".")[0] in ("analysis", "experiments", "figures", "pipeline") for m in mods)
    assert "core.settings" not in closure(shear_entries, package=library)


def test_editing_another_section_reruns_no_simulation(library):
    """Rewording a claims tolerance, a scene's cost constant or a search's key changes no
    simulation's code hash; editing the run settings changes every 1-D one, the shear flow's
    settings only the shear flow's."""
    before = _simulation_hashes(library)
    settings = library / "core" / "settings.py"
    _edit(settings, '"allowed |H_C - analytic| of adaptive-kernel PT at t = 1000"', '"a reworded claim"')
    _edit(settings, "MAX_REALISATIONS = 10_000", "MAX_REALISATIONS = 20_000")
    _edit(settings, '"the searched model (unset dimensions from case_defaults)"', '"a reworded search key"')
    assert _simulation_hashes(library) == before
    _edit(library / "core" / "shear_settings.py", '"longitudinal dispersivity"', '"reworded"')
    after_shear = _simulation_hashes(library)
    assert after_shear["shear"] != before["shear"]
    assert {m: h for m, h in after_shear.items() if m != "shear"} == {m: h for m, h in before.items() if m != "shear"}
    _edit(library / "core" / "run_settings.py", '"diffusion coefficient"', '"reworded"')
    after_run = _simulation_hashes(library)
    assert all(after_run[m] != after_shear[m] for m in after_run)


# --------------------------------------------------------------------------- hashes from scripts
def test_script_imports_reads_every_form_of_absolute_import(tmp_path):
    script = tmp_path / "job.py"
    script.write_text(
        "import sys\nimport particle_entropy.core.io\nfrom particle_entropy.figures import fig10, style as s\n"
        "from particle_entropy.analysis.aggregate import (\n    tradeoff_table,\n)\n\n\n"
        "def main():\n    from particle_entropy.core.heap import keep_freed_pages\n"
        "\n\n# from particle_entropy.core.labels import case_label\n"
    )
    assert script_imports(script) == {"core.io", "figures.fig10", "figures.style", "analysis.aggregate", "core.heap"}
    rules = tmp_path / "rule.smk"  # a run: block's imports, read by a pattern (not Python)
    rules.write_text("rule x:\n    run:\n        from particle_entropy.analysis.aggregate import summarise_files\n")
    assert script_imports(rules) == {"analysis.aggregate"}


# The entry modules that common.smk listed by hand for the simulation jobs, before each rule's hash
# was read from its script: the script-derived hashes must equal these, or every simulation reruns.
HAND_LISTED = {
    "simulate.py": ("models.simulate", "core.io", "core.heap", "core.reference_file"),
    "shear2d.py": ("models.shear2d", "core.io", "core.heap"),
}


def test_simulation_hashes_equal_the_hand_listed_ones():
    """Reading the entries from simulate.py and shear2d.py reruns no simulation: the hashes are
    those of the hand-written lists. When this fails a script's imports reach a module the old
    list did not, so every such simulation would rerun: update HAND_LISTED only if that is meant."""
    from particle_entropy.core.registry import METHODS
    from particle_entropy.pipeline.codeversion import simulation_code

    for method in METHODS:
        others = {f"models.{m}" for m in METHODS if m != method}
        old = code_version(
            *HAND_LISTED["simulate.py"], f"models.{method}", exclude=others, files=[SCRIPTS / "simulate.py"]
        )
        assert simulation_code(method, METHODS, SCRIPTS / "simulate.py") == old, method
    old_shear = code_version(*HAND_LISTED["shear2d.py"], files=[SCRIPTS / "shear2d.py"])
    assert script_code(SCRIPTS / "shear2d.py") == old_shear
