"""Environment importance sampling for the reference mode (matedit/ibl/importance.py,
shaders/env_sampling.glsl) and the MIS estimator (ibl.glsl, referenceEnvironmentIBL),
against independent numpy references (tests/env_reference.py: no matedit.shading).

Environments: the built-in studio, and a generated sun and sky (a 0.5-degree sun 3e4 times
the horizon sky), each resampled to a 128^2 cube by the IBL baker (the real GL path) and
read with NEAREST filtering, so that the brute-force quadrature over the texels is exactly
the integral the GPU estimates. The estimator runs as the renderer runs it: frames of 32
samples, each frame's set rotated by the R2 offset of its index, averaged (each frame is
one element of one draw here). llvmpipe caps a shader's loop iterations (65535, inner
loops included), so one call of thousands of samples would be cut short: frames are also
what keeps the test honest on it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from env_reference import CubeQuadrature, sun_sky
from gpu_eval import gpu_eval_many

from matedit.ibl.builtin import builtin_environment
from matedit.ibl.cubemap import face_directions, sample_equirect, texel_solid_angles
from matedit.ibl.importance import (
    build_distribution,
    distribution_from_cube,
    table_size,
)

LUM = np.array([0.2126, 0.7152, 0.0722])
CUBE = 128


def _r2(frame: int) -> tuple[float, float]:
    """The renderer's per-frame offset (matedit.render.frames.r2_offset), restated."""
    g = 1.32471795724474602596
    return ((0.5 + frame / g) % 1.0, (0.5 + frame / (g * g)) % 1.0)


def _uv(d):
    """Equirect (u, v) of unit directions, the convention of matedit/ibl/cubemap.py."""
    u = 0.5 + np.arctan2(d[..., 0], -d[..., 2]) / (2 * np.pi)
    v = np.arccos(np.clip(d[..., 1], -1, 1)) / np.pi
    return u, v


# --- the table (numpy) -----------------------------------------------------------------


@pytest.fixture(scope="module")
def sun_faces_numpy():
    """Sun and sky as a 64^2 cube resampled on the CPU (bilinear), for the numpy tests."""
    return sample_equirect(sun_sky(1024), face_directions(64)).astype(np.float32)


def test_table_layout_and_cdfs(sun_faces_numpy):
    dist = distribution_from_cube(sun_faces_numpy)
    t = dist.table
    w, h = table_size(64)
    assert t.shape == (h, w + 1, 2) == (128, 257, 2) and t.dtype == np.float32
    cond, marg = t[:, :w, 0], t[:, w, 0]
    assert np.all(np.diff(cond, axis=1) >= 0) and np.all(cond[:, -1] == 1.0)
    assert np.all(np.diff(marg) >= 0) and marg[-1] == 1.0
    # densities over the unit square average to 1, and a row's conditional CDF steps are its
    # pixels' densities over the row's
    assert abs(dist.density.mean() - 1.0) < 1e-5
    row = int(np.argmax(t[:, w, 1]))  # the sun's row
    steps = np.diff(np.concatenate([[0.0], cond[row]]))
    np.testing.assert_allclose(steps, dist.density[row] / dist.density[row].sum(), atol=1e-6)
    # the sun's pixels carry the largest density, by orders of magnitude
    assert dist.density.max() > 1e3 * np.median(dist.density)


def test_black_environment_is_uniform_over_the_sphere():
    t = build_distribution(np.zeros((8, 16))).table
    theta = np.pi * (np.arange(8) + 0.5) / 8
    # p(u, v) proportional to sin(theta): p / (2 pi^2 sin(theta)) is 1 / (4 pi) at row centres
    p = t[:, :16, 1] / (2 * np.pi**2 * np.sin(theta)[:, None])
    # (the midpoint sum of sin(theta) stands for its integral 2 / pi: a factor near 1)
    np.testing.assert_allclose(p, 1 / (4 * np.pi) * (2 / np.pi / np.mean(np.sin(theta))),
                               rtol=1e-6)


