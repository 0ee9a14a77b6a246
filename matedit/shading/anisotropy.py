"""Twin of ``anisotropy.glsl``: anisotropic GGX, its projected-roughness Schlick-Smith
visibility, the bent reflection vector, the split sum's taps, the area lights' metric
representative points (their frame and disc point; the points are in lights.py) and widening,
and the sampling.

Same names, same arithmetic, float64; vectorised over leading axes (pixels). The
convention (see the GLSL header): the lobe's T is the direction the highlight stretches
along, the roughness along it (at) the larger; physically that is across a brushing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading.brdf import (
    F_Schlick,
    F_SchlickExact,
    k_Analytic,
    k_IBL,
    reflectionHalfVector,
)
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


def anisotropicLobeTerms(l: AnisotropicLobe, N, V, L):
    """(D, VoH, alphaV, alphaL) at H = normalize(L + V), the terms both forms of the lobe
    share (Burley 2012 B.2 eq 13; Heitz 2014 eq 80); each caller applies its own k."""
    N, V, L = f64(N), f64(V), f64(L)
    H = _half(L, V)
    NoH = saturate(dot(N, H))
    VoH = saturate(dot(V, H))
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), _onemx2(N, H), l.at, l.ab)
        alphaV = projectedAlpha(l.at, l.ab, dot(l.T, V), _onemx2(N, V))
        alphaL = projectedAlpha(l.at, l.ab, dot(l.T, L), _onemx2(N, L))
    return D, VoH, alphaV, alphaL


def anisotropicSpecularTowards(l: AnisotropicLobe, N, V, NoV, F0, L) -> np.ndarray:
    """D Vis F NoL for analytic lights (spherical-Gaussian Fresnel, remapped k); 0 below
    the horizon, as the GLSL returns early."""
    NoL = saturate(dot(f64(N), f64(L)))
    D, VoH, alphaV, alphaL = anisotropicLobeTerms(l, N, V, L)
    with np.errstate(divide="ignore", invalid="ignore"):
        kV, kL = k_AnalyticProjected(alphaV), k_AnalyticProjected(alphaL)
        h = f64(L) + f64(V)  # L = -V: H undefined, nothing reflected (as the GLSL)
        lobe = np.where((NoL > 0.0) & (dot(h, h) >= 1e-12),
                        D * V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) * NoL, 0.0)
    return lobe[..., None] * F_Schlick(F0, VoH)


def anisotropicReflection(l: AnisotropicLobe, N, V) -> np.ndarray:
    """The bent reflection (benchmarks/bench_aniso_ibl.py's comparison; not the lights').
    Revie 2011 / McAuley 2015 (Filament's anisotropic IBL): reflect V about
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


ANISOTROPY_LIGHT_NEWTON_STEPS = 2


def anisotropicLightFrame(l: AnisotropicLobe, Ln) -> tuple[np.ndarray, np.ndarray]:
    """The light's tangent-plane frame at Ln: e1 the lobe's T projected, e2 = Ln x e1; where T
    lies along Ln, B projected gives e2 and e1 = e2 x Ln."""
    Ln = f64(Ln)
    t = l.T - Ln * dot(l.T, Ln)[..., None]
    tt = dot(t, t)
    b = l.B - Ln * dot(l.B, Ln)[..., None]
    e2b = b / np.sqrt(np.maximum(dot(b, b), 1e-30))[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        e1 = t / np.sqrt(tt)[..., None]
    e2 = cross(Ln, e1)
    degenerate = (tt < 1e-12)[..., None]
    e1 = np.where(degenerate, cross(e2b, Ln), e1)
    e2 = np.where(degenerate, e2b, e2)
    return e1, e2


def anisotropicDiscPoint(o1, o2, rho, q) -> tuple[np.ndarray, np.ndarray]:
    """The point of the disc |p| <= rho closest to (o1, o2) in the metric q p1^2 + p2^2:
    (o1, o2) inside; outside, the Lagrange point rho u, u = (q o1 / (mu + q rho), o2 / (mu +
    rho)) normalised, mu by ANISOTROPY_LIGHT_NEWTON_STEPS Newton steps on G(mu) = 1 / |u|
    = 1 from |(q o1, o2)| - rho (see the GLSL)."""
    o1, o2, rho, q = f64(o1), f64(o2), f64(rho), f64(q)
    A, C = q * o1, o2
    mu = np.maximum(np.sqrt(A * A + C * C) - rho, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(ANISOTROPY_LIGHT_NEWTON_STEPS):
            da, dc = mu + q * rho, mu + rho
            S = np.maximum(A * A / (da * da) + C * C / (dc * dc), 1e-30)
            dG = (A * A / (da * da * da) + C * C / (dc * dc * dc)) / (S * np.sqrt(S))
            mu = np.maximum(mu + (1.0 - 1.0 / np.sqrt(S)) / np.maximum(dG, 1e-30), 0.0)
        u1, u2 = A / (mu + q * rho), C / (mu + rho)
        uu = u1 * u1 + u2 * u2
        scale = np.where(uu > 0.0, rho / np.sqrt(uu), 0.0)
    inside = o1 * o1 + o2 * o2 <= rho * rho
    return np.where(inside, o1, u1 * scale), np.where(inside, o2, u2 * scale)


def anisotropicWidening(l: AnisotropicLobe, V, L, widen) -> tuple[np.ndarray, np.ndarray]:
    """The light's widening along T and B in H: w in the plane of V and L, w / (V.H) across it
    (dH = dL / (2 V.H) across, dL / 2 in the plane): the support of that ellipse along each
    axis, sqrt(w^2 (X.e_in)^2 + (w / V.H)^2 (X.e_perp)^2), e_perp the tangent direction across
    the plane. V along L (no plane) or a plane along the surface: w on both axes."""
    V, L, w = f64(V), f64(L), f64(widen)
    h = V + L
    c = np.maximum(dot(V, h) / np.sqrt(np.maximum(dot(h, h), 1e-30)), 1e-4)
    e = cross(V, L)
    pT, pB = dot(e, l.T), dot(e, l.B)
    pp = pT * pT + pB * pB
    with np.errstate(divide="ignore", invalid="ignore"):
        cT2, cB2 = pT * pT / pp, pB * pB / pp
    flat = pp < 1e-12
    cT2, cB2 = np.where(flat, 0.0, cT2), np.where(flat, 0.0, cB2)
    ic2 = 1.0 / (c * c)
    return w * np.sqrt(cB2 + cT2 * ic2 + np.where(flat, 1.0, 0.0)), \
        w * np.sqrt(cT2 + cB2 * ic2 + np.where(flat, 1.0, 0.0))


def anisotropicSphereNormalization(l: AnisotropicLobe, V, L, sourceRadius, d) -> np.ndarray:
    """(at ab) / (at' ab'): each alpha widened by the disc's support along its axis in H
    (anisotropicWidening of w = r / (2 d)), a' = saturate(a + w_axis)."""
    wT, wB = anisotropicWidening(
        l, V, L, f64(sourceRadius) / (_widen_divisor() * np.maximum(f64(d), 1e-8)))
    return (l.at * l.ab) / (saturate(l.at + wT) * saturate(l.ab + wB))


def anisotropicTubeNormalization(l: AnisotropicLobe, N, V, L, axis, sourceLength, d,
                                 sourceRadius, dp) -> np.ndarray:
    """(at ab) / (at' ab' + wl' (a_across + w_across)): the lobe's ellipse grown by the
    capsule (Steiner), wl' = min(0.5 l / (2 d), 1 - a_axis), w = r / (2 dp) widened as the
    sphere's (anisotropicWidening)."""
    N = f64(N)
    axis = np.broadcast_to(f64(axis), np.broadcast_shapes(np.shape(axis), N.shape))
    across = cross(N, axis)
    aAxis = projectedAlpha(l.at, l.ab, dot(l.T, axis), _onemx2(N, axis))
    aAcross = projectedAlpha(l.at, l.ab, dot(l.T, across), _onemx2(N, across))
    wT, wB = anisotropicWidening(
        l, V, L, f64(sourceRadius) / (_widen_divisor() * np.maximum(f64(dp), 1e-8)))
    wAcross = projectedAlpha(wT, wB, dot(l.T, across), _onemx2(N, across))
    wl = np.minimum(0.5 * f64(sourceLength) / (_widen_divisor() * np.maximum(f64(d), 1e-8)),
                    np.maximum(1.0 - aAxis, 0.0))
    return (l.at * l.ab) / (saturate(l.at + wT) * saturate(l.ab + wB)
                            + wl * (aAcross + wAcross))


def importanceSampleGGXAnisotropic(Xi, at, ab, N, T, B) -> np.ndarray:
    """Burley 2012, B.2 eq 16: normalize(sqrt(y/(1-y)) (at cos 2pi x T + ab sin 2pi x B) + N)."""
    Xi = f64(Xi)
    phi = 2.0 * PI * Xi[..., 0]
    tan_theta = np.sqrt(Xi[..., 1] / np.maximum(1.0 - Xi[..., 1], 1e-12))
    h = (tan_theta * f64(at) * np.cos(phi))[..., None] * f64(T) \
        + (tan_theta * f64(ab) * np.sin(phi))[..., None] * f64(B) + f64(N)
    return h / np.sqrt(dot(h, h))[..., None]


def ggxAnisotropicDirectionPdf(l: AnisotropicLobe, N, V, L) -> np.ndarray:
    """Walter et al. 2007 eq 14, 38: D(h) NoH / (4 VoH); 0 where H is undefined or VoH <= 0
    (the half vector shared with brdf.ggxReflectionPdf: reflectionHalfVector)."""
    H, VoH, NoH, oneMinusNoH2, valid = reflectionHalfVector(N, V, L)
    with np.errstate(divide="ignore", invalid="ignore"):
        D = D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), oneMinusNoH2, l.at, l.ab)
        pdf = D * NoH / (4.0 * VoH)
    return np.where(valid, pdf, 0.0)


def ggxAnisotropicSampleDirection(l: AnisotropicLobe, N, V, Xi) -> np.ndarray:
    H = importanceSampleGGXAnisotropic(Xi, l.at, l.ab, N, l.T, l.B)
    V = f64(V)
    return 2.0 * dot(V, H)[..., None] * H - V


def anisotropicBrdfCosineIBL(l: AnisotropicLobe, N, V, F0, L) -> np.ndarray:
    """f NoL as the IBL reference integrates it: k = alpha_o / 2 per direction, exact Fresnel."""
    NoL = saturate(dot(f64(N), f64(L)))
    NoV = np.maximum(dot(f64(N), f64(V)), 1e-4)
    D, VoH, alphaV, alphaL = anisotropicLobeTerms(l, N, V, L)
    with np.errstate(divide="ignore", invalid="ignore"):
        kV, kL = k_IBL(alphaV), k_IBL(alphaL)
        h = f64(L) + f64(V)  # L = -V: H undefined, nothing reflected (as the GLSL)
        lobe = np.where((NoL > 0.0) & (dot(h, h) >= 1e-12),
                        D * V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) * NoL, 0.0)
    return lobe[..., None] * F_SchlickExact(F0, VoH)


