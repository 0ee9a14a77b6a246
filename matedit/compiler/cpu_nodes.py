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

from matedit.graph.nodes import ATTRIBUTE_NAMES, kinds_where

# Kinds with no entry in IMPLS: the compiler evaluates them from the graph itself.
COMPILER_HANDLED = kinds_where(lambda d: d.lowered)

Attributes = dict[str, np.ndarray]


@dataclass
class SurfaceArrays:
    """The numpy counterpart of `SurfaceContext` (shaders/nodes/context.glsl), one row a point."""

    uv: np.ndarray  # (N, 2) mesh UV set 0
    position: np.ndarray  # (N, 3) world space, metres
    normal: np.ndarray  # (N, 3) world geometric normal
    view: np.ndarray  # (N, 3) unit vector surface -> eye
    time: float = 0.0  # seconds
    # The footprint: the points as an image of (rows, columns), row-major, so that screen
    # derivatives are the GPU's 2 x 2 quad differences (see `derivatives`); None: the
    # points are scattered, derivatives read 0 and filtered patterns have hard edges.
    grid: tuple[int, int] | None = None
    tangent: np.ndarray | None = None  # (N, 4) world tangent and handedness; None: +X, +1
    model: np.ndarray | None = None  # (4, 4) object to world; None: identity
    view_projection: np.ndarray | None = None  # (4, 4) world to clip; None: no camera

    @property
    def count(self) -> int:
        return len(self.uv)


# A node kind's numpy twin: fn(surface, *inputs) -> its outputs, a tuple in declaration order
# (one output may come bare: an array, or a MaterialAttributes dict).
NumpyTwin = Callable[..., "tuple | np.ndarray | Attributes"]
IMPLS: dict[str, NumpyTwin] = {}


def _impl(kind: str) -> Callable[[NumpyTwin], NumpyTwin]:
    def register(fn: NumpyTwin) -> NumpyTwin:
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
_X = (1.0, 0.0, 0.0)


