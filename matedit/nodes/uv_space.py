"""Coordinates: UVs, the surface's geometry and time, space transforms, triplanar mapping."""

from __future__ import annotations

from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    _UV,
    UNIT,
    Makers,
    MxBuilder,
    MxNode,
    MxRecipe,
    NodeDef,
    Ref,
    T,
    Thumbnail,
    _fn,
    _i,
    _o,
    _op,
    register,
)
from matedit.nodes.maths import multiply_then_add
from matedit.nodes.textures import sample_bilinear
from matedit.nodes.twin import SurfaceArrays, _col, _dot, _need, _turns

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



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


def triplanar_weights(normal, sharpness):
    w = np.power(np.abs(normal), _col(np.maximum(sharpness, 1.0)))
    return w / _col(np.maximum(w[:, 0] + w[:, 1] + w[:, 2], 1e-6))


def _texcoord(ctx: SurfaceArrays, tiling, offset):
    return (ctx.uv * tiling + offset,)


# --- geometry --------------------------------------------------------------------------------
def _tiled_texcoord(b: MxBuilder) -> Makers:  # texcoord * tiling + offset
    return [lambda: b.node("add", "vector2", "", ("in1", b.node(
        "multiply", "vector2", "tile", ("in1", b.uv()), ("in2", b.arg(0)))), ("in2", b.arg(1)))]


register(NodeDef(
    "texcoord", "Texture Coordinate", "Coordinates",
    "The mesh's UV set, tiled and offset.",
    inputs=(_i("tiling", "vec2", [1.0, 1.0], "repeats across the surface"),
            _i("offset", "vec2", [0.0, 0.0], "shift in UV units")),
    outputs=(_o("uv", "vec2"),),
    glsl="node_texcoord", impure=True,
    mtlx=MxRecipe("tiled_texcoord", _tiled_texcoord),
    numpy=_texcoord,  # texcoord * tiling + offset
))
register(NodeDef("world_position", "World Position", "Coordinates",
                 "Surface position in world space (metres).",
                 outputs=(_o("position", "vec3"),), glsl="node_world_position",
                 impure=True, geometry=True, mtlx=MxNode("position", ()),
                 numpy=lambda ctx: (ctx.position,)))
register(NodeDef("world_normal", "World Normal", "Coordinates",
                 "Interpolated geometric normal in world space (before normal maps).",
                 outputs=(_o("normal", "vec3"),), glsl="node_world_normal",
                 impure=True, geometry=True, mtlx=MxNode("normal", ()),
                 numpy=lambda ctx: (ctx.normal,)))


def _negated_viewdirection(b: MxBuilder) -> Makers:  # -viewdirection: ours points at the eye
    return [lambda: b.node("multiply", "vector3", "", (
        "in1", b.node("viewdirection", "vector3", "eye", space="world")),
        ("in2", b.value(-1.0, "float")))]


register(NodeDef("view_direction", "View Direction", "Coordinates",
                 "Unit vector from the surface towards the camera, world space.",
                 outputs=(_o("direction", "vec3"),), glsl="node_view_direction",
                 impure=True, geometry=True,
                 mtlx=MxRecipe("negated_viewdirection", _negated_viewdirection),
                 numpy=lambda ctx: (ctx.view,)))
register(NodeDef("time", "Time", "Coordinates", "Seconds since the preview started.",
                 outputs=(_o("seconds", "float"),), glsl="node_time",
                 impure=True, geometry=True, thumbnail=Thumbnail.NEVER,
                 mtlx=MxNode("time", ()),
                 numpy=lambda ctx: (np.full(ctx.count, ctx.time, dtype=ctx.uv.dtype),)))


def _tiling_offset(ctx, uv, tiling, offset):
    return (uv * tiling + offset,)


def _bc_w(weights, i, like):
    w = weights[:, i]
    return w if like.ndim == 1 else w[:, None]


# --- UV and space ----------------------------------------------------------------------------
_fn("tiling_offset", "Tiling and Offset", "Coordinates", "uv × tiling + offset.",
    [_i(*_UV), _i("tiling", "vec2", [1.0, 1.0]), _i("offset", "vec2", [0.0, 0.0])],
    [_o("uv", "vec2")], mtlx=MxRecipe("multiply_then_add", multiply_then_add),
    numpy=_tiling_offset)


