"""Twin of ``brdf.glsl``: Lambert, GGX, Schlick-Smith visibility, Schlick Fresnel."""

from __future__ import annotations

import numpy as np

from matedit.shading.common import INV_PI, PI, f64, pow5

# a' = a + sourceRadius / (AREA_WIDEN_DIVISOR d): brdf.glsl's MATEDIT_AREA_WIDEN_DIVISOR (read
# at call time by the lights and the anisotropic lobe; benchmarks/bench_lights.py varies it).
AREA_WIDEN_DIVISOR = 2.0


def Fd_Lambert() -> float:
    return INV_PI


def D_GGX(NoH, a, oneMinusNoH2=None) -> np.ndarray:
    """Both GLSL overloads: D_GGX(NoH, a) and D_GGX(NoH, a, oneMinusNoH2)."""
    NoH, a = f64(NoH), f64(a)
    a2 = a * a
    if oneMinusNoH2 is None:
        oneMinusNoH2 = (1.0 - NoH) * (1.0 + NoH)
    d = f64(oneMinusNoH2) + NoH * NoH * a2
    return a2 / (PI * d * d)


def reflectionHalfVector(N, V, L):
    """(H, VoH, NoH, |N x H|^2, valid) of a reflection density (Walter et al. 2007 eq 13,
    14); valid where |L + V|^2 >= 1e-12 and V.H > 0. Shared by the isotropic and the
    anisotropic GGX densities."""
    N, V = f64(N), f64(V)
    h = f64(L) + V
    hh = (h * h).sum(-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        H = h / np.sqrt(np.maximum(hh, 1e-30))[..., None]
    VoH = (V * H).sum(-1)
    NoH = np.clip((N * H).sum(-1), 0.0, 1.0)
    NxH = np.cross(N, H)
    return H, VoH, NoH, (NxH * NxH).sum(-1), (hh >= 1e-12) & (VoH > 0.0)


def ggxReflectionPdf(N, V, L, a) -> np.ndarray:
    """Walter et al. 2007 eq 14, 38: D NoH / (4 VoH); 0 where H is undefined or VoH <= 0."""
    _, VoH, NoH, oneMinusNoH2, valid = reflectionHalfVector(N, V, L)
    with np.errstate(divide="ignore", invalid="ignore"):
        pdf = D_GGX(NoH, a, oneMinusNoH2) * NoH / (4.0 * VoH)
    return np.where(valid, pdf, 0.0)


def k_Analytic(roughness) -> np.ndarray:
    r = f64(roughness) + 1.0
    return r * r * 0.125


def k_IBL(a) -> np.ndarray:
    return 0.5 * f64(a)


def G1_Schlick(NoX, k) -> np.ndarray:
    NoX, k = f64(NoX), f64(k)
    return NoX / (NoX * (1.0 - k) + k)


def V_SchlickSmith(NoV, NoL, k) -> np.ndarray:
    NoV, NoL, k = f64(NoV), f64(NoL), f64(k)
    return 0.25 / ((NoV * (1.0 - k) + k) * (NoL * (1.0 - k) + k))


def Fc_SphericalGaussian(VoH) -> np.ndarray:
    VoH = f64(VoH)
    return np.exp2((-5.55473 * VoH - 6.98316) * VoH)


def Fc_Exact(VoH) -> np.ndarray:
    return pow5(1.0 - f64(VoH))


def F_Schlick(F0, VoH) -> np.ndarray:
    """F0 (..., 3), VoH (...) -> (..., 3)."""
    F0 = f64(F0)
    return F0 + (1.0 - F0) * Fc_SphericalGaussian(VoH)[..., None]


def F_SchlickExact(F0, VoH) -> np.ndarray:
    F0 = f64(F0)
    return F0 + (1.0 - F0) * Fc_Exact(VoH)[..., None]


def specularLobe(F0, a, k, NoV, NoL, NoH, VoH) -> np.ndarray:
    s = D_GGX(NoH, a) * V_SchlickSmith(NoV, NoL, k)
    return s[..., None] * F_Schlick(F0, VoH)


def diffuseLobe(diffuseColor) -> np.ndarray:
    return f64(diffuseColor) * INV_PI
