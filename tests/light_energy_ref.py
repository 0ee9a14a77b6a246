"""Independent numpy references for the area lights' specular energy (no matedit import).

Setup: a surface point at the origin, N = +Z, a white metal (F0 = 1, so F = 1), a light of
intensity I = 1 straight above at distance d. "Specular energy" is the reflected radiant
exitance, the outgoing specular radiance integrated over the hemisphere of view directions
weighted by N.V.

True energy: the light is a uniform emitter of radiance Le, a sphere (radius r; Le =
I / (pi r^2), so its irradiance is that of the point light the model uses for diffuse) or a
capsule (radius r, segment length l along X; Le = I / (2 r l + pi r^2), its broadside
projected area, so the sphere is the l -> 0 limit). Swapping the two integrals,
    E_true = Le * integral over the light's solid angle of rho(l) (N.l) dl,
where rho(l) is the specular's directional albedo for incidence l (by reciprocity the
integral of f(l, v) N.v over v): GGX D, Schlick-Smith G with k = (roughness + 1)^2 / 8.

Representative-point energy: the caller gives the model's outgoing specular radiance for
arrays of view directions; `exitance_*` integrate it over the hemisphere.
"""

from __future__ import annotations

import math

import numpy as np


def ggx_albedo(mu: np.ndarray, roughness: float, ny: int = 2048, nphi: int = 64) -> np.ndarray:
    """rho(mu) = integral of f_spec(l, v) N.l dl for a view at cos mu (F = 1), by a midpoint
    quadrature in the GGX half-vector CDF variables: the integrand is G VoH / (NoH NoV)."""
    a = roughness * roughness
    k = (roughness + 1.0) ** 2 / 8.0
    y = (np.arange(ny) + 0.5) / ny
    phi = (np.arange(nphi) + 0.5) / nphi * 2 * np.pi
    cos_h = np.sqrt((1 - y) / (1 + (a * a - 1) * y))
    sin_h = np.sqrt(np.maximum(0.0, 1 - cos_h ** 2))
    hx = sin_h[:, None] * np.cos(phi)[None, :]
    hz = np.broadcast_to(cos_h[:, None], hx.shape)
    out = np.empty(len(mu))
    for i, c in enumerate(np.asarray(mu, np.float64)):
        c = max(c, 1e-6)
        vx = math.sqrt(max(0.0, 1 - c * c))
        voh = vx * hx + c * hz
        nol = 2 * voh * hz - c
        g = (nol / (nol * (1 - k) + k)) * (c / (c * (1 - k) + k))
        out[i] = np.where(nol > 0, g * voh / (hz * c), 0.0).mean()
    return out


def _albedo_table(roughness: float):
    mu = np.linspace(0.0, 1.0, 257)
    return mu, ggx_albedo(mu, roughness)


def sphere_true_energy(radius: float, d: float, roughness: float) -> float:
    """Le * 2 pi * integral over the cone (cos from cos(theta_max) to 1) of rho(mu) mu dmu."""
    le = 1.0 / (math.pi * radius * radius)
    cmax = math.sqrt(max(0.0, 1.0 - (radius / d) ** 2))
    mu_t, rho_t = _albedo_table(roughness)
    n = 4096
    mu = cmax + (np.arange(n) + 0.5) / n * (1.0 - cmax)
    integrand = np.interp(mu, mu_t, rho_t) * mu
    return le * 2 * math.pi * integrand.mean() * (1.0 - cmax)


def _rho_of(roughness: float, rho):
    """rho(directions (..., 3)) -> albedo: the given callable, or GGX's, of the direction's z."""
    if rho is not None:
        return rho
    mu_t, rho_t = _albedo_table(roughness)
    return lambda u: np.interp(np.clip(u[..., 2], 0.0, 1.0), mu_t, rho_t)