def test_pdf_integrates_to_one_over_the_sphere(sun_faces_numpy):
    """Sum of pdf x solid angle over the texels of a fine cube (a parameterisation unrelated
    to the equirect's): exact but for texels straddling the table's pixel edges, whose share
    is about a texel's width over a pixel's (0.2 / 0.7 degrees) of the sun's few pixels'
    mass, and cancels on average; stated tolerance 2e-3."""
    from matedit.shading.env_sampling import environmentPdf

    table = distribution_from_cube(sun_faces_numpy).table
    n = 512
    d = face_directions(n).reshape(-1, 3)
    omega = np.broadcast_to(texel_solid_angles(n), (6, n, n)).reshape(-1)
    total = float(np.sum(environmentPdf(table, d) * omega))
    assert abs(total - 1.0) < 2e-3, total
    # and the same for the studio's table
    studio = sample_equirect(builtin_environment("studio", 512), face_directions(64))
    total = float(np.sum(environmentPdf(distribution_from_cube(studio).table, d) * omega))
    assert abs(total - 1.0) < 2e-3, total


def _chi_square(counts, expected, min_expected=20.0):
    """(statistic, degrees of freedom), bins with fewer expected counts pooled into one."""
    small = expected < min_expected
    obs = np.append(counts[~small], counts[small].sum())
    exp = np.append(expected[~small], expected[small].sum())
    keep = exp > 0
    return float(np.sum((obs[keep] - exp[keep]) ** 2 / exp[keep])), int(keep.sum() - 1)


def _pixel_histogram(dirs, w, h):
    u, v = _uv(dirs)
    i = np.clip((u * w).astype(int), 0, w - 1)
    j = np.clip((v * h).astype(int), 0, h - 1)
    return np.bincount(j * w + i, minlength=w * h).astype(float)


def _check_histogram(dirs, table, min_dof=100):
    """Sampled directions land in each table pixel as often as its probability says: a
    chi-square statistic within 5 standard deviations of its mean (chance of a false alarm
    < 1e-6); the directions are binned by an equirect mapping written here."""
    h, w = table.shape[0], table.shape[1] - 1
    counts = _pixel_histogram(dirs, w, h)
    expected = len(dirs) * table[:, :w, 1].astype(np.float64).reshape(-1) / (w * h)
    stat, dof = _chi_square(counts, expected)
    assert dof >= min_dof, dof
    assert stat < dof + 5 * math.sqrt(2 * dof), (stat, dof)
    return stat, dof


def test_samples_follow_the_table_numpy(sun_faces_numpy):
    from matedit.shading.env_sampling import sampleEnvironmentDirection

    u = np.random.default_rng(7).uniform(0, 1, (400_000, 2)).astype(np.float32)
    # the studio spreads its light: thousands of pixels get enough samples to test
    studio = sample_equirect(builtin_environment("studio", 512), face_directions(64))
    table = distribution_from_cube(studio).table
    dirs, _ = sampleEnvironmentDirection(table, u)
    _check_histogram(dirs, table, min_dof=1000)
    # the sun takes nearly all the samples: its pixels, and the pooled rest, are tested
    table = distribution_from_cube(sun_faces_numpy).table
    dirs, _ = sampleEnvironmentDirection(table, u)
    _check_histogram(dirs, table, min_dof=8)
    # a wrong table fails the same check: the sun's row swapped with its neighbour
    wrong = table.copy()
    row = int(np.argmax(table[:, -1, 1]))
    wrong[[row, row + 1], :-1, 1] = wrong[[row + 1, row], :-1, 1]
    with pytest.raises(AssertionError):
        _check_histogram(dirs, wrong, min_dof=8)


def _distribution_texture(ctx, table):
    tex = ctx.texture((table.shape[1], table.shape[0]), 2,
                      np.ascontiguousarray(table, np.float32).tobytes(), dtype="f4")
    tex.filter = (ctx.NEAREST, ctx.NEAREST)
    return tex


