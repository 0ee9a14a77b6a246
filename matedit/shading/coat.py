"""Twin of ``coat.glsl``: the clear coat lobe over the base (issue 23, beyond the talk).

Same names, same formulas and the same sources as the GLSL (cited there at each function;
docs/shading.md, "Clear coat", states the model). Vectors on the last axis; every field of a
CoatContext broadcasts over pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading.brdf import (
    D_GGX,
    Fc_Exact,
    Fc_SphericalGaussian,
    V_SchlickSmith,
    k_Analytic,
    k_IBL,
)
from matedit.shading.common import dot, f64, mix, reflect, saturate
from matedit.shading.ibl import environmentBRDF, prefilteredRadiance
from matedit.shading.sampling import importanceSampleGGX


@dataclass
class CoatContext:
    N: np.ndarray
    NoV: np.ndarray
    weight: np.ndarray
    roughness: np.ndarray
    a: np.ndarray
    k: np.ndarray
    F0: np.ndarray
    tint: np.ndarray
    scale: float = 1.0


def coatF0FromIor(ior) -> np.ndarray:
    # Fresnel at normal incidence, ((n - 1) / (n + 1))^2; glTF KHR_materials_clearcoat
    r = (f64(ior) - 1.0) / (f64(ior) + 1.0)
    return r * r


def f0UnderCoat(F0, coatIor) -> np.ndarray:
    # ((n1 - n2) / (n1 + n2))^2 with the base's n recovered from F0, n1 = coatIor
    s = np.sqrt(saturate(F0))
    n = f64(coatIor)[..., None]
    num = (1.0 + s) - n * (1.0 - s)
    den = (1.0 + s) + n * (1.0 - s)
    return (num / den) ** 2


def makeCoatContext(Nc, V, weight, roughness, minRoughness, color, ior, scale=1.0) -> CoatContext:
    # Karis 2013: a = roughness^2, k = (roughness + 1)^2 / 8, on the coat's roughness
    Nc, V = f64(Nc), f64(V)
    w = saturate(weight)
    r = np.clip(f64(roughness), minRoughness, 1.0)
    return CoatContext(
        N=Nc, NoV=np.maximum(dot(Nc, V), 1e-4), weight=w, roughness=saturate(roughness),
        a=r * r, k=k_Analytic(r), F0=coatF0FromIor(ior),
        tint=mix(np.ones(3), saturate(color), w[..., None]), scale=scale,
    )  # fmt: skip


def coatFresnel(c: CoatContext, cosTheta) -> np.ndarray:
    # Schlick 1994, exact fifth power, times the coat's weight
    return c.weight * (c.F0 + (1.0 - c.F0) * Fc_Exact(saturate(cosTheta)))


def coatTransmittance(c: CoatContext, NoLc) -> np.ndarray:
    # Filament's (1 - Fc), once towards V and once towards L; OpenPBR coat_color tint
    t = (1.0 - coatFresnel(c, c.NoV)) * (1.0 - coatFresnel(c, NoLc))
    return c.tint * t[..., None]


def coatSpecularTowards(c: CoatContext, V, L) -> np.ndarray:
    # Karis 2013, eq 3-5 on the coat's normal and alpha (a second GGX lobe, Filament)
    V, L = f64(V), f64(L)
    NoL = saturate(dot(c.N, L))
    h = L + V
    H = h / np.sqrt(np.maximum(dot(h, h), 1e-30))[..., None]
    NoH = saturate(dot(c.N, H))
    VoH = saturate(dot(V, H))
    NxH = np.cross(c.N, H)
    F = c.F0 + (1.0 - c.F0) * Fc_SphericalGaussian(VoH)
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGX(NoH, c.a, dot(NxH, NxH))
        lobe = np.where((NoL > 0.0) & (dot(h, h) >= 1e-12),
                        D * V_SchlickSmith(c.NoV, NoL, c.k) * F * NoL, 0.0)
    return lobe * c.weight * c.scale


def coatLayer(c: CoatContext, V, L, base) -> np.ndarray:
    # Filament: f = f_base (1 - Fc) + f_coat
    return f64(base) * coatTransmittance(c, dot(c.N, L)) + coatSpecularTowards(c, V, L)[..., None]


def coatImageBasedLighting(c: CoatContext, V, baseIbl, prefiltered, brdfLut, mipCount,
                           intensity, lut_values: bool = False) -> np.ndarray:
    """`prefiltered`: callable (R, lod) -> rgb, or already looked-up radiance; `brdfLut`: a LUT
    array or callable, or (A, B) values when `lut_values` (as surface.IblInputs)."""
    V = f64(V)
    Rc = reflect(-V, c.N)
    if callable(prefiltered):
        pref = prefilteredRadiance(prefiltered, Rc, c.roughness, mipCount)
    else:
        pref = f64(prefiltered)
    AB = f64(brdfLut) if lut_values else environmentBRDF(brdfLut, saturate(dot(c.N, V)),
                                                         c.roughness)
    coat = (c.F0 * AB[..., 0] + AB[..., 1]) * c.weight * c.scale
    return f64(baseIbl) * coatTransmittance(c, c.NoV) + pref * (coat * intensity)[..., None]


def coatReferenceAlpha(c: CoatContext) -> np.ndarray:
    return np.maximum(c.roughness * c.roughness, 1e-3)


def coatBrdfCosine(c: CoatContext, V, L) -> np.ndarray:
    # Karis 2013, SpecularIBL terms: D G F / (4 NoL NoV), k = a / 2, exact Fresnel
    V, L = f64(V), f64(L)
    NoL = saturate(dot(c.N, L))
    h = L + V
    H = h / np.sqrt(np.maximum(dot(h, h), 1e-30))[..., None]
    a = coatReferenceAlpha(c)
    NoH = saturate(dot(c.N, H))
    VoH = saturate(dot(V, H))
    NxH = np.cross(c.N, H)
    F = c.F0 + (1.0 - c.F0) * Fc_Exact(VoH)
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGX(NoH, a, dot(NxH, NxH))
        f = np.where((NoL > 0.0) & (dot(h, h) >= 1e-12),
                     D * V_SchlickSmith(c.NoV, NoL, k_IBL(a)) * F * NoL, 0.0)
    return f * c.weight * c.scale


def coatPdf(c: CoatContext, V, L) -> np.ndarray:
    # Walter et al. 2007: p(l) = D(h) NoH / (4 VoH)
    V, L = f64(V), f64(L)
    h = L + V
    hh = dot(h, h)
    with np.errstate(divide="ignore", invalid="ignore"):
        H = h / np.sqrt(np.maximum(hh, 1e-30))[..., None]
        VoH = dot(V, H)
        NoH = saturate(dot(c.N, H))
        NxH = np.cross(c.N, H)
        pdf = D_GGX(NoH, coatReferenceAlpha(c), dot(NxH, NxH)) * NoH / (4.0 * VoH)
    return np.where((hh >= 1e-12) & (VoH > 0.0), pdf, 0.0)


def coatSampleDirection(c: CoatContext, V, Xi) -> tuple[np.ndarray, np.ndarray]:
    """(L, pdf): the GLSL's return value and its `out float pdf`."""
    V = f64(V)
    H = importanceSampleGGX(f64(Xi), coatReferenceAlpha(c), c.N)
    L = 2.0 * dot(V, H)[..., None] * H - V
    return L, coatPdf(c, V, L)
