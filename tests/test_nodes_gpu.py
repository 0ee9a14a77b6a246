"""The node library: every kind has a GLSL implementation that compiles on its own, a numpy
twin (NodeDef.numpy, in its matedit/nodes category module), and the two agree on the GPU.

Inputs are float32 and both sides compute in float32, so the twins differ only where the
GPU is allowed to: fused multiply-adds, inversesqrt and the transcendental functions.
Tolerance: |gpu - numpy| <= rtol |numpy| + atol, 1e-5 each unless a kind states why not.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from matedit.compiler import cpu_nodes
from matedit.compiler.cpu_nodes import IMPLS, SurfaceArrays
from matedit.graph.nodes import ATTRIBUTE_FIELDS, ATTRIBUTE_NAMES, GENERIC, REGISTRY, PortsRule
from matedit.nodes import material, noise
from matedit.resources import shaders_dir
from tests.gpu_eval import gpu_eval, gpu_eval_many

N = 4096
NODES = shaders_dir() / "nodes"
NODE_FILES = sorted(p.name for p in NODES.glob("*.glsl"))
HELPER_FILES = {"context.glsl", "normal_math.glsl", "noise_lib.glsl", "filter_lib.glsl",
                "color_lib.glsl", "space_lib.glsl"}  # included by node files, not kinds
# The kinds the compiler evaluates itself; they have no numpy impl here.
COMPILER_HANDLED = {
    "constant", "scalar_parameter", "color_parameter", "texture_parameter", "function_input",
    "function_output", "function_call", "layer_stack", "material_output", "set_attributes",
    "component_mask", "append", "reroute",
}  # fmt: skip
COMPILER_HANDLED |= {"static_switch"}  # chosen at compile time (issue 14)
# (written out here, not read from NodeDef.lowered, so the catalogue is checked against it)
VEC = {1: "float", 2: "vec2", 3: "vec3", 4: "vec4"}
MAX_ERRORS: dict[str, tuple[float, float]] = {}  # name -> (abs, rel to |numpy| + atol)


@pytest.fixture(scope="module", autouse=True)
def _report():
    yield
    if MAX_ERRORS:
        print("\nmax |gpu - numpy| per node (abs, rel):")
        for name, (a, r) in sorted(MAX_ERRORS.items()):
            print(f"  {name:28s} {a:10.3e} {r:10.3e}")


@pytest.fixture
def rng(request):
    return np.random.default_rng(sum(map(ord, request.node.name)))


def f32(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float32)


def check(name, gpu, ref, rtol=1e-5, atol=1e-5):
    gpu = np.asarray(gpu, dtype=np.float64)
    ref = np.broadcast_to(np.asarray(ref, dtype=np.float64), gpu.shape)
    assert np.all(np.isfinite(gpu)), f"{name}: NaN/Inf on the GPU"
    assert np.all(np.isfinite(ref)), f"{name}: NaN/Inf in numpy"
    err = np.abs(gpu - ref)
    a, r = MAX_ERRORS.get(name, (0.0, 0.0))
    rel = err / (np.abs(ref) + max(atol, 1e-30))
    MAX_ERRORS[name] = (max(a, float(err.max())), max(r, float(rel.max())))
    bad = np.argwhere(err > rtol * np.abs(ref) + atol)
    assert bad.size == 0, (
        f"{name}: {len(bad)} of {err.size} beyond tolerance; first at {bad[0]}: "
        f"gpu {gpu[tuple(bad[0])]} numpy {ref[tuple(bad[0])]}"
    )


def surface(rng, n=N) -> SurfaceArrays:
    """Random surface points; laid out as gpu_eval lays elements out on its render target
    (256 a row), so derivatives (fwidth) are the same quad differences on both sides."""
    normal = f32(_unit(rng, n))
    grid = (n // 256, 256) if n % 256 == 0 else None
    return SurfaceArrays(uv=f32(rng.uniform(-2, 3, (n, 2))), position=f32(rng.normal(0, 5, (n, 3))),
                         normal=normal, view=f32(_unit(rng, n)), time=12.375,
                         grid=grid)  # fmt: skip


def _unit(rng, n, upper=False) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    if upper:
        v[:, 2] = np.abs(v[:, 2]) + 0.05
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def run_node(ctx, kind, args: dict, out_types: dict, *, preamble="", textures=None,
             sampler_inputs=()):  # fmt: skip
    """Evaluate node `kind` on the GPU: its function, or its inline template with each
    {input} replaced by the input's variable. Returns {output: array}."""
    d = REGISTRY[kind]
    names = {n: ("u_" + n if n in sampler_inputs else "i_" + n) for n in args}
    inputs = {names[n]: v for n, v in args.items() if n not in sampler_inputs}
    outputs = {f"o_{n}": t for n, t in out_types.items()}
    if d.glsl:
        body = f"{d.glsl}({', '.join([*names.values(), *outputs])});"
        includes = [f"nodes/{kind}.glsl"]
    else:
        body = f"o_result = {d.inline.format(**names)};"
        includes = []
    res = gpu_eval_many(ctx, body, inputs, outputs, includes=includes, preamble=preamble,
                        textures=textures)  # fmt: skip
    return {n: res[f"o_{n}"] for n in out_types}


