"""Twin of ``sampling.glsl``: Hammersley points, GGX and cosine importance sampling."""

from __future__ import annotations

import numpy as np

from matedit.shading.common import PI, cross, f64, normalize


def radicalInverse_VdC(bits) -> np.ndarray:
    """Van der Corput radical inverse in base 2 of 32-bit unsigned integers."""
    b = np.asarray(bits).astype(np.uint32)
    b = (b << np.uint32(16)) | (b >> np.uint32(16))
    for shift, mask in ((1, 0x55555555), (2, 0x33333333), (4, 0x0F0F0F0F), (8, 0x00FF00FF)):
        lo, s = np.uint32(mask), np.uint32(shift)
        b = ((b & lo) << s) | ((b >> s) & lo)
    return b.astype(np.float64) * 2.3283064365386963e-10


def hammersley(i, n) -> np.ndarray:
    """Point i of an n-point Hammersley set, shape (..., 2)."""
    i = np.asarray(i)
    return np.stack([f64(i) / f64(n), radicalInverse_VdC(i)], axis=-1)


def tangentFrame(N) -> tuple[np.ndarray, np.ndarray]:
    """(T, B) around N; same up-vector choice as the GLSL (Z unless N is near it, then Y, so
    that N = +Z has the identity frame)."""
    N = f64(N)
    up = np.where(
        (np.abs(N[..., 2]) < 0.999)[..., None], np.array([0.0, 0.0, 1.0]), np.array([0.0, 1, 0])
    )
    T = normalize(cross(up, N))
    B = cross(N, T)
    return T, B


def _to_world(local, N) -> np.ndarray:
    T, B = tangentFrame(N)
    return T * local[..., 0:1] + B * local[..., 1:2] + f64(N) * local[..., 2:3]


def importanceSampleGGX(Xi, a, N) -> np.ndarray:
    """GGX half vector around N for uniform Xi (..., 2); a is alpha = roughness^2."""
    Xi, a = f64(Xi), f64(a)
    phi = 2.0 * PI * Xi[..., 0]
    a2y = a * a * Xi[..., 1]
    denom = np.maximum((1.0 - Xi[..., 1]) + a2y, 1e-30)
    cos_t = np.sqrt((1.0 - Xi[..., 1]) / denom)
    sin_t = np.sqrt(a2y / denom)
    local = np.stack(np.broadcast_arrays(sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t), -1)
    return _to_world(local, N)


def importanceSampleCosine(Xi, N) -> np.ndarray:
    """Cosine-weighted direction around N (pdf NoL / pi)."""
    Xi = f64(Xi)
    phi = 2.0 * PI * Xi[..., 0]
    r = np.sqrt(Xi[..., 1])
    z = np.sqrt(np.maximum(0.0, 1.0 - Xi[..., 1]))
    local = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    return _to_world(local, N)