def _rotate_uv(ctx, uv, angle, pivot):
    a = np.radians(angle)
    c, s = np.cos(a), np.sin(a)
    d = uv - pivot
    return (pivot + np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]], -1),)


def _rotate_about_pivot(b: MxBuilder) -> Makers:  # rotate2d turns clockwise: by −angle about 0
    def make() -> Ref:
        d = b.node("subtract", "vector2", "centred", ("in1", b.arg(0)), ("in2", b.arg(2)))
        turn = b.node("multiply", "float", "cw", ("in1", b.arg(1)),
                      ("in2", b.value(-1.0, "float")))
        r = b.node("rotate2d", "vector2", "rotate", ("in", d), ("amount", turn))
        return b.node("add", "vector2", "", ("in1", r), ("in2", b.arg(2)))
    return [make]


_fn("rotate_uv", "Rotate UV", "Coordinates", "Rotates uv about a pivot, counter-clockwise.",
    [_i(*_UV), _i("angle", "float", 0.0, "degrees", (0.0, 360.0)),
     _i("pivot", "vec2", [0.5, 0.5])], [_o("uv", "vec2")],
    mtlx=MxRecipe("rotate_about_pivot", _rotate_about_pivot),
    numpy=_rotate_uv)


def _panner(ctx, uv, speed):
    return (uv + speed * np.asarray(_need(ctx).time, dtype=uv.dtype),)


_fn("panner", "Panner", "Coordinates", "Scrolls uv over time: uv + speed × seconds.",
    [_i(*_UV), _i("speed", "vec2", [0.1, 0.0], "UV units per second")], [_o("uv", "vec2")],
    impure=True, geometry=True,
    numpy=_panner)


def _polar_coordinates(ctx, uv, center):
    d = uv - center
    return (np.stack([_turns(d), np.sqrt(_dot(d, d))], -1),)


_fn("polar_coordinates", "Polar Coordinates", "Coordinates",
    "uv as (angle in turns, distance) about a centre: wraps patterns around a point.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5])], [_o("uv", "vec2")],
    numpy=_polar_coordinates)


def _object_position(ctx):
    ctx = _need(ctx)
    inv = np.linalg.inv(_model(ctx))
    p = ctx.position
    return ((p @ inv[:3, :3].T + inv[:3, 3]).astype(p.dtype),)


_fn("object_position", "Object Position", "Coordinates",
    "Surface position in the object's own space.", [], [_o("position", "vec3")],
    impure=True, geometry=True,
    numpy=_object_position)
_fn("tangent", "Tangent", "Coordinates",
    "World-space unit tangent (along +u), orthogonal to the normal.", [],
    [_o("tangent", "vec3")], impure=True, geometry=True,
    numpy=lambda ctx: (surface_tangent(_need(ctx)),))
_fn("bitangent", "Bitangent", "Coordinates",
    "World-space unit bitangent (along +v), normal × tangent with the mesh's handedness.",
    [], [_o("bitangent", "vec3")], impure=True, geometry=True,
    numpy=lambda ctx: (surface_bitangent(_need(ctx)),))
_V3 = ("vector", "vec3", [0.0, 0.0, 1.0], "a direction")


def _tangent_to_world(ctx, vector):
    ctx = _need(ctx)
    t, b, n = surface_tangent(ctx), surface_bitangent(ctx), ctx.normal
    return (t * vector[:, 0:1] + b * vector[:, 1:2] + n * vector[:, 2:3],)


def _world_to_tangent(ctx, vector):
    ctx = _need(ctx)
    t, b, n = surface_tangent(ctx), surface_bitangent(ctx), ctx.normal
    return (np.stack([_dot(vector, t), _dot(vector, b), _dot(vector, n)], -1),)


