"""numpy twins of the node implementations in `shaders/nodes/` and the inline templates.

`IMPLS[kind](ctx, *inputs)` returns the node's outputs as a tuple in declaration order.
Floats are arrays of shape (N,), vectors (N, k), textures (H, W, 4) float arrays and
MaterialAttributes dicts {field: array}. Generic (`T`) inputs arrive splatted to one
shape. Each function follows its GLSL twin's order of operations, so float32 inputs give
float32 results within a few ulps of the GPU; the value noise hash is integer arithmetic
and matches bit for bit. The compiler evaluates the kinds in `COMPILER_HANDLED` itself.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from matedit.graph.nodes import ATTRIBUTE_NAMES

# Kinds with no entry in IMPLS: the compiler evaluates them from the graph itself.
COMPILER_HANDLED = frozenset({
    "constant", "scalar_parameter", "color_parameter", "texture_parameter", "function_input",
    "function_output", "function_call", "layer_stack", "material_output", "set_attributes",
    "component_mask", "append", "reroute",
})  # fmt: skip
COMPILER_HANDLED = COMPILER_HANDLED | {"static_switch"}  # chosen at compile time (issue 14)

Attributes = dict[str, np.ndarray]


@dataclass
class SurfaceArrays:
    """The numpy counterpart of `SurfaceContext` (shaders/nodes/context.glsl), one row a point."""

    uv: np.ndarray  # (N, 2) mesh UV set 0
    position: np.ndarray  # (N, 3) world space, metres
    normal: np.ndarray  # (N, 3) world geometric normal
    view: np.ndarray  # (N, 3) unit vector surface -> eye
    time: float = 0.0  # seconds

    @property
    def count(self) -> int:
        return len(self.uv)


IMPLS: dict[str, Callable[..., tuple]] = {}


def _impl(kind: str):
    def register(fn):
        IMPLS[kind] = fn
        return fn

    return register


def _col(x: np.ndarray) -> np.ndarray:
    """A per-point float (N,) as a column (N, 1), to scale vectors (N, k) row by row."""
    return x[..., None]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """GLSL dot: a product of floats, or the sum of component products of vectors."""
    return a * b if a.ndim == 1 else np.sum(a * b, axis=-1)


def _mix(a, b, t):
    """GLSL mix, by its definition a (1 - t) + b t."""
    return a * (1.0 - t) + b * t


def _clamp(x, lo, hi):
    """GLSL clamp, by its definition min(max(x, lo), hi)."""
    return np.minimum(np.maximum(x, lo), hi)


def _smoothstep(e0, e1, x):
    """GLSL smoothstep: t = clamp((x - e0) / (e1 - e0), 0, 1); t t (3 - 2 t)."""
    t = _clamp((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _safe_normalize(v: np.ndarray, fallback) -> np.ndarray:
    """nodeSafeNormalize (shaders/nodes/normal_math.glsl): v / |v|, fallback where v = 0."""
    len2 = np.sum(v * v, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = v * _col(1.0 / np.sqrt(len2))
    return np.where(_col(len2 > 0.0), unit, np.asarray(fallback, dtype=v.dtype))


_Z = (0.0, 0.0, 1.0)


# --- inline maths: GLSL built-ins -------------------------------------------------------------
_impl("add")(lambda ctx, a, b: (a + b,))
_impl("subtract")(lambda ctx, a, b: (a - b,))
_impl("multiply")(lambda ctx, a, b: (a * b,))
_impl("lerp")(lambda ctx, a, b, alpha: (_mix(a, b, alpha),))
_impl("clamp")(lambda ctx, value, lo, hi: (_clamp(value, lo, hi),))
_impl("saturate")(lambda ctx, value: (_clamp(value, 0.0, 1.0),))
_impl("one_minus")(lambda ctx, value: (1.0 - value,))
_impl("abs")(lambda ctx, value: (np.abs(value),))
_impl("min")(lambda ctx, a, b: (np.minimum(a, b),))
_impl("max")(lambda ctx, a, b: (np.maximum(a, b),))
_impl("dot")(lambda ctx, a, b: (_dot(a, b),))
_impl("cross")(lambda ctx, a, b: (np.cross(a, b),))
_impl("length")(lambda ctx, value: (np.sqrt(_dot(value, value)),))
_impl("sin")(lambda ctx, value: (np.sin(value),))
_impl("cos")(lambda ctx, value: (np.cos(value),))
_impl("frac")(lambda ctx, value: (value - np.floor(value),))  # GLSL fract: x - floor(x)
_impl("floor")(lambda ctx, value: (np.floor(value),))
# GLSL step(edge, x): 0 where x < edge, else 1.
_impl("step")(lambda ctx, edge, value: (np.where(value < edge, 0.0, 1.0).astype(value.dtype),))
_impl("smoothstep")(lambda ctx, e0, e1, value: (_smoothstep(e0, e1, value),))


@_impl("divide")
def _divide(ctx, a, b):
    with np.errstate(divide="ignore", invalid="ignore"):  # the GPU's infinity, as documented
        return (a / b,)


@_impl("power")
def _power(ctx, base, exponent):
    # pow(max(b, 0), e); numpy's 0 ** -e is inf like the GPU's exp2(-e * log2(0)).
    with np.errstate(divide="ignore", invalid="ignore"):
        return (np.power(np.maximum(base, 0.0), exponent),)


@_impl("sqrt")
def _sqrt(ctx, value):
    return (np.sqrt(np.maximum(value, 0.0)),)


# --- GLSL functions: maths and vectors --------------------------------------------------------
@_impl("normalize")
def _normalize(ctx, value):
    if value.ndim == 1:
        return (np.sign(value),)
    len2 = np.sum(value * value, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = value * _col(1.0 / np.sqrt(len2))
    return (np.where(_col(len2 > 0.0), unit, value),)


@_impl("remap")
def _remap(ctx, value, in_min, in_max, out_min, out_max):
    with np.errstate(divide="ignore", invalid="ignore"):
        return (out_min + (value - in_min) / (in_max - in_min) * (out_max - out_min),)


@_impl("vector_parameter")
def _vector_parameter(ctx, value):
    return value, value[:, :3]


@_impl("split")
def _split(ctx, value):
    cols = value[:, None] if value.ndim == 1 else value
    zero = np.zeros(len(cols), dtype=cols.dtype)
    return tuple(cols[:, i] if i < cols.shape[1] else zero for i in range(4))


@_impl("combine")
def _combine(ctx, x, y, z, w):
    return np.stack([x, y], -1), np.stack([x, y, z], -1), np.stack([x, y, z, w], -1)


# --- geometry ---------------------------------------------------------------------------------
@_impl("texcoord")
def _texcoord(ctx: SurfaceArrays, tiling, offset):
    return (ctx.uv * tiling + offset,)


_impl("world_position")(lambda ctx: (ctx.position,))
_impl("world_normal")(lambda ctx: (ctx.normal,))
_impl("view_direction")(lambda ctx: (ctx.view,))
_impl("time")(lambda ctx: (np.full(ctx.count, ctx.time, dtype=ctx.uv.dtype),))


# --- textures and procedurals -----------------------------------------------------------------
def sample_bilinear(tex: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """GL_LINEAR, GL_REPEAT, no mipmaps: texel (i, j) is centred at ((i + 0.5)/W, (j + 0.5)/H)
    and row j = 0 of `tex` (H, W, C) is v = 0, as moderngl uploads it. Returns (N, C)."""
    h, w = tex.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = uv[:, 1] * h - 0.5
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = _col(x - x0)
    fy = _col(y - y0)
    i0 = x0.astype(np.int64) % w
    j0 = y0.astype(np.int64) % h
    i1 = (i0 + 1) % w
    j1 = (j0 + 1) % h
    top = tex[j0, i0] * (1.0 - fx) + tex[j0, i1] * fx
    bottom = tex[j1, i0] * (1.0 - fx) + tex[j1, i1] * fx
    return top * (1.0 - fy) + bottom * fy


@_impl("texture_sample")
def _texture_sample(ctx, tex, uv):
    rgba = sample_bilinear(np.asarray(tex), uv).astype(uv.dtype, copy=False)
    return rgba, rgba[:, :3], rgba[:, 0], rgba[:, 1], rgba[:, 2], rgba[:, 3]


NOISE_MAX_OCTAVES = 6


def pcg_hash(v: np.ndarray) -> np.ndarray:
    """nodeNoisePcg: Jarzynski & Olano 2020, "Hash Functions for GPU Rendering", pcg; uint32
    arithmetic wrapping like the GPU's."""
    state = v.astype(np.uint32) * np.uint32(747796405) + np.uint32(2891336453)
    word = ((state >> ((state >> np.uint32(28)) + np.uint32(4))) ^ state) * np.uint32(277803737)
    return (word >> np.uint32(22)) ^ word