def derivatives(ctx, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """dFdx and dFdy of per-point values `p`, as a GPU computes them on 2 x 2 pixel quads
    with fine derivatives (llvmpipe's, measured): dFdx is the difference across the pixel's
    quad along its own row, dFdy along its own column. Needs `ctx.grid`; without one
    (scattered points, or constant folding with no surface) both are zero. A last odd row
    or column pairs with its neighbour before it."""
    grid = getattr(ctx, "grid", None)
    p = np.asarray(p)
    if grid is None or p.ndim == 0 or p.shape[0] == 1:
        z = np.zeros_like(p)
        return z, z
    h, w = grid
    if h * w != p.shape[0]:
        raise ValueError(f"footprint grid {h} x {w} does not hold {p.shape[0]} points")
    a = p.reshape(h, w, *p.shape[1:])
    return (_quad_diff(a, 1).reshape(p.shape), _quad_diff(a, 0).reshape(p.shape))


def _quad_diff(a: np.ndarray, axis: int) -> np.ndarray:
    a = np.moveaxis(a, axis, 0)
    n = a.shape[0]
    out = np.zeros_like(a)
    m = n // 2 * 2
    d = a[1:m:2] - a[0:m:2]
    out[0:m:2] = d
    out[1:m:2] = d
    if n % 2 and n > 1:
        out[n - 1] = a[n - 1] - a[n - 2]
    return np.moveaxis(out, 0, axis)


def fwidth(ctx, p: np.ndarray) -> np.ndarray:
    """GLSL fwidth: |dFdx p| + |dFdy p| (see `derivatives`)."""
    dx, dy = derivatives(ctx, p)
    return np.abs(dx) + np.abs(dy)


def _need(ctx) -> SurfaceArrays:
    """The surface, for kinds that read it; refusing keeps them out of constant folding."""
    if ctx is None:
        raise TypeError("this node reads the surface")
    return ctx


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
def _checker(ctx, uv, scale, color_a, color_b, filter_width):
    p = uv * _col(scale)
    w = fwidth(ctx, p) * _col(filter_width)
    sx = filtered_square(p[:, 0], w[:, 0])
    sy = filtered_square(p[:, 1], w[:, 1])
    mask = 0.5 - 0.5 * sx * sy
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
    out["coatNormal"] = _safe_normalize(out["coatNormal"], _Z)
    out["anisotropyDirection"] = _safe_normalize(out["anisotropyDirection"], _X)
    return out


def coat_layer_share(below: np.ndarray, w: np.ndarray) -> np.ndarray:
    """coatLayerShare (shaders/nodes/layer_blend.glsl): the new coat's share w / coverage of
    the coverage w + (1 - w) a of a coat of weight w over one of weight a (independent
    presences, OpenPBR's coat_weight); 0 where w = 0, so the coat below is kept exactly.
    OpenPBR 2024, "OpenPBR Surface Specification", coat_weight"""
    coverage = w + (1.0 - w) * below
    return w / np.maximum(coverage, 1e-6)


def coat_material_attributes(base: Attributes, layer: Attributes, w: np.ndarray) -> Attributes:
    """coatMaterialAttributes (shaders/nodes/layer_blend.glsl): the `coat` layer blend. The
    base's fields are kept; the layer's roughness, base colour, IOR and normal become the
    coat's roughness, tint, IOR and normal by the new coat's share, and the weights combine
    as coverages, 1 - (1 - a)(1 - w).
    glTF KHR_materials_clearcoat; OpenPBR 2024, "OpenPBR Surface Specification", coat_*"""
    out = {name: np.array(base[name], copy=True) for name in ATTRIBUTE_NAMES}
    w = np.asarray(w, dtype=base["coat"].dtype)
    s = coat_layer_share(base["coat"], w)
    out["coat"] = 1.0 - (1.0 - base["coat"]) * (1.0 - w)
    out["coatRoughness"] = _mix(base["coatRoughness"], layer["roughness"], s)
    out["coatColor"] = _mix(base["coatColor"], layer["baseColor"], _col(s))
    out["coatIor"] = _mix(base["coatIor"], layer["ior"], s)
    out["coatNormal"] = _safe_normalize(_mix(base["coatNormal"], layer["normal"], _col(s)), _Z)
    return out


@_impl("layer_blend")
def _layer_blend(ctx, base, layer, mask):
    return (blend_material_attributes(base, layer, mask),)


@_impl("height_blend")
def _height_blend(ctx, base, layer, base_height, layer_height, contrast):
    c = np.maximum(contrast, 1e-5)
    t = _smoothstep(-c, c, layer_height - base_height)
    return (blend_material_attributes(base, layer, t),)


# =============================================================================================
# The node library (matedit.graph.library): twins of shaders/nodes/*.glsl, same operation
# order. Integer hashes are uint32 arithmetic and match the GPU bit for bit.
# =============================================================================================
def _bc(cond: np.ndarray, like: np.ndarray) -> np.ndarray:
    """A per-point condition (N,) shaped to select rows of `like` (N,) or (N, k)."""
    return cond if like.ndim == cond.ndim else cond[..., None]


def _where(cond, a, b):
    a, b = np.asarray(a), np.asarray(b)
    like = a if a.ndim >= b.ndim else b
    return np.where(_bc(np.asarray(cond), like), a, b)


# --- maths ------------------------------------------------------------------------------------
_impl("atan2")(lambda ctx, y, x: (np.arctan2(y, x),))
_impl("exp")(lambda ctx, value: (np.exp(value),))
_impl("log")(lambda ctx, value: (np.log(np.maximum(value, 1e-30)),))
_impl("mod")(lambda ctx, a, b: (a - b * np.floor(a / b),))
_impl("sign")(lambda ctx, value: (np.sign(value),))
_impl("round")(lambda ctx, value: (np.floor(value + 0.5),))
_impl("ceil")(lambda ctx, value: (np.ceil(value),))
_impl("trunc")(lambda ctx, value: (np.trunc(value),))
_impl("negate")(lambda ctx, value: (-value,))
_impl("tan")(lambda ctx, value: (np.tan(value),))
_impl("asin")(lambda ctx, value: (np.arcsin(_clamp(value, -1.0, 1.0)),))
_impl("acos")(lambda ctx, value: (np.arccos(_clamp(value, -1.0, 1.0)),))
_impl("radians")(lambda ctx, value: (np.radians(value),))
_impl("degrees")(lambda ctx, value: (np.degrees(value),))
_impl("multiply_add")(lambda ctx, a, b, c: (a * b + c,))
_impl("distance")(lambda ctx, a, b: (np.sqrt(_dot(a - b, a - b)),))
_impl("fwidth")(lambda ctx, value: (fwidth(ctx, value),))
_impl("triplanar_blend")(
    lambda ctx, x, y, z, weights: (x * _bc_w(weights, 0, x) + y * _bc_w(weights, 1, x)
                                   + z * _bc_w(weights, 2, x),))


def _bc_w(weights, i, like):
    w = weights[:, i]
    return w if like.ndim == 1 else w[:, None]


@_impl("reciprocal")
def _reciprocal(ctx, value):
    with np.errstate(divide="ignore"):
        return (1.0 / value,)


@_impl("posterize")
def _posterize(ctx, value, steps):
    s = np.maximum(steps, 1.0)
    return (np.floor(value * s) / s,)


@_impl("smooth_min")
def _smooth_min(ctx, a, b, smoothness):
    k = np.maximum(smoothness, 1e-6)
    h = _clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return (_mix(b, a, h) - smoothness * h * (1.0 - h),)


@_impl("reflect")
def _reflect(ctx, incident, normal):
    return (incident - 2.0 * _col(_dot(normal, incident)) * normal,)


@_impl("refract")
def _refract(ctx, incident, normal, eta):
    d = _dot(normal, incident)
    k = 1.0 - eta * eta * (1.0 - d * d)
    out = _col(eta) * incident - _col(eta * d + np.sqrt(np.maximum(k, 0.0))) * normal
    return (np.where(_col(k < 0.0), 0.0, out).astype(incident.dtype, copy=False),)


@_impl("if_greater")
def _if_greater(ctx, a, b, if_true, if_false):
    return (_where(a > b, if_true, if_false),)


@_impl("if_equal")
def _if_equal(ctx, a, b, tolerance, if_true, if_false):
    return (_where(np.abs(a - b) <= tolerance, if_true, if_false),)


# --- colour -----------------------------------------------------------------------------------
LUMA_REC709 = (0.2126, 0.7152, 0.0722)


def _luminance(c):
    w = np.asarray(LUMA_REC709, dtype=np.float32).astype(c.dtype)
    return c[:, 0] * w[0] + c[:, 1] * w[1] + c[:, 2] * w[2]


def rgb_to_hsv(c: np.ndarray) -> np.ndarray:
    """nodeRgbToHsv (shaders/nodes/color_lib.glsl): Hocevar's branchless form."""
    r, g, b = c[:, 0], c[:, 1], c[:, 2]
    kx, ky, kz, kw = 0.0, -1.0 / 3.0, 2.0 / 3.0, -1.0
    gb = g < b
    p = np.stack([np.where(gb, b, g), np.where(gb, g, b), np.where(gb, kw, kx),
                  np.where(gb, kz, ky)], -1).astype(c.dtype)
    rp = r < p[:, 0]
    q = np.stack([np.where(rp, p[:, 0], r), p[:, 1], np.where(rp, p[:, 3], p[:, 2]),
                  np.where(rp, r, p[:, 0])], -1).astype(c.dtype)
    d = q[:, 0] - np.minimum(q[:, 3], q[:, 1])
    e = 1.0e-10
    return np.stack([np.abs(q[:, 2] + (q[:, 3] - q[:, 1]) / (6.0 * d + e)), d / (q[:, 0] + e),
                     q[:, 0]], -1)


def hsv_to_rgb(c: np.ndarray) -> np.ndarray:
    """nodeHsvToRgb (shaders/nodes/color_lib.glsl)."""
    k = np.asarray([1.0, 2.0 / 3.0, 1.0 / 3.0], dtype=np.float32).astype(c.dtype)
    x = c[:, 0:1] + k
    p = np.abs((x - np.floor(x)) * 6.0 - 3.0)
    return c[:, 2:3] * _mix(1.0, _clamp(p - 1.0, 0.0, 1.0), c[:, 1:2])


_impl("luminance")(lambda ctx, color: (_luminance(color),))
_impl("rgb_to_hsv")(lambda ctx, color: (rgb_to_hsv(color),))
_impl("hsv_to_rgb")(lambda ctx, hsv: (hsv_to_rgb(hsv),))
_impl("gamma")(lambda ctx, color, gamma: (np.power(np.maximum(color, 0.0), _col(gamma)),))
_impl("invert")(lambda ctx, color, amount: (_mix(color, 1.0 - color, _col(amount)),))
_impl("saturation")(
    lambda ctx, color, amount: (_mix(_col(_luminance(color)), color, _col(amount)),))


@_impl("hsv_adjust")
def _hsv_adjust(ctx, color, hue, saturation, value):
    hsv = rgb_to_hsv(color)
    h = hsv[:, 0] + hue
    h = h - np.floor(h)
    s = _clamp(hsv[:, 1] * saturation, 0.0, 1.0)
    v = hsv[:, 2] * value
    return (hsv_to_rgb(np.stack([h, s, v], -1)),)


@_impl("brightness_contrast")
def _brightness_contrast(ctx, color, brightness, contrast):
    a = 1.0 + contrast
    b = brightness - contrast * 0.5
    return (np.maximum(_col(a) * color + _col(b), 0.0),)


@_impl("levels")
def _levels(ctx, color, in_black, in_white, gamma, out_black, out_white):
    rng = np.maximum(in_white - in_black, 1e-5)
    t = _clamp((color - _col(in_black)) / _col(rng), 0.0, 1.0)
    t = np.power(t, _col(1.0 / np.maximum(gamma, 1e-3)))
    return (_mix(_col(out_black), _col(out_white), t),)


@_impl("srgb_to_linear")
def _srgb_to_linear(ctx, color):
    c = np.maximum(color, 0.0)
    return (np.where(c <= 0.04045, c / 12.92, np.power((c + 0.055) / 1.055, 2.4)),)


@_impl("linear_to_srgb")
def _linear_to_srgb(ctx, color):
    c = np.maximum(color, 0.0)
    return (np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1.0 / 2.4) - 0.055),)