@pytest.mark.gl
def test_samples_follow_the_table_gpu(ctx):
    studio = sample_equirect(builtin_environment("studio", 512), face_directions(64))
    table = distribution_from_cube(studio).table
    u = np.random.default_rng(8).uniform(0, 1, (200_000, 2)).astype(np.float32)
    tex = _distribution_texture(ctx, table)
    try:
        out = gpu_eval_many(ctx, "d = sampleEnvironmentDirection(dist, u, p);", {"u": u},
                            {"d": "vec3", "p": "float"}, includes=["env_sampling.glsl"],
                            preamble="uniform sampler2D dist;", textures={"dist": tex})
    finally:
        tex.release()
    d = out["d"].astype(np.float64)
    _check_histogram(d, table, min_dof=1000)
    # the pdf returned is the table's density over the Jacobian 2 pi^2 sin(theta)
    u_, v_ = _uv(d / np.linalg.norm(d, axis=1, keepdims=True))
    h, w = table.shape[0], table.shape[1] - 1
    i = np.clip((u_ * w).astype(int), 0, w - 1)
    j = np.clip((v_ * h).astype(int), 0, h - 1)
    expect = table[j, i, 1] / (2 * np.pi**2 * np.sin(np.pi * v_))
    inside = np.abs(np.sin(np.pi * v_)) > 1e-3  # away from the poles' float32 noise
    close = np.isclose(out["p"][inside], expect[inside], rtol=1e-3)
    assert close.mean() > 0.999, close.mean()  # but samples on a pixel's edge


def test_table_build_is_cheap():
    """The table of a 256^2 cube (the default bake) builds in well under a second: no cache."""
    import time

    faces = np.random.default_rng(0).uniform(0, 1, (6, 256, 256, 3)).astype(np.float32)
    start = time.perf_counter()
    dist = distribution_from_cube(faces)
    elapsed = time.perf_counter() - start
    assert dist.table.shape == (256, 513, 2)
    assert elapsed < 1.0, elapsed


# --- the estimator on the GPU against the brute force ----------------------------------

BODY = """
    ReferenceSurface s = makeReferenceSurface(N, V, dc, F0, r, vec3(1.0));
    mis = referenceEnvironmentIBL(env, dist, s, 32u, off);
    brdf = referenceIBL(env, dc, F0, r, N, V, 32u, off);
"""


class GpuEnvironment:
    """A cube (NEAREST) and its sampling table as the renderer uploads it."""

    def __init__(self, ctx, equirect):
        from matedit.ibl.gpu import Baker
        from matedit.render.environment import upload_distribution

        baker = Baker(ctx)
        try:
            self.faces = baker.equirect_to_cube(equirect, CUBE).astype(np.float32)
        finally:
            baker.close()
        self.cube = ctx.texture_cube((CUBE, CUBE), 3, dtype="f4")
        for f in range(6):
            self.cube.write(f, np.ascontiguousarray(self.faces[f]).tobytes())
        self.cube.filter = (ctx.NEAREST, ctx.NEAREST)
        self.dist = upload_distribution(ctx, self.faces)
        self.quadrature = CubeQuadrature(self.faces)

    def estimate(self, ctx, cases, frames):
        """(mis, brdf-only) estimates (len(cases), 3), `frames` x 32 samples each."""
        n = len(cases)
        rep = {k: np.repeat(np.array([c[k] for c in cases], np.float64), frames, axis=0)
               for k in ("N", "V", "dc", "F0", "r")}
        rep["off"] = np.tile(np.array([_r2(f) for f in range(frames)]), (n, 1))
        out = gpu_eval_many(ctx, BODY, rep, {"mis": "vec3", "brdf": "vec3"},
                            includes=["ibl.glsl"],
                            preamble="uniform samplerCube env; uniform sampler2D dist;",
                            textures={"env": self.cube, "dist": self.dist})
        return (out["mis"].reshape(n, frames, 3).mean(axis=1),
                out["brdf"].reshape(n, frames, 3).mean(axis=1))

    def truth(self, cases):
        return np.array([self.quadrature.integrate(c["N"], c["V"], c["dc"], c["F0"], c["r"])
                         for c in cases])

    def release(self):
        self.cube.release()
        self.dist.release()


