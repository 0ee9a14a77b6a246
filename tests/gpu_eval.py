"""Evaluate GLSL expressions on the GPU over numpy arrays, element by element.

Each named input array becomes an RGBA32F texture; a full-screen triangle runs a fragment
shader in which every input is a local variable read with ``texelFetch`` at the pixel,
then your statements or expression, whose values land in RGBA32F render targets that come
back as numpy arrays. One element per pixel, so thousands of elements are one draw.

    from tests.gpu_eval import gpu_eval
    d = gpu_eval(ctx, "D_GGX(NoH, a)", {"NoH": noh, "a": a}, includes=["brdf.glsl"])

Inputs: ``(n,)`` arrays are ``float``, ``(n, k)`` with k = 2, 3, 4 are ``vecK``; or a pair
``(array, "int")`` / ``(array, "uint")`` for integer values (stored exactly up to 2^24).
Several results: ``gpu_eval_many(ctx, body, inputs, outputs={"x": "vec3", ...})`` where
``body`` assigns each output variable (up to 8). Uniform blocks, textures and plain
uniforms can be bound by name for code that reads them. The shader is GLSL 330 core,
assembled with ``matedit.glsl.include`` so errors name the library file and line.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from collections.abc import Mapping

import numpy as np

from matedit.glsl.include import assemble

_TYPES = {1: "float", 2: "vec2", 3: "vec3", 4: "vec4"}
_SWIZZLE = {"float": "x", "vec2": "xy", "vec3": "xyz", "vec4": "xyzw", "int": "x", "uint": "x"}
_WIDTH = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4}
_VERTEX = """#version 330 core
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1)) - 1.0;
    gl_Position = vec4(p, 0.0, 1.0);
}
"""


class GpuEvalError(RuntimeError):
    """The generated shader did not compile or link; the message is the mapped driver log."""


def _normalise_input(value) -> tuple[np.ndarray, str]:
    if isinstance(value, tuple):
        arr, kind = value
        arr = np.asarray(arr)
        if kind not in ("int", "uint"):
            raise ValueError(f"unknown input kind {kind!r}")
        if np.any(np.abs(arr) >= 2**24):
            raise ValueError("integer inputs must be below 2^24 to pass through float32")
        return arr.astype(np.float32).reshape(len(arr), 1), kind
    arr = np.asarray(value, dtype=np.float32)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[1] not in _TYPES:
        raise ValueError(f"input of shape {arr.shape}: expected (n,) or (n, 2|3|4)")
    return arr, _TYPES[arr.shape[1]]


def _grid(n: int, max_width: int = 256) -> tuple[int, int]:
    width = min(n, max_width)
    return width, -(-n // width)


def gpu_eval_many(
    ctx,
    body: str,
    inputs: Mapping[str, object],
    outputs: Mapping[str, str],
    includes: list[str] | None = None,
    preamble: str = "",
    uniform_blocks: Mapping[str, bytes] | None = None,
    textures: Mapping[str, object] | None = None,
    uniforms: Mapping[str, object] | None = None,
    defines: tuple[str, ...] = (),
) -> dict[str, np.ndarray]:
    """Run `body` once per element; returns each output as float32 (n,) or (n, k).
    `defines` are `#define NAME 1` lines placed before the includes (feature switches).

    `body` sees every input as a local of its type and assigns every output variable.
    `includes` are library files (``shaders/`` names); `preamble` is extra GLSL placed
    after them (helper functions). Textures and uniforms the program optimised away are
    skipped silently; the i-th uniform block is bound to binding point i.
    """
    prepared = {name: _normalise_input(v) for name, v in inputs.items()}
    sizes = {len(a) for a, _ in prepared.values()}
    if len(sizes) != 1:
        raise ValueError(f"inputs differ in length: {sorted(sizes)}")
    n = sizes.pop()
    if not 1 <= len(outputs) <= 8:
        raise ValueError("between 1 and 8 outputs")
    width, height = _grid(n)

    decl = [f"uniform sampler2D _in_{name};" for name in prepared]
    decl += [f"layout(location = {i}) out vec4 _out_{name};" for i, name in enumerate(outputs)]
    reads = []
    for name, (_, kind) in prepared.items():
        fetch = f"texelFetch(_in_{name}, _p, 0).{_SWIZZLE[kind]}"
        reads.append(f"    {kind} {name} = {kind}({fetch});")
    locals_ = [f"    {t} {name};" for name, t in outputs.items()]
    writes = []
    for name, t in outputs.items():
        pad = ", ".join(["0.0"] * (4 - _WIDTH[t]))
        writes.append(f"    _out_{name} = vec4({name}{', ' + pad if pad else ''});")
    main = "\n".join(
        [*decl, preamble, "void main() {", "    ivec2 _p = ivec2(gl_FragCoord.xy);", *reads,
         *locals_, "    {", body, "    }", *writes, "}"]
    )  # fmt: skip
    asm = assemble(main, version="330 core", includes=includes or [], name="<gpu_eval>",
                   prelude="\n".join(f"#define {d} 1" for d in defines))
    try:
        prog = ctx.program(vertex_shader=_VERTEX, fragment_shader=asm.text)
    except Exception as exc:
        raise GpuEvalError(asm.map_log(str(exc))) from exc

    resources = []
    previous_fbo = ctx.fbo
    try:
        unit = 0
        for name, (arr, _) in prepared.items():
            data = np.zeros((width * height, 4), dtype=np.float32)
            data[:n, : arr.shape[1]] = arr
            tex = ctx.texture((width, height), 4, data.tobytes(), dtype="f4")
            tex.filter = (ctx.NEAREST, ctx.NEAREST)
            resources.append(tex)
            tex.use(location=unit)
            member = prog.get(f"_in_{name}", None)  # unused inputs are optimised away
            if member is not None:
                member.value = unit
            unit += 1
        for name, tex in (textures or {}).items():
            tex.use(location=unit)
            member = prog.get(name, None)
            if member is not None:
                member.value = unit
            unit += 1
        for binding, (name, data) in enumerate((uniform_blocks or {}).items()):
            buf = ctx.buffer(data)
            resources.append(buf)
            buf.bind_to_uniform_block(binding)
            member = prog.get(name, None)
            if member is not None:
                member.binding = binding
        for name, value in (uniforms or {}).items():
            member = prog.get(name, None)
            if member is not None:
                member.value = value
        targets = [ctx.texture((width, height), 4, dtype="f4") for _ in outputs]
        resources += targets
        fbo = ctx.framebuffer(color_attachments=targets)
        vao = ctx.vertex_array(prog, [])
        resources += [fbo, vao]
        fbo.use()
        fbo.viewport = (0, 0, width, height)
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        result = {}
        for i, (name, t) in enumerate(outputs.items()):
            raw = np.frombuffer(fbo.read(components=4, dtype="f4", attachment=i), np.float32)
            vals = raw.reshape(-1, 4)[:n, : _WIDTH[t]].copy()
            result[name] = vals[:, 0] if t == "float" else vals
        return result
    finally:
        # Rebind what was bound: moderngl re-binds the "current" framebuffer when it builds
        # the next one, and binding a deleted framebuffer is GL_INVALID_OPERATION.
        (previous_fbo or ctx.detect_framebuffer(0)).use()
        for r in resources:
            r.release()
        prog.release()


def gpu_eval(
    ctx,
    expr: str,
    inputs: Mapping[str, object],
    out_type: str = "float",
    **kwargs,
) -> np.ndarray:
    """Evaluate one GLSL expression of type `out_type` per element (see gpu_eval_many)."""
    return gpu_eval_many(ctx, f"result = {expr};", inputs, {"result": out_type}, **kwargs)["result"]


def write_cube_level(tex, face: int, level: int, data: np.ndarray) -> None:
    """Write one face (0..5: +X, -X, +Y, -Y, +Z, -Z) of one mip level of a float RGB/RGBA
    cubemap. moderngl only writes level 0 of a cubemap; this calls glTexSubImage2D
    through the system libOpenGL (GLVND), which dispatches to the current context."""
    gl = _libgl()
    data = np.ascontiguousarray(data, dtype=np.float32)
    size = max(tex.size[0] >> level, 1)
    fmt = {3: 0x1907, 4: 0x1908}[tex.components]  # GL_RGB, GL_RGBA
    if data.size != size * size * tex.components:
        raise ValueError(f"level {level} needs {size}x{size}x{tex.components} floats")
    tex.use(location=0)
    gl.glPixelStorei(0x0CF5, 1)  # GL_UNPACK_ALIGNMENT
    gl.glTexSubImage2D(0x8515 + face, level, 0, 0, size, size, fmt, 0x1406,  # GL_FLOAT
                       data.ctypes.data_as(ctypes.c_void_p))  # fmt: skip


def constant_cubemap(ctx, colors_per_mip) -> object:
    """An RGB32F cubemap whose mip m is the constant colours_per_mip[m] on every face,
    trilinear filtering: textureLod then blends known constants (tests of lod selection)."""
    levels = len(colors_per_mip)
    size = 2 ** (levels - 1)
    tex = ctx.texture_cube((size, size), 3, dtype="f4")
    tex.build_mipmaps(0, levels - 1)
    for m, c in enumerate(colors_per_mip):
        s = max(size >> m, 1)
        texels = np.tile(np.asarray(c, np.float32), s * s)
        for face in range(6):
            write_cube_level(tex, face, m, texels)
    tex.filter = (ctx.LINEAR_MIPMAP_LINEAR, ctx.LINEAR)
    return tex


_GL = None


def _libgl():
    global _GL
    if _GL is None:
        name = ctypes.util.find_library("OpenGL") or ctypes.util.find_library("GL")
        if name is None:
            raise RuntimeError("no libOpenGL / libGL to write cubemap mip levels")
        _GL = ctypes.CDLL(name)
    return _GL
