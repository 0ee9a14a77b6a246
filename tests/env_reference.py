"""Independent numpy references for the reference mode's environment lighting.

Nothing here imports matedit: a generated sun-and-sky environment, the cube-map geometry
(OpenGL's face table, the convention of matedit/ibl/cubemap.py, restated), the BRDF of the
reference mode written from Karis 2013 (docs/shading.md#brdf) (Lambert c_diff / pi; GGX D with
alpha = roughness^2, at least 1e-3 as the shader takes for a mirror; Schlick-Smith
visibility with k = alpha / 2; Schlick Fresnel with the exact fifth power), and a brute-force
quadrature of f(l, v) N.l L(l) over a cube map taken as piecewise constant on its texels
(the GPU reads it with NEAREST filtering in these tests, so that is exactly what it sees).

The quadrature: every texel split into 2 x 2 sub-texels, each with its exact solid angle;
for lobes narrower than a few texels (alpha < 3 texel widths), texels within a cone of
0.06 + 10 alpha radians around the mirror direction split finer, into sub-texels of about
alpha / 3 (at most 32 x 32).
"""

from __future__ import annotations

import math

import numpy as np

SUN_DIRECTION = np.array([0.35, 0.64, 0.68]) / np.linalg.norm([0.35, 0.64, 0.68])
SUN_RADIUS = math.radians(0.5)


def equirect_directions(h: int, w: int) -> np.ndarray:
    """Pixel-centre directions of an equirect: +Y up, row 0 the zenith, u = 0.5 looks -Z."""
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    phi = 2 * np.pi * (u - 0.5)
    theta = np.pi * v
    st = np.sin(theta)[:, None]
    return np.stack([st * np.sin(phi)[None, :], np.repeat(np.cos(theta)[:, None], w, 1),
                     -st * np.cos(phi)[None, :]], -1)


def sun_sky(width: int = 2048, sun_ratio: float = 3e4) -> np.ndarray:
    """A (width / 2, width, 3) float32 equirect: a blue gradient sky (zenith ~0.35, horizon
    ~1), a dim ground, and a sun disc of 0.5 degrees radius whose radiance is `sun_ratio`
    times the horizon sky's, its edge anti-aliased by 8 x 8 sub-pixel coverage."""
    h = width // 2
    d = equirect_directions(h, width)
    y = d[..., 1]
    up = np.clip(y, 0.0, 1.0)[..., None]
    horizon, zenith = np.array([1.0, 1.0, 1.05]), np.array([0.25, 0.4, 0.9])
    sky = horizon + (zenith - horizon) * np.sqrt(up)
    ground = np.array([0.12, 0.1, 0.08])
    img = np.where((y >= 0)[..., None], sky, ground)
    # the sun: coverage of each pixel near it by 8 x 8 sub-pixel samples
    near = np.argwhere(d @ SUN_DIRECTION > math.cos(SUN_RADIUS + 4 * np.pi / width))
    k = 8
    sub = (np.arange(k) + 0.5) / k
    for j, i in near:
        u = (i + sub[None, :]) / width
        v = (j + sub[:, None]) / h
        phi, theta = 2 * np.pi * (u - 0.5), np.pi * v
        dd = np.stack(np.broadcast_arrays(np.sin(theta) * np.sin(phi), np.cos(theta),
                                          -np.sin(theta) * np.cos(phi)), -1)
        cover = np.mean(dd @ SUN_DIRECTION > math.cos(SUN_RADIUS))
        img[j, i] = img[j, i] * (1 - cover) + cover * sun_ratio * np.array([1.0, 0.95, 0.85])
    return img.astype(np.float32)


def face_point(face: int, sc: np.ndarray, tc: np.ndarray) -> np.ndarray:
    """Unnormalised direction of face coordinates sc, tc in [-1, 1] (OpenGL's table:
    +X -X +Y -Y +Z -Z, texel column along s, row along t)."""
    one = np.ones_like(sc)
    comps = {0: (one, -tc, -sc), 1: (-one, -tc, sc), 2: (sc, one, tc), 3: (sc, -one, -tc),
             4: (sc, -tc, one), 5: (-sc, -tc, -one)}[face]
    return np.stack(comps, -1)


