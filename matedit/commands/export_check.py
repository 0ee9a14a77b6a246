"""`matedit export ... --check [--check-image OUT.png] [--check-size N]`: a measured loss
report of an export.

After the export is written, what was written is read back into a matedit material by the
format's re-import function (`REIMPORTERS`, by output suffix):
  .mtlx        the MaterialX importer (matedit.interop.mtlx_import, as `matedit import`);
  .gltf/.glb   the asset's metallic-roughness material on its own baked maps: the images are
               taken out of the file and read by graphs/interop/gltf_metallic_roughness.json
               (base colour and alpha, metallic-roughness and occlusion, normal, emissive, and
               the material's factors; KHR_materials_* lobe extensions are not read back, so
               their loss shows in the figure).
  .usda/.usdz  the UsdPreviewSurface network on its own maps (matedit.interop.usd_readback:
               the same template, its clearcoat and ior constants as lobe fields; the
               MaterialX network and a separate opacity map are not read back).
The original and the round trip are rendered alike (`matedit render`'s defaults: the studio
environment, the default light rig, split-sum, exposure 0; the export's mesh for glTF and USD, the
sphere for MaterialX; N x N pixels) and compared per pixel with CIEDE2000 on the display
images (matedit.shading.color_difference) over the pixels the mesh covers; the command
prints `note: FILE: round trip: mean ΔE X max ΔE Y (CIEDE2000 on the display image)`.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from matedit.cli_support import UsageError

if TYPE_CHECKING:  # numpy is imported where an export is checked, not for every command
    import numpy as np

DEFAULT_SIZE = 256
COVER_THRESHOLD = 0.05  # display difference that marks a pixel as the mesh's (see `coverage`)


def register(p) -> None:
    """The options, on the export command's parser."""
    p.add_argument("--check", action="store_true",
                   help="after writing, read the export back and render original and round "
                   "trip alike; print their CIEDE2000 difference (mean, max) as a note")
    p.add_argument("--check-image", default=None, metavar="OUT.png",
                   help="with --check: also write original | round trip | ΔE (white = 10) "
                   "side by side")
    p.add_argument("--check-size", default=None, metavar="N",
                   help=f"with --check: the renders' size in pixels (default {DEFAULT_SIZE})")


def validate(args, out: Path) -> None:
    """Refuse bad --check options before anything is written."""
    if (args.check_image or args.check_size) and not args.check:
        raise UsageError("--check-image and --check-size need --check")
    if args.check_size is not None:
        parse_render_size(args.check_size)
    if args.check_image:
        img = Path(args.check_image)
        if img.suffix.lower() != ".png":
            raise UsageError(f"{img}: --check-image must be a .png file")
        if not img.parent.is_dir():
            raise UsageError(f"{img}: folder {img.parent} does not exist")
        if img.resolve() == out.resolve():
            raise UsageError(f"{img}: --check-image must not be the export's output")


def outputs(args) -> list[Path]:
    """The files --check writes (its image), for the export's refuse_overwrite."""
    return [Path(args.check_image)] if getattr(args, "check_image", None) else []


