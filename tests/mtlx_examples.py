"""The import tally of MaterialX's own example documents (tests/data/mtlx/examples): each
one imported, and the result (clean, with warnings, refused) as docs/materialx.md shows it.
docs/materialx.py writes the section; tests/test_interop_mtlx_examples.py checks it."""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent / "data" / "mtlx" / "examples"
HEADING = "## Import tally: MaterialX's example documents"


@dataclass
class Outcome:
    name: str
    surfaces: list[str]
    materials: int
    warnings: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)

    @property
    def status(self) -> str:
        return "refused" if self.errors else "warnings" if self.warnings else "clean"


def files() -> list[Path]:
    return sorted(EXAMPLES.glob("*.mtlx"))


def _surfaces(path: Path) -> tuple[list[str], int]:
    import MaterialX as mx

    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(path))
    cats = []
    mats = doc.getMaterialNodes()
    for m in mats:
        s = m.getInput("surfaceshader")
        node = doc.getNode(s.getNodeName()) if s is not None and s.getNodeName() else None
        if node is not None and node.getCategory() not in cats:
            cats.append(node.getCategory())
    return cats, len(mats)


def outcome(path: Path) -> Outcome:
    from matedit.interop.mtlx_import import MtlxImportError, import_all

    cats, count = _surfaces(path)
    out = Outcome(path.name, cats, count)
    with tempfile.TemporaryDirectory() as d:
        try:
            import_all(path, Path(d), out.warnings)
        except MtlxImportError as exc:
            out.errors = list(exc.messages)
            out.warnings = []
    return out


def outcomes() -> list[Outcome]:
    return [outcome(p) for p in files()]


def _input_of(warning: str) -> str:
    """The input a warning names (`FILE: material M: INPUT VALUE of ...`)."""
    return warning.split(": ", 2)[2].split(" ", 1)[0]


def _reason(error: str) -> str:
    text = error.split(": ", 1)[1]
    m = re.search(r"unsupported MaterialX node '(\w+)'", text)
    return f"`{m.group(1)}` node" if m else text


def section(results: list[Outcome] | None = None) -> str:
    """The tally section of docs/materialx.md."""
    results = outcomes() if results is None else results
    n = {s: sum(r.status == s for r in results) for s in ("clean", "warnings", "refused")}
    lines = [
        HEADING,
        "",
        f"The {len(results)} example documents of the MaterialX project in",
        "tests/data/mtlx/examples (Apache-2.0, see the README there), imported with",
        "`matedit import`: written by tests/mtlx_examples.py through docs/materialx.py, and",
        "checked by tests/test_interop_mtlx_examples.py, so it is what the import does today.",
        "",
        f"**{n['clean']} import clean, {n['warnings']} with warnings, "
        f"{n['refused']} {'is' if n['refused'] == 1 else 'are'} refused.**",
        "",
        "| document | surface | materials | import |",
        "|---|---|---|---|",
    ]
    for r in results:
        if r.status == "clean":
            what = "clean"
        elif r.status == "warnings":
            names = sorted({_input_of(w) for w in r.warnings})
            what = f"{len(r.warnings)} warning{'s' * (len(r.warnings) > 1)}: " + ", ".join(
                f"`{x}`" for x in names)
        else:
            what = "refused: " + "; ".join(dict.fromkeys(_reason(e) for e in r.errors))
        lines.append(f"| {r.name} | {', '.join(r.surfaces)} | {r.materials} | {what} |")
    lines.append("")
    return "\n".join(lines)