def _rect_solid_angle(x0, x1, y0, y1):
    """Solid angle of the rectangle [x0, x1] x [y0, y1] of the plane z = 1 seen from 0."""
    def f(x, y):
        return np.arctan2(x * y, np.sqrt(x * x + y * y + 1.0))

    return f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)


def _subtexels(n: int, split: int, rows=None, cols=None):
    """(face-independent) sub-texel centres (sc, tc) and solid angles of texels (rows,
    cols) of an n x n face, split x split each: arrays (..., split, split)."""
    if rows is None:
        rows, cols = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    e = np.arange(split + 1) / split
    x0 = -1 + 2 * (cols[..., None, None] + e[None, :-1]) / n  # (..., 1, split)
    x1 = -1 + 2 * (cols[..., None, None] + e[None, 1:]) / n
    y0 = -1 + 2 * (rows[..., None, None] + e[:-1, None]) / n  # (..., split, 1)
    y1 = -1 + 2 * (rows[..., None, None] + e[1:, None]) / n
    x0, x1, y0, y1 = np.broadcast_arrays(x0, x1, y0, y1)
    return 0.5 * (x0 + x1), 0.5 * (y0 + y1), _rect_solid_angle(x0, x1, y0, y1)


def brdf_cosine(L, N, V, diffuse, F0, rough):
    """f(l, v) N.l for unit directions L (..., 3); one surface (N, V vectors)."""
    a = max(rough * rough, 1e-3)
    k = a / 2
    nol = L @ N
    nov = max(float(N @ V), 1e-4)
    H = L + V
    H = H / np.linalg.norm(H, axis=-1, keepdims=True)
    noh = np.clip(H @ N, 0, 1)
    voh = np.clip(H @ V, 0, 1)
    one_minus = np.sum(np.cross(N, H) ** 2, axis=-1)
    D = a * a / (math.pi * (one_minus + noh * noh * a * a) ** 2)
    vis = 0.25 / ((nov * (1 - k) + k) * (np.maximum(nol, 0) * (1 - k) + k))
    F = F0 + (1 - F0) * ((1 - voh) ** 5)[..., None]
    out = diffuse / math.pi * nol[..., None] + (D * vis * nol)[..., None] * F
    return np.where((nol > 0)[..., None], out, 0.0)


class CubeQuadrature:
    """Brute-force reflected radiance under cube faces (6, n, n, 3), piecewise constant."""

    def __init__(self, faces: np.ndarray, split: int = 2, fine_split: int = 32):
        self.faces = np.asarray(faces, np.float64)
        self.n = n = self.faces.shape[1]
        self.fine_split = fine_split
        sc, tc, om = _subtexels(n, split)
        self.dirs = np.stack([face_point(f, sc, tc) for f in range(6)])  # (6,n,n,s,s,3)
        self.dirs /= np.linalg.norm(self.dirs, axis=-1, keepdims=True)
        self.omega = np.broadcast_to(om, (6,) + om.shape)
        self.rad = np.broadcast_to(self.faces[:, :, :, None, None, :], self.dirs.shape)
        c = (np.arange(n) + 0.5) / n * 2 - 1
        tcc, scc = np.meshgrid(c, c, indexing="ij")
        centres = np.stack([face_point(f, scc, tcc) for f in range(6)])
        self.centres = centres / np.linalg.norm(centres, axis=-1, keepdims=True)

    def integrate(self, N, V, diffuse, F0, rough) -> np.ndarray:
        N, V = np.asarray(N, np.float64), np.asarray(V, np.float64)
        diffuse, F0 = np.asarray(diffuse, np.float64), np.asarray(F0, np.float64)
        return self.integrate_brdf(lambda L: brdf_cosine(L, N, V, diffuse, F0, rough),
                                   2 * (N @ V) * N - V, max(rough * rough, 1e-3))

    def integrate_brdf(self, brdf, R, a, cone_alpha=None) -> np.ndarray:
        """Integral of brdf(L) (f N.l, (..., 3)) L(l) dl; texels within 0.06 + 10
        `cone_alpha` (default a) of R split to about a / 3 where a is narrower than texels."""
        texel = 2.0 / self.n  # radians, about, at a face's centre
        split = int(min(self.fine_split, math.ceil(3 * texel / a)))
        cone = 0.06 + 10 * (a if cone_alpha is None else cone_alpha)  # around R
        fine = self.centres @ R > math.cos(cone) if split > 2 else np.zeros(
            self.centres.shape[:3], bool)  # (6, n, n)
        f = brdf(self.dirs)
        contrib = f * self.rad * self.omega[..., None]
        total = contrib[~fine].sum(axis=(0, 1, 2))
        faces, rows, cols = np.nonzero(fine)
        for face in range(6):
            sel = faces == face
            if not sel.any():
                continue
            sc, tc, om = _subtexels(self.n, split, rows[sel], cols[sel])
            d = face_point(face, sc, tc)
            d /= np.linalg.norm(d, axis=-1, keepdims=True)
            fd = brdf(d)
            rad = self.faces[face, rows[sel], cols[sel]][:, None, None, :]
            total = total + (fd * rad * om[..., None]).sum(axis=(0, 1, 2))
        return total