def _soft_light(a, b):
    a = _clamp(a, 0.0, 1.0)
    d = np.where(a <= 0.25, ((16.0 * a - 12.0) * a + 4.0) * a, np.sqrt(a))
    dark = a - (1.0 - 2.0 * b) * a * (1.0 - a)
    light = a + (2.0 * b - 1.0) * (d - a)
    return np.where(b <= 0.5, dark, light)


def _dodge(a, b):
    q = np.minimum(1.0, a / np.maximum(1.0 - b, 1e-6))
    r = np.where(b >= 1.0, 1.0, q)
    return np.where(a <= 0.0, 0.0, r)


def _burn(a, b):
    q = 1.0 - np.minimum(1.0, (1.0 - a) / np.maximum(b, 1e-6))
    r = np.where(b <= 0.0, 0.0, q)
    return np.where(a >= 1.0, 1.0, r)


BLEND_MODES: dict[str, Callable] = {
    "multiply": lambda a, b: a * b,
    "screen": lambda a, b: 1.0 - (1.0 - a) * (1.0 - b),
    "overlay": lambda a, b: np.where(a >= 0.5, 1.0 - 2.0 * (1.0 - a) * (1.0 - b), 2.0 * a * b),
    "soft_light": _soft_light,
    "add": lambda a, b: a + b,
    "subtract": lambda a, b: a - b,
    "difference": lambda a, b: np.abs(a - b),
    "dodge": _dodge,
    "burn": _burn,
    "lighten": np.maximum,
    "darken": np.minimum,
}


