"""Twin of ``ibl.glsl`` (split sum, SH irradiance, reference estimator) and the
bytes of the ``IblBlock`` uniform block of ``ibl_inputs.glsl``.

Textures become callables: an environment is ``env(directions (..., 3)) -> rgb (..., 3)``,
a prefiltered environment ``env(directions, lod) -> rgb``; the BRDF LUT is an array
``(N, N, >=2)`` laid out as the EXR (row k: roughness (k + 0.5) / N, column i: NoV).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from matedit.glsl import layout as _layout
from matedit.shading.brdf import D_GGX, F_SchlickExact, G1_Schlick, V_SchlickSmith, k_IBL
from matedit.shading.common import INV_PI, cross, dot, f64, saturate, sq
from matedit.shading.env_sampling import environmentPdf, sampleEnvironmentDirection
from matedit.shading.sampling import hammersley, importanceSampleCosine, importanceSampleGGX

Environment = Callable[[np.ndarray], np.ndarray]
PrefilteredEnvironment = Callable[[np.ndarray, np.ndarray], np.ndarray]

# from the one layout source (matedit/glsl/layout.py), like the shader's defines
IBL_MODE_SPLIT_SUM = _layout.IBL_MODES["SPLIT_SUM"]
IBL_MODE_REFERENCE = _layout.IBL_MODES["REFERENCE"]
IBL_MODE_NONE = _layout.IBL_MODES["NONE"]
IBL_BLOCK_SIZE = _layout.IBL_BLOCK.size  # 176

# Real SH basis constants, order L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22.
_Y0 = 0.5 * np.sqrt(1.0 / np.pi)
_Y1 = np.sqrt(3.0 / (4.0 * np.pi))
_Y2 = 0.5 * np.sqrt(15.0 / np.pi)
_Y20 = 0.25 * np.sqrt(5.0 / np.pi)
_Y22 = 0.25 * np.sqrt(15.0 / np.pi)


def prefilteredRadiance(prefilteredEnv: PrefilteredEnvironment, R, roughness, mipCount):
    return f64(prefilteredEnv(f64(R), f64(roughness) * (f64(mipCount) - 1.0)))


def sample_lut(lut: np.ndarray, NoV, roughness) -> np.ndarray:
    """Bilinear, clamp-to-edge lookup of a LUT array at (s, t) = (NoV, roughness), like GL."""
    lut = f64(lut)
    h, w = lut.shape[:2]
    x = np.clip(f64(NoV) * w - 0.5, 0.0, w - 1.0)
    y = np.clip(f64(roughness) * h - 0.5, 0.0, h - 1.0)
    x0 = np.minimum(np.floor(x).astype(int), w - 2) if w > 1 else np.zeros_like(x, int)
    y0 = np.minimum(np.floor(y).astype(int), h - 2) if h > 1 else np.zeros_like(y, int)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    top = lut[y0, x0] * (1 - fx) + lut[y0, x1] * fx
    bottom = lut[y1, x0] * (1 - fx) + lut[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def environmentBRDF(brdfLut, NoV, roughness) -> np.ndarray:
    """(A, B) from a LUT array (see module doc) or a callable (NoV, roughness) -> (..., 2)."""
    if callable(brdfLut):
        return f64(brdfLut(f64(NoV), f64(roughness)))[..., :2]
    return sample_lut(brdfLut, NoV, roughness)[..., :2]


def energyCompensation(F0, envBRDF) -> tuple[np.ndarray, np.ndarray]:
    """Twin of ibl.glsl's: (specular scale, diffuse scale), Fdez-Aguera 2019."""
    envBRDF, F0 = f64(envBRDF), f64(F0)
    A, B = envBRDF[..., 0:1], envBRDF[..., 1:2]
    FssEss = F0 * A + B
    Ems = 1.0 - (A + B)
    Favg = F0 + (1.0 - F0) / 21.0
    Fms = FssEss * Favg / np.maximum(1.0 - Ems * Favg, 1e-4)
    total = FssEss + Fms * Ems
    return 1.0 + Fms * Ems / np.maximum(FssEss, 1e-6), np.clip(1.0 - total, 0.0, 1.0)


