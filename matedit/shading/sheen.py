"""Twin of ``sheen.glsl`` and ``sheen_shading.glsl``: the Charlie sheen lobe (Estevez and
Kulla 2017), its albedo scaling of the base (glTF KHR_materials_sheen) and its IBL terms.

The LUT is the environment BRDF LUT array ``(N, N, 3)`` (blue channel: the sheen's
directional albedo E), or a callable ``(NoV, roughness) -> (..., >= 3)``; a two-channel LUT
reads E = 0, as the GPU reads 0 from the blue channel of an RG texture.
"""

from __future__ import annotations

import numpy as np

from matedit.shading.common import INV_PI, PI, dot, f64, mix, saturate, sq
from matedit.shading.ibl import (
    IBL_MODE_NONE,
    prefilteredRadiance,
    sample_lut,
)
from matedit.shading.sampling import tangentFrame

# Smallest sheen roughness: below ~0.26 the fitted Lambda lets the lobe's directional albedo
# exceed 1 at grazing views (sheen.glsl); at 0.3 it stays below 0.93 for every NoV.
MIN_SHEEN_ROUGHNESS = 0.3


def sheenAlpha(sheenRoughness) -> np.ndarray:
    """glTF KHR_materials_sheen: alpha = sheenRoughness^2, clamped to MIN_SHEEN_ROUGHNESS."""
    r = np.clip(f64(sheenRoughness), MIN_SHEEN_ROUGHNESS, 1.0)
    return r * r


def D_Charlie(sin2h, alpha) -> np.ndarray:
    """Estevez and Kulla 2017, the Charlie distribution: (2 + 1/a) sin^(1/a) / (2 pi)."""
    inv = 1.0 / f64(alpha)
    return (2.0 + inv) * np.power(np.maximum(f64(sin2h), 0.0), 0.5 * inv) / (2.0 * PI)


def sheenLambdaFit(x, alpha) -> np.ndarray:
    """Estevez and Kulla 2017, fitted Lambda: L(x) = a / (1 + b x^c) + d x + e."""
    x, t = f64(x), sq(1.0 - f64(alpha))
    a = mix(21.5473, 25.3245, t)
    b = mix(3.82987, 3.32435, t)
    c = mix(0.19823, 0.16801, t)
    d = mix(-1.97760, -1.27393, t)
    e = mix(-4.32054, -4.85967, t)
    return a / (1.0 + b * np.power(x, c)) + d * x + e


def sheenLambda(NoX, alpha) -> np.ndarray:
    """Estevez and Kulla 2017: exp(L(cos)) below 0.5, exp(2 L(0.5) - L(1 - cos)) above."""
    NoX = f64(NoX)
    low = np.exp(sheenLambdaFit(np.minimum(NoX, 0.5), alpha))
    mirrored = saturate(1.0 - np.maximum(NoX, 0.5))
    high = np.exp(2.0 * sheenLambdaFit(0.5, alpha) - sheenLambdaFit(mirrored, alpha))
    return np.where(NoX < 0.5, low, high)


def V_Charlie(NoV, NoL, alpha) -> np.ndarray:
    """Estevez and Kulla 2017: G2 / (4 NoV NoL), G2 = 1 / (1 + Lambda(NoV) + Lambda(NoL))."""
    NoV, NoL = f64(NoV), f64(NoL)
    with np.errstate(divide="ignore"):
        return 1.0 / ((1.0 + sheenLambda(NoV, alpha) + sheenLambda(NoL, alpha)) * 4.0 * NoV * NoL)


def sheenBRDF(N, V, L, alpha) -> np.ndarray:
    """D_Charlie V_Charlie (no Fresnel), 0 below the horizon."""
    N, V, L = f64(N), f64(V), f64(L)
    NoL = saturate(dot(N, L))
    NoV = np.maximum(dot(N, V), 1e-4)
    h = L + V
    H = h / np.sqrt(np.maximum(dot(h, h), 1e-30))[..., None]
    NxH = np.cross(N, H)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        f = D_Charlie(dot(NxH, NxH), alpha) * V_Charlie(NoV, NoL, alpha)
    return np.where(NoL > 0.0, f, 0.0)


def sheenBrdfCosine(N, V, L, sheenColor, alpha) -> np.ndarray:
    """glTF KHR_materials_sheen: sheenColor D V NoL."""
    NoL = saturate(dot(f64(N), f64(L)))
    return f64(sheenColor) * (sheenBRDF(N, V, L, alpha) * NoL)[..., None]


def sheenDFG(brdfLut, NoV, sheenRoughness) -> np.ndarray:
    """The LUT's blue channel at (NoV, clamped sheen roughness)."""
    r = np.clip(f64(sheenRoughness), MIN_SHEEN_ROUGHNESS, 1.0)
    values = f64(brdfLut(f64(NoV), r)) if callable(brdfLut) else sample_lut(brdfLut, NoV, r)
    if values.shape[-1] < 3:
        return np.zeros(values.shape[:-1])
    return values[..., 2]


def sheenAlbedoScaling(sheenMax, E) -> np.ndarray:
    """glTF KHR_materials_sheen, albedo-scaling: 1 - max3(sheenColor) E, saturated."""
    return saturate(1.0 - f64(sheenMax) * f64(E))