def _blend_impl(mode):
    def impl(ctx, base, blend, opacity):
        r = np.asarray(mode(base, blend), dtype=base.dtype)
        return (_mix(base, r, _col(opacity)),)  # from the unclamped base, as the GLSL

    return impl


for _name, _mode in BLEND_MODES.items():
    IMPLS[f"blend_{_name}"] = _blend_impl(_mode)


@_impl("color_ramp")
def _color_ramp(ctx, value, stops, *rest):
    positions, colors = rest[:6], rest[6:]
    n = _clamp(np.floor(stops), 2.0, 6.0)
    color = np.array(colors[0], copy=True)
    for k in range(1, 6):
        gap = positions[k] - positions[k - 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(gap > 0.0, _clamp((value - positions[k - 1]) / gap, 0.0, 1.0),
                         np.where(value < positions[k], 0.0, 1.0))
        t = np.where(k < n, t, 0.0).astype(value.dtype)
        color = _mix(color, colors[k], _col(t))
    return (color,)


# --- noise ------------------------------------------------------------------------------------
_U = np.uint32


def _as_uint(cells: np.ndarray) -> np.ndarray:
    """GLSL uint(ivec(floor(x))): two's complement of the integer cell."""
    return cells.astype(np.int64).astype(np.uint32)


def hash_cell2(cx, cy, seed) -> np.ndarray:
    """nodeHashCell2: pcg(x + pcg(y + seed)) of uint32 cell coordinates."""
    return pcg_hash(cx + pcg_hash(cy + np.asarray(seed, dtype=np.uint32)))


def hash_cell3(cx, cy, cz, seed) -> np.ndarray:
    """nodeHashCell3: pcg(x + pcg(y + pcg(z + seed)))."""
    return pcg_hash(cx + pcg_hash(cy + pcg_hash(cz + np.asarray(seed, dtype=np.uint32))))


def hash_unit(h: np.ndarray, dtype=np.float32) -> np.ndarray:
    """nodeHashUnit: the top 24 bits in [0, 1), exact in float32."""
    return ((h >> _U(8)).astype(np.float32) * np.float32(1.0 / 16777216.0)).astype(dtype)


def node_seed(seed) -> np.ndarray:
    """nodeSeed: floor, negative reads 0, as uint32."""
    return np.maximum(np.floor(seed), 0.0).astype(np.int64).astype(np.uint32)


def _gradient2(h: np.ndarray, dtype) -> np.ndarray:
    d = np.float32(0.70710678)
    g = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [d, d], [-d, d], [d, -d], [-d, -d]],
                 dtype=np.float32)
    return g[h >> _U(29)].astype(dtype)


def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def gradient_noise2(p: np.ndarray, seed) -> np.ndarray:
    """nodeGradientNoise2 (shaders/nodes/noise_lib.glsl) at points p (N, 2)."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    cx, cy = c[:, 0], c[:, 1]
    one = _U(1)
    dt = p.dtype

    def corner(ox, oy, hx, hy):
        g = _gradient2(hash_cell2(cx + hx, cy + hy, seed), dt)
        return g[:, 0] * (f[:, 0] - ox) + g[:, 1] * (f[:, 1] - oy)

    n00 = corner(0.0, 0.0, _U(0), _U(0))
    n10 = corner(1.0, 0.0, one, _U(0))
    n01 = corner(0.0, 1.0, _U(0), one)
    n11 = corner(1.0, 1.0, one, one)
    u = _fade(f)
    return _mix(_mix(n00, n10, u[:, 0]), _mix(n01, n11, u[:, 0]), u[:, 1]) * np.asarray(
        1.41421356, dtype=np.float32).astype(dt)


def _grad_dot3(h, d):
    k = h >> _U(28)
    u = np.where(k < 8, d[:, 0], d[:, 1])
    v = np.where(k < 4, d[:, 1], np.where((k == 12) | (k == 14), d[:, 0], d[:, 2]))
    return np.where((k & 1) == 0, u, -u) + np.where((k & 2) == 0, v, -v)


def gradient_noise3(p: np.ndarray, seed) -> np.ndarray:
    """nodeGradientNoise3 at points p (N, 3)."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    u = _fade(f)
    vals = {}
    for ox in (0, 1):
        for oy in (0, 1):
            for oz in (0, 1):
                h = hash_cell3(c[:, 0] + _U(ox), c[:, 1] + _U(oy), c[:, 2] + _U(oz), seed)
                off = np.asarray([ox, oy, oz], dtype=p.dtype)
                vals[ox, oy, oz] = _grad_dot3(h, f - off)
    x00 = _mix(vals[0, 0, 0], vals[1, 0, 0], u[:, 0])
    x10 = _mix(vals[0, 1, 0], vals[1, 1, 0], u[:, 0])
    x01 = _mix(vals[0, 0, 1], vals[1, 0, 1], u[:, 0])
    x11 = _mix(vals[0, 1, 1], vals[1, 1, 1], u[:, 0])
    return _mix(_mix(x00, x10, u[:, 1]), _mix(x01, x11, u[:, 1]), u[:, 2])


FBM_MAX_OCTAVES = 8