def _unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def _case(rough, metal, nov, N, sun_highlight=False):
    """A surface: base colour (0.8, 0.5, 0.3) (F0 0.04 dielectric, else the base colour),
    V at angle acos(nov) from N; `sun_highlight`: N halfway between V and the sun, so the
    mirror direction is the sun's."""
    from env_reference import SUN_DIRECTION

    base = np.array([0.8, 0.5, 0.3])
    N = _unit(N)
    t = _unit(np.cross(N, [0.3, 0.2, 0.9]))
    V = _unit(nov * N + math.sqrt(1 - nov * nov) * t)
    if sun_highlight:
        N = _unit(SUN_DIRECTION + V)
    return {"N": N, "V": V, "dc": base * (1 - metal), "F0": 0.04 * (1 - metal) + base * metal,
            "r": rough}


CASES = [
    _case(0.05, 1.0, 0.9, [0.2, 0.9, 0.3]),
    _case(0.05, 0.0, 0.5, [0.5, 0.5, 0.7]),
    _case(0.05, 1.0, 0.8, [0.0, 0.0, 1.0], sun_highlight=True),
    _case(0.3, 1.0, 0.7, [0.4, 0.6, 0.7]),
    _case(0.3, 0.0, 0.6, [0.4, 0.6, 0.7], sun_highlight=True),
    _case(0.6, 0.5, 0.4, [-0.3, 0.5, 0.8]),
    _case(0.9, 0.0, 0.8, [0.35, 0.64, 0.68]),
    _case(0.9, 1.0, 0.3, [0.1, 0.2, 1.0]),
]


@pytest.fixture(scope="module")
def environments(gl_ctx):
    envs = {"studio": GpuEnvironment(gl_ctx, builtin_environment("studio", 1024)),
            "sun": GpuEnvironment(gl_ctx, sun_sky(2048))}
    yield envs
    for e in envs.values():
        e.release()


@pytest.mark.gl
@pytest.mark.parametrize("env_name", ["studio", "sun"])
def test_reference_converges_to_the_brute_force(ctx, environments, env_name):
    env = environments[env_name]
    truth = env.truth(CASES)
    mis, _ = env.estimate(ctx, CASES, frames=128)  # 4,096 samples
    rel = np.abs(mis - truth) @ LUM / (truth @ LUM)
    print(f"\n{env_name}: relative error at 4096 samples", np.round(rel, 5))
    # measured max 0.0046 (studio) and 0.012 (sun, the 0.3 dielectric reflecting the sun);
    # the quadrature's own error is < 1e-4 (doubling its splits moves it by < 1e-5)
    assert rel.max() < 0.03, rel


@pytest.mark.gl
def test_no_fireflies_under_the_sun(ctx, environments):
    """Per-pixel error of a sphere's pixels (orthographic, V = +Z) at 2,048 samples, the
    default of `matedit render --samples`: MIS against BRDF sampling alone."""
    env = environments["sun"]
    c = (np.arange(10) + 0.5) / 10 * 2 - 1
    x, y = np.meshgrid(c, c)
    inside = x * x + y * y < 0.95
    N = np.stack([x[inside], y[inside], np.sqrt(1 - x[inside] ** 2 - y[inside] ** 2)], -1)
    cases = [{"N": n, "V": np.array([0.0, 0.0, 1.0]), "dc": np.array([0.5, 0.1, 0.1]),
              "F0": np.full(3, 0.04), "r": 0.6} for n in N]
    truth = env.truth(cases)
    mis, brdf = env.estimate(ctx, cases, frames=64)
    rel_mis = np.abs(mis - truth) @ LUM / (truth @ LUM)
    rel_brdf = np.abs(brdf - truth) @ LUM / (truth @ LUM)
    print(f"\nMIS max {rel_mis.max():.4f} p95 {np.percentile(rel_mis, 95):.4f}; "
          f"BRDF only max {rel_brdf.max():.4f} p95 {np.percentile(rel_brdf, 95):.4f}")
    # measured MIS max 0.019, p95 0.018 (the environment samples are shared by all pixels,
    # so their error is too); BRDF sampling alone misses or over-counts the sun: max 8.1
    assert rel_mis.max() < 0.04, rel_mis.max()
    assert np.percentile(rel_mis, 95) < 0.03
    assert rel_brdf.max() > 10 * rel_mis.max()
