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

On a mesh (`bake_on_mesh`, the glTF export): the mesh's triangles are drawn in UV space, so
each texel the mesh covers gets the mesh's own interpolated world position, normal and
tangent there (the object's space is the world's: the asset has no transform), and looks that
depend on position, height or slope survive. The view is along the geometric normal at every
texel (MATEDIT_BAKE_VIEW_NORMAL), the plane bake's straight-on view carried to the mesh. The
maps are dilated `DILATE` texels past the covered texels so that filtering at UV seams does
not blend in the background. A mesh whose UVs overlap or leave the unit square has no one
surface point for some texels; it is baked on the plane (`mesh_bake_problem` says why).
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
DILATE = 4  # texels grown past the mesh's UV islands
VIEW_NORMAL_DEFINE = "MATEDIT_BAKE_VIEW_NORMAL"


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


_MESH_VERTEX = """#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_tangent;
layout(location = 3) in vec2 a_uv;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
uniform vec4 uvRect;
void main() {
    v_position = a_position;
    v_normal = a_normal;
    v_tangent = a_tangent;
    v_uv = a_uv;
    gl_Position = vec4((a_uv - uvRect.xy) / uvRect.zw * 2.0 - 1.0, 0.0, 1.0);
}
"""

_COUNT_FRAGMENT = """#version 330 core
out vec4 o;
void main() { o = vec4(1.0); }
"""


def _attrs_of(out: np.ndarray) -> dict[str, np.ndarray]:
    return {
        "baseColor": out[0, ..., :3], "metallic": out[0, ..., 3:4],
        "normal": out[1, ..., :3], "roughness": out[1, ..., 3:4],
        "emissive": out[2, ..., :3], "cavity": out[2, ..., 3:4],
        "opacity": out[3, ..., 0:1],
    }


def attributes_gpu(ctx, compiled, size: int, uniforms=None,
                   progress: Callable[[float], None] | None = None) -> dict[str, np.ndarray]:
    """Draw the ATTRIBUTES-mode shader of `compiled` (glsl330, mode="attributes") over the
    bake surface in tiles; returns each attribute as (size, size, k) float32."""
    return _attrs_of(_draw(ctx, compiled, size, uniforms, progress, None))


def mesh_bake_problem(mesh) -> str | None:
    """Why `mesh` cannot be baked on (its UVs leave the unit square or cover nothing), or
    None. Overlaps are found by `uv_overlap` on the GPU."""
    uv = np.asarray(mesh.uvs, np.float64)
    idx = np.asarray(mesh.indices).reshape(-1, 3)
    if len(idx) == 0:
        return "the mesh has no triangles"
    if uv.min() < -1e-6 or uv.max() > 1.0 + 1e-6:
        return "its UVs leave the unit square (the maps would repeat over it)"
    a, b, c = uv[idx[:, 0]], uv[idx[:, 1]], uv[idx[:, 2]]
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                        - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    if area.sum() < 1e-6:
        return "it has no UV layout (every triangle has zero area in UV space)"
    return None


def uv_overlap(ctx, mesh, size: int = 256) -> float:
    """The fraction of the texels a mesh covers in UV space (at size x size) that more than
    one triangle covers: additive counts into a float target."""
    prog = ctx.program(vertex_shader=_MESH_VERTEX, fragment_shader=_COUNT_FRAGMENT)
    target = ctx.texture((size, size), 1, dtype="f4")
    fbo = ctx.framebuffer(color_attachments=[target])
    res = _mesh_buffers(ctx, mesh, prog)
    vao = ctx.vertex_array(prog, res[:1], index_buffer=res[1])
    previous = ctx.fbo
    try:
        fbo.use()
        fbo.viewport = (0, 0, size, size)
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        if "uvRect" in prog:
            prog["uvRect"].value = (0.0, 0.0, 1.0, 1.0)
        ctx.enable(ctx.BLEND)
        ctx.blend_func = ctx.ONE, ctx.ONE
        vao.render()
        ctx.disable(ctx.BLEND)
        count = np.frombuffer(fbo.read(components=1, dtype="f4"), np.float32)
        (previous or ctx.detect_framebuffer(0)).use()
    finally:
        for r in (vao, fbo, target, res[0][0], res[1], prog):
            r.release()
    covered = np.count_nonzero(count > 0.5)
    return float(np.count_nonzero(count > 1.5) / covered) if covered else 0.0


