"""The README as a front page and the pages it points to: it stays short, names both jobs before
its commands, holds the two commands that `.ci/run` repeats, and every relative link of it and of
docs/*.md reaches a file and, for `#anchor`, a heading of that file."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from conftest import ROOT

README = ROOT / "README.md"
MAX_LINES = 200  # a front page: the long tables and caveats live in docs/
FENCE = re.compile(r"^```.*?^```[ \t]*$", re.S | re.M)
CODE_SPAN = re.compile(r"`[^`\n]*`")
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^#{1,6}[ \t]+(.+?)[ \t]*#*[ \t]*$", re.M)


def section(text: str, title: str) -> str:
    """The body of the level-2 section ``title``, up to the next level-2 heading."""
    m = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    assert m, f"no section {title!r}"
    return m[1]


def commands(text: str) -> list[str]:
    """The command lines of the bash blocks in ``text`` (comments and blank lines left out)."""
    blocks = re.findall(r"^```bash\n(.*?)^```", text, re.S | re.M)
    return [line for b in blocks for line in b.splitlines() if line.strip() and not line.startswith("#")]


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, each space a hyphen."""
    text = CODE_SPAN.sub(lambda m: m[0].strip("`"), heading).strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    """The anchors of a Markdown page's headings (a repeated heading gets -1, -2, ... as on GitHub)."""
    seen: dict[str, int] = {}
    out = set()
    for heading in HEADING.findall(FENCE.sub("", page.read_text(encoding="utf-8"))):
        base = slug(heading)
        k = seen.get(base, 0)
        seen[base] = k + 1
        out.add(base if k == 0 else f"{base}-{k}")
    return out


def broken_links(page: Path) -> list[str]:
    """Relative links of ``page`` whose file is missing or whose #anchor names no heading there.
    Links in code (fenced blocks, `spans`) are text, not links, and are skipped."""
    text = CODE_SPAN.sub("``", FENCE.sub("", page.read_text(encoding="utf-8")))
    bad = []
    for target in LINK.findall(text):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto:, ...
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        if not dest.exists():
            bad.append(f"{target}: no file {dest.relative_to(ROOT) if dest.is_relative_to(ROOT) else dest}")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            bad.append(f"{target}: no heading #{anchor} in {dest.name}")
    return bad


def test_readme_is_a_front_page():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_LINES, f"README.md has {len(lines)} lines: move tables and caveats to docs/"


def test_readme_names_both_jobs_before_its_commands():
    text = README.read_text(encoding="utf-8")
    opening = text[: text.index("\n## ")]
    assert "Advances in Water Resources 103509" in opening  # the paper, cited
    assert "scene" in opening.lower()  # a modeller's own problem


def test_readme_has_the_two_commands_that_ci_runs():
    """One command sets up and reproduces the paper, one sets up and runs the tests; `.ci/run` runs
    the same set-up and the same tests (with the linters between), so the two cannot drift apart."""
    shown = commands(section(README.read_text(encoding="utf-8"), "Two commands"))
    assert len(shown) == 2, shown
    setups = {line.rsplit(" && ", 1)[0] for line in shown}
    assert len(setups) == 1, setups  # both set up alike
    paper, tests = (line.rsplit(" && ", 1)[1] for line in shown)
    assert paper == ".venv/bin/snakemake -j2"
    assert tests == ".venv/bin/python -m pytest -q"
    ci = [line for line in (ROOT / ".ci" / "run").read_text().splitlines() if line and not line.startswith("#")]
    assert setups.pop() in ci
    assert ci[-1] == tests


@pytest.mark.parametrize("page", [README, *sorted((ROOT / "docs").glob("*.md"))], ids=lambda p: p.name)
def test_relative_links_resolve(page):
    assert not broken_links(page)


def test_a_broken_link_or_anchor_is_found(tmp_path):
    (tmp_path / "other.md").write_text("# A title: with `code`\n\n## Again\n\n## Again\n", encoding="utf-8")
    page = tmp_path / "page.md"
    page.write_text(
        "[ok](other.md#a-title-with-code) [ok](other.md#again-1) [gone](missing.md) [bad](other.md#nothing)\n"
        "`[in code](missing.md)` [web](https://example.org/x.md)\n```\n[fenced](missing.md)\n```\n",
        encoding="utf-8",
    )
    found = broken_links(page)
    assert len(found) == 2 and found[0].startswith("missing.md") and found[1].startswith("other.md#nothing"), found