# --- completeness and compilation ---------------------------------------------------------


def _functions(text: str) -> list[tuple[str, str, str]]:
    """(name, first parameter's type, first line of the body) of every function in `text`."""
    pattern = r"^[\w ]+?\b(\w+)\(\s*(?:out\s+)?(\w*)[^()]*\)\s*\{\n\s*(.*)$"
    return [m.groups() for m in re.finditer(pattern, text, re.MULTILINE)]


def test_every_glsl_kind_has_a_file_defining_its_function():
    for kind, d in REGISTRY.items():
        if d.glsl is None:
            continue
        path = NODES / f"{kind}.glsl"
        assert path.is_file(), f"{kind}: no shaders/nodes/{kind}.glsl"
        first_types = {t for name, t, _ in _functions(path.read_text()) if name == d.glsl}
        assert first_types, f"{kind}: {d.glsl} not defined"
        if d.inputs and (d.inputs[0].type == GENERIC or d.ports_rule == PortsRule.COMPONENTS):
            assert first_types == set(VEC.values()), f"{kind}: overloads {first_types}"
    kinds = {k for k, d in REGISTRY.items() if d.glsl}
    helpers = {f.removesuffix(".glsl") for f in HELPER_FILES}
    assert {f.removesuffix(".glsl") for f in NODE_FILES} - kinds == helpers


def test_every_node_function_cites_its_method_on_its_first_line():
    for name in NODE_FILES:
        text = (NODES / name).read_text()
        assert "#version" not in text and "precision " not in text, name
        for fn, _, first in _functions(text):
            assert first.startswith("//"), f"{name}: {fn} opens without a comment"


def test_every_kind_but_the_compilers_own_has_a_numpy_impl():
    assert COMPILER_HANDLED <= set(REGISTRY)
    assert cpu_nodes.COMPILER_HANDLED == COMPILER_HANDLED
    assert set(IMPLS) == set(REGISTRY) - COMPILER_HANDLED


# Each node file compiling on its own (llvmpipe, glslang) is checked with the rest of the
# library in test_shading_compile.py.


# --- generic maths: inline templates and the normalize / remap overloads ------------------


def _u(rng, lo, hi, shape):
    return f32(rng.uniform(lo, hi, shape))


def _sign(rng, shape):
    return np.where(rng.uniform(size=shape) < 0.5, -1.0, 1.0)


