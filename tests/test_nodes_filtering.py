"""Band-limited patterns: at a distance, a filtered pattern is close to the supersampled
truth, where the unfiltered one aliases; and the numpy twin with a footprint (a pixel grid)
gives the same filtered image as the GPU, so thumbnails match the viewport.

The scene is a ground plane seen at a grazing angle from 1 m up: each pixel's UV comes from
intersecting its ray with the plane (float64). The reference averages the hard-edged pattern
over 8 x 8 sub-pixel rays; the GPU filters with fwidth of the UVs it is given.
"""

from __future__ import annotations

import numpy as np
import pytest

from matedit.compiler.cpu_nodes import IMPLS, SurfaceArrays
from matedit.graph.nodes import REGISTRY
from tests.gpu_eval import gpu_eval_many

W, H = 256, 64  # gpu_eval lays 256 elements a row: the same quads as this image
SUB = 8


def _plane_uv(px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """UV (world x, z) where the ray through pixel position (px, py) meets y = 0; the eye
    is 1 m up, pitched 22 degrees down, 36 degree vertical and 40 degree horizontal field
    of view."""
    fov, pitch = np.radians(36.0), np.radians(-22.0)
    t = np.tan(fov / 2)
    sx = (2 * px / W - 1) * np.tan(np.radians(20.0))
    sy = (2 * py / H - 1) * t
    dy = np.sin(pitch) + sy * np.cos(pitch)
    dz = np.cos(pitch) - sy * np.sin(pitch)
    d = 1.0 / -dy  # distance along the ray to the plane (dy < 0 everywhere here)
    return np.stack([sx * d, dz * d], -1)


def _pixel_uvs() -> np.ndarray:
    y, x = np.mgrid[0:H, 0:W] + 0.5
    return _plane_uv(x.ravel(), y.ravel())


def _supersampled(hard) -> np.ndarray:
    y, x = np.mgrid[0:H, 0:W]
    acc = np.zeros(W * H)
    for j in range(SUB):
        for i in range(SUB):
            acc += hard(_plane_uv(x.ravel() + (i + 0.5) / SUB, y.ravel() + (j + 0.5) / SUB))
    return acc / SUB**2


def _hard_bricks(uv):
    p = uv * [3.0, 6.0]
    row = np.floor(p[:, 1])
    p[:, 0] += 0.5 * row
    f = p - np.floor(p)
    e = np.minimum(np.minimum(f, 1 - f)[:, 0] / 3.0, np.minimum(f, 1 - f)[:, 1] / 6.0)
    return (e >= 0.02).astype(float)


PATTERNS = {
    # kind: (inputs after uv, output index, hard-edged numpy reference of uv)
    "checker": ([6.0, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], 1,
                lambda uv: (np.floor(6 * uv[:, 0]) + np.floor(6 * uv[:, 1])) % 2),
    "stripes": ([5.0, 0.5, 30.0], 0,
                lambda uv: (((uv @ [np.cos(np.radians(30)), np.sin(np.radians(30))]) * 5) % 1
                            < 0.5).astype(float)),
    "bricks": ([[3.0, 6.0], 0.04, 0.01, 0.5, 0.0], 0, _hard_bricks),
}


FAR_BOUNDS = {"checker": (0.09, 0.3), "stripes": (0.09, 0.3), "bricks": (0.14, 0.4)}


def _filtered(ctx, kind, uv, filter_width):
    d = REGISTRY[kind]
    extra, out_index, _ = PATTERNS[kind]
    n = len(uv)
    args = {"uv": np.asarray(uv, np.float32)}
    for spec, v in zip(d.inputs[1:], extra + [filter_width]):
        a = np.asarray(v, np.float32)
        args[spec.name] = np.broadcast_to(a, (n,) + a.shape).copy()
    inputs = {f"i_{k}": v for k, v in args.items()}
    outputs = {f"o_{o.name}": o.type for o in d.outputs}
    call = f"{d.glsl}({', '.join([*inputs, *outputs])});"
    gpu = gpu_eval_many(ctx, call, inputs, outputs, includes=[f"nodes/{kind}.glsl"])
    ctx_np = SurfaceArrays(args["uv"], np.zeros((n, 3), np.float32),
                           np.zeros((n, 3), np.float32), np.zeros((n, 3), np.float32),
                           grid=(H, W))
    cpu = IMPLS[kind](ctx_np, *args.values())
    return list(gpu.values())[out_index], cpu[out_index]


@pytest.mark.gl
@pytest.mark.parametrize("kind", sorted(PATTERNS))
def test_filtered_pattern_at_a_distance_matches_the_supersampled_reference(ctx, kind):
    uv = _pixel_uvs()
    reference = _supersampled(PATTERNS[kind][2])
    filtered, filtered_cpu = _filtered(ctx, kind, uv, 1.0)
    hard, _ = _filtered(ctx, kind, uv, 0.0)
    far = np.repeat(np.arange(H) >= H // 2, W)  # the upper half of the image: the distance
    near = np.repeat(np.arange(H) < H // 8, W)
    err_filtered = np.abs(filtered - reference)
    err_hard = np.abs(hard - reference)
    # Mean |error| far away, measured (llvmpipe), filtered against unfiltered: checker
    # 0.058 against 0.36, stripes 0.030 against 0.30, bricks 0.108 against 0.33; over the
    # whole image 0.035 / 0.21, 0.021 / 0.17, 0.066 / 0.21. A box of fwidth is wider than
    # the pixel where the mapping shears, the reference is a pixel box, and the bricks'
    # mask is filtered as a product of two pulse trains (rows shift the joints), so the
    # error is not zero.
    far_bound, far_ratio = FAR_BOUNDS[kind]
    assert err_filtered[far].mean() < far_bound, err_filtered[far].mean()
    assert err_filtered[far].mean() < far_ratio * err_hard[far].mean()
    assert err_filtered.mean() < 0.5 * err_hard.mean()
    # Near the camera (cells several pixels wide) filtering changes only the edge pixels
    # (measured: 83%, 84% and 73% of the nearest eighth unchanged).
    assert np.mean(np.abs(filtered - hard)[near] < 0.01) > 0.6
    # The numpy twin given the same footprint (pixel grid) gives the GPU's filtered image.
    np.testing.assert_allclose(filtered_cpu, filtered, atol=1e-4)


def test_no_footprint_means_hard_edges():
    uv = np.random.default_rng(1).uniform(-3, 3, (500, 2))
    n = len(uv)
    s = SurfaceArrays(uv, np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)))
    ones = np.ones(n)
    _, mask = IMPLS["checker"](s, uv, 4 * ones, np.zeros((n, 3)), np.ones((n, 3)), ones)
    np.testing.assert_array_equal(mask, (np.floor(4 * uv[:, 0]) + np.floor(4 * uv[:, 1])) % 2)


def test_derivatives_are_quad_differences_even_on_odd_grids():
    from matedit.nodes.twin import derivatives, fwidth

    h, w = 5, 7
    y, x = np.mgrid[0:h, 0:w].astype(float)
    s = SurfaceArrays(np.zeros((h * w, 2)), np.zeros((h * w, 3)), np.zeros((h * w, 3)),
                      np.zeros((h * w, 3)), grid=(h, w))
    ramp = (3.0 * x - 2.0 * y).ravel()
    dx, dy = derivatives(s, ramp)
    np.testing.assert_array_equal(dx, 3.0)  # a linear ramp: its slope everywhere
    np.testing.assert_array_equal(dy, -2.0)
    np.testing.assert_array_equal(fwidth(s, ramp), 5.0)
    sq = (x * x).ravel()
    dx, _ = derivatives(s, sq)
    # pairs (0,1), (2,3), (4,5): both pixels of a pair get the pair's difference; the odd
    # last column pairs backwards with column 5
    np.testing.assert_array_equal(dx.reshape(h, w)[0], [1, 1, 5, 5, 9, 9, 11])
    flat = SurfaceArrays(s.uv, s.position, s.normal, s.view)  # scattered points
    assert not fwidth(flat, ramp).any()
