"""MaterialX's side of the structural-edit comparison: an equivalent material per sample,
generated to GLSL by MaterialXGenGlsl, linked and drawn on a moderngl context.

Run alone: MESA_SHADER_CACHE_DISABLE=true .venv/bin/python benchmarks/bench_materialx.py
(needs `pip install materialx`; benchmarks/run.sh installs it into .venv).

The equivalent of a sample is built from what the sample layers: one `standard_surface`
per layer (a layer stack's entries, and `function_call`s of files under graphs/layers/),
folded by `mix` nodes of surfaceshaders, each mask a `noise2d` on the texture coordinates
(the samples' masks are value noise, gradients and small functions of similar cost). A
sample with no layer is one `standard_surface`. A second variant ("inputs") mixes the layers'
base colour, metalness and roughness by the same masks into one `standard_surface`.
Specular IBL uses MaterialX's prefiltered environment method, the analogue of matedit's
split sum; no analytic lights are bound.
"""

from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")


@dataclass
class Equivalent:
    layers: int
    blends: int

    def describe(self, mode: str = "shaders") -> str:
        if self.layers == 1:
            return "1 standard_surface"
        if mode == "inputs":
            return f"1 standard_surface, inputs mixed over {self.layers} layers by noise2d"
        return (f"{self.layers} standard_surface, {self.blends} mix(surfaceshader) "
                f"by noise2d")


def equivalent_of(path: Path) -> Equivalent:
    """How many layers (and so blends) the sample file layers."""
    data = json.loads(Path(path).read_text())
    layers = 0
    for node in data.get("nodes", []):
        settings = node.get("settings") or {}
        if node.get("kind") == "layer_stack":
            layers += len(settings.get("layers", []))
        elif node.get("kind") == "function_call" and "/layers/" in settings.get("function", ""):
            layers += 1
    layers = max(layers, 1)
    return Equivalent(layers, layers - 1)


