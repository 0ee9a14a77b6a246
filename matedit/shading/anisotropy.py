"""Twin of ``anisotropy.glsl``: anisotropic GGX, its projected-roughness Schlick-Smith
visibility, the bent reflection vector, the area lights' widening and the sampling.

Same names, same arithmetic, float64; vectorised over leading axes (pixels). The
convention (see the GLSL header): the lobe's T is the direction the highlight stretches
along, the roughness along it (at) the larger; physically that is across a brushing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading.brdf import F_Schlick, F_SchlickExact, k_Analytic, k_IBL
from matedit.shading.common import PI, cross, dot, f64, reflect, saturate

ANISOTROPY_MIN_ALPHA = 1e-3


def _widen_divisor() -> float:
    """brdf.glsl's MATEDIT_AREA_WIDEN_DIVISOR, read when called (a benchmark varies it)."""
    from matedit.shading import brdf

    return brdf.AREA_WIDEN_DIVISOR


@dataclass
class AnisotropicLobe:
    T: np.ndarray
    B: np.ndarray
    anisotropy: np.ndarray
    at: np.ndarray
    ab: np.ndarray


def anisotropicAlphas(a, anisotropy) -> tuple[np.ndarray, np.ndarray]:
    """Kulla and Conty 2017, "Revisiting Physically Based Shading at Imageworks":
    at = a (1 + anisotropy), ab = a (1 - anisotropy), ab kept at or above min(a, 1e-3)."""
    a, an = f64(a), f64(anisotropy)
    at = np.minimum(a * (1.0 + an), 1.0)
    ab = np.maximum(a * (1.0 - an), np.minimum(a, ANISOTROPY_MIN_ALPHA))
    return at, ab


def anisotropicTangent(direction, T, B, N) -> np.ndarray:
    """Gram-Schmidt of the tangent-space direction (z ignored) against N (Mikkelsen 2008);
    falls back to the projected T, then to the projected B turned a quarter about N."""
    d, T, B, N = f64(direction), f64(T), f64(B), f64(N)
    w = T * d[..., 0:1] + B * d[..., 1:2]
    t = w - N * dot(N, w)[..., None]
    tt = dot(t, t)
    tT = T - N * dot(N, T)[..., None]
    t = np.where((tt < 1e-12)[..., None], tT, t)
    tt = dot(t, t)
    tB = cross(B - N * dot(N, B)[..., None], N)
    t = np.where((tt < 1e-12)[..., None], tB, t)
    tt = dot(t, t)
    return t / np.sqrt(np.maximum(tt, 1e-30))[..., None]


def makeAnisotropicLobe(a, anisotropy, direction, T, B, N) -> AnisotropicLobe:
    """Kulla and Conty 2017 (alphas); bitangent N x T' of the projected tangent."""
    an = saturate(anisotropy)
    t = anisotropicTangent(direction, T, B, N)
    at, ab = anisotropicAlphas(a, an)
    return AnisotropicLobe(T=t, B=cross(f64(N), t), anisotropy=an, at=at, ab=ab)


def D_GGXAnisotropic(NoH, ToH, BoH, oneMinusNoH2, at, ab) -> np.ndarray:
    """Burley 2012, "Physically-Based Shading at Disney", B.2 eq 13, multiplied through by
    ab^2: (ab / at) ab^2 / (pi (ToH^2 ab^2/at^2 + BoH^2 + NoH^2 ab^2)^2); at at = ab, D_GGX's
    arithmetic on |N x H|^2."""
    NoH, ToH, BoH, om, at, ab = map(f64, (NoH, ToH, BoH, oneMinusNoH2, at, ab))
    ab2 = ab * ab
    d = np.where(at == ab, om + NoH * NoH * ab2,
                 ToH * ToH * (ab2 / (at * at)) + BoH * BoH + NoH * NoH * ab2)
    return (ab / at) * (ab2 / (PI * d * d))


def projectedAlpha(at, ab, ToX, oneMinusNoX2) -> np.ndarray:
    """Heitz 2014, "Understanding the Masking-Shadowing Function", eq 80:
    sqrt(ab^2 + (at^2 - ab^2) cos^2 phi)."""
    at, ab, ToX, om = map(f64, (at, ab, ToX, oneMinusNoX2))
    cos2 = np.minimum(ToX * ToX / np.maximum(om, 1e-12), 1.0)
    return np.sqrt(ab * ab + (at * at - ab * ab) * cos2)


def V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) -> np.ndarray:
    """Karis 2013 eq 4 with one k per direction (Heitz 2014 eq 80's projected roughness)."""
    NoV, NoL, kV, kL = map(f64, (NoV, NoL, kV, kL))
    return 0.25 / ((NoV * (1.0 - kV) + kV) * (NoL * (1.0 - kL) + kL))


def k_AnalyticProjected(alphaO) -> np.ndarray:
    """Karis 2013 eq 4 (Disney remapping) of the perceptual projected roughness."""
    return k_Analytic(np.sqrt(f64(alphaO)))


def _onemx2(N, X) -> np.ndarray:
    c = cross(N, X)
    return dot(c, c)


def _half(L, V) -> np.ndarray:
    h = f64(L) + f64(V)
    return h / np.sqrt(np.maximum(dot(h, h), 1e-30))[..., None]