# --- the layered BRDF (docs/shading.md: Clear coat, Anisotropy) ------------------------------

def _ggx_term(L, N, V, a):
    """D_GGX (Walter 2007) and the unit half vector, for the directions L."""
    H = L + V
    H = H / np.linalg.norm(H, axis=-1, keepdims=True)
    noh = np.clip(H @ N, 0, 1)
    D = a * a / (math.pi * (1 - noh * noh + noh * noh * a * a) ** 2)
    return D, H


# Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF", table 1: the fitted
# exponent L(x) = a / (1 + b x^c) + d x + e of the Charlie lobe's Lambda, at r = 0 and r = 1,
# interpolated by (1 - r)^2 with r = alpha.
_SHEEN_FIT_R0 = (25.3245, 3.32435, 0.16801, -1.27393, -4.85967)
_SHEEN_FIT_R1 = (21.5473, 3.82987, 0.19823, -1.97760, -4.32054)


def _sheen_lambda(x, alpha):
    t = (1 - alpha) ** 2
    a, b, c, d, e = (r1 * (1 - t) + r0 * t for r0, r1 in zip(_SHEEN_FIT_R0, _SHEEN_FIT_R1))

    def fit(u):
        return a / (1 + b * np.power(u, c)) + d * u + e
    x = np.clip(x, 0.0, 1.0)
    return np.where(x < 0.5, np.exp(fit(x)), np.exp(2 * fit(0.5) - fit(1 - x)))


def sheen_white(L, N, V, alpha):
    """D_Charlie G2 / (4 NoL NoV) NoL of a white sheen (height-correlated Smith G2 of the
    fitted Lambda, no Fresnel): what the sheen contributes towards L, per unit colour."""
    nol = L @ N
    nov = max(float(N @ V), 1e-4)
    H = L + V
    H = H / np.linalg.norm(H, axis=-1, keepdims=True)
    sin2 = np.clip(1 - (H @ N) ** 2, 0, 1)
    D = (2 + 1 / alpha) * sin2 ** (0.5 / alpha) / (2 * math.pi)
    nl = np.maximum(nol, 1e-12)
    G = 1 / (1 + _sheen_lambda(nov, alpha) + _sheen_lambda(nl, alpha))
    return np.where(nol > 0, D * G / (4 * nov), 0.0)  # D G / (4 NoL NoV) times NoL


def sheen_albedo(alpha, n_mu: int = 129, n_theta: int = 192, n_phi: int = 384):
    """E(mu) of the white sheen lobe, its directional albedo, on a grid of mu = NoV in
    [0, 1], by the midpoint rule over the hemisphere of L (the sheen's own integral, not
    the LUT the shader reads). Returns (mu, E)."""
    mu = np.linspace(0.0, 1.0, n_mu)
    th = (np.arange(n_theta) + 0.5) * (math.pi / 2) / n_theta
    ph = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    st, ct = np.sin(th)[:, None], np.cos(th)[:, None]
    L = np.stack(np.broadcast_arrays(st * np.cos(ph), st * np.sin(ph), ct), -1)
    dw = (math.pi / 2 / n_theta) * (2 * math.pi / n_phi) * st
    N = np.array([0.0, 0.0, 1.0])
    E = np.empty(n_mu)
    for i, m in enumerate(mu):
        m = max(m, 1e-4)
        V = np.array([math.sqrt(1 - m * m), 0.0, m])
        E[i] = float((sheen_white(L, N, V, alpha) * dw).sum())
    return mu, E


