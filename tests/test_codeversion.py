"""Content hashes of library code (codeversion.py): the import closure of a fake package in tmp_path,
exclusions, a hash that follows content (not modification times) of exactly the modules reached, and
the closures the simulation rules use on the real package."""

from __future__ import annotations

import os

import pytest

from particle_entropy.pipeline.codeversion import closure, code_version, imports, modules

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
def test_fd_simulation_closure_leaves_out_the_particle_code():
    mods = closure(["simulate", "fd"], exclude={"pt", "mtpt"})
    assert {"simulate", "fd"} <= set(mods)
    assert "gauss" not in mods and "mass_transfer" not in mods
    assert "pt" not in mods and "mtpt" not in mods


def test_mtpt_simulation_closure_holds_mass_transfer():
    mods = closure(["simulate", "mtpt"], exclude={"pt", "fd"})
    assert {"simulate", "mtpt", "mass_transfer"} <= set(mods)
    assert "pt" not in mods and "fd" not in mods
    assert code_version("simulate", "mtpt", exclude={"pt", "fd"}) != code_version(
        "simulate", "fd", exclude={"pt", "mtpt"}
    )


def test_library_path_is_exported_first_and_once(monkeypatch, tmp_path):
    import os

    from particle_entropy.pipeline.codeversion import export_library_path

    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(["/elsewhere", str(tmp_path)]))
    export_library_path(tmp_path)
    export_library_path(tmp_path)  # a job re-parsing the Snakefile exports it again
    assert os.environ["PYTHONPATH"].split(os.pathsep) == [str(tmp_path), "/elsewhere"]