def anisotropicSpecularTowards(l: AnisotropicLobe, N, V, NoV, F0, L) -> np.ndarray:
    """D Vis F NoL for analytic lights (spherical-Gaussian Fresnel, remapped k); 0 below
    the horizon, as the GLSL returns early."""
    N, V, L = f64(N), f64(V), f64(L)
    NoL = saturate(dot(N, L))
    H = _half(L, V)
    NoH = saturate(dot(N, H))
    VoH = saturate(dot(V, H))
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), _onemx2(N, H), l.at, l.ab)
        kV = k_AnalyticProjected(projectedAlpha(l.at, l.ab, dot(l.T, V), _onemx2(N, V)))
        kL = k_AnalyticProjected(projectedAlpha(l.at, l.ab, dot(l.T, L), _onemx2(N, L)))
        lobe = np.where(NoL > 0.0, D * V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) * NoL, 0.0)
    return lobe[..., None] * F_Schlick(F0, VoH)


def anisotropicReflection(l: AnisotropicLobe, N, V) -> np.ndarray:
    """Revie 2011 / McAuley 2015 (Filament's anisotropic IBL): reflect V about
    normalize(mix(N, (B x V) x B, anisotropy))."""
    N, V = f64(N), f64(V)
    n_a = cross(cross(l.B, V), l.B)
    an = f64(l.anisotropy)[..., None]
    bent = N * (1.0 - an) + n_a * an
    bb = dot(bent, bent)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = bent / np.sqrt(bb)[..., None]
    bent = np.where((bb > 1e-12)[..., None], unit, np.broadcast_to(N, unit.shape))
    # at anisotropy 0, N itself (not renormalised), as the GLSL
    bent = np.where((an > 0.0), bent, np.broadcast_to(N, bent.shape))
    return reflect(-V, bent)


def anisotropicSphereNormalization(at, ab, sourceRadius, d) -> np.ndarray:
    """Karis 2013 eq 10, 14 per axis: (at ab) / (at' ab'), a' = saturate(a + r / (2 d))."""
    at, ab = f64(at), f64(ab)
    widen = f64(sourceRadius) / (_widen_divisor() * np.maximum(f64(d), 1e-8))
    return (at * ab) / (saturate(at + widen) * saturate(ab + widen))


def anisotropicLineNormalization(l: AnisotropicLobe, N, axis, sourceLength, d) -> np.ndarray:
    """Karis 2013 eq 20 (a / a') of the lobe's alpha projected on the tube's axis."""
    axis = np.broadcast_to(f64(axis), np.broadcast_shapes(np.shape(axis), f64(N).shape))
    aAxis = projectedAlpha(l.at, l.ab, dot(l.T, axis), _onemx2(f64(N), axis))
    widen = 0.5 * f64(sourceLength) / (_widen_divisor() * np.maximum(f64(d), 1e-8))
    return aAxis / saturate(aAxis + widen)


def importanceSampleGGXAnisotropic(Xi, at, ab, N, T, B) -> np.ndarray:
    """Burley 2012, B.2 eq 16: normalize(sqrt(y/(1-y)) (at cos 2pi x T + ab sin 2pi x B) + N)."""
    Xi = f64(Xi)
    phi = 2.0 * PI * Xi[..., 0]
    tan_theta = np.sqrt(Xi[..., 1] / np.maximum(1.0 - Xi[..., 1], 1e-12))
    h = (tan_theta * f64(at) * np.cos(phi))[..., None] * f64(T) \
        + (tan_theta * f64(ab) * np.sin(phi))[..., None] * f64(B) + f64(N)
    return h / np.sqrt(dot(h, h))[..., None]


def ggxAnisotropicDirectionPdf(l: AnisotropicLobe, N, V, L) -> np.ndarray:
    """Walter et al. 2007 eq 14, 38: D(h) NoH / (4 VoH); 0 where H is undefined or VoH <= 0."""
    N, V = f64(N), f64(V)
    h = f64(L) + V
    hh = dot(h, h)
    with np.errstate(divide="ignore", invalid="ignore"):
        H = h / np.sqrt(np.maximum(hh, 1e-30))[..., None]
        VoH = dot(V, H)
        NoH = saturate(dot(N, H))
        D = D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), _onemx2(N, H), l.at, l.ab)
        pdf = D * NoH / (4.0 * VoH)
    return np.where((hh >= 1e-12) & (VoH > 0.0), pdf, 0.0)


def ggxAnisotropicSampleDirection(l: AnisotropicLobe, N, V, Xi) -> np.ndarray:
    H = importanceSampleGGXAnisotropic(Xi, l.at, l.ab, N, l.T, l.B)
    V = f64(V)
    return 2.0 * dot(V, H)[..., None] * H - V


def anisotropicBrdfCosineIBL(l: AnisotropicLobe, N, V, F0, L) -> np.ndarray:
    """f NoL as the IBL reference integrates it: k = alpha_o / 2 per direction, exact Fresnel."""
    N, V, L = f64(N), f64(V), f64(L)
    NoL = saturate(dot(N, L))
    NoV = np.maximum(dot(N, V), 1e-4)
    H = _half(L, V)
    NoH = saturate(dot(N, H))
    VoH = saturate(dot(V, H))
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), _onemx2(N, H), l.at, l.ab)
        kV = k_IBL(projectedAlpha(l.at, l.ab, dot(l.T, V), _onemx2(N, V)))
        kL = k_IBL(projectedAlpha(l.at, l.ab, dot(l.T, L), _onemx2(N, L)))
        lobe = np.where(NoL > 0.0, D * V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) * NoL, 0.0)
    return lobe[..., None] * F_SchlickExact(F0, VoH)


def anisotropicSampleIBL(l: AnisotropicLobe, N, V, Xi) -> tuple[np.ndarray, np.ndarray]:
    """(L, pdf): the GLSL's out parameter returned as the second value."""
    L = ggxAnisotropicSampleDirection(l, N, V, Xi)
    return L, ggxAnisotropicDirectionPdf(l, N, V, L)


def anisotropicPdfIBL(l: AnisotropicLobe, N, V, L) -> np.ndarray:
    return ggxAnisotropicDirectionPdf(l, N, V, L)