def anisotropicSampleIBL(l: AnisotropicLobe, N, V, Xi) -> tuple[np.ndarray, np.ndarray]:
    """(L, pdf): the GLSL's out parameter returned as the second value."""
    L = ggxAnisotropicSampleDirection(l, N, V, Xi)
    return L, ggxAnisotropicDirectionPdf(l, N, V, L)


def anisotropicPdfIBL(l: AnisotropicLobe, N, V, L) -> np.ndarray:
    return ggxAnisotropicDirectionPdf(l, N, V, L)


# The anisotropic split sum's prefiltered radiance (the GLSL's comment): ANISOTROPY_IBL_TAPS
# narrow lookups (roughness sqrt(ab)) along reflect(-V, normalize(N + s_i w T)), w =
# sqrt(at^2 - ab^2), weights (1 + s_i^2)^-2 faded out near N's horizon, normalised by their
# sum; at = ab they all read reflect(-V, N).
ANISOTROPY_IBL_TAPS = 3
ANISOTROPY_TAP_HORIZON_FADE = 0.25
ANISOTROPY_TAP_MIN_WEIGHT = 1e-3


def anisotropicTapOffset(i: int) -> float:
    """Slope offset of tap i along T in units of the spread: -0.8, 0, 0.8."""
    return 0.8 * float(i - 1)