def noise_lattice(cx: np.ndarray, cy: np.ndarray, seed) -> np.ndarray:
    """nodeNoiseLattice: pcg(x + pcg(y + seed)) of uint32 cell coordinates, its top 24 bits
    as a float in [0, 1) (exact in float32)."""
    h = pcg_hash(cx + pcg_hash(cy + np.asarray(seed, dtype=np.uint32)))
    return (h >> np.uint32(8)).astype(np.float32) * np.float32(1.0 / 16777216.0)


def _noise_octave(p: np.ndarray, seed: int) -> np.ndarray:
    i = np.floor(p)
    f = p - i
    # int(floor(p)) then uint(): two's complement, as GLSL converts int to uint.
    c = i.astype(np.int64).astype(np.uint32)
    cx, cy = c[:, 0], c[:, 1]
    one = np.uint32(1)
    v00 = noise_lattice(cx, cy, seed)
    v10 = noise_lattice(cx + one, cy, seed)
    v01 = noise_lattice(cx, cy + one, seed)
    v11 = noise_lattice(cx + one, cy + one, seed)
    u = f * f * (3.0 - 2.0 * f)
    return _mix(_mix(v00, v10, u[:, 0]), _mix(v01, v11, u[:, 0]), u[:, 1])


@_impl("value_noise")
def _value_noise(ctx, uv, scale, octaves):
    n = _clamp(octaves, 1.0, float(NOISE_MAX_OCTAVES))
    total = np.zeros(len(uv), dtype=uv.dtype)
    norm = np.zeros(len(uv), dtype=uv.dtype)
    amplitude = 1.0
    frequency = scale
    for k in range(NOISE_MAX_OCTAVES):
        # Per point, as the GPU's loop: octaves of weight 0 add nothing (the GPU breaks).
        w = _clamp(n - k, 0.0, 1.0) * amplitude
        if not np.any(w > 0.0):
            break
        total = total + w * _noise_octave(uv * _col(frequency), k)
        norm = norm + w
        amplitude *= 0.5
        frequency = frequency * 2.0
    return (total / norm,)


