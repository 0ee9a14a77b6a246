"""The documentation stays true: Markdown links resolve, cli.md covers every command and
option, and the user guide's screenshots are the ones docs/screenshots.py makes."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from matedit.cli import build_parser

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
SKIP_DIRS = {".venv", "dist", "build", "node_modules", "__pycache__"}
LINK = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def markdown_files() -> list[Path]:
    out = []
    for p in ROOT.rglob("*.md"):
        rel = p.relative_to(ROOT)
        if any(part in SKIP_DIRS or part.startswith(".") for part in rel.parts[:-1]):
            continue
        out.append(p)
    return sorted(out)


def without_code(text: str) -> str:
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    return re.sub(r"`[^`\n]*`", "", text)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to '-'."""
    h = re.sub(r"[`*_]", "", heading.strip().lower())
    h = re.sub(r"[^\w\- ]", "", h)
    return h.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    text = re.sub(r"```.*?```", "", path.read_text(), flags=re.S)
    return {slug(m.group(1)) for m in re.finditer(r"^#+\s+(.*)$", text, re.M)}


def links(path: Path) -> list[str]:
    return LINK.findall(without_code(path.read_text()))


def test_the_repository_has_its_docs():
    for name in ("architecture", "file-format", "shading", "cli", "user-guide"):
        assert (DOCS / f"{name}.md").is_file(), name
    assert (ROOT / "README.md") in markdown_files()


def broken_links(path: Path) -> list[str]:
    broken = []
    for target in links(path):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        file_part, _, anchor = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path
        if not dest.exists():
            broken.append(target)
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            broken.append(target + " (no such heading)")
    return broken


