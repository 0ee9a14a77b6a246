"""Baking a material's attributes into texture maps over UV space.

The bake surface is the UV unit square laid flat: texel (i, j) of an N x N map sits at
uv = ((i + 0.5) / N, (j + 0.5) / N), world position (u, v, 0) metres, geometric normal +Z,
viewed straight on from far above (camera at (0.5, 0.5, 1000)), time 0. Nodes that read
the position, normal or view direction bake what they give on that plane.

The GPU pass is the compiler's ATTRIBUTES mode (matedit.compiler.emit) drawn over that
square on a headless context; `attributes_cpu` is the same surface on the CPU evaluator,
the reference the tests hold the GPU bake to.

Maps (arrays are row 0 = v = 0; files are written top row first, v = 1 at the top, as the
renderer reads them):
  base_color  RGB, sRGB-encoded in 8-bit formats (linear in EXR)
  normal      tangent-space normal * 0.5 + 0.5, +Y up (OpenGL and glTF convention)
  orm         R cavity (as occlusion), G roughness, B metallic (glTF's packing)
  emissive    RGB linear HDR in EXR; sRGB, clamped to [0, 1], in 8-bit formats
  opacity     one channel
emissive and opacity only where the graph writes them (`MaterialIR.attributes`) and they are
not the default everywhere (no emission, fully opaque): a layer that sets every field does
not produce an all-black emissive map.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from matedit.compiler.cpu_nodes import SurfaceArrays

CAMERA = (0.5, 0.5, 1000.0)
MAP_NAMES = ("base_color", "normal", "orm", "emissive", "opacity")
FORMATS = ("png", "exr")
TILE = 512


def surface(size: int, rows: tuple[int, int] | None = None) -> SurfaceArrays:
    """The bake surface at the texel centres of an size x size map (rows j0..j1)."""
    j0, j1 = rows or (0, size)
    u, v = np.meshgrid((np.arange(size) + 0.5) / size, (np.arange(j0, j1) + 0.5) / size)
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    pos = np.concatenate([uv, np.zeros((len(uv), 1))], axis=1)
    nrm = np.tile([0.0, 0.0, 1.0], (len(uv), 1))
    view = np.asarray(CAMERA) - pos
    view /= np.linalg.norm(view, axis=1, keepdims=True)
    # the texel grid as the GPU's pixel grid, so screen derivatives (bump from height,
    # filtered patterns) are the same 2 x 2 quad differences on both
    return SurfaceArrays(uv, pos, nrm, view, 0.0, grid=(j1 - j0, size))


def load_textures(ir) -> dict[str, np.ndarray]:
    """The material's textures decoded to linear RGBA by their colour space, as the viewport
    and the CPU evaluator decode them (matedit.shading.colorspace: an sRGB 8-bit file through
    the sRGB transfer function, a linear one as stored, an OpenColorIO space converted), row
    0 = v = 0; the checker when a file is missing or unreadable. The GPU and CPU passes sample
    these same linear texels (bilinear, no mipmaps), so decoding happens before filtering,
    as in the viewport's sRGB textures."""
    from matedit.compiler.cpu_eval import checker_texture
    from matedit.shading.colorspace import effective_space, load_texture_cached

    out = {}
    for t in ir.textures:
        img = None
        if t.path:
            try:
                space = effective_space(getattr(t, "color_space", ""), t.srgb)
                img = np.ascontiguousarray(load_texture_cached(t.path, space).linear,
                                           dtype="f4")
            except (ValueError, OSError):  # ImageError and ColorSpaceError are ValueErrors
                img = None
        out[t.name] = img if img is not None else checker_texture(8)
    return out


def attributes_cpu(ir, size: int) -> dict[str, np.ndarray]:
    """The CPU evaluator's attributes on the bake surface, each (size, size, k) float64."""
    from matedit.compiler.cpu_eval import evaluate

    attrs = evaluate(ir, surface(size), textures=load_textures(ir))
    return {k: np.asarray(v).reshape(size, size, -1) for k, v in attrs.items()}


