"""Twin of ``material.glsl``: MaterialAttributes, defaults, diffuse colour and F0."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from matedit.shading.common import f64, mix, normalize


def _v(*xs: float):
    return field(default_factory=lambda: np.array(xs, dtype=np.float64))


@dataclass
class MaterialAttributes:
    """Fields in the GLSL struct's order; each may be an array broadcasting over pixels."""

    baseColor: np.ndarray = _v(0.5, 0.5, 0.5)
    metallic: np.ndarray | float = 0.0
    roughness: np.ndarray | float = 0.5
    cavity: np.ndarray | float = 1.0
    normal: np.ndarray = _v(0.0, 0.0, 1.0)
    emissive: np.ndarray = _v(0.0, 0.0, 0.0)
    opacity: np.ndarray | float = 1.0
    # Beyond the talk; each default turns its lobe off.
    specularColor: np.ndarray = _v(1.0, 1.0, 1.0)
    ior: np.ndarray | float = 1.5
    coat: np.ndarray | float = 0.0
    coatRoughness: np.ndarray | float = 0.0
    coatColor: np.ndarray = _v(1.0, 1.0, 1.0)
    coatIor: np.ndarray | float = 1.5
    coatNormal: np.ndarray = _v(0.0, 0.0, 1.0)
    sheenColor: np.ndarray = _v(0.0, 0.0, 0.0)
    sheenRoughness: np.ndarray | float = 0.3
    anisotropy: np.ndarray | float = 0.0
    anisotropyDirection: np.ndarray = _v(1.0, 0.0, 0.0)
    subsurface: np.ndarray | float = 0.0
    subsurfaceColor: np.ndarray = _v(1.0, 1.0, 1.0)
    subsurfaceRadius: np.ndarray = _v(1.0, 1.0, 1.0)
    thickness: np.ndarray | float = 1.0
    thinFilmThickness: np.ndarray | float = 0.0
    thinFilmIor: np.ndarray | float = 1.3
    transmission: np.ndarray | float = 0.0
    transmissionColor: np.ndarray = _v(1.0, 1.0, 1.0)
    attenuationColor: np.ndarray = _v(1.0, 1.0, 1.0)
    attenuationDistance: np.ndarray | float = 0.0


def defaultMaterialAttributes() -> MaterialAttributes:
    return MaterialAttributes()


def computeDiffuseColor(baseColor, metallic) -> np.ndarray:
    return f64(baseColor) * (1.0 - f64(metallic))[..., None]


def computeF0(baseColor, metallic) -> np.ndarray:
    return mix(np.full(3, 0.04), f64(baseColor), f64(metallic)[..., None])


def dielectricF0(ior, specularColor) -> np.ndarray:
    r = (f64(ior) - 1.0) / (f64(ior) + 1.0)
    return np.minimum((r * r)[..., None] * f64(specularColor), 1.0)


def materialF0(m: MaterialAttributes) -> np.ndarray:
    """The GLSL compiles the talk's 0.04 where the material writes neither ior nor
    specularColor; at their defaults this gives 0.04 to 1e-16."""
    return mix(dielectricF0(m.ior, m.specularColor), f64(m.baseColor), f64(m.metallic)[..., None])


def tangentToWorldNormal(tangentNormal, T, B, N) -> np.ndarray:
    n = f64(tangentNormal)
    return normalize(f64(T) * n[..., 0:1] + f64(B) * n[..., 1:2] + f64(N) * n[..., 2:3])
