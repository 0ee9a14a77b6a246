"""`matedit bake FILE -o DIR [--size N] [--format png|exr]`: the material's attributes baked
over UV space into DIR/STEM_base_color, _normal, _orm and, where written, _emissive and
_opacity (see matedit.interop.bake for the encodings)."""

from __future__ import annotations

import sys
from pathlib import Path

from matedit.cli_support import UsageError, report
from matedit.io.input_kinds import declare_inputs

MAX_SIZE = 8192


def register(sub) -> None:
    p = sub.add_parser("bake", help="bake a material's attributes to texture maps",
                       description="Bake base colour (sRGB), tangent-space normal (+Y up), "
                       "ORM (occlusion from cavity, roughness, metallic) and, where the "
                       "material writes them, emissive and opacity maps over UV space.")
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--size", type=str, default="1024", metavar="N",
                   help=f"map width and height in texels, 1..{MAX_SIZE} (default 1024)")
    p.add_argument("--format", default="png", choices=["png", "exr"],
                   help="8-bit PNG or float EXR (default png)")
    declare_inputs(p, file="document")
    p.set_defaults(run=run)


def parse_size(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if not 1 <= n <= MAX_SIZE:
        raise UsageError(f"--size must be a whole number in 1..{MAX_SIZE}, got {text!r}")
    return n


def load_material(path: Path):
    """The material `path` holds, or the effective material of the instance it holds (named
    after the instance: its file's stem and its name), as compile and render read them; an
    instance's warnings are `warning:` lines."""
    from matedit.io.document import FormatError
    from matedit.io.instance import InstanceError, load_effective

    try:
        doc, notes = load_effective(path)
    except (FormatError, InstanceError) as exc:
        raise UsageError(str(exc)) from None
    for note in notes:
        report("warning", note.format())
    if doc.is_function:
        raise UsageError(f"{path}: is a material function; use a material that calls it")
    return doc


def progress_printer(label: str):
    if not sys.stderr.isatty():
        return None
    return lambda f: print(f"\r{label} {f * 100:5.1f}%", end="" if f < 1 else "\n",
                           file=sys.stderr)


def compile_error(exc, path: Path) -> UsageError:
    d = exc.diagnostics[0] if exc.diagnostics else None
    return UsageError(f"{d.file or path}: {d.format()}" if d else f"{path}: {exc}")


def run(args) -> int:
    from matedit.io.document import FileResolver
    from matedit.io.inputs import command_inputs

    size = parse_size(args.size)
    path = Path(args.file)
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise UsageError(f"{out}: exists and is not a folder")
    doc = load_material(path)
    resolver = FileResolver()
    inputs = command_inputs(args, [doc], resolver)
    paths = bake_to_folder(doc, resolver, path, out, size, args.format, inputs,
                           progress_printer("baking"))
    if sys.stderr.isatty():
        print(f"baked {', '.join(p.name for p in paths)} into {out}", file=sys.stderr)
    return 0


def bake_to_folder(doc, resolver, path: Path, out: Path, size: int, fmt: str, inputs: dict,
                   progress=None) -> list[Path]:
    """Bake the material `doc` (read from `path`) into the folder `out` as STEM_*.`fmt`
    (every map, or none), never over one of `inputs`; the files written. Raises UsageError
    (one line) for anything that stops it; makes its own headless GL context. The editor's
    File › Export Baked Textures runs this too."""
    from matedit.compiler import CompileError
    from matedit.interop.bake import MAP_NAMES, bake_document, map_paths, write_maps
    from matedit.interop.export import stem_of
    from matedit.io.images import ImageError
    from matedit.io.inputs import OverwriteError, refuse_overwrite
    from matedit.render.context import headless

    if out.exists() and not out.is_dir():
        raise UsageError(f"{out}: exists and is not a folder")
    stem = stem_of(doc)
    try:
        refuse_overwrite(map_paths(out, stem, MAP_NAMES, fmt).values(), inputs)
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    try:
        with headless() as ctx:
            maps, _ = bake_document(ctx, doc, resolver, size, progress, fmt)
    except CompileError as exc:
        raise compile_error(exc, path) from None
    try:
        paths = write_maps(out, stem, maps, fmt)  # every map, or none
    except ImageError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{out}: cannot write: {exc.strerror or exc}") from None
    return list(paths.values())
