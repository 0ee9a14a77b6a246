"""Texture colour spaces: decode a texture file to linear RGB before anything filters it.

One decode for the renderer, the CPU evaluator and the node thumbnails, so the three agree:
- ``srgb``: integer (8/16-bit) files are decoded with the sRGB transfer function
  (IEC 61966-2-1); float files (EXR, HDR) are already linear and stay as stored;
- ``linear``: values as stored (data textures: normals, roughness, masks);
- any other name: an OpenColorIO colour space of OpenImageIO's built-in config (e.g.
  ``ACEScg``, ``Linear P3-D65``, ``sRGB Encoded P3-D65``), converted to linear Rec.709.
Alpha is never converted.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

SRGB = "srgb"
LINEAR = "linear"
# Linear Rec.709 primaries, what the shading uses. (The built-in config's scene_linear role
# is ACEScg, so the target is named, not taken from the role.)
SCENE_LINEAR = "Linear Rec.709 (sRGB)"


class ColorSpaceError(ValueError):
    """A colour-space name that neither matedit nor the OpenColorIO config knows."""


def srgb_to_linear(x) -> np.ndarray:
    """The sRGB transfer function inverted (IEC 61966-2-1), per component."""
    x = np.asarray(x, dtype=np.float64)
    return np.where(x <= 0.04045, x / 12.92, ((np.maximum(x, 0.04045) + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1), per component, input clamped to [0, 1]."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x,
                    1.055 * np.maximum(x, 0.0031308) ** (1 / 2.4) - 0.055)


@lru_cache(maxsize=1)
def ocio_spaces() -> tuple[str, ...]:
    """Colour-space names of OpenImageIO's built-in OpenColorIO config."""
    import OpenImageIO as oiio

    return tuple(oiio.ColorConfig().getColorSpaceNames())


def effective_space(color_space: str | None, srgb: bool = True) -> str:
    """The texture's colour space: its `color_space` setting, else the `srgb` flag's choice."""
    text = (color_space or "").strip()
    if not text:
        return SRGB if srgb else LINEAR
    return text


def check_space(space: str) -> str:
    """`space` in canonical form (srgb and linear lower case); raises ColorSpaceError."""
    if space.lower() in (SRGB, LINEAR):
        return space.lower()
    if space in ocio_spaces():
        return space
    known = ", ".join([SRGB, LINEAR, *ocio_spaces()])
    raise ColorSpaceError(f"unknown colour space {space!r} (known: {known})")


def decode(pixels: np.ndarray, is_ldr: bool, space: str) -> np.ndarray:
    """Linear float32 RGBA (H, W, 4) from stored pixels (H, W, C), C in 1..4 (more: the first
    four). Grey files are replicated to RGB; a missing alpha is 1."""
    space = check_space(space)
    a = np.asarray(pixels, dtype=np.float32)
    if a.ndim == 2:
        a = a[:, :, None]
    c = a.shape[2]
    if c == 1:
        rgb, alpha = np.repeat(a, 3, axis=2), None
    elif c == 2:  # grey + alpha
        rgb, alpha = np.repeat(a[:, :, :1], 3, axis=2), a[:, :, 1:2]
    else:
        rgb, alpha = a[:, :, :3], (a[:, :, 3:4] if c >= 4 else None)
    if space == SRGB and is_ldr:
        rgb = srgb_to_linear(rgb).astype(np.float32)
    elif space not in (SRGB, LINEAR):
        rgb = _ocio_to_linear(rgb, space)
    if alpha is None:
        alpha = np.ones(rgb.shape[:2] + (1,), np.float32)
    return np.ascontiguousarray(np.concatenate([rgb, alpha], axis=2), dtype=np.float32)


