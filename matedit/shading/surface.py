"""Twin of ``surface.glsl``: the whole shading of a MaterialAttributes, for renderer tests."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from matedit.shading.common import dot, f64, reflect, saturate
from matedit.shading.ibl import (
    IBL_MODE_NONE,
    IBL_MODE_REFERENCE,
    diffuseIrradianceSH9,
    energyCompensation,
    environmentBRDF,
    makeReferenceSurface,
    prefilteredRadiance,
    referenceEnvironmentIBL,
    splitSumSpecular,
)
from matedit.shading.lights import Light, ShadingContext, evaluateLight, makeShadingContext
from matedit.shading.material import MaterialAttributes, computeDiffuseColor, computeF0


@dataclass
class IblInputs:
    """What the shader reads from IblBlock and the environment textures.

    `prefiltered`: callable (R, lod) -> rgb, or an array of radiance values broadcasting
    over pixels (already looked up). `brdf_lut`: LUT array, callable, or an array of
    (A, B) values (shape (..., 2), already looked up) when `lut_values` is true.
    `environment`: callable directions -> rgb, and `environment_distribution` its sampling
    table (matedit.ibl.importance, the array the renderer uploads), for the reference mode.
    """

    sh: np.ndarray = field(default_factory=lambda: np.zeros((9, 3)))
    prefiltered: object = 0.0
    mip_count: float = 1.0
    brdf_lut: object = field(default_factory=lambda: np.zeros((1, 1, 2)))
    lut_values: bool = False
    environment: object = None
    environment_distribution: object = None
    intensity: float = 1.0
    samples: int = 64
    sample_offset: tuple[float, float] = (0.0, 0.0)
    mode: int = 0


def directLighting(s: ShadingContext, lights: Sequence[Light]) -> np.ndarray:
    total = np.zeros(np.broadcast_shapes(s.N.shape, s.P.shape))
    for light in lights:
        total = total + evaluateLight(s, light)
    return total


def imageBasedLighting(N, V, diffuseColor, F0, roughness, ibl: IblInputs,
                       specularScale=1.0) -> np.ndarray:
    N, V = f64(N), f64(V)
    if ibl.mode == IBL_MODE_NONE:
        return np.zeros(np.broadcast_shapes(N.shape, V.shape))
    if ibl.mode == IBL_MODE_REFERENCE:
        count = max(int(ibl.samples), 1)
        if ibl.environment_distribution is None:
            raise ValueError("reference mode needs IblInputs.environment_distribution")
        rs = makeReferenceSurface(N, V, diffuseColor, F0, roughness, specularScale)
        color = referenceEnvironmentIBL(ibl.environment, ibl.environment_distribution, rs,
                                        count, ibl.sample_offset)
    else:
        NoV = saturate(dot(N, V))
        R = reflect(-V, N)
        if callable(ibl.prefiltered):
            pref = prefilteredRadiance(ibl.prefiltered, R, roughness, ibl.mip_count)
        else:
            pref = f64(ibl.prefiltered)
        AB = f64(ibl.brdf_lut) if ibl.lut_values else environmentBRDF(ibl.brdf_lut, NoV, roughness)
        color = diffuseIrradianceSH9(ibl.sh, N, diffuseColor) + splitSumSpecular(
            pref, AB, F0) * f64(specularScale)
    return color * ibl.intensity


def shadeSurface(
    m: MaterialAttributes, P, N, V, lights: Sequence[Light] = (), ibl: IblInputs | None = None,
    energy_compensation: bool = False,
) -> np.ndarray:
    """(direct + ibl) * cavity + emissive; N is the world shading normal.
    `energy_compensation`: the GLSL's MATEDIT_ENERGY_COMPENSATION (Fdez-Aguera 2019)."""
    ibl = ibl or IblInputs(mode=IBL_MODE_NONE)
    diffuseColor = computeDiffuseColor(m.baseColor, m.metallic)
    F0 = computeF0(m.baseColor, m.metallic)
    roughness = saturate(m.roughness)
    s = makeShadingContext(P, N, V, diffuseColor, F0, roughness)
    if energy_compensation:
        NoV = saturate(dot(f64(N), f64(V)))
        AB = f64(ibl.brdf_lut) if ibl.lut_values else environmentBRDF(ibl.brdf_lut, NoV,
                                                                      roughness)
        s.specularScale, diffuse_scale = energyCompensation(F0, AB)
        s.diffuseColor = s.diffuseColor * diffuse_scale
        diffuseColor = s.diffuseColor
    direct = directLighting(s, lights)
    indirect = imageBasedLighting(N, V, diffuseColor, F0, roughness, ibl, s.specularScale)
    return (direct + indirect) * f64(m.cavity)[..., None] + f64(m.emissive)
