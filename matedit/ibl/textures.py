"""Upload a bake to moderngl textures for the renderer.

    from matedit.ibl import bake, upload
    ibl = upload(ctx, bake("studio"))
    ibl.use(prefiltered=5, lut=6)          # texture units
    prog["uPrefiltered"] = 5; prog["uBrdfLut"] = 6
    prog["uPrefilteredLevels"] = float(ibl.levels)   # M; sample at roughness * (M - 1)
    prog["uIrradianceSH"].write(ibl.sh.astype("f4").tobytes())  # uniform vec3 [9]

GLSL side (docs/shading.md#image-based-lighting, split sum):

    vec3 pre = textureLod(uPrefiltered, R, roughness * (uPrefilteredLevels - 1.0)).rgb;
    vec2 AB = texture(uBrdfLut, vec2(NoV, roughness)).rg;
    vec3 specular = pre * (F0 * AB.x + AB.y);
    vec3 E = sum_i uIrradianceSH[i] * Y_i(N);        // basis in matedit/ibl/sh.py
    vec3 diffuse = diffuseColor * E / PI;

The cube is RGB32F with levels 0..M-1 (GL_TEXTURE_MAX_LEVEL = M - 1), trilinear, and
`upload` enables GL_TEXTURE_CUBE_MAP_SEAMLESS on the context (core profile default is off).
The LUT is RGB32F (A, B, the Charlie sheen's albedo E), bilinear, clamped to edge.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from dataclasses import dataclass
from functools import cache

import moderngl
import numpy as np

from matedit.ibl.bake import IBLBake

GL_TEXTURE_CUBE_MAP_SEAMLESS = 0x884F
GL_TEXTURE_CUBE_MAP_POSITIVE_X = 0x8515
GL_RGB = 0x1907
GL_FLOAT = 0x1406
GL_UNPACK_ALIGNMENT = 0x0CF5


@dataclass
class IBLTextures:
    """GPU copies of an `IBLBake`; release() when done (or let the context go)."""

    prefiltered: moderngl.TextureCube
    brdf_lut: moderngl.Texture
    sh: np.ndarray
    levels: int

    def use(self, prefiltered: int = 0, lut: int = 1) -> None:
        """Bind the cube and the LUT to the given texture units."""
        self.prefiltered.use(location=prefiltered)
        self.brdf_lut.use(location=lut)

    def release(self) -> None:
        self.prefiltered.release()
        self.brdf_lut.release()


@cache
def _gl():
    """Core GL 1.1 entry points, which moderngl does not expose for cube mip levels.

    They dispatch to whichever context is current (GLVND), EGL or Qt's alike.
    """
    for name in ("OpenGL", "GL", "opengl32"):
        path = ctypes.util.find_library(name)
        if not path:
            continue
        try:
            lib = ctypes.CDLL(path)
            sub = lib.glTexSubImage2D
            store = lib.glPixelStorei
        except (OSError, AttributeError):
            continue
        sub.restype = None
        sub.argtypes = [
            ctypes.c_uint,
            ctypes.c_int,
            ctypes.c_int,
            ctypes.c_int,
            ctypes.c_int,
            ctypes.c_int,
            ctypes.c_uint,
            ctypes.c_uint,
            ctypes.c_void_p,
        ]
        store.restype = None
        store.argtypes = [ctypes.c_uint, ctypes.c_int]
        return sub, store
    raise RuntimeError("cannot find the OpenGL library to upload cube map mip levels")


def upload_cube(ctx: moderngl.Context, mips: list[np.ndarray], unit: int | None = None):
    """A trilinear RGB32F cube map whose level m holds mips[m] (each (6, s, s, 3))."""
    n = mips[0].shape[1]
    tex = ctx.texture_cube((n, n), 3, dtype="f4")
    for face in range(6):
        tex.write(face, np.ascontiguousarray(mips[0][face], dtype=np.float32).tobytes())
    levels = len(mips)
    # Allocates levels 1..M-1 (and sets BASE/MAX_LEVEL), which are then overwritten.
    tex.build_mipmaps(0, levels - 1)
    if levels > 1:
        sub, store = _gl()
        # Bind through moderngl so the binding it tracks stays true, on a spare unit.
        tex.use(location=unit if unit is not None else ctx.info["GL_MAX_TEXTURE_IMAGE_UNITS"] - 1)
        store(GL_UNPACK_ALIGNMENT, 1)
        for m in range(1, levels):
            mip = mips[m]
            s = mip.shape[1]
            for face in range(6):
                data = np.ascontiguousarray(mip[face], dtype=np.float32)
                sub(
                    GL_TEXTURE_CUBE_MAP_POSITIVE_X + face,
                    m,
                    0,
                    0,
                    s,
                    s,
                    GL_RGB,
                    GL_FLOAT,
                    data.ctypes.data,
                )
    tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    ctx.enable_direct(GL_TEXTURE_CUBE_MAP_SEAMLESS)
    return tex


def upload_lut(ctx: moderngl.Context, lut: np.ndarray) -> moderngl.Texture:
    """The (N, N, 3) LUT as an RGB32F texture (a two-channel one as RG32F: its blue, the
    sheen's albedo, then reads 0); texture coordinates (NoV, roughness)."""
    h, w = lut.shape[:2]
    tex = ctx.texture(
        (w, h), lut.shape[2], data=np.ascontiguousarray(lut, dtype=np.float32).tobytes(), dtype="f4"
    )
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x = tex.repeat_y = False
    return tex


def upload(ctx: moderngl.Context, result: IBLBake) -> IBLTextures:
    """Upload a bake: prefiltered cube with mips, LUT, and the SH coefficients (CPU side)."""
    return IBLTextures(
        prefiltered=upload_cube(ctx, result.mips),
        brdf_lut=upload_lut(ctx, result.lut),
        sh=np.asarray(result.sh, dtype=np.float64),
        levels=len(result.mips),
    )
