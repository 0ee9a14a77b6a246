"""Shaded thumbnails of MaterialAttributes for the editor's node previews (Python side only).

A thumbnail is the numpy twin of the shading (`surface.shadeSurface`, every lobe the twin
has) on the preview sphere, seen head-on, under a fixed small rig: a key and a rim light and
a sky-over-ground environment. The environment's split-sum terms are computed here without
textures: its SH9 coefficients in closed form, its radiance read along the reflection vector
(no prefiltering: thumbnails are 48 pixels wide), and the environment BRDF from Karis's
analytic fit, so a thumbnail needs no LUT bake and no GL context.
"""

from __future__ import annotations

import numpy as np

from matedit.shading.ibl import IBL_MODE_SPLIT_SUM
from matedit.shading.lights import Light
from matedit.shading.material import MaterialAttributes, tangentToWorldNormal
from matedit.shading.surface import IblInputs, shadeSurface

# Sky radiance (linear) above the horizon and ground below, blended by the direction's y.
SKY = np.array([0.55, 0.6, 0.7])
GROUND = np.array([0.12, 0.1, 0.09])
LIGHTS = (
    Light("directional", direction=(0.45, -0.55, -0.7), intensity=2.2, color=(1.0, 0.97, 0.92)),
    Light("directional", direction=(-0.6, -0.2, 0.77), intensity=0.8, color=(0.85, 0.9, 1.0)),
)


def environment_radiance(R: np.ndarray, lod=None) -> np.ndarray:
    """L(d) = mix(ground, sky, (d.y + 1) / 2): linear in d.y, so its SH9 is exact."""
    t = (np.clip(R[..., 1:2], -1.0, 1.0) + 1.0) * 0.5
    return GROUND + (SKY - GROUND) * t


def environment_sh9() -> np.ndarray:
    """The SH9 of environment_radiance: L = a + b y projects onto L00 and L1-1 alone,
    a * 4 pi Y00 and b * (4 pi / 3) Y1-1 (Y00 = 1 / (2 sqrt(pi)), Y1-1 = sqrt(3 / (4 pi)) y)."""
    a = (SKY + GROUND) * 0.5
    b = (SKY - GROUND) * 0.5
    sh = np.zeros((9, 3))
    sh[0] = a * 4.0 * np.pi * 0.5 / np.sqrt(np.pi)
    sh[1] = b * (4.0 * np.pi / 3.0) * np.sqrt(3.0 / (4.0 * np.pi))
    return sh


def environment_brdf_fit(NoV, roughness) -> np.ndarray:
    """(A, B) of the split sum from an analytic fit instead of the LUT: thumbnails only."""
    # Karis 2014, "Physically Based Shading on Mobile": EnvBRDFApprox (Lazarov's fit)
    r = np.asarray(roughness, float)[..., None] * np.array([-1.0, -0.0275, -0.572, 0.022]) \
        + np.array([1.0, 0.0425, 1.04, -0.04])
    nov = np.asarray(NoV, float)
    a004 = np.minimum(r[..., 0] ** 2, np.exp2(-9.28 * nov)) * r[..., 0] + r[..., 1]
    return np.stack([-1.04 * a004 + r[..., 2], 1.04 * a004 + r[..., 3]], axis=-1)


def _field(attrs: dict, name: str, default):
    v = attrs.get(name)
    return np.asarray(default if v is None else v, dtype=np.float64)


def shade_attributes(attrs: dict, N: np.ndarray, T: np.ndarray, B: np.ndarray,
                     V: np.ndarray) -> np.ndarray:
    """Linear colour of `attrs` (the CPU evaluator's {field: array}) at points with unit
    geometric normal N, tangent frame (T, B) and view V, under the thumbnail rig."""
    defaults = MaterialAttributes()
    fields = {name: _field(attrs, name, getattr(defaults, name))
              for name in MaterialAttributes.__dataclass_fields__}
    m = MaterialAttributes(**fields)
    n = m.normal if m.normal.ndim > 1 else np.broadcast_to(m.normal, N.shape)
    Ns = tangentToWorldNormal(n, T, B, N) if "normal" in attrs else N
    ibl = IblInputs(sh=environment_sh9(), prefiltered=environment_radiance, mip_count=1.0,
                    brdf_lut=environment_brdf_fit, intensity=1.0, mode=IBL_MODE_SPLIT_SUM)
    # A lobe is shaded where its weight is not 0 anywhere (at 0 it equals the talk's model).
    return shadeSurface(m, np.zeros_like(N), Ns, V, LIGHTS, ibl, frame=(N, T, B),
                        anisotropic=bool(np.any(m.anisotropy != 0.0)))


def preview_frame(N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangent and bitangent of the preview UV sphere (u around +Y, v up): T = Y x N
    normalised (the direction u grows), B = N x T; at the poles T falls back to +X."""
    t = np.cross(np.array([0.0, 1.0, 0.0]), N)
    length = np.linalg.norm(t, axis=-1, keepdims=True)
    T = np.where(length > 1e-6, t / np.maximum(length, 1e-12), np.array([1.0, 0.0, 0.0]))
    return T, np.cross(N, T)
