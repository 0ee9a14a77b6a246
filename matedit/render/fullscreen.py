"""What the renderer's parts share: programs built from `shaders/render/`, the full-screen
triangle that every screen pass draws, and the GL-side packing of matrices and uniforms."""

from __future__ import annotations

import moderngl
import numpy as np

from matedit.glsl.include import assemble

GLSL_VERSION = "330 core"  # of every program built from shaders/render/


def read_shader(name: str) -> str:
    from matedit.resources import shaders_dir

    return (shaders_dir() / "render" / name).read_text()


def render_program(ctx: moderngl.Context, vert: str, frag: str, prelude: str = "",
                   roots=None, vertex_prelude: bool = True) -> moderngl.Program:
    """Links two files of `shaders/render/` (their includes resolved against `roots`, default
    the shaders folder), `prelude` (#define and #extension lines only) ahead of the fragment
    shader and, with `vertex_prelude`, of the vertex shader."""
    v = assemble(read_shader(vert), GLSL_VERSION, [], "<vertex>", roots,
                 prelude if vertex_prelude else "")
    f = assemble(read_shader(frag), GLSL_VERSION, [], "<fragment>", roots, prelude)
    return ctx.program(vertex_shader=v.text, fragment_shader=f.text)


def set_uniform(prog: moderngl.Program, name: str, value) -> None:
    """Sets a uniform the program has (the compiler drops unused ones)."""
    if name in prog:
        prog[name].value = value


def mat_bytes(m: np.ndarray) -> bytes:
    return np.ascontiguousarray(m.T, dtype="f4").tobytes()  # GLSL is column-major


class FullscreenQuad:
    """One triangle covering the screen (shaders/render/fullscreen.vert), a vertex array per
    program drawn with it."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self._buffer = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], dtype="f4").tobytes())
        self._vaos: dict[int, moderngl.VertexArray] = {}

    def draw(self, prog: moderngl.Program) -> None:
        vao = self._vaos.get(prog.glo)
        if vao is None:
            vao = self._vaos[prog.glo] = self.ctx.vertex_array(
                prog, [(self._buffer, "2f", "a_pos")])
        vao.render(vertices=3)

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()
        self._buffer.release()
