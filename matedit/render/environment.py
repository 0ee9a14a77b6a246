"""Environment lighting on the GPU: the baked environment (prefiltered cube, BRDF LUT, SH
irradiance; baked and cached by matedit.ibl), the unfiltered cube behind the mesh and for
reference mode with its importance-sampling table (matedit.ibl.importance, built when an
environment is set: ~0.1 s for a 256² cube), the IblBlock uniform buffer, and the
background pass."""

from __future__ import annotations

import math
from pathlib import Path

import moderngl
import numpy as np

from matedit.glsl.layout import BINDINGS, IBL_BLOCK
from matedit.ibl.importance import distribution_from_cube
from matedit.render.fullscreen import FullscreenQuad, mat_bytes, render_program
from matedit.shading.ibl import IBL_MODE_NONE, pack_ibl_block

PREFILTERED_UNIT, LUT_UNIT, ENVIRONMENT_UNIT, DISTRIBUTION_UNIT, ANISOTROPY_LUT_UNIT = (
    BINDINGS[k] for k in ("PREFILTERED_ENV", "BRDF_LUT", "ENVIRONMENT", "ENV_DISTRIBUTION",
                          "ANISOTROPY_LUT"))
# SH irradiance coefficients -> radiance coefficients: divide by the cosine lobe's A_l
# (Ramamoorthi and Hanrahan 2001): pi, 2pi/3, pi/4 for bands 0, 1, 2.
SH_BAND_SCALE = np.array([math.pi] + [2 * math.pi / 3] * 3 + [math.pi / 4] * 5)


def upload_distribution(ctx: moderngl.Context, faces: np.ndarray) -> moderngl.Texture:
    """The importance-sampling table of cube faces (6, n, n, 3) as an RG32F texture,
    (W + 1) x H texels, read with texelFetch (matedit.ibl.importance for the layout)."""
    table = distribution_from_cube(faces).table
    h, w1 = table.shape[:2]
    tex = ctx.texture((w1, h), 2, np.ascontiguousarray(table, dtype="f4").tobytes(), dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    return tex


class EnvironmentLighting:
    """One environment at a time (`set`), none before; `bind` before drawing a lit program."""

    def __init__(self, ctx: moderngl.Context, quad: FullscreenQuad) -> None:
        self.ctx = ctx
        self._quad = quad
        self._background = render_program(ctx, "fullscreen.vert", "background.frag")
        self._block = ctx.buffer(reserve=IBL_BLOCK.size)
        self._ibl = None  # matedit.ibl.IBLTextures
        self._cube: moderngl.TextureCube | None = None
        self._distribution: moderngl.Texture | None = None  # env_sampling.glsl's table
        # anisotropy.glsl's environment BRDF table (read only by anisotropic programs)
        self._anisotropy_lut: moderngl.Texture3D | None = None
        self.levels = 1
        self.sh = np.zeros((9, 3))  # radiance coefficients
        self.warnings: list[str] = []

    @property
    def loaded(self) -> bool:
        return self._ibl is not None

    def set(self, spec: str | Path, settings=None, progress=None) -> None:
        """A built-in name (studio, sky) or an HDR/EXR file, baked (cached) and uploaded;
        `progress(fraction)`."""
        from matedit.ibl import bake, upload

        result = bake(spec, settings, ctx=self.ctx,
                      progress=(lambda f, m: progress(f)) if progress else None)
        self._release_textures()
        self._ibl = upload(self.ctx, result)
        base = result.mips[0]
        n = base.shape[1]
        cube = self.ctx.texture_cube((n, n), 3, dtype="f4")
        for face in range(6):
            cube.write(face, np.ascontiguousarray(base[face, ..., :3], dtype="f4").tobytes())
        cube.build_mipmaps()
        cube.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        self._cube = cube
        self._distribution = upload_distribution(self.ctx, base)
        self.levels = result.levels
        self.sh = np.asarray(result.sh, dtype=np.float64) / SH_BAND_SCALE[:, None]
        self.warnings = list(result.warnings)

    def _use_textures(self) -> None:
        self._ibl.prefiltered.use(location=PREFILTERED_UNIT)
        self._ibl.brdf_lut.use(location=LUT_UNIT)
        self._cube.use(location=ENVIRONMENT_UNIT)
        self._distribution.use(location=DISTRIBUTION_UNIT)
        if self._anisotropy_lut is None:
            from matedit.ibl.anisotropy_lut import upload_anisotropy_lut

            self._anisotropy_lut = upload_anisotropy_lut(self.ctx)
        self._anisotropy_lut.use(location=ANISOTROPY_LUT_UNIT)

    def draw_background(self, view_projection: np.ndarray, blur: float,
                        intensity: float) -> None:
        """The environment behind the mesh into the bound target (nothing when none is set);
        `blur` in [0, 1] reads that fraction of the prefiltered mips."""
        if self._ibl is None:
            return
        self._use_textures()
        bg = self._background
        bg["uEnvironmentCube"].value = PREFILTERED_UNIT if blur > 0 else ENVIRONMENT_UNIT
        bg["uInvViewProjection"].write(mat_bytes(np.linalg.inv(view_projection)))
        bg["uLod"].value = float(blur * (self.levels - 1))
        bg["uIntensity"].value = float(intensity)
        self._quad.draw(bg)

    def bind(self, mode: int, intensity: float, samples: int, offset=(0.0, 0.0),
             reference_lights: bool = False) -> None:
        """Writes and binds IblBlock (mode NONE without an environment) and binds the
        environment's textures to their units."""
        self._block.write(pack_ibl_block(
            self.sh, float(self.levels), intensity, samples,
            mode if self._ibl is not None else IBL_MODE_NONE, offset,
            reference_lights=reference_lights))
        self._block.bind_to_uniform_block(BINDINGS["IBL"])
        if self._ibl is not None:
            self._use_textures()

    def _release_textures(self) -> None:
        if self._ibl is not None:
            self._ibl.release()
            self._cube.release()
            self._distribution.release()
        self._ibl = self._cube = self._distribution = None

    def release(self) -> None:
        self._release_textures()
        if self._anisotropy_lut is not None:
            self._anisotropy_lut.release()
            self._anisotropy_lut = None
        self._block.release()
        self._background.release()
