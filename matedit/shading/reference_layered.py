"""Twin of shaders/reference_layered.glsl: reference mode's MIS estimator of the whole
layered BRDF (coat over sheen over base, anisotropic GGX and the subsurface diffuse where the
material has them), with
a one-sample lobe mixture as the BRDF strategy. Loops over samples, vectorised over pixels."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading import anisotropy as _aniso
from matedit.shading import coat as _coat
from matedit.shading import sheen as _sheen
from matedit.shading import subsurface as _sss
from matedit.shading import thin_film as _film
from matedit.shading import transmission as _trans
from matedit.shading.brdf import D_GGX, F_Schlick, F_SchlickExact
from matedit.shading.common import INV_PI, dot, f64, saturate
from matedit.shading.env_sampling import environmentPdf, sampleEnvironmentDirection
from matedit.shading.ibl import (
    ReferenceSurface,
    environmentSamplePoint,
    makeReferenceSurface,
    referenceBrdfCosine,
    referenceGgxPdf,
    referenceGgxSample,
    rotatedHammersley,
)
from matedit.shading.lights import ShadingContext, transmissionLayers
from matedit.shading.sampling import importanceSampleCosine, importanceSampleGGX

# the GLSL's order; the subsurface lobe's front (cosine about N) and back (about -N) samplings
LAYER_SPECULAR, LAYER_DIFFUSE, LAYER_SHEEN, LAYER_COAT, LAYER_SUBSURFACE, LAYER_SUBSURFACE_BACK = (
    range(6))
LAYER_COUNT = 6
_LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
_ONE_BELOW = float(np.float32(0.99999994))


@dataclass
class LayeredReference:
    s: ShadingContext
    base: ReferenceSurface
    chance: np.ndarray  # (..., 6): base specular, diffuse, sheen, coat, subsurface front, back


def makeLayeredReference(s: ShadingContext, roughness) -> LayeredReference:
    """Lobe chances from the lobes' estimated reflectances towards the eye (luminance)."""
    base = makeReferenceSurface(s.N, s.V, s.diffuseColor, s.F0, roughness, s.specularScale)
    NoV = saturate(dot(s.N, s.V))
    shape = NoV.shape
    under = np.ones(shape)
    w_sheen = np.zeros(shape)
    w_coat = np.zeros(shape)
    if s.coat is not None:
        under = under * (_coat.coatTransmittance(s.coat, s.coat.NoV) @ _LUMINANCE)
        w_coat = np.broadcast_to(_coat.coatFresnel(s.coat, s.coat.NoV) * s.coat.scale, shape)
    if s.sheenMax is not None:
        smax = f64(s.sheenMax)
        with np.errstate(invalid="ignore", divide="ignore"):
            E = np.where(smax > 0.0, (1.0 - f64(s.sheenScaleV)) / np.where(smax > 0, smax, 1.0),
                         0.0)
        w_sheen = under * (f64(s.sheenColor) @ _LUMINANCE) * E
        under = under * f64(s.sheenScaleV)
    w_front = np.zeros(shape)
    w_back = np.zeros(shape)
    if s.subsurface is not None:
        sl = s.subsurface
        below = sl.wrap * sl.wrap / ((1.0 + sl.wrap) * (1.0 + sl.wrap))
        front = (1.0 - sl.transmittance) * (1.0 - below)
        w_front = under * ((sl.color * front) @ _LUMINANCE)
        w_back = under * ((sl.color * (1.0 - front)) @ _LUMINANCE)
    w_diff = under * (f64(s.diffuseColor) @ _LUMINANCE)
    w_spec = under * ((F_SchlickExact(f64(s.F0), NoV) * f64(s.specularScale)) @ _LUMINANCE)
    w = np.stack(np.broadcast_arrays(w_spec, w_diff, w_sheen, w_coat, w_front, w_back), -1)
    total = w.sum(-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        chance = np.where(total > 0.0, w / np.where(total > 0, total, 1.0), 1.0 / LAYER_COUNT)
    return LayeredReference(s, base, chance)


def layeredBrdfCosine(r: LayeredReference, L) -> np.ndarray:
    """f(l, v) N.l of the layered BRDF towards L, in lights.glsl's order of layers."""
    s, L = r.s, f64(L)
    # no lobe where the half vector is below its normal (the GLSL's comment)
    h = L + s.V
    H = h / np.sqrt(np.maximum(dot(h, h), 1e-30))[..., None]
    # the base specular's Fresnel: Schlick's, or the film's at V.H with F0 = 1 in the lobe
    spec_f0, film_f = f64(s.F0), np.ones(1)
    if s.film is not None:
        on = (f64(s.film.thickness) > 0.0)[..., None]
        spec_f0 = np.where(on, 1.0, spec_f0)
        film_f = np.where(on, _film.thinFilmFresnel(s.film, saturate(dot(s.V, H))), 1.0)
    if s.aniso is not None:
        NoL = dot(s.N, L)
        spec = _aniso.anisotropicBrdfCosineIBL(s.aniso, s.N, s.V, spec_f0, L) * f64(
            s.specularScale) * film_f
        f = (f64(s.diffuseColor) * (INV_PI * NoL)[..., None]
             + np.where((dot(s.N, H) > 0.0)[..., None], np.nan_to_num(spec), 0.0))
        f = np.where((NoL > 0.0)[..., None], f, 0.0)
    else:
        b = r.base
        f = referenceBrdfCosine(ReferenceSurface(b.N, b.V, b.diffuseColor, spec_f0, b.roughness,
                                                 f64(b.specularScale) * film_f), L)
    if s.subsurface is not None:  # part of the base
        f = f + _sss.subsurfaceCosine(s.subsurface, dot(s.N, L))
    if s.sheenMax is not None:
        f = (f * _sheen.sheenBaseScale(s, saturate(dot(s.N, L)))[..., None]
             + _sheen.sheenBrdfCosine(s.N, s.V, L, s.sheenColor, s.sheenAlpha))
    if s.coat is not None:
        coat = np.where(dot(s.coat.N, H) > 0.0, np.nan_to_num(
            _coat.coatBrdfCosine(s.coat, s.V, L)), 0.0)
        f = f * _coat.coatTransmittance(s.coat, dot(s.coat.N, L)) + coat[..., None]
    return f


def layeredLobePdf(r: LayeredReference, lobe: int, L) -> np.ndarray:
    """Density of L under one lobe's own sampling (0 for a lobe the material lacks)."""
    s, L = r.s, f64(L)
    if lobe == LAYER_DIFFUSE:
        return np.maximum(dot(s.N, L), 0.0) * INV_PI
    if lobe == LAYER_SPECULAR:
        if s.aniso is not None:
            return _aniso.anisotropicPdfIBL(s.aniso, s.N, s.V, L)
        return referenceGgxPdf(r.base, L)
    if lobe == LAYER_SHEEN and s.sheenMax is not None:
        return _sheen.sheenSamplePdf(s.N, L)
    if lobe == LAYER_COAT and s.coat is not None:
        return _coat.coatPdf(s.coat, s.V, L)
    if lobe == LAYER_SUBSURFACE and s.subsurface is not None:
        return np.maximum(dot(s.N, L), 0.0) * INV_PI
    if lobe == LAYER_SUBSURFACE_BACK and s.subsurface is not None:
        return np.maximum(-dot(s.N, L), 0.0) * INV_PI
    return np.zeros(np.broadcast_shapes(s.N.shape, L.shape)[:-1])


def layeredBrdfPdf(r: LayeredReference, L) -> np.ndarray:
    """The mixture's density: sum of chance_i p_i(L)."""
    return sum(r.chance[..., i] * layeredLobePdf(r, i, L) for i in range(LAYER_COUNT))


def layeredBrdfSample(r: LayeredReference, Xi) -> tuple[np.ndarray, np.ndarray]:
    """(L, pdf): one lobe picked by Xi.x, which is stretched back to [0, 1) for it."""
    s, Xi, c = r.s, f64(Xi), r.chance
    x = Xi[..., 0]
    last = LAYER_COUNT - 1
    before = np.concatenate([np.zeros(c.shape[:-1] + (1,)), np.cumsum(c, -1)[..., :last]], -1)
    # the GLSL's loop: the first lobe i < last with x < start_i + c_i, else the last
    ends = before[..., :last] + c[..., :last]
    lobe = np.where((x[..., None] < ends).any(-1), np.argmax(x[..., None] < ends, -1), last)
    start = np.take_along_axis(before, lobe[..., None], -1)[..., 0]
    width = np.maximum(np.take_along_axis(c, lobe[..., None], -1)[..., 0], 1e-20)
    X = np.stack(np.broadcast_arrays(np.clip((x - start) / width, 0.0, _ONE_BELOW),
                                     Xi[..., 1]), -1)
    L = importanceSampleCosine(X, s.N)  # the diffuse lobe, and a chance-0 coat's stand-in
    if s.aniso is not None:
        Ls = _aniso.anisotropicSampleIBL(s.aniso, s.N, s.V, X)[0]
    else:
        Ls = referenceGgxSample(r.base, X)
    L = np.where((lobe == LAYER_SPECULAR)[..., None], Ls, L)
    if s.sheenMax is not None:
        L = np.where((lobe == LAYER_SHEEN)[..., None], _sheen.sheenSampleDirection(X, s.N)[0], L)
    if s.coat is not None:
        L = np.where((lobe == LAYER_COAT)[..., None],
                     _coat.coatSampleDirection(s.coat, s.V, X)[0], L)
    L = np.where((lobe == LAYER_SUBSURFACE_BACK)[..., None], importanceSampleCosine(X, -s.N), L)
    # a draw the chosen lobe's own density does not count (V below its normal, V.H < 0) fails
    own = np.zeros(L.shape[:-1])
    for i in range(LAYER_COUNT):
        own = np.where(lobe == i, layeredLobePdf(r, i, L), own)
    return L, np.where(own > 0.0, layeredBrdfPdf(r, L), 0.0)


def layeredEnvironmentIBL(env, dist, r: LayeredReference, sampleCount: int,
                          offset) -> np.ndarray:
    """Balance heuristic over one BRDF and one environment sample per step."""
    total = np.zeros(np.broadcast_shapes(r.s.N.shape, r.s.V.shape))
    for i in range(sampleCount):
        Xi = np.broadcast_to(rotatedHammersley(i, sampleCount, f64(offset)),
                             total.shape[:-1] + (2,))
        Lb, pb = layeredBrdfSample(r, Xi)
        with np.errstate(invalid="ignore", divide="ignore"):
            wb = np.where(pb > 0.0, 1.0 / (pb + environmentPdf(dist, Lb)), 0.0)
        Le, pe = sampleEnvironmentDirection(dist, environmentSamplePoint(Xi))
        with np.errstate(invalid="ignore", divide="ignore"):
            we = np.where(pe > 0.0, 1.0 / (pe + layeredBrdfPdf(r, Le)), 0.0)
        fb = np.nan_to_num(layeredBrdfCosine(r, Lb))
        fe = np.nan_to_num(layeredBrdfCosine(r, Le))
        total = total + fb * f64(env(Lb)) * wb[..., None] + fe * f64(env(Le)) * we[..., None]
    return total / sampleCount


def thinWalledBtdfPdf(N, V, L, a) -> np.ndarray:
    """Twin of reference_layered.glsl's: D (N.m) / (4 V.m) of m = normalize(V + L mirrored)."""
    N, V, L = f64(N), f64(V), f64(L)
    NoL = dot(N, L)
    h = V + (L - 2.0 * NoL[..., None] * N)
    hh = dot(h, h)
    m = h / np.sqrt(np.maximum(hh, 1e-30))[..., None]
    VoM, NoM = dot(V, m), dot(N, m)
    NxM = np.cross(N, m)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = D_GGX(NoM, a, dot(NxM, NxM)) * NoM / (4.0 * VoM)
    return np.where((NoL < 0.0) & (hh >= 1e-12) & (VoM > 0.0) & (NoM > 0.0), p, 0.0)


def transmissionEnvironmentIBL(env, dist, s: ShadingContext, roughness, sampleCount: int,
                               offset) -> np.ndarray:
    """Twin of reference_layered.glsl's: the transmitted radiance by sampling the BTDF (a GGX
    normal, refracted through it and out of the sphere, or reflected and mirrored for a thin
    wall), weight (1 - F) G V.m / (N.V N.m); thin walls add an environment sample a step
    (`dist`, the environment's sampling table), balance heuristic."""
    t = s.transmission
    assert t is not None
    N, V = f64(s.N), f64(s.V)
    NoV = dot(N, V)
    a = np.maximum(f64(roughness) ** 2, 1e-4)
    shape = np.broadcast_shapes(N.shape, V.shape)
    total = np.zeros(shape)
    offset = np.mod(f64(offset) + np.array([0.5, 0.25]), 1.0)
    alive = (NoV > 0.0)[..., None]
    for i in range(sampleCount):
        Xi = np.broadcast_to(rotatedHammersley(i, sampleCount, offset), shape[:-1] + (2,))
        if s.thin_walled:  # the environment's sample (MIS)
            Le, pe = sampleEnvironmentDirection(dist, environmentSamplePoint(Xi))
            fe, VoHe = _trans.thinWalledBtdfCosineNoFresnel(N, V, Le, a)
            ok_e = (pe > 0.0) & (dot(N, Le) < 0.0)
            with np.errstate(invalid="ignore", divide="ignore"):
                we = np.where(ok_e, fe / (pe + thinWalledBtdfPdf(N, V, Le, a)), 0.0)
            Fe = _film.filmOrFresnel(s.film, s.F0, VoHe, F_Schlick)
            contrib = (1.0 - Fe) * transmissionLayers(s, Le) * we[..., None] * f64(env(Le))
            total = total + np.where((ok_e[..., None] & alive), np.nan_to_num(contrib), 0.0)
        H = importanceSampleGGX(Xi, a, N)
        VoH, NoH = dot(V, H), dot(N, H)
        if s.thin_walled:
            R = 2.0 * VoH[..., None] * H - V
            L = R - 2.0 * dot(N, R)[..., None] * N
            direction = L
        else:
            L = _trans.refractClamped(-V, H, 1.0 / f64(t.eta))
            direction = _trans.transmissionSphereExit(N, L, t.eta)
        NoL = dot(N, L)
        ok = (VoH > 0.0) & (NoH > 0.0) & (NoL < 0.0) & (NoV > 0.0)
        G = _trans.smithG1GGX(NoV, a) * _trans.smithG1GGX(NoL, a)
        with np.errstate(invalid="ignore", divide="ignore"):
            w = np.where(ok, G * VoH / (NoV * NoH), 0.0)
            if s.thin_walled:  # the balance heuristic's share, p_b / (p_b + p_e)
                pb = thinWalledBtdfPdf(N, V, L, a)
                peL = environmentPdf(dist, L)
                w = np.where(ok, np.where(peL > 0.0, w * pb / (pb + peL), w), 0.0)
        # the base's Fresnel (or the film's) and the layers over it (lights.transmissionTowards)
        F = _film.filmOrFresnel(s.film, s.F0, np.where(ok, VoH, 1.0), F_Schlick)
        f = (1.0 - F) * transmissionLayers(s, L) * w[..., None]
        total = total + np.where(ok[..., None], f * f64(env(direction)), 0.0)
    return total * f64(t.tint) * (f64(t.weight) / sampleCount)[..., None]
