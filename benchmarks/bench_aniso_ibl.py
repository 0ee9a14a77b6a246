"""Anisotropic split sum against brute force under real environments (not a test).

    .venv/bin/python benchmarks/bench_aniso_ibl.py

For each environment (the built-in studio and sky, sun and sky dome, and a smooth analytic
one) and a set of cases (roughness, anisotropy, view, normal), one IBL value of a white
metal (F0 = 1), luminance: the brute force integrates the anisotropic lobe (k = alpha_o / 2)
against the environment by importance sampling (2^17 half vectors), the split sum is the
environment prefiltered by Karis 2013's estimator (N = V = R, weights NoL) along the twin's
bent reflection, times the environment BRDF: the isotropic E(NoV, r) ("before") or E plus
the anisotropic table's change ("table": the shader until the taps). The prefiltered lookup is also
tried at an effective roughness, alpha_eff = sqrt(at ab) ("table + geometric alpha"), and
along the bent reflection of half the anisotropy ("half bend") or the mirror direction
("no bend"), and taps along the lobe's long axis: 3 or 5 at spread at, or the shader's
(surface.glsl anisotropicPrefilteredRadiance: 3 at spread sqrt(at^2 - ab^2), faded out
near the horizon).
Prints the worst and mean error |split - brute| per environment and variant, in units of the
environment's mean radiance (a relative error is meaningless where the lobe sees a dark
part of the studio: the brute force is near 0 there).
"""

from __future__ import annotations

import numpy as np

from matedit.ibl.anisotropy_lut import anisotropy_lut, directional_ab
from matedit.ibl.builtin import builtin_environment
from matedit.shading import anisotropy, surface

N_SAMPLES = 1 << 17
LUMA = np.array([0.2126, 0.7152, 0.0722])


def _lookup(img):
    h, w = img.shape[:2]
    lum = img[..., :3] @ LUMA

    def env(d):
        theta = np.arccos(np.clip(d[..., 1], -1, 1))
        phi = np.arctan2(d[..., 0], -d[..., 2])
        i = np.clip((theta / np.pi * h).astype(int), 0, h - 1)
        j = np.clip(((phi / (2 * np.pi) + 0.5) * w).astype(int), 0, w - 1)
        return lum[i, j]
    return env


def _sample_h(u, at, ab):
    phi = 2 * np.pi * u[:, 0]
    t = np.sqrt(u[:, 1] / (1 - u[:, 1]))
    h = np.stack([at * t * np.cos(phi), ab * t * np.sin(phi), np.ones_like(t)], -1)
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def _g1(x, at, ab):
    s2 = np.maximum(x[..., 0] ** 2 + x[..., 1] ** 2, 1e-300)
    k = 0.5 * np.sqrt((x[..., 0] ** 2 * at * at + x[..., 1] ** 2 * ab * ab) / s2)
    return x[..., 2] / (x[..., 2] * (1 - k) + k)


def _frame(z):
    t = np.cross([0.0, 0.0, 1.0] if abs(z[2]) < 0.999 else [0.0, 1.0, 0.0], z)
    t /= np.linalg.norm(t)
    return t, np.cross(z, t)


