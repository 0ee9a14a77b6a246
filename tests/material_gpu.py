"""Render a compiled material's attributes as a full-screen pass into float targets.

The vertex stage here replaces the mesh one: every varying is an affine function
of the screen position, so its value at a pixel centre is known exactly and the
CPU evaluator can be fed the same surface.
"""

from __future__ import annotations

import struct

import numpy as np

from matedit.compiler.cpu_nodes import SurfaceArrays
from matedit.compiler.targets import FRAME_BINDING, MATERIAL_BINDING

VERTEX = """#version 330 core
layout(location = 0) in vec2 a_pos;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
uniform vec4 uvRect;
void main() {
    vec2 t = a_pos * 0.5 + 0.5;
    v_uv = uvRect.xy + t * uvRect.zw;
    v_position = vec3(t * 2.0 - 1.0, 0.5 * t.x);
    v_normal = vec3(0.3 * (t.x - 0.5), 0.2 * (t.y - 0.5), 1.0);
    v_tangent = vec4(1.0, 0.0, 0.0, 1.0);
    gl_Position = vec4(a_pos, 0.0, 1.0);
}
"""
CAMERA = (0.2, -0.1, 3.0)
UV_RECT = (-0.25, -0.25, 1.5, 1.5)  # beyond [0, 1] to exercise wrapping and tiling


def surface(w: int, h: int, time: float = 1.25) -> SurfaceArrays:
    ti, tj = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    t = np.stack([ti.ravel(), tj.ravel()], axis=1)  # row 0 of the image first (GL's bottom)
    uv = np.array(UV_RECT[:2]) + t * np.array(UV_RECT[2:])
    pos = np.stack([t[:, 0] * 2 - 1, t[:, 1] * 2 - 1, 0.5 * t[:, 0]], axis=1)
    nrm = np.stack([0.3 * (t[:, 0] - 0.5), 0.2 * (t[:, 1] - 0.5), np.ones(len(t))], axis=1)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    view = np.array(CAMERA) - pos
    view /= np.linalg.norm(view, axis=1, keepdims=True)
    return SurfaceArrays(uv, pos, nrm, view, time, grid=(h, w))  # the footprint: this image


def render_attributes(ctx, compiled, w: int = 64, h: int = 64, uniforms=None,
                      time: float = 1.25) -> dict[str, np.ndarray]:
    prog = ctx.program(vertex_shader=VERTEX, fragment_shader=compiled.fragment_text)
    try:
        if "uvRect" in prog:
            prog["uvRect"].value = UV_RECT
        frame = np.zeros(56, dtype=np.float32)  # 3 mat4 + 2 vec4
        frame[48:51] = CAMERA
        frame[52] = time
        frame_buf = ctx.buffer(frame.tobytes())
        frame_buf.bind_to_uniform_block(FRAME_BINDING)
        if "FrameBlock" in prog:
            prog["FrameBlock"].binding = FRAME_BINDING
        bufs = [frame_buf]
        if "MaterialParams" in prog:
            params = ctx.buffer(compiled.pack_uniforms(uniforms))
            params.bind_to_uniform_block(MATERIAL_BINDING)
            prog["MaterialParams"].binding = MATERIAL_BINDING
            bufs.append(params)
        targets = [ctx.texture((w, h), 4, dtype="f4") for _ in range(4)]
        fbo = ctx.framebuffer(color_attachments=targets)
        quad = ctx.buffer(struct.pack("8f", -1, -1, 1, -1, -1, 1, 1, 1))
        vao = ctx.vertex_array(prog, [(quad, "2f", "a_pos")])
        previous = ctx.fbo
        fbo.use()
        vao.render(mode=ctx.TRIANGLE_STRIP)
        out = [np.frombuffer(fbo.read(components=4, attachment=i, dtype="f4"), np.float32)
               .reshape(h * w, 4) for i in range(4)]
        (previous or ctx.detect_framebuffer(0)).use()  # never leave a released one bound
        for r in [vao, fbo, quad, *targets, *bufs]:
            r.release()
    finally:
        prog.release()
    return {
        "baseColor": out[0][:, :3], "metallic": out[0][:, 3],
        "normal": out[1][:, :3], "roughness": out[1][:, 3],
        "emissive": out[2][:, :3], "cavity": out[2][:, 3],
        "opacity": out[3][:, 0],
    }
