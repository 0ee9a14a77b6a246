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
