"""One scene frame into the multisampled HDR target: the environment background, the material
on the mesh and the light gizmos, then the resolve.

Forward, the mesh's FORWARD program draws (blended) into the target. Deferred, its GBUFFER
program fills the G-buffer (sharing the target's depth) and the lighting pass shades it into
the target over the background, which was drawn first into a one-sample texture.
"""

from __future__ import annotations

import moderngl
import numpy as np

from matedit.render.camera import sphere_screen_bounds
from matedit.render.deferred import ENERGY_COMPENSATION, LightingPass
from matedit.render.environment import EnvironmentLighting
from matedit.render.frames import SceneTargets
from matedit.render.fullscreen import FullscreenQuad
from matedit.render.gizmos import Gizmos
from matedit.render.material import MaterialResources
from matedit.render.mesh import GpuMesh
from matedit.render.programs import bind_program
from matedit.render.settings import PreviewSettings
from matedit.render.uniforms import SceneUniforms
from matedit.shading.ibl import IBL_MODE_REFERENCE
from matedit.shading.views import lobe_mask


class ScenePass:
    """The scene's shared inputs (uniform blocks, environment) and passes (lighting, gizmos)."""

    def __init__(self, ctx: moderngl.Context, samples: int, quad: FullscreenQuad,
                 settings: PreviewSettings, prelink: bool = False) -> None:
        """`prelink`: the split-sum lighting program now, at start-up (the deferred path)."""
        self.ctx = ctx
        self.uniforms = SceneUniforms(ctx, settings.lights)
        self.environment = EnvironmentLighting(ctx, quad)
        self.gizmos = Gizmos(ctx)
        self.lighting = LightingPass(ctx, samples, bind_program, quad)
        if prelink:
            self.lighting.program(True, False)

    def draw(self, view: PreviewSettings, targets: SceneTargets, mesh: GpuMesh | None,
             program: moderngl.Program | None, forward: bool, material: MaterialResources,
             ibl_mode: int, offset=(0.0, 0.0)) -> None:
        """The scene as `view` shows it, the mesh drawn with `program` (none: no mesh) on the
        forward or the deferred path, with IBL mode `ibl_mode` (reference: sample set rotated
        by `offset`), into `targets` and resolved."""
        ctx, reference = self.ctx, ibl_mode == IBL_MODE_REFERENCE
        vp = self.uniforms.write_frame(view.camera, targets.size, view.time, view.exposure)
        drawn = program is not None and mesh is not None
        deferred = drawn and not forward
        targets.begin_background(deferred)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        if view.show_background:
            self.environment.draw_background(vp, view.background_blur,
                                             view.environment_intensity)
        if drawn:
            self.uniforms.bind()
            self.environment.bind(ibl_mode, view.environment_intensity, view.reference_samples,
                                  offset, reference and view.reference_lights)
            material.bind(program)
            if deferred:
                targets.begin_gbuffer()
            ctx.enable(moderngl.DEPTH_TEST | (0 if deferred else moderngl.BLEND))
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            # An opaque surface (the G-buffer, or a forward material of opacity 1: blending
            # then replaces) of a closed mesh seen from outside hides its back faces, which
            # would only cost their fragments' material and lighting code (llvmpipe shades
            # them before the depth test drops them): they are culled. Translucent materials
            # and open meshes draw both sides.
            cull = (deferred or material.opaque) and mesh.closed and mesh.seen_from_outside(
                view.camera, targets.size[0] / max(1, targets.size[1]))
            if cull:
                ctx.front_face, ctx.cull_face = "ccw", "back"
                ctx.enable(moderngl.CULL_FACE)
            mesh.render(program)
            ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
            if deferred:
                targets.begin_lighting()
                compensation = view.energy_compensation or \
                    ENERGY_COMPENSATION in material.compiled.ir.defines
                background = targets.background.color_attachments[0]
                # Lit only where the mesh may be: on llvmpipe the lighting program costs
                # much of its price on background pixels too (its edge path runs, masked,
                # for every vector it rasterizes: about 12 ms of a 512 px frame of the sample
                # sphere). The rest of the target gets the background the pass would have
                # written there, so the image is the same.
                rect = mesh_rect(mesh, view.camera, targets.size)
                lit = True
                if rect is not None:
                    self.lighting.copy_background(background)
                    lit = targets.narrow(rect)
                if lit:
                    self.lighting.draw(targets.gbuffer, background,
                                       np.array(view.camera.eye, "f4"), not reference,
                                       compensation, lobe_mask(getattr(view, "view", "lit")))
                targets.widen()
        if view.show_gizmos:
            ctx.enable(moderngl.DEPTH_TEST)
            self.gizmos.draw(vp, view.lights)
        ctx.disable(moderngl.DEPTH_TEST)
        targets.resolve()

    def release(self) -> None:
        for part in (self.lighting, self.gizmos, self.environment, self.uniforms):
            part.release()


# pixels added around the mesh's rectangle (rounding, and samples within the border pixels)
RECT_MARGIN_PX = 2


def mesh_rect(mesh: GpuMesh, camera, size: tuple[int, int]) -> tuple[int, int, int, int] | None:
    """The pixels (x, y, width, height; GL's window coordinates) that hold every sample the
    mesh may cover, from its bounding sphere's projection (camera.sphere_screen_bounds); None
    when they are not known to be fewer than the whole frame."""
    w, h = size
    centre, radius = mesh.bounding_sphere()
    b = sphere_screen_bounds(centre, radius, camera.view_matrix(),
                             camera.projection(w / max(1, h)))
    if b is None:
        return None
    x0, y0, x1, y1 = b
    px0 = max(0, int(np.floor((x0 + 1.0) * 0.5 * w)) - RECT_MARGIN_PX)
    py0 = max(0, int(np.floor((y0 + 1.0) * 0.5 * h)) - RECT_MARGIN_PX)
    px1 = min(w, int(np.ceil((x1 + 1.0) * 0.5 * w)) + RECT_MARGIN_PX)
    py1 = min(h, int(np.ceil((y1 + 1.0) * 0.5 * h)) + RECT_MARGIN_PX)
    if (px0, py0, px1, py1) == (0, 0, w, h):
        return None
    return px0, py0, max(0, px1 - px0), max(0, py1 - py0)
