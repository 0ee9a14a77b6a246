"""`matedit contact-sheet [FILE|DIR ...] -o OUT.png [--size N] [--columns N] [--mesh M]`:
every material rendered side by side and labelled, one PNG (the shipped samples by default).

Each tile is what `matedit render` draws for that file (its preview mesh, the studio
environment unless it names another, split-sum IBL), rendered in one GL context. A preview
mesh or environment that cannot be loaded is an error naming the material and the field.
Tiles of at least LABEL_MIN_SIZE pixels carry the material's name; smaller ones do not.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from matedit.cli_support import UsageError, one_line
from matedit.io.input_kinds import declare_inputs

MIN_SIZE = 16
LABEL_BAND = 26  # pixels: the band under a tile that holds its name
LABEL_MIN_SIZE = 64  # below this the band would hide most of the tile


def register(sub) -> None:
    p = sub.add_parser("contact-sheet", help="render every material side by side to a PNG",
                       description="Render materials (default: the shipped samples) to one "
                       "labelled PNG, a tile each.")
    p.add_argument("files", nargs="*", metavar="FILE|DIR")
    p.add_argument("-o", "--output", required=True, metavar="OUT.png")
    p.add_argument("--size", type=int, default=256, metavar="N", help="tile size in pixels")
    p.add_argument("--columns", type=int, default=4, metavar="N")
    p.add_argument("--mesh", default=None, help="override every file's preview mesh")
    declare_inputs(p, files="documents", mesh="mesh")
    p.set_defaults(run=run)


def materials(files: list[str]) -> list[Path]:
    from matedit.resources import graphs_dir

    if not files:
        return sorted((graphs_dir() / "materials").glob("*.json"))
    out: list[Path] = []
    for f in files:
        p = Path(f)
        if p.is_dir():
            out.extend(sorted(p.glob("*.json")))
        elif p.is_file():
            out.append(p)
        else:
            raise UsageError(f"{p}: no such file or folder")
    if not out:
        raise UsageError("no material files found")
    return out


def _label(tile, text: str):
    """The tile with `text` in a band along its bottom; tiles under LABEL_MIN_SIZE as they
    are."""
    import numpy as np
    import OpenImageIO as oiio

    h, w, _ = tile.shape
    if min(h, w) < LABEL_MIN_SIZE:
        return tile
    band_h = LABEL_BAND
    buf = oiio.ImageBuf(oiio.ImageSpec(w, band_h, 3, "float"))
    oiio.ImageBufAlgo.render_text(buf, 6, 19, text, 15, "", (0.92, 0.92, 0.92))
    band = np.asarray(buf.get_pixels(oiio.FLOAT)).reshape(band_h, w, 3)
    out = tile.copy()
    out[h - band_h:] = np.maximum(out[h - band_h:] * 0.35, band)
    return out


def _preview(doc, path: Path, key: str, override: str | None, fallback: str) -> tuple[str, str]:
    """(what to load, the field it came from) for the tile's mesh or environment; a file
    named by the document is relative to it, as `matedit render` reads it."""
    from matedit.io.inputs import preview_file

    if override:
        return override, f"--{'mesh' if key == 'mesh' else 'env'}"
    found = preview_file(doc, key)
    if found is not None:
        return str(found), f"{path}: preview.{key}"
    value = doc.preview.get(key) if isinstance(doc.preview, dict) else None
    return (value if isinstance(value, str) and value else fallback), f"{path}: preview.{key}"


def run(args) -> int:
    import numpy as np

    from matedit.commands.render import write_png
    from matedit.compiler import CompileError, compile_document
    from matedit.io.document import FileResolver, FormatError, load
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite

    out = Path(args.output)
    if out.suffix.lower() != ".png":
        raise UsageError(f"{out}: the output must be a .png file")
    if not out.parent.exists():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    if not MIN_SIZE <= args.size <= 2048:
        raise UsageError(f"--size must be {MIN_SIZE}..2048, got {args.size}")
    if args.columns < 1:
        raise UsageError(f"--columns must be at least 1, got {args.columns}")
    paths = materials(args.files)
    loaded = []
    for path in paths:
        try:
            loaded.append((path, load(path)))
        except FormatError as exc:
            raise UsageError(str(exc)) from None
    try:  # every sheet file, and every texture, function, mesh and environment they read
        refuse_overwrite([out], command_inputs(args, [d for _, d in loaded], FileResolver()))
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    docs = []
    for path, doc in loaded:
        if doc.is_function:
            continue
        try:
            docs.append((path, doc, compile_document(doc, FileResolver(), "glsl330")))
        except CompileError as exc:
            d = exc.diagnostics[0]
            raise UsageError(f"{d.file or path}: {d.format()}") from None

    from matedit.ibl import EnvironmentMapError
    from matedit.render import MeshError, Renderer
    from matedit.render.context import headless_context

    n = args.size
    cols = min(args.columns, max(len(docs), 1))
    rows = max(math.ceil(len(docs) / cols), 1)
    sheet = np.full((rows * n, cols * n, 3), 0.06)
    ctx = headless_context()
    try:
        renderer = Renderer(ctx, (n, n), environment=None)
        env = None
        for i, (path, doc, compiled) in enumerate(docs):
            want, field = _preview(doc, path, "environment", None, "studio")
            if want != env:
                try:
                    renderer.set_environment(want)
                except (EnvironmentMapError, ValueError, OSError) as exc:
                    raise UsageError(f"{field}: {exc}") from None
                env = want
            mesh, field = _preview(doc, path, "mesh", args.mesh, "sphere")
            try:
                renderer.set_mesh(mesh)
            except (MeshError, OSError) as exc:
                raise UsageError(f"{field}: {exc}") from None
            # the cube's corners reach further than the sphere: step back so it fits a tile
            renderer.camera.reset()
            renderer.camera.distance *= 1.25 if mesh == "cube" else 1.0
            status = renderer.set_material(compiled)
            if not status.ok:
                node, msg = status.errors[0]
                raise UsageError(f"{path}: node {node}: GLSL: {msg}")
            renderer.render()
            tile = _label(np.asarray(renderer.read_image(), dtype=np.float64),
                          doc.name or path.stem)
            r, c = divmod(i, cols)
            sheet[r * n:(r + 1) * n, c * n:(c + 1) * n] = tile
            if sys.stderr is not None and sys.stderr.isatty():  # progress only on a terminal
                print(f"{i + 1}/{len(docs)} {one_line(path.name)}", file=sys.stderr)
        renderer.release()
    finally:
        ctx.release()
    write_png(out, sheet)
    return 0