@_impl("checker")
def _checker(ctx, uv, scale, color_a, color_b):
    cell = np.floor(uv * _col(scale))
    s = cell[:, 0] + cell[:, 1]
    mask = s - 2.0 * np.floor(s / 2.0)  # GLSL mod(x, y) = x - y floor(x / y)
    return _mix(color_a, color_b, _col(mask)), mask


@_impl("gradient")
def _gradient(ctx, uv, angle):
    a = np.radians(angle)
    d = np.stack([np.cos(a), np.sin(a)], -1)
    extent = np.abs(d[:, 0]) + np.abs(d[:, 1])
    return (_clamp(_dot(uv - 0.5, d) / extent + 0.5, 0.0, 1.0),)


# --- normals ----------------------------------------------------------------------------------
@_impl("unpack_normal")
def _unpack_normal(ctx, packed, strength):
    n = packed * 2.0 - 1.0
    n = np.concatenate([n[:, :2] * _col(strength), n[:, 2:]], axis=-1)
    return (_safe_normalize(n, _Z),)


@_impl("blend_normals")
def _blend_normals(ctx, base, detail):
    # Barré-Brisebois & Hill 2012, "Blending in Detail": reoriented normal mapping.
    t = base + np.asarray(_Z, dtype=base.dtype)
    u = detail * np.asarray((-1.0, -1.0, 1.0), dtype=detail.dtype)
    r = t * _col(_dot(t, u)) / t[:, 2:3] - u
    return (_safe_normalize(r, _Z),)


@_impl("flatten_normal")
def _flatten_normal(ctx, normal, flatness):
    n = _mix(normal, np.asarray(_Z, dtype=normal.dtype), _col(flatness))
    return (_safe_normalize(n, _Z),)


# --- material attributes ----------------------------------------------------------------------
@_impl("make_attributes")
def _make_attributes(ctx, *fields):
    return (dict(zip(ATTRIBUTE_NAMES, fields, strict=True)),)


@_impl("break_attributes")
def _break_attributes(ctx, attributes: Attributes):
    return tuple(attributes[name] for name in ATTRIBUTE_NAMES)


def blend_material_attributes(a: Attributes, b: Attributes, t: np.ndarray) -> Attributes:
    """blendMaterialAttributes (shaders/nodes/layer_blend.glsl): a at t = 0, b at t = 1;
    every field linearly, the tangent-space normal by nlerp (falling back to (0, 0, 1))."""
    out = {}
    for name in ATTRIBUTE_NAMES:
        x, y = a[name], b[name]
        out[name] = _mix(x, y, _col(t) if x.ndim == 2 else t)
    out["normal"] = _safe_normalize(out["normal"], _Z)
    return out


@_impl("layer_blend")
def _layer_blend(ctx, base, layer, mask):
    return (blend_material_attributes(base, layer, mask),)


@_impl("height_blend")
def _height_blend(ctx, base, layer, base_height, layer_height, contrast):
    c = np.maximum(contrast, 1e-5)
    t = _smoothstep(-c, c, layer_height - base_height)
    return (blend_material_attributes(base, layer, t),)
