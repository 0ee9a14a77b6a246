"""The anisotropic environment BRDF table (matedit/ibl/anisotropy_lut.py): the shipped file
is what the generator computes, the table against a brute-force integral written here from
the papers (nothing from matedit.shading or the generator's quadrature), and the GLSL lookup
(anisotropy.glsl, anisotropicEnvironmentBRDF) against its numpy twin."""

from __future__ import annotations

import numpy as np
import pytest

from matedit.ibl import anisotropy_lut as alut
from matedit.shading import anisotropy
from tests.gpu_eval import gpu_eval_many
from tests.test_lobe_anisotropy import ref_albedo, ref_alphas


def test_shipped_table_is_what_the_generator_computes():
    """12 random cells recomputed (float32, bit for bit) and the anisotropy-0 slab all 0;
    the whole file: `python tools/anisotropy_lut.py --check` (~2 min)."""
    table = alut.anisotropy_lut()
    assert table.shape == alut.ANISOTROPY_LUT_SHAPE + (2,)
    assert np.all(table[:, :, 0] == 0.0)
    rng = np.random.default_rng(7)
    for _ in range(12):
        i, j, m = (int(rng.integers(n)) for n in np.take(alut.ANISOTROPY_LUT_SHAPE, (0, 1, 3)))
        k = int(rng.integers(1, alut.ANISOTROPY_LUT_SHAPE[2]))
        np.testing.assert_array_equal(alut.cell(i, j, k, m), table[i, j, k, m])


def test_glsl_constant_matches_the_table_shape():
    text = (alut.Path(__file__).resolve().parents[1] / "shaders" / "anisotropy.glsl").read_text()
    assert f"const int ANISOTROPY_LUT_NODES = {alut.ANISOTROPY_LUT_SHAPE[2]};" in text


@pytest.mark.parametrize("an", [0.3, 0.62, 0.9, 0.97])
def test_table_against_brute_force(an):
    """The interpolated change of the white metal's albedo (dA + dB, F0 = 1) at off-node
    points against the brute force's own difference E(an) - E(0) (ref_albedo, 2^17
    importance samples, the same seed for both: their noise largely cancels, ~1e-3 left).
    Tolerance 6e-3 (interpolation, worst measured 3.5e-3 over these points)."""
    rng = np.random.default_rng(int(an * 100))
    table = alut.anisotropy_lut()
    worst = 0.0
    for _ in range(6):
        nov, rough, phi = rng.uniform(0.15, 1.0), rng.uniform(0.1, 0.95), rng.uniform(0, 2 * np.pi)
        s = np.sqrt(1 - nov * nov)
        v = np.array([s * np.cos(phi), s * np.sin(phi), nov])
        brute = ref_albedo(v, *ref_alphas(rough, an), n=1 << 17) - \
            ref_albedo(v, *ref_alphas(rough, 0.0), n=1 << 17)
        got = anisotropy.anisotropicEnvironmentBRDF(table, nov, rough, an, np.cos(phi) ** 2)
        worst = max(worst, abs(got.sum() - brute))
    print(f"anisotropy {an}: worst |table - brute| {worst:.4f}")
    assert worst <= 6e-3, worst


def test_lookup_gpu_equals_twin(ctx):
    """The GLSL lookup (3D texture, linear filtering) against the twin's arithmetic on the
    same table: 2e-5 absolute (GL's filtering weights)."""
    rng = np.random.default_rng(3)
    n = 4096
    inputs = {"NoV": rng.uniform(0, 1, n), "r": rng.uniform(0, 1, n),
              "an": rng.uniform(-0.1, 1.1, n), "c2": rng.uniform(-0.05, 1.05, n)}
    inputs["an"][:64] = 0.0
    tex = alut.upload_anisotropy_lut(ctx)
    try:
        got = gpu_eval_many(
            ctx, "d = anisotropicEnvironmentBRDF(uAnisotropyLut, NoV, r, an, c2);", inputs,
            {"d": "vec2"}, includes=["anisotropy.glsl"],
            preamble="uniform highp sampler3D uAnisotropyLut;",
            textures={"uAnisotropyLut": tex})["d"]
    finally:
        tex.release()
    want = anisotropy.anisotropicEnvironmentBRDF(alut.anisotropy_lut(), inputs["NoV"],
                                                 inputs["r"], inputs["an"], inputs["c2"])
    # the twin returns 0 at anisotropy <= 0, as surface.glsl only adds it above 0
    keep = inputs["an"] > 0
    np.testing.assert_allclose(got[keep], want[keep], rtol=0, atol=2e-5)
    assert np.all(got[:64] == 0.0)