def layered_brdf_cosine(L, p):
    """f(l, v) N.l of a colourless clear coat (on the base's normal) over a base whose
    specular is anisotropic GGX (Burley 2012 B.2: at = a (1 + an), ab = a (1 - an);
    Schlick-Smith k = alpha_o / 2 of each direction's projected roughness, Heitz 2014
    eq 80) or, at an = 0, the isotropic one of brdf_cosine. The coat: Fc(x) = w (F0c +
    (1 - F0c)(1 - x)^5); the base seen through it times (1 - Fc(NoV)) (1 - Fc(NoL)); the
    coat's GGX at alpha max(rc^2, 1e-3), k = alpha / 2, Schlick F, times w. Between them,
    where p has a sheen colour sc > 0: the Charlie sheen of roughness sr (clamped at 0.3)
    over the base, which it scales by its albedo (p["sheen_albedo"]: sheen_albedo's table).
    p: N, V, dc, F0, r, an, T, cw, cr, cf0 [, sc, sr, sheen_albedo]."""
    N, V, T = p["N"], p["V"], p["T"]
    nol = L @ N
    nov = max(float(N @ V), 1e-4)
    if p["an"] == 0.0:
        base = brdf_cosine(L, N, V, p["dc"], p["F0"], p["r"])
    else:
        a = p["r"] ** 2
        at = min(a * (1 + p["an"]), 1.0)
        ab = max(a * (1 - p["an"]), min(a, 1e-3))
        B = np.cross(N, T)
        H = L + V
        H = H / np.linalg.norm(H, axis=-1, keepdims=True)
        d = (H @ T / at) ** 2 + (H @ B / ab) ** 2 + (H @ N) ** 2
        D = 1.0 / (math.pi * at * ab * d * d)

        def k_of(X):
            c2 = (X @ T) ** 2 / np.maximum(1 - (X @ N) ** 2, 1e-12)
            return np.sqrt(ab * ab + (at * at - ab * ab) * np.minimum(c2, 1.0)) / 2

        kv, kl = k_of(V), k_of(L)
        vis = 0.25 / ((nov * (1 - kv) + kv) * (np.maximum(nol, 0) * (1 - kl) + kl))
        voh = np.clip(H @ V, 0, 1)
        F = p["F0"] + (1 - p["F0"]) * ((1 - voh) ** 5)[..., None]
        base = p["dc"] / math.pi * nol[..., None] + (D * vis * nol)[..., None] * F
        base = np.where((nol > 0)[..., None], base, 0.0)
    sc = np.asarray(p.get("sc", (0.0, 0.0, 0.0)), float)
    if sc.max() > 0:
        # the sheen over the base (glTF KHR_materials_sheen albedo scaling): the base times
        # min(1 - max(c) E(NoV), 1 - max(c) E(NoL)), plus c D G / (4 NoL NoV) NoL
        alpha = max(p["sr"], 0.3) ** 2
        mu, E = p["sheen_albedo"]
        m = sc.max()
        scale = np.minimum(1 - m * np.interp(nov, mu, E),
                           1 - m * np.interp(np.clip(nol, 0, 1), mu, E))
        base = base * scale[..., None] + sheen_white(L, N, V, alpha)[..., None] * sc
    w, f0c = p["cw"], p["cf0"]

    def fc(x):
        return w * (f0c + (1 - f0c) * (1 - np.clip(x, 0, 1)) ** 5)

    ac = max(p["cr"] ** 2, 1e-3)
    D, H = _ggx_term(L, N, V, ac)
    kc = ac / 2
    vis = 0.25 / ((nov * (1 - kc) + kc) * (np.maximum(nol, 0) * (1 - kc) + kc))
    coat = np.where(nol > 0, D * vis * nol * (f0c + (1 - f0c) * (1 - np.clip(H @ V, 0, 1)) ** 5)
                    * w, 0.0)
    through = (1 - fc(nov)) * (1 - fc(nol))
    return base * through[..., None] + coat[..., None]
