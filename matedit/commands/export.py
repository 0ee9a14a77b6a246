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
(matedit.commands.export_check)."""

from __future__ import annotations

import sys
from pathlib import Path

from matedit.cli_support import UsageError, report
from matedit.commands import export_check
from matedit.commands.bake import compile_error, load_material, parse_size, progress_printer
from matedit.io.inputs import declare_inputs


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
    kind = out.suffix.lower()
    if kind not in (".gltf", ".glb", ".mtlx", ".usda", ".usdz"):
        raise UsageError(f"{out}: the output must end in .gltf, .glb, .mtlx, .usda or .usdz")
    if not out.parent.is_dir():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    export_check.validate(args, out)
    if args.arkit and kind != ".usdz":
        raise UsageError("--arkit applies to .usdz exports only")
    if kind == ".mtlx":
        if args.mesh:
            raise UsageError("--mesh applies to glTF and USD exports only")
        if args.zip and args.check:
            raise UsageError("--check reads back the .mtlx it wrote; with --zip there is "
                             "none: export without --zip to check it")
        return _mtlx(args, out)
    for flag, given in (("--surface", args.surface != "open_pbr_surface"),
                        ("--format", args.format != "png"), ("--zip", args.zip)):
        if given:
            raise UsageError(f"{flag} applies to MaterialX (.mtlx) exports only")
    if kind in (".usda", ".usdz"):
        return _usd(args, out)
    return _gltf(args, out)


def _gltf(args, out: Path) -> int:
    import numpy as np

    from matedit.compiler import CompileError
    from matedit.interop import gltf
    from matedit.interop.bake import bake_for_export, is_plane_spec, maps_from
    from matedit.interop.export import stem_of
    from matedit.io.document import FileResolver
    from matedit.io.inputs import OverwriteError, command_inputs, preview_spec, refuse_overwrite
    from matedit.render.context import headless
    from matedit.render.mesh import MeshError, mesh_from_spec

    size = parse_size(args.size or "1024")
    path = Path(args.file)
    doc = load_material(path)
    resolver = FileResolver()
    mesh_spec = args.mesh or preview_spec(doc, "mesh", "sphere")
    inputs = command_inputs(args, [doc], resolver)
    outputs = [out] + ([out.with_suffix(".bin")] if out.suffix.lower() == ".gltf" else [])
    outputs += export_check.outputs(args)
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
                progress_printer("baking"))
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
        report("note", f"{path}: {note}")
    if sys.stderr.isatty():
        print(f"exported {path} to {', '.join(str(p) for p in files)}", file=sys.stderr)
    export_check.after_write(args, path, doc, out, str(mesh_spec))
    return 0


def _mtlx(args, out: Path) -> int:
    from matedit.compiler import CompileError
    from matedit.interop import mtlx_export
    from matedit.io.document import FileResolver
    from matedit.io.images import ImageError
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite

    size = parse_size(args.size or "512")
    path = Path(args.file)
    doc = load_material(path)
    resolver = FileResolver()
    inputs = command_inputs(args, [doc], resolver)
    try:
        result = mtlx_export.export(doc, resolver, out, size, args.surface, args.format,
                                    args.zip)
        refuse_overwrite([*result.files, *export_check.outputs(args)], inputs)
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
        report("note", f"{path}: node {node}: baked to an image ({why})")
    for line in result.notes:
        report("note", f"{path}: {line}")
    export_check.after_write(args, path, doc, out)
    return 0


def _usd(args, out: Path) -> int:
    """USD: the preview mesh bound to a Material with a UsdPreviewSurface network on the
    baked maps and the MaterialX export as a network in the mtlx render context."""
    from matedit.compiler import CompileError
    from matedit.interop import usd
    from matedit.interop.bake import bake_for_export, is_plane_spec
    from matedit.io.document import FileResolver
    from matedit.io.inputs import OverwriteError, command_inputs, preview_spec, refuse_overwrite
    from matedit.render.context import headless
    from matedit.render.mesh import MeshError, mesh_from_spec

    size = parse_size(args.size or "1024")
    path = Path(args.file)
    doc = load_material(path)
    resolver = FileResolver()
    mesh_spec = args.mesh or preview_spec(doc, "mesh", "sphere")
    inputs = command_inputs(args, [doc], resolver)
    try:
        refuse_overwrite([out, *export_check.outputs(args)], inputs)
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
                progress_printer("baking"))
        result = usd.export_baked(doc, resolver, attrs, ir, mesh, out, size, args.arkit)
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
        report("note", f"{path}: {note}")
    if sys.stderr.isatty():
        print(f"exported {path} to {', '.join(str(p) for p in result.files)}", file=sys.stderr)
    export_check.after_write(args, path, doc, out, str(mesh_spec))
    return 0
