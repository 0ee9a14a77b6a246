"""Texture sampling."""

from __future__ import annotations

import numpy as np

from matedit.nodes.kind import MESH_UV, MxRecipe, NodeDef, Role, Thumbnail, _i, _o, register
from matedit.nodes.twin import _col


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
