"""Kinds that split, mask, join and pass vectors through."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    LOWERED,
    Makers,
    MxBuilder,
    MxRecipe,
    NodeDef,
    PortsRule,
    Ref,
    Role,
    SettingDef,
    T,
    Thumbnail,
    _i,
    _o,
    register,
)

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np


# Components of a MaterialX value type.
_WIDTH = {"float": 1, "vector2": 2, "vector3": 3, "vector4": 4}


# --- vectors ---------------------------------------------------------------------------------
def _mask(b: MxBuilder) -> Makers:  # the chosen components, combined
    idx = ["xyzw".index(c) for c in b.data["channels"]]
    return [lambda: b.combine([b.component(0, i) for i in idx], b.result_type)]


register(NodeDef(
    "component_mask", "Component Mask", "Vector",
    "Keeps the chosen channels of a vector (e.g. 'xy', 'b', 'rgb').",
    inputs=(_i("value", T),), outputs=(_o("result", T),),
    settings=(SettingDef("channels", "channels", "xy", "up to 4 of x y z w (or r g b a)"),),
    ports_rule=PortsRule.CHANNELS,
    role=Role.COMPONENT_MASK, lowered=True, mtlx=MxRecipe("mask", _mask),  # extract / combineN
))


def _split(ctx, value):
    cols = value[:, None] if value.ndim == 1 else value
    zero = np.zeros(len(cols), dtype=cols.dtype)
    return tuple(cols[:, i] if i < cols.shape[1] else zero for i in range(4))


def _extract_each(b: MxBuilder) -> Makers:  # extract per component
    def component(i: int) -> Callable[[], Ref]:
        return lambda: b.component(0, i)
    return [component(i) for i in range(4)]


register(NodeDef(
    "split", "Split", "Vector", "Splits a vector into its components (missing ones read 0).",
    inputs=(_i("value", "vec4"),),
    outputs=(_o("x", "float"), _o("y", "float"), _o("z", "float"), _o("w", "float")),
    glsl="node_split", ports_rule=PortsRule.COMPONENTS,
    mtlx=MxRecipe("extract_each", _extract_each),
    numpy=_split,  # extract per component
))


def _concatenate(b: MxBuilder) -> Makers:  # the operands' components, combined
    def make() -> Ref:
        parts = []
        for k in range(b.operands):
            parts += [b.component(k, i) for i in range(_WIDTH[b.arg_type(k)])]
        return b.combine(parts, b.result_type)
    return [make]


register(NodeDef(
    "append", "Append", "Vector", "Concatenates two values into a longer vector (up to 4).",
    inputs=(_i("a", T), _i("b", T)), outputs=(_o("result", T),),
    ports_rule=PortsRule.CONCATENATION,
    role=Role.APPEND, lowered=True, mtlx=MxRecipe("concatenate", _concatenate),
))


def _combine(ctx, x, y, z, w):
    return np.stack([x, y], -1), np.stack([x, y, z], -1), np.stack([x, y, z, w], -1)


def _combine_n(b: MxBuilder) -> Makers:  # combine2, combine3, combine4
    def first(k: int) -> Callable[[], Ref]:
        return lambda: b.combine([b.arg(i) for i in range(k)], f"vector{k}")
    return [first(k) for k in (2, 3, 4)]


register(NodeDef(
    "combine", "Combine", "Vector", "Builds vectors from four scalars.",
    inputs=(_i("x", "float"), _i("y", "float"), _i("z", "float"), _i("w", "float", 1.0)),
    outputs=(_o("xy", "vec2"), _o("xyz", "vec3"), _o("xyzw", "vec4")),
    glsl="node_combine", mtlx=MxRecipe("combine_n", _combine_n),
    numpy=_combine,  # combine2/3/4
))
register(NodeDef(
    "reroute", "Reroute", "Utility", "A wire waypoint; passes its value through.",
    inputs=(_i("value", T),), outputs=(_o("value", T),),
    ports_rule=PortsRule.PASSTHROUGH,
    role=Role.REROUTE, lowered=True, mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
))
