"""The anisotropic environment BRDF of the split sum (docs/shading.md#anisotropy): how far the
anisotropic GGX lobe's scale and bias of F0 move from the isotropic LUT's.

The isotropic LUT (matedit.ibl.lut) holds A(NoV, r) and B(NoV, r) of the GGX lobe with the
talk's Schlick-Smith k = alpha / 2. The anisotropic lobe (anisotropy.glsl) has alphas
at = min(a (1 + an), 1), ab = max(a (1 - an), min(a, 1e-3)) and each direction's k from its
projected alpha (Heitz 2014, eq 80), so its A and B also depend on the anisotropy an and on
the view's azimuth phi from the stretch direction T. This table holds the difference

    dA(NoV, r, an, c) = A_aniso(NoV, r, an, phi) - A_aniso(NoV, r, 0, phi), same for B,

c = |cos(phi)|. Symmetry: the lobe is even in T and in B, so phi, -phi, pi - phi give the same
values and c in [0, 1] covers every azimuth. |cos(phi)| rather than cos^2: the view's
projected alpha, sqrt(ab^2 + (at^2 - ab^2) cos^2), is nearly at |cos(phi)| when ab << at, so
the table is nearly linear along this axis (in cos^2 it has a square-root edge at 0).
The difference is exactly 0 at an = 0 (the same quadrature at the same points) and smooth,
so a small table interpolated linearly is added to the 128 x 128 isotropic LUT: the
shader's (A, B) = LUT(NoV, r) + table(NoV, r, an, c), only where an > 0.

Axes and resolution (ANISOTROPY_LUT_SHAPE): NoV and roughness at the centres of 16 and 24
cells ((i + 0.5) / n, clamped at the ends, as the isotropic LUT), anisotropy at 13 nodes
i / 12 and c at 9 nodes i / 8 (both ends included). Stored as float32 (NoV, r, an, c, 2),
shipped in the package (anisotropy_dfg.npy, 360 KB); `python tools/anisotropy_lut.py
--regen` regenerates it (~2 min) and a test recomputes sample cells. Interpolation error of
dA + dB against the quadrature at random off-node points: median 2e-4, worst 5e-3 (near
anisotropy 1 and where at reaches its clamp at 1).

Quadrature, per cell: half vectors H from stretched unit-roughness GGX slopes (Heitz 2014,
sec. 5.3): slope = e^s (at cos psi, ab sin psi), whose density is D NoH when s is weighted by
du = 2 u (1 - u) ds, u = t^2 / (1 + t^2), t = e^s. The estimator of f NoL / p is the notes'
G1(L) G1(V) VoH / (NoH NoV) (zero where NoL <= 0 or VoH <= 0), split by the exact Fresnel
power Fc = (1 - VoH)^5 into A (1 - Fc) and B (Fc). s runs over [-S_SPAN, S_SPAN] in
Gauss-Legendre panels, psi over [0, 2 pi) by the trapezoid rule (periodic: its error comes from
the horizon's kink, where G1(L) reaches 0 continuously, O(h^2)).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

ANISOTROPY_LUT_SHAPE = (16, 24, 13, 9)  # NoV, roughness, anisotropy, |cos(azimuth)|
ANISOTROPY_LUT_PATH = Path(__file__).with_name("anisotropy_dfg.npy")
S_SPAN = 8.0
S_PANELS = 32
S_NODES = 4
PSI_NODES = 128
MIN_ALPHA = 1e-3  # anisotropy.glsl's ANISOTROPY_MIN_ALPHA


def _alphas(a, an):
    """Kulla and Conty 2017: at = a (1 + an), ab = a (1 - an), ab >= min(a, 1e-3)."""
    return np.minimum(a * (1.0 + an), 1.0), np.maximum(a * (1.0 - an), np.minimum(a, MIN_ALPHA))


def _g1(z, x, y, at, ab):
    """Schlick-Smith G1 with k = alpha_o / 2 of the projected alpha (Heitz 2014 eq 80)."""
    s2 = x * x + y * y
    cos2 = np.where(s2 > 1e-12, np.minimum(x * x / np.maximum(s2, 1e-300), 1.0), 1.0)
    k = 0.5 * np.sqrt(ab * ab + (at * at - ab * ab) * cos2)
    return z / (z * (1.0 - k) + k)


@lru_cache(maxsize=1)
def _nodes():
    x, w = np.polynomial.legendre.leggauss(S_NODES)
    h = 2.0 * S_SPAN / S_PANELS
    s = (-S_SPAN + h * (np.arange(S_PANELS)[:, None] + 0.5 * (x[None] + 1.0))).ravel()
    ws = np.tile(0.5 * h * w, S_PANELS)
    t = np.exp(s)
    u = t * t / (1.0 + t * t)
    ws = ws * 2.0 * u * (1.0 - u)
    psi = 2.0 * np.pi * np.arange(PSI_NODES) / PSI_NODES
    return t, ws, psi


def directional_ab(NoV: float, roughness: float, anisotropy: float, cos2phi: float) -> np.ndarray:
    """(A, B) of the anisotropic lobe for a view at NoV and cos^2 of its azimuth from T."""
    t, ws, psi = _nodes()
    at, ab = _alphas(roughness * roughness, anisotropy)
    sinv = np.sqrt(max(1.0 - NoV * NoV, 0.0))
    cphi, sphi = np.sqrt(cos2phi), np.sqrt(max(1.0 - cos2phi, 0.0))
    v = np.array([sinv * cphi, sinv * sphi, NoV])
    hx = t[:, None] * at * np.cos(psi)[None]
    hy = t[:, None] * ab * np.sin(psi)[None]
    inv = 1.0 / np.sqrt(hx * hx + hy * hy + 1.0)
    hx, hy, hz = hx * inv, hy * inv, inv
    voh = v[0] * hx + v[1] * hy + v[2] * hz
    lx, ly, lz = 2 * voh * hx - v[0], 2 * voh * hy - v[1], 2 * voh * hz - v[2]
    ok = (lz > 0.0) & (voh > 0.0)
    lz_ = np.where(ok, lz, 1.0)
    g = _g1(lz_, lx, ly, at, ab) * _g1(NoV, v[0], v[1], at, ab) * voh / (hz * NoV)
    g = np.where(ok, g, 0.0) * ws[:, None] / PSI_NODES
    fc = np.clip(1.0 - voh, 0.0, 1.0) ** 5
    return np.array([np.sum(g * (1.0 - fc)), np.sum(g * fc)])


def axes() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The table's node values: NoV, roughness (cell centres), anisotropy, |cos(phi)|."""
    nv, nr, na, nc = ANISOTROPY_LUT_SHAPE
    return ((np.arange(nv) + 0.5) / nv, (np.arange(nr) + 0.5) / nr,
            np.linspace(0.0, 1.0, na), np.linspace(0.0, 1.0, nc))