def splitSumSpecular(prefiltered, envBRDF, F0) -> np.ndarray:
    envBRDF = f64(envBRDF)
    return f64(prefiltered) * (f64(F0) * envBRDF[..., 0:1] + envBRDF[..., 1:2])


def irradianceSH9(sh, N) -> np.ndarray:
    """sh (..., 9, 3), N (..., 3) -> E (..., 3)."""
    sh, N = f64(sh), f64(N)
    c1, c2, c3, c4, c5 = 0.429043, 0.511664, 0.743125, 0.886227, 0.247708
    x, y, z = (N[..., i : i + 1] for i in range(3))
    L = [sh[..., i, :] for i in range(9)]
    return (
        c1 * L[8] * (x * x - y * y) + c3 * L[6] * z * z + c4 * L[0] - c5 * L[6]
        + 2.0 * c1 * (L[4] * x * y + L[7] * x * z + L[5] * y * z)
        + 2.0 * c2 * (L[3] * x + L[1] * y + L[2] * z)
    )  # fmt: skip


def diffuseIrradianceSH9(sh, N, diffuseColor) -> np.ndarray:
    return f64(diffuseColor) * irradianceSH9(sh, N) * INV_PI


def sh9_basis(dirs) -> np.ndarray:
    """The 9 real SH basis functions at unit directions, (..., 9), in the order above."""
    d = f64(dirs)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack(
        [
            np.full_like(x, _Y0), _Y1 * y, _Y1 * z, _Y1 * x, _Y2 * x * y, _Y2 * y * z,
            _Y20 * (3.0 * z * z - 1.0), _Y2 * x * z, _Y22 * (x * x - y * y),
        ],
        axis=-1,
    )  # fmt: skip


def sh9_project(env: Environment, n: int = 128) -> np.ndarray:
    """SH coefficients (9, 3) of an environment, by midpoint quadrature on an n x 2n grid."""
    theta = (np.arange(n) + 0.5) * np.pi / n
    phi = (np.arange(2 * n) + 0.5) * np.pi / n
    t, p = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    w = np.sin(t) * (np.pi / n) ** 2
    return np.einsum("ijk,ijc,ij->kc", sh9_basis(dirs), f64(env(dirs)), w)


def rotatedHammersley(i, n, offset) -> np.ndarray:
    return np.mod(hammersley(i, n) + f64(offset), 1.0)


def _sample_points(sampleCount: int, offset) -> np.ndarray:
    """Rotated Hammersley points (..., sampleCount, 2) for per-pixel offsets (..., 2)."""
    return rotatedHammersley(np.arange(sampleCount), sampleCount, f64(offset)[..., None, :])


def referenceSpecularIBL(env: Environment, F0, roughness, N, V, sampleCount: int, offset):
    """Vectorised over pixels (leading axes of N, V) and samples."""
    N, V, F0 = f64(N)[..., None, :], f64(V)[..., None, :], f64(F0)[..., None, :]
    a = sq(f64(roughness))[..., None]
    k = k_IBL(a)
    NoV = np.maximum(dot(N, V), 1e-4)
    Xi = _sample_points(sampleCount, offset)
    H = importanceSampleGGX(Xi, a, N)
    L = 2.0 * dot(V, H)[..., None] * H - V
    NoL = saturate(dot(N, L))
    NoH = saturate(dot(N, H))
    VoH = saturate(dot(V, H))
    G = G1_Schlick(NoL, k) * G1_Schlick(NoV, k)
    w = np.where(NoL > 0.0, G * VoH / np.maximum(NoH * NoV, 1e-8), 0.0)
    contrib = f64(env(L)) * F_SchlickExact(F0, VoH) * w[..., None]
    return contrib.sum(axis=-2) / sampleCount


def referenceDiffuseIBL(env: Environment, diffuseColor, N, sampleCount: int, offset):
    Xi = _sample_points(sampleCount, offset)
    L = importanceSampleCosine(Xi, f64(N)[..., None, :])
    return f64(diffuseColor) * f64(env(L)).sum(axis=-2) / sampleCount


def referenceIBL(env, diffuseColor, F0, roughness, N, V, sampleCount: int, offset):
    return referenceDiffuseIBL(env, diffuseColor, N, sampleCount, offset) + referenceSpecularIBL(
        env, F0, roughness, N, V, sampleCount, offset
    )


