"""Twin of ``lights_reference.glsl``: Monte Carlo sphere and tube lights for reference mode.

Vectorised over pixels (rows of the ShadingContext's arrays), one loop over the samples; the
same sample points, sampling and balance-heuristic weights as the GLSL (see its header).
"""

from __future__ import annotations

import numpy as np

from matedit.shading import anisotropy as _aniso
from matedit.shading import coat
from matedit.shading.brdf import ggxReflectionPdf
from matedit.shading.common import PI, dot, f64, length, sq
from matedit.shading.ibl import rotatedHammersley
from matedit.shading.lights import (
    Light,
    ShadingContext,
    diffuseTowards,
    distanceWindow,
    evaluateLight,
    pointLight,
    specularTowards,
    sphereLight,
    tubeLight,
)
from matedit.shading.sampling import importanceSampleGGX, tangentFrame
from matedit.shading.sheen import sheenLayerCosine


def brdfCosine(s: ShadingContext, L) -> np.ndarray:
    base = diffuseTowards(s, dot(s.N, L)) + specularTowards(s, L)
    if s.sheenColor is not None:
        base = sheenLayerCosine(s, base, L)
    if s.coat is not None:
        return coat.coatLayer(s.coat, s.V, L, base)
    return base


def ggxDirectionPdf(s: ShadingContext, L) -> np.ndarray:
    if s.aniso is not None:
        return _aniso.ggxAnisotropicDirectionPdf(s.aniso, s.N, s.V, L)
    return ggxReflectionPdf(s.N, s.V, L, s.a)


def ggxSampleDirection(s: ShadingContext, Xi) -> np.ndarray:
    if s.aniso is not None:
        return _aniso.ggxAnisotropicSampleDirection(s.aniso, s.N, s.V, Xi)
    H = importanceSampleGGX(Xi, s.a, s.N)
    return 2.0 * dot(s.V, H)[..., None] * H - s.V


def companionPoint(u) -> np.ndarray:
    u = f64(u)
    return np.mod(u[..., ::-1] + np.array([0.5, 0.25]), 1.0)


def _points(count: int, offset) -> np.ndarray:
    return rotatedHammersley(np.arange(count), count, f64(offset))