def _ocio_to_linear(rgb: np.ndarray, space: str) -> np.ndarray:
    import OpenImageIO as oiio

    h, w, _ = rgb.shape
    buf = oiio.ImageBuf(oiio.ImageSpec(w, h, 3, oiio.FLOAT))
    buf.set_pixels(oiio.ROI(0, w, 0, h, 0, 1, 0, 3), np.ascontiguousarray(rgb, np.float32))
    out = oiio.ImageBufAlgo.colorconvert(buf, space, SCENE_LINEAR)
    if out.has_error:
        raise ColorSpaceError(f"colour space {space!r}: {out.geterror()}")
    return np.asarray(out.get_pixels(oiio.FLOAT), np.float32).reshape(h, w, 3)


@dataclass(frozen=True)
class TextureImage:
    """A decoded texture, row 0 the bottom row (v = 0), as GL uploads it.

    `linear` is float32 RGBA (H, W, 4). `srgb8` keeps the file's own 8-bit RGBA codes
    (same orientation) when the file is 8-bit and marked sRGB, so a GPU can sample it from
    an sRGB internal format (decoded before filtering, exactly as `linear`)."""

    linear: np.ndarray
    srgb8: np.ndarray | None
    space: str


def load_texture(path: str | os.PathLike, space: str) -> TextureImage:
    """Reads and decodes a texture file; raises ImageError (a ValueError) or ColorSpaceError."""
    from matedit.io.images import read_image

    space = check_space(space)
    img = read_image(path)
    linear = decode(img.pixels, img.is_ldr, space)[::-1]
    srgb8 = None
    if space == SRGB and img.is_ldr and img.is_8bit:
        rgba = decode(img.pixels, True, LINEAR)[::-1]  # codes / 255, alpha added
        srgb8 = np.ascontiguousarray(np.rint(rgba * 255.0).clip(0, 255).astype(np.uint8))
    return TextureImage(np.ascontiguousarray(linear), srgb8, space)


_CACHE: dict[tuple, TextureImage] = {}


def load_texture_cached(path: str | os.PathLike, space: str) -> TextureImage:
    """`load_texture`, remembered while the file's size and modification time stay the same."""
    st = os.stat(path)
    key = (os.path.realpath(path), space, st.st_size, st.st_mtime_ns)
    hit = _CACHE.get(key)
    if hit is None:
        hit = load_texture(path, space)
        if len(_CACHE) > 32:
            _CACHE.clear()
        _CACHE[key] = hit
    return hit


def mip_chain(linear: np.ndarray) -> list[np.ndarray]:
    """Mip levels of a linear RGBA image (GL sizes: each level floor(size / 2), at least 1),
    each the 2 x 2 box average of the level above, in linear space."""
    levels = [np.asarray(linear, np.float32)]
    while max(levels[-1].shape[:2]) > 1:
        a = levels[-1].astype(np.float64)
        h, w = a.shape[:2]
        if h > 1:
            a = 0.5 * (a[0:h - h % 2:2] + a[1:h - h % 2:2]) if h % 2 == 0 else \
                _odd_down(a, axis=0)
        if w > 1:
            a = 0.5 * (a[:, 0:w - w % 2:2] + a[:, 1:w - w % 2:2]) if w % 2 == 0 else \
                _odd_down(a, axis=1)
        levels.append(a.astype(np.float32))
    return levels


def _odd_down(a: np.ndarray, axis: int) -> np.ndarray:
    """Odd size n to floor(n / 2): each output texel averages the three input texels it
    covers, weighted by their overlap (a polyphase box filter)."""
    n = a.shape[axis]
    m = n // 2
    a = np.moveaxis(a, axis, 0)
    out = np.empty((m,) + a.shape[1:])
    for i in range(m):
        # output texel i covers input [i * n / m, (i + 1) * n / m)
        lo, hi = i * n / m, (i + 1) * n / m
        acc = 0.0
        for j in range(int(np.floor(lo)), min(int(np.ceil(hi)), n)):
            acc = acc + a[j] * (min(hi, j + 1) - max(lo, j))
        out[i] = acc / (hi - lo)
    return np.moveaxis(out, 0, axis)