# --- Reference with multiple importance sampling (twin of ibl.glsl's) ------------------------
# `dist` is the environment's sampling table, the array matedit.ibl.importance builds and the
# renderer uploads (env_sampling.py); `env` a callable directions -> rgb as above.

_LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
_ONE_BELOW = float(np.float32(0.99999994))


@dataclass
class ReferenceSurface:
    """The struct of ibl.glsl: arrays broadcasting like the other twins' inputs."""

    N: np.ndarray
    V: np.ndarray
    diffuseColor: np.ndarray
    F0: np.ndarray
    roughness: np.ndarray
    specularScale: np.ndarray


def makeReferenceSurface(N, V, diffuseColor, F0, roughness, specularScale=1.0):
    N, V = f64(N), f64(V)
    shape = np.broadcast_shapes(N.shape, V.shape)
    return ReferenceSurface(N, V, f64(diffuseColor), f64(F0), f64(roughness),
                            np.broadcast_to(f64(specularScale), shape[:-1] + (3,)))


def _with_sample_axis(s: ReferenceSurface) -> ReferenceSurface:
    """The surface with an axis before the components, to broadcast against samples."""
    def vec(x):
        return f64(x)[..., None, :]

    return ReferenceSurface(vec(s.N), vec(s.V), vec(s.diffuseColor), vec(s.F0),
                            f64(s.roughness)[..., None], vec(s.specularScale))


def referenceAlpha(s: ReferenceSurface) -> np.ndarray:
    return np.maximum(sq(s.roughness), 1e-3)


def referenceSpecularChance(s: ReferenceSurface) -> np.ndarray:
    NoV = saturate(dot(s.N, s.V))
    spec = (F_SchlickExact(s.F0, NoV) * f64(s.specularScale)) @ _LUMINANCE
    diff = f64(s.diffuseColor) @ _LUMINANCE
    total = spec + diff
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0.0, saturate(spec / total), 0.5)


def _half(s: ReferenceSurface, L):
    """(H, valid): the unit half vector of L and V, valid where |L + V|^2 >= 1e-12."""
    h = f64(L) + s.V
    hh = dot(h, h)
    valid = hh >= 1e-12
    return h / np.sqrt(np.where(valid, hh, 1.0))[..., None], valid


def referenceBrdfCosine(s: ReferenceSurface, L) -> np.ndarray:
    """f(l, v) N.l of the whole BRDF towards unit directions L (..., 3)."""
    L = f64(L)
    NoL = dot(s.N, L)
    H, valid = _half(s, L)
    a = referenceAlpha(s)
    NoV = np.maximum(dot(s.N, s.V), 1e-4)
    NoH = dot(s.N, H)
    VoH = dot(s.V, H)
    # no specular where GGX sampling cannot reach (ibl.glsl)
    valid = valid & (VoH > 0.0) & (NoH > 0.0)
    NoH, VoH = saturate(NoH), saturate(VoH)
    NxH = cross(s.N, H)
    D = D_GGX(NoH, a, dot(NxH, NxH))
    Vis = V_SchlickSmith(NoV, np.maximum(NoL, 0.0), k_IBL(a))
    spec = (D * Vis * NoL)[..., None] * F_SchlickExact(s.F0, VoH) * f64(s.specularScale)
    out = f64(s.diffuseColor) * (INV_PI * NoL)[..., None] + np.where(valid[..., None], spec, 0.0)
    return np.where((NoL > 0.0)[..., None], out, 0.0)


def referenceGgxPdf(s: ReferenceSurface, L) -> np.ndarray:
    """D NoH / (4 VoH) of the reference's GGX, 0 where L + V vanishes or V.H <= 0."""
    H, valid = _half(s, f64(L))
    VoH = dot(s.V, H)
    NoH = saturate(dot(s.N, H))
    NxH = cross(s.N, H)
    with np.errstate(invalid="ignore", divide="ignore"):
        ggx = D_GGX(NoH, referenceAlpha(s), dot(NxH, NxH)) * NoH / (4.0 * VoH)
    return np.where(valid & (VoH > 0.0), ggx, 0.0)


