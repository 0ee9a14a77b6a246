"""`matedit validate FILE...`: exit 0, or 2 with one `error: FILE: ...` line per problem."""

from __future__ import annotations

from pathlib import Path

from matedit.cli_support import report
from matedit.graph.validate import Severity, analyse
from matedit.io.document import INSTANCE_FORMAT, FileResolver, FormatError, load
from matedit.io.input_kinds import declare_inputs


def register(sub) -> None:
    p = sub.add_parser("validate", help="check material, function and instance files",
                       description="Check material, material-function and material-instance "
                       "files (folders are searched for *.json).")
    p.add_argument("files", nargs="+", metavar="FILE")
    declare_inputs(p, files="documents")  # read only: validate writes no file
    p.set_defaults(run=run)


def expand(files: list[str]) -> list[Path]:
    out: list[Path] = []
    for f in files:
        p = Path(f)
        out.extend(sorted(p.rglob("*.json")) if p.is_dir() else [p])
    return out


def empty_folders(files: list[str]) -> list[Path]:
    """The folders named on the command line that hold no *.json at any depth: checking
    nothing is not a pass."""
    return [Path(f) for f in files if Path(f).is_dir() and next(Path(f).rglob("*.json"),
                                                                None) is None]


def _format_of(path: Path) -> str | None:
    """The `format` of a small JSON file, cheaply, to pick its reader; None if unknown."""
    from matedit.io.bounded import read_bounded
    from matedit.io.jsontext import parse_json

    try:
        raw = parse_json(read_bounded(path, 1 << 20))
    except (OSError, ValueError):
        return None
    return raw.get("format") if isinstance(raw, dict) else None


def problems(path: Path, resolver: FileResolver) -> list[tuple[str, str]]:
    """(severity, message) lines for one file."""
    fmt = _format_of(path)
    if fmt == "matedit.lightrig":
        from matedit.io.rig import RigError
        from matedit.io.rig import load as load_rig

        try:
            load_rig(path)
        except RigError as exc:
            return [("error", str(exc))]
        return []
    if isinstance(fmt, str) and fmt != INSTANCE_FORMAT:
        # read in full and not an instance: the instance reader is not needed (nor imported)
        try:
            doc = load(path)
        except FormatError as exc:
            return [("error", str(exc))]
        return _document_problems(path, doc, resolver)
    from matedit.io.instance import InstanceError, is_instance_file, load_instance, resolve

    lines = []
    try:
        if is_instance_file(path):  # its own rules, then its effective material's
            r = resolve(load_instance(path))
            lines = [(p.severity, p.format()) for p in r.problems]
            if r.errors:
                return lines
            doc = r.document
        else:
            doc = load(path)
    except (FormatError, InstanceError) as exc:
        return [("error", str(exc))]
    return lines + _document_problems(path, doc, resolver)


def _document_problems(path: Path, doc, resolver: FileResolver) -> list[tuple[str, str]]:
    """(severity, message) lines of a loaded material or function: its analysis, and for a
    material without errors, its compile."""
    lines = []
    diagnostics = analyse(doc, resolver).diagnostics
    for d in diagnostics:
        lines.append((d.severity.value, f"{d.file or path}: {d.format()}"))
    if not doc.is_function and not any(d.severity == Severity.ERROR for d in diagnostics):
        # What validate accepts must compile: the functions it calls are checked in full, and
        # anything only the compiler can see (names, emission) is reported here too.
        from matedit.compiler import CompileError, compile_document

        try:
            compile_document(doc, resolver, "glsl330")
        except CompileError as exc:
            for d in exc.diagnostics:
                lines.append(("error", f"{d.file or path}: {d.format()}"))
        except (RecursionError, ValueError, LookupError) as exc:
            lines.append(("error", f"{path}: does not compile: {exc}"))
    return lines


def run(args) -> int:
    resolver = FileResolver()
    failed = False
    for folder in empty_folders(args.files):
        report("error", f"{folder}: no material, function or instance files (*.json)")
        failed = True
    for path in expand(args.files):
        for severity, message in problems(path, resolver):
            report(severity, message)
            failed |= severity == Severity.ERROR.value
    return 2 if failed else 0
