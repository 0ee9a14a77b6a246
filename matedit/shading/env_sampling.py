"""Twin of ``env_sampling.glsl``: sampling directions from an environment's luminance
distribution, and the density of a direction.

The distribution is the table of ``matedit.ibl.importance`` (the texture's texels): an
array ``(H, W + 1, 2)``; ``[j, i, 0]`` conditional CDFs (column W: the marginal CDF over
rows), ``[j, i, 1]`` the pixel densities p(u, v). The binary searches compare in float32,
as the shader's texel values and points are float32; the rest is float64.
"""

from __future__ import annotations

import numpy as np

from matedit.shading.common import INV_PI, PI, f64


def equirectDirection(uv) -> np.ndarray:
    uv = f64(uv)
    phi = 2.0 * PI * (uv[..., 0] - 0.5)
    theta = PI * uv[..., 1]
    st = np.sin(theta)
    return np.stack([st * np.sin(phi), np.cos(theta), -st * np.cos(phi)], axis=-1)


def directionToEquirect(d) -> np.ndarray:
    d = f64(d)
    u = 0.5 + np.arctan2(d[..., 0], -d[..., 2]) * (0.5 * INV_PI)
    v = np.arctan2(np.hypot(d[..., 0], d[..., 2]), d[..., 1]) * INV_PI
    return np.stack([u, v], axis=-1)


def _search(cdf_at, n: int, x) -> np.ndarray:
    """Smallest k in [0, n) with cdf_at(k) > x, elementwise, by the shader's bisection."""
    x = np.asarray(x, dtype=np.float32)
    lo = np.zeros(x.shape, dtype=np.int64)
    hi = np.full(x.shape, n - 1, dtype=np.int64)
    while True:
        active = lo < hi
        if not active.any():
            return lo
        mid = (lo + hi) // 2
        above = cdf_at(mid) > x
        hi = np.where(active & above, mid, hi)
        lo = np.where(active & ~above, mid + 1, lo)


def sampleEnvironmentDirection(dist, u) -> tuple[np.ndarray, np.ndarray]:
    """(direction (..., 3), solid-angle pdf (...)) for uniform points u (..., 2)."""
    table = np.asarray(dist, dtype=np.float32)
    h, w = table.shape[0], table.shape[1] - 1
    u = np.asarray(u, dtype=np.float32)
    ux, uy = u[..., 0], u[..., 1]
    marginal = table[:, w, 0]
    j = _search(lambda k: marginal[k], h, uy)
    r0 = np.where(j > 0, marginal[np.maximum(j - 1, 0)], 0.0).astype(np.float64)
    r1 = f64(marginal[j])
    with np.errstate(invalid="ignore", divide="ignore"):
        dv = np.where(r1 > r0, np.clip((uy - r0) / (r1 - r0), 0.0, 1.0), 0.5)
    i = _search(lambda k: table[j, k, 0], w, ux)
    c0 = np.where(i > 0, table[j, np.maximum(i - 1, 0), 0], 0.0).astype(np.float64)
    c1 = f64(table[j, i, 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        du = np.where(c1 > c0, np.clip((ux - c0) / (c1 - c0), 0.0, 1.0), 0.5)
    uv = np.stack([(i + du) / w, (j + dv) / h], axis=-1)
    sin_theta = np.sin(PI * uv[..., 1])
    p = f64(table[j, i, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        pdf = np.where(sin_theta > 1e-7, p / (2.0 * PI * PI * sin_theta), 0.0)
    return equirectDirection(uv), pdf


def environmentPdf(dist, L) -> np.ndarray:
    """Solid-angle density of unit directions L (..., 3) under sampleEnvironmentDirection."""
    table = np.asarray(dist, dtype=np.float32)
    h, w = table.shape[0], table.shape[1] - 1
    L = f64(L)
    sin_theta = np.hypot(L[..., 0], L[..., 2])
    uv = directionToEquirect(L)
    i = np.clip((uv[..., 0] * w).astype(np.int64), 0, w - 1)
    j = np.clip((uv[..., 1] * h).astype(np.int64), 0, h - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(sin_theta > 1e-7, f64(table[j, i, 1]) / (2.0 * PI * PI * sin_theta),
                        0.0)