def referenceGgxSample(s: ReferenceSurface, Xi) -> np.ndarray:
    """A direction of the reference's GGX lobe for the points Xi (may lie below the horizon)."""
    H = importanceSampleGGX(f64(Xi), referenceAlpha(s), s.N)
    return 2.0 * dot(s.V, H)[..., None] * H - s.V


def referenceBrdfPdf(s: ReferenceSurface, L) -> np.ndarray:
    L = f64(L)
    c = referenceSpecularChance(s)
    cosine = np.maximum(dot(s.N, L), 0.0) * INV_PI
    return (1.0 - c) * cosine + c * referenceGgxPdf(s, L)


def referenceBrdfSample(s: ReferenceSurface, Xi) -> tuple[np.ndarray, np.ndarray]:
    """(L, pdf) for uniform points Xi (..., 2); the GLSL returns pdf through `out`."""
    Xi = f64(Xi)
    c = referenceSpecularChance(s)
    x = Xi[..., 0]
    spec = x < c
    with np.errstate(invalid="ignore", divide="ignore"):
        xs = np.minimum(np.where(spec, x / np.where(c > 0, c, 1.0), 0.0), _ONE_BELOW)
        xd = np.minimum(np.where(spec, 0.0, (x - c) / np.where(c < 1, 1.0 - c, 1.0)),
                        _ONE_BELOW)
    Ls = referenceGgxSample(s, np.stack(np.broadcast_arrays(xs, Xi[..., 1]), -1))
    Ld = importanceSampleCosine(np.stack(np.broadcast_arrays(xd, Xi[..., 1]), -1), s.N)
    L = np.where(spec[..., None], Ls, Ld)
    # a GGX draw its own density does not count (V.H < 0) is a failed sample: pdf 0
    failed = spec & ~(referenceGgxPdf(s, L) > 0.0)
    return L, np.where(failed, 0.0, referenceBrdfPdf(s, L))


def environmentSamplePoint(Xi) -> np.ndarray:
    Xi = f64(Xi)
    return np.mod(Xi[..., ::-1] + np.array([0.5, 0.25]), 1.0)


def referenceEnvironmentIBL(env: Environment, dist, s: ReferenceSurface, sampleCount: int,
                            offset) -> np.ndarray:
    """Vectorised over pixels (leading axes of the surface's arrays) and samples."""
    t = _with_sample_axis(s)
    Xi = _sample_points(sampleCount, offset)
    Lb, pb = referenceBrdfSample(t, Xi)
    ok = (pb > 0.0) & (dot(t.N, Lb) > 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        wb = np.where(ok, 1.0 / (pb + environmentPdf(dist, Lb)), 0.0)
    Le, pe = sampleEnvironmentDirection(dist, environmentSamplePoint(Xi))
    ok = (pe > 0.0) & (dot(t.N, Le) > 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        we = np.where(ok, 1.0 / (pe + referenceBrdfPdf(t, Le)), 0.0)
    total = (referenceBrdfCosine(t, Lb) * f64(env(Lb)) * wb[..., None]
             + referenceBrdfCosine(t, Le) * f64(env(Le)) * we[..., None])
    return total.sum(axis=-2) / sampleCount


def pack_ibl_block(
    sh,
    mip_count: float,
    intensity: float = 1.0,
    samples: int = 64,
    mode: int = IBL_MODE_SPLIT_SUM,
    sample_offset: tuple[float, float] = (0.0, 0.0),
    reference_lights: bool = False,
) -> bytes:
    """Bytes of IblBlock (std140, 176 bytes): vec4 sh[9], vec4 params, vec4 sampleOffset
    (z = 1: sphere and tube lights by Monte Carlo, lights_reference.glsl)."""
    offsets = _layout.IBL_BLOCK.offsets()
    data = np.zeros((IBL_BLOCK_SIZE // 16, 4), dtype="<f4")  # rows of one vec4
    sh_row, params_row, offset_row = (offsets[k] // 16 for k in ("sh", "params", "sampleOffset"))
    data[sh_row:sh_row + 9, :3] = f64(sh).reshape(9, 3)
    data[params_row] = (mip_count, intensity, samples, mode)
    data[offset_row, :2] = sample_offset
    data[offset_row, 2] = 1.0 if reference_lights else 0.0
    return data.tobytes()