# (from, to) -> the twin of <from>_to_<to>
_TRANSFORMS = {
    ("tangent", "world"): _tangent_to_world,
    ("world", "tangent"): _world_to_tangent,
    ("object", "world"):
        lambda ctx, vector: (_rows(_model(_need(ctx))[:3, :3], vector),),
    ("world", "object"):
        lambda ctx, vector: (_rows(np.linalg.inv(_model(_need(ctx)))[:3, :3], vector),),
    ("world", "view"): lambda ctx, vector: (_rows(world_to_view(_need(ctx)), vector),),
    ("view", "world"): lambda ctx, vector: (_rows(world_to_view(_need(ctx)).T, vector),),
}
for (_a, _b), _twin in _TRANSFORMS.items():
    _fn(f"{_a}_to_{_b}", f"{_a.title()} to {_b.title()}", "Coordinates",
        f"Transforms a direction from {_a} space to {_b} space.", [_i(*_V3)],
        [_o("vector", "vec3")], impure=True, geometry=True, numpy=_twin)


def _triplanar_mapping(ctx, scale, sharpness):
    ctx = _need(ctx)
    p = ctx.position * _col(scale)
    return p[:, [2, 1]], p[:, [0, 2]], p[:, [0, 1]], triplanar_weights(ctx.normal, sharpness)


_fn("triplanar_mapping", "Triplanar Mapping", "Coordinates",
    "Three planar projections of world position (onto YZ, XZ and XY) and their blend "
    "weights from the normal: feed each UV to a procedural, then a Triplanar Blend.",
    [_i("scale", "float", 1.0, "repeats per metre", (0.0, 64.0)),
     _i("sharpness", "float", 4.0, "blend sharpness (higher: crisper seams)", (1.0, 64.0))],
    [_o("uv_x", "vec2"), _o("uv_y", "vec2"), _o("uv_z", "vec2"), _o("weights", "vec3")],
    impure=True, geometry=True,
    numpy=_triplanar_mapping)


def _weighted_sum(b: MxBuilder) -> Makers:  # x w.x + y w.y + z w.z
    def make() -> Ref:
        w = b.arg(3)
        terms = [b.node("multiply", None, c, ("in1", b.arg(i)), ("in2", b.extract(w, i)))
                 for i, c in enumerate("xyz")]
        s = b.node("add", None, "xy", ("in1", terms[0]), ("in2", terms[1]))
        return b.node("add", None, "", ("in1", s), ("in2", terms[2]))
    return [make]


_op("triplanar_blend", "Triplanar Blend",
    "({x} * {weights}.x + {y} * {weights}.y + {z} * {weights}.z)",
    [_i("x", T), _i("y", T), _i("z", T), _i("weights", "vec3", [1 / 3] * 3, "", UNIT)],
    "Blends three projections by the Triplanar Mapping weights.", category="Coordinates",
    mtlx=MxRecipe("weighted_sum", _weighted_sum),
    numpy=lambda ctx, x, y, z, weights: (x * _bc_w(weights, 0, x) + y * _bc_w(weights, 1, x)
                                   + z * _bc_w(weights, 2, x),))  # x w.x + y w.y + z w.z


def _triplanar_texture(ctx, tex, scale, sharpness):
    ctx = _need(ctx)
    tex = np.asarray(tex)
    p = ctx.position * _col(scale)
    w = triplanar_weights(ctx.normal, sharpness)
    rgba = (sample_bilinear(tex, p[:, [2, 1]]) * w[:, 0:1]
            + sample_bilinear(tex, p[:, [0, 2]]) * w[:, 1:2]
            + sample_bilinear(tex, p[:, [0, 1]]) * w[:, 2:3]).astype(p.dtype, copy=False)
    return rgba, rgba[:, :3]


_fn("triplanar_texture", "Triplanar Texture", "Texture",
    "Samples a texture by triplanar projection of world position, no UVs needed.",
    [_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
     _i("scale", "float", 1.0, "repeats per metre", (0.0, 64.0)),
     _i("sharpness", "float", 4.0, "", (1.0, 64.0))],
    [_o("rgba", "vec4"), _o("rgb", "vec3")], thumbnail=Thumbnail.ALWAYS, impure=True, geometry=True,
    numpy=_triplanar_texture)
