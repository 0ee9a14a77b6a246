"""The node library (tests/library_kinds.py) on the GPU against its numpy twins, kind by kind.

Every fixed-type kind runs once on smooth input fields (so screen derivatives mean
something), once at large coordinates (UV and positions near 1,000) and once on a grazing
footprint (UVs stretched 40 times along x, as a plane seen edge-on). The GPU evaluates
float32, numpy float32 with the same operation order and the same fine 2 x 2 quad
derivatives (SurfaceArrays.grid): |gpu - numpy| <= rtol |numpy| + atol, 1e-5 each unless
a kind states why not. Outputs with jumps (a floor, a cell border, a nearest-point switch)
may differ where float32 rounding (fused multiply-adds) puts one point on the other side:
those allow a stated share of points past the bound. The generic kinds are checked in
tests/test_nodes_gpu.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from matedit.compiler.cpu_nodes import IMPLS, SurfaceArrays
from matedit.graph.nodes import GENERIC, MESH_UV, REGISTRY
from matedit.nodes import noise
from tests.gpu_eval import gpu_eval, gpu_eval_many
from tests.library_kinds import LIBRARY_KINDS

W, H = 256, 16
N = W * H
COMPS = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4}
# The library's kinds with fixed port types (the generic ones are checked by
# test_nodes_gpu.py's generic machinery), and the band-limited checker.
KINDS = sorted({k for k in LIBRARY_KINDS
                if not any(i.type == GENERIC for i in REGISTRY[k].inputs)} | {"checker"})
# Outputs with jumps: the share of points allowed past the bound (measured: none reach it).
JUMPY = {"saw": 0.01, "cell_id": 0.005, "tile_id": 0.005, "tile_uv": 0.005, "f2": 0.005,
         "edge": 0.005, "edges": 0.01, "mask": 0.01, "value": 0.0, "result": 0.0}
JUMPY_KINDS = {"wave", "rings", "cellular_noise", "cellular_noise_3d", "bricks", "stripes",
               "checker", "radial_gradient", "polar_coordinates", "hsv_adjust", "color_ramp",
               "filtered_step", "filtered_smoothstep", "cell_hash", "white_noise"}
TOLERANCE: dict[str, dict] = {
    # normal_from_height divides derivative differences by the UV Jacobian's determinant:
    # float32 rounding of the differences (~1e-7 of uv) grows by 1/|det| (~1e4 here).
    "normal_from_height": {"rtol": 0.0, "atol": 2e-3},
    # curvature: a ratio of products of differences of float32 normals and positions.
    "curvature": {"rtol": 1e-3, "atol": 1e-3},
    # pow (exp2 log2) and the sRGB curve: llvmpipe's pow is ~1e-6 relative, over [0, 4].
    "levels": {"rtol": 1e-5, "atol": 2e-5},
    "gamma": {"rtol": 2e-5, "atol": 1e-5},
    # sin/cos of angles in degrees up to 360, then products with coordinates up to 1,000.
    "rotate_uv": {"rtol": 2e-5, "atol": 1e-4},
    "stripes": {"rtol": 0.0, "atol": 2e-4},
    # world-to-view builds the camera basis from normalised matrix rows (float32 on the GPU,
    # float64 in numpy).
    "world_to_view": {"rtol": 1e-5, "atol": 1e-5},
    "view_to_world": {"rtol": 1e-5, "atol": 1e-5},
    "object_position": {"rtol": 1e-5, "atol": 1e-4},
    # wave, rings: the phase passes through distortion x fBm (up to 4 x) and a cosine of up
    # to 2 pi: ~1e-4 measured.
    "wave": {"rtol": 0.0, "atol": 1e-3},
    "rings": {"rtol": 0.0, "atol": 1e-3},
}
# At coordinates near 1,000 a float32 coordinate itself is only exact to 6e-5; kinds whose
# result moves fast with it get that error times their slope.
LARGE_TOLERANCE: dict[str, dict] = {
    # a band phase of up to 16,000 (1,000 x frequency) in float32 is exact to ~1e-3 of a
    # band, and the GPU may fuse the multiply-adds that make it: the sine profile moves by
    # up to 2 pi times that
    "wave": {"rtol": 0.0, "atol": 2e-2},
    "rings": {"rtol": 0.0, "atol": 2e-2},
    # texture coordinates up to 4,000 texels: the GPU's bilinear weights keep fewer bits
    "triplanar_texture": {"rtol": 0.0, "atol": 2e-3},
    "world_to_object": {"rtol": 1e-5, "atol": 1e-5},
}


def f32(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float32)


def _smooth(rng, lo, hi, comps, grazing=False):
    """A smooth random field over the W x H grid in [lo, hi], (N,) or (N, comps)."""
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    out = []
    for _ in range(comps):
        a, b = rng.uniform(0.01, 0.08, 2) * (40.0 if grazing else 1.0)
        c = rng.uniform(0, 6.3)
        t = 0.5 + 0.5 * np.sin(a * x + b * y + c) * np.cos(0.7 * a * y - 0.3 * b * x)
        out.append((lo + (hi - lo) * t).ravel())
    arr = np.stack(out, -1)
    return f32(arr[:, 0] if comps == 1 else arr)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _matrices(rng):
    ang = rng.uniform(0, 6.28)
    c, s = np.cos(ang), np.sin(ang)
    model = np.array([[c, 0, s, 0.5], [0, 1.5, 0, -0.2], [-s, 0, c, 1.0], [0, 0, 0, 1]])
    eye, target = np.array([2.0, 1.5, 3.0]), np.zeros(3)
    f = _unit(target - eye)
    r = _unit(np.cross(f, [0.0, 1.0, 0.0]))
    u = np.cross(r, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = r, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    n, fa, t = 0.1, 100.0, 1.0 / np.tan(np.radians(22.5))
    proj = np.array([[t / 1.6, 0, 0, 0], [0, t, 0, 0],
                     [0, 0, (fa + n) / (n - fa), 2 * fa * n / (n - fa)], [0, 0, -1, 0]])
    return f32(model), f32(proj @ view)


def _surface(rng, variant: str) -> SurfaceArrays:
    big = variant == "large"
    grazing = variant == "grazing"
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    stretch = 40.0 if grazing else 1.0
    uv = np.stack([(x + 0.5) / W * 4.0 * stretch - 1.0, (y + 0.5) / H * 0.5 - 0.2], -1)
    uv = uv.reshape(-1, 2) + _smooth(rng, -0.05, 0.05, 2)
    if big:
        uv = uv + 1000.0
    pos = _smooth(rng, -2, 2, 3) + (1000.0 if big else 0.0)
    normal = f32(_unit(_smooth(rng, -1, 1, 3) + [0.0, 0.0, 0.3]))
    view = f32(_unit(_smooth(rng, -1, 1, 3) + [0.0, 0.0, 1.0]))
    tangent = np.concatenate([_smooth(rng, -1, 1, 3) + [1.0, 0.0, 0.0],
                              np.where(rng.uniform(size=(N, 1)) < 0.3, -1.0, 1.0)], -1)
    model, vp = _matrices(rng)
    return SurfaceArrays(f32(uv), f32(pos), normal, view, 3.625, grid=(H, W),
                         tangent=f32(tangent), model=model, view_projection=vp)


def _inputs(kind: str, rng, s: SurfaceArrays, variant: str) -> dict[str, np.ndarray]:
    d = REGISTRY[kind]
    args = {}
    for i in d.inputs:
        if i.type == "texture2d":
            args[i.name] = "texture"
            continue
        if i.default == MESH_UV:
            args[i.name] = s.uv
            continue
        lo, hi = i.range or (-4.0, 4.0)
        if i.type == "vec3" and i.name in ("position", "vector", "value"):
            lo, hi = -3.0, 3.0
        args[i.name] = _smooth(rng, lo, hi, COMPS[i.type], grazing=variant == "grazing")
        if i.name == "position" and variant == "large":
            args[i.name] = f32(args[i.name] + 1000.0)
    # domain notes, kind by kind
    if "seed" in args:
        args["seed"] = f32(np.floor(_smooth(rng, 0, 20, 1)))
    if kind == "color_ramp":
        pos = np.sort(rng.uniform(0, 1, (N, 6)), axis=1)
        for k in range(6):
            args[f"position{k}"] = f32(pos[:, k])
        args["stops"] = f32(np.floor(rng.uniform(2, 7, N)))
    if kind in ("hsv_to_rgb",):
        args["hsv"] = f32(np.stack([rng.uniform(0, 1, N), rng.uniform(0, 1, N),
                                    rng.uniform(0, 2, N)], -1))
    if kind in ("reflect", "refract"):
        args["incident"] = f32(_unit(args["incident"]))
        args["normal"] = f32(_unit(args["normal"]))
    if kind in ("normal_strength", "flip_green"):
        args["normal"] = f32(_unit(args["normal"] + [0.0, 0.0, 2.0]))
    if kind == "normal_from_height":
        args["height"] = _smooth(rng, 0, 1, 1)
    if kind == "curvature":
        args["scale"] = _smooth(rng, 0.1, 2, 1)
    if kind == "height_mask":
        args["low"] = f32(args["low"] - 3.0 + (1000.0 if variant == "large" else 0.0))
        args["high"] = f32(args["low"] + rng.uniform(0.5, 6, N))
    if kind in ("wave", "rings"):
        args["frequency"] = _smooth(rng, 0, 16, 1)
    if kind == "triplanar_texture":
        args["scale"] = _smooth(rng, 0.2, 4, 1)
    return args


_SURFACE_BODY = """
    g_surface.uv = s_uv;
    g_surface.position = s_position;
    g_surface.normal = s_normal;
    g_surface.view = s_view;
    g_surface.time = 3.625;
    nodeSurfaceFrame(s_tangent, u_model, u_vp);