_VERTEX = """#version 330 core
layout(location = 0) in vec2 a_pos;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
uniform vec4 uvRect;
void main() {
    vec2 t = a_pos * 0.5 + 0.5;
    v_uv = uvRect.xy + t * uvRect.zw;
    v_position = vec3(v_uv, 0.0);
    v_normal = vec3(0.0, 0.0, 1.0);
    v_tangent = vec4(1.0, 0.0, 0.0, 1.0);
    gl_Position = vec4(a_pos, 0.0, 1.0);
}
"""


def attributes_gpu(ctx, compiled, size: int, uniforms=None,
                   progress: Callable[[float], None] | None = None) -> dict[str, np.ndarray]:
    """Draw the ATTRIBUTES-mode shader of `compiled` (glsl330, mode="attributes") over the
    bake surface in tiles; returns each attribute as (size, size, k) float32."""
    import moderngl

    from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING

    out = np.zeros((4, size, size, 4), np.float32)
    prog = ctx.program(vertex_shader=_VERTEX, fragment_shader=compiled.fragment_text)
    res = []
    try:
        frame = np.zeros(56, dtype=np.float32)  # 3 mat4 + 2 vec4
        frame[48:51] = CAMERA
        frame_buf = ctx.buffer(frame.tobytes())
        res.append(frame_buf)
        frame_buf.bind_to_uniform_block(FRAME_BINDING)
        if "FrameBlock" in prog:
            prog["FrameBlock"].binding = FRAME_BINDING
        if "MaterialParams" in prog:
            params = ctx.buffer(compiled.pack_uniforms(uniforms))
            res.append(params)
            params.bind_to_uniform_block(MATERIAL_BINDING)
            prog["MaterialParams"].binding = MATERIAL_BINDING
        for i, (name, img) in enumerate(load_textures(compiled.ir).items()):
            tex = ctx.texture((img.shape[1], img.shape[0]), 4, img.tobytes(), dtype="f4")
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = True
            res.append(tex)
            unit = FIRST_TEXTURE_BINDING + i
            tex.use(unit)
            if name in prog:
                prog[name].value = unit
        tile = min(size, TILE)
        targets = [ctx.texture((tile, tile), 4, dtype="f4") for _ in range(4)]
        fbo = ctx.framebuffer(color_attachments=targets)
        quad = ctx.buffer(struct.pack("8f", -1, -1, 1, -1, -1, 1, 1, 1))
        vao = ctx.vertex_array(prog, [(quad, "2f", "a_pos")])
        res += [vao, fbo, quad, *targets]
        previous = ctx.fbo
        fbo.use()
        tiles = [(x, y) for y in range(0, size, tile) for x in range(0, size, tile)]
        for k, (x, y) in enumerate(tiles):
            w, h = min(tile, size - x), min(tile, size - y)
            fbo.viewport = (0, 0, w, h)
            if "uvRect" in prog:
                prog["uvRect"].value = (x / size, y / size, w / size, h / size)
            vao.render(mode=ctx.TRIANGLE_STRIP)
            for i in range(4):
                data = fbo.read(viewport=(0, 0, w, h), components=4, attachment=i, dtype="f4")
                out[i, y:y + h, x:x + w] = np.frombuffer(data, np.float32).reshape(h, w, 4)
            if progress:
                progress((k + 1) / len(tiles))
        (previous or ctx.detect_framebuffer(0)).use()
    finally:
        for r in reversed(res):
            r.release()
        prog.release()
    return {
        "baseColor": out[0, ..., :3], "metallic": out[0, ..., 3:4],
        "normal": out[1, ..., :3], "roughness": out[1, ..., 3:4],
        "emissive": out[2, ..., :3], "cavity": out[2, ..., 3:4],
        "opacity": out[3, ..., 0:1],
    }


