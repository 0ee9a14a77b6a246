"""`matedit import FILE.mtlx|FILE.gltf|FILE.glb -o OUT.json|DIR [--material NAME]`: MaterialX
or glTF 2.0 materials as matedit materials (the file's suffix chooses the reader).

`-o OUT.json` writes one material: the document's only one, or the one `--material` names.
`-o DIR` (any output not ending in .json; created if missing) writes every material, or the
one named, as DIR/NAME.json, NAME the material's name as a checked identifier
(matedit.interop.mtlx_import.output_paths); a DIR/NAME.json that exists already is an
`error:` naming it (exit 2, nothing written) unless `--overwrite` is given. A document with
several materials, written to OUT.json without `--material`, is an `error:` listing their
names (exit 2).

Every unsupported node or input is an `error:` line naming it (exit 2); nothing is written
then (with -o DIR: nothing at all, every material is read before the first file is written).
Nothing is dropped silently: every input, node or attribute the file sets that the import
does not represent exactly (dropped, approximated, clamped) is a `warning:` line naming the
file, material, node, input and value; `--strict` makes each an `error:` line instead (exit
2, nothing written).
No output may replace the MaterialX document or an image a material reads. See
matedit.interop.mtlx_import for what is read.

glTF (matedit.interop.gltf_import) follows the same rules; images the asset embeds (in a
.glb, a .bin or a data: URI) are written beside each material as STEM_imageN.png|jpg, with
it (all or nothing); under -o DIR an existing one is refused like DIR/NAME.json. No output
may replace the asset, a .bin it reads or an image it names."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from matedit.cli_support import UsageError, report
from matedit.io.input_kinds import declare_inputs


def register(sub) -> None:
    p = sub.add_parser("import", help="import MaterialX or glTF materials",
                       description="Convert a MaterialX document's materials (standard_surface,"
                       " open_pbr_surface, gltf_pbr or UsdPreviewSurface, with nodegraphs of "
                       "stdlib nodes matedit has), or a glTF 2.0 asset's materials (.gltf or "
                       ".glb: metallic-roughness and the KHR_materials_* lobes), into matedit "
                       "materials.")
    p.add_argument("file", metavar="FILE.mtlx|FILE.gltf|FILE.glb")
    p.add_argument("-o", "--output", required=True, metavar="OUT.json|DIR",
                   help="one material to OUT.json, or every material (or the one named) to "
                   "DIR/NAME.json")
    p.add_argument("--material", metavar="NAME",
                   help="the surfacematerial (or glTF material) to import (required for "
                   "OUT.json when the document holds several)")
    p.add_argument("--overwrite", action="store_true",
                   help="with -o DIR: replace DIR/NAME.json files that exist already "
                   "(without it they are an error and nothing is written)")
    p.add_argument("--strict", action="store_true",
                   help="treat every warning (an input, node or attribute not represented "
                   "exactly) as an error: exit 2 and write nothing")
    declare_inputs(p, file="mtlx")
    p.set_defaults(run=run)


def _fail(exc) -> UsageError:
    for m in exc.messages[1:]:
        report("error", m)
    return UsageError(exc.messages[0])


def refuse_existing(targets, overwrite: bool) -> None:
    """`import -o DIR` never replaces a material file silently: an existing DIR/NAME.json (or
    anything at that name, a link included) is refused unless --overwrite is given."""
    if overwrite:
        return
    for target in targets:
        if os.path.lexists(target):
            raise UsageError(f"{target}: exists already; pass --overwrite to replace it, or "
                             "import into another folder")


def _output(args, inputs) -> tuple[Path, bool]:
    """OUT and whether it is a folder, checked: a folder that is not one, a missing parent,
    or an input at OUT's name is an error."""
    from matedit.io.inputs import OverwriteError, refuse_overwrite

    out = Path(args.output)
    to_folder = out.suffix.lower() != ".json"
    if to_folder:
        if out.exists() and not out.is_dir():
            raise UsageError(f"{out}: exists and is not a folder (a single material's output "
                             "must end in .json)")
    elif not out.parent.is_dir():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    if not to_folder:
        try:
            refuse_overwrite([out], inputs)
        except OverwriteError as exc:
            raise UsageError(str(exc)) from None
    return out, to_folder


def _imported(args, path: Path, out: Path, to_folder: bool, import_all, import_one, error):
    """target -> what the format's importer made of `path` (every material into a folder,
    or the one asked for), its warnings reported; --strict makes them errors."""
    from matedit.interop.mtlx_import import output_paths

    warnings: list[str] = []
    try:
        if to_folder and args.material is None:
            made = import_all(path, out, warnings)
        else:
            target = out
            if to_folder:
                target = output_paths([args.material], out)[args.material]
            made = {target: import_one(path, target, args.material, warnings)}
    except error as exc:
        raise _fail(exc) from None
    if warnings and args.strict:
        raise _fail(error([f"{w} (--strict)" for w in warnings])) from None
    for w in warnings:
        report("warning", w)
    return made


def run(args) -> int:
    if Path(args.file).suffix.lower() in (".gltf", ".glb"):
        return run_gltf(args)
    from matedit.interop.mtlx_import import MtlxImportError, import_all, import_mtlx
    from matedit.io.atomic import atomic_write_text, staged_outputs
    from matedit.io.document import dumps
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite

    path = Path(args.file)
    out, to_folder = _output(args, command_inputs(args))
    docs = _imported(args, path, out, to_folder, import_all, import_mtlx, MtlxImportError)
    try:  # the MaterialX document, and every image an imported material reads
        refuse_overwrite(list(docs), command_inputs(args, written=docs.values()))
        if to_folder:  # every material, or none
            refuse_existing(docs, args.overwrite)
            with staged_outputs(out) as stage:
                for target, doc in docs.items():
                    stage.write_text(target, dumps(doc))
        else:
            for target, doc in docs.items():
                atomic_write_text(target, dumps(doc))
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{getattr(exc, 'filename', None) or out}: cannot write: "
                         f"{exc.strerror or exc}") from None
    if sys.stderr.isatty():
        print(f"imported {path} into {', '.join(str(p) for p in docs)}", file=sys.stderr)
    return 0


def run_gltf(args) -> int:
    """`import FILE.gltf|glb`: as the MaterialX import, with each material's embedded images
    written beside it."""
    from matedit.interop.gltf_import import GltfImportError, import_all, import_gltf
    from matedit.io.atomic import staged_outputs
    from matedit.io.document import dumps
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite

    path = Path(args.file)
    inputs = {p: ("the glTF asset" if w == "the MaterialX document" else w)
              for p, w in command_inputs(args).items()}
    out, to_folder = _output(args, inputs)
    results = _imported(args, path, out, to_folder, import_all, import_gltf, GltfImportError)
    files: dict[Path, bytes] = {}
    for target, result in results.items():
        files.update(result.images)
        files[target] = dumps(result.document).encode("utf-8")  # after its images
        for p in result.reads:
            inputs.setdefault(Path(os.path.realpath(p)), "a file the glTF asset reads")
    try:
        refuse_overwrite(list(files), inputs)
        if to_folder:
            refuse_existing(files, args.overwrite)
        with staged_outputs(out if to_folder else out.parent) as stage:  # all, or none
            for target, data in files.items():
                stage.write_bytes(target, data)
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{getattr(exc, 'filename', None) or out}: cannot write: "
                         f"{exc.strerror or exc}") from None
    if sys.stderr.isatty():
        print(f"imported {path} into {', '.join(str(p) for p in results)}", file=sys.stderr)
    return 0