def capsule_true_energy(radius: float, length: float, d: float, roughness: float,
                        nx: int = 3000, ny: int = 300, rho=None) -> float:
    """Ray-cast quadrature over the plane z = d: the direction to (x, y, d) sees the capsule
    (axis along X through (0, 0, d), segment half-length length / 2) when the ray passes
    within `radius` of the segment; dOmega = d dx dy / |q|^3. `rho`: the albedo of a
    direction (an anisotropic lobe's), else GGX's at `roughness`."""
    h = length / 2
    le = 1.0 / (2 * radius * length + math.pi * radius * radius)
    albedo = _rho_of(roughness, rho)
    ext = h + radius
    # The capsule is seen within |x| <= ext (1 + small) on the plane at height d; rays from
    # the origin hitting it at depth d +- r land within that box widened by r / d.
    xs = (np.arange(nx) + 0.5) / nx * 2 - 1
    ys = (np.arange(ny) + 0.5) / ny * 2 - 1
    wx = ext * (1 + radius / d) + radius
    wy = radius * (1 + ext / d) * 1.05 + 1e-9
    x, y = np.meshgrid(xs * wx, ys * wy, indexing="ij")
    q = np.stack([x, y, np.full_like(x, d)], axis=-1)
    qn = np.linalg.norm(q, axis=-1)
    u = q / qn[..., None]
    ux, uz = u[..., 0], u[..., 2]
    den = np.maximum(1 - ux * ux, 1e-12)
    t = np.clip(d * ux * uz / den, -h, h)
    # squared distance from the ray (through the origin along u) to the point (t, 0, d)
    s_dot_u = t * ux + d * uz
    dist2 = t * t + d * d - s_dot_u ** 2
    hit = dist2 <= radius * radius
    domega = d * (2 * wx / nx) * (2 * wy / ny) / qn ** 3
    mu = uz
    return float(le * np.sum(np.where(hit, albedo(u) * mu * domega, 0.0)))


def exitance_axisymmetric(spec_of_view, n: int = 40000) -> float:
    """2 pi * integral over theta_v of L(theta_v) cos sin: `spec_of_view(V)` takes (n, 3) unit
    view vectors in the XZ plane and returns the specular radiance (n,). Quadrature nodes
    theta = (pi/2) s^2, dense near the normal where the highlight of an overhead light is."""
    s = (np.arange(n) + 0.5) / n
    theta = 0.5 * math.pi * s * s
    dtheta = math.pi * s / n
    V = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=1)
    L = np.asarray(spec_of_view(V), np.float64)
    return float(2 * math.pi * np.sum(L * np.cos(theta) * np.sin(theta) * dtheta))


def tube_view_grid(nb: int = 1600, ng: int = 1600):
    """View directions for a tube along X overhead, and their solid-angle weights times N.V:
    the mirror direction R = (-Vx, -Vy, Vz) is (sin b, cos b sin g, cos b cos g), b along the
    tube, g across it (dOmega = cos b db dg); g = (pi/2) s |s| is dense across the strip."""
    b = ((np.arange(nb) + 0.5) / nb * 2 - 1) * 0.5 * math.pi
    s = (np.arange(ng) + 0.5) / ng * 2 - 1
    g = 0.5 * math.pi * s * np.abs(s)
    dg = math.pi * np.abs(s) * (2.0 / ng)
    db = math.pi / nb
    B, G = np.meshgrid(b, g, indexing="ij")
    R = np.stack([np.sin(B), np.cos(B) * np.sin(G), np.cos(B) * np.cos(G)], axis=-1)
    V = np.stack([-R[..., 0], -R[..., 1], R[..., 2]], axis=-1).reshape(-1, 3)
    w = (np.cos(B) * db * dg[None, :] * R[..., 2]).reshape(-1)
    return V, w


def sphere_true_energy_tilted(radius: float, d: float, tilt: float, roughness: float,
                              n: int = 512, rho=None) -> float:
    """As sphere_true_energy for a sphere whose centre lies `tilt` radians from the normal
    (in the XZ plane): a solid-angle grid over its cone, clipped at the horizon. `rho`: the
    albedo of a direction (an anisotropic lobe's), else GGX's at `roughness`."""
    le = 1.0 / (math.pi * radius * radius)
    cmax = math.sqrt(max(0.0, 1.0 - (radius / d) ** 2))
    albedo = _rho_of(roughness, rho)
    c = cmax + (np.arange(n) + 0.5) / n * (1.0 - cmax)
    phi = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * math.pi
    C, P = np.meshgrid(c, phi, indexing="ij")
    s = np.sqrt(1 - C * C)
    # cone around the axis (sin t, 0, cos t): z of the direction
    z = C * math.cos(tilt) - s * np.cos(P) * math.sin(tilt)
    w = (1.0 - cmax) * 2 * math.pi / C.size
    x = C * math.sin(tilt) + s * np.cos(P) * math.cos(tilt)
    u = np.stack([x, s * np.sin(P), z], -1)
    zc = np.clip(z, 0.0, 1.0)
    return float(le * np.sum(np.where(z > 0, albedo(u) * zc, 0.0)) * w)


