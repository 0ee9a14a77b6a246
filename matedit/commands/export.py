"""`matedit export FILE -o OUT.gltf|OUT.glb|OUT.mtlx|OUT.usda|OUT.usdz [--size N] [--mesh ...]
[--check ...]`.

glTF 2.0: the preview mesh with tangents and a metallic-roughness material on maps baked
on that mesh in UV space (matedit.interop.bake.bake_for_export, matedit.interop.gltf).
MaterialX: a nodegraph reproducing the attribute graph feeding one open_pbr_surface,
standard_surface or gltf_pbr (matedit.interop.mtlx_export); subgraphs MaterialX cannot
express are baked to images in OUT_textures/ beside the document, with copies of the
textures the material reads, and reported (--zip: OUT.zip). USD: the preview mesh bound to
a Material with a UsdPreviewSurface network on the baked maps and the MaterialX export in
the mtlx render context (matedit.interop.usd; `--arkit`: Apple's usdz profile, the preview
network alone). `--check` measures the round trip's loss
(matedit.commands.export_check).

The editor's File › Export dialogs run the same functions (`validate`, `export_document`)
on the document in the editor."""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from matedit.cli_support import UsageError, report
from matedit.commands import export_check
from matedit.commands.bake import compile_error, load_material, parse_size, progress_printer
from matedit.io.input_kinds import declare_inputs

SUFFIXES = (".gltf", ".glb", ".mtlx", ".usda", ".usdz")
SURFACES = ("open_pbr_surface", "standard_surface", "gltf_pbr")
MAP_FORMATS = ("png", "exr")


def default_size(out: Path) -> int:
    """The bake size of an export to `out` when none is given: 512 for the MaterialX bakes,
    1024 for glTF and USD."""
    return 512 if out.suffix.lower() == ".mtlx" else 1024


@dataclass
class ExportOptions:
    """What `matedit export` takes besides FILE and -o, by its options' names (`--format`
    is `format`); the editor's Export dialog fills one in."""

    size: str | None = None  # None: default_size
    mesh: str | None = None
    surface: str = "open_pbr_surface"
    format: str = "png"
    zip: bool = False
    check: bool = False
    check_image: str | None = None
    check_size: str | None = None
    arkit: bool = False


@dataclass
class Exported:
    files: list[Path]  # what was written
    round_trip: export_check.RoundTrip | None = None  # with --check


Say = Callable[[str], None]  # takes each `note:` line's text (without "FILE: ") as it arises


def register(sub) -> None:
    p = sub.add_parser("export", help="export a material to glTF 2.0, MaterialX or USD",
                       description="Export a material as a glTF 2.0 asset (.gltf or .glb: "
                       "preview mesh, baked maps, metallic-roughness material) or as a "
                       "MaterialX document (.mtlx: nodegraph and a surface shader, with its baked "
                       "maps and texture copies in OUT_textures/) or as a USD asset (.usda with "
                       "its textures beside it, or a .usdz package: preview mesh, "
                       "UsdPreviewSurface on baked maps, MaterialX network).")
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", required=True,
                   metavar="OUT.gltf|OUT.glb|OUT.mtlx|OUT.usda|OUT.usdz")
    p.add_argument("--size", default=None, metavar="N",
                   help="baked map size in texels (default 1024 for glTF and USD, 512 for "
                   "the MaterialX bakes)")
    p.add_argument("--mesh", default=None,
                   help="glTF and USD only: sphere, cube, plane, cylinder (or builtin:sphere, "
                   "...) or an OBJ file (./sphere for a file of that name) (default: the file's "
                   "preview mesh, else sphere)")
    export_check.register(p)
    p.add_argument("--surface", default="open_pbr_surface",
                   choices=("open_pbr_surface", "standard_surface", "gltf_pbr"),
                   help="MaterialX only: the surface shader (default open_pbr_surface, "
                   "MaterialX 1.39's own)")
    p.add_argument("--format", default="png", choices=("png", "exr"),
                   help="MaterialX only: baked maps as 8-bit PNG (sRGB colour, linear "
                   "data; default) or float EXR")
    p.add_argument("--zip", action="store_true",
                   help="MaterialX only: pack OUT.mtlx and its side files into OUT.zip")
    p.add_argument("--arkit", action="store_true",
                   help=".usdz only: Apple's usdz profile (AR Quick Look): the "
                   "UsdPreviewSurface network on PNG maps, without the MaterialX network")
    declare_inputs(p, file="document", mesh="mesh")
    p.set_defaults(run=run)


