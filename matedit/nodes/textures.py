"""Texture sampling."""

from __future__ import annotations

import math
import struct
from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    MESH_UV,
    UNIT,
    MxRecipe,
    NodeDef,
    Role,
    Thumbnail,
    _i,
    _o,
    register,
)
from matedit.nodes.twin import _col

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



def sample_bilinear(tex: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """GL_LINEAR, GL_REPEAT, no mipmaps: texel (i, j) is centred at ((i + 0.5)/W, (j + 0.5)/H)
    and row j = 0 of `tex` (H, W, C) is v = 0, as moderngl uploads it. Returns (N, C)."""
    h, w = tex.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = uv[:, 1] * h - 0.5
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = _col(x - x0)
    fy = _col(y - y0)
    i0 = x0.astype(np.int64) % w
    j0 = y0.astype(np.int64) % h
    i1 = (i0 + 1) % w
    j1 = (j0 + 1) % h
    top = tex[j0, i0] * (1.0 - fx) + tex[j0, i1] * fx
    bottom = tex[j1, i0] * (1.0 - fx) + tex[j1, i1] * fx
    return top * (1.0 - fy) + bottom * fy


def _texture_sample(ctx, tex, uv):
    rgba = sample_bilinear(np.asarray(tex), uv).astype(uv.dtype, copy=False)
    return rgba, rgba[:, :3], rgba[:, 0], rgba[:, 1], rgba[:, 2], rgba[:, 3]


# --- textures and procedurals ----------------------------------------------------------------
register(NodeDef(
    "texture_sample", "Texture Sample", "Texture", "Samples a texture at uv (mesh UVs if unset).",
    inputs=(_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
            _i("uv", "vec2", MESH_UV, "texture coordinates")),
    outputs=(_o("rgba", "vec4"), _o("rgb", "vec3"), _o("r", "float"), _o("g", "float"),
             _o("b", "float"), _o("a", "float")),
    glsl="node_texture_sample", role=Role.TEXTURE_SAMPLE, impure=True,
    thumbnail=Thumbnail.ALWAYS, mtlx=MxRecipe("image_read"),
    numpy=_texture_sample,  # image (vector4)
))


# MaterialX image's address modes (its uaddressmode / vaddressmode enum), by the code the
# Addressed Texture Sample's u_address / v_address inputs take.
ADDRESS_MODES = ("periodic", "clamp", "mirror", "constant")
# ... and its filter types, by the code of the filter input (cubic has no code: MaterialX's
# GLSL renderer reads it as linear, see docs/materialx.md).
FILTER_TYPES = ("linear", "closest")


def _addressed_index(i: np.ndarray, n: int, mode: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Texel index `i` (any integer) of an axis of `n` texels under each element's address
    mode, as OpenGL's samplers do it (what MaterialX's renderer binds): periodic GL_REPEAT,
    clamp GL_CLAMP_TO_EDGE, mirror GL_MIRRORED_REPEAT, constant GL_CLAMP_TO_BORDER.
    Returns (index in 0..n-1, whether the texel is in the image: False only for a
    constant-mode texel outside it, which reads the border colour)."""
    m = i % (2 * n)
    idx = np.select([mode == 0, mode == 2], [i % n, np.where(m < n, m, 2 * n - 1 - m)],
                    np.clip(i, 0, n - 1))
    inside = (mode != 3) | ((i >= 0) & (i < n))
    return idx, inside


def sample_addressed(tex: np.ndarray, uv: np.ndarray, default: np.ndarray, u_mode, v_mode,
                     closest) -> np.ndarray:
    """The texture read of MaterialX's image node, tap by tap: each of the (bilinear: four,
    closest: one) texels is addressed per axis (`_addressed_index`), a constant-mode texel
    outside the image reads `default` (the border colour), and the taps are weighted as
    GL_LINEAR does (texel (i, j) centred at ((i + 0.5)/W, (j + 0.5)/H), row 0 at v = 0, no
    mipmaps). `u_mode`, `v_mode`: ADDRESS_MODES codes; `closest`: nearest texel. (N, C)."""
    tex = np.asarray(tex)
    h, w = tex.shape[:2]
    count = len(uv)
    um = np.rint(np.clip(np.broadcast_to(u_mode, (count,)), 0, 3)).astype(np.int64)
    vm = np.rint(np.clip(np.broadcast_to(v_mode, (count,)), 0, 3)).astype(np.int64)
    near = np.broadcast_to(closest, (count,)) >= 0.5
    default = np.broadcast_to(default, (count, tex.shape[2])).astype(np.float64)
    uvd = uv.astype(np.float64)
    x = np.where(near, np.floor(uvd[:, 0] * w), uvd[:, 0] * w - 0.5)
    y = np.where(near, np.floor(uvd[:, 1] * h), uvd[:, 1] * h - 0.5)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = np.where(near, 0.0, x - x0), np.where(near, 0.0, y - y0)
    out = np.zeros((count, tex.shape[2]))
    for dx, wx in ((0, 1.0 - fx), (1, fx)):
        i, iu = _addressed_index(x0.astype(np.int64) + dx, w, um)
        for dy, wy in ((0, 1.0 - fy), (1, fy)):
            j, jv = _addressed_index(y0.astype(np.int64) + dy, h, vm)
            texel = np.where(_col(iu & jv), tex[j, i], default)
            out += texel * _col(wx * wy)
    return out


def _texture_sample_addressed(ctx, tex, uv, default_color, u_address, v_address, closest):
    rgba = sample_addressed(tex, uv, default_color, u_address, v_address, closest).astype(
        uv.dtype, copy=False)
    return rgba, rgba[:, :3], rgba[:, 0], rgba[:, 1], rgba[:, 2], rgba[:, 3]


_MODES_DOC = ", ".join(f"{k} {m}" for k, m in enumerate(ADDRESS_MODES))
register(NodeDef(
    "texture_sample_addressed", "Addressed Texture Sample", "Texture",
    "Samples a texture with MaterialX image addressing: outside 0..1 each axis repeats, "
    "clamps to its edge, mirrors or reads the default colour; linear or closest-texel "
    "filtering.",
    inputs=(_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
            _i("uv", "vec2", MESH_UV, "texture coordinates"),
            _i("default_color", "vec4", [0.0, 0.0, 0.0, 0.0], "the colour outside the image "
               "(constant addressing)"),
            _i("u_address", "float", 0.0, f"address mode along u: {_MODES_DOC}", (0.0, 3.0),
               limits=(0.0, 3.0)),
            _i("v_address", "float", 0.0, f"address mode along v: {_MODES_DOC}", (0.0, 3.0),
               limits=(0.0, 3.0)),
            _i("filter", "float", 0.0, "0 linear (bilinear), 1 closest texel", (0.0, 1.0),
               limits=(0.0, 1.0))),
    outputs=(_o("rgba", "vec4"), _o("rgb", "vec3"), _o("r", "float"), _o("g", "float"),
             _o("b", "float"), _o("a", "float")),
    glsl="node_texture_sample_addressed", role=Role.ADDRESSED_TEXTURE_SAMPLE, impure=True,
    thumbnail=Thumbnail.ALWAYS,
    numpy=_texture_sample_addressed,  # image (vector4) under its address modes
))


# --- hex tiling (Mikkelsen 2022, as MaterialX's hextiledimage parameterises it) -------------
def _to_f32(x: float) -> float:
    """x rounded to the nearest float32, as a Python float (numpy is not needed for it)."""
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


_SQRT3_2 = _to_f32(math.sqrt(3.0) * 2.0)  # the triangle grid's scale: keeps the image's fit
_SKEW = _to_f32(1.15470054)  # 2 tan 30: skewed space's v, and its inverse


def hex_hash(p: np.ndarray) -> np.ndarray:
    """Two uniform numbers in 0..1 per grid vertex (Dave Hoskins' hash without sine, the one
    hextiledimage uses), in float32 as the GPU computes it. p: (N, 2)."""
    f32 = np.float32
    p = p.astype(f32)
    p3 = np.stack([p[:, 0], p[:, 1], p[:, 0]], -1) * np.asarray([0.1031, 0.1030, 0.0973], f32)
    p3 = p3 - np.floor(p3)
    d: np.ndarray = np.asarray(np.sum(p3 * (p3[:, [1, 2, 0]] + f32(33.33)), -1, dtype=f32))
    p3 = p3 + d[:, None]
    h = (p3[:, [0, 0]] + p3[:, [1, 2]]) * p3[:, [2, 1]]
    return h - np.floor(h)


def _gain(x: np.ndarray, r) -> np.ndarray:
    """Schlick's gain (Graphics Gems IV), r clamped to 0.001..0.999."""
    rr = np.clip(r, 0.001, 0.999)
    a = (1.0 / rr - 2.0) * (1.0 - 2.0 * x)
    return np.where(x < 0.5, x / (a + 1.0), (a - x) / (a - 1.0))


