"""Tangent-space normal kinds."""

from __future__ import annotations

from typing import TYPE_CHECKING

from matedit.nodes.kind import (
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
from matedit.nodes.twin import _Z, _col, _dot, _mix, _need, _safe_normalize, derivatives

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



def _unpack_normal(ctx, packed, strength):
    n = packed * 2.0 - 1.0
    n = np.concatenate([n[:, :2] * _col(strength), n[:, 2:]], axis=-1)
    return (_safe_normalize(n, _Z),)


# --- normals ---------------------------------------------------------------------------------
def _decode_normal(b: MxBuilder) -> Makers:  # normalize((2 p - 1) * (s, s, 1))
    def make() -> Ref:
        x = b.node("subtract", "vector3", "signed", ("in1", b.node(
            "multiply", "vector3", "twice", ("in1", b.arg("packed")),
            ("in2", b.value(2.0, "float")))), ("in2", b.value(1.0, "float")))
        st = b.arg("strength")
        k = b.node("combine3", "vector3", "strength", ("in1", st), ("in2", st),
                   ("in3", b.value(1.0, "float")))
        return b.node("normalize", "vector3", "", ("in", b.node(
            "multiply", "vector3", "scaled", ("in1", x), ("in2", k))))
    return [make]


register(NodeDef(
    "unpack_normal", "Unpack Normal", "Normal",
    "Tangent-space normal from a normal-map texel in [0, 1] (OpenGL convention, +Y up).",
    inputs=(_i("packed", "vec3", [0.5, 0.5, 1.0]), _i("strength", "float", 1.0, "", (0.0, 2.0))),
    outputs=(_o("normal", "vec3"),),
    glsl="node_unpack_normal",
    mtlx=MxRecipe("decode_normal", _decode_normal),
    numpy=_unpack_normal,  # normalize((2 p - 1) * (s, s, 1))
))


def _blend_normals(ctx, base, detail):
    # Barré-Brisebois & Hill 2012, "Blending in Detail": reoriented normal mapping.
    t = base + np.asarray(_Z, dtype=base.dtype)
    u = detail * np.asarray((-1.0, -1.0, 1.0), dtype=detail.dtype)
    r = t * _col(_dot(t, u)) / t[:, 2:3] - u
    return (_safe_normalize(r, _Z),)


def _reoriented_normals(b: MxBuilder) -> Makers:
    """Reoriented normal mapping (Barré-Brisebois & Hill 2012), node by node."""
    def make() -> Ref:
        t = b.node("add", "vector3", "t", ("in1", b.arg("base")),
                   ("in2", b.value((0.0, 0.0, 1.0), "vector3")))
        u = b.node("multiply", "vector3", "u", ("in1", b.arg("detail")),
                   ("in2", b.value((-1.0, -1.0, 1.0), "vector3")))
        tu = b.node("dotproduct", "float", "tu", ("in1", t), ("in2", u))
        tz = b.extract(t, 2)
        r = b.node("subtract", "vector3", "r", ("in1", b.node(
            "divide", "vector3", "scaled", ("in1", b.node(
                "multiply", "vector3", "tdot", ("in1", t), ("in2", tu))), ("in2", tz))),
            ("in2", u))
        return b.node("normalize", "vector3", "", ("in", r))
    return [make]


register(NodeDef(
    "blend_normals", "Blend Normals", "Normal",
    "Detail normal on a base normal by reoriented normal mapping (Barré-Brisebois & Hill 2012).",
    inputs=(_i("base", "vec3", [0.0, 0.0, 1.0]), _i("detail", "vec3", [0.0, 0.0, 1.0])),
    outputs=(_o("normal", "vec3"),),
    glsl="node_blend_normals", mtlx=MxRecipe("reoriented_normals", _reoriented_normals),
    numpy=_blend_normals,  # reoriented normal mapping
))


def _flatten_normal(ctx, normal, flatness):
    n = _mix(normal, np.asarray(_Z, dtype=normal.dtype), _col(flatness))
    return (_safe_normalize(n, _Z),)


def _mix_towards_z(b: MxBuilder) -> Makers:  # normalize(mix(n, +Z, flatness))
    def make() -> Ref:
        m = b.node("mix", "vector3", "towards_z", ("bg", b.arg("normal")),
                   ("fg", b.value((0.0, 0.0, 1.0), "vector3")), ("mix", b.arg("flatness")))
        return b.node("normalize", "vector3", "", ("in", m))
    return [make]


register(NodeDef(
    "flatten_normal", "Flatten Normal", "Normal",
    "Moves a tangent-space normal towards (0, 0, 1) by flatness.",
    inputs=(_i("normal", "vec3", [0.0, 0.0, 1.0]), _i("flatness", "float", 0.5, "", UNIT)),
    outputs=(_o("normal", "vec3"),),
    glsl="node_flatten_normal",
    mtlx=MxRecipe("mix_towards_z", _mix_towards_z),
    numpy=_flatten_normal,  # normalize(mix(n, +Z, flatness))
))


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


_fn("normal_from_height", "Normal from Height", "Normal",
    "Tangent-space normal of a height field from its screen-space derivatives (bump "
    "mapping without a texture): strength is the relief depth, in UV units, of height 1.",
    [_i("height", "float", 0.0, "", UNIT),
     _i("strength", "float", 0.005, "relief depth in UV units", (0.0, 0.1))],
    [_o("normal", "vec3")], thumbnail=Thumbnail.ALWAYS,
    numpy=_normal_from_height)


def _normal_strength(ctx, normal, strength):
    n = np.concatenate([normal[:, :2] * _col(strength), normal[:, 2:]], axis=-1)
    return (_safe_normalize(n, _Z),)


_fn("normal_strength", "Normal Strength", "Normal",
    "Scales a tangent-space normal's tilt (0: flat, 1: unchanged, 2: twice as steep).",
    [_i("normal", "vec3", [0.0, 0.0, 1.0]), _i("strength", "float", 1.0, "", (0.0, 4.0))],
    [_o("normal", "vec3")],
    numpy=_normal_strength)
_fn("flip_green", "Flip Green", "Normal",
    "Negates a tangent-space normal's Y: converts DirectX-convention normal maps to ours.",
    [_i("normal", "vec3", [0.0, 0.0, 1.0])], [_o("normal", "vec3")],
    numpy=lambda ctx, normal: (normal * np.asarray([1.0, -1.0, 1.0], normal.dtype),))