def run(args) -> int:
    out = Path(args.output)
    options = ExportOptions(args.size, args.mesh, args.surface, args.format, args.zip,
                            args.check, args.check_image, args.check_size, args.arkit)
    validate(options, out)
    path = Path(args.file)
    doc = load_material(path)
    from matedit.io.document import FileResolver
    from matedit.io.inputs import command_inputs

    resolver = FileResolver()
    inputs = command_inputs(args, [doc], resolver)
    done = export_document(doc, resolver, path, out, options, inputs,
                           lambda text: report("note", f"{path}: {text}"),
                           progress_printer("baking"))
    if sys.stderr.isatty() and out.suffix.lower() != ".mtlx":
        print(f"exported {path} to {', '.join(str(p) for p in done.files)}", file=sys.stderr)
    return 0


def validate(options: ExportOptions, out: Path) -> None:
    """Refuse (UsageError) an output or an option the export to `out` cannot take, before
    anything is read or written."""
    kind = out.suffix.lower()
    if kind not in SUFFIXES:
        raise UsageError(f"{out}: the output must end in .gltf, .glb, .mtlx, .usda or .usdz")
    if not out.parent.is_dir():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    export_check.validate(options, out)
    if options.size is not None:
        parse_size(options.size)
    if options.arkit and kind != ".usdz":
        raise UsageError("--arkit applies to .usdz exports only")
    if kind == ".mtlx":
        if options.mesh:
            raise UsageError("--mesh applies to glTF and USD exports only")
        if options.zip and options.check:
            raise UsageError("--check reads back the .mtlx it wrote; with --zip there is "
                             "none: export without --zip to check it")
        return
    for flag, given in (("--surface", options.surface != "open_pbr_surface"),
                        ("--format", options.format != "png"), ("--zip", options.zip)):
        if given:
            raise UsageError(f"{flag} applies to MaterialX (.mtlx) exports only")


def export_document(doc, resolver, path: Path, out: Path, options: ExportOptions,
                    inputs: dict, say: Say, progress=None) -> Exported:
    """Export the material `doc` (read from `path`, or named so) to `out` with `options`
    (`validate`d): never over one of `inputs`; each note to `say`. Raises UsageError (one
    line, naming the file) for anything that stops it. Baking makes its own headless GL
    context (on the calling thread)."""
    kind = out.suffix.lower()
    size = parse_size(options.size) if options.size is not None else default_size(out)
    if kind == ".mtlx":
        files = _mtlx(doc, resolver, path, out, options, inputs, say, size)
        mesh = None
    elif kind in (".usda", ".usdz"):
        files = _usd(doc, resolver, path, out, options, inputs, say, size, progress)
        mesh = _mesh_spec(doc, options)
    else:
        files, mesh = _gltf(doc, resolver, path, out, options, inputs, say, size, progress)
    return Exported(files, export_check.after_write(options, doc, out, say, mesh))


def _mesh_spec(doc, options: ExportOptions) -> str:
    from matedit.io.inputs import preview_spec

    return options.mesh or preview_spec(doc, "mesh", "sphere")


