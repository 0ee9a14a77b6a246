"""Twin of ``surface.glsl``: the whole shading of a MaterialAttributes, for renderer tests."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from matedit.shading import anisotropy as _aniso
from matedit.shading import coat as _coat
from matedit.shading import reference_layered as _layered
from matedit.shading import subsurface as _sss
from matedit.shading import thin_film as _film
from matedit.shading import transmission as _trans
from matedit.shading.common import dot, f64, mix, reflect, saturate
from matedit.shading.ibl import (
    IBL_MODE_NONE,
    IBL_MODE_REFERENCE,
    IBL_MODE_SPLIT_SUM,
    Environment,
    diffuseIrradianceSH9,
    energyCompensation,
    environmentBRDF,
    irradianceSH9,
    makeReferenceSurface,
    prefilteredRadiance,
    referenceEnvironmentIBL,
    splitSumSpecular,
)
from matedit.shading.lights import (
    MIN_ANALYTIC_ROUGHNESS,
    Light,
    ShadingContext,
    evaluateLight,
    makeShadingContext,
)
from matedit.shading.material import (
    MaterialAttributes,
    computeDiffuseColor,
    materialF0,
    tangentToWorldNormal,
)
from matedit.shading.sampling import tangentFrame
from matedit.shading.sheen import lut_of, setupSheen, sheenImageBasedLighting

# The lobe bits of MATEDIT_LOBES (surface.glsl).
LOBE_DIFFUSE, LOBE_SPECULAR, LOBE_COAT, LOBE_SHEEN, LOBE_EMISSIVE = 1, 2, 4, 8, 16
LOBE_SUBSURFACE = 32
LOBE_TRANSMISSION = 64
LOBES_ALL = 127


def lobeOn(lobes: int, lobe: int) -> float:
    return 1.0 if lobes & lobe else 0.0


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
    environment: Environment | None = None
    environment_distribution: object = None
    intensity: float = 1.0
    samples: int = 64
    sample_offset: tuple[float, float] = (0.0, 0.0)
    mode: int = 0
    # The coat's own lookups where `prefiltered` / `brdf_lut` hold already looked-up values
    # (the coat reads them along its own reflection vector, NoV and roughness); None: the same.
    coat_prefiltered: object = None
    coat_brdf_lut: object = None
    # The anisotropic environment BRDF table the renderer binds at ANISOTROPY_LUT
    # (matedit.ibl.anisotropy_lut.anisotropy_lut()); None: the isotropic LUT alone.
    anisotropy_lut: object = None
    # The transmission's lookup along its exit ray where `prefiltered` holds looked-up
    # values; None: `prefiltered` (then callable).
    transmission_prefiltered: object = None


def directLighting(s: ShadingContext, lights: Sequence[Light]) -> np.ndarray:
    total = np.zeros(np.broadcast_shapes(s.N.shape, s.P.shape))
    for light in lights:
        total = total + evaluateLight(s, light)
    return total


def subsurfaceImageBasedLighting(lobe: _sss.SubsurfaceLobe, N, ibl: IblInputs) -> np.ndarray:
    """The subsurface lobe's split sum: wrapped SH irradiance at N, irradiance about -N."""
    N = f64(N)
    return _sss.subsurfaceIrradiance(lobe, _sss.wrappedIrradianceSH9(ibl.sh, N, lobe.wrap),
                                     irradianceSH9(ibl.sh, -N)) * ibl.intensity


def anisotropicPrefilteredRadiance(prefilteredEnv, l: _aniso.AnisotropicLobe, N, V, roughness,
                                   mipCount) -> np.ndarray:
    """The taps' lookups (anisotropy.anisotropicTapDirection) weighted by
    anisotropicTapWeight, normalised by the weights' sum; `prefilteredEnv` as
    prefilteredRadiance's (R, lod) -> (..., 3)."""
    tap_roughness = _aniso.anisotropicTapRoughness(l, roughness)
    tap_sum: np.ndarray = np.zeros(3)
    weight_sum: np.ndarray = np.zeros(1)
    for i in range(_aniso.ANISOTROPY_IBL_TAPS):
        R = _aniso.anisotropicTapDirection(l, N, V, i)
        w = _aniso.anisotropicTapWeight(N, R, i)[..., None]
        tap_sum = tap_sum + w * prefilteredRadiance(prefilteredEnv, R, tap_roughness, mipCount)
        weight_sum = weight_sum + w
    return tap_sum / weight_sum