def _octaves(noise, p, octaves, lacunarity, gain, seed, shape=None):
    """The fBm loop of nodeFbm2/3: per-point weights, seed + k per octave; `shape` maps
    each octave's noise (ridged)."""
    n = _clamp(octaves, 1.0, float(FBM_MAX_OCTAVES))
    total = np.zeros(len(p), dtype=p.dtype)
    norm = np.zeros(len(p), dtype=p.dtype)
    amplitude = np.ones(len(p), dtype=p.dtype)
    q = p
    for k in range(FBM_MAX_OCTAVES):
        w = _clamp(n - k, 0.0, 1.0) * amplitude
        if not np.any(w > 0.0):
            break
        v = noise(q, seed + _U(k))
        total = total + w * (shape(v) if shape else v)
        norm = norm + w
        amplitude = amplitude * gain
        q = q * _col(lacunarity)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(norm > 0.0, total / norm, 0.0).astype(p.dtype)


def fbm2(p, octaves, lacunarity, gain, seed):
    return _octaves(gradient_noise2, p, octaves, lacunarity, gain, seed)


def cellular2(p: np.ndarray, jitter, seed):
    """nodeCellular2: (F1, F2, cell id) over the 3 x 3 neighbourhood, in the GLSL's order."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    dt = p.dtype
    d1 = np.full(len(p), 64.0, dtype=dt)
    d2 = np.full(len(p), 64.0, dtype=dt)
    cid = np.zeros(len(p), dtype=dt)
    for y in (-1, 0, 1):
        for x in (-1, 0, 1):
            h = hash_cell2(c[:, 0] + np.uint32(x % 2**32), c[:, 1] + np.uint32(y % 2**32), seed)
            h2 = pcg_hash(h)
            o = np.stack([hash_unit(h, dt), hash_unit(h2, dt)], -1) - 0.5
            d = np.asarray([x, y], dtype=dt) + 0.5 + o * _col(jitter) - f
            dd = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
            nearer = dd < d1
            second = ~nearer & (dd < d2)
            d2 = np.where(nearer, d1, np.where(second, dd, d2))
            cid = np.where(nearer, hash_unit(pcg_hash(h2), dt), cid)
            d1 = np.where(nearer, dd, d1)
    return np.sqrt(d1), np.sqrt(d2), cid


def cellular3(p: np.ndarray, jitter, seed):
    """nodeCellular3: (F1, F2, cell id) over the 3 x 3 x 3 neighbourhood."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    dt = p.dtype
    d1 = np.full(len(p), 64.0, dtype=dt)
    d2 = np.full(len(p), 64.0, dtype=dt)
    cid = np.zeros(len(p), dtype=dt)
    for z in (-1, 0, 1):
        for y in (-1, 0, 1):
            for x in (-1, 0, 1):
                h = hash_cell3(c[:, 0] + np.uint32(x % 2**32), c[:, 1] + np.uint32(y % 2**32),
                               c[:, 2] + np.uint32(z % 2**32), seed)
                h2 = pcg_hash(h)
                h3 = pcg_hash(h2)
                o = np.stack([hash_unit(h, dt), hash_unit(h2, dt), hash_unit(h3, dt)], -1) - 0.5
                d = np.asarray([x, y, z], dtype=dt) + 0.5 + o * _col(jitter) - f
                dd = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]
                nearer = dd < d1
                second = ~nearer & (dd < d2)
                d2 = np.where(nearer, d1, np.where(second, dd, d2))
                cid = np.where(nearer, hash_unit(pcg_hash(h3), dt), cid)
                d1 = np.where(nearer, dd, d1)
    return np.sqrt(d1), np.sqrt(d2), cid