def _gltf(doc, resolver, path: Path, out: Path, options: ExportOptions, inputs: dict,
          say: Say, size: int, progress) -> tuple[list[Path], str]:
    import numpy as np

    from matedit.compiler import CompileError
    from matedit.interop import gltf
    from matedit.interop.bake import bake_for_export, is_plane_spec, maps_from
    from matedit.interop.export import stem_of
    from matedit.io.inputs import OverwriteError, refuse_overwrite
    from matedit.render.context import headless
    from matedit.render.mesh import MeshError, mesh_from_spec

    mesh_spec = _mesh_spec(doc, options)
    outputs = [out] + ([out.with_suffix(".bin")] if out.suffix.lower() == ".gltf" else [])
    outputs += export_check.outputs(options)
    try:
        refuse_overwrite(outputs, inputs)
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    try:
        mesh = mesh_from_spec(mesh_spec)
    except MeshError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{mesh_spec}: cannot read mesh: {exc.strerror or exc}") from None
    try:
        with headless() as ctx:
            attrs, ir, bake_notes = bake_for_export(
                ctx, doc, resolver, size, None if is_plane_spec(mesh_spec) else mesh,
                progress)
    except CompileError as exc:
        raise compile_error(exc, path) from None
    emax = float(max(1.0, np.max(attrs["emissive"])))
    attrs["emissive"] = attrs["emissive"] / emax
    maps = maps_from(attrs, ir.attributes, "png")
    lobes = gltf.lobes_of(ir)
    files = gltf.files_for(out, maps, mesh, stem_of(doc), emax, lobes)
    try:
        gltf.write(files)
    except OSError as exc:
        raise UsageError(f"{out}: cannot write: {exc.strerror or exc}") from None
    for note in [*bake_notes, *lobes.notes]:
        say(note)
    return list(files), str(mesh_spec)


def _mtlx(doc, resolver, path: Path, out: Path, options: ExportOptions, inputs: dict,
          say: Say, size: int) -> list[Path]:
    from matedit.compiler import CompileError
    from matedit.interop import mtlx_export
    from matedit.io.images import ImageError
    from matedit.io.inputs import OverwriteError, refuse_overwrite

    try:
        result = mtlx_export.export(doc, resolver, out, size, options.surface, options.format,
                                    options.zip)
        refuse_overwrite([*result.files, *export_check.outputs(options)], inputs)
        mtlx_export.write(result)
    except CompileError as exc:
        raise compile_error(exc, path) from None
    except mtlx_export.MtlxExportError as exc:
        msg = str(exc)  # a node's problem is named in the document it belongs to
        raise UsageError(f"{path}: {msg}" if msg.startswith("node ") else msg) from None
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    except ImageError as exc:  # a baked image that could not be written
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{out}: cannot write: {exc.strerror or exc}") from None
    for node, why in result.baked:
        say(f"node {node}: baked to an image ({why})")
    for line in result.notes:
        say(line)
    return list(result.files)


def _usd(doc, resolver, path: Path, out: Path, options: ExportOptions, inputs: dict,
         say: Say, size: int, progress) -> list[Path]:
    """USD: the preview mesh bound to a Material with a UsdPreviewSurface network on the
    baked maps and the MaterialX export as a network in the mtlx render context."""
    from matedit.compiler import CompileError
    from matedit.interop import usd
    from matedit.interop.bake import bake_for_export, is_plane_spec
    from matedit.io.inputs import OverwriteError, refuse_overwrite
    from matedit.render.context import headless
    from matedit.render.mesh import MeshError, mesh_from_spec

    mesh_spec = _mesh_spec(doc, options)
    try:
        refuse_overwrite([out, *export_check.outputs(options)], inputs)
        mesh = mesh_from_spec(mesh_spec)
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    except MeshError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{mesh_spec}: cannot read mesh: {exc.strerror or exc}") from None
    try:
        with headless() as ctx:  # on the mesh, as the glTF export bakes
            attrs, ir, bake_notes = bake_for_export(
                ctx, doc, resolver, size, None if is_plane_spec(mesh_spec) else mesh,
                progress)
        result = usd.export_baked(doc, resolver, attrs, ir, mesh, out, size, options.arkit)
        refuse_overwrite(result.files, inputs)
        usd.write(result)
    except CompileError as exc:
        raise compile_error(exc, path) from None
    except usd.UsdExportError as exc:
        raise UsageError(f"{path}: {exc}") from None
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{exc.filename or out}: cannot write: {exc.strerror or exc}") from None
    for note in [*bake_notes, *result.notes]:
        say(note)
    return list(result.files)