def hex_tiles(coord: np.ndarray, rotation, rotation_range, scale, scale_range, offset,
              offset_range) -> tuple[list[np.ndarray], np.ndarray]:
    """The three hex tiles over each point: their lookup coordinates (each tile's own
    random rotation about its centre, scale and offset) and barycentric weights (N, 3)."""
    coord = coord.astype(np.float64)
    st = coord * _SQRT3_2
    sk = np.stack([st[:, 0] - 0.57735027 * st[:, 1], 1.15470054 * st[:, 1]], -1)
    frac = sk - np.floor(sk)
    z = 1.0 - frac[:, 0] - frac[:, 1]
    s = (-z >= 0.0).astype(np.float64)  # upper triangle of the cell
    s2 = 2.0 * s - 1.0
    weights = np.stack([-z * s2, s - frac[:, 1] * s2, s - frac[:, 0] * s2], -1)
    base = np.floor(sk)
    si = s[:, None]
    ids = [base + np.concatenate([si, si], 1), base + np.concatenate([si, 1.0 - si], 1),
           base + np.concatenate([1.0 - si, si], 1)]
    rr = np.radians(np.asarray(rotation_range, np.float64))
    coords = []
    for vid in ids:
        g = vid / _SQRT3_2
        centre = np.stack([g[:, 0] + 0.5 * g[:, 1], g[:, 1] / _SKEW], -1)
        rand = hex_hash(vid + np.float32(0.12345)).astype(np.float64)
        angle = rr[..., 0] + (rr[..., 1] - rr[..., 0]) * rand[:, 0] * rotation
        c, sn = np.cos(angle), np.sin(angle)
        srange = np.asarray(scale_range, np.float64)
        k = 1.0 + (srange[..., 0] + (srange[..., 1] - srange[..., 0]) * rand[:, 1] - 1.0) * scale
        orange = np.asarray(offset_range, np.float64)
        off = orange[..., :1] + (orange[..., 1:] - orange[..., :1]) * rand * _col(offset)
        d = coord - centre
        turned = np.stack([c * d[:, 0] - sn * d[:, 1], sn * d[:, 0] + c * d[:, 1]], -1)
        coords.append(turned / _col(k) + centre + off)
    return coords, weights