"""
_PREAMBLE = "uniform mat4 u_model;\nuniform mat4 u_vp;\nuniform sampler2D u_texture;\n"


def _run(ctx, kind, args, s: SurfaceArrays, tex=None):
    d = REGISTRY[kind]
    names = {n: ("u_texture" if isinstance(v, str) else "i_" + n) for n, v in args.items()}
    inputs = {f"i_{n}": v for n, v in args.items() if not isinstance(v, str)}
    inputs |= {"s_uv": s.uv, "s_position": s.position, "s_normal": s.normal,
               "s_view": s.view, "s_tangent": s.tangent}
    outputs = {f"o_{o.name}": o.type for o in d.outputs}
    if d.glsl:
        call = f"{d.glsl}({', '.join([*names.values(), *outputs])});"
    else:
        call = f"o_{d.outputs[0].name} = {d.inline.format(**names)};"
    res = gpu_eval_many(
        ctx, _SURFACE_BODY + call, inputs, outputs,
        includes=["nodes/context.glsl"] + ([f"nodes/{kind}.glsl"] if d.glsl else []),
        preamble=_PREAMBLE,
        uniforms={"u_model": tuple(s.model.T.ravel()), "u_vp": tuple(s.view_projection.T.ravel())},
        textures={"u_texture": tex} if tex is not None else None)
    return {o.name: res[f"o_{o.name}"] for o in d.outputs}


def _compare(name, gpu, ref, share=0.0, rtol=1e-5, atol=1e-5):
    gpu = np.asarray(gpu, dtype=np.float64)
    ref = np.broadcast_to(np.asarray(ref, dtype=np.float64), gpu.shape)
    assert np.all(np.isfinite(gpu)), f"{name}: NaN/Inf on the GPU"
    assert np.all(np.isfinite(ref)), f"{name}: NaN/Inf in numpy"
    err = np.abs(gpu - ref)
    bad = err > rtol * np.abs(ref) + atol
    if bad.ndim == 2:
        bad = bad.any(axis=1)
    frac = bad.mean()
    first = np.argwhere(bad)
    assert frac <= share, (
        f"{name}: {bad.sum()} of {len(bad)} points beyond tolerance (allowed {share:.1%}); "
        f"first at {first[0] if first.size else None}: gpu {gpu[first[0][0]]} "
        f"numpy {ref[first[0][0]]}")


@pytest.fixture
def texture(ctx):
    rng = np.random.default_rng(11)
    data = f32(rng.uniform(0, 1, (5, 7, 4)))
    tex = ctx.texture((7, 5), 4, data.tobytes(), dtype="f4")
    tex.filter = (ctx.LINEAR, ctx.LINEAR)
    tex.repeat_x = tex.repeat_y = True
    yield tex, data
    tex.release()


def test_the_library_is_the_size_the_issue_asks():
    assert len(REGISTRY) >= 120
    assert len(KINDS) >= 60


@pytest.mark.gl
@pytest.mark.parametrize("variant", ["smooth", "large", "grazing"])
@pytest.mark.parametrize("kind", KINDS)
def test_library_node_matches_numpy(ctx, kind, variant, texture):
    rng = np.random.default_rng(sum(map(ord, kind + variant)))
    s = _surface(rng, variant)
    args = _inputs(kind, rng, s, variant)
    tex, data = texture
    uses_texture = any(isinstance(v, str) for v in args.values())
    gpu = _run(ctx, kind, args, s, tex if uses_texture else None)
    ref_args = [data if isinstance(v, str) else v for v in args.values()]
    ref = IMPLS[kind](s, *ref_args)
    tol = TOLERANCE.get(kind, {})
    if variant == "large" or (variant == "grazing" and kind in ("wave", "rings")):
        tol = LARGE_TOLERANCE.get(kind) or {"rtol": tol.get("rtol", 1e-5),
                                            "atol": max(tol.get("atol", 1e-5), 1e-4)}
    for (name, g), r in zip(gpu.items(), ref, strict=True):
        share = JUMPY.get(name, 0.0) if kind in JUMPY_KINDS else 0.0
        _compare(f"{kind}.{name}[{variant}]", g, r, share=share, **tol)


# --- determinism and precision far from the origin ----------------------------------------
NOISES = ["gradient_noise", "fbm", "ridged_noise", "cellular_noise", "value_noise",
          "domain_warp"]


def _noise_args(kind, uv, seed):
    n = len(uv)
    full = lambda v: np.full(n, v, np.float32)  # noqa: E731
    table = {
        "gradient_noise": [uv, full(8.0), seed],
        "fbm": [uv, full(4.0), full(5.0), full(2.0), full(0.5), seed],
        "ridged_noise": [uv, full(4.0), full(5.0), full(2.0), full(0.5), seed],
        "cellular_noise": [uv, full(8.0), full(1.0), full(0.05), seed, full(0.0)],
        "value_noise": [uv, full(8.0), full(3.0)],
        "domain_warp": [uv, full(4.0), full(0.1), full(3.0), seed],
    }
    return table[kind]


def _gpu_noise(ctx, kind, args):
    d = REGISTRY[kind]
    inputs = {f"i_{k}": v for k, v in zip([i.name for i in d.inputs], args)}
    outputs = {f"o_{o.name}": o.type for o in d.outputs}
    call = f"{d.glsl}({', '.join([*inputs, *outputs])});"
    res = gpu_eval_many(ctx, call, inputs, outputs, includes=[f"nodes/{kind}.glsl"])
    return [res[k] for k in outputs]


@pytest.mark.gl
@pytest.mark.parametrize("kind", NOISES)
def test_noise_keeps_its_precision_at_uv_1000(ctx, kind):
    """Float32 on the GPU at UV ~1,000 equals numpy in float64 on the same inputs: the
    integer-hashed lattice loses nothing far from the origin (a sin-based hash would). The
    noise there is as lively as near the origin (same spread of values)."""
    rng = np.random.default_rng(4)
    near = f32(rng.uniform(0, 1, (N, 2)))
    far = f32(near + 1000.0)
    seed = np.full(N, 3.0, np.float32)
    gpu = _gpu_noise(ctx, kind, _noise_args(kind, far, seed))
    ref = IMPLS[kind](None, *[np.asarray(a, np.float64) for a in _noise_args(kind, far, seed)])
    # The cell is found from the float32 coordinate exactly and the position within it is
    # exact too (p - floor(p)), so the GPU's float32 noise equals float64 numpy on the same
    # inputs to ~1e-6 (measured, max over 4,096 points: gradient 1.0e-6, fBm 3.3e-7,
    # ridged 1.2e-6, cellular 1.1e-7, value 1.1e-7); the warp's output is a UV near 1,000,
    # itself a float32 exact to 6e-5 (measured 3.1e-5).
    for g, r in zip(gpu, ref):
        bound = 1e-5
        if g.ndim == 2:
            g, r = g - np.asarray(far), r - np.asarray(far, np.float64)  # warp: the offset
            bound = 1e-4
        err = np.abs(np.asarray(g, np.float64) - r)
        assert err.max() < bound, f"{kind}: {err.max():.2e}"
    v_far = np.asarray(gpu[0]).reshape(N, -1)[:, 0]
    v_near = np.asarray(IMPLS[kind](None, *_noise_args(kind, near, seed))[0]).reshape(N, -1)[:, 0]
    if kind == "domain_warp":
        v_far, v_near = v_far - far[:, 0], v_near - near[:, 0]
    assert 0.5 < np.std(v_far) / np.std(v_near) < 2.0


@pytest.mark.gl
@pytest.mark.parametrize("kind", ["gradient_noise", "fbm", "ridged_noise", "cellular_noise",
                                  "domain_warp"])
def test_same_seed_same_pattern_gpu_and_numpy(ctx, kind):
    rng = np.random.default_rng(9)
    uv = f32(rng.uniform(-5, 5, (N, 2)))
    outs = {}
    for seed in (0.0, 0.0, 7.0):
        s = np.full(N, seed, np.float32)
        g = _gpu_noise(ctx, kind, _noise_args(kind, uv, s))[0]
        c = IMPLS[kind](None, *_noise_args(kind, uv, s))[0]
        _compare(f"{kind} seed {seed}", g, c, share=0.002)  # cellular id: nearest-point ties
        outs.setdefault(seed, []).append(g)
    np.testing.assert_array_equal(outs[0.0][0], outs[0.0][1])  # bit-identical rerun
    assert np.mean(np.abs(outs[0.0][0] - outs[7.0][0])) > 0.02  # another seed, another one


@pytest.mark.gl
def test_hashes_are_bit_exact(ctx):
    rng = np.random.default_rng(2)
    cells = rng.integers(-100_000, 100_000, (N, 3))
    seeds = rng.integers(0, 1000, N)
    gpu = gpu_eval(ctx, "nodeHashUnit(nodeHashCell3(ivec3(cx, cy, cz), uint(seed)))",
                   {"cx": (cells[:, 0], "int"), "cy": (cells[:, 1], "int"),
                    "cz": (cells[:, 2], "int"), "seed": (seeds, "uint")},
                   includes=["nodes/noise_lib.glsl"])
    c = cells.astype(np.uint32)
    ref = noise.hash_unit(noise.hash_cell3(c[:, 0], c[:, 1], c[:, 2], seeds))
    np.testing.assert_array_equal(gpu, ref)


def test_gradient_noise_is_continuous_and_in_range():
    p = np.linspace(-20, 20, 200_001)
    uv = np.stack([p, 0.37 * p + 0.11], -1)
    v = noise.gradient_noise2(uv, np.uint32(0))
    assert np.max(np.abs(np.diff(v))) < 1e-3  # no jumps at cell borders
    assert -1.0 <= v.min() and v.max() <= 1.0 and v.std() > 0.15
    v3 = noise.gradient_noise3(np.stack([p, 0.3 * p, -0.7 * p + 1.3], -1), np.uint32(5))
    assert np.max(np.abs(np.diff(v3))) < 1e-3 and -1.1 <= v3.min() and v3.max() <= 1.1


def test_cellular_f1_is_the_nearest_feature_point():
    """F1 equals a brute-force nearest distance over a 5 x 5 neighbourhood (jitter 1)."""
    rng = np.random.default_rng(6)
    p = rng.uniform(-10, 10, (500, 2))
    f1, f2, _ = noise.cellular2(p, np.ones(500), np.uint32(0))
    best = np.full(500, np.inf)
    i = np.floor(p)
    for y in range(-2, 3):
        for x in range(-2, 3):
            c = noise._as_uint(i + [x, y])
            h = noise.hash_cell2(c[:, 0], c[:, 1], np.uint32(0))
            o = np.stack([noise.hash_unit(h, np.float64),
                          noise.hash_unit(noise.pcg_hash(h), np.float64)], -1)
            best = np.minimum(best, np.linalg.norm(i + [x, y] + o - p, axis=1))
    np.testing.assert_allclose(f1, best, atol=1e-12)
    assert np.all(f2 >= f1)
