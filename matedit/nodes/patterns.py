"""Procedural patterns: checker, gradients, bricks, stripes, waves, rings, filtered steps.

Pattern edges are band-limited: kinds with a `filter_width` input box-filter their edges
over `filter_width` pixels of screen-space footprint (`fwidth`); the numpy twins take the
same footprint from the evaluator's pixel grid (`SurfaceArrays.grid`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    _FILTER,
    _SEED,
    _UV,
    MESH_UV,
    UNIT,
    Makers,
    MxBuilder,
    MxRecipe,
    NodeDef,
    Ref,
    Thumbnail,
    _fn,
    _i,
    _o,
    register,
)
from matedit.nodes.noise import _as_uint, fbm2, hash_cell2, hash_unit, node_seed
from matedit.nodes.twin import (
    _clamp,
    _col,
    _dot,
    _mix,
    _turns,
    filtered_pulse,
    filtered_square,
    filtered_step,
    fwidth,
)

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



def _direction(angle):
    a = np.radians(angle)
    return np.stack([np.cos(a), np.sin(a)], -1)


def _waves(x):
    saw = x - np.floor(x)
    return 0.5 - 0.5 * np.cos(np.asarray(6.28318531, dtype=np.float32).astype(x.dtype) * saw), saw


def _fbm_fixed(p, seed):
    n = len(p)
    dt = p.dtype
    return fbm2(p, np.full(n, 3.0, dt), np.full(n, 2.0, dt), np.full(n, 0.5, dt), np.uint32(seed))


def _checker(ctx, uv, scale, color_a, color_b, filter_width):
    p = uv * _col(scale)
    w = fwidth(ctx, p) * _col(filter_width)
    sx = filtered_square(p[:, 0], w[:, 0])
    sy = filtered_square(p[:, 1], w[:, 1])
    mask = 0.5 - 0.5 * sx * sy
    return _mix(color_a, color_b, _col(mask)), mask


def _checkerboard(b: MxBuilder) -> Makers:
    """modulo(floor(u s) + floor(v s), 2) into a mix (the mask built once for both outputs)."""
    shared: dict[str, Ref] = {}

    def mask() -> Ref:
        if "mask" not in shared:
            cell = b.node("floor", "vector2", "cell", ("in", b.node(
                "multiply", "vector2", "scaled", ("in1", b.arg("uv")), ("in2", b.arg("scale")))))
            s = b.node("add", "float", "parity_sum", ("in1", b.extract(cell, 0)),
                       ("in2", b.extract(cell, 1)))
            shared["mask"] = b.node("modulo", "float", "mask", ("in1", s),
                                    ("in2", b.value(2.0, "float")))
        return shared["mask"]

    def color() -> Ref:
        return b.node("mix", "vector3", "", ("bg", b.arg("color_a")), ("fg", b.arg("color_b")),
                      ("mix", mask()))
    return [color, mask]


register(NodeDef(
    "checker", "Checker", "Procedural",
    "A two-colour checkerboard over uv; edges box-filtered over the pixel footprint.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("scale", "float", 8.0, "squares per UV unit"),
            _i("color_a", "vec3", [0.9, 0.9, 0.9]), _i("color_b", "vec3", [0.1, 0.1, 0.1]),
            _i("filter_width", "float", 1.0, "edge blur in pixels (0: hard edges)", (0.0, 4.0))),
    outputs=(_o("color", "vec3"), _o("mask", "float")),
    glsl="node_checker", thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("checkerboard", _checkerboard),
    numpy=_checker,  # modulo(floor(u s) + floor(v s), 2) into a mix
))


def _gradient(ctx, uv, angle):
    a = np.radians(angle)
    d = np.stack([np.cos(a), np.sin(a)], -1)
    extent = np.abs(d[:, 0]) + np.abs(d[:, 1])
    return (_clamp(_dot(uv - 0.5, d) / extent + 0.5, 0.0, 1.0),)


def _linear_ramp(b: MxBuilder) -> Makers:  # clamp(dot(uv - 0.5, d) / (|dx| + |dy|) + 0.5)
    def make() -> Ref:
        ang = b.node("multiply", "float", "rad", ("in1", b.arg("angle")),
                     ("in2", b.value(math.pi / 180.0, "float")))
        c = b.node("cos", "float", "cos", ("in", ang))
        s = b.node("sin", "float", "sin", ("in", ang))
        d = b.node("combine2", "vector2", "dir", ("in1", c), ("in2", s))
        ext = b.node("add", "float", "extent", ("in1", b.node("absval", "float", "abs_x",
                                                             ("in", c))),
                     ("in2", b.node("absval", "float", "abs_y", ("in", s))))
        p = b.node("subtract", "vector2", "centred", ("in1", b.arg("uv")),
                   ("in2", b.value((0.5, 0.5), "vector2")))
        proj = b.node("dotproduct", "float", "proj", ("in1", p), ("in2", d))
        v = b.node("add", "float", "ramp", ("in1", b.node(
            "divide", "float", "norm", ("in1", proj), ("in2", ext))),
            ("in2", b.value(0.5, "float")))
        return b.node("clamp", "float", "", ("in", v), ("low", b.value(0.0, "float")),
                      ("high", b.value(1.0, "float")))
    return [make]


register(NodeDef(
    "gradient", "Gradient", "Procedural", "Linear ramp 0→1 across uv along an angle.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("angle", "float", 0.0, "degrees", (0.0, 360.0))),
    outputs=(_o("value", "float"),),
    glsl="node_gradient", thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("linear_ramp", _linear_ramp),
    numpy=_gradient,  # clamp(dot(uv - 0.5, d) / (|dx| + |dy|) + 0.5)
))


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


# --- patterns --------------------------------------------------------------------------------
_fn("bricks", "Bricks", "Procedural",
    "Running-bond bricks or tiles: a filtered brick mask, a bevelled height, a random value "
    "per brick and each brick's own UV.",
    [_i(*_UV), _i("count", "vec2", [4.0, 8.0], "bricks across and rows up, per UV unit"),
     _i("mortar", "float", 0.02, "mortar width in UV units", (0.0, 0.2)),
     _i("bevel", "float", 0.01, "edge rounding in UV units", (0.0, 0.2)),
     _i("offset", "float", 0.5, "row shift in bricks (0: tiles)", UNIT), _i(*_SEED),
     _i(*_FILTER)],
    [_o("mask", "float"), _o("height", "float"), _o("tile_id", "float"),
     _o("tile_uv", "vec2")], thumbnail=Thumbnail.ALWAYS,
     numpy=_bricks)


def _stripes(ctx, uv, frequency, width, angle, filter_width):
    x = _dot(uv, _direction(angle)) * frequency
    return (filtered_pulse(x, width, fwidth(ctx, x) * filter_width),)


_fn("stripes", "Stripes", "Procedural",
    "Parallel stripes along an angle, band-limited so they never moiré.",
    [_i(*_UV), _i("frequency", "float", 8.0, "stripes per UV unit", (0.0, 128.0)),
     _i("width", "float", 0.5, "stripe share of each period", UNIT),
     _i("angle", "float", 0.0, "degrees", (0.0, 360.0)), _i(*_FILTER)],
    [_o("mask", "float")], thumbnail=Thumbnail.ALWAYS,
    numpy=_stripes)


def _wave(ctx, uv, frequency, angle, distortion, detail_scale):
    x = _dot(uv, _direction(angle)) * frequency
    x = x + distortion * _fbm_fixed(uv * _col(detail_scale), 0)
    return _waves(x)


_fn("wave", "Wave", "Procedural",
    "Bands along an angle with a sine profile, optionally distorted by noise.",
    [_i(*_UV), _i("frequency", "float", 8.0, "bands per UV unit", (0.0, 128.0)),
     _i("angle", "float", 0.0, "degrees", (0.0, 360.0)),
     _i("distortion", "float", 0.0, "noise displacement in bands", (0.0, 4.0)),
     _i("detail_scale", "float", 4.0, "noise features per UV unit", (0.0, 64.0))],
    [_o("value", "float"), _o("saw", "float")], thumbnail=Thumbnail.ALWAYS,
    numpy=_wave)


def _rings(ctx, uv, center, frequency, distortion, detail_scale):
    d = uv - center
    x = np.sqrt(_dot(d, d)) * frequency
    x = x + distortion * _fbm_fixed(uv * _col(detail_scale), 7)
    return _waves(x)


_fn("rings", "Rings", "Procedural",
    "Concentric rings about a centre with a sine profile and noise distortion (wood, "
    "ripples); saw is the ramp within each ring.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5]),
     _i("frequency", "float", 8.0, "rings per UV unit", (0.0, 128.0)),
     _i("distortion", "float", 0.0, "noise displacement in rings", (0.0, 4.0)),
     _i("detail_scale", "float", 4.0, "noise features per UV unit", (0.0, 64.0))],
    [_o("value", "float"), _o("saw", "float")], thumbnail=Thumbnail.ALWAYS,
    numpy=_rings)


def _radial_gradient(ctx, uv, center):
    return (_turns(uv - center),)


_fn("radial_gradient", "Radial Gradient", "Procedural",
    "The angle about a centre, 0 → 1 counter-clockwise from +u.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5])], [_o("value", "float")],
    thumbnail=Thumbnail.ALWAYS,
    numpy=_radial_gradient)


def _spherical_gradient(ctx, uv, center, radius):
    d = uv - center
    return (_clamp(1.0 - np.sqrt(_dot(d, d)) / np.maximum(radius, 1e-6), 0.0, 1.0),)


def _falloff_from_centre(b: MxBuilder) -> Makers:  # clamp(1 − |uv − c| / max(radius, 1e-6))
    def make() -> Ref:
        r = b.node("magnitude", "float", "r", ("in", b.node(
            "subtract", "vector2", "d", ("in1", b.arg(0)), ("in2", b.arg(1)))))
        rad = b.node("max", "float", "radius", ("in1", b.arg(2)),
                     ("in2", b.value(1e-6, "float")))
        f = b.node("subtract", "float", "falloff", ("in1", b.value(1.0, "float")), (
            "in2", b.node("divide", "float", "ratio", ("in1", r), ("in2", rad))))
        return b.node("clamp", "float", "", ("in", f), ("low", b.value(0.0, "float")),
                      ("high", b.value(1.0, "float")))
    return [make]


_fn("spherical_gradient", "Spherical Gradient", "Procedural",
    "1 at the centre falling to 0 at radius.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5]),
     _i("radius", "float", 0.5, "UV units", (0.0, 2.0))], [_o("value", "float")],
    thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("falloff_from_centre", _falloff_from_centre),
    numpy=_spherical_gradient)


def _filtered_step(ctx, edge, value, filter_width):
    return (filtered_step(edge, value, fwidth(ctx, value) * filter_width),)


_fn("filtered_step", "Filtered Step", "Procedural",
    "step(edge, value) with the edge blurred over the pixel footprint of value: an "
    "anti-aliased threshold for any pattern.",
    [_i("edge", "float", 0.5), _i("value", "float"), _i(*_FILTER)], [_o("result", "float")],
    numpy=_filtered_step)


def _filtered_smoothstep(ctx, edge0, edge1, value, filter_width):
    w = fwidth(ctx, value) * filter_width
    a = edge0 - 0.5 * w
    b = edge1 + 0.5 * w
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(b > a, _clamp((value - a) / (b - a), 0.0, 1.0),
                     np.where(value < edge0, 0.0, 1.0)).astype(value.dtype)
    return (t * t * (3.0 - 2.0 * t),)


_fn("filtered_smoothstep", "Filtered Smooth Step", "Procedural",
    "smoothstep(edge0, edge1, value) widened by the pixel footprint of value, so a narrow "
    "ramp never aliases.",
    [_i("edge0", "float", 0.4), _i("edge1", "float", 0.6), _i("value", "float"),
     _i(*_FILTER)], [_o("result", "float")],
     numpy=_filtered_smoothstep)