def anisotropicTapDirection(l: AnisotropicLobe, N, V, i: int) -> np.ndarray:
    """reflect(-V, normalize(N + s_i w T)), w = sqrt(at^2 - ab^2), H at N's length (no
    offset: N itself)."""
    N, V = f64(N), f64(V)
    w = np.sqrt(np.maximum(f64(l.at) * l.at - f64(l.ab) * l.ab, 0.0))
    h = N + (anisotropicTapOffset(i) * w)[..., None] * f64(l.T)
    return reflect(-V, h * (np.sqrt(dot(N, N)) / np.sqrt(dot(h, h)))[..., None])


def anisotropicTapWeight(N, R, i: int) -> np.ndarray:
    """Not normalised: (1 + s_i^2)^-2 (GGX's unit-roughness slope density, Walter et al. 2007
    eq 33, Heitz 2014 eq 9) times max(saturate(N.R / fade), floor)."""
    fade = np.maximum(saturate(dot(f64(N), f64(R)) / ANISOTROPY_TAP_HORIZON_FADE),
                      ANISOTROPY_TAP_MIN_WEIGHT)
    return fade / (1.0 + anisotropicTapOffset(i) ** 2) ** 2


def anisotropicTapRoughness(l: AnisotropicLobe, roughness) -> np.ndarray:
    """sqrt(ab), the narrow alpha's roughness; the given IBL roughness at anisotropy 0."""
    return np.where(f64(l.anisotropy) > 0.0, np.sqrt(f64(l.ab)), f64(roughness))


