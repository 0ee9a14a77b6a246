"""Node thumbnails of MaterialAttributes are shaded by the numpy twin under a fixed rig.

The rig's closed forms are checked against independent integrations written here: the SH9
of the sky-over-ground environment against a midpoint quadrature of L(d) Y_lm(d), and the
analytic environment-BRDF fit against a brute-force integral of the split sum's A + B
(the notes' IntegrateBRDF) at a few points.
"""

from __future__ import annotations

import numpy as np
import pytest

from matedit.shading import thumbnail


def _sphere_grid(n: int = 200):
    theta = (np.arange(n) + 0.5) * np.pi / n
    phi = (np.arange(2 * n) + 0.5) * np.pi / n
    t, p = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    return d, np.sin(t) * (np.pi / n) ** 2


def test_environment_sh9_is_the_projection_of_its_radiance():
    d, w = _sphere_grid()
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    basis = [np.full_like(x, 0.5 / np.sqrt(np.pi)), np.sqrt(3 / (4 * np.pi)) * y,
             np.sqrt(3 / (4 * np.pi)) * z, np.sqrt(3 / (4 * np.pi)) * x]
    L = thumbnail.environment_radiance(d)
    got = thumbnail.environment_sh9()
    for k, Y in enumerate(basis):
        want = np.einsum("ij,ijc,ij->c", Y, L, w)
        # midpoint quadrature on a 200 x 400 grid: ~1e-5 of the coefficients
        np.testing.assert_allclose(got[k], want, atol=1e-4, err_msg=f"coefficient {k}")
    assert not np.any(got[4:])  # linear in y: no second-order terms


def _split_sum_ab(NoV: float, roughness: float, n: int = 400) -> tuple[float, float]:
    """A and B of the split sum by a midpoint quadrature over half vectors (GGX D, Smith
    with k = a / 2, exact Schlick weight), written from Karis 2013's IntegrateBRDF."""
    a = roughness * roughness
    V = np.array([np.sqrt(1 - NoV * NoV), 0.0, NoV])
    th = (np.arange(n) + 0.5) * (np.pi / 2) / n
    ph = (np.arange(2 * n) + 0.5) * np.pi / n
    t, p = np.meshgrid(th, ph, indexing="ij")
    H = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    dw = np.sin(t) * (np.pi / 2 / n) * (np.pi / n)
    VoH = H @ V
    L = 2 * VoH[..., None] * H - V
    NoL, NoH = L[..., 2], H[..., 2]
    D = a * a / (np.pi * ((NoH * NoH) * (a * a - 1) + 1) ** 2)
    k = a / 2
    G = NoL / (NoL * (1 - k) + k) * NoV / (NoV * (1 - k) + k)
    ok = (NoL > 0) & (VoH > 0)
    # f NoL dL = D G F / (4 NoV) dL, and dL = 4 VoH dH in the half-vector measure
    base = np.where(ok, D * G / (4 * NoV) * 4 * VoH, 0.0)
    Fc = (1 - np.clip(VoH, 0, 1)) ** 5
    A = np.sum(base * (1 - Fc) * dw)
    B = np.sum(base * Fc * dw)
    return A, B


@pytest.mark.parametrize("NoV,roughness", [(0.9, 0.3), (0.5, 0.5), (0.7, 0.8), (0.3, 0.6)])
def test_the_analytic_environment_brdf_fit_is_close_to_the_integral(NoV, roughness):
    A, B = _split_sum_ab(NoV, roughness)
    got = thumbnail.environment_brdf_fit(np.array(NoV), np.array(roughness))
    # A mobile fit, used for thumbnails only: measured here its worst error is 0.147 on A
    # (NoV 0.9, roughness 0.3: it darkens smooth dielectrics facing the eye by ~15%), 0.03
    # on B. The bound 0.16 keeps it from drifting; the viewport uses the real LUT.
    assert abs(got[0] - A) < 0.16 and abs(got[1] - B) < 0.04, (got, A, B)


def _sphere(size: int = 32):
    t = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(t, -t)
    inside = (x * x + y * y < 1).ravel()
    z = np.sqrt(np.clip(1 - x * x - y * y, 0, 1))
    N = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)[inside]
    T, B = thumbnail.preview_frame(N)
    return N, T, B, np.tile([0.0, 0.0, 1.0], (len(N), 1))


def _shade(**fields):
    N, T, B, V = _sphere()
    n = len(N)
    attrs = {k: np.broadcast_to(np.asarray(v, float), (n,) + np.shape(v)) for k, v in
             fields.items()}
    return thumbnail.shade_attributes(attrs, N, T, B, V)


def test_a_mirror_metal_thumbnail_reflects_the_sky_and_is_not_black():
    rgb = _shade(baseColor=[0.95, 0.95, 0.95], metallic=1.0, roughness=0.05)
    assert rgb.mean() > 0.25  # the environment, not only the two highlights
    assert np.all(np.isfinite(rgb))


def test_rougher_materials_have_a_lower_highlight_and_colour_shows():
    smooth = _shade(baseColor=[0.8, 0.1, 0.1], roughness=0.15)
    rough = _shade(baseColor=[0.8, 0.1, 0.1], roughness=0.9)
    assert smooth.max() > 2 * rough.max()
    assert rough[:, 0].mean() > 3 * rough[:, 2].mean()  # red reads red


def test_the_frame_is_orthonormal_with_the_tangent_along_u():
    N, T, B, _ = _sphere()
    np.testing.assert_allclose(np.sum(T * N, -1), 0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(T, axis=-1), 1, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(B, axis=-1), 1, atol=1e-12)
    front = np.argmax(N[:, 2])  # facing the viewer: u grows towards +X, v towards +Y
    np.testing.assert_allclose(T[front], [1, 0, 0], atol=0.1)
    np.testing.assert_allclose(B[front], [0, 1, 0], atol=0.1)