def sheenSplitSum(prefiltered, sheenColor, dfg) -> np.ndarray:
    """Filament's cloth IBL: prefiltered sheenColor DFG."""
    return f64(prefiltered) * f64(sheenColor) * f64(dfg)[..., None]


def sheenSampleDirection(Xi, N) -> tuple[np.ndarray, np.ndarray]:
    """Uniform hemisphere around N: (direction, pdf = 1 / (2 pi))."""
    Xi, N = f64(Xi), f64(N)
    phi = 2.0 * PI * Xi[..., 0]
    cosT = Xi[..., 1]
    sinT = np.sqrt(np.maximum(0.0, 1.0 - cosT * cosT))
    T, B = tangentFrame(N)
    L = (T * (sinT * np.cos(phi))[..., None] + B * (sinT * np.sin(phi))[..., None]
         + N * cosT[..., None])  # fmt: skip
    return L, np.full(L.shape[:-1], 0.5 * INV_PI)


def sheenSamplePdf(N, L) -> np.ndarray:
    return np.where(dot(f64(N), f64(L)) > 0.0, 0.5 * INV_PI, 0.0)


# -- sheen_shading.glsl -------------------------------------------------------------------


def lut_of(ibl):
    """The LUT the sheen reads from IblInputs: its array or callable, or where it holds
    already looked-up values (lut_values), those values at every (NoV, roughness)."""
    if not ibl.lut_values:
        return ibl.brdf_lut
    values = f64(ibl.brdf_lut)
    return lambda NoV, r: np.broadcast_to(values, np.broadcast_shapes(
        np.shape(NoV), np.shape(r), values.shape[:-1]) + values.shape[-1:])  # fmt: skip


def setupSheen(s, sheenColor, sheenRoughness, shownColor, brdfLut) -> None:
    """Sets the context's sheen fields; `brdfLut` stands for uBrdfLut (kept on the context
    as `sheenLut`, which the lights read as the GLSL reads the uniform)."""
    s.sheenColor = f64(shownColor)
    s.sheenRoughness = np.clip(f64(sheenRoughness), MIN_SHEEN_ROUGHNESS, 1.0)
    s.sheenAlpha = sheenAlpha(sheenRoughness)
    c = f64(sheenColor)
    s.sheenMax = np.maximum(np.maximum(c[..., 0], c[..., 1]), c[..., 2])
    s.sheenLut = brdfLut
    s.sheenScaleV = sheenAlbedoScaling(s.sheenMax, sheenDFG(brdfLut, s.NoV, s.sheenRoughness))


def sheenBaseScale(s, NoL) -> np.ndarray:
    """glTF KHR_materials_sheen: min(1 - max3(c) E(NoV), 1 - max3(c) E(NoL))."""
    E = sheenDFG(s.sheenLut, saturate(NoL), s.sheenRoughness)
    return np.minimum(s.sheenScaleV, sheenAlbedoScaling(s.sheenMax, E))


def sheenLayer(s, base, L, cosine) -> np.ndarray:
    """base * sheenBaseScale + sheenColor D V cosine."""
    NoL = saturate(dot(s.N, L))
    sheen = sheenBRDF(s.N, s.V, L, s.sheenAlpha) * f64(cosine)
    return f64(base) * sheenBaseScale(s, NoL)[..., None] + s.sheenColor * sheen[..., None]


def sheenLayerCosine(s, base, L) -> np.ndarray:
    return sheenLayer(s, base, L, saturate(dot(s.N, L)))


SHEEN_IBL_LOOKUP_ROUGHNESS = 1.0  # sheen_shading.glsl: the widest mip, around N


def sheenImageBasedLighting(s, ibl) -> np.ndarray:
    """Split sum (prefiltered at SHEEN_IBL_LOOKUP_ROUGHNESS = 1 around N, see the GLSL;
    reference mode integrates the sheen in reference_layered);
    `ibl` is matedit.shading.surface.IblInputs."""
    if ibl.mode == IBL_MODE_NONE:
        return np.zeros(np.broadcast_shapes(s.N.shape, s.V.shape))
    NoV = saturate(dot(s.N, s.V))
    if callable(ibl.prefiltered):  # around N (sheen_shading.glsl)
        pref = prefilteredRadiance(ibl.prefiltered, s.N,
                                   np.full(np.shape(NoV), SHEEN_IBL_LOOKUP_ROUGHNESS),
                                   ibl.mip_count)
    else:
        pref = f64(ibl.prefiltered)
    dfg = sheenDFG(s.sheenLut, NoV, s.sheenRoughness)
    return sheenSplitSum(pref, s.sheenColor, dfg) * ibl.intensity


__all__ = [
    "MIN_SHEEN_ROUGHNESS", "D_Charlie", "V_Charlie", "setupSheen",
    "sheenAlbedoScaling", "sheenAlpha", "sheenBRDF", "sheenBaseScale", "sheenBrdfCosine",
    "sheenDFG", "sheenImageBasedLighting", "sheenLambda", "sheenLambdaFit", "sheenLayer",
    "sheenLayerCosine", "sheenSampleDirection", "sheenSamplePdf", "sheenSplitSum",
]  # fmt: skip