def transmissionImageBasedLighting(lobe: _trans.TransmissionLobe, N, reflected, roughness,
                                   thin: bool, ibl: IblInputs) -> np.ndarray:
    """Twin of surface.glsl's: the prefiltered environment along the exit ray, times what
    the reflection leaves."""
    if ibl.transmission_prefiltered is not None:
        pref = f64(ibl.transmission_prefiltered)
    elif callable(ibl.prefiltered):
        R = _trans.transmissionLookupRay(lobe, N, roughness, thin)
        pref = prefilteredRadiance(ibl.prefiltered, R,
                                   _trans.transmissionLookupRoughness(lobe, roughness, thin),
                                   ibl.mip_count)
    else:
        raise ValueError("the transmission looks the environment up along its own ray: "
                         "IblInputs.prefiltered must be callable, or give "
                         "transmission_prefiltered")
    return _trans.transmissionRadiance(lobe, pref, reflected) * ibl.intensity


def imageBasedLighting(N, V, diffuseColor, F0, roughness, ibl: IblInputs,
                       specularScale=1.0, aniso=None, film=None) -> np.ndarray:
    """`aniso`: the anisotropic lobe (MATERIAL_HAS_ANISOTROPY), None where it is off.
    `film`: the thin film (MATERIAL_HAS_THIN_FILM_THICKNESS), whose Airy reflectance at N.V
    replaces F0 in the split sum where its thickness is not 0; None where it is off."""
    N, V = f64(N), f64(V)
    if ibl.mode == IBL_MODE_NONE:
        return np.zeros(np.broadcast_shapes(N.shape, V.shape))
    if ibl.mode == IBL_MODE_REFERENCE:
        if ibl.environment is None:
            raise ValueError("the reference mode samples IblInputs.environment: none given")
        count = max(int(ibl.samples), 1)
        if ibl.environment_distribution is None:
            raise ValueError("reference mode needs IblInputs.environment_distribution")
        rs = makeReferenceSurface(N, V, diffuseColor, F0, roughness, specularScale)
        color = referenceEnvironmentIBL(ibl.environment, ibl.environment_distribution, rs,
                                        count, ibl.sample_offset)
    else:
        NoV = saturate(dot(N, V))
        if not callable(ibl.prefiltered):
            pref = f64(ibl.prefiltered)
        elif aniso is not None:
            # the anisotropic split sum's taps along the lobe's long axis (anisotropy.glsl)
            pref = anisotropicPrefilteredRadiance(ibl.prefiltered, aniso, N, V, roughness,
                                                  ibl.mip_count)
        else:
            pref = prefilteredRadiance(ibl.prefiltered, reflect(-V, N), roughness, ibl.mip_count)
        AB = f64(ibl.brdf_lut) if ibl.lut_values else environmentBRDF(ibl.brdf_lut, NoV, roughness)
        if aniso is not None and ibl.anisotropy_lut is not None:
            AB = AB + _aniso.anisotropicEnvironmentBRDF(
                ibl.anisotropy_lut, NoV, roughness, aniso.anisotropy,
                _aniso.anisotropicViewCos2(aniso, N, V))
        if film is not None:  # F_film(NoV) A + B (thin_film.glsl)
            F0 = np.where((f64(film.thickness) > 0.0)[..., None],
                          _film.thinFilmFresnel(film, NoV), f64(F0))
        color = diffuseIrradianceSH9(ibl.sh, N, diffuseColor) + splitSumSpecular(
            pref, AB, F0) * f64(specularScale)
    return color * ibl.intensity


