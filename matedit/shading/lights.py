"""Twin of ``lights.glsl``: the Light description and point, directional, sphere and tube lights."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from matedit.shading import anisotropy as _aniso
from matedit.shading import brdf as _brdf
from matedit.shading import coat
from matedit.shading.brdf import D_GGX, F_Schlick, V_SchlickSmith, diffuseLobe, k_Analytic
from matedit.shading.common import dot, f64, length, normalize, reflect, saturate, sq
from matedit.shading.sheen import sheenBaseScale, sheenLayer
from matedit.shading.subsurface import SubsurfaceLobe, subsurfaceCosine
from matedit.shading.thin_film import ThinFilm, filmOrFresnel, thinFilmFresnel
from matedit.shading.transmission import (
    TransmissionLobe,
    refractionBtdfCosineNoFresnel,
    thinWalledBtdfCosineNoFresnel,
)

LIGHT_TYPE_POINT = 0
LIGHT_TYPE_DIRECTIONAL = 1
LIGHT_TYPE_SPHERE = 2
LIGHT_TYPE_TUBE = 3
LIGHT_TYPES = {
    "point": LIGHT_TYPE_POINT,
    "directional": LIGHT_TYPE_DIRECTIONAL,
    "sphere": LIGHT_TYPE_SPHERE,
    "tube": LIGHT_TYPE_TUBE,
}
LIGHT_FALLOFF_EPS = 0.01
MIN_ANALYTIC_ROUGHNESS = 0.03

LightKind = Literal["point", "directional", "sphere", "tube"]


@dataclass
class Light:
    """One analytic light. Units: metres; `direction` is the travel direction of a
    directional light and the unit axis of a tube; `position` is a sphere's or tube's centre."""

    kind: LightKind = "point"
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    influence_radius: float = 10.0
    source_radius: float = 0.0
    source_length: float = 0.0

    @property
    def type(self) -> int:
        return LIGHT_TYPES[self.kind]


@dataclass
class ShadingContext:
    P: np.ndarray
    N: np.ndarray
    V: np.ndarray
    NoV: np.ndarray
    diffuseColor: np.ndarray
    F0: np.ndarray
    roughness: np.ndarray
    a: np.ndarray
    k: np.ndarray
    specularScale: object = 1.0  # or the multiple-scattering compensation, (..., 3)
    coat: coat.CoatContext | None = None  # where the material has a coat (MATERIAL_HAS_COAT)
    # MATERIAL_HAS_ANISOTROPY: the anisotropic lobe (anisotropy.AnisotropicLobe); None: off
    aniso: _aniso.AnisotropicLobe | None = None
    # The sheen (the GLSL's fields under MATERIAL_HAS_SHEEN_COLOR): None = no sheen;
    # matedit.shading.sheen.setupSheen sets them and sheenLut, the LUT the lights read.
    sheenColor: object = None
    sheenRoughness: object = None
    sheenAlpha: object = None
    sheenMax: object = None
    sheenScaleV: object = None
    sheenLut: object = None
    # MATERIAL_HAS_SUBSURFACE: the subsurface diffuse (subsurface.SubsurfaceLobe); None: off
    subsurface: SubsurfaceLobe | None = None
    # MATERIAL_HAS_THIN_FILM_THICKNESS: the thin film on the base (thin_film.ThinFilm); None: off
    film: ThinFilm | None = None
    # MATERIAL_HAS_TRANSMISSION: transmission.TransmissionLobe; None: off. thin_walled:
    # MATERIAL_THIN_WALLED
    transmission: TransmissionLobe | None = None
    thin_walled: bool = False


def makeShadingContext(P, N, V, diffuseColor, F0, roughness) -> ShadingContext:
    N, V = f64(N), f64(V)
    r = np.clip(f64(roughness), MIN_ANALYTIC_ROUGHNESS, 1.0)
    return ShadingContext(
        P=f64(P), N=N, V=V, NoV=np.maximum(dot(N, V), 1e-4), diffuseColor=f64(diffuseColor),
        F0=f64(F0), roughness=r, a=r * r, k=k_Analytic(r),
    )  # fmt: skip


def diffuseTowards(s: ShadingContext, NoL) -> np.ndarray:
    """Lambert of the clamped cosine plus the subsurface lobe of the signed cosine NoL."""
    NoL = f64(NoL)
    diffuse = diffuseLobe(s.diffuseColor) * saturate(NoL)[..., None]
    if s.subsurface is not None:
        diffuse = diffuse + subsurfaceCosine(s.subsurface, NoL)
    return diffuse


def distanceWindow(d, influenceRadius) -> np.ndarray:
    x = f64(d) / f64(influenceRadius)
    x2 = x * x
    return sq(saturate(1.0 - x2 * x2))


def distanceFalloff(d, influenceRadius) -> np.ndarray:
    d = f64(d)
    return distanceWindow(d, influenceRadius) / (d * d + LIGHT_FALLOFF_EPS**2)


def specularTowards(s: ShadingContext, L) -> np.ndarray:
    if s.aniso is not None:
        if s.film is None:
            return _aniso.anisotropicSpecularTowards(s.aniso, s.N, s.V, s.NoV, s.F0, L) * f64(
                s.specularScale)
        # F0 = 1: the lobe's Schlick factor exactly 1, times the film's Fresnel at V.H
        hf = f64(L) + s.V
        VoHf = saturate(dot(s.V, hf / np.sqrt(np.maximum(dot(hf, hf), 1e-30))[..., None]))
        lobe = _aniso.anisotropicSpecularTowards(s.aniso, s.N, s.V, s.NoV, np.ones(3), L)
        return np.where((s.film.thickness > 0.0)[..., None],
                        lobe * thinFilmFresnel(s.film, VoHf),
                        _aniso.anisotropicSpecularTowards(s.aniso, s.N, s.V, s.NoV, s.F0, L)
                        ) * f64(s.specularScale)
    NoL = saturate(dot(s.N, L))
    h = f64(L) + s.V
    H = h / np.sqrt(np.maximum(dot(h, h), 1e-30))[..., None]
    NoH = saturate(dot(s.N, H))
    VoH = saturate(dot(s.V, H))
    NxH = np.cross(s.N, H)
    # Masked where NoL = 0 or L = -V (H undefined, D infinite), as the GLSL returns 0.
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGX(NoH, s.a, dot(NxH, NxH))
        lobe = np.where((NoL > 0.0) & (dot(h, h) >= 1e-12),
                        D * V_SchlickSmith(s.NoV, NoL, s.k) * NoL, 0.0)
    return lobe[..., None] * filmOrFresnel(s.film, s.F0, VoH, F_Schlick) * f64(s.specularScale)


def sphereRepresentativePoint(Lc, R, sourceRadius) -> np.ndarray:
    Lc, R = f64(Lc), f64(R)
    centerToRay = dot(Lc, R)[..., None] * R - Lc
    t = saturate(f64(sourceRadius) / np.maximum(length(centerToRay), 1e-8))
    return Lc + centerToRay * t[..., None]


def sphereNormalization(a, sourceRadius, d) -> np.ndarray:
    a = f64(a)
    widen = f64(sourceRadius) / (_brdf.AREA_WIDEN_DIVISOR * np.maximum(f64(d), 1e-8))
    a_prime = saturate(a + widen)
    return sq(a / a_prime)


def lineNormalization(a, sourceLength, d) -> np.ndarray:
    a = f64(a)
    a_prime = saturate(a + 0.5 * f64(sourceLength) / (_brdf.AREA_WIDEN_DIVISOR
                                                       * np.maximum(f64(d), 1e-8)))
    return a / a_prime


def _scale(light: Light, factor) -> np.ndarray:
    return f64(light.color) * (light.intensity * f64(factor))[..., None]


def pointLight(s: ShadingContext, light: Light) -> np.ndarray:
    Lc = f64(light.position) - s.P
    d = length(Lc)
    L = Lc / np.maximum(d, 1e-8)[..., None]
    NoL = saturate(dot(s.N, L))
    radiance = diffuseTowards(s, dot(s.N, L)) + specularTowards(s, L)
    if s.sheenColor is not None:
        radiance = sheenLayer(s, radiance, L, NoL)
    if s.coat is not None:
        radiance = coat.coatLayer(s.coat, s.V, L, radiance)
    return radiance * _scale(light, distanceFalloff(d, light.influence_radius))


def directionalLight(s: ShadingContext, light: Light) -> np.ndarray:
    L = np.broadcast_to(-f64(light.direction), s.N.shape)
    NoL = saturate(dot(s.N, L))
    radiance = diffuseTowards(s, dot(s.N, L)) + specularTowards(s, L)
    if s.sheenColor is not None:
        radiance = sheenLayer(s, radiance, L, NoL)
    if s.coat is not None:
        radiance = coat.coatLayer(s.coat, s.V, L, radiance)
    return radiance * _scale(light, 1.0)


def sphereLight(s: ShadingContext, light: Light) -> np.ndarray:
    Lc = f64(light.position) - s.P
    d = length(Lc)
    falloff = distanceFalloff(d, light.influence_radius)
    NoLc = saturate(dot(s.N, Lc / np.maximum(d, 1e-8)[..., None]))
    diffuse = diffuseTowards(s, dot(s.N, Lc / np.maximum(d, 1e-8)[..., None]))
    R = reflect(-s.V, s.N)
    L = normalize(sphereRepresentativePoint(Lc, R, light.source_radius))
    specular = specularTowards(s, L) * sphereNormalization(s.a, light.source_radius, d)[..., None]
    if s.aniso is not None:  # the point closest to R in the lobe's metric where anisotropy > 0
        La = normalize(anisotropicSphereRepresentativePoint(s.aniso, Lc, R, light.source_radius))
        lit = specularTowards(s, La) * _aniso.anisotropicSphereNormalization(
            s.aniso, s.V, La, light.source_radius, d)[..., None]
        specular = np.where((f64(s.aniso.anisotropy) > 0.0)[..., None], lit, specular)
    if s.sheenColor is not None:  # towards the centre, like the diffuse
        diffuse = sheenLayer(s, diffuse + specular, Lc / np.maximum(d, 1e-8)[..., None], NoLc)
        specular = 0.0
    if s.coat is not None:
        c = s.coat
        Lcoat = normalize(sphereRepresentativePoint(Lc, reflect(-s.V, c.N), light.source_radius))
        through = coat.coatTransmittance(c, dot(c.N, Lc) / np.maximum(d, 1e-8))
        highlight = coat.coatSpecularTowards(c, s.V, Lcoat) * sphereNormalization(
            c.a, light.source_radius, d)
        return ((diffuse + specular) * through + highlight[..., None]) * _scale(light, falloff)
    return (diffuse + specular) * _scale(light, falloff)


def tubeCosine(N, L0, L1) -> np.ndarray:
    return dot(N, L0) / (2.0 * length(L0)) + dot(N, L1) / (2.0 * length(L1))


def tubeDenominator(L0, L1) -> np.ndarray:
    l0l1, d01 = length(L0) * length(L1), dot(L0, L1)
    c = np.cross(f64(L0), f64(L1))
    with np.errstate(divide="ignore", invalid="ignore"):
        opposed = dot(c, c) / (l0l1 - d01)
    den = np.where(d01 >= 0.0, l0l1 + d01, opposed)
    return den + 2.0 * LIGHT_FALLOFF_EPS**2


def tubeIrradiance(N, L0, L1) -> np.ndarray:
    return 2.0 * saturate(tubeCosine(N, L0, L1)) / tubeDenominator(L0, L1)


def tubeRepresentativePoint(L0, L1, R) -> np.ndarray:
    L0, L1, R = f64(L0), f64(L1), f64(R)
    Ld = L1 - L0
    RoLd = dot(R, Ld)
    t = (dot(R, L0) * RoLd - dot(L0, Ld)) / np.maximum(dot(Ld, Ld) - RoLd * RoLd, 1e-12)
    return L0 + saturate(t)[..., None] * Ld


def anisotropicSphereRepresentativePoint(l, Lc, R, sourceRadius) -> np.ndarray:
    """The disc point closest to the mirror direction R in the lobe's metric, in the gnomonic
    plane about the light's direction (unnormalised); the talk's point where R.Ln <= 0."""
    Lc, R = f64(Lc), f64(R)
    d = length(Lc)
    Ln = Lc / np.maximum(d, 1e-8)[..., None]
    RoL = dot(R, Ln)
    e1, e2 = _aniso.anisotropicLightFrame(l, Ln)
    o = R / np.where(RoL > 1e-8, RoL, 1.0)[..., None] - Ln
    r = f64(sourceRadius)
    rho = r / np.sqrt(np.maximum(d * d - r * r, 1e-16))
    p1, p2 = _aniso.anisotropicDiscPoint(dot(o, e1), dot(o, e2), rho, sq(l.ab / l.at))
    point = Ln + p1[..., None] * e1 + p2[..., None] * e2
    return np.where((RoL <= 1e-8)[..., None], sphereRepresentativePoint(Lc, R, sourceRadius),
                    point)


def anisotropicTubeRepresentativePoint(l, L0, L1, R) -> np.ndarray:
    """The segment's point whose direction is closest to R in the lobe's metric (gnomonic
    image about the centre's direction, clamped quadratic, projective parameter); the talk's
    where R or an end points away."""
    L0, L1, R = f64(L0), f64(L1), f64(R)
    Lc = 0.5 * (L0 + L1)
    Ln = Lc / np.maximum(length(Lc), 1e-8)[..., None]
    z0, z1, RoL = dot(L0, Ln), dot(L1, Ln), dot(R, Ln)
    bad = (RoL <= 1e-8) | (z0 <= 1e-8) | (z1 <= 1e-8)
    safe = lambda z: np.where(bad, 1.0, z)[..., None]  # noqa: E731
    e1, e2 = _aniso.anisotropicLightFrame(l, Ln)
    g0 = L0 / safe(z0)
    dl = L1 / safe(z1) - g0
    og = R / safe(RoL) - g0
    q = sq(l.ab / l.at)
    dl1, dl2 = dot(dl, e1), dot(dl, e2)
    num = q * dot(og, e1) * dl1 + dot(og, e2) * dl2
    den = q * dl1 * dl1 + dl2 * dl2
    sg = saturate(num / np.maximum(den, 1e-30))
    t = sg * z0 / np.maximum(sg * z0 + (1.0 - sg) * z1, 1e-30)
    return np.where(bad[..., None], tubeRepresentativePoint(L0, L1, R),
                    L0 + t[..., None] * (L1 - L0))


def tubeLight(s: ShadingContext, light: Light) -> np.ndarray:
    Lc = f64(light.position) - s.P
    d = length(Lc)
    half_axis = 0.5 * f64(light.source_length)[..., None] * f64(light.direction)
    L0, L1 = Lc - half_axis, Lc + half_axis
    window = distanceWindow(d, light.influence_radius)
    diffuse = diffuseLobe(s.diffuseColor) * tubeIrradiance(s.N, L0, L1)[..., None]
    if s.subsurface is not None:  # the segment's signed mean cosine
        diffuse = diffuse + subsurfaceCosine(s.subsurface, tubeCosine(s.N, L0, L1)) * (
            2.0 / tubeDenominator(L0, L1))[..., None]
    R = reflect(-s.V, s.N)
    Lp = tubeRepresentativePoint(L0, L1, R)
    dp = length(Lp)
    L = normalize(sphereRepresentativePoint(Lp, R, light.source_radius))
    energy = lineNormalization(s.a, light.source_length, d) * sphereNormalization(
        s.a, light.source_radius, dp
    )
    specular = specularTowards(s, L) * (energy / (dp * dp + LIGHT_FALLOFF_EPS**2))[..., None]
    if s.aniso is not None:  # the points closest to R in the lobe's metric (anisotropy > 0)
        Lpa = anisotropicTubeRepresentativePoint(s.aniso, L0, L1, R)
        dpa = length(Lpa)
        La = normalize(anisotropicSphereRepresentativePoint(s.aniso, Lpa, R,
                                                            light.source_radius))
        energy_a = _aniso.anisotropicTubeNormalization(
            s.aniso, s.N, s.V, La, light.direction, light.source_length, d,
            light.source_radius, dpa)
        lit = specularTowards(s, La) * (energy_a / (dpa * dpa + LIGHT_FALLOFF_EPS**2))[..., None]
        specular = np.where((f64(s.aniso.anisotropy) > 0.0)[..., None], lit, specular)
    if s.sheenColor is not None:  # towards the centre times the segment's irradiance
        diffuse = sheenLayer(s, diffuse + specular, Lc / np.maximum(d, 1e-8)[..., None],
                             tubeIrradiance(s.N, L0, L1))
        specular = 0.0
    if s.coat is not None:
        c = s.coat
        Rc = reflect(-s.V, c.N)
        Lpc = tubeRepresentativePoint(L0, L1, Rc)
        dpc = length(Lpc)
        Lcoat = normalize(sphereRepresentativePoint(Lpc, Rc, light.source_radius))
        coat_energy = lineNormalization(c.a, light.source_length, d) * sphereNormalization(
            c.a, light.source_radius, dpc)
        through = coat.coatTransmittance(c, dot(c.N, Lc) / np.maximum(d, 1e-8))
        highlight = coat.coatSpecularTowards(c, s.V, Lcoat) * (
            coat_energy / (dpc * dpc + LIGHT_FALLOFF_EPS**2))
        return ((diffuse + specular) * through + highlight[..., None]) * _scale(light, window)
    return (diffuse + specular) * _scale(light, window)


def transmissionLayers(s: ShadingContext, L) -> np.ndarray:
    """Twin of lights.glsl's: the sheen's albedo scaling and the coat's transmittance at the
    light's mirrored cosine -N.L (1 where the material has neither)."""
    k: np.ndarray = np.ones(np.broadcast_shapes(s.N.shape, np.shape(L)))
    if s.sheenColor is not None:
        k = k * sheenBaseScale(s, -dot(s.N, L))[..., None]
    if s.coat is not None:
        k = k * coat.coatTransmittance(s.coat, -dot(s.coat.N, L))
    return k


def transmissionTowards(s: ShadingContext, L) -> np.ndarray:
    """Twin of lights.glsl's: the BTDF with the base's (or the film's) Fresnel, through the
    layers over the base."""
    t = s.transmission
    assert t is not None
    if s.thin_walled:
        f, VoH = thinWalledBtdfCosineNoFresnel(s.N, s.V, L, s.a)
    else:
        f, VoH = refractionBtdfCosineNoFresnel(s.N, s.V, L, s.a, t.eta)
    return ((1.0 - filmOrFresnel(s.film, s.F0, VoH, F_Schlick)) * f[..., None] * f64(t.tint)
            * f64(t.weight)[..., None] * transmissionLayers(s, L))


def transmissionLight(s: ShadingContext, light: Light) -> np.ndarray:
    """Twin of lights.glsl's: each type as its specular, along the transmitted view ray."""
    assert s.transmission is not None
    ray = f64(s.transmission.inside)
    if light.kind == "directional":
        L = np.broadcast_to(-f64(light.direction), s.N.shape)
        return transmissionTowards(s, L) * _scale(light, 1.0)
    Lc = f64(light.position) - s.P
    d = length(Lc)
    if light.kind == "sphere":
        L = normalize(sphereRepresentativePoint(Lc, ray, light.source_radius))
        return transmissionTowards(s, L) * _scale(
            light, sphereNormalization(s.a, light.source_radius, d)
            * distanceFalloff(d, light.influence_radius))
    if light.kind == "tube":
        half_axis = 0.5 * f64(light.source_length)[..., None] * f64(light.direction)
        Lp = tubeRepresentativePoint(Lc - half_axis, Lc + half_axis, ray)
        dp = length(Lp)
        L = normalize(sphereRepresentativePoint(Lp, ray, light.source_radius))
        energy = (lineNormalization(s.a, light.source_length, d)
                  * sphereNormalization(s.a, light.source_radius, dp))
        return transmissionTowards(s, L) * _scale(
            light, energy / (dp * dp + LIGHT_FALLOFF_EPS**2)
            * distanceWindow(d, light.influence_radius))
    return transmissionTowards(s, Lc / np.maximum(d, 1e-8)[..., None]) * _scale(
        light, distanceFalloff(d, light.influence_radius))


def evaluateLight(s: ShadingContext, light: Light) -> np.ndarray:
    kind = {
        "point": pointLight,
        "directional": directionalLight,
        "sphere": sphereLight,
        "tube": tubeLight,
    }
    out = kind[light.kind](s, light)
    if s.transmission is not None:  # from behind the surface
        out = out + transmissionLight(s, light)
    return out