def filtered_step(edge, x, w):
    """nodeFilteredStep (shaders/nodes/filter_lib.glsl)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = _clamp((x - edge) / w + 0.5, 0.0, 1.0)
    return np.where(w > 0.0, soft, np.where(x < edge, 0.0, 1.0)).astype(np.asarray(x).dtype)


def _pulse_integral(x, duty):
    i = np.floor(x)
    return i * duty + np.minimum(x - i, duty)


def filtered_pulse(x, duty, w):
    """nodeFilteredPulse: the period-1 pulse train (1 on [0, duty)) box-filtered over w."""
    x = x - np.floor(x)
    hard = np.where(x < duty, 1.0, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = (_pulse_integral(x + 0.5 * w, duty) - _pulse_integral(x - 0.5 * w, duty)) / w
    return np.where(w > 0.0, soft, hard).astype(x.dtype)


def _square_integral(x):
    return 1.0 - np.abs(x - 2.0 * np.floor(0.5 * x) - 1.0)


def filtered_square(x, w):
    """nodeFilteredSquare: +1 where floor(x) is even, -1 where odd, box-filtered over w."""
    x = x - 2.0 * np.floor(0.5 * x)
    hard = np.where(x < 1.0, 1.0, -1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = (_square_integral(x + 0.5 * w) - _square_integral(x - 0.5 * w)) / w
    return np.where(w > 0.0, soft, hard).astype(x.dtype)


@_impl("gradient_noise")
def _gradient_noise(ctx, uv, scale, seed):
    return (gradient_noise2(uv * _col(scale), node_seed(seed)),)


@_impl("gradient_noise_3d")
def _gradient_noise_3d(ctx, position, scale, seed):
    return (gradient_noise3(position * _col(scale), node_seed(seed)),)


@_impl("cellular_noise")
def _cellular_noise(ctx, uv, scale, jitter, edge_width, seed, filter_width):
    f1, f2, cid = cellular2(uv * _col(scale), jitter, node_seed(seed))
    edge = f2 - f1
    edges = 1.0 - filtered_step(edge_width, edge, fwidth(ctx, edge) * filter_width)
    return f1, f2, edge, cid, edges


@_impl("cellular_noise_3d")
def _cellular_noise_3d(ctx, position, scale, jitter, seed):
    f1, f2, cid = cellular3(position * _col(scale), jitter, node_seed(seed))
    return f1, f2, f2 - f1, cid


@_impl("fbm")
def _fbm(ctx, uv, scale, octaves, lacunarity, gain, seed):
    return (0.5 + 0.5 * fbm2(uv * _col(scale), octaves, lacunarity, gain, node_seed(seed)),)


@_impl("fbm_3d")
def _fbm_3d(ctx, position, scale, octaves, lacunarity, gain, seed):
    v = _octaves(gradient_noise3, position * _col(scale), octaves, lacunarity, gain,
                 node_seed(seed))
    return (0.5 + 0.5 * v,)


@_impl("ridged_noise")
def _ridged_noise(ctx, uv, scale, octaves, lacunarity, gain, seed):
    def ridge(v):
        r = 1.0 - np.abs(v)
        return r * r

    return (_octaves(gradient_noise2, uv * _col(scale), octaves, lacunarity, gain,
                     node_seed(seed), ridge),)


def _three_units(h, dt):
    h2 = pcg_hash(h)
    h3 = pcg_hash(h2)
    return hash_unit(h, dt), np.stack([hash_unit(h, dt), hash_unit(h2, dt), hash_unit(h3, dt)],
                                      -1)


@_impl("white_noise")
def _white_noise(ctx, value, seed):
    # The float32 bit pattern, as floatBitsToUint sees it on the GPU.
    b = np.ascontiguousarray(value, dtype=np.float32).view(np.uint32)
    h = pcg_hash(b[:, 0] + pcg_hash(b[:, 1] + pcg_hash(b[:, 2] + node_seed(seed))))
    return _three_units(h, value.dtype)


@_impl("cell_hash")
def _cell_hash(ctx, cell, seed):
    c = _as_uint(np.floor(cell))
    return _three_units(hash_cell2(c[:, 0], c[:, 1], node_seed(seed)), cell.dtype)


@_impl("domain_warp")
def _domain_warp(ctx, uv, scale, strength, octaves, seed):
    s = node_seed(seed) * _U(2)
    p = uv * _col(scale)
    two = np.full(len(uv), 2.0, dtype=uv.dtype)
    half = np.full(len(uv), 0.5, dtype=uv.dtype)
    d = np.stack([fbm2(p, octaves, two, half, s), fbm2(p, octaves, two, half, s + _U(101))], -1)
    return (uv + _col(strength) * d,)


# --- patterns ---------------------------------------------------------------------------------
@_impl("bricks")
def _bricks(ctx, uv, count, mortar, bevel, offset, seed, filter_width):
    p = uv * count
    row = np.floor(p[:, 1])
    p = np.stack([p[:, 0] + offset * row, p[:, 1]], -1)
    cell = np.floor(p)
    f = p - cell
    size = 1.0 / np.maximum(np.abs(count), 1e-6)
    border = np.minimum(f, 1.0 - f) * size
    e = np.minimum(border[:, 0], border[:, 1])
    half = 0.5 * mortar
    m = _clamp(_col(mortar) * np.abs(count), 0.0, 1.0)
    w = fwidth(ctx, p) * _col(filter_width)
    mask = (filtered_pulse(p[:, 0] - 0.5 * m[:, 0], 1.0 - m[:, 0], w[:, 0])
            * filtered_pulse(p[:, 1] - 0.5 * m[:, 1], 1.0 - m[:, 1], w[:, 1]))
    t = _clamp((e - half) / np.maximum(bevel, 1e-6), 0.0, 1.0)
    c = _as_uint(cell)
    tile_id = hash_unit(hash_cell2(c[:, 0], c[:, 1], node_seed(seed)), uv.dtype)
    return mask, t * (2.0 - t), tile_id, f


def _direction(angle):
    a = np.radians(angle)
    return np.stack([np.cos(a), np.sin(a)], -1)


@_impl("stripes")
def _stripes(ctx, uv, frequency, width, angle, filter_width):
    x = _dot(uv, _direction(angle)) * frequency
    return (filtered_pulse(x, width, fwidth(ctx, x) * filter_width),)


def _waves(x):
    saw = x - np.floor(x)
    return 0.5 - 0.5 * np.cos(np.asarray(6.28318531, dtype=np.float32).astype(x.dtype) * saw), saw


def _fbm_fixed(p, seed):
    n = len(p)
    dt = p.dtype
    return fbm2(p, np.full(n, 3.0, dt), np.full(n, 2.0, dt), np.full(n, 0.5, dt), _U(seed))


@_impl("wave")
def _wave(ctx, uv, frequency, angle, distortion, detail_scale):
    x = _dot(uv, _direction(angle)) * frequency
    x = x + distortion * _fbm_fixed(uv * _col(detail_scale), 0)
    return _waves(x)


@_impl("rings")
def _rings(ctx, uv, center, frequency, distortion, detail_scale):
    d = uv - center
    x = np.sqrt(_dot(d, d)) * frequency
    x = x + distortion * _fbm_fixed(uv * _col(detail_scale), 7)
    return _waves(x)


def _turns(d):
    a = np.arctan2(d[:, 1], d[:, 0]) * np.asarray(0.15915494, dtype=np.float32).astype(d.dtype)
    t = a - np.floor(a)
    return np.where((d[:, 0] == 0.0) & (d[:, 1] == 0.0), 0.0, t).astype(d.dtype)


@_impl("radial_gradient")
def _radial_gradient(ctx, uv, center):
    return (_turns(uv - center),)


@_impl("spherical_gradient")
def _spherical_gradient(ctx, uv, center, radius):
    d = uv - center
    return (_clamp(1.0 - np.sqrt(_dot(d, d)) / np.maximum(radius, 1e-6), 0.0, 1.0),)


@_impl("filtered_step")
def _filtered_step(ctx, edge, value, filter_width):
    return (filtered_step(edge, value, fwidth(ctx, value) * filter_width),)


@_impl("filtered_smoothstep")
def _filtered_smoothstep(ctx, edge0, edge1, value, filter_width):
    w = fwidth(ctx, value) * filter_width
    a = edge0 - 0.5 * w
    b = edge1 + 0.5 * w
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(b > a, _clamp((value - a) / (b - a), 0.0, 1.0),
                     np.where(value < edge0, 0.0, 1.0)).astype(value.dtype)
    return (t * t * (3.0 - 2.0 * t),)


# --- UV and space -----------------------------------------------------------------------------
@_impl("tiling_offset")
def _tiling_offset(ctx, uv, tiling, offset):
    return (uv * tiling + offset,)


@_impl("rotate_uv")
def _rotate_uv(ctx, uv, angle, pivot):
    a = np.radians(angle)
    c, s = np.cos(a), np.sin(a)
    d = uv - pivot
    return (pivot + np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]], -1),)


@_impl("panner")
def _panner(ctx, uv, speed):
    return (uv + speed * np.asarray(_need(ctx).time, dtype=uv.dtype),)


@_impl("polar_coordinates")
def _polar_coordinates(ctx, uv, center):
    d = uv - center
    return (np.stack([_turns(d), np.sqrt(_dot(d, d))], -1),)


def surface_tangent(ctx) -> np.ndarray:
    """nodeSurfaceTangent (shaders/nodes/space_lib.glsl): Gram-Schmidt of the mesh tangent."""
    n = ctx.normal
    t4 = _tangent4(ctx)
    t = t4[:, :3] - n * _col(_dot(n, t4[:, :3]))
    a = np.where(_col(np.abs(n[:, 0]) < 0.9), np.asarray([1.0, 0.0, 0.0], n.dtype),
                 np.asarray([0.0, 1.0, 0.0], n.dtype))
    t = np.where(_col(_dot(t, t) < 1e-12), a - n * _col(_dot(n, a)), t)
    return t / _col(np.sqrt(_dot(t, t)))


def _tangent4(ctx) -> np.ndarray:
    if ctx.tangent is not None:
        return np.asarray(ctx.tangent, dtype=ctx.normal.dtype)
    return np.broadcast_to(np.asarray([1.0, 0.0, 0.0, 1.0], ctx.normal.dtype),
                           (len(ctx.normal), 4))


def surface_bitangent(ctx) -> np.ndarray:
    s = np.where(_tangent4(ctx)[:, 3] < 0.0, -1.0, 1.0)
    return np.cross(ctx.normal, surface_tangent(ctx)) * _col(s).astype(ctx.normal.dtype)


def _model(ctx) -> np.ndarray:
    m = np.eye(4) if ctx.model is None else np.asarray(ctx.model, dtype=np.float64)
    return m if abs(np.linalg.det(m)) > 1e-12 else np.eye(4)


def world_to_view(ctx) -> np.ndarray:
    """nodeWorldToView: the camera rotation from a symmetric view-projection matrix."""
    if ctx.view_projection is None:
        return np.eye(3)
    m = np.asarray(ctx.view_projection, dtype=np.float64)  # rows as written: m[row, col]
    r0, r1, r2, r3 = m[0, :3], m[1, :3], m[2, :3], m[3, :3]
    z = -r3 if r3 @ r3 > 1e-12 else -r2
    if min(r0 @ r0, r1 @ r1, z @ z) < 1e-12:
        return np.eye(3)
    return np.stack([r0 / np.linalg.norm(r0), r1 / np.linalg.norm(r1), z / np.linalg.norm(z)])


def _rows(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    return (v @ np.asarray(m, dtype=np.float64).T).astype(v.dtype)


@_impl("object_position")
def _object_position(ctx):
    ctx = _need(ctx)
    inv = np.linalg.inv(_model(ctx))
    p = ctx.position
    return ((p @ inv[:3, :3].T + inv[:3, 3]).astype(p.dtype),)


_impl("tangent")(lambda ctx: (surface_tangent(_need(ctx)),))
_impl("bitangent")(lambda ctx: (surface_bitangent(_need(ctx)),))


@_impl("tangent_to_world")
def _tangent_to_world(ctx, vector):
    ctx = _need(ctx)
    t, b, n = surface_tangent(ctx), surface_bitangent(ctx), ctx.normal
    return (t * vector[:, 0:1] + b * vector[:, 1:2] + n * vector[:, 2:3],)


@_impl("world_to_tangent")
def _world_to_tangent(ctx, vector):
    ctx = _need(ctx)
    t, b, n = surface_tangent(ctx), surface_bitangent(ctx), ctx.normal
    return (np.stack([_dot(vector, t), _dot(vector, b), _dot(vector, n)], -1),)


_impl("object_to_world")(lambda ctx, vector: (_rows(_model(_need(ctx))[:3, :3], vector),))
_impl("world_to_object")(
    lambda ctx, vector: (_rows(np.linalg.inv(_model(_need(ctx)))[:3, :3], vector),))
_impl("world_to_view")(lambda ctx, vector: (_rows(world_to_view(_need(ctx)), vector),))
_impl("view_to_world")(lambda ctx, vector: (_rows(world_to_view(_need(ctx)).T, vector),))


def triplanar_weights(normal, sharpness):
    w = np.power(np.abs(normal), _col(np.maximum(sharpness, 1.0)))
    return w / _col(np.maximum(w[:, 0] + w[:, 1] + w[:, 2], 1e-6))


@_impl("triplanar_mapping")
def _triplanar_mapping(ctx, scale, sharpness):
    ctx = _need(ctx)
    p = ctx.position * _col(scale)
    return p[:, [2, 1]], p[:, [0, 2]], p[:, [0, 1]], triplanar_weights(ctx.normal, sharpness)


@_impl("triplanar_texture")
def _triplanar_texture(ctx, tex, scale, sharpness):
    ctx = _need(ctx)
    tex = np.asarray(tex)
    p = ctx.position * _col(scale)
    w = triplanar_weights(ctx.normal, sharpness)
    rgba = (sample_bilinear(tex, p[:, [2, 1]]) * w[:, 0:1]
            + sample_bilinear(tex, p[:, [0, 2]]) * w[:, 1:2]
            + sample_bilinear(tex, p[:, [0, 1]]) * w[:, 2:3]).astype(p.dtype, copy=False)
    return rgba, rgba[:, :3]


# --- normals ----------------------------------------------------------------------------------
@_impl("normal_from_height")
def _normal_from_height(ctx, height, strength):
    ctx = _need(ctx)
    duvdx, duvdy = derivatives(ctx, np.asarray(ctx.uv, dtype=height.dtype))
    dhdx, dhdy = derivatives(ctx, height)
    det = duvdx[:, 0] * duvdy[:, 1] - duvdx[:, 1] * duvdy[:, 0]
    ok = np.abs(det) > 1e-20
    safe = np.where(ok, det, 1.0)
    gx = np.where(ok, (dhdx * duvdy[:, 1] - dhdy * duvdx[:, 1]) / safe, 0.0)
    gy = np.where(ok, (dhdy * duvdx[:, 0] - dhdx * duvdy[:, 0]) / safe, 0.0)
    n = np.stack([-strength * gx, -strength * gy, np.ones_like(height)], -1).astype(height.dtype)
    return (n / _col(np.sqrt(_dot(n, n))),)


@_impl("normal_strength")
def _normal_strength(ctx, normal, strength):
    n = np.concatenate([normal[:, :2] * _col(strength), normal[:, 2:]], axis=-1)
    return (_safe_normalize(n, _Z),)


_impl("flip_green")(lambda ctx, normal: (normal * np.asarray([1.0, -1.0, 1.0], normal.dtype),))


# --- masks ------------------------------------------------------------------------------------
def _nov(ctx):
    return _clamp(_dot(ctx.normal, ctx.view), 0.0, 1.0)


@_impl("fresnel")
def _fresnel(ctx, base, exponent):
    nov = _nov(_need(ctx))
    return (base + (1.0 - base) * np.power(1.0 - nov, np.maximum(exponent, 1e-4)),)


_impl("facing_ratio")(lambda ctx: (_nov(_need(ctx)),))


def _unit_axis(up):
    return up / _col(np.sqrt(np.maximum(_dot(up, up), 1e-12)))


@_impl("slope_mask")
def _slope_mask(ctx, up, threshold, softness):
    d = _dot(_need(ctx).normal, _unit_axis(up))
    s = np.maximum(softness, 1e-4)
    return (_smoothstep(threshold - s, threshold + s, d),)


@_impl("height_mask")
def _height_mask(ctx, up, low, high):
    h = _dot(_need(ctx).position, _unit_axis(up))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(high > low + 1e-6, _clamp((h - low) / (high - low), 0.0, 1.0),
                     np.where(h < low, 0.0, 1.0)).astype(h.dtype)
    return (t * t * (3.0 - 2.0 * t),)


@_impl("curvature")
def _curvature(ctx, scale):
    ctx = _need(ctx)
    dndx, dndy = derivatives(ctx, ctx.normal)
    dpdx, dpdy = derivatives(ctx, ctx.position)
    kx = _dot(dndx, dpdx) / np.maximum(_dot(dpdx, dpdx), 1e-12)
    ky = _dot(dndy, dpdy) / np.maximum(_dot(dpdy, dpdy), 1e-12)
    k = 0.5 * (kx + ky)
    return k, _clamp(k * scale, 0.0, 1.0), _clamp(-k * scale, 0.0, 1.0)