def hex_blend_weights(luma: np.ndarray, tile: np.ndarray, falloff) -> np.ndarray:
    """The three samples' weights: luminance x barycentric^7, normalised, then (falloff
    other than 0.5) Schlick's gain of each, normalised again."""
    w = luma * np.power(np.maximum(tile, 0.0), 7.0)
    w = w / w.sum(-1, keepdims=True)
    f = np.broadcast_to(np.asarray(falloff, np.float64), (len(w),))[:, None]
    g = _gain(w, f)
    g = g / g.sum(-1, keepdims=True)
    return np.where(f != 0.5, g, w)


def sample_hex_tiled(tex, uv, tiling, rotation, rotation_range, scale, scale_range, offset,
                     offset_range, falloff, falloff_contrast, luma) -> np.ndarray:
    """hextiledimage: three hex tiles' reads (bilinear, periodic) blended by luminance
    (mixed towards 1 by 1 - falloff_contrast) and barycentric weight. (N, 4)."""
    tex = np.asarray(tex)
    coords, tile = hex_tiles(uv * tiling, rotation, rotation_range, scale, scale_range,
                             offset, offset_range)
    reads = [sample_bilinear(tex, c) for c in coords]
    luma = np.asarray(luma, np.float64)
    fc = _col(np.broadcast_to(falloff_contrast, (len(uv),)))
    cw = np.stack([np.sum(r[:, :3] * luma, -1) for r in reads], -1)
    cw = 1.0 + (cw - 1.0) * fc
    w = hex_blend_weights(cw, tile, falloff)
    aw = hex_blend_weights(np.ones_like(cw), tile, falloff)
    rgb = sum(w[:, i:i + 1] * reads[i][:, :3] for i in range(3))
    a = sum(aw[:, i:i + 1] * reads[i][:, 3:4] for i in range(3))
    return np.concatenate([rgb, a], -1)


def _hex_tiled_texture(ctx, tex, uv, tiling, rotation, rotation_range, scale, scale_range,
                       offset, offset_range, falloff, falloff_contrast, luma):
    rgba = sample_hex_tiled(tex, uv, tiling, rotation, rotation_range, scale, scale_range,
                            offset, offset_range, falloff, falloff_contrast, luma).astype(
        uv.dtype, copy=False)
    return rgba, rgba[:, :3]


register(NodeDef(
    "hex_tiled_texture", "Hex-Tiled Texture", "Texture",
    "Samples a texture over a hexagonal grid of randomly turned, scaled and shifted tiles, "
    "blended so that no repeat shows (MaterialX's hextiledimage).",
    inputs=(_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
            _i("uv", "vec2", MESH_UV, "texture coordinates"),
            _i("tiling", "vec2", [1.0, 1.0], "repeats across the surface"),
            _i("rotation", "float", 1.0, "amount of random rotation", UNIT),
            _i("rotation_range", "vec2", [0.0, 360.0], "random rotation range, degrees"),
            _i("scale", "float", 1.0, "amount of random scale", UNIT),
            _i("scale_range", "vec2", [0.5, 2.0], "random scale range"),
            _i("offset", "float", 1.0, "amount of random offset", UNIT),
            _i("offset_range", "vec2", [0.0, 1.0], "random offset range, UV units"),
            _i("falloff", "float", 0.5, "blend falloff (0.5: none)", UNIT),
            _i("falloff_contrast", "float", 0.5, "how much brighter texels win the blend",
               UNIT),
            _i("luma", "vec3", [0.2722287, 0.6740818, 0.0536895],
               "luminance coefficients of the blend (ACEScg's by default)")),
    outputs=(_o("rgba", "vec4"), _o("rgb", "vec3")),
    glsl="node_hex_tiled_texture", role=Role.HEX_TILED_TEXTURE, impure=True,
    thumbnail=Thumbnail.ALWAYS,
    numpy=_hex_tiled_texture,  # hextiledimage (color4)
))