class MaterialXSide:
    """One MaterialX library and GLSL generator (kept across edits, as an editor would),
    drawing onto the caller's moderngl context at `size` with 4x MSAA, like matedit's view."""

    def __init__(self, ctx, size=(512, 512), camera=None) -> None:
        import MaterialX as mx
        import moderngl
        from MaterialX import PyMaterialXGenGlsl as mx_glsl
        from MaterialX import PyMaterialXGenShader as mx_gen

        from matedit.ibl.builtin import studio
        from matedit.render.camera import OrbitCamera
        from matedit.render.mesh import builtin_mesh

        self.mx, self.mx_gen, self.moderngl = mx, mx_gen, moderngl
        self.ctx = ctx
        self.version = mx.__version__
        self.library = mx.createDocument()
        search = mx.getDefaultDataSearchPath()
        mx.loadLibraries(mx.getDefaultDataLibraryFolders(), search, self.library)
        self.generator = mx_glsl.GlslShaderGenerator.create()
        self.gen_context = mx_gen.GenContext(self.generator)
        self.gen_context.registerSourceCodeSearchPath(search)
        options = self.gen_context.getOptions()
        options.hwSpecularEnvironmentMethod = mx_gen.SPECULAR_ENVIRONMENT_PREFILTER

        w, h = size
        self.fbo = ctx.framebuffer(
            [ctx.renderbuffer((w, h), 4, samples=4, dtype="f4")],
            ctx.depth_renderbuffer((w, h), samples=4))
        mesh = builtin_mesh("sphere")
        self.attributes = {
            "i_position": (ctx.buffer(mesh.positions.astype("f4").tobytes()), "3f"),
            "i_normal": (ctx.buffer(mesh.normals.astype("f4").tobytes()), "3f"),
            "i_tangent": (ctx.buffer(mesh.tangents[:, :3].astype("f4").tobytes()), "3f"),
            "i_texcoord_0": (ctx.buffer(mesh.uvs.astype("f4").tobytes()), "2f"),
        }
        self.indices = ctx.buffer(mesh.indices.astype("u4").tobytes())
        env = np.ascontiguousarray(studio(256)[::-1], dtype="f4")  # lat-long, row 0 at bottom
        self.env = ctx.texture((env.shape[1], env.shape[0]), 3, env.tobytes(), dtype="f4")
        self.env.build_mipmaps()
        self.env.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        self.env_mips = int(np.log2(max(env.shape[:2]))) + 1
        cam = camera or OrbitCamera()
        self.view_projection = cam.projection(w / h) @ cam.view_matrix()
        self.eye = tuple(float(x) for x in cam.eye)

    # -- the document ----------------------------------------------------------------------
    def build(self, eq: Equivalent, seed: int = 0, mode: str = "shaders"):
        """A document holding the equivalent material; returns (document, material node).
        mode "shaders": a standard_surface per layer, folded by mix nodes of surfaceshaders
        (a BSDF evaluation per layer, MaterialX's usual layering); mode "inputs": one
        standard_surface whose base colour, metalness and roughness are each folded by mix
        nodes over the layers' values (one BSDF, matedit's own scheme)."""
        mx = self.mx
        doc = mx.createDocument()
        doc.importLibrary(self.library)
        rng = np.random.default_rng(seed)
        values = [(mx.Color3(*[float(x) for x in rng.random(3)]), float(rng.random() > 0.5),
                   float(0.1 + 0.8 * rng.random())) for _ in range(eq.layers)]
        masks = []
        for i in range(1, eq.layers):
            uv = doc.addNode("texcoord", f"uv{i}", "vector2")
            mask = doc.addNode("noise2d", f"mask{i}", "float")
            mask.setConnectedNode("texcoord", uv)
            masks.append(mask)
        names = (("base_color", "color3"), ("metalness", "float"),
                 ("specular_roughness", "float"))
        if mode == "inputs":
            shader = doc.addNode("standard_surface", "surface", "surfaceshader")
            for k, (name, kind) in enumerate(names):
                if eq.layers == 1:
                    shader.setInputValue(name, values[0][k])
                    continue
                prev = None
                for i in range(1, eq.layers):
                    mix = doc.addNode("mix", f"{name}_blend{i}", kind)
                    if prev is None:
                        mix.setInputValue("bg", values[0][k])
                    else:
                        mix.setConnectedNode("bg", prev)
                    mix.setInputValue("fg", values[i][k])
                    mix.setConnectedNode("mix", masks[i - 1])
                    prev = mix
                shader.setConnectedNode(name, prev)
        else:
            shader = None
            for i in range(eq.layers):
                layer = doc.addNode("standard_surface", f"layer{i}", "surfaceshader")
                for k, (name, _) in enumerate(names):
                    layer.setInputValue(name, values[i][k])
                if shader is None:
                    shader = layer
                    continue
                mix = doc.addNode("mix", f"blend{i}", "surfaceshader")
                mix.setConnectedNode("bg", shader)
                mix.setConnectedNode("fg", layer)
                mix.setConnectedNode("mix", masks[i - 1])
                shader = mix
        material = doc.addMaterialNode("equivalent", shader)
        ok, message = doc.validate()
        if not ok:
            raise RuntimeError(f"MaterialX document does not validate: {message}")
        return doc, material

    def generate(self, material) -> tuple[str, str]:
        shader = self.generator.generate("equivalent", material, self.gen_context)
        return (shader.getSourceCode(self.mx_gen.VERTEX_STAGE),
                shader.getSourceCode(self.mx_gen.PIXEL_STAGE))

    # -- GL --------------------------------------------------------------------------------
    def _bind(self, prog) -> None:
        """Set what the generated program reads; the rest keep their GLSL defaults (and the
        light count is 0)."""
        def mat(m):
            return np.ascontiguousarray(m.T, dtype="f4").tobytes()

        for name, value in (("u_viewProjectionMatrix", mat(self.view_projection)),
                            ("u_worldMatrix", mat(np.eye(4))),
                            ("u_worldInverseTransposeMatrix", mat(np.eye(4)))):
            if name in prog:
                prog[name].write(value)
        scalars = {"u_viewPosition": self.eye, "u_envRadiance": 0, "u_envIrradiance": 0,
                   "u_envRadianceMips": self.env_mips, "u_numActiveLightSources": 0,
                   "u_envLightIntensity": 1.0}
        for name, value in scalars.items():
            if name in prog:
                prog[name].value = value

    def draw(self, prog) -> None:
        ctx = self.ctx
        vao = ctx.vertex_array(
            prog, [(buf, fmt, name) for name, (buf, fmt) in self.attributes.items()
                   if name in prog], self.indices)
        self.fbo.use()
        ctx.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        ctx.enable(self.moderngl.DEPTH_TEST)
        self.env.use(location=0)
        vao.render()
        ctx.finish()
        vao.release()

    def structural_edit(self, eq: Equivalent, repeat: int = 3, seed: int = 0,
                        mode: str = "shaders") -> dict:
        """Median seconds: generate GLSL, link, first draw (JIT + draw), and the total; and a
        second draw of the same program (the steady frame)."""
        doc, material = self.build(eq, seed, mode)  # keep the document alive while generating
        rows = []
        steady = []
        size = 0
        for _ in range(repeat):
            t0 = time.perf_counter()
            vert, frag = self.generate(material)
            t1 = time.perf_counter()
            prog = self.ctx.program(vertex_shader=vert, fragment_shader=frag)
            self._bind(prog)
            self.ctx.finish()
            t2 = time.perf_counter()
            self.draw(prog)
            t3 = time.perf_counter()
            rows.append((t1 - t0, t2 - t1, t3 - t2, t3 - t0))
            if not steady:
                t4 = time.perf_counter()
                self.draw(prog)
                steady.append(time.perf_counter() - t4)
            prog.release()
            size = len(frag)
        del doc
        rows.sort(key=lambda r: r[3])
        gen, link, first, total = rows[len(rows) // 2]
        return {"generate": gen, "link": link, "first_frame": first, "total": total,
                "steady_frame": steady[0], "fragment_chars": size,
                "totals": [r[3] for r in rows]}

    def release(self) -> None:
        self.fbo.release()
        for buf, _ in self.attributes.values():
            buf.release()
        self.indices.release()
        self.env.release()


def main() -> None:
    import moderngl

    from matedit.resources import graphs_dir

    ctx = moderngl.create_standalone_context(backend="egl")
    side = MaterialXSide(ctx)
    print(f"# MaterialX {side.version} GLSL on {ctx.info['GL_RENDERER']}")
    print("| sample | equivalent | generate (ms) | link (ms) | first frame (ms) | total (ms) |")
    print("|---|---|---:|---:|---:|---:|")
    for path in sorted((graphs_dir() / "materials").glob("*.json")):
        eq = equivalent_of(path)
        mode = sys.argv[1] if len(sys.argv) > 1 else "shaders"
        r = side.structural_edit(eq, repeat=1, mode=mode)
        print(f"| {path.stem} | {eq.describe(mode)} | {r['generate'] * 1000:.1f} | "
              f"{r['link'] * 1000:.0f} | {r['first_frame'] * 1000:.0f} | "
              f"{r['total'] * 1000:.0f} |")
    side.release()


if __name__ == "__main__":
    main()
