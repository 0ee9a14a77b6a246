"""Physical properties of the shading layer (docs/shading.md#what-the-tests-hold), in numpy."""

from __future__ import annotations

import numpy as np
import pytest

from matedit.shading import brdf, ibl, lights
from matedit.shading.common import normalize
from matedit.shading.lights import Light


@pytest.mark.parametrize("roughness", [0.03, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.85, 1.0])
def test_ggx_is_normalised_over_the_hemisphere(roughness):
    # 2 pi * integral of D(cos t) cos t sin t dt; the grid crowds t = 0 (t = s^3 pi/2) to
    # resolve the narrow peak at roughness 0.03. Quadrature error is below 1e-4.
    s = np.linspace(0.0, 1.0, 400_001)
    t = 0.5 * np.pi * s**3
    f = brdf.D_GGX(np.cos(t), roughness**2) * np.cos(t) * np.sin(t)
    assert 2.0 * np.pi * np.trapezoid(f, t) == pytest.approx(1.0, abs=1e-4)


def test_fresnel_at_normal_incidence_is_f0():
    F0 = np.random.default_rng(1).uniform(0, 1, (100, 3))
    np.testing.assert_array_equal(brdf.F_SchlickExact(F0, np.ones(100)), F0)
    # The spherical Gaussian leaves 2^-12.54 = 1.7e-4 of (1 - F0) at VoH = 1.
    np.testing.assert_allclose(brdf.F_Schlick(F0, np.ones(100)), F0, atol=2e-4)


def test_spherical_gaussian_fresnel_follows_the_fifth_power():
    VoH = np.linspace(0.0, 1.0, 100_001)
    gap = np.abs(brdf.Fc_SphericalGaussian(VoH) - brdf.Fc_Exact(VoH))
    assert gap.max() < 4e-3


def _context(rng, n=2000, rough=None):
    N = normalize(rng.normal(size=(n, 3)))
    V = normalize(N + rng.normal(size=(n, 3)) * 0.6)
    V = np.where((np.sum(N * V, -1) > 0.05)[:, None], V, N)
    r = rng.uniform(0.03, 1.0, n) if rough is None else np.full(n, rough)
    return lights.makeShadingContext(
        rng.uniform(-1, 1, (n, 3)), N, V, rng.uniform(0, 1, (n, 3)), rng.uniform(0.02, 1, (n, 3)), r
    )


def _light(kind, **kw):
    base = dict(position=(0.3, 2.0, 1.5), direction=normalize(np.array([1.0, 0.2, -0.3])),
                color=(1.0, 0.8, 0.6), intensity=40.0, influence_radius=12.0)  # fmt: skip
    return Light(kind=kind, **{**base, **kw})


def _relative_gap(x, ref):
    return np.max(np.abs(x - ref) / (np.abs(ref) + 1e-6 * np.abs(ref).max()))


# The gap is first order in the size: the highlight moves by ~size / d against a lobe of
# width a = 9e-4 at roughness 0.03, so gap <= C * size with C ~ 2e2..4e2 here; 1e3 bounds it.
CONVERGENCE = 1e3


def test_sphere_light_converges_to_point_light():
    s = _context(np.random.default_rng(2))
    point = lights.pointLight(s, _light("point"))
    for radius in (1e-4, 1e-6, 1e-8):
        sphere = lights.sphereLight(s, _light("sphere", source_radius=radius))
        assert _relative_gap(sphere, point) <= CONVERGENCE * radius
    np.testing.assert_allclose(lights.sphereLight(s, _light("sphere")), point, rtol=1e-12)


def test_tube_light_converges_to_sphere_light():
    s = _context(np.random.default_rng(3))
    sphere = lights.sphereLight(s, _light("sphere", source_radius=0.05))
    for length in (1e-4, 1e-6, 1e-8):
        tube = lights.tubeLight(s, _light("tube", source_radius=0.05, source_length=length))
        assert _relative_gap(tube, sphere) <= CONVERGENCE * length
    np.testing.assert_allclose(lights.tubeLight(s, _light("tube", source_radius=0.05)), sphere,
                               rtol=1e-10)  # fmt: skip


def test_falloff_is_zero_at_and_beyond_the_influence_radius():
    R = np.array([0.5, 1.0, 7.0, 100.0])
    for factor in (1.0, 1.0 + 1e-9, 1.5, 10.0):
        assert np.all(lights.distanceFalloff(R * factor, R) == 0.0)
    assert np.all(lights.distanceFalloff(R * 0.999, R) > 0.0)
    # Near the light the falloff is inverse-square, softened by eps = 1 cm.
    assert lights.distanceFalloff(0.0, 10.0) == pytest.approx(1e4)
    assert lights.distanceFalloff(0.1, 1e6) == pytest.approx(1.0 / (0.01 + 1e-4))


