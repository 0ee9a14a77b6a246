"""Twin of ``subsurface.glsl``: the subsurface diffuse (wrapped diffuse plus transmission from
behind, split by the transmittance exp(-thickness / radius))."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading.common import f64, saturate

MIN_SUBSURFACE_RADIUS = 1e-4
INV_PI = 1.0 / np.pi


@dataclass
class SubsurfaceLobe:
    color: np.ndarray          # (..., 3): weight x subsurfaceColor x (1 - metallic), as drawn
    wrap: np.ndarray           # (..., 3)
    transmittance: np.ndarray  # (..., 3)


def subsurfaceWrap(radius, thickness) -> np.ndarray:
    r = np.maximum(f64(radius), MIN_SUBSURFACE_RADIUS)
    return r / (r + np.maximum(f64(thickness), 0.0)[..., None])


def subsurfaceTransmittance(radius, thickness) -> np.ndarray:
    r = np.maximum(f64(radius), MIN_SUBSURFACE_RADIUS)
    return np.exp(-np.maximum(f64(thickness), 0.0)[..., None] / r)


def makeSubsurfaceLobe(weight, color, radius, thickness, metallic, shown) -> SubsurfaceLobe:
    scale = saturate(weight) * (1.0 - f64(metallic)) * f64(shown)
    c = saturate(color) * scale[..., None]
    w = subsurfaceWrap(radius, thickness)
    t = subsurfaceTransmittance(radius, thickness)
    shape = np.broadcast_shapes(c.shape, w.shape)
    return SubsurfaceLobe(np.broadcast_to(c, shape), np.broadcast_to(w, shape),
                          np.broadcast_to(t, shape))


def wrappedDiffuseCosine(NoL, w) -> np.ndarray:
    w = f64(w)
    return np.maximum(f64(NoL)[..., None] + w, 0.0) / ((1.0 + w) * (1.0 + w))


def subsurfaceCosine(lobe: SubsurfaceLobe, NoL) -> np.ndarray:
    NoL = f64(NoL)
    T = lobe.transmittance
    return lobe.color * INV_PI * ((1.0 - T) * wrappedDiffuseCosine(NoL, lobe.wrap)
                                  + T * np.maximum(-NoL, 0.0)[..., None])


def wrappedIrradianceSH9(sh, N, w) -> np.ndarray:
    """Bands of irradianceSH9 (ibl.py) scaled by the wrapped kernel's: 1, 1 - w/2, (1 - w)^2.
    sh (..., 9, 3), N (..., 3), w (..., 3) -> (..., 3)."""
    c1, c2, c3, c4, c5 = 0.429043, 0.511664, 0.743125, 0.886227, 0.247708
    sh, N = f64(sh), f64(N)
    x, y, z = (N[..., i : i + 1] for i in range(3))
    L = [sh[..., i, :] for i in range(9)]
    band0 = c4 * L[0]
    band1 = 2.0 * c2 * (L[3] * x + L[1] * y + L[2] * z)
    band2 = (c1 * L[8] * (x * x - y * y) + c3 * L[6] * z * z - c5 * L[6]
             + 2.0 * c1 * (L[4] * x * y + L[7] * x * z + L[5] * y * z))
    w = f64(w)
    return band0 + (1.0 - 0.5 * w) * band1 + (1.0 - w) * (1.0 - w) * band2


def subsurfaceIrradiance(lobe: SubsurfaceLobe, Ewrap, Eback) -> np.ndarray:
    T = lobe.transmittance
    return lobe.color * INV_PI * ((1.0 - T) * f64(Ewrap) + T * f64(Eback))