def shadeSurface(
    m: MaterialAttributes, P, N, V, lights: Sequence[Light] = (), ibl: IblInputs | None = None,
    energy_compensation: bool = False, frame: tuple | None = None, lobes: int = LOBES_ALL,
    coat: bool | None = None,
    anisotropic: bool = False,
    sheen: bool | None = None,
    subsurface: bool | None = None,
    thin_film: bool | None = None,
    transmission: bool | None = None,
    thin_walled: bool = False,
) -> np.ndarray:
    """(direct + ibl) * cavity + emissive; N is the world shading normal.
    `energy_compensation`: the GLSL's MATEDIT_ENERGY_COMPENSATION (Fdez-Aguera 2019).
    `frame`: (Ng, T, B), the orthonormal tangent frame of the geometric normal that the coat
    normal and the anisotropy direction are given in (None: the talk's model needs none).
    `lobes`: the GLSL's MATEDIT_LOBES, a mask of LOBE_* bits (the viewport's lobe views).
    `coat`: the GLSL's MATERIAL_HAS_COAT (None: where m.coat is not 0 anywhere).
    `anisotropic`: the GLSL's MATERIAL_HAS_ANISOTROPY (anisotropic GGX from m.anisotropy and
    m.anisotropyDirection in `frame`; without a frame, tangentFrame(N) as the GLSL's
    4-argument overload).
    `sheen`: the GLSL's MATERIAL_HAS_SHEEN_COLOR; None: where any sheenColor is not 0.
    `subsurface`: the GLSL's MATERIAL_HAS_SUBSURFACE; None: where any subsurface is not 0.
    `thin_film`: the GLSL's MATERIAL_HAS_THIN_FILM_THICKNESS; None: where any
    thinFilmThickness is not 0.
    `transmission`: MATERIAL_HAS_TRANSMISSION; None: where any transmission is not 0.
    `thin_walled`: MATERIAL_THIN_WALLED."""
    ibl = ibl or IblInputs(mode=IBL_MODE_NONE)
    if sheen is None:
        sheen = bool(np.any(f64(m.sheenColor) != 0.0))
    if subsurface is None:
        subsurface = bool(np.any(f64(m.subsurface) != 0.0))
    if transmission is None:
        transmission = bool(np.any(f64(m.transmission) != 0.0))
    diffuseColor = computeDiffuseColor(m.baseColor, m.metallic)
    F0 = materialF0(m)
    if coat is None:
        coat = bool(np.any(f64(m.coat) != 0.0))
    if coat:
        F0 = mix(F0, _coat.f0UnderCoat(F0, m.coatIor), saturate(m.coat)[..., None])
    roughness = saturate(m.roughness)
    s = makeShadingContext(P, N, V, diffuseColor, F0, roughness)
    if coat:
        # the coat normal in the geometric normal's frame (its default (0, 0, 1) is Ng)
        Nc = f64(N) if frame is None else tangentToWorldNormal(m.coatNormal, frame[1],
                                                                 frame[2], frame[0])
        s.coat = _coat.makeCoatContext(Nc, V, m.coat, m.coatRoughness, MIN_ANALYTIC_ROUGHNESS,
                                       m.coatColor, m.coatIor, lobeOn(lobes, LOBE_COAT))
    if anisotropic:
        if frame is None:
            T, B = tangentFrame(f64(N))
        else:
            _, T, B = frame
        s.aniso = _aniso.makeAnisotropicLobe(s.a, m.anisotropy, m.anisotropyDirection, T, B, N)
    if subsurface:  # the subsurface diffuse takes its weight's share of the Lambert lobe
        s.subsurface = _sss.makeSubsurfaceLobe(m.subsurface, m.subsurfaceColor,
                                               m.subsurfaceRadius, m.thickness, m.metallic,
                                               lobeOn(lobes, LOBE_SUBSURFACE))
        s.diffuseColor = s.diffuseColor * (1.0 - saturate(m.subsurface))[..., None]
        diffuseColor = s.diffuseColor
    if thin_film is None:
        thin_film = bool(np.any(f64(m.thinFilmThickness) != 0.0))
    if thin_film:  # on the base, under the coat where there is one (surface.glsl)
        outside = 1.0 + (f64(m.coatIor) - 1.0) * saturate(m.coat) if coat else 1.0
        s.film = _film.makeThinFilm(m.thinFilmThickness, m.thinFilmIor, outside, materialF0(m))
    reflected = None
    if transmission:  # the diffuse keeps 1 - transmission (transmission.glsl)
        s.transmission = _trans.makeTransmissionLobe(
            m.transmission, m.transmissionColor, m.attenuationColor, m.attenuationDistance,
            m.thickness, m.ior, m.metallic, thin_walled, N, V,
            lobeOn(lobes, LOBE_TRANSMISSION))
        s.thin_walled = thin_walled
        NoV = saturate(dot(f64(N), f64(V)))
        AB = f64(ibl.brdf_lut) if ibl.lut_values else environmentBRDF(ibl.brdf_lut, NoV,
                                                                      roughness)
        # the film's reflectance at N.V in place of F0 where there is one (surface.glsl)
        tF0 = f64(F0)
        if s.film is not None:
            tF0 = np.where((f64(s.film.thickness) > 0.0)[..., None],
                           _film.thinFilmFresnel(s.film, NoV), tF0)
        reflected = saturate(tF0 * AB[..., 0:1] + AB[..., 1:2])
        keep = (1.0 - saturate(m.transmission))[..., None]
        s.diffuseColor = s.diffuseColor * keep
        diffuseColor = s.diffuseColor
        if s.subsurface is not None:
            s.subsurface.color = s.subsurface.color * keep
    if energy_compensation:
        NoV = saturate(dot(f64(N), f64(V)))
        AB = f64(ibl.brdf_lut) if ibl.lut_values else environmentBRDF(ibl.brdf_lut, NoV,
                                                                      roughness)
        s.specularScale, diffuse_scale = energyCompensation(F0, AB)
        s.diffuseColor = s.diffuseColor * diffuse_scale
        diffuseColor = s.diffuseColor
        if s.subsurface is not None:
            s.subsurface.color = s.subsurface.color * diffuse_scale
        if reflected is not None:  # what the compensated reflection leaves (surface.glsl)
            reflected = saturate(reflected * f64(s.specularScale))
    if lobes != LOBES_ALL:
        s.diffuseColor = s.diffuseColor * lobeOn(lobes, LOBE_DIFFUSE)
        diffuseColor = s.diffuseColor
        s.specularScale = f64(s.specularScale) * lobeOn(lobes, LOBE_SPECULAR)
    if sheen:
        setupSheen(s, m.sheenColor, m.sheenRoughness,
                   f64(m.sheenColor) * lobeOn(lobes, LOBE_SHEEN), lut_of(ibl))
    direct = directLighting(s, lights)
    if ibl.mode == IBL_MODE_REFERENCE and (coat or sheen or anisotropic or subsurface
                                           or thin_film or transmission):
        # the whole layered BRDF by one MIS estimator (reference_layered.glsl)
        if ibl.environment is None or ibl.environment_distribution is None:
            raise ValueError("reference mode needs IblInputs.environment and its distribution")
        indirect = _layered.layeredEnvironmentIBL(
            ibl.environment, ibl.environment_distribution,
            _layered.makeLayeredReference(s, roughness), max(int(ibl.samples), 1),
            ibl.sample_offset) * ibl.intensity
        if s.transmission is not None:  # by sampling the BTDF (reference_layered.glsl)
            indirect = indirect + _layered.transmissionEnvironmentIBL(
                ibl.environment, ibl.environment_distribution, s, roughness,
                max(int(ibl.samples), 1),
                ibl.sample_offset) * ibl.intensity
    else:
        indirect = imageBasedLighting(N, V, diffuseColor, F0, roughness, ibl, s.specularScale,
                                      s.aniso, s.film)
        if s.subsurface is not None and ibl.mode == IBL_MODE_SPLIT_SUM:
            indirect = indirect + subsurfaceImageBasedLighting(s.subsurface, N, ibl)
        if s.transmission is not None and ibl.mode != IBL_MODE_NONE:
            indirect = indirect + transmissionImageBasedLighting(
                s.transmission, N, reflected, roughness, thin_walled, ibl)
        if sheen:  # the base's IBL is linear in diffuseColor and specularScale
            indirect = indirect * f64(s.sheenScaleV)[..., None] + sheenImageBasedLighting(s, ibl)
        if coat and s.coat is not None and ibl.mode == IBL_MODE_SPLIT_SUM:
            indirect = _coat.coatImageBasedLighting(
                s.coat, V, indirect, ibl.coat_prefiltered if ibl.coat_prefiltered is not None
                else ibl.prefiltered, ibl.coat_brdf_lut if ibl.coat_brdf_lut is not None
                else ibl.brdf_lut, ibl.mip_count, ibl.intensity, ibl.lut_values)
    return (direct + indirect) * f64(m.cavity)[..., None] + f64(m.emissive) * lobeOn(
        lobes, LOBE_EMISSIVE)