def _mesh_buffers(ctx, mesh, prog) -> list:
    """[(vertex buffer, format, names...) of the attributes `prog` reads, index buffer]."""
    data = np.hstack([np.asarray(mesh.positions, "f4"), np.asarray(mesh.normals, "f4"),
                      np.asarray(mesh.tangents, "f4"), np.asarray(mesh.uvs, "f4")])
    vbo = ctx.buffer(np.ascontiguousarray(data, "f4").tobytes())
    ibo = ctx.buffer(np.ascontiguousarray(np.asarray(mesh.indices).reshape(-1), "u4").tobytes())
    fmt, names = [], []
    for name, n in (("a_position", 3), ("a_normal", 3), ("a_tangent", 4), ("a_uv", 2)):
        if name in prog:  # the compiler drops the inputs a program does not read
            fmt.append(f"{n}f")
            names.append(name)
        else:
            fmt.append(f"{4 * n}x")
    return [(vbo, " ".join(fmt), *names), ibo]


def attributes_on_mesh(ctx, compiled, size: int, mesh, uniforms=None,
                       progress: Callable[[float], None] | None = None,
                       dilate: int = DILATE) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The ATTRIBUTES-mode shader of `compiled` drawn over `mesh`'s triangles laid out in UV
    space, viewed along the normal (see the module notes); returns (attributes (size, size, k)
    float32, dilated `dilate` texels past the mesh, the (size, size) bool mask of the texels
    the mesh covers)."""
    compiled = compiled.variant("attributes", (VIEW_NORMAL_DEFINE,))
    out = _draw(ctx, compiled, size, uniforms, progress, mesh)
    covered = out[3, ..., 3] > 0.5
    out[3, ..., 3] = 1.0  # the last target's alpha was the coverage
    grown = dilate_into(out, covered, dilate)
    return _attrs_of(grown), covered


def dilate_into(out: np.ndarray, covered: np.ndarray, steps: int) -> np.ndarray:
    """`out` (..., H, W, C) with the texels outside `covered` filled, ring by ring for `steps`
    rings, by the mean of their already-filled 8 neighbours (no wrap); texels further away
    keep the mean of all covered texels, so nothing reads the cleared background."""
    out = out.copy()
    if not covered.any():
        return out
    filled = covered.copy()
    mean = out[..., covered, :].mean(axis=-2)
    for _ in range(steps):
        acc = np.zeros_like(out)
        cnt = np.zeros(filled.shape, np.float32)
        pad_v = np.pad(out * filled[..., None], [(0, 0)] * (out.ndim - 3) + [(1, 1), (1, 1),
                                                                               (0, 0)])
        pad_f = np.pad(filled.astype(np.float32), 1)
        h, w = filled.shape
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                if dy == 0 and dx == 0:
                    continue
                acc += pad_v[..., 1 + dy:1 + dy + h, 1 + dx:1 + dx + w, :]
                cnt += pad_f[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
        ring = ~filled & (cnt > 0)
        if not ring.any():
            break
        out[..., ring, :] = acc[..., ring, :] / cnt[ring][:, None]
        filled |= ring
    out[..., ~filled, :] = mean[..., None, :]
    return out


def _draw(ctx, compiled, size: int, uniforms, progress, mesh) -> np.ndarray:
    """(4, size, size, 4) float32: the four attribute targets over the plane (mesh None) or
    over `mesh` in UV space (alpha of the last target 1 where a triangle covers the texel)."""
    import moderngl

    from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING

    out = np.zeros((4, size, size, 4), np.float32)
    prog = ctx.program(vertex_shader=_VERTEX if mesh is None else _MESH_VERTEX,
                       fragment_shader=compiled.fragment_text)
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
        if mesh is None:
            quad = ctx.buffer(struct.pack("8f", -1, -1, 1, -1, -1, 1, 1, 1))
            vao = ctx.vertex_array(prog, [(quad, "2f", "a_pos")])
            res += [vao, fbo, quad, *targets]
        else:
            bufs = _mesh_buffers(ctx, mesh, prog)
            vao = ctx.vertex_array(prog, bufs[:1], index_buffer=bufs[1])
            res += [vao, fbo, bufs[0][0], bufs[1], *targets]
        previous = ctx.fbo
        fbo.use()
        tiles = [(x, y) for y in range(0, size, tile) for x in range(0, size, tile)]
        for k, (x, y) in enumerate(tiles):
            w, h = min(tile, size - x), min(tile, size - y)
            fbo.viewport = (0, 0, w, h)
            if "uvRect" in prog:
                prog["uvRect"].value = (x / size, y / size, w / size, h / size)
            if mesh is None:
                vao.render(mode=ctx.TRIANGLE_STRIP)
            else:
                fbo.clear(0.0, 0.0, 0.0, 0.0)
                vao.render()
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
    return out


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


OVERLAP_LIMIT = 0.005  # the share of covered texels two triangles may both claim


def is_plane_spec(spec) -> bool:
    """The built-in plane: the glTF export bakes it on the UV plane, as `matedit bake` does."""
    return str(spec) in ("plane", "builtin:plane")


def view_dependent_nodes(ir) -> list[str]:
    """The ids of the nodes left in the optimised IR (what reaches the output) whose code
    reads the view direction (their library file reads g_surface.view), in IR order."""
    from matedit.compiler import ops
    from matedit.graph import nodes
    from matedit.resources import shaders_dir

    found: list[str] = []
    for scope in [*ir.functions, ir.main]:
        for op in scope.ops:
            units = list(ops.implementation(op.kind).units)
            d = nodes.REGISTRY.get(op.kind)
            if d is not None and d.glsl:
                units.append(f"nodes/{op.kind}")  # a catalogue node's own library file
            for unit in units:
                if unit == "nodes/context":
                    continue
                f = shaders_dir() / f"{unit}.glsl"
                if f.is_file() and "g_surface.view" in f.read_text() and op.node not in found:
                    found.append(op.node)
    return found


def bake_for_export(ctx, doc, resolver, size: int, mesh=None,
                    progress: Callable[[float], None] | None = None):
    """(attributes, optimised IR, notes): baked on `mesh` (`attributes_on_mesh`) where it
    can be, else (mesh None, or UVs that overlap or leave the unit square) on the plane;
    `notes` says which where it matters, and how view-dependent nodes were baked."""
    from matedit.compiler.api import compile_document, lower_and_optimise

    ir = lower_and_optimise(doc, resolver)
    compiled = compile_document(doc, resolver, "glsl330", mode="attributes", ir=ir)
    notes: list[str] = []
    why = None
    if mesh is not None:
        why = mesh_bake_problem(mesh)
        if why is None:
            share = uv_overlap(ctx, mesh)
            if share > OVERLAP_LIMIT:
                why = f"its UVs overlap ({share:.0%} of the texels it covers)"
    view = view_dependent_nodes(ir)
    if mesh is None or why is not None:
        if why is not None:
            notes.append(f"baked over UV space on a plane, not on the mesh: {why}; looks "
                         "that depend on position or slope are those of the plane")
        if view:
            notes.append(f"node {', '.join(view)}: depends on the view; baked for a view "
                         "straight down on the plane")
        return attributes_gpu(ctx, compiled, size, progress=progress), ir, notes
    attrs, _ = attributes_on_mesh(ctx, compiled, size, mesh, progress=progress)
    if view:
        notes.append(f"node {', '.join(view)}: depends on the view; baked for a view along "
                     "the normal at every point")
    return attrs, ir, notes
