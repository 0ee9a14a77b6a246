"""Order-2 SH irradiance against brute-force cosine convolution of the cube map."""

from __future__ import annotations

import numpy as np

from matedit.ibl.builtin import studio
from matedit.ibl.cubemap import face_directions, sample_equirect, texel_solid_angles
from matedit.ibl.sh import eval_irradiance, sh_basis, sh_irradiance


def brute_force_irradiance(faces: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """E(N) = sum over texels of L * max(0, N . w) * dOmega."""
    n = faces.shape[1]
    dirs = face_directions(n).reshape(-1, 3)
    omega = np.broadcast_to(texel_solid_angles(n), (6, n, n)).reshape(-1)
    cos = np.maximum(normals @ dirs.T, 0.0) * omega
    return cos @ faces.reshape(-1, 3).astype(np.float64)


def random_normals(count: int, seed: int = 3) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(count, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_texel_solid_angles_cover_the_sphere():
    assert abs(6 * texel_solid_angles(16).sum() - 4 * np.pi) < 1e-12


def test_basis_is_orthonormal_over_the_cube():
    n = 48
    basis = sh_basis(face_directions(n)).reshape(-1, 9)
    omega = np.broadcast_to(texel_solid_angles(n), (6, n, n)).reshape(-1)
    gram = basis.T @ (basis * omega[:, None])
    np.testing.assert_allclose(gram, np.eye(9), atol=2e-4)


def test_low_order_environment_irradiance_is_exact():
    # Radiance with only l <= 2 content: order-2 SH lose nothing, so SH irradiance equals
    # the cosine convolution up to the cube discretisation of the clamped cosine (~1e-3).
    n = 48
    d = face_directions(n)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    radiance = np.stack([1.0 + 0.5 * x, 1.0 + 0.3 * y * y - 0.2 * y * z, 0.8 + 0.4 * z * x], -1)
    normals = random_normals(64)
    sh = eval_irradiance(sh_irradiance(radiance), normals)
    ref = brute_force_irradiance(radiance, normals)
    np.testing.assert_allclose(sh, ref, rtol=2e-3)


def test_uniform_environment_irradiance_is_pi_times_radiance():
    faces = np.full((6, 8, 8, 3), 2.0)
    e = eval_irradiance(sh_irradiance(faces), random_normals(10))
    np.testing.assert_allclose(e, 2.0 * np.pi, rtol=1e-9)


def test_studio_irradiance_is_close_to_brute_force():
    # A real environment has l > 2 content that order 2 drops; Ramamoorthi and Hanrahan
    # bound the loss at a few percent. Measured here: ~3% of the brightest irradiance.
    n = 32
    faces = sample_equirect(studio(512), face_directions(n))
    normals = random_normals(200)
    sh = eval_irradiance(sh_irradiance(faces), normals)
    ref = brute_force_irradiance(faces, normals)
    err = np.abs(sh - ref).max() / ref.max()
    assert err < 0.06, f"{err:.3f}"