def parse_render_size(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise UsageError(f"--check-size must be a whole number of pixels, got {text!r}") \
            from None
    if not 16 <= n <= 4096:
        raise UsageError(f"--check-size must be 16..4096, got {n}")
    return n


# ---- re-import, one function a format: (written file, work folder) -> (document, notes) --

def reimport_mtlx(out: Path, work: Path):
    from matedit.interop.mtlx_import import MtlxImportError, import_mtlx

    warnings: list[str] = []
    target = out.parent / f"{out.stem}.roundtrip.json"  # never written: resolves relative paths
    try:
        doc = import_mtlx(out, target, warnings=warnings)
    except MtlxImportError as exc:
        raise UsageError(f"{out}: --check: cannot read the export back: "
                         f"{exc.messages[0]}") from None
    doc.path = target
    return doc, [f"round trip import: {w}" for w in warnings]


def reimport_gltf_maps(out: Path, work: Path):
    """The glTF asset's first material on its own maps (matedit.interop.gltf_readback)."""
    from matedit.interop.gltf_readback import GltfReadbackError, read_material

    try:
        return read_material(out, work)
    except GltfReadbackError as exc:
        raise UsageError(f"--check: cannot read the export back: {exc}") from None


def reimport_usd_preview(out: Path, work: Path):
    """The USD asset's UsdPreviewSurface on its own maps (matedit.interop.usd_readback)."""
    from matedit.interop.usd_readback import UsdReadbackError, read_material

    try:
        return read_material(out, work)
    except UsdReadbackError as exc:
        raise UsageError(f"--check: cannot read the export back: {exc}") from None


REIMPORTERS: dict[str, Callable] = {
    ".mtlx": reimport_mtlx,
    ".gltf": reimport_gltf_maps,
    ".glb": reimport_gltf_maps,
    ".usda": reimport_usd_preview,
    ".usdz": reimport_usd_preview,
}


# ---- rendering and the figure ----------------------------------------------------------

@dataclass
class RoundTrip:
    mean: float
    max: float
    original: np.ndarray  # (n, n, 3) display sRGB
    round_trip: np.ndarray
    delta_e: np.ndarray  # (n, n), 0 off the mesh
    notes: list[str]

    def line(self) -> str:
        return (f"round trip: mean ΔE {self.mean:.2f} max ΔE {self.max:.2f} "
                "(CIEDE2000 on the display image)")

    def side_by_side(self) -> np.ndarray:
        import numpy as np

        heat = np.repeat(np.clip(self.delta_e / 10.0, 0.0, 1.0)[..., None], 3, axis=2)
        return np.concatenate([self.original, self.round_trip, heat], axis=1)


def render_display(docs, resolver, size: int, mesh: str) -> list[np.ndarray]:
    """Display images (size x size, sRGB in [0, 1]) of each document, all under one
    renderer: `matedit render`'s defaults (studio, default rig, split-sum, exposure 0)."""
    import numpy as np

    from matedit.commands.render import _renderer
    from matedit.compiler import CompileError, compile_document
    from matedit.render import MeshError, Renderer
    from matedit.render.context import headless_context

    ctx = headless_context()
    images = []
    try:
        renderer = _renderer(ctx, (size, size), Renderer)
        try:
            renderer.set_mesh(mesh)
        except (MeshError, OSError) as exc:
            raise UsageError(f"--check: {mesh}: {exc}") from None
        renderer.set_environment("studio")
        for doc in docs:
            try:
                compiled = compile_document(doc, resolver, "glsl330")
            except CompileError as exc:
                raise UsageError(f"--check: the round trip does not compile: "
                                 f"{exc.diagnostics[0].format()}") from None
            status = renderer.set_material(compiled)
            if not status.ok:
                raise UsageError(f"--check: GLSL: {status.errors[0][1]}")
            while True:
                renderer.render()
                if not renderer.needs_redraw:
                    break
            images.append(np.asarray(renderer.read_image(), np.float64)[..., :3])
        renderer.release()
    finally:
        ctx.release()
    return images


def _probes():
    """Two versions of the glTF template, dark and glowing: where their renders differ is the
    mesh (its silhouette on the environment)."""
    from matedit.interop import gltf_readback
    from matedit.io.document import load
    from matedit.resources import graphs_dir

    out = []
    for glow in (0.0, 40.0):
        d = load(graphs_dir().joinpath(*gltf_readback.TEMPLATE))
        for n in d.graph.nodes.values():
            name = n.settings.get("name")
            if name == "base_color_factor":
                n.values["value"] = [0.0, 0.0, 0.0]
            elif name == "emissive_factor":
                n.values["value"] = [1.0, 1.0, 1.0]
            elif name == "emissive_strength":
                n.values["value"] = glow
        out.append(d)
    return out


def measure(original, round_trip, resolver, size: int, mesh: str) -> RoundTrip:
    """Render both (and the two coverage probes) and compare (module notes)."""
    import numpy as np

    from matedit.shading.color_difference import image_difference

    a, b, dark, glow = render_display([original, round_trip, *_probes()], resolver, size, mesh)
    covered = np.abs(glow - dark).max(axis=-1) > COVER_THRESHOLD
    de = np.where(covered, image_difference(a, b), 0.0)
    if not covered.any():
        raise UsageError(f"--check: the mesh {mesh} covers no pixel of the render")
    return RoundTrip(float(de[covered].mean()), float(de[covered].max()), a, b, de, [])


def after_write(options, doc, out: Path, say: Callable[[str], None],
                mesh: str | None = None) -> RoundTrip | None:
    """The export of `doc` was written to `out`: with `options.check` (--check), measure the
    round trip, give its notes and figure to `say` (the command prints them as `note:`
    lines) and write --check-image; return it (None without --check)."""
    if not getattr(options, "check", False):
        return None
    from matedit.io.document import FileResolver

    resolver = FileResolver()
    image = Path(options.check_image) if options.check_image else None
    size = parse_render_size(options.check_size) if options.check_size else DEFAULT_SIZE
    with tempfile.TemporaryDirectory(prefix="matedit-check-") as tmp:
        back, notes = REIMPORTERS[out.suffix.lower()](out, Path(tmp))
        rt = measure(doc, back, resolver, size, mesh or "sphere")
    rt.notes = list(notes)
    for note in notes:
        say(note)
    say(rt.line())
    if image is not None:
        from matedit.commands.render import write_png

        write_png(image, rt.side_by_side())
    return rt