def referenceSphereLight(s: ShadingContext, light: Light, count: int, offset) -> np.ndarray:
    Lc = f64(light.position) - s.P
    d = length(Lc)
    r = float(light.source_radius)
    if r <= 0.0:
        return sphereLight(s, light)
    inside = d <= r * 1.0001
    dd = np.where(inside, 2.0 * r, d)
    axis = Lc / dd[..., None]
    cosMax = np.sqrt(np.maximum(0.0, 1.0 - sq(r / dd)))
    lightPdf = 1.0 / (2.0 * PI * (1.0 - cosMax))
    T, B = tangentFrame(axis)
    total = np.zeros(np.broadcast_shapes(s.N.shape, s.P.shape))
    for u in _points(count, offset):
        cosT = 1.0 - u[1] * (1.0 - cosMax)
        sinT = np.sqrt(np.maximum(0.0, 1.0 - cosT * cosT))
        phi = 2.0 * PI * u[0]
        L = T * (sinT * np.cos(phi))[..., None] + B * (sinT * np.sin(phi))[..., None] \
            + axis * cosT[..., None]
        total = total + brdfCosine(s, L) / (lightPdf + ggxDirectionPdf(s, L))[..., None]
        Lb = ggxSampleDirection(s, np.broadcast_to(companionPoint(u), s.N.shape[:-1] + (2,)))
        hit = (dot(Lb, axis) >= cosMax) & (dot(s.N, Lb) > 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            contrib = brdfCosine(s, Lb) / (lightPdf + ggxDirectionPdf(s, Lb))[..., None]
        total = total + np.where(hit[..., None], contrib, 0.0)
    Le = light.intensity * distanceWindow(dd, light.influence_radius) / (PI * r * r)
    out = f64(light.color) * (Le[..., None] * total / count)
    return np.where(inside[..., None], sphereLight(s, light), out)


def capsuleHit(rd, pa, pb, r: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, n) of the first hit of the unit rays rd from the origin; t = -1 on a miss."""
    rd, pa, pb = f64(rd), f64(pa), f64(pb)
    ba = pb - pa
    oa = -pa
    baba, bard, baoa = dot(ba, ba), dot(ba, rd), dot(ba, oa)
    rdoa, oaoa = dot(rd, oa), dot(oa, oa)
    qa = baba - bard * bard
    qb = baba * rdoa - baoa * bard
    qc = baba * oaoa - baoa * baoa - r * r * baba
    disc = qb * qb - qa * qc
    ok_q = qa > 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        t_side = np.where(ok_q, (-qb - np.sqrt(np.maximum(disc, 0.0))) / np.where(ok_q, qa, 1),
                          -1.0)
    y = baoa + t_side * bard
    side = ok_q & (t_side > 0.0) & (y > 0.0) & (y < baba)
    with np.errstate(divide="ignore", invalid="ignore"):
        n_side = (t_side[..., None] * rd - (pa + ba * (y / baba)[..., None])) / r
    c = np.where(ok_q[..., None], np.where((y <= 0.0)[..., None], pa, pb),
                 np.where((dot(pa, rd) < dot(pb, rd))[..., None], pa, pb))
    b = dot(rd, -c)
    h = b * b - (dot(c, c) - r * r)
    t_cap = -b - np.sqrt(np.maximum(h, 0.0))
    cap = (h >= 0.0) & (t_cap > 0.0)
    n_cap = (t_cap[..., None] * rd - c) / r
    t = np.where(disc < 0.0, -1.0, np.where(side, t_side, np.where(cap, t_cap, -1.0)))
    n = np.where((disc < 0.0)[..., None], 0.0, np.where(side[..., None], n_side,
                                                        np.where(cap[..., None], n_cap, 0.0)))
    return t, n


def referenceTubeLight(s: ShadingContext, light: Light, count: int, offset) -> np.ndarray:
    Lc = f64(light.position) - s.P
    d = length(Lc)
    length_ = float(light.source_length)
    r = float(light.source_radius)
    if length_ <= 0.0:
        return referenceSphereLight(s, light, count, offset) if r > 0.0 \
            else pointLight(s, light)
    axis = f64(light.direction)
    pa = Lc - 0.5 * length_ * axis
    pb = Lc + 0.5 * length_ * axis
    window = distanceWindow(d, light.influence_radius)
    T, B = tangentFrame(axis)
    total = np.zeros(np.broadcast_shapes(s.N.shape, s.P.shape))
    pts = _points(count, offset)
    if r <= 0.0:
        for u in pts:
            X = pa + (u[0] * length_) * axis
            dist2 = dot(X, X)
            L = X / np.sqrt(dist2)[..., None]
            sinPsi = length(np.cross(L, axis))
            total = total + brdfCosine(s, L) * (sinPsi / dist2)[..., None]
        return f64(light.color) * ((light.intensity * window)[..., None] * total / count)
    foot = pa + axis * np.clip(dot(-pa, axis), 0.0, length_)[..., None]
    inside = dot(foot, foot) <= r * r
    sideArea = 2.0 * PI * r * length_
    area = sideArea + 4.0 * PI * r * r
    for u in pts:
        pick = u[0] * area
        phi = 2.0 * PI * u[1]
        if pick < sideArea:
            n = T * np.cos(phi) + B * np.sin(phi)
            X = pa + axis * (length_ * pick / sideArea) + r * n
        else:
            z = 1.0 - 2.0 * (pick - sideArea) / (area - sideArea)
            rho = np.sqrt(max(0.0, 1.0 - z * z))
            n = T * (rho * np.cos(phi)) + B * (rho * np.sin(phi)) + axis * z
            X = (pb if z >= 0.0 else pa) + r * n
        n = np.broadcast_to(n, X.shape)
        dist2 = dot(X, X)
        L = X / np.sqrt(dist2)[..., None]
        cosL = -dot(n, L)
        with np.errstate(divide="ignore", invalid="ignore"):
            lightPdf = dist2 / (cosL * area)
            contrib = brdfCosine(s, L) / (lightPdf + ggxDirectionPdf(s, L))[..., None]
        total = total + np.where((cosL > 0.0)[..., None], contrib, 0.0)
        Lb = ggxSampleDirection(s, np.broadcast_to(companionPoint(u), s.N.shape[:-1] + (2,)))
        t, nb = capsuleHit(Lb, pa, pb, r)
        cosB = -dot(nb, Lb)
        hit = (dot(s.N, Lb) > 0.0) & (t > 0.0) & (cosB > 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            lightPdf = t * t / (cosB * area)
            contrib = brdfCosine(s, Lb) / (lightPdf + ggxDirectionPdf(s, Lb))[..., None]
        total = total + np.where(hit[..., None], contrib, 0.0)
    Le = light.intensity * window / (2.0 * r * length_ + PI * r * r)
    out = f64(light.color) * (Le[..., None] * total / count)
    return np.where(inside[..., None], tubeLight(s, light), out)


def evaluateLightReference(s: ShadingContext, light: Light, count: int, offset) -> np.ndarray:
    if light.kind == "sphere":
        return referenceSphereLight(s, light, count, offset)
    if light.kind == "tube":
        return referenceTubeLight(s, light, count, offset)
    return evaluateLight(s, light)


__all__ = ["brdfCosine", "capsuleHit", "companionPoint", "evaluateLightReference",
           "ggxDirectionPdf", "ggxSampleDirection", "referenceSphereLight",
           "referenceTubeLight"]
