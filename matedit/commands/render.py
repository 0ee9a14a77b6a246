"""`matedit render FILE -o OUT.png|OUT.exr [--size WxH] [--mesh ...] [--env PATH|studio]
[--ibl ...] [--exposure EV] [--lights default|none|RIG.json] [--samples N] [--view VIEW]`:
a headless, deterministic preview render. A .png is display-referred (exposure, ACES, sRGB); an .exr
holds the scene-referred linear radiance of the same frame, before exposure and display."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from matedit.cli_support import UsageError
from matedit.io.input_kinds import declare_inputs

# matedit.shading.views.VIEWS, spelled here so parsing the command line imports no numpy
# (tests/test_views.py checks the two agree)
VIEW_NAMES = ("lit", "base", "coat", "sheen", "subsurface", "transmission", "specular",
              "roughness", "normal", "coat-weight", "anisotropy", "thin-film")


def register(sub) -> None:
    p = sub.add_parser("render", help="render a material to a PNG, headless",
                       description="Render a material on a preview mesh under the default "
                       "light rig and an environment, headless (EGL), to a PNG.")
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", required=True, metavar="OUT.png|OUT.exr",
                   help=".png: display-referred 8-bit sRGB; .exr: scene-referred linear "
                   "radiance (RGBA float, A = 1), before exposure and the display transform")
    p.add_argument("--size", default="512x512", metavar="WxH")
    p.add_argument("--mesh", default=None,
                   help="sphere, cube, plane, cylinder (or builtin:sphere, ...) or an OBJ file "
                   "(./sphere for a file of that name) (default: the file's preview mesh, "
                   "else sphere)")
    p.add_argument("--env", default=None, metavar="PATH|studio|sky",
                   help="built-in environment (studio, sky, or builtin:studio, builtin:sky), "
                   "an HDR/EXR file, or a folder of six cube-face files (px nx py ny pz nz); "
                   "./studio is a file or folder of that name (default: studio)")
    p.add_argument("--ibl", default="splitsum", choices=["splitsum", "reference", "difference"],
                   help="split-sum approximation, converged importance-sampled reference, "
                   "or a heat map of their difference")
    p.add_argument("--exposure", type=_exposure, default=None, metavar="EV",
                   help="exposure in stops, -30 to 30 (default 0)")
    p.add_argument("--lights", default="default", metavar="default|none|RIG.json",
                   help="the built-in light rig, no analytic lights, or a light-rig file "
                   "(format matedit.lightrig)")
    p.add_argument("--samples", type=int, default=None, metavar="N",
                   help="reference-mode samples a pixel (default 2048)")
    p.add_argument("--view", default="lit", choices=VIEW_NAMES, metavar="VIEW",
                   help="what the mesh shows: lit (default), a lobe view (base, coat, sheen, "
                   "subsurface, transmission, specular) or an attribute view (roughness, "
                   "normal, coat-weight, anisotropy, thin-film); see docs/cli.md")
    p.add_argument("--half", action="store_true", help="EXR output as half floats")
    p.add_argument("--energy-compensation", action="store_true",
                   help="multiple-scattering specular compensation (Fdez-Aguera 2019), beyond "
                   "the talk; a material can also ask for it (preview "
                   "\"energy_compensation\": true)")
    declare_inputs(p, file="document", mesh="mesh", env="environment", lights="rig")
    p.set_defaults(run=run)


def _exposure(text: str) -> float:
    """--exposure EV: a finite number of stops within the stated range (settings.py)."""
    import argparse

    from matedit.render.settings import exposure_problem

    try:
        ev = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    why = exposure_problem(ev)
    if why:
        raise argparse.ArgumentTypeError(why)
    return ev


def _size(text: str) -> tuple[int, int]:
    m = re.fullmatch(r"(\d+)x(\d+)", text.strip())
    if not m or not (1 <= int(m.group(1)) <= 16384 and 1 <= int(m.group(2)) <= 16384):
        raise UsageError(f"--size must be WxH with 1..16384, e.g. 512x512, got {text!r}")
    return int(m.group(1)), int(m.group(2))


def write_png(path: Path, rgb) -> None:
    import numpy as np
    import OpenImageIO as oiio

    from matedit.io.images import ImageError, write_oiio

    h, w, _ = rgb.shape
    pixels = np.clip(np.rint(rgb * 255.0), 0, 255).astype(np.uint8)
    try:
        write_oiio(path, oiio.ImageSpec(w, h, 3, "uint8"), pixels)
    except ImageError as exc:
        raise UsageError(str(exc)) from None


def gl_size_limit(ctx) -> int:
    """The largest width or height this GL implementation can render to."""
    info = ctx.info
    dims = info.get("GL_MAX_VIEWPORT_DIMS", (16384, 16384))
    return int(min(info.get("GL_MAX_RENDERBUFFER_SIZE", 16384),
                   info.get("GL_MAX_TEXTURE_SIZE", 16384), *dims))


def _renderer(ctx, size: tuple[int, int], cls):
    """A renderer of `size`, or a UsageError that names the limit (queried from GL)."""
    import moderngl

    limit = gl_size_limit(ctx)
    if max(size) > limit:
        raise UsageError(f"--size {size[0]}x{size[1]}: this GL implementation renders at most "
                         f"{limit}x{limit} (GL_MAX_RENDERBUFFER_SIZE)")
    samples = max(1, min(4, int(ctx.info.get("GL_MAX_SAMPLES", 4))))
    try:
        return cls(ctx, size, samples=samples, environment=None)
    except moderngl.Error:
        pass  # too large multisampled: one sample a pixel may still fit
    try:
        return cls(ctx, size, samples=1, environment=None)
    except moderngl.Error as exc:
        raise UsageError(f"--size {size[0]}x{size[1]}: this GL implementation cannot allocate "
                         f"float colour and depth targets of this size with {samples} or 1 "
                         f"samples ("
                         f"{' '.join(str(exc).split())[:80]}); try a smaller size") from None


def write_exr(path: Path, rgb, half: bool = False) -> None:
    """Scene-referred linear radiance as RGBA (A = 1: the frame is opaque)."""
    import numpy as np

    from matedit.io.images import ImageError, write_image

    rgba = np.concatenate([rgb, np.ones(rgb.shape[:2] + (1,), np.float32)], axis=2)
    try:
        write_image(path, rgba, half=half)
    except ImageError as exc:
        raise UsageError(str(exc)) from None


def _lights(spec: str):
    """None for the default rig (the renderer's own), [] for none, else the rig file's."""
    if spec == "default":
        return None
    if spec == "none":
        return []
    from matedit.io.rig import RigError, load

    try:
        return load(spec)
    except RigError as exc:
        raise UsageError(str(exc)) from None


def _check_texture_spaces(compiled, path: Path) -> None:
    from matedit.shading.colorspace import ColorSpaceError, check_space, effective_space

    for t in compiled.ir.textures:
        try:
            check_space(effective_space(t.color_space, t.srgb))
        except ColorSpaceError as exc:
            raise UsageError(f"{path}: node {t.node}: field color_space: {exc}") from None


def run(args) -> int:
    from matedit.compiler import CompileError, compile_document
    from matedit.io.document import FileResolver, FormatError
    from matedit.io.inputs import OverwriteError, command_inputs, preview_spec, refuse_overwrite

    size = _size(args.size)
    path = Path(args.file)
    out = Path(args.output)
    if out.suffix.lower() not in (".png", ".exr"):
        raise UsageError(f"{out}: the output must be a .png or .exr file")
    if args.samples is not None and not 1 <= args.samples <= 1 << 20:
        raise UsageError(f"--samples must be 1..{1 << 20}, got {args.samples}")
    lights = _lights(args.lights)
    if not out.parent.exists():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    from matedit.io.instance import InstanceError, load_effective

    try:
        doc, notes = load_effective(path)  # a material, or an instance's effective material
    except (FormatError, InstanceError) as exc:
        raise UsageError(str(exc)) from None
    for note in notes:
        print(f"warning: {note.format()}", file=sys.stderr)
    if doc.is_function:
        raise UsageError(f"{path}: is a material function; render a material that uses it")
    resolver = FileResolver()
    try:
        refuse_overwrite([out], command_inputs(args, [doc], resolver))
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    try:
        compiled = compile_document(doc, resolver, "glsl330")
    except CompileError as exc:
        d = exc.diagnostics[0]
        raise UsageError(f"{d.file or path}: {d.format()}") from None
    _check_texture_spaces(compiled, path)

    from matedit.ibl import EnvironmentMapError
    from matedit.render import MeshError, Renderer
    from matedit.render.context import headless_context

    ctx = headless_context()
    env = args.env or preview_spec(doc, "environment", "studio")
    mesh = args.mesh or preview_spec(doc, "mesh", "sphere")
    tty = sys.stderr.isatty()
    try:
        renderer = _renderer(ctx, size, Renderer)
        try:
            renderer.set_mesh(mesh)
        except MeshError as exc:
            raise UsageError(str(exc)) from None
        try:
            renderer.set_environment(env, progress=(lambda f: print(
                f"\rbaking environment {f * 100:5.1f}%", end="", file=sys.stderr))
                if tty else None)
        except (EnvironmentMapError, ValueError) as exc:
            raise UsageError(f"{env}: {exc}" if str(env) not in str(exc) else str(exc)) \
                from None
        if tty:
            print(file=sys.stderr)
        renderer.set_view(args.view)  # before the material: one link, of the view's variant
        status = renderer.set_material(compiled)
        if not status.ok:
            node, msg = status.errors[0]
            raise UsageError(f"{path}: node {node}: GLSL: {msg}" if node else f"{path}: {msg}")
        if args.exposure is not None:
            renderer.exposure = args.exposure
        if lights is not None:
            renderer.set_lights(lights)
        if args.energy_compensation:
            renderer.set_energy_compensation(True)
        if args.samples is not None:
            renderer.set_reference_samples(args.samples)
        renderer.mode = args.ibl
        frames = 0
        while True:
            renderer.render()
            frames += 1
            if tty and renderer.mode != "splitsum":
                print(f"\raccumulating reference {frames}/{renderer.reference_frames}", end="",
                      file=sys.stderr)
            if not renderer.needs_redraw:
                break
        if tty and renderer.mode != "splitsum":
            print(file=sys.stderr)
        if out.suffix.lower() == ".exr":
            write_exr(out, renderer.read_linear(), half=args.half)
        else:
            write_png(out, renderer.read_image())
        if renderer.mode == "difference":
            print(f"mean |split-sum - reference| (linear HDR): {renderer.difference_mean:.5f}")
        renderer.release()
    finally:
        ctx.release()
    return 0
