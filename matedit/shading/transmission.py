"""Twin of ``transmission.glsl``: specular transmission (Walter et al. 2007's rough
refraction for solids, the mirrored reflection lobe for thin walls, a sphere exit and
Beer-Lambert absorption)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading.brdf import D_GGX, F_Schlick
from matedit.shading.common import dot, f64, normalize, saturate


@dataclass
class TransmissionLobe:
    weight: np.ndarray   # (...,): transmission x (1 - metallic) x lobe view
    tint: np.ndarray     # (..., 3): transmissionColor x the absorption along the path
    eta: np.ndarray      # (...,)
    inside: np.ndarray   # (..., 3): the view ray after the first interface (thin: -V)


def refractClamped(incident, n, eta) -> np.ndarray:
    """GLSL's refract with the root's argument kept at 0 or more (tangent at the edge)."""
    incident, n, eta = f64(incident), f64(n), f64(eta)
    c = dot(n, incident)
    k = np.maximum(1.0 - eta * eta * (1.0 - c * c), 0.0)
    return eta[..., None] * incident - (eta * c + np.sqrt(k))[..., None] * n


def transmissionEntry(N, V, eta) -> np.ndarray:
    return refractClamped(-f64(V), N, 1.0 / f64(eta))


def transmissionSphereExit(N, inside, eta) -> np.ndarray:
    N, inside = f64(N), f64(inside)
    c = np.maximum(-dot(N, inside), 0.0)
    nOut = normalize(2.0 * c[..., None] * inside + N)
    return normalize(refractClamped(inside, -nOut, eta))


def beerLambert(attenuationColor, attenuationDistance, d) -> np.ndarray:
    dist = f64(attenuationDistance)
    c = np.clip(f64(attenuationColor), 1e-6, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(dist > 0.0, np.maximum(f64(d), 0.0) / np.where(dist > 0.0, dist, 1.0),
                         0.0)
    return np.where((dist > 0.0)[..., None], np.exp(np.log(c) * ratio[..., None]), 1.0)


def makeTransmissionLobe(weight, color, attenuationColor, attenuationDistance, thickness, ior,
                         metallic, thin: bool, N, V, shown) -> TransmissionLobe:
    N, V = f64(N), f64(V)
    shape = np.broadcast_shapes(N.shape, V.shape)[:-1]
    w = np.broadcast_to(saturate(weight) * (1.0 - f64(metallic)) * f64(shown), shape)
    eta = np.broadcast_to(np.maximum(f64(ior), 1.0 + 1e-4), shape)
    entry = transmissionEntry(N, V, eta)
    c = np.maximum(-dot(N, entry), 1e-3)
    thickness = f64(thickness)
    if thin:
        inside = np.broadcast_to(-V, shape + (3,))
        d = thickness / c
    else:
        inside = entry
        d = thickness * c
    tint = saturate(color) * beerLambert(attenuationColor, attenuationDistance, d)
    return TransmissionLobe(w, np.broadcast_to(tint, shape + (3,)), eta, inside)


def transmissionLookupRay(lobe: TransmissionLobe, N, roughness, thin: bool) -> np.ndarray:
    N = f64(N)
    if not thin:
        return transmissionSphereExit(N, lobe.inside, lobe.eta)
    a = f64(roughness) ** 2
    f = ((1.0 - a) * (np.sqrt(1.0 - a) + a))[..., None]
    return normalize(f * f64(lobe.inside) + (1.0 - f) * -N)


def transmissionLookupRoughness(lobe: TransmissionLobe, roughness, thin: bool) -> np.ndarray:
    r = f64(roughness)
    return r if thin else r * np.sqrt(0.5 * (1.0 - 1.0 / f64(lobe.eta)))


def smithG1GGX(NoX, a) -> np.ndarray:
    c, a = np.abs(f64(NoX)), f64(a)
    return 2.0 * c / np.maximum(c + np.sqrt(a * a + (1.0 - a * a) * c * c), 1e-12)


def refractionBtdfCosineNoFresnel(N, V, L, a, eta) -> tuple[np.ndarray, np.ndarray]:
    """f |NoL| / (1 - F) of Walter et al. 2007 eq 21 (GGX, separable Smith G), light below
    (NoL < 0), and the V.h its Fresnel takes (0 where the BTDF is 0)."""
    N, V, L, eta = f64(N), f64(V), f64(L), f64(eta)
    NoV, NoL = dot(N, V), dot(N, L)
    h = -(V + eta[..., None] * L)
    hh = dot(h, h)
    H = h / np.sqrt(np.maximum(hh, 1e-30))[..., None]
    H = np.where((dot(N, H) < 0.0)[..., None], -H, H)
    VoH, LoH = dot(V, H), dot(L, H)
    den = VoH + eta * LoH
    NxH = np.cross(N, H)
    D = D_GGX(saturate(dot(N, H)), a, dot(NxH, NxH))
    G = smithG1GGX(NoV, a) * smithG1GGX(NoL, a)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = VoH * -LoH * eta * eta * G * D / (NoV * np.maximum(den * den, 1e-12))
    ok = (NoL < 0.0) & (NoV > 0.0) & (hh >= 1e-12) & (VoH > 0.0) & (LoH < 0.0)
    return np.where(ok, f, 0.0), np.where(ok, VoH, 0.0)


def refractionBtdfCosine(N, V, L, a, eta, F0) -> np.ndarray:
    """f |NoL| of Walter et al. 2007 eq 21 (GGX, separable Smith G), light below (NoL < 0)."""
    f, VoH = refractionBtdfCosineNoFresnel(N, V, L, a, eta)
    return (1.0 - F_Schlick(F0, VoH)) * f[..., None]


def thinWalledBtdfCosineNoFresnel(N, V, L, a) -> tuple[np.ndarray, np.ndarray]:
    """f |NoL| / (1 - F) of the reflection lobe of L mirrored through the tangent plane, and
    the V.h of its Fresnel (0 where the BTDF is 0)."""
    N, V, L = f64(N), f64(V), f64(L)
    NoV, NoL = dot(N, V), dot(N, L)
    Lm = L - 2.0 * NoL[..., None] * N
    H = normalize(V + Lm)
    NxH = np.cross(N, H)
    D = D_GGX(saturate(dot(N, H)), a, dot(NxH, NxH))
    G = smithG1GGX(NoV, a) * smithG1GGX(NoL, a)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = D * G / (4.0 * NoV)
    ok = (NoL < 0.0) & (NoV > 0.0)
    return np.where(ok, f, 0.0), np.where(ok, saturate(dot(V, H)), 0.0)


def thinWalledBtdfCosine(N, V, L, a, F0) -> np.ndarray:
    """f |NoL| of the reflection lobe of L mirrored through the tangent plane, times 1 - F."""
    f, VoH = thinWalledBtdfCosineNoFresnel(N, V, L, a)
    return (1.0 - F_Schlick(F0, VoH)) * f[..., None]


def transmissionRadiance(lobe: TransmissionLobe, prefiltered, reflectedAlbedo) -> np.ndarray:
    return (f64(lobe.tint) * (f64(lobe.weight)[..., None] * (1.0 - f64(reflectedAlbedo)))
            * f64(prefiltered))
