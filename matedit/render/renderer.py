"""The preview renderer: moderngl only, no Qt; any context (headless EGL or Qt's).

Frame: environment background, the material on the preview mesh (one program per
structure hash; parameter edits only rewrite the MaterialParams buffer), light
gizmos, all in a multisampled linear-HDR target; then resolve, and in reference
mode accumulate frames with rotated sample sets; finally the display pass
(exposure, ACES, sRGB) or the difference heat map into the caller's framebuffer.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import moderngl
import numpy as np

from matedit.compiler.api import CompiledMaterial
from matedit.compiler.emit import Entry
from matedit.compiler.ir import MaterialIR, Scope
from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING
from matedit.glsl import layout as _layout
from matedit.glsl.include import assemble
from matedit.render.camera import OrbitCamera
from matedit.render.deferred import (
    ENERGY_COMPENSATION,
    SPLIT_SUM_ONLY,
    GBuffer,
    LightingPass,
    wants_forward,
)
from matedit.render.lights import default_rig
from matedit.render.mesh import GpuMesh, mesh_from_spec, uv_sphere
from matedit.render.programs import MaterialStatus, ProgramCache, failure
from matedit.render.textures import file_stamp, texture_from
from matedit.shading.ibl import (
    IBL_MODE_NONE,
    IBL_MODE_REFERENCE,
    IBL_MODE_SPLIT_SUM,
    pack_ibl_block,
)
from matedit.shading.lights import Light
from matedit.shading.lights_block import pack_lights

MODES = ("splitsum", "reference", "difference")
# binding numbers and block sizes: matedit/glsl/layout.py, the one source
LIGHTS_BINDING, IBL_BINDING = _layout.BINDINGS["LIGHTS"], _layout.BINDINGS["IBL"]
PREFILTERED_UNIT, LUT_UNIT, ENVIRONMENT_UNIT = (
    _layout.BINDINGS[k] for k in ("PREFILTERED_ENV", "BRDF_LUT", "ENVIRONMENT"))
_FRAME_OFFSETS = _layout.FRAME_BLOCK.offsets()
# SH irradiance coefficients -> radiance coefficients: divide by the cosine lobe's A_l
# (Ramamoorthi and Hanrahan 2001): pi, 2pi/3, pi/4 for bands 0, 1, 2.
_SH_BAND_SCALE = np.array([math.pi] + [2 * math.pi / 3] * 3 + [math.pi / 4] * 5)


def _program(ctx, vert: str, frag: str, defines: str = "") -> moderngl.Program:
    v = assemble(vert, "330 core", [], "<vertex>", prelude=defines)
    f = assemble(frag, "330 core", [], "<fragment>", prelude=defines)
    return ctx.program(vertex_shader=v.text, fragment_shader=f.text)


def _read_shader(name: str) -> str:
    from matedit.resources import shaders_dir

    return (shaders_dir() / "render" / name).read_text()


def _set(prog, name: str, value) -> None:
    if name in prog:
        prog[name].value = value


def _mat_bytes(m: np.ndarray) -> bytes:
    return np.ascontiguousarray(m.T, dtype="f4").tobytes()  # GLSL is column-major


def r2_offset(frame: int) -> tuple[float, float]:
    """Per-frame rotation of the reference sample set: the R2 sequence (Roberts 2018)."""
    g = 1.32471795724474602596
    return ((0.5 + frame / g) % 1.0, (0.5 + frame / (g * g)) % 1.0)


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
        self._difference_cache: tuple[int, float] | None = None
        self._frames_drawn = 0
        self.bake_settings = bake_settings
        self.programs = ProgramCache(ctx, self._bind_program)
        self._programs = self.programs.table  # variant structure hash -> program
        self._compiled: CompiledMaterial | None = None
        self._program: moderngl.Program | None = None
        self._values: dict[str, Any] = {}
        self._textures: dict[str, moderngl.Texture] = {}
        self._texture_keys: dict[str, tuple[str | None, str]] = {}  # name: (path, space)
        self._texture_stamps: dict[str, tuple] = {}  # name: textures.file_stamp
        self._accum_frames = 0
        self._frame_index = 0
        self._size = (0, 0)
        self._ibl = None
        self._env_cube = None
        self._env_levels = 1
        self._sh = np.zeros((9, 3))
        self._mesh: GpuMesh | None = None
        self.mesh_name = "sphere"

        self._quad = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], dtype="f4").tobytes())
        fs = _read_shader("fullscreen.vert")
        self._bg = _program(ctx, fs, _read_shader("background.frag"))
        self._display = _program(ctx, fs, _read_shader("display.frag"))
        self._accumulate = _program(ctx, fs, _read_shader("accumulate.frag"))
        self._gizmo = _program(ctx, _read_shader("gizmo.vert"), _read_shader("gizmo.frag"))
        self._fs_vaos = {p.glo: ctx.vertex_array(p, [(self._quad, "2f", "a_pos")])
                         for p in (self._bg, self._display, self._accumulate)}
        ball = uv_sphere(1.0, 16, 8)
        self._gizmo_vbo = ctx.buffer(ball.positions.astype("f4").tobytes())
        self._gizmo_ibo = ctx.buffer(ball.indices.astype("u4").tobytes())
        self._gizmo_vao = ctx.vertex_array(self._gizmo, [(self._gizmo_vbo, "3f", "a_position")],
                                           self._gizmo_ibo)
        self._line_vbo = ctx.buffer(reserve=24)
        self._line_vao = ctx.vertex_array(self._gizmo, [(self._line_vbo, "3f", "a_position")])
        self._frame_buf = ctx.buffer(reserve=_layout.FRAME_BLOCK.size)
        self._lights_buf = ctx.buffer(pack_lights(self.lights))
        self._ibl_buf = ctx.buffer(reserve=_layout.IBL_BLOCK.size)
        self._params_buf: moderngl.Buffer | None = None
        self._gbuffer: GBuffer | None = None
        self.lighting = LightingPass(ctx, samples, self._bind_program)
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
        self._program = self._compiled = None

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
        ctx = self.ctx
        s = self.samples
        depth = ctx.depth_renderbuffer((width, height), samples=s)
        self._msaa_fbo = ctx.framebuffer(
            [ctx.renderbuffer((width, height), 4, samples=s, dtype="f4")], depth)
        if self.deferred:
            self._gbuffer = GBuffer(ctx, (width, height), s, depth)
            self._background_fbo = ctx.framebuffer([ctx.texture((width, height), 4, dtype="f4")])
        self._resolve_fbo = ctx.framebuffer([ctx.texture((width, height), 4, dtype="f4")])
        self._accum_fbo = ctx.framebuffer([ctx.texture((width, height), 4, dtype="f4")])
        self._split_fbo = ctx.framebuffer([ctx.texture((width, height), 4, dtype="f4")])
        self._out_fbo = None
        self.reset_accumulation()

    def _release_targets(self) -> None:
        """Releases the internal render targets. Framebuffer 0 is bound first: moderngl would
        otherwise bind a released framebuffer again later (GL_INVALID_OPERATION)."""
        if any(getattr(self, n, None) is not None for n in self._TARGETS):
            self.ctx.detect_framebuffer(0).use()
        if self._gbuffer is not None:
            self._gbuffer.release()  # before the depth it shares with _msaa_fbo
            self._gbuffer = None
        for name in self._TARGETS:
            fbo = getattr(self, name, None)
            if fbo is not None:
                for a in fbo.color_attachments:
                    a.release()
                if fbo.depth_attachment is not None:
                    fbo.depth_attachment.release()
                fbo.release()
                setattr(self, name, None)

    _TARGETS = ("_msaa_fbo", "_resolve_fbo", "_accum_fbo", "_split_fbo", "_out_fbo",
                "_background_fbo")

    def reset_accumulation(self) -> None:
        self._accum_frames = 0
        self._frame_index = 0

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
        from matedit.ibl import bake, upload

        result = bake(spec, self.bake_settings, ctx=self.ctx,
                      progress=(lambda f, m: progress(f)) if progress else None)
        if self._ibl is not None:
            self._ibl.release()
            self._env_cube.release()
        self._ibl = upload(self.ctx, result)
        base = result.mips[0]
        n = base.shape[1]
        cube = self.ctx.texture_cube((n, n), 3, dtype="f4")
        for face in range(6):
            cube.write(face, np.ascontiguousarray(base[face, ..., :3], dtype="f4").tobytes())
        cube.build_mipmaps()
        cube.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        self._env_cube = cube
        self._env_levels = result.levels
        self._sh = np.asarray(result.sh, dtype=np.float64) / _SH_BAND_SCALE[:, None]
        self.environment_name = str(spec)
        self.environment_warnings = list(result.warnings)
        self.reset_accumulation()

    # --- material -------------------------------------------------------------------------
    @property
    def link_count(self) -> int:
        """Material programs linked so far (the lighting pass's are `lighting.link_count`)."""
        return self.programs.link_count

    def _forward_defines(self, split_sum_only: bool) -> tuple[str, ...]:
        return (((SPLIT_SUM_ONLY,) if split_sum_only else ())
                + ((ENERGY_COMPENSATION,) if self.energy_compensation else ()))

    def _material_program(self, compiled: CompiledMaterial, forward: bool):
        if forward:  # split sum only: the reference estimator is a third of llvmpipe's work
            return self.programs.get(compiled, Entry.FORWARD, self._forward_defines(True))
        return self.programs.get(compiled, Entry.GBUFFER)

    def _program_for(self, ibl_mode: int) -> moderngl.Program | None:
        if ibl_mode != IBL_MODE_REFERENCE or self._compiled is None or not self.is_forward:
            return self._program
        try:
            return self.programs.get(self._compiled, Entry.FORWARD,
                                     self._forward_defines(False))[0]
        except moderngl.Error:
            return self._program  # cannot happen when the split-sum variant linked

    def set_material(self, compiled: CompiledMaterial) -> MaterialStatus:
        """Structural edit: link (or reuse) the material's program, its GBUFFER entry when
        deferred; keep the last good one on failure."""
        values = {u.name: u.default for u in compiled.ir.uniforms}
        forward = not self.deferred or wants_forward(compiled, values)
        try:
            prog, _ = self._material_program(compiled, forward)
        except moderngl.Error as exc:  # located in the variant that failed
            entry = Entry.FORWARD if forward else Entry.GBUFFER
            defines = self._forward_defines(True) if forward else ()
            return failure(compiled.variant(entry, defines), exc)
        self._program = prog
        self.is_forward = forward
        self._compiled = compiled
        self._values = values
        size = max(16, len(compiled.pack_uniforms()))
        if self._params_buf is None or self._params_buf.size != size:
            if self._params_buf is not None:
                self._params_buf.release()
            self._params_buf = self.ctx.buffer(reserve=size)
        self._params_buf.write(compiled.pack_uniforms(self._values))
        self._load_textures(compiled)
        self.reset_accumulation()
        return MaterialStatus(True)

    def _bind_program(self, prog: moderngl.Program) -> None:
        for block, binding in (("LightsBlock", LIGHTS_BINDING), ("IblBlock", IBL_BINDING),
                               ("FrameBlock", FRAME_BINDING),
                               ("MaterialParams", MATERIAL_BINDING)):
            if block in prog:
                prog[block].binding = binding
        _set(prog, "uPrefilteredEnv", PREFILTERED_UNIT)
        _set(prog, "uBrdfLut", LUT_UNIT)
        _set(prog, "uEnvironment", ENVIRONMENT_UNIT)

    def set_energy_compensation(self, on: bool) -> None:
        """The preview's multiple-scattering compensation option (relinks once per state)."""
        on = bool(on)
        if on == self.energy_compensation:
            return
        self.energy_compensation = on
        if self._compiled is not None:
            self._program = self._material_program(self._compiled, self.is_forward)[0]
        self.reset_accumulation()

    def set_uniforms(self, values: dict[str, Any]) -> None:
        """Parameter edit: rewrite the MaterialParams buffer; never links a program."""
        if self._compiled is None:
            return
        known = {u.name for u in self._compiled.ir.uniforms}
        self._values.update({k: v for k, v in values.items() if k in known})
        self._params_buf.write(self._compiled.pack_uniforms(self._values))
        forward = not self.deferred or wants_forward(self._compiled, self._values)
        if forward != self.is_forward:  # opacity crossed 1: the other path (linked once)
            try:
                self._program = self._material_program(self._compiled, forward)[0]
                self.is_forward = forward
            except moderngl.Error:
                pass  # keeps the current path: the variants share the material's code
        self.reset_accumulation()

    def set_texture(self, name: str, path: str | None, color_space: str | None = None) -> None:
        """Loads a material texture (a value edit); a missing file shows a checker. The colour
        space defaults to the compiled material's setting for that texture (srgb, linear or an
        OpenColorIO space; matedit.shading.colorspace)."""
        space = color_space or self._texture_space(name)
        stamp = file_stamp(path, space)
        if name in self._textures and self._texture_stamps.get(name) == stamp:
            return  # the same unchanged file: nothing to read, upload or redraw
        old = self._textures.pop(name, None)
        if old is not None:
            old.release()
        self._textures[name] = self._texture_from(path, space)
        self._texture_keys[name] = (path, space)
        self._texture_stamps[name] = stamp
        self.reset_accumulation()

    def _texture_space(self, name: str) -> str:
        from matedit.shading.colorspace import effective_space

        for t in (self._compiled.ir.textures if self._compiled is not None else ()):
            if t.name == name:
                return effective_space(getattr(t, "color_space", ""), t.srgb)
        return "srgb"

    def _texture_from(self, path: str | None, space: str = "srgb") -> moderngl.Texture:
        return texture_from(self.ctx, path, space)

    def _load_textures(self, compiled: CompiledMaterial) -> None:
        from matedit.shading.colorspace import effective_space

        wanted = {t.name: t for t in compiled.ir.textures}
        for name in list(self._textures):
            if name not in wanted:
                self._textures.pop(name).release()
                self._texture_keys.pop(name, None)
                self._texture_stamps.pop(name, None)
        for name, info in wanted.items():
            key = (info.path, effective_space(getattr(info, "color_space", ""), info.srgb))
            if name not in self._textures or self._texture_keys.get(name, key)[1] != key[1]:
                old = self._textures.pop(name, None)
                if old is not None:
                    old.release()
                path = self._texture_keys.get(name, key)[0] if name in self._texture_keys \
                    else info.path
                self._textures[name] = self._texture_from(path, key[1])
                self._texture_keys[name] = (path, key[1])
                self._texture_stamps[name] = file_stamp(path, key[1])

    # --- drawing --------------------------------------------------------------------------
    @property
    def needs_redraw(self) -> bool:
        """True while reference or difference mode is still converging."""
        return self.mode != "splitsum" and self._accum_frames < self.reference_frames

    @property
    def converged(self) -> bool:
        return self.mode == "splitsum" or self._accum_frames >= self.reference_frames

    @property
    def accumulated_frames(self) -> int:
        """Reference frames averaged so far (converged at `reference_frames`)."""
        return self._accum_frames

    def _write_frame_block(self) -> np.ndarray:
        w, h = self._size
        view = self.camera.view_matrix()
        proj = self.camera.projection(w / h)
        vp = proj @ view
        data = bytearray(_layout.FRAME_BLOCK.size)
        for name, value in (("viewProjection", _mat_bytes(vp)), ("model", _mat_bytes(np.eye(4))),
                            ("normalMatrix", _mat_bytes(np.eye(4))),
                            ("cameraPosition", np.array([*self.camera.eye, 1.0], "f4").tobytes()),
                            ("params", np.array([self.time, self.exposure, w, h], "f4").tobytes())):
            off = _FRAME_OFFSETS[name]
            data[off:off + len(value)] = value
        self._frame_buf.write(bytes(data))
        return vp

    def _scene(self, ibl_mode: int, offset=(0.0, 0.0)) -> None:
        """Background, mesh and gizmos into the multisampled HDR target, then resolve. Deferred:
        the mesh's GBUFFER program fills the G-buffer (sharing the depth), the lighting pass
        shades it into the target; forward: the mesh's FORWARD program draws into it."""
        ctx = self.ctx
        vp = self._write_frame_block()
        program = self._program_for(ibl_mode)
        deferred = program is not None and self._mesh is not None and not self.is_forward
        # the background: into the target itself (forward), or a one-sample texture that the
        # lighting pass reads where the mesh is not (deferred)
        backdrop = self._background_fbo if deferred else self._msaa_fbo
        backdrop.use()
        backdrop.viewport = (0, 0, *self._size)
        ctx.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        if self.show_background and self._ibl is not None:
            self._ibl.prefiltered.use(location=PREFILTERED_UNIT)
            self._env_cube.use(location=ENVIRONMENT_UNIT)
            blur = self.background_blur > 0
            self._bg["uEnvironmentCube"].value = PREFILTERED_UNIT if blur else ENVIRONMENT_UNIT
            self._bg["uInvViewProjection"].write(_mat_bytes(np.linalg.inv(vp)))
            self._bg["uLod"].value = float(self.background_blur * (self._env_levels - 1))
            self._bg["uIntensity"].value = float(self.environment_intensity)
            self._fs_vaos[self._bg.glo].render(vertices=3)
        if program is not None and self._mesh is not None:
            self._bind_scene_inputs(program, ibl_mode, offset)
            if not deferred:
                ctx.enable(moderngl.DEPTH_TEST | moderngl.BLEND)
                ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
                self._mesh.render(program)
                ctx.disable(moderngl.BLEND)
            else:
                self._gbuffer.fbo.use()
                self._gbuffer.fbo.viewport = (0, 0, *self._size)
                ctx.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
                ctx.enable(moderngl.DEPTH_TEST)
                self._mesh.render(program)
                ctx.disable(moderngl.DEPTH_TEST)
                self._msaa_fbo.use()  # no clear: the pass writes every sample; depth is kept
                self._msaa_fbo.viewport = (0, 0, *self._size)
                compensation = self.energy_compensation or \
                    ENERGY_COMPENSATION in self._compiled.ir.defines
                self.lighting.draw(self._gbuffer, self._background_fbo.color_attachments[0],
                                   np.array(self.camera.eye, "f4"),
                                   ibl_mode != IBL_MODE_REFERENCE, compensation)
        if self.show_gizmos:
            ctx.enable(moderngl.DEPTH_TEST)
            self._draw_gizmos(vp)
        ctx.disable(moderngl.DEPTH_TEST)
        ctx.copy_framebuffer(self._resolve_fbo, self._msaa_fbo)

    def _bind_scene_inputs(self, program, ibl_mode: int, offset) -> None:
        """Uniform blocks and textures of the material and lighting programs."""
        self._lights_buf.bind_to_uniform_block(LIGHTS_BINDING)
        mode = ibl_mode if self._ibl is not None else IBL_MODE_NONE
        self._ibl_buf.write(pack_ibl_block(
            self._sh, float(self._env_levels), self.environment_intensity,
            self.reference_samples, mode, offset,
            reference_lights=ibl_mode == IBL_MODE_REFERENCE and self.reference_lights))
        self._ibl_buf.bind_to_uniform_block(IBL_BINDING)
        self._frame_buf.bind_to_uniform_block(FRAME_BINDING)
        self._params_buf.bind_to_uniform_block(MATERIAL_BINDING)
        if self._ibl is not None:
            self._ibl.prefiltered.use(location=PREFILTERED_UNIT)
            self._ibl.brdf_lut.use(location=LUT_UNIT)
            self._env_cube.use(location=ENVIRONMENT_UNIT)
        for i, t in enumerate(self._compiled.ir.textures):
            unit = FIRST_TEXTURE_BINDING + i
            self._textures[t.name].use(location=unit)
            _set(program, t.name, unit)

    def _draw_gizmos(self, vp: np.ndarray) -> None:
        self._gizmo["uViewProjection"].write(_mat_bytes(vp))
        for light in self.lights:
            if light.kind == "directional":
                continue
            color = np.asarray(light.color) * min(light.intensity, 50.0) / 10.0 + 0.2
            self._gizmo["uColor"].value = tuple(float(c) for c in color)
            r = max(light.source_radius, 0.04)
            if light.kind == "tube":
                d = np.asarray(light.direction, dtype=np.float64)
                d = d / (np.linalg.norm(d) or 1.0)
                half = d * light.source_length / 2
                ends = [np.asarray(light.position) - half, np.asarray(light.position) + half]
                self._line_vbo.write(np.array(ends, "f4").tobytes())
                self._gizmo["uModel"].write(_mat_bytes(np.eye(4)))
                self._line_vao.render(mode=moderngl.LINES)
                for e in ends:
                    self._draw_ball(e, r)
            else:
                self._draw_ball(np.asarray(light.position), r)

    def _draw_ball(self, centre, radius: float) -> None:
        m = np.eye(4) * radius
        m[3, 3] = 1.0
        m[:3, 3] = centre
        self._gizmo["uModel"].write(_mat_bytes(m))
        self._gizmo_vao.render()

    def _accumulate_into(self, fbo: moderngl.Framebuffer) -> None:
        fbo.use()
        if self._accum_frames == 0:
            self.ctx.clear(0.0, 0.0, 0.0, 0.0)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = moderngl.ONE, moderngl.ONE
        self._resolve_fbo.color_attachments[0].use(location=0)
        self._accumulate["uFrame"].value = 0
        self._fs_vaos[self._accumulate.glo].render(vertices=3)
        self.ctx.disable(moderngl.BLEND)

    def render(self, target: moderngl.Framebuffer | None = None) -> None:
        """Draws one frame into `target` (default: an internal sRGB8 image, see read_image)."""
        if target is None:
            target = self._output_fbo()
        if self.mode == "splitsum":
            self._scene(IBL_MODE_SPLIT_SUM)
            source, scale = self._resolve_fbo, 1.0
        else:
            if self._accum_frames < self.reference_frames:
                self._scene(IBL_MODE_REFERENCE, r2_offset(self._frame_index))
                self._accumulate_into(self._accum_fbo)
                self._accum_frames += 1
                self._frame_index += 1
            source, scale = self._accum_fbo, 1.0 / max(self._accum_frames, 1)
            if self.mode == "difference":
                self._scene(IBL_MODE_SPLIT_SUM)
                self._split_fbo.use()
                self.ctx.copy_framebuffer(self._split_fbo, self._resolve_fbo)
        self._display_pass(target, source, scale)
        self._frames_drawn += 1

    def _display_pass(self, target, source, scale: float) -> None:
        target.use()
        w, h = self._size
        target.viewport = (0, 0, w, h)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        d = self._display
        if self.mode == "difference":
            self._split_fbo.color_attachments[0].use(location=0)
            source.color_attachments[0].use(location=1)
            d["uImage"].value = 0
            d["uReference"].value = 1
            d["uScale"].value = 1.0
            d["uReferenceScale"].value = scale
            d["uMode"].value = 1
            d["uHeatRange"].value = 0.1
        else:
            source.color_attachments[0].use(location=0)
            d["uImage"].value = 0
            _set(d, "uReference", 0)
            d["uScale"].value = scale
            _set(d, "uReferenceScale", 1.0)
            d["uMode"].value = 0
        d["uExposure"].value = float(self.exposure)
        target.use()
        self._fs_vaos[d.glo].render(vertices=3)

    @property
    def difference_mean(self) -> float | None:
        """Mean |split-sum - reference| of the last difference frame, linear HDR (read back
        from the GPU when asked, once per frame drawn, not on every frame)."""
        if self.mode != "difference" or self._accum_frames == 0:
            return None
        if self._difference_cache is None or self._difference_cache[0] != self._frames_drawn:
            mean = float(np.mean(np.abs(self.read_hdr("splitsum") - self.read_hdr("reference"))))
            self._difference_cache = (self._frames_drawn, mean)
        return self._difference_cache[1]

    def _output_fbo(self) -> moderngl.Framebuffer:
        w, h = self._size
        if self._out_fbo is None or self._out_fbo.size != (w, h):
            if self._out_fbo is not None:
                self._out_fbo.color_attachments[0].release()
                self._out_fbo.release()
            self._out_fbo = self.ctx.framebuffer([self.ctx.texture((w, h), 4)])
        return self._out_fbo

    # --- reading back ---------------------------------------------------------------------
    def read_image(self) -> np.ndarray:
        """The last frame drawn into the internal target: (H, W, 3) float sRGB, top row first."""
        w, h = self._size
        raw = self._output_fbo().read(components=3, alignment=1)
        return np.frombuffer(raw, np.uint8).reshape(h, w, 3)[::-1].astype(np.float32) / 255.0

    def read_hdr(self, which: str | None = None) -> np.ndarray:
        """Linear HDR (H, W, 3), top row first: the split-sum frame or the reference average."""
        which = which or ("splitsum" if self.mode == "splitsum" else "reference")
        w, h = self._size
        if which == "reference":
            fbo, scale = self._accum_fbo, 1.0 / max(self._accum_frames, 1)
        elif self.mode == "difference":
            fbo, scale = self._split_fbo, 1.0
        else:
            fbo, scale = self._resolve_fbo, 1.0
        raw = fbo.read(components=4, dtype="f4")
        return np.frombuffer(raw, np.float32).reshape(h, w, 4)[::-1, :, :3] * scale

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
        per_frame = min(32, total)
        self.reference_samples = per_frame
        self.reference_frames = max(1, math.ceil(total / per_frame))
        self.reset_accumulation()

    def render_converged(self, target=None, max_frames: int | None = None) -> int:
        """Renders until reference/difference mode has converged; returns frames drawn."""
        frames = 0
        limit = max_frames if max_frames is not None else self.reference_frames + 1
        while True:
            self.render(target)
            frames += 1
            if not self.needs_redraw or frames >= limit:
                return frames

    def release(self) -> None:
        self._release_targets()
        self.programs.release(self._mesh.forget if self._mesh is not None else None)
        self.lighting.release()
        if self._mesh is not None:
            self._mesh.release()
        for t in self._textures.values():
            t.release()
        if self._ibl is not None:
            self._ibl.release()
            self._env_cube.release()
