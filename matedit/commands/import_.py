"""`matedit import FILE.mtlx -o OUT.json`: a MaterialX material as a matedit material.

Every unsupported node or input is an `error:` line naming it (exit 2); nothing is written
then. See matedit.interop.mtlx_import for what is read."""

from __future__ import annotations

import sys
from pathlib import Path

from matedit.cli import UsageError, report


def register(sub) -> None:
    p = sub.add_parser("import", help="import a MaterialX material",
                       description="Convert a MaterialX document's material (standard_surface,"
                       " open_pbr_surface, gltf_pbr or UsdPreviewSurface, with nodegraphs of "
                       "stdlib nodes matedit has) into a matedit material.")
    p.add_argument("file", metavar="FILE.mtlx")
    p.add_argument("-o", "--output", required=True, metavar="OUT.json")
    p.set_defaults(run=run)


def run(args) -> int:
    import os

    from matedit.interop.mtlx_import import MtlxImportError, import_mtlx
    from matedit.io.atomic import atomic_write_text
    from matedit.io.document import dumps
    from matedit.io.inputs import OverwriteError, refuse_overwrite

    path = Path(args.file)
    out = Path(args.output)
    if out.suffix.lower() != ".json":
        raise UsageError(f"{out}: the output must be a .json file")
    if not out.parent.is_dir():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    try:
        refuse_overwrite([out], {Path(os.path.realpath(path)): "the MaterialX document"})
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    try:
        doc = import_mtlx(path, out)
    except MtlxImportError as exc:
        for m in exc.messages[1:]:
            report("error", m)
        raise UsageError(exc.messages[0]) from None
    inputs = {}
    from matedit.io.document import reference_fields

    for container, key in reference_fields(doc):
        inputs[Path(os.path.realpath(out.parent / container[key]))] = "an image the material reads"
    try:
        refuse_overwrite([out], inputs)
        atomic_write_text(out, dumps(doc))
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{out}: cannot write: {exc.strerror or exc}") from None
    if sys.stderr.isatty():
        print(f"imported {path} into {out}", file=sys.stderr)
    return 0
