"""Draw a MaterialX nodegraph output with MaterialX's own GLSL generator on the bake plane
(matedit.interop.bake): the UV square at z = 0, normal +Z, tangent +X, bitangent +Y, camera at
bake.CAMERA, one pixel per texel centre. Images the document reads are bound as float
textures of their stored values (codes / 255 for 8-bit; row 0 = v = 0, MaterialX's
convention); MaterialX's colour management decodes them in its shader, from each file's
colorspace to lin_rec709."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from matedit.interop import bake
from matedit.io.images import read_image

# MaterialX's GLSL renderer (MaterialXRenderGlsl's texture handler) reads an image's
# address modes and filter type as sampler state: these GL values.
GL_WRAP = {"periodic": 0x2901, "clamp": 0x812F, "mirror": 0x8370, "constant": 0x812D}


def sampler_state(ctx, tex, node) -> None:
    """Bind `tex`'s sampler as MaterialX's renderer does for `node`: its address modes (the
    default colour as the border of constant addressing) and filter type (cubic and linear:
    GL_LINEAR, closest: GL_NEAREST); the node's definition's defaults where it sets none."""
    import ctypes

    from tests.gpu_eval import _libgl

    def text(name: str, default: str) -> str:
        inp = node.getInput(name)
        return (inp.getValueString().strip() if inp is not None else "") or default

    f = ctx.NEAREST if text("filtertype", "linear") == "closest" else ctx.LINEAR
    tex.filter = (f, f)
    gl = _libgl()
    gl.glTexParameteri(0x0DE1, 0x2802, GL_WRAP[text("uaddressmode", "periodic")])
    gl.glTexParameteri(0x0DE1, 0x2803, GL_WRAP[text("vaddressmode", "periodic")])
    border = [float(x) for x in text("default", "0,0,0").split(",")]
    border = (border * 4 if len(border) == 1 else border + [0.0] * 4)[:4]
    gl.glTexParameterfv(0x0DE1, 0x1004, (ctypes.c_float * 4)(*border))


class MtlxDrawer:
    def __init__(self, ctx, size: int) -> None:
        import MaterialX as mx
        from MaterialX import PyMaterialXGenGlsl as mx_glsl
        from MaterialX import PyMaterialXGenShader as mx_gen

        self.mx, self.mx_gen, self.ctx, self.size = mx, mx_gen, ctx, size
        self.library = mx.createDocument()
        search = mx.getDefaultDataSearchPath()
        mx.loadLibraries(mx.getDefaultDataLibraryFolders(), search, self.library)
        self.generator = mx_glsl.GlslShaderGenerator.create()
        # MaterialX's own colour management: images are decoded from their file's
        # colorspace to the document's (lin_rec709) in the generated shader
        cms = mx_gen.DefaultColorManagementSystem.create(self.generator.getTarget())
        cms.loadLibrary(self.library)
        self.generator.setColorManagementSystem(cms)
        self.context = mx_gen.GenContext(self.generator)
        self.context.getOptions().targetColorSpaceOverride = "lin_rec709"
        self.context.registerSourceCodeSearchPath(search)
        quad = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], "f4")
        n = len(quad)
        self.buffers = {
            "i_position": (np.hstack([quad, np.zeros((n, 1), "f4")]), "3f"),
            "i_normal": (np.tile(np.array([0, 0, 1], "f4"), (n, 1)), "3f"),
            "i_tangent": (np.tile(np.array([1, 0, 0], "f4"), (n, 1)), "3f"),
            "i_bitangent": (np.tile(np.array([0, 1, 0], "f4"), (n, 1)), "3f"),
            "i_texcoord_0": (quad, "2f"),
        }
        self.gl_buffers = {k: (ctx.buffer(np.ascontiguousarray(a).tobytes()), f)
                           for k, (a, f) in self.buffers.items()}
        self.indices = ctx.buffer(np.array([0, 1, 2, 1, 3, 2], "u4").tobytes())
        self.target = ctx.texture((size, size), 4, dtype="f4")
        self.fbo = ctx.framebuffer([self.target])

    def generate(self, element) -> tuple[str, str]:
        shader = self.generator.generate(element.getName(), element, self.context)
        return (shader.getSourceCode(self.mx_gen.VERTEX_STAGE),
                shader.getSourceCode(self.mx_gen.PIXEL_STAGE))

    def draw(self, doc, element, folder: Path) -> np.ndarray:
        """(size, size, 4) float32, row 0 = v = 0."""
        ctx = self.ctx
        vert, frag = self.generate(element)
        prog = ctx.program(vertex_shader=vert, fragment_shader=frag)
        vp = np.array([[2, 0, 0, -1], [0, 2, 0, -1], [0, 0, 0, 0], [0, 0, 0, 1]], "f4")

        def mat(m):
            return np.ascontiguousarray(m.T, dtype="f4").tobytes()

        for name, value in (("u_viewProjectionMatrix", mat(vp)),
                            ("u_worldMatrix", mat(np.eye(4))),
                            ("u_worldInverseTransposeMatrix", mat(np.eye(4)))):
            if name in prog:
                prog[name].write(value)
        if "u_viewPosition" in prog:
            prog["u_viewPosition"].value = bake.CAMERA
        textures = []
        graph = element.getParent()
        # every node reading a file (image, and the nodes made of one: tiledimage,
        # gltf_image...; MaterialX names the sampler after the node)
        readers = [n for n in graph.getNodes() if n.getInput("file") is not None]
        for unit, img in enumerate(readers):
            name = f"{img.getName()}_file"
            if name not in prog:
                continue
            px = read_image(folder / img.getInputValue("file")).pixels[::-1]
            if px.shape[2] == 1:
                px = np.repeat(px, 3, axis=2)
            if px.shape[2] == 3:
                px = np.concatenate([px, np.ones(px.shape[:2] + (1,), "f4")], 2)
            tex = ctx.texture((px.shape[1], px.shape[0]), 4,
                              np.ascontiguousarray(px, "f4").tobytes(), dtype="f4")
            tex.use(unit)
            sampler_state(ctx, tex, img)
            prog[name].value = unit
            textures.append(tex)
        vao = ctx.vertex_array(prog, [(buf, fmt, name) for name, (buf, fmt)
                                      in self.gl_buffers.items() if name in prog],
                               self.indices)
        previous = ctx.fbo
        self.fbo.use()
        ctx.clear(0, 0, 0, 0)
        vao.render()
        out = np.frombuffer(self.fbo.read(components=4, dtype="f4"), "f4")
        (previous or ctx.detect_framebuffer(0)).use()  # never leave a released one bound
        for r in [vao, prog, *textures]:
            r.release()
        return out.reshape(self.size, self.size, 4).copy()

    def release(self) -> None:
        for buf, _ in self.gl_buffers.values():
            buf.release()
        for r in (self.indices, self.fbo, self.target):
            r.release()