def brdf_albedo(brdf, n_mu: int = 129, n_cos: int = 192, n_phi: int = 96):
    """rho(u) = integral of f(v, u) N.v dv over the hemisphere of v (N = +Z) of an isotropic
    BRDF `brdf(V (n, 3), L (n, 3)) -> (n,)` (the lobe under test, passed in), by a midpoint
    grid uniform in solid angle (cos theta_v, phi_v), tabulated over u's cos theta at n_mu
    nodes and interpolated linearly. With a reciprocal f, rho(l) is the directional albedo
    for incidence l, so the exitance under a light of radiance Le is Le * integral over the
    light of rho(l) N.l dl (the swapped integrals of this module's docstring)."""
    c = (np.arange(n_cos) + 0.5) / n_cos
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * math.pi
    C, P = np.meshgrid(c, phi, indexing="ij")
    S = np.sqrt(1 - C * C)
    V = np.stack([S * np.cos(P), S * np.sin(P), C], -1).reshape(-1, 3)
    d_omega = 2 * math.pi / V.shape[0]
    mus = np.linspace(0.0, 1.0, n_mu)
    tab = np.empty(n_mu)
    for i, mu in enumerate(mus):
        s = math.sqrt(max(1 - mu * mu, 0.0))
        L = np.broadcast_to(np.array([s, 0.0, max(mu, 1e-6)]), V.shape)
        tab[i] = float(np.sum(np.asarray(brdf(V, L), np.float64) * V[:, 2]) * d_omega)

    def rho(u):
        return np.interp(np.clip(u[..., 2], 0.0, 1.0), mus, tab)
    return rho


def aniso_albedo(rough: float, an: float, nmu: int = 65, nc: int = 17, ny: int = 256,
                 npsi: int = 64):
    """rho(l) of the anisotropic lobe for analytic lights (k = (sqrt(alpha_o) + 1)^2 / 8 per
    direction, Heitz 2014's projected alpha; F = 1), written here from the papers: midpoint
    quadrature over stretched unit-GGX slopes (Heitz 2014 sec. 5.3), tabulated over cos(theta)
    and |cos(phi)| of the direction from X and interpolated bilinearly."""
    a = rough * rough
    at, ab = min(a * (1 + an), 1.0), max(a * (1 - an), min(a, 1e-3))
    y = (np.arange(ny) + 0.5) / ny
    t = np.sqrt(y / (1 - y))
    psi = (np.arange(npsi) + 0.5) / npsi * 2 * math.pi
    hx, hy = t[:, None] * at * np.cos(psi), t[:, None] * ab * np.sin(psi)
    inv = 1 / np.sqrt(hx * hx + hy * hy + 1)
    hx, hy, hz = hx * inv, hy * inv, inv

    def g1(x, y_, z):
        s2 = np.maximum(x * x + y_ * y_, 1e-300)
        alpha_o = np.sqrt((x * x * at * at + y_ * y_ * ab * ab) / s2)
        k = (np.sqrt(alpha_o) + 1) ** 2 / 8
        return z / (z * (1 - k) + k)
    mus, cs = np.linspace(1e-3, 1, nmu), np.linspace(0, 1, nc)
    tab = np.zeros((nmu, nc))
    for i, mu in enumerate(mus):
        for j, c in enumerate(cs):
            st = math.sqrt(1 - mu * mu)
            v = (st * c, st * math.sqrt(1 - c * c), mu)
            vh = v[0] * hx + v[1] * hy + v[2] * hz
            lx, ly, lz = 2 * vh * hx - v[0], 2 * vh * hy - v[1], 2 * vh * hz - v[2]
            ok = (lz > 0) & (vh > 0)
            w = g1(lx, ly, np.where(ok, lz, 1.0)) * g1(v[0], v[1], mu) * vh / (hz * mu)
            tab[i, j] = np.where(ok, w, 0.0).mean()

    def rho(u):
        z = np.clip(u[..., 2], mus[0], 1.0)
        c = np.clip(np.abs(u[..., 0]) / np.sqrt(np.maximum(1 - u[..., 2] ** 2, 1e-12)), 0, 1)
        p, q = (z - mus[0]) / (mus[1] - mus[0]), c * (nc - 1)
        i0, j0 = np.minimum(p.astype(int), nmu - 2), np.minimum(q.astype(int), nc - 2)
        fp, fq = p - i0, q - j0
        return ((1 - fp) * ((1 - fq) * tab[i0, j0] + fq * tab[i0, j0 + 1])
                + fp * ((1 - fq) * tab[i0 + 1, j0] + fq * tab[i0 + 1, j0 + 1]))
    return rho


def turned_albedo(rho, axis_deg: float):
    """The albedo of the lobe turned by -axis_deg about N: a tube along X then sees the lobe
    as a tube `axis_deg` from the stretch would (capsule_true_energy's capsule lies along X)."""
    ca, sa = math.cos(math.radians(axis_deg)), math.sin(math.radians(axis_deg))

    def turned(u):
        return rho(np.stack([ca * u[..., 0] - sa * u[..., 1], sa * u[..., 0] + ca * u[..., 1],
                             u[..., 2]], -1))
    return turned