def test_lights_beyond_their_radius_contribute_nothing():
    s = _context(np.random.default_rng(4))
    for kind in ("point", "sphere", "tube"):
        far = _light(kind, position=(50.0, 0.0, 0.0), influence_radius=10.0,
                     source_radius=0.2, source_length=1.0)  # fmt: skip
        assert np.all(lights.evaluateLight(s, far) == 0.0)


def _analytic_env(d):
    """A smooth sky: bright above, a warm lobe towards +x, dim below."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([1.0 + 0.8 * z + 1.5 * np.maximum(x, 0) ** 3, 0.9 + 0.6 * z + 0.2 * y,
                     0.7 + 0.9 * z * z], -1)  # fmt: skip


def _brute_force(N, V, dc, F0, roughness, n=400):
    """Midpoint quadrature over the hemisphere of the split-free integral with k = a/2."""
    T = normalize(np.cross([0.3, 0.5, 0.8], N))
    B = np.cross(N, T)
    theta = (np.arange(n) + 0.5) * (0.5 * np.pi / n)
    phi = (np.arange(4 * n) + 0.5) * (0.5 * np.pi / n)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    local = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    L = local[..., :1] * T + local[..., 1:2] * B + local[..., 2:] * N
    H = normalize(L + V)
    NoL, NoV = local[..., 2], float(np.dot(N, V))
    NoH, VoH = np.sum(N * H, -1), np.sum(V * H, -1)
    a = roughness**2
    k = brdf.k_IBL(a)
    spec = (brdf.D_GGX(NoH, a) * brdf.V_SchlickSmith(NoV, NoL, k))[..., None] * \
        brdf.F_SchlickExact(F0, VoH)  # fmt: skip
    f = spec + brdf.diffuseLobe(dc)
    w = (np.sin(t) * NoL)[..., None] * (0.5 * np.pi / n) ** 2
    return np.sum(_analytic_env(L) * f * w, axis=(0, 1))


@pytest.mark.parametrize("roughness,nov", [(0.4, 0.9), (0.6, 0.3), (0.9, 0.6)])
def test_reference_estimator_converges_to_quadrature(roughness, nov):
    N = normalize(np.array([0.2, -0.3, 1.0]))
    T = normalize(np.cross([1.0, 0.0, 0.0], N))
    V = nov * N + np.sqrt(1 - nov**2) * T
    dc, F0 = np.array([0.5, 0.3, 0.2]), np.array([0.9, 0.6, 0.3])
    exact = _brute_force(N, V, dc, F0, roughness)
    coarse = ibl.referenceIBL(_analytic_env, dc, F0, roughness, N, V, 1 << 6, (0.3, 0.7))
    estimate = ibl.referenceIBL(_analytic_env, dc, F0, roughness, N, V, 1 << 14, (0.3, 0.7))
    # The quadrature (400 x 1600 midpoints) is good to ~2e-6; 16,384 rotated Hammersley
    # samples of this smooth integrand land within ~3e-5: 2e-4 leaves margin.
    np.testing.assert_allclose(estimate, exact, rtol=2e-4)
    assert np.abs(estimate - exact).max() < np.abs(coarse - exact).max()


def test_sh_irradiance_of_a_constant_environment_is_pi_times_radiance():
    sh = ibl.sh9_project(lambda d: np.broadcast_to([0.5, 1.0, 2.0], d.shape), n=256)
    N = normalize(np.random.default_rng(5).normal(size=(50, 3)))
    # Ramamoorthi-Hanrahan constants have 6 digits; E = c4 * L00 = pi * L to ~1e-5.
    want = np.broadcast_to(np.pi * np.array([0.5, 1.0, 2.0]), (50, 3))
    np.testing.assert_allclose(ibl.irradianceSH9(sh, N), want, rtol=1e-4)


def test_lights_block_packs_the_documented_std140_layout():
    from matedit.shading.lights_block import LIGHTS_BLOCK_SIZE, pack_lights, unpack_lights

    scene = [_light("tube", source_radius=0.1, source_length=2.0), _light("directional")]
    data = pack_lights(scene)
    assert len(data) == LIGHTS_BLOCK_SIZE == 1040
    assert np.frombuffer(data, "<i4", 1)[0] == 2
    first = np.frombuffer(data, "<f4", 16, offset=16)
    np.testing.assert_allclose(first[[3, 7, 11, 12, 13]], [3, 40.0, 12.0, 0.1, 2.0], rtol=1e-6)
    back = unpack_lights(data)
    assert [b.kind for b in back] == ["tube", "directional"]
    with pytest.raises(ValueError):
        pack_lights([_light("point")] * 17)