def linear_to_srgb(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def srgb_to_linear(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, np.float64)
    return np.where(x <= 0.04045, x / 12.92, np.power((x + 0.055) / 1.055, 2.4))


@dataclass
class BakedMap:
    name: str  # one of MAP_NAMES
    pixels: np.ndarray  # (N, N, C) float, row 0 = v = 0, encoded as stored (sRGB or linear)
    srgb: bool


def maps_from(attrs: dict[str, np.ndarray], written, fmt: str = "png") -> list[BakedMap]:
    """The texture maps of baked attributes (see the module notes for the encodings)."""
    ldr = fmt != "exr"
    col = attrs["baseColor"].astype(np.float64)
    out = [BakedMap("base_color", linear_to_srgb(col) if ldr else col, ldr)]
    n = attrs["normal"].astype(np.float64)
    out.append(BakedMap("normal", np.clip(n * 0.5 + 0.5, 0.0, 1.0), False))
    orm = np.concatenate([attrs["cavity"], attrs["roughness"], attrs["metallic"]], axis=-1)
    out.append(BakedMap("orm", np.clip(orm.astype(np.float64), 0.0, 1.0), False))
    if "emissive" in written and np.any(attrs["emissive"] != 0.0):
        e = attrs["emissive"].astype(np.float64)
        out.append(BakedMap("emissive", linear_to_srgb(e) if ldr else np.maximum(e, 0.0), ldr))
    if "opacity" in written and np.any(attrs["opacity"] != 1.0):
        out.append(BakedMap("opacity", np.clip(attrs["opacity"].astype(np.float64), 0, 1),
                            False))
    return out


def encode_file(path: Path, m: BakedMap) -> None:
    """Write one map (8-bit PNG, or float EXR) through matedit.io.images."""
    import OpenImageIO as oiio

    from matedit.io.images import write_image, write_oiio

    pixels = np.ascontiguousarray(m.pixels[::-1])  # top row first: v = 1 at the top
    if path.suffix.lower() == ".exr":
        write_image(path, pixels)
        return
    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, "uint8")
    if c == 4:  # colour and alpha stored as given (glTF's base colour is not premultiplied)
        spec.attribute("oiio:UnassociatedAlpha", 1)
    if m.srgb:
        spec.attribute("oiio:ColorSpace", "sRGB")
    write_oiio(path, spec, np.clip(np.rint(pixels * 255.0), 0, 255).astype(np.uint8))


def map_paths(folder: Path, stem: str, names, fmt: str) -> dict[str, Path]:
    return {n: Path(folder) / f"{stem}_{n}.{fmt}" for n in names}


def write_maps(folder: Path, stem: str, maps: list[BakedMap], fmt: str) -> dict[str, Path]:
    """Write every map into `folder` (created), all of them or none (staged_outputs);
    returns map name -> path."""
    from matedit.io.atomic import staged_outputs

    paths = map_paths(folder, stem, [m.name for m in maps], fmt)
    with staged_outputs(folder) as stage:
        for m in maps:
            encode_file(stage.path(paths[m.name]), m)
    return paths


def bake_document(ctx, doc, resolver, size: int,
                  progress: Callable[[float], None] | None = None, fmt: str = "png"):
    """Compile `doc` in attribute mode and bake it on the GL context `ctx`.

    Returns (maps, ir). Raises CompileError for a bad graph."""
    attrs, ir = bake_attributes(ctx, doc, resolver, size, progress)
    return maps_from(attrs, ir.attributes, fmt), ir


def bake_attributes(ctx, doc, resolver, size: int,
                    progress: Callable[[float], None] | None = None):
    """(attributes (size, size, k) float32 from the GPU pass on `ctx`, the optimised IR).
    The caller owns the context (matedit.render.context.headless in the command line, one
    made on the worker thread in the editor)."""
    from matedit.compiler.api import compile_document, lower_and_optimise

    ir = lower_and_optimise(doc, resolver)
    compiled = compile_document(doc, resolver, "glsl330", mode="attributes", ir=ir)
    return attributes_gpu(ctx, compiled, size, progress=progress), ir
