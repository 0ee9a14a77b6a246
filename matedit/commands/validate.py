"""`matedit validate FILE...`: exit 0, or 2 with one `error: FILE: ...` line per problem."""

from __future__ import annotations

import sys
from pathlib import Path

from matedit.graph.validate import Severity, analyse
from matedit.io.document import FileResolver, FormatError, load


def register(sub) -> None:
    p = sub.add_parser("validate", help="check material and function files",
                       description="Check material and material-function files (folders are "
                       "searched for *.json).")
    p.add_argument("files", nargs="+", metavar="FILE")
    p.set_defaults(run=run)


def expand(files: list[str]) -> list[Path]:
    out: list[Path] = []
    for f in files:
        p = Path(f)
        out.extend(sorted(p.rglob("*.json")) if p.is_dir() else [p])
    return out


def problems(path: Path, resolver: FileResolver) -> list[tuple[str, str]]:
    """(severity, message) lines for one file."""
    try:
        doc = load(path)
    except FormatError as exc:
        return [("error", str(exc))]
    lines = []
    for d in analyse(doc, resolver).diagnostics:
        lines.append((d.severity.value, f"{path}: {d.format()}"))
    return lines


def run(args) -> int:
    resolver = FileResolver()
    failed = False
    for path in expand(args.files):
        for severity, message in problems(path, resolver):
            print(f"{severity}: {message}", file=sys.stderr)
            failed |= severity == Severity.ERROR.value
    return 2 if failed else 0