@pytest.mark.parametrize("path", markdown_files(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_markdown_links_resolve(path):
    broken = broken_links(path)
    assert broken == [], f"{path.relative_to(ROOT)} links to missing paths: {broken}"


def test_link_checker_sees_a_broken_link(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("See [this](missing.md), `[not](code.md)` and [web](https://x.org).\n"
                    "```\n[neither](block.md)\n```\n![img](pic.png) [me](#nowhere)\n"
                    "## A heading, `here`\n[ok](#a-heading-here)\n")
    assert links(page) == ["missing.md", "https://x.org", "pic.png", "#nowhere",
                           "#a-heading-here"]
    assert broken_links(page) == ["missing.md", "pic.png", "#nowhere (no such heading)"]


# Documents that are not in the repository (spelled in two parts, so that this file does not
# cite them itself).
OUTSIDE = ("ARCHITECTURE" + ".md", "SHADING" + ".md")
CITATION = re.compile(r"(?<![\w/.])(?:\.\./)?docs/([\w.-]+\.md)(?:#([\w-]+))?")


def repository_files() -> list[Path]:
    """The files of the repository: those git tracks and the untracked ones it does not
    ignore (every file below ROOT outside SKIP_DIRS where git is missing)."""
    import subprocess

    try:
        out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                             capture_output=True, check=True).stdout.decode()
        return sorted(ROOT / n for n in out.split("\0") if n and (ROOT / n).is_file())
    except (OSError, subprocess.CalledProcessError):
        return sorted(p for p in ROOT.rglob("*") if p.is_file()
                      and not set(p.relative_to(ROOT).parts) & SKIP_DIRS)


def citation_problems(files: list[Path], root: Path = ROOT) -> list[str]:
    """A citation of a document outside the repository, or of a page of docs/ (with or
    without `#section`) where the page or the section heading does not exist."""
    problems = []
    for path in files:
        try:
            text = path.read_text()
        except (UnicodeDecodeError, OSError):
            continue  # not text
        rel = path.relative_to(root).as_posix()
        for n, line in enumerate(text.splitlines(), 1):
            problems += [f"{rel}:{n}: cites {name}, which is not in the repository"
                         for name in OUTSIDE if name in line]
            for m in CITATION.finditer(line):
                doc = root / "docs" / m.group(1)
                if not doc.is_file():
                    problems.append(f"{rel}:{n}: cites docs/{m.group(1)}, which does not exist")
                elif m.group(2) and m.group(2) not in anchors(doc):
                    problems.append(f"{rel}:{n}: cites docs/{m.group(1)}#{m.group(2)}: no such "
                                    "heading")
    return problems


def test_no_file_cites_a_document_outside_the_repository_or_a_missing_section():
    problems = citation_problems(repository_files())
    assert problems == [], "\n".join(problems)


def test_the_citation_checker_sees_bad_citations(tmp_path):
    d = "docs" + "/"  # (so that this file does not cite the missing pages itself)
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "shading.md").write_text("# Shading\n## The material model\n")
    good = tmp_path / "good.py"
    good.write_text(f"# {d}shading.md#the-material-model, ../{d}shading.md, {d}shading.md\n")
    bad = tmp_path / "bad.glsl"
    bad.write_text(f"// {OUTSIDE[1]}, output\n// {d}shading.md#output\n"
                   f"/* see {d}lighting.md */ {OUTSIDE[0]}\n")
    assert citation_problems([good, bad], tmp_path) == [
        f"bad.glsl:1: cites {OUTSIDE[1]}, which is not in the repository",
        f"bad.glsl:2: cites {d}shading.md#output: no such heading",
        f"bad.glsl:3: cites {OUTSIDE[0]}, which is not in the repository",
        f"bad.glsl:3: cites {d}lighting.md, which does not exist",
    ]


def test_readme_points_at_nothing_outside_the_repository():
    text = (ROOT / "README.md").read_text()
    assert not any(name in text for name in OUTSIDE)
    assert "docs/user-guide.md" in text and "packaging/build.sh" in text


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_cli_doc_covers_every_command_and_option():
    text = (DOCS / "cli.md").read_text()
    assert "`matedit --version`" in text
    for name, parser in _commands().items():
        # the heading of this command, not of one whose name it begins (bake, bake-ibl)
        m = re.search(rf"^## `matedit {re.escape(name)}[ `]", text, re.M)
        assert m, f"docs/cli.md: no section for {name}"
        section = text[m.end():].split("\n## ", 1)[0]
        for action in parser._actions:
            for opt in action.option_strings:
                if opt in ("-h", "--help"):
                    continue
                assert f"`{opt}" in section or f"{opt}`" in section or f"`{opt} " in section, \
                    f"docs/cli.md, {name}: option {opt} is not documented"
            for choice in action.choices or ():
                assert f"`{choice}`" in section, f"docs/cli.md, {name}: {choice} missing"
    for status in ("| 0 |", "| 1 |", "| 2 |"):
        assert status in text


def test_user_guide_images_are_the_screenshot_scripts():
    guide = (DOCS / "user-guide.md").read_text()
    used = {Path(t).name for t in links(DOCS / "user-guide.md") if t.startswith("images/")}
    script = (DOCS / "screenshots.py").read_text()
    made = set(re.findall(r'"([a-z0-9-]+\.png)"', script))
    on_disk = {p.name for p in (DOCS / "images").glob("*.png")}
    assert used <= made, f"the guide shows images the script does not make: {used - made}"
    assert made == on_disk, "docs/images/ is out of date: run docs/screenshots.py"
    assert used == on_disk, f"screenshots the guide does not show: {on_disk - used}"
    assert "docs/screenshots.py" in guide


def test_shading_doc_names_the_command_of_each_table():
    text = (DOCS / "shading.md").read_text()
    assert "### Command: `.venv/bin/python docs/accuracy.py`" in text
    assert "### Command: `benchmarks/run.sh`" in text
    assert (DOCS / "accuracy.py").is_file()
    for header in ("Environment BRDF LUT", "Prefiltered environment", "Sphere light",
                   "Split sum against the reference", "White furnace"):
        assert header in text and header in (DOCS / "accuracy.py").read_text()