def _linear_axis(x, n: int, centred: bool):
    """Texel indices and weight of GL linear filtering along one axis of n texels, for a
    value x in [0, 1] at texel centres (i + 0.5) / n (clamped to the edge) or, `centred`
    False, at nodes i / (n - 1) (the texture coordinate (x (n - 1) + 0.5) / n)."""
    p = x * n - 0.5 if centred else x * (n - 1)
    p = np.clip(p, 0.0, n - 1)
    i0 = np.minimum(np.floor(p).astype(np.int64), n - 1)
    i1 = np.minimum(i0 + 1, n - 1)
    return i0, i1, p - i0


def anisotropicViewCos2(l: AnisotropicLobe, N, V) -> np.ndarray:
    """cos^2 of V's azimuth from T, the table's fourth axis (projectedAlpha's cos^2)."""
    ToV = dot(l.T, f64(V))
    return np.minimum(ToV * ToV / np.maximum(_onemx2(f64(N), f64(V)), 1e-12), 1.0)


def anisotropicEnvironmentBRDF(table, NoV, roughness, anisotropy, cos2) -> np.ndarray:
    """The change (dA, dB) of the environment BRDF for the anisotropic lobe
    (matedit.ibl.anisotropy_lut): `table` (NoV, roughness, anisotropy, cos^2, 2) filtered as
    the GLSL's 3D texture is (linear in NoV, roughness and anisotropy inside the slab of one
    |cos(phi)| = sqrt(cos2) node), then linear between the two slabs; 0 at anisotropy 0."""
    t = f64(table)
    nv, nr, na, nc = t.shape[:4]
    NoV, r, an, c = np.broadcast_arrays(f64(NoV), f64(roughness), saturate(anisotropy),
                                        np.sqrt(saturate(cos2)))
    out = np.zeros(NoV.shape + (2,))
    iv = _linear_axis(NoV, nv, True)
    ir = _linear_axis(r, nr, True)
    ia = _linear_axis(an, na, False)
    ic = _linear_axis(c, nc, False)
    for a_, wa in ((iv[0], 1 - iv[2]), (iv[1], iv[2])):
        for b_, wb in ((ir[0], 1 - ir[2]), (ir[1], ir[2])):
            for c_, wc in ((ia[0], 1 - ia[2]), (ia[1], ia[2])):
                for d_, wd in ((ic[0], 1 - ic[2]), (ic[1], ic[2])):
                    out += (wa * wb * wc * wd)[..., None] * t[a_, b_, c_, d_]
    return np.where((an > 0.0)[..., None], out, 0.0)
