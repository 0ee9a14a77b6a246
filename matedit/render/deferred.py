"""The deferred preview: the material's GBUFFER program fills three multisampled targets, and
one lighting program (shaders/render/lighting.frag), linked once a variant for the renderer's
lifetime, shades them in a screen pass over the background (drawn first into a one-sample
texture), writing every sample; see that file for how edges are anti-aliased. The pass covers
the mesh's screen rectangle (matedit/render/scene.py, mesh_rect) and `copy_background` the
rest of the target.

G-buffer layout (GBUFFER entry, shaders/entry/gbuffer.frag.glsl; packing: shaders/gbuffer.glsl):
  0, RGBA32UI: x, y, z  world position (m), float32 bits: exact
               w        world-space shading normal, octahedral, 16 bits a coordinate (angular
                        error below 1e-4 rad)
  1, RGBA32UI: halves   baseColor.r|g, baseColor.b|metallic, emissive.r|g, emissive.b|cavity:
                        relative error at most 2^-11 (11-bit significand), clamped to +-65504
  2, RG32F:             roughness, float32: exact; coverage, 1 where the mesh was drawn
Fewer and narrower targets than four RGBA float32 ones: llvmpipe's JIT at a new material
program's first draw, and its fill of every frame, grow with the targets' number and size (the
structural edit's latency). The lighting pass sees the forward entry's shadeSurface arguments up
to those roundings. The targets are cleared to 0; only the float one's coverage is read where the
mesh was not drawn (GL leaves a glClear of an integer target undefined).
"""

from __future__ import annotations

import moderngl

from matedit.glsl.include import packing_prelude
from matedit.render.fullscreen import GLSL_VERSION, FullscreenQuad, render_program, set_uniform
from matedit.resources import shaders_dir

# (components, moderngl dtype) of each target, in location order (the layout above)
GBUFFER_FORMATS = ((4, "u4"), (4, "u4"), (2, "f4"))
GBUFFER_TARGETS = len(GBUFFER_FORMATS)
GBUFFER_FIRST_UNIT = 8  # texture units of the G-buffer in the lighting pass
SPLIT_SUM_ONLY = "MATEDIT_SPLIT_SUM_ONLY"
ENERGY_COMPENSATION = "MATEDIT_ENERGY_COMPENSATION"


class GBuffer:
    """The multisampled targets of one size; shares its depth with the colour target."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], samples: int,
                 depth: moderngl.Renderbuffer) -> None:
        self.textures = [ctx.texture(size, components, dtype=dtype, samples=samples)
                         for components, dtype in GBUFFER_FORMATS]
        self.fbo = ctx.framebuffer(self.textures, depth)

    def release(self) -> None:
        self.fbo.release()
        for t in self.textures:
            t.release()


class LightingPass:
    """The lighting programs, keyed by (split sum only, energy compensation, edges once, lobe
    mask), each linked on first use and then kept for the renderer's lifetime."""

    def __init__(self, ctx: moderngl.Context, samples: int, bind, quad: FullscreenQuad) -> None:
        self.ctx = ctx
        self.samples = max(1, samples)
        self._bind = bind
        self._quad = quad
        self._programs: dict[tuple[bool, bool, bool, int], moderngl.Program] = {}
        self.link_count = 0
        self.edges_once = False  # benchmarks only (see program)
        self._copy: moderngl.Program | None = None  # copy_background's, linked on first use

    def program(self, split_sum_only: bool, compensation: bool, edges_once: bool = False,
                lobes: int = 127) -> moderngl.Program:
        """`edges_once` (benchmarks only) shades every pixel once, edges too: no anti-aliasing
        of the lighting, to measure what lighting edges per sample costs. `lobes`: the lobe
        view's MATEDIT_LOBES mask (127, every lobe, adds no define)."""
        key = (bool(split_sum_only), bool(compensation), bool(edges_once), int(lobes))
        prog = self._programs.get(key)
        if prog is None:
            defines = ([SPLIT_SUM_ONLY] if split_sum_only else []) + \
                      ([ENERGY_COMPENSATION] if compensation else []) + \
                      (["MATEDIT_EDGES_ONCE"] if edges_once else [])
            lines = [packing_prelude(GLSL_VERSION)]  # shaders/gbuffer.glsl unpacks halves
            lines += [f"#define {d} 1" for d in defines]
            if int(lobes) != 127:
                lines.append(f"#define MATEDIT_LOBES {int(lobes)}")
            lines.append(f"#define MATEDIT_GBUFFER_SAMPLES {self.samples}")
            prog = render_program(self.ctx, "fullscreen.vert", "lighting.frag",
                                  "\n".join(lines), [shaders_dir() / "render", shaders_dir()],
                                  vertex_prelude=False)
            self._bind(prog)
            for i in range(GBUFFER_TARGETS):
                prog[f"uGBuffer{i}"].value = GBUFFER_FIRST_UNIT + i
            prog["uBackground"].value = GBUFFER_FIRST_UNIT + GBUFFER_TARGETS
            self.link_count += 1
            self._programs[key] = prog
        return prog

    def copy_background(self, background: moderngl.Texture) -> None:
        """`background` into every sample of the bound target (within its scissor): where the
        lighting pass, drawn within the mesh's bound only, does not reach."""
        if self._copy is None:
            self._copy = render_program(self.ctx, "fullscreen.vert", "copy.frag")
            self._copy["uSource"].value = GBUFFER_FIRST_UNIT + GBUFFER_TARGETS
        background.use(location=GBUFFER_FIRST_UNIT + GBUFFER_TARGETS)
        self._quad.draw(self._copy)

    def draw(self, gbuffer: GBuffer, background: moderngl.Texture, eye,
             split_sum_only: bool, compensation: bool, lobes: int = 127) -> None:
        """Shades the G-buffer over `background` into every sample of the bound target, with
        the lobes of the `lobes` mask."""
        for i, t in enumerate(gbuffer.textures):
            t.use(location=GBUFFER_FIRST_UNIT + i)
        background.use(location=GBUFFER_FIRST_UNIT + GBUFFER_TARGETS)
        prog = self.program(split_sum_only, compensation, self.edges_once, lobes)
        # (a lobe view that shades nothing, coat only on a talk material, drops the uniform)
        set_uniform(prog, "uCameraPosition", tuple(float(x) for x in eye))
        self._quad.draw(prog)

    def release(self) -> None:
        for prog in self._programs.values():
            prog.release()
        self._programs.clear()
        if self._copy is not None:
            self._copy.release()
            self._copy = None