def cell(i: int, j: int, k: int, m: int) -> np.ndarray:
    """One entry of the table: (dA, dB) at node (NoV i, roughness j, anisotropy k, c m)."""
    nov, rough, an, c = axes()
    return (directional_ab(nov[i], rough[j], an[k], c[m] ** 2)
            - directional_ab(nov[i], rough[j], 0.0, c[m] ** 2)).astype(np.float32)


def generate() -> np.ndarray:
    """The whole table, float32 (NoV, roughness, anisotropy, c, 2); cell() for each entry."""
    nov, rough, an, c = axes()
    out = np.zeros(ANISOTROPY_LUT_SHAPE + (2,), np.float32)
    for i, j, m in np.ndindex(len(nov), len(rough), len(c)):
        iso = directional_ab(nov[i], rough[j], 0.0, c[m] ** 2)
        for k in range(1, len(an)):
            out[i, j, k, m] = (directional_ab(nov[i], rough[j], an[k], c[m] ** 2) - iso)
    return out


@lru_cache(maxsize=1)
def anisotropy_lut() -> np.ndarray:
    """The shipped table (read once), float32 (NoV, roughness, anisotropy, c, 2)."""
    table = np.load(ANISOTROPY_LUT_PATH)
    if table.shape != ANISOTROPY_LUT_SHAPE + (2,):
        raise ValueError(f"{ANISOTROPY_LUT_PATH}: shape {table.shape}, expected "
                         f"{ANISOTROPY_LUT_SHAPE + (2,)}; run tools/anisotropy_lut.py --regen")
    table.setflags(write=False)
    return table


def texture_layout(table: np.ndarray) -> np.ndarray:
    """The table as the 3D texture's texels (depth, height, width, 2): width NoV, height
    roughness, depth the anisotropy slabs of each c node (z = m * n_an + k)."""
    nv, nr, na, nc = table.shape[:4]
    return np.ascontiguousarray(table.transpose(3, 2, 1, 0, 4).reshape(nc * na, nr, nv, 2))


def upload_anisotropy_lut(ctx):
    """The table as an RG32F 3D texture, linear filtering, clamped to the edge
    (anisotropy.glsl's anisotropicEnvironmentBRDF reads it; bound to ANISOTROPY_LUT)."""
    import moderngl

    texels = texture_layout(anisotropy_lut())
    d, h, w = texels.shape[:3]
    tex = ctx.texture3d((w, h, d), 2, texels.astype("f4").tobytes(), dtype="f4")
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x = tex.repeat_y = tex.repeat_z = False
    return tex
