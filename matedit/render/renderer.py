"""The preview renderer: moderngl only, no Qt; any context (headless EGL or Qt's).

Frame: environment background, the material on the preview mesh, light gizmos, all in a
multisampled linear-HDR target; then resolve, and in reference mode accumulate frames with
rotated sample sets; finally the display pass (exposure, ACES, sRGB) or the difference heat
map into the caller's framebuffer. Deferred, the mesh's GBUFFER program fills the G-buffer and
one lighting pass shades it; forward (translucent materials), its FORWARD program draws.

The parts: programs.ProgramCache (one program per variant's structure hash),
material.MaterialResources (parameter buffer, textures), environment.EnvironmentLighting,
gizmos.Gizmos, frames.SceneTargets and frames.Accumulator (accumulation, display pass).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import moderngl
import numpy as np

from matedit.compiler.api import CompiledMaterial
from matedit.compiler.ir import MaterialIR, Scope
from matedit.glsl.layout import BINDINGS, FRAME_BLOCK
from matedit.render.camera import OrbitCamera
from matedit.render.deferred import ENERGY_COMPENSATION, LightingPass, wants_forward
from matedit.render.environment import EnvironmentLighting
from matedit.render.frames import Accumulator, SceneTargets, r2_offset
from matedit.render.fullscreen import FullscreenQuad, mat_bytes
from matedit.render.gizmos import Gizmos
from matedit.render.lights import default_rig
from matedit.render.material import MaterialResources
from matedit.render.mesh import GpuMesh, mesh_from_spec
from matedit.render.programs import MaterialStatus, ProgramCache, bind_program
from matedit.shading.ibl import IBL_MODE_REFERENCE, IBL_MODE_SPLIT_SUM
from matedit.shading.lights import Light
from matedit.shading.lights_block import pack_lights

__all__ = ["MODES", "MaterialStatus", "Renderer", "r2_offset"]
MODES = ("splitsum", "reference", "difference")
_FRAME_OFFSETS = FRAME_BLOCK.offsets()


class Renderer:
    """Draws one material on a preview mesh. See the module docstring for the passes."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int] = (512, 512),
                 samples: int = 4, environment: str | None = "studio",
                 bake_settings=None, deferred: bool = True) -> None:
        self.ctx = ctx
        self.samples = samples
        # deferred preview (GBUFFER entry + one lighting pass) for opaque materials; forward
        # (FORWARD entry) for materials that write opacity, or when asked
        self.deferred = bool(deferred) and samples >= 2
        self.is_forward = True  # the current material's path
        self.camera = OrbitCamera()
        self.lights: list[Light] = default_rig()
        self.mode = "splitsum"
        self.exposure = -0.5
        self.time = 0.0
        self.show_background = True
        self.background_blur = 0.0
        self.show_gizmos = True
        self.environment_intensity = 1.0
        self.reference_samples = 32  # per pixel per frame
        self.reference_frames = 64  # frames to converge (32 x 64 = 2048 samples a pixel)
        # reference mode integrates sphere and tube lights by Monte Carlo over their shapes
        self.reference_lights = True
        # multiple-scattering compensation in every material (beyond the talk; off), on top
        # of materials that ask for it themselves (preview "energy_compensation": true)
        self.energy_compensation = False
        self.bake_settings = bake_settings
        self._difference_cache: tuple[int, float] | None = None
        self._frames_drawn = 0
        self._size = (0, 0)
        self._program: moderngl.Program | None = None
        self._mesh: GpuMesh | None = None
        self.mesh_name = "sphere"
        self.programs = ProgramCache(ctx, bind_program)
        self._programs = self.programs.table  # variant structure hash -> program
        self.material = MaterialResources(ctx)
        self._quad = FullscreenQuad(ctx)
        self.environment = EnvironmentLighting(ctx, self._quad)
        self.gizmos = Gizmos(ctx)
        self.frames = Accumulator(ctx, self._quad)
        self.targets: SceneTargets | None = None
        self._frame_buf = ctx.buffer(reserve=FRAME_BLOCK.size)
        self._lights_buf = ctx.buffer(pack_lights(self.lights))
        self.lighting = LightingPass(ctx, samples, bind_program, self._quad)
        if self.deferred:
            self.lighting.program(True, False)  # linked once, at start-up
        self.set_mesh("sphere")
        self.resize(*size)
        if environment is not None:
            self.set_environment(environment)
        if self.deferred:
            self._warm_up()

    def _warm_up(self) -> None:
        """The driver compiles at a program's first draw (and builds its per-framebuffer state
        the first time a target is used): one frame of a constant material now, at start-up,
        so that the lighting pass and the G-buffer targets cost nothing at the first edit."""
        from matedit.compiler.api import compile_ir

        self.set_material(compile_ir(MaterialIR(Scope("evaluateMaterial"), [], [], [], set(),
                                                [])))
        self.render()
        self._program = self.material.compiled = None

    @property
    def _compiled(self) -> CompiledMaterial | None:
        return self.material.compiled

    @property
    def _values(self) -> dict[str, Any]:
        return self.material.values

    # --- configuration --------------------------------------------------------------------
    @property
    def size(self) -> tuple[int, int]:
        return self._size

    def resize(self, width: int, height: int) -> None:
        width, height = max(1, int(width)), max(1, int(height))
        if (width, height) == self._size:
            return
        self._size = (width, height)
        self._release_targets()
        self.targets = SceneTargets(self.ctx, self._size, self.samples, self.deferred)
        self.frames.resize(self._size)
        self.reset_accumulation()

    def _release_targets(self) -> None:
        """Framebuffer 0 is bound first: moderngl would otherwise bind a released framebuffer
        again later (GL_INVALID_OPERATION)."""
        if self.targets is not None:
            self.ctx.detect_framebuffer(0).use()
            self.targets.release()
            self.targets = None
        self.frames.release_targets()

    def reset_accumulation(self) -> None:
        self.frames.frames = 0

    def set_mesh(self, spec: str | Path) -> None:
        """A built-in mesh name or an OBJ path; raises MeshError (a ValueError) on bad files."""
        data = mesh_from_spec(spec)
        if self._mesh is not None:
            self._mesh.release()
        self._mesh = GpuMesh(self.ctx, data)
        self.mesh_name = str(spec)
        self.reset_accumulation()

    def set_lights(self, lights: list[Light]) -> None:
        self.lights = list(lights)[:16]
        self._lights_buf.write(pack_lights(self.lights))
        self.reset_accumulation()

    def set_environment(self, spec: str | Path, progress=None) -> None:
        """A built-in name (studio, sky) or an HDR/EXR file, baked (cached) and uploaded."""
        self.environment.set(spec, self.bake_settings, progress)
        self.environment_name = str(spec)
        self.environment_warnings = list(self.environment.warnings)
        self.reset_accumulation()

    # --- material -------------------------------------------------------------------------
    @property
    def link_count(self) -> int:
        """Material programs linked so far (the lighting pass's are `lighting.link_count`)."""
        return self.programs.link_count

    def set_material(self, compiled: CompiledMaterial) -> MaterialStatus:
        """Structural edit: link (or reuse) the material's program, its GBUFFER entry when
        deferred; keep the last good one on failure."""
        values = {u.name: u.default for u in compiled.ir.uniforms}
        forward = not self.deferred or wants_forward(compiled, values)
        prog = self.programs.link(compiled, forward, self.energy_compensation)
        if isinstance(prog, MaterialStatus):
            return prog
        self._program, self.is_forward = prog, forward
        self.material.load(compiled, values)
        self.reset_accumulation()
        return MaterialStatus(True)

    def set_energy_compensation(self, on: bool) -> None:
        """The preview's multiple-scattering compensation option (relinks once per state)."""
        if bool(on) == self.energy_compensation:
            return
        self.energy_compensation = bool(on)
        if self._compiled is not None:
            self._program = self.programs.material(self._compiled, self.is_forward, bool(on))
        self.reset_accumulation()

    def set_uniforms(self, values: dict[str, Any]) -> None:
        """Parameter edit: rewrite the MaterialParams buffer; never links a program."""
        if self._compiled is None:
            return
        self.material.set_values(values)
        forward = not self.deferred or wants_forward(self._compiled, self._values)
        if forward != self.is_forward:  # opacity crossed 1: the other path (linked once)
            try:
                self._program = self.programs.material(self._compiled, forward,
                                                       self.energy_compensation)
                self.is_forward = forward
            except moderngl.Error:
                pass  # keeps the current path: the variants share the material's code
        self.reset_accumulation()

    def set_texture(self, name: str, path: str | None, color_space: str | None = None) -> None:
        """Loads a material texture (a value edit); a missing file shows a checker. The colour
        space defaults to the compiled material's setting for that texture (srgb, linear or an
        OpenColorIO space; matedit.shading.colorspace). The same unchanged file again reads,
        uploads and redraws nothing."""
        if self.material.set_texture(name, path, color_space):
            self.reset_accumulation()

    # --- drawing --------------------------------------------------------------------------
    @property
    def needs_redraw(self) -> bool:
        """True while reference or difference mode is still converging."""
        return not self.converged

    @property
    def converged(self) -> bool:
        return self.mode == "splitsum" or self.frames.frames >= self.reference_frames

    @property
    def accumulated_frames(self) -> int:
        """Reference frames averaged so far (converged at `reference_frames`)."""
        return self.frames.frames

    def _write_frame_block(self) -> np.ndarray:
        w, h = self._size
        vp = self.camera.projection(w / h) @ self.camera.view_matrix()
        data = bytearray(FRAME_BLOCK.size)
        for name, value in (("viewProjection", mat_bytes(vp)), ("model", mat_bytes(np.eye(4))),
                            ("normalMatrix", mat_bytes(np.eye(4))),
                            ("cameraPosition", np.array([*self.camera.eye, 1.0], "f4").tobytes()),
                            ("params", np.array([self.time, self.exposure, w, h], "f4").tobytes())):
            data[_FRAME_OFFSETS[name]:_FRAME_OFFSETS[name] + len(value)] = value
        self._frame_buf.write(bytes(data))
        return vp

    def _scene(self, ibl_mode: int, offset=(0.0, 0.0)) -> None:
        """Background, mesh and gizmos into the multisampled HDR target, then resolve. Deferred:
        the mesh's GBUFFER program fills the G-buffer (sharing the depth), the lighting pass
        shades it into the target; forward: the mesh's FORWARD program draws into it."""
        ctx, t, reference = self.ctx, self.targets, ibl_mode == IBL_MODE_REFERENCE
        vp = self._write_frame_block()
        program = self._program
        if reference and self.is_forward and self._compiled is not None:
            program = self.programs.reference(self._compiled, self.energy_compensation,
                                              fallback=program)
        drawn = program is not None and self._mesh is not None
        deferred = drawn and not self.is_forward
        # the background: into the target itself (forward), or a one-sample texture that the
        # lighting pass reads where the mesh is not (deferred)
        backdrop = t.background if deferred else t.msaa
        backdrop.use()
        backdrop.viewport = (0, 0, *self._size)
        ctx.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        if self.show_background:
            self.environment.draw_background(vp, self.background_blur,
                                             self.environment_intensity)
        if drawn:
            self._lights_buf.bind_to_uniform_block(BINDINGS["LIGHTS"])
            self.environment.bind(ibl_mode, self.environment_intensity, self.reference_samples,
                                  offset, reference and self.reference_lights)
            self._frame_buf.bind_to_uniform_block(BINDINGS["FRAME"])
            self.material.bind(program)
            if deferred:
                t.gbuffer.fbo.use()
                t.gbuffer.fbo.viewport = (0, 0, *self._size)
                ctx.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            ctx.enable(moderngl.DEPTH_TEST | (0 if deferred else moderngl.BLEND))
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            self._mesh.render(program)
            ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
            if deferred:
                t.msaa.use()  # no clear: the pass writes every sample; depth is kept
                t.msaa.viewport = (0, 0, *self._size)
                compensation = self.energy_compensation or \
                    ENERGY_COMPENSATION in self._compiled.ir.defines
                self.lighting.draw(t.gbuffer, t.background.color_attachments[0],
                                   np.array(self.camera.eye, "f4"), not reference, compensation)
        if self.show_gizmos:
            ctx.enable(moderngl.DEPTH_TEST)
            self.gizmos.draw(vp, self.lights)
        ctx.disable(moderngl.DEPTH_TEST)
        ctx.copy_framebuffer(t.resolved, t.msaa)

    def render(self, target: moderngl.Framebuffer | None = None) -> None:
        """Draws one frame into `target` (default: an internal sRGB8 image, see read_image)."""
        if self.mode == "splitsum":
            self._scene(IBL_MODE_SPLIT_SUM)
        else:
            if self.frames.frames < self.reference_frames:
                self._scene(IBL_MODE_REFERENCE, r2_offset(self.frames.frames))
                self.frames.add(self.targets.resolved)
            if self.mode == "difference":
                self._scene(IBL_MODE_SPLIT_SUM)
                self.frames.keep_split_sum(self.targets.resolved)
        self.frames.display(target if target is not None else self.frames.output(), self.mode,
                            self.targets.resolved, self.exposure)
        self._frames_drawn += 1

    @property
    def difference_mean(self) -> float | None:
        """Mean |split-sum - reference| of the last difference frame, linear HDR (read back
        from the GPU when asked, once per frame drawn, not on every frame)."""
        if self.mode != "difference" or self.frames.frames == 0:
            return None
        if self._difference_cache is None or self._difference_cache[0] != self._frames_drawn:
            mean = float(np.mean(np.abs(self.read_linear())))
            self._difference_cache = (self._frames_drawn, mean)
        return self._difference_cache[1]

    # --- reading back ---------------------------------------------------------------------
    def read_image(self) -> np.ndarray:
        """The last frame drawn into the internal target: (H, W, 3) float sRGB, top row first."""
        return self.frames.read_image()

    def read_hdr(self, which: str | None = None) -> np.ndarray:
        """Linear HDR (H, W, 3), top row first: the split-sum frame or the reference average."""
        which = which or ("splitsum" if self.mode == "splitsum" else "reference")
        return self.frames.read_hdr(which, self.mode, self.targets.resolved)

    def read_linear(self) -> np.ndarray:
        """The scene-referred linear radiance of the current mode's frame, (H, W, 3), top row
        first, before exposure and the display transform: split sum, the reference average,
        or in difference mode split sum minus reference (signed)."""
        if self.mode == "difference":
            return self.read_hdr("splitsum") - self.read_hdr("reference")
        return self.read_hdr()

    def set_reference_samples(self, total: int) -> None:
        """Reference mode's samples a pixel: up to 32 a frame, accumulated over frames."""
        total = max(1, int(total))
        self.reference_samples = min(32, total)
        self.reference_frames = max(1, math.ceil(total / self.reference_samples))
        self.reset_accumulation()

    def render_converged(self, target=None, max_frames: int | None = None) -> int:
        """Renders until reference/difference mode has converged; returns frames drawn."""
        limit = max_frames if max_frames is not None else self.reference_frames + 1
        frames = 0
        while True:
            self.render(target)
            frames += 1
            if not self.needs_redraw or frames >= limit:
                return frames

    def release(self) -> None:
        self._release_targets()
        self.programs.release(self._mesh.forget if self._mesh is not None else None)
        self.lighting.release()
        for part in (self._mesh, self.material, self.environment, self.gizmos, self.frames,
                     self._quad, self._frame_buf, self._lights_buf):
            if part is not None:
                part.release()