def _generic_inputs(kind: str, rng, shape) -> dict[str, np.ndarray]:
    """Inputs inside each kind's defined domain (GLSL leaves clamp with lo > hi, smoothstep
    with edge0 >= edge1 and pow(0, e <= 0) undefined)."""
    d = REGISTRY[kind]
    width = 1 if len(shape) == 1 else shape[1]
    comps = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4}
    args = {i.name: _u(rng, -4, 4, shape if i.type == GENERIC
                       else (N,) if i.type == "float" else (N, comps[i.type]))
            for i in d.inputs}
    if kind == "divide":
        args["b"] = f32(_sign(rng, shape) * rng.uniform(0.25, 4, shape))
    elif kind == "power":
        base = rng.uniform(-0.5, 4, shape)
        exponent = np.where(base > 0.05, rng.uniform(-3, 3, shape), rng.uniform(0.1, 3, shape))
        args = {"base": f32(base), "exponent": f32(exponent)}
    elif kind == "sqrt":
        args["value"] = _u(rng, -1, 16, shape)
    elif kind in ("sin", "cos"):
        args["value"] = _u(rng, -10, 10, shape)
    elif kind == "lerp":
        args["alpha"] = _u(rng, -0.5, 1.5, shape)
    elif kind == "clamp":
        args["max"] = f32(args["min"] + rng.uniform(0, 3, shape))
    elif kind == "smoothstep":
        args["edge1"] = f32(args["edge0"] + rng.uniform(0.1, 3, shape))
    elif kind == "remap":
        args["in_max"] = f32(args["in_min"] + _sign(rng, shape) * rng.uniform(0.25, 3, shape))
    elif kind in ("frac", "floor"):
        args["value"] = f32(np.where(rng.uniform(size=shape) < 0.1,
                                     np.round(args["value"]), args["value"]))  # fmt: skip
    elif kind == "step":
        args["value"] = np.where(rng.uniform(size=shape) < 0.1, args["edge"], args["value"])
    elif kind == "normalize":
        args["value"][:8] = 0.0  # zero stays zero
    elif kind == "log":
        args["value"] = _u(rng, -0.5, 8, shape)
    elif kind == "mod":
        b = f32(_sign(rng, shape) * rng.uniform(0.5, 3, shape))
        q = rng.uniform(-5, 5, shape)
        q = np.floor(q) + np.clip(q - np.floor(q), 0.05, 0.95)  # not at a wrap
        args = {"a": f32(q * b), "b": b}
    elif kind in ("round", "ceil", "trunc"):
        v = rng.uniform(-4, 4, shape)
        args["value"] = f32(np.where(np.abs(v - np.round(v)) < 0.02, v + 0.1, v))
        args["value"][:4] = (-1.5, 1.5, 2.0, -2.0) if width == 1 else args["value"][:4]
    elif kind == "tan":
        args["value"] = _u(rng, -1.4, 1.4, shape)
    elif kind == "reciprocal":
        args["value"] = f32(_sign(rng, shape) * rng.uniform(0.25, 4, shape))
    elif kind == "posterize":
        v = rng.uniform(-2, 2, shape)
        steps = np.floor(rng.uniform(1, 9, shape))
        q = v * steps
        args = {"value": f32((np.floor(q) + np.clip(q - np.floor(q), 0.05, 0.95)) / steps),
                "steps": f32(steps)}
    elif kind == "smooth_min":
        args["smoothness"] = _u(rng, 0, 1, shape)
    elif kind == "atan2":
        args["x"][:4] = 0.0  # on the y axis: +-pi/2
    elif kind == "if_equal":
        args["b"][: N // 2] = args["a"][: N // 2]
        args["tolerance"] = _u(rng, 0, 0.5, (N,))
    elif kind == "triplanar_blend":
        w = rng.uniform(0, 1, (N, 3))
        args["weights"] = f32(w / w.sum(axis=1, keepdims=True))
    return args


GENERIC_KINDS = sorted(
    k for k, d in REGISTRY.items()
    if k not in COMPILER_HANDLED and any(i.type == GENERIC for i in d.inputs)
)  # fmt: skip
# sin, cos and pow (exp2(e log2 b) on the GPU) are transcendental: GLSL gives them no
# precision bound, but llvmpipe's are within ~1e-7 relative of numpy over these domains
# (measured), so they keep the default 1e-5.


# llvmpipe's asin/acos are polynomial fits good to ~2e-4 rad (measured 1.6e-4; GLSL states
# no bound for them).
GENERIC_TOLERANCE = {"asin": {"rtol": 0.0, "atol": 5e-4}, "acos": {"rtol": 0.0, "atol": 5e-4}}


@pytest.mark.gl
@pytest.mark.parametrize("width", [1, 2, 3, 4])
@pytest.mark.parametrize("kind", GENERIC_KINDS)
def test_generic_node_matches_numpy(ctx, rng, kind, width):
    shape = (N,) if width == 1 else (N, width)
    args = _generic_inputs(kind, rng, shape)
    d = REGISTRY[kind]
    out_type = VEC[width] if d.outputs[0].type == GENERIC else d.outputs[0].type
    gpu = run_node(ctx, kind, args, {"result": out_type})["result"]
    (ref,) = IMPLS[kind](surface(rng), *args.values())
    check(kind, gpu, ref, **GENERIC_TOLERANCE.get(kind, {}))


@pytest.mark.gl
def test_cross_matches_numpy(ctx, rng):
    args = {"a": _u(rng, -4, 4, (N, 3)), "b": _u(rng, -4, 4, (N, 3))}
    gpu = run_node(ctx, "cross", args, {"result": "vec3"})["result"]
    check("cross", gpu, IMPLS["cross"](surface(rng), *args.values())[0])


# --- vectors, parameters, geometry ----------------------------------------------------------


def _check_outputs(kind, gpu: dict, ref: tuple, **tol):
    for (name, value), expected in zip(gpu.items(), ref, strict=True):
        check(f"{kind}.{name}", value, expected, **tol)


@pytest.mark.gl
@pytest.mark.parametrize("width", [1, 2, 3, 4])
def test_split_reads_missing_components_as_zero(ctx, rng, width):
    value = _u(rng, -4, 4, (N,) if width == 1 else (N, width))
    outs = {c: "float" for c in "xyzw"}
    gpu = run_node(ctx, "split", {"value": value}, outs)
    ref = IMPLS["split"](surface(rng), value)
    _check_outputs("split", gpu, ref, rtol=0.0, atol=0.0)
    assert all(np.all(r == 0.0) for r in ref[width:])


@pytest.mark.gl
def test_combine_and_vector_parameter(ctx, rng):
    args = {c: _u(rng, -4, 4, N) for c in "xyzw"}
    gpu = run_node(ctx, "combine", args, {"xy": "vec2", "xyz": "vec3", "xyzw": "vec4"})
    _check_outputs("combine", gpu, IMPLS["combine"](surface(rng), *args.values()), atol=0.0)
    value = _u(rng, -4, 4, (N, 4))
    gpu = run_node(ctx, "vector_parameter", {"value": value}, {"result": "vec4", "xyz": "vec3"})
    _check_outputs("vector_parameter", gpu, IMPLS["vector_parameter"](surface(rng), value),
                   atol=0.0)  # fmt: skip


@pytest.mark.gl
def test_geometry_nodes_read_the_surface_context(ctx, rng):
    s = surface(rng)
    tiling, offset = _u(rng, -4, 4, (N, 2)), _u(rng, -4, 4, (N, 2))
    body = """
    g_surface.uv = s_uv;
    g_surface.position = s_position;
    g_surface.normal = s_normal;
    g_surface.view = s_view;
    g_surface.time = s_time;
    node_texcoord(i_tiling, i_offset, o_uv);
    node_world_position(o_position);
    node_world_normal(o_normal);
    node_view_direction(o_direction);
    node_time(o_seconds);
    """
    inputs = {
        "s_uv": s.uv,
        "s_position": s.position,
        "s_normal": s.normal,
        "s_view": s.view,
        "s_time": np.full(N, s.time, np.float32),
        "i_tiling": tiling,
        "i_offset": offset,
    }
    outputs = {"o_uv": "vec2", "o_position": "vec3", "o_normal": "vec3", "o_direction": "vec3",
               "o_seconds": "float"}  # fmt: skip
    kinds = ["texcoord", "world_position", "world_normal", "view_direction", "time"]
    gpu = gpu_eval_many(ctx, body, inputs, outputs, includes=[f"nodes/{k}.glsl" for k in kinds])
    refs = [IMPLS["texcoord"](s, tiling, offset)] + [IMPLS[k](s) for k in kinds[1:]]
    for kind, out, (ref,) in zip(kinds, outputs, refs, strict=True):
        # texcoord: uv * tiling + offset may be one fused multiply-add on the GPU.
        check(kind, gpu[out], ref, atol=0.0 if kind != "texcoord" else 1e-5)


# --- textures and procedurals ---------------------------------------------------------------


@pytest.mark.gl
def test_texture_sample_is_bilinear_with_repeat(ctx, rng):
    h, w = 5, 7  # not square, so a transposed lookup cannot pass
    data = f32(rng.uniform(0, 1, (h, w, 4)))
    tex = ctx.texture((w, h), 4, data.tobytes(), dtype="f4")
    tex.filter = (ctx.LINEAR, ctx.LINEAR)
    tex.repeat_x = tex.repeat_y = True
    uv = _u(rng, -2, 3, (N, 2))
    uv[:16] = f32((np.arange(16)[:, None] % [w, h] + 0.5) / [w, h])  # texel centres
    outs = {"rgba": "vec4", "rgb": "vec3", "r": "float", "g": "float", "b": "float",
            "a": "float"}  # fmt: skip
    try:
        gpu = run_node(ctx, "texture_sample", {"texture": "tex", "uv": uv}, outs,
                       preamble="uniform sampler2D u_texture;", textures={"u_texture": tex},
                       sampler_inputs=("texture",))  # fmt: skip
    finally:
        tex.release()
    ref = IMPLS["texture_sample"](surface(rng), data, uv)
    # llvmpipe filters float textures with float weights (measured ~1e-6). GL leaves the
    # sub-texel precision to the implementation: hardware with 8-bit weights would need
    # atol ~ 2^-9 here.
    _check_outputs("texture_sample", gpu, ref, rtol=0.0, atol=1e-5)
    k = np.arange(16)
    check("texture_sample.centres", gpu["rgba"][:16], data[k % h, k % w], rtol=0.0, atol=0.0)


@pytest.mark.gl
def test_value_noise_lattice_hash_is_bit_exact(ctx, rng):
    cells = rng.integers(-100_000, 100_000, (N, 2))
    seeds = rng.integers(0, 6, N)
    gpu = gpu_eval(ctx, "nodeNoiseLattice(ivec2(cx, cy), uint(seed))",
                   {"cx": (cells[:, 0], "int"), "cy": (cells[:, 1], "int"),
                    "seed": (seeds, "uint")}, includes=["nodes/value_noise.glsl"])  # fmt: skip
    c = cells.astype(np.uint32)
    ref = noise.noise_lattice(c[:, 0], c[:, 1], seeds)
    check("value_noise.lattice", gpu, ref, rtol=0.0, atol=0.0)


@pytest.mark.gl
def test_value_noise_matches_numpy(ctx, rng):
    args = {"uv": _u(rng, -3, 3, (N, 2)), "scale": _u(rng, 0, 64, N),
            "octaves": _u(rng, 0.5, 6.5, N)}  # fmt: skip
    args["octaves"][: N // 4] = np.round(args["octaves"][: N // 4])
    gpu = run_node(ctx, "value_noise", args, {"value": "float"})["value"]
    (ref,) = IMPLS["value_noise"](surface(rng), *args.values())
    # Same lattice bits; the fade and the mixes may fuse multiply-adds: a few ulps of 1.
    check("value_noise", gpu, ref, rtol=0.0, atol=1e-5)
    assert 0.0 <= ref.min() and ref.max() < 1.0 and abs(ref.mean() - 0.5) < 0.05


@pytest.mark.gl
def test_checker_matches_numpy(ctx, rng):
    args = {"uv": _u(rng, -3, 3, (N, 2)), "scale": _u(rng, 0.5, 16, N),
            "color_a": _u(rng, 0, 1, (N, 3)), "color_b": _u(rng, 0, 1, (N, 3)),
            "filter_width": np.zeros(N, np.float32)}  # fmt: skip  (hard edges)
    gpu = run_node(ctx, "checker", args, {"color": "vec3", "mask": "float"})
    ref = IMPLS["checker"](surface(rng), *args.values())
    # The same float32 product is floored on both sides: the parity agrees exactly.
    check("checker.mask", gpu["mask"], ref[1], rtol=0.0, atol=0.0)
    check("checker.color", gpu["color"], ref[0], atol=1e-6)


@pytest.mark.gl
def test_gradient_matches_numpy(ctx, rng):
    args = {"uv": _u(rng, -0.5, 1.5, (N, 2)), "angle": _u(rng, -360, 720, N)}
    args["angle"][:8] = (0, 45, 90, 135, 180, 225, 270, 315)
    gpu = run_node(ctx, "gradient", args, {"value": "float"})["value"]
    (ref,) = IMPLS["gradient"](surface(rng), *args.values())
    # cos/sin of up to 4 pi radians, then a ramp in [0, 1]: an absolute bound.
    check("gradient", gpu, ref, rtol=0.0, atol=1e-5)


# --- normals ----------------------------------------------------------------------------------


@pytest.mark.gl
def test_unpack_normal_matches_numpy(ctx, rng):
    args = {"packed": _u(rng, 0, 1, (N, 3)), "strength": _u(rng, 0, 2, N)}
    args["packed"][:4] = 0.5  # the zero vector: falls back to (0, 0, 1)
    gpu = run_node(ctx, "unpack_normal", args, {"normal": "vec3"})["normal"]
    (ref,) = IMPLS["unpack_normal"](surface(rng), *args.values())
    # Unit vectors: an absolute bound (inversesqrt is a few ulps on the GPU).
    check("unpack_normal", gpu, ref, rtol=0.0, atol=1e-5)
    np.testing.assert_array_equal(ref[:4], np.tile([0.0, 0.0, 1.0], (4, 1)))


@pytest.mark.gl
def test_blend_normals_matches_numpy(ctx, rng):
    args = {"base": f32(_unit(rng, N, upper=True)), "detail": f32(_unit(rng, N, upper=True))}
    gpu = run_node(ctx, "blend_normals", args, {"normal": "vec3"})["normal"]
    (ref,) = IMPLS["blend_normals"](surface(rng), *args.values())
    check("blend_normals", gpu, ref, rtol=0.0, atol=1e-5)


@pytest.mark.gl
def test_flatten_normal_matches_numpy(ctx, rng):
    args = {"normal": f32(_unit(rng, N, upper=True)), "flatness": _u(rng, 0, 1, N)}
    gpu = run_node(ctx, "flatten_normal", args, {"result": "vec3"})["result"]
    (ref,) = IMPLS["flatten_normal"](surface(rng), *args.values())
    check("flatten_normal", gpu, ref, rtol=0.0, atol=1e-5)


def test_rnm_with_a_flat_base_returns_the_detail():
    rng = np.random.default_rng(3)
    detail = _unit(rng, 64, upper=True)
    (out,) = IMPLS["blend_normals"](None, np.tile([0.0, 0.0, 1.0], (64, 1)), detail)
    np.testing.assert_allclose(out, detail, atol=1e-12)


# --- material attributes --------------------------------------------------------------------


_UNIT_FIELDS = ("normal", "coatNormal", "anisotropyDirection")  # directions: unit vectors


def _attributes(rng, prefix: str) -> dict[str, np.ndarray]:
    out = {}
    for f in ATTRIBUTE_FIELDS:
        shape = (N,) if f.type == "float" else (N, 3)
        out[f"{prefix}{f.name}"] = _u(rng, 0, 4 if f.name == "emissive" else 1, shape)
    for name in _UNIT_FIELDS:
        out[f"{prefix}{name}"] = f32(_unit(rng, N, upper=True))
    return out


# GL guarantees 16 texture units (one an input) and 8 colour outputs: the fields are checked
# in chunks, the others held at their defaults (GLSL literals here, arrays for numpy).
_CHUNKS = [ATTRIBUTE_FIELDS[i:i + 7] for i in range(0, len(ATTRIBUTE_FIELDS), 7)]


def _glsl_literal(f) -> str:
    if f.type == "float":
        return repr(float(f.default))
    return "vec3(" + ", ".join(repr(float(x)) for x in f.default) + ")"


def _blend_body(call: str, chunk, second: str = "b") -> str:
    """Make A from the inputs a_*, B from {second}_* (fields outside `chunk` at their
    defaults), run `call` (setting R), break R into the chunk's outputs."""
    names = {f.name for f in chunk}

    def args(prefix):
        return ", ".join(f"{prefix}_{f.name}" if f.name in names else _glsl_literal(f)
                         for f in ATTRIBUTE_FIELDS)
    outs = ", ".join(f"o_{f.name}" if f.name in names else f"_unused_{f.name}"
                     for f in ATTRIBUTE_FIELDS)
    unused = " ".join(f"{f.type} _unused_{f.name};" for f in ATTRIBUTE_FIELDS
                      if f.name not in names)
    return (
        f"MaterialAttributes A, B, R; {unused}\n node_make_attributes({args('a')}, A);\n"
        f" node_make_attributes({args(second)}, B);\n {call};\n node_break_attributes(R, {outs});"
    )


def _in_chunk(values: dict, chunk, prefixes=("a_", "b_")) -> dict:
    names = {f"{p}{f.name}" for p in prefixes for f in chunk}
    return {k: v for k, v in values.items() if k in names}


def _with_defaults(values: dict, chunk, prefix: str) -> list:
    """The make_attributes arguments for numpy: the chunk's random values, defaults else."""
    names = {f.name for f in chunk}
    return [values[f"{prefix}{f.name}"] if f.name in names else np.broadcast_to(
        np.asarray(f.default, np.float32), (N,) + np.shape(f.default)).copy()
        for f in ATTRIBUTE_FIELDS]


_ATTR_INCLUDES = ["nodes/make_attributes.glsl", "nodes/break_attributes.glsl"]


def _outs(chunk) -> dict:
    return {f"o_{f.name}": f.type for f in chunk}


def _break(s, attrs, chunk) -> tuple:
    names = [f.name for f in ATTRIBUTE_FIELDS]
    full = IMPLS["break_attributes"](s, attrs)
    return tuple(full[names.index(f.name)] for f in chunk)


@pytest.mark.gl
@pytest.mark.parametrize("k", range(len(_CHUNKS)))
def test_make_then_break_attributes_is_the_identity(ctx, rng, k):
    chunk = _CHUNKS[k]
    a = _attributes(rng, "a_")
    gpu = gpu_eval_many(ctx, _blend_body("R = A", chunk, second="a"), _in_chunk(a, chunk),
                        _outs(chunk), includes=_ATTR_INCLUDES)  # fmt: skip
    s = surface(rng)
    (made,) = IMPLS["make_attributes"](s, *_with_defaults(a, chunk, "a_"))
    _check_outputs("make_break_attributes", gpu, _break(s, made, chunk), rtol=0.0, atol=0.0)


@pytest.mark.gl
@pytest.mark.parametrize("k", range(len(_CHUNKS)))
def test_layer_blend_matches_numpy(ctx, rng, k):
    chunk = _CHUNKS[k]
    a, b = _attributes(rng, "a_"), _attributes(rng, "b_")
    mask = _u(rng, 0, 1, N)
    mask[:4] = (0.0, 1.0, 0.0, 1.0)
    gpu = gpu_eval_many(ctx, _blend_body("node_layer_blend(A, B, mask, R)", chunk),
                        {**_in_chunk({**a, **b}, chunk), "mask": mask}, _outs(chunk),
                        includes=[*_ATTR_INCLUDES, "nodes/layer_blend.glsl"])  # fmt: skip
    s = surface(rng)
    (base,) = IMPLS["make_attributes"](s, *_with_defaults(a, chunk, "a_"))
    (layer,) = IMPLS["make_attributes"](s, *_with_defaults(b, chunk, "b_"))
    (blended,) = IMPLS["layer_blend"](s, base, layer, mask)
    _check_outputs("layer_blend", gpu, _break(s, blended, chunk))


@pytest.mark.gl
@pytest.mark.parametrize("k", range(len(_CHUNKS)))
def test_height_blend_matches_numpy(ctx, rng, k):
    chunk = _CHUNKS[k]
    a, b = _attributes(rng, "a_"), _attributes(rng, "b_")
    heights = {"base_height": _u(rng, 0, 1, N), "layer_height": _u(rng, 0, 1, N),
               "contrast": _u(rng, 0.001, 1, N)}  # fmt: skip
    heights["contrast"][:4] = 0.0  # guarded: a hard step, never smoothstep(0, 0, x)
    call = "node_height_blend(A, B, base_height, layer_height, contrast, R)"
    gpu = gpu_eval_many(ctx, _blend_body(call, chunk), {**_in_chunk({**a, **b}, chunk),
                                                        **heights}, _outs(chunk),
                        includes=[*_ATTR_INCLUDES, "nodes/height_blend.glsl"])  # fmt: skip
    s = surface(rng)
    (base,) = IMPLS["make_attributes"](s, *_with_defaults(a, chunk, "a_"))
    (layer,) = IMPLS["make_attributes"](s, *_with_defaults(b, chunk, "b_"))
    (blended,) = IMPLS["height_blend"](s, base, layer, *heights.values())
    _check_outputs("height_blend", gpu, _break(s, blended, chunk))


def test_blend_at_zero_and_one_returns_base_and_layer():
    rng = np.random.default_rng(5)
    a, b = _attributes(rng, ""), _attributes(rng, "")
    zero, one = np.zeros(N, np.float32), np.ones(N, np.float32)
    for t, expected in ((zero, a), (one, b)):
        out = material.blend_material_attributes(a, b, t)
        for name in ATTRIBUTE_NAMES:
            np.testing.assert_allclose(out[name], expected[name], atol=1e-6, err_msg=name)
