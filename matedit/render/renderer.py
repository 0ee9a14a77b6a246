"""The preview renderer: moderngl only, no Qt; any context (headless EGL or Qt's).

A frame: the scene (background, the material on the mesh, light gizmos; scene.ScenePass) in a
multisampled HDR target, resolved, reference frames accumulated, then the display pass or the
difference heat map (frames.Accumulator). Opaque materials take the deferred path (GBUFFER
entry, one shared lighting pass), translucent ones the forward path (FORWARD entry). Programs:
programs.ProgramCache; parameter buffer and textures: material.MaterialResources.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import moderngl
import numpy as np

from matedit.compiler.api import CompiledMaterial, compile_ir
from matedit.compiler.ir import MaterialIR, Scope
from matedit.render.frames import Accumulator, SceneTargets, r2_offset
from matedit.render.fullscreen import FullscreenQuad
from matedit.render.material import MaterialResources
from matedit.render.mesh import GpuMesh, mesh_from_spec
from matedit.render.paths import wants_forward
from matedit.render.programs import MaterialStatus, ProgramCache
from matedit.render.scene import ScenePass
from matedit.render.settings import MODES, PreviewSettings
from matedit.render.slicing import BandPlanner
from matedit.shading.ibl import IBL_MODE_REFERENCE
from matedit.shading.lights import Light
from matedit.shading.views import check_view, is_attribute_view

__all__ = ["MODES", "MaterialStatus", "Renderer", "r2_offset"]


class Renderer(PreviewSettings):
    """Draws one material on a preview mesh. See the module docstring for the passes, and
    PreviewSettings for the attributes a caller sets between frames."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int] = (512, 512),
                 samples: int = 4, environment: str | None = "studio",
                 bake_settings=None, deferred: bool = True, warm_up: bool = True) -> None:
        super().__init__()
        self.ctx, self.samples = ctx, samples
        # deferred preview (GBUFFER entry + one lighting pass) for opaque materials; forward
        # (FORWARD entry) for materials that write opacity, or when asked
        self.deferred = bool(deferred) and samples >= 2
        self.is_forward = True  # the current material's path
        # structure hash of the material drawn forward once the editor was idle
        # (promote_forward), and of one whose forward program failed to link (not tried again)
        self._promoted: str | None = None
        self._not_promoted: str | None = None
        self.bake_settings = bake_settings
        self.environment_name = ""  # none until set_environment
        self.environment_warnings: list[str] = []
        self._size = (0, 0)
        self._program: moderngl.Program | None = None
        self._mesh: GpuMesh | None = None
        self.mesh_name = "sphere"
        self.programs = ProgramCache(ctx)
        self._programs = self.programs.table  # variant structure hash -> program
        self.material = MaterialResources(ctx)
        self._quad = FullscreenQuad(ctx)
        self.scene = ScenePass(ctx, samples, self._quad, self, prelink=self.deferred)
        self.lighting = self.scene.lighting
        self.accumulator = Accumulator(ctx, self._quad)
        # reference and difference frames drawn in bands of about this many ms a render()
        # call (the editor's viewport sets it; None: whole frames, as the CLI draws)
        self.slice_budget_ms: float | None = None
        self.planner = BandPlanner()
        self.targets: SceneTargets | None = None
        # A/B split: another material drawn left of `split` (a fraction of the width), the
        # current one right of it (set_compare); None: the current material everywhere
        self.compare: _CompareSlot | None = None
        self.split = 0.5
        self.set_mesh("sphere")
        self.resize(*size)
        if environment is not None:
            self.set_environment(environment)
        if self.deferred and warm_up:  # False: the first frame is a deferred material's
            self._warm_up()

    def _warm_up(self) -> None:
        """The driver compiles at a program's first draw (and builds its per-framebuffer state
        the first time a target is used): one frame of a constant material now, at start-up,
        so that the lighting pass and the G-buffer targets cost nothing at the first edit."""
        self.set_material(compile_ir(MaterialIR(Scope("evaluateMaterial"), [], [], [], set(),
                                                [])))
        self.render()
        self._program = self.material.compiled = None

    @property
    def _compiled(self) -> CompiledMaterial | None:
        return self.material.compiled

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
        self.accumulator.resize(self._size)

    def _release_targets(self) -> None:
        if self.targets is not None:
            self.targets.release()
        self.targets = None
        self.accumulator.release_targets()

    def reset_accumulation(self) -> None:
        self.accumulator.frames = 0

    def set_mesh(self, spec: str | Path) -> None:
        """A built-in mesh name or an OBJ path; raises MeshError (a ValueError) on bad files."""
        data = mesh_from_spec(spec)
        if self._mesh is not None:
            self._mesh.release()
        self._mesh = GpuMesh(self.ctx, data)
        self.mesh_name = str(spec)
        self.reset_accumulation()

    def set_lights(self, lights: list[Light]) -> None:
        self.lights = self.scene.uniforms.set_lights(lights)
        self.reset_accumulation()

    def set_environment(self, spec: str | Path, progress=None) -> None:
        """A built-in name (studio, sky) or an HDR/EXR file, baked (cached) and uploaded."""
        self.scene.environment.set(spec, self.bake_settings, progress)
        self.environment_name = str(spec)
        self.environment_warnings = list(self.scene.environment.warnings)
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
        promoted = self._promoted
        if promoted != compiled.structure_hash:
            self._promoted = None  # a new program: the deferred one, quick to link and JIT
        forward = self._forward(compiled, values)
        prog = self.programs.link(compiled, forward, self.energy_compensation, self.view)
        if isinstance(prog, MaterialStatus):  # located in the variant that failed
            self._promoted = promoted  # the last good material is still drawn
            return prog
        self._program, self.is_forward = prog, forward
        self.material.load(compiled, values)
        self.reset_accumulation()
        return MaterialStatus(True)

    def set_compare(self, compiled: CompiledMaterial | None, values: dict[str, Any] | None = None,
                    textures: dict[str, str | None] | None = None) -> MaterialStatus:
        """A/B split: `compiled` (with these uniform values and texture files) drawn on the
        part of the frame left of `split`, the current material on the rest; None ends the
        split. Programs come from the same cache as the current material's."""
        if compiled is None:
            if self.compare is not None:
                self.compare.resources.release()
                self.compare = None
                self.reset_accumulation()
            return MaterialStatus(True)
        vals = {u.name: u.default for u in compiled.ir.uniforms}
        vals.update(values or {})
        forward = self._forward(compiled, vals)
        prog = self.programs.link(compiled, forward, self.energy_compensation, self.view)
        if isinstance(prog, MaterialStatus):
            return prog
        slot = self.compare or _CompareSlot(MaterialResources(self.ctx))
        slot.program, slot.forward = prog, forward
        slot.resources.load(compiled, vals)
        for name, path in (textures or {}).items():
            slot.resources.set_texture(name, path)
        self.compare = slot
        self.reset_accumulation()
        return MaterialStatus(True)

    def set_split(self, fraction: float) -> None:
        """Where the A/B split's divider is, as a fraction of the width (0.05 .. 0.95)."""
        fraction = min(0.95, max(0.05, float(fraction)))
        if fraction != self.split:
            self.split = fraction
            if self.compare is not None:
                self.reset_accumulation()

    def _forward(self, compiled: CompiledMaterial, values: dict) -> bool:
        """The path a material takes: forward when not deferred, when the material wants it
        (translucent, lobes beyond the talk), in an attribute view (FORWARD entry only), or
        once promoted (promote_forward) while the view is the lit one (a lobe view is a
        variant of the lighting pass, linked once)."""
        return not self.deferred or is_attribute_view(self.view) or \
            wants_forward(compiled, values) or \
            (self._promoted == compiled.structure_hash and self.view == "lit")

    @property
    def promoted(self) -> bool:
        """Whether the current material is drawn forward by promote_forward."""
        c = self._compiled
        return c is not None and self._promoted == c.structure_hash

    @property
    def can_promote(self) -> bool:
        """Whether promote_forward would try something: a material on the deferred path, in
        split-sum mode without an A/B split, not refused before."""
        c = self._compiled
        return (self.deferred and c is not None and self._program is not None
                and not self.is_forward and self.mode == "splitsum" and self.view == "lit"
                and self.compare is None and self._not_promoted != c.structure_hash)

    def promote_forward(self) -> bool:
        """The current material drawn forward from now on, until the next structural edit.
        On llvmpipe a forward frame takes about half a deferred one's time at the editor's
        viewport size (no G-buffer to fill, clear and read back, no per-sample edge test),
        while the deferred program is the quicker to link and JIT after a structural edit:
        the render server draws an edit's first frames deferred and asks for this once it has
        been idle a while (matedit.render.server). Reference and difference modes keep
        drawing the deferred program (their lighting pass is linked). Returns whether the
        path changed (False: nothing to promote, or the forward program failed to link,
        which is not tried again for this material)."""
        if not self.can_promote:
            return False
        c = self._compiled
        try:
            prog = self.programs.material(c, True, self.energy_compensation, self.view)
        except moderngl.Error:
            self._not_promoted = c.structure_hash
            return False
        self._promoted = c.structure_hash
        self._program, self.is_forward = prog, True
        self.reset_accumulation()
        return True

    def set_view(self, view: str) -> None:
        """The viewport's view (matedit.shading.views; ValueError for an unknown one): a lobe
        view relinks the material's FORWARD variant (or uses the lighting pass's, deferred),
        an attribute view its FORWARD variant; each is linked once and then cached. On a link
        failure the view stays as it was (and the error is raised)."""
        check_view(view)
        if view == self.view:
            return
        old, self.view = self.view, view
        if self._compiled is not None:
            forward = self._forward(self._compiled, self.material.values)
            try:
                self._program = self.programs.material(self._compiled, forward,
                                                       self.energy_compensation, view)
            except moderngl.Error:
                self.view = old
                raise
            self.is_forward = forward
        self._relink_compare()
        self.reset_accumulation()

    def _relink_compare(self) -> None:
        """The A side's program for the current view and energy compensation."""
        c = self.compare
        if c is not None and c.resources.compiled is not None:
            c.forward = self._forward(c.resources.compiled, c.resources.values)
            c.program = self.programs.material(c.resources.compiled, c.forward,
                                               self.energy_compensation, self.view)

    @property
    def has_material(self) -> bool:
        """Whether a material program is drawn on the mesh (False: the scene without it)."""
        return self._program is not None

    def clear_material(self) -> None:
        """Draw no material until the next `set_material`: the program linked for another
        document must not stand in for one that has none (the programs stay cached)."""
        self._program = self.material.compiled = None
        self.reset_accumulation()

    def set_energy_compensation(self, on: bool) -> None:
        """The preview's multiple-scattering compensation option (relinks once per state)."""
        if bool(on) == self.energy_compensation:
            return
        self.energy_compensation = bool(on)
        if self._compiled is not None:
            self._program = self.programs.material(self._compiled, self.is_forward, bool(on),
                                                   self.view)
        self._relink_compare()
        self.reset_accumulation()

    def set_uniforms(self, values: dict[str, Any]) -> None:
        """Parameter edit: rewrite the MaterialParams buffer; never links a program, except
        once when opacity crosses 1 and the material changes path."""
        if self._compiled is None:
            return
        self.material.set_values(values)
        forward = self._forward(self._compiled, self.material.values)
        if forward != self.is_forward:
            try:
                self._program = self.programs.material(self._compiled, forward,
                                                       self.energy_compensation, self.view)
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
        return self.mode == "splitsum" or self.accumulator.frames >= self.reference_frames

    @property
    def accumulated_frames(self) -> int:
        """Reference frames averaged so far (converged at `reference_frames`)."""
        return self.accumulator.frames

    def _scene(self, ibl_mode: int, offset=(0.0, 0.0), band=None) -> None:
        """The scene into the targets, only the rows of `band` (x, y, w, h) when given; with
        an A/B split, the compared material left of the divider and the current one right."""
        parts = [(self._program, self.is_forward, self.material, band)]
        if self.compare is not None and self._program is not None:
            w, h = self.targets.size
            cut = int(round(self.split * w))
            c, whole = self.compare, band or (0, 0, w, h)
            parts = [p for p in ((c.program, c.forward, c.resources, _clip(whole, 0, cut)),
                                 (self._program, self.is_forward, self.material,
                                  _clip(whole, cut, w))) if p[3] is not None]
        for program, forward, material, rect in parts:
            if forward and self.mode != "splitsum" and material is self.material \
                    and self.promoted:
                # promoted for split-sum frames only: the deferred program (linked first)
                program, forward = self.programs.material(
                    material.compiled, False, self.energy_compensation, self.view), False
            if ibl_mode == IBL_MODE_REFERENCE and forward and material.compiled is not None:
                program = self.programs.reference(material.compiled, self.energy_compensation,
                                                  fallback=program, view=self.view)
            self.targets.scissor = rect
            try:
                self.scene.draw(self, self.targets, self._mesh, program, forward, material,
                                ibl_mode, offset)
            finally:
                self.targets.scissor = None

    def render(self, target: moderngl.Framebuffer | None = None) -> None:
        """Draws one frame into `target` (default: an internal sRGB8 image, see read_image).
        With `slice_budget_ms` set, reference and difference mode draw as much of their next
        frame as fits that budget (frames.Accumulator.draw_sliced): call again while
        `needs_redraw`."""
        if self.slice_budget_ms is not None:
            self.planner.budget_ms = float(self.slice_budget_ms)
            self.accumulator.draw_sliced(self.mode, self.reference_frames, self._scene,
                                         self.targets.resolved, target, self.exposure,
                                         self.planner)
            return
        self.accumulator.draw(self.mode, self.reference_frames, self._scene,
                              self.targets.resolved, target, self.exposure)

    def advance(self) -> int:
        """With `slice_budget_ms` set, reference or difference mode's next bands within that
        budget, without a display (the next `render` shows them); returns the bands drawn
        (0 when converged, in split-sum mode or without a budget)."""
        if self.slice_budget_ms is None or self.mode == "splitsum":
            return 0
        self.planner.budget_ms = float(self.slice_budget_ms)
        return self.accumulator.advance(self.mode, self.reference_frames, self._scene,
                                        self.targets.resolved, self.planner)

    def display(self, target: moderngl.Framebuffer) -> None:
        """The display pass alone into `target`: the frame as far as `advance` has drawn it
        (split sum until the first reference frame is complete), no new bands."""
        a = self.accumulator
        a.display(target, "splitsum" if a.frames == 0 and self.mode != "splitsum" else
                  self.mode, self.targets.resolved, self.exposure)

    @property
    def difference_mean(self) -> float | None:
        """Mean |split-sum - reference| of the last difference frame, linear HDR (read back
        from the GPU when asked, once per frame drawn, not on every frame)."""
        return self.accumulator.difference_mean(self.mode, self.targets.resolved)

    def render_converged(self, target=None, max_frames: int | None = None) -> int:
        """Renders until reference/difference mode has converged; returns frames drawn."""
        limit = max_frames if max_frames is not None else self.reference_frames + 1
        frames = 0
        budget, self.slice_budget_ms = self.slice_budget_ms, None  # whole frames here
        try:
            while True:
                self.render(target)
                frames += 1
                if not self.needs_redraw or frames >= limit:
                    return frames
        finally:
            self.slice_budget_ms = budget

    def set_reference_samples(self, total: int) -> None:
        """Reference mode's samples a pixel: up to 32 a frame, accumulated over frames."""
        total = max(1, int(total))
        self.reference_samples = min(32, total)
        self.reference_frames = max(1, math.ceil(total / self.reference_samples))
        self.reset_accumulation()

    # --- reading back ---------------------------------------------------------------------
    def read_image(self) -> np.ndarray:
        """The last frame drawn into the internal target: (H, W, 3) float sRGB, top row first."""
        return self.accumulator.read_image()

    def read_hdr(self, which: str | None = None) -> np.ndarray:
        """Linear HDR (H, W, 3), top row first: the split-sum frame or the reference average."""
        which = which or ("splitsum" if self.mode == "splitsum" else "reference")
        return self.accumulator.read_hdr(which, self.mode, self.targets.resolved)

    def read_linear(self) -> np.ndarray:
        """The scene-referred linear radiance of the current mode's frame, (H, W, 3), top row
        first, before exposure and the display transform: split sum, the reference average,
        or in difference mode split sum minus reference (signed)."""
        return self.accumulator.read_linear(self.mode, self.targets.resolved)

    def release(self) -> None:
        self._release_targets()
        self.programs.release(self._mesh.forget if self._mesh is not None else None)
        self.set_compare(None)
        for part in (self.scene, self._mesh, self.material, self.accumulator, self._quad):
            if part is not None:
                part.release()


class _CompareSlot:
    """The A side of an A/B split: its program, path and resources."""

    def __init__(self, resources: MaterialResources) -> None:
        self.resources = resources
        self.program: moderngl.Program | None = None
        self.forward = True


def _clip(band: tuple[int, int, int, int], x0: int, x1: int):
    """`band` (x, y, w, h) within columns x0 .. x1, None when nothing is left."""
    x, y, w, h = band
    left, right = max(x, x0), min(x + w, x1)
    return (left, y, right - left, h) if right > left else None