def case(env, u, rough, an, N, theta_v, phi_v):
    T, B = _frame(N)
    V = np.sin(theta_v) * (np.cos(phi_v) * T + np.sin(phi_v) * B) + np.cos(theta_v) * N
    a = rough * rough
    at, ab = min(a * (1 + an), 1.0), max(a * (1 - an), min(a, 1e-3))
    h = _sample_h(u, at, ab)
    H = h[:, :1] * T + h[:, 1:2] * B + h[:, 2:] * N
    vh = H @ V
    L = 2 * vh[:, None] * H - V
    ll = np.stack([L @ T, L @ B, L @ N], -1)
    vl = np.array([V @ T, V @ B, V @ N])
    w = _g1(ll, at, ab) * _g1(vl[None], at, ab) * vh / (h[:, 2] * vl[2])
    brute = np.where((ll[:, 2] > 0) & (vh > 0), env(L) * w, 0).sum() / len(u)
    lobe = anisotropy.makeAnisotropicLobe(a, an, np.array([1.0, 0, 0]), T, B, N)
    R = anisotropy.anisotropicReflection(lobe, N, V)
    c2 = vl[0] ** 2 / max(vl[0] ** 2 + vl[1] ** 2, 1e-12)
    e_iso = directional_ab(vl[2], rough, 0.0, c2).sum()
    e_tab = e_iso + anisotropy.anisotropicEnvironmentBRDF(anisotropy_lut(), vl[2], rough, an,
                                                          c2).sum()

    def pref(alpha, R=R):
        Rt, Rb = _frame(R)
        hp = _sample_h(u[: 1 << 15], alpha, alpha)
        Hp = hp[:, :1] * Rt + hp[:, 1:2] * Rb + hp[:, 2:] * R
        Lp = 2 * (Hp @ R)[:, None] * Hp - R
        nol = np.maximum(Lp @ R, 0)
        return np.sum(env(Lp) * nol) / np.sum(nol)
    p_base, p_geo = pref(a), pref(np.sqrt(at * ab))
    # the bend halved (anisotropy / 2 in the mix) and no bend (the mirror direction)
    half = anisotropy.makeAnisotropicLobe(a, an / 2, np.array([1.0, 0, 0]), T, B, N)
    p_half = pref(a, anisotropy.anisotropicReflection(half, N, V))
    p_mirror = pref(a, 2 * (V @ N) * N - V)
    # (a) Filament's bend factor: anisotropy * saturate(5 roughness) in the mix
    fil = anisotropy.makeAnisotropicLobe(a, an * min(5 * rough, 1.0), np.array([1.0, 0, 0]),
                                         T, B, N)
    p_fil = pref(a, anisotropy.anisotropicReflection(fil, N, V))

    # (b) taps along the lobe's long axis: H_i = normalize(N + s_i at T), each prefiltered at
    # the narrow alpha ab along reflect(-V, H_i); weights normalised to 1 (furnace unchanged)
    def taps(s_i):
        w_i = (1 + s_i * s_i) ** -2
        acc = 0.0
        for s, w in zip(s_i, w_i):
            Hi = N + s * at * T
            Hi /= np.linalg.norm(Hi)
            Ri = 2 * (V @ Hi) * Hi - V
            if Ri @ N <= 0:
                Ri = Ri - 1.01 * (Ri @ N) * N
                Ri /= np.linalg.norm(Ri)
            acc += w * pref(ab, Ri)
        return acc / w_i.sum()
    p_t3 = taps(np.array([-0.8, 0.0, 0.8]))
    # (c) the shader's taps (the twin, surface.anisotropicPrefilteredRadiance): spread
    # sqrt(at^2 - ab^2), each prefiltered at alpha ab (the lookup at lod = roughness, mipCount
    # 2), weights faded out near the horizon
    p_shader = float(surface.anisotropicPrefilteredRadiance(
        lambda R, lod: np.full(3, pref(float(lod) ** 2, R)), lobe, N, V, rough, 2)[0])
    p_t5 = taps(np.array([-1.2, -0.6, 0.0, 0.6, 1.2]))
    return brute, {"before": p_base * e_iso, "table": p_base * e_tab,
                   "table + geometric alpha": p_geo * e_tab,
                   "table + half bend": p_half * e_tab, "table + no bend": p_mirror * e_tab,
                   "table + Filament bend": p_fil * e_tab, "table + 3 taps": p_t3 * e_tab,
                   "table + 5 taps": p_t5 * e_tab, "shader (3 taps, faded)": p_shader * e_tab}


def main() -> int:
    rng = np.random.default_rng(11)
    u = rng.random((N_SAMPLES, 2))
    envs = {"studio": _lookup(builtin_environment("studio", 512)),
            "sky (sun and dome)": _lookup(builtin_environment("sky", 512)),
            "smooth": lambda d: 1.0 + 0.8 * d[..., 1] + 0.5 * d[..., 0] ** 2}
    cases = []
    for rough in (0.2, 0.5, 0.8):
        for an in (0.5, 0.9):
            for _ in range(4):
                N = rng.normal(size=3)
                N /= np.linalg.norm(N)
                cases.append((rough, an, N, rng.uniform(0.1, 1.2), rng.uniform(0, 2 * np.pi)))
    d = rng.normal(size=(1 << 16, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    for name, env in envs.items():
        scale = float(np.mean(env(d)))
        errs: dict[str, list[float]] = {}
        for c in cases:
            brute, split = case(env, u, *c)
            for k, v in split.items():
                errs.setdefault(k, []).append(abs(v - brute) / scale)
        for k, e in errs.items():
            print(f"{name:20s} {k:30s} worst {max(e):6.3f}  mean {np.mean(e):6.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
