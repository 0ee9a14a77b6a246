"""Maths, vector and logic kinds: GLSL built-ins as inline templates, a few functions."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    UNIT,
    Makers,
    MxBuilder,
    MxNode,
    MxRecipe,
    Ref,
    T,
    _bin,
    _i,
    _op,
    _un,
)
from matedit.nodes.twin import _clamp, _col, _dot, _mix, _smoothstep, _where, fwidth

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np


# --- maths -----------------------------------------------------------------------------------
_op("add", "Add", "({a} + {b})", [_i("a", T), _i("b", T)], "a + b, per component.",
    mtlx=_bin("add"),
    numpy=lambda ctx, a, b: (a + b,))
_op("subtract", "Subtract", "({a} - {b})", [_i("a", T), _i("b", T)], "a − b, per component.",
    mtlx=_bin("subtract"),
    numpy=lambda ctx, a, b: (a - b,))
_op("multiply", "Multiply", "({a} * {b})", [_i("a", T, 1.0), _i("b", T, 1.0)],
    "a × b, per component.", mtlx=_bin("multiply"),
    numpy=lambda ctx, a, b: (a * b,))


def _divide(ctx, a, b):
    with np.errstate(divide="ignore", invalid="ignore"):  # the GPU's infinity, as documented
        return (a / b,)


_op("divide", "Divide", "({a} / {b})", [_i("a", T, 1.0), _i("b", T, 1.0)],
    "a ÷ b, per component (division by zero gives the GPU's infinity).",
    mtlx=_bin("divide"),
    numpy=_divide)
_op("lerp", "Lerp", "mix({a}, {b}, {alpha})",
    [_i("a", T), _i("b", T, 1.0), _i("alpha", T, 0.5, "blend factor", UNIT)],
    "Linear interpolation: a at alpha 0, b at alpha 1.",
    mtlx=MxNode("mix", (("a", "bg"), ("b", "fg"), ("alpha", "mix"))),
    numpy=lambda ctx, a, b, alpha: (_mix(a, b, alpha),))
_op("clamp", "Clamp", "clamp({value}, {min}, {max})",
    [_i("value", T), _i("min", T, 0.0), _i("max", T, 1.0)], "Clamps value into [min, max].",
    mtlx=MxNode("clamp", (("value", "in"), ("min", "low"), ("max", "high"))),
    numpy=lambda ctx, value, lo, hi: (_clamp(value, lo, hi),))
_op("saturate", "Saturate", "clamp({value}, 0.0, 1.0)", [_i("value", T)],
    "Clamps value into [0, 1].",
    mtlx=MxNode("clamp", (("value", "in"),), (("low", 0.0), ("high", 1.0))),
    numpy=lambda ctx, value: (_clamp(value, 0.0, 1.0),))


def _subtract_from_one(b: MxBuilder) -> Makers:  # subtract(1, value)
    return [lambda: b.node("subtract", None, "", ("in1", b.value(1.0)), ("in2", b.arg(0)))]


_op("one_minus", "One Minus", "(1.0 - {value})", [_i("value", T)], "1 − value.",
    mtlx=MxRecipe("subtract_from_one", _subtract_from_one),
    numpy=lambda ctx, value: (1.0 - value,))


def _power(ctx, base, exponent):
    # pow(max(b, 0), e); numpy's 0 ** -e is inf like the GPU's exp2(-e * log2(0)).
    with np.errstate(divide="ignore", invalid="ignore"):
        return (np.power(np.maximum(base, 0.0), exponent),)


def positive_power(b: MxBuilder) -> Makers:
    """power(max(x, 0), e): GLSL's pow is undefined for negative x (power, gamma)."""
    return [lambda: b.node("power", None, "", (
        "in1", b.node("max", None, "max", ("in1", b.arg(0)), ("in2", b.value(0.0)))),
        ("in2", b.arg(1)))]


_op("power", "Power", "pow(max({base}, 0.0), {exponent})",
    [_i("base", T, 1.0), _i("exponent", T, 1.0)],
    "base raised to exponent; negative bases clamp to 0 (GLSL's pow is undefined there).",
    mtlx=MxRecipe("positive_power", positive_power),
    reads=MxNode("power", (("base", "in1"), ("exponent", "in2"))),  # power(max(base, 0), exponent)
    numpy=_power)
_op("abs", "Abs", "abs({value})", [_i("value", T)], "Absolute value.", mtlx=_un("absval"),
    numpy=lambda ctx, value: (np.abs(value),))
_op("min", "Min", "min({a}, {b})", [_i("a", T), _i("b", T)], "Smaller of a and b.",
    mtlx=_bin("min"),
    numpy=lambda ctx, a, b: (np.minimum(a, b),))
_op("max", "Max", "max({a}, {b})", [_i("a", T), _i("b", T)], "Larger of a and b.",
    mtlx=_bin("max"),
    numpy=lambda ctx, a, b: (np.maximum(a, b),))


def _dot_or_multiply(b: MxBuilder) -> Makers:  # the stdlib's dotproduct takes vectors only
    category = "multiply" if b.arg_type(0) == "float" else "dotproduct"
    return [lambda: b.node(category, "float", "", ("in1", b.arg(0)), ("in2", b.arg(1)))]


_op("dot", "Dot", "dot({a}, {b})", [_i("a", T), _i("b", T)], "Dot product.", out_type="float",
    category="Vector", mtlx=MxRecipe("dot_or_multiply", _dot_or_multiply), reads=_bin("dotproduct"),
    numpy=lambda ctx, a, b: (_dot(a, b),))
_op("cross", "Cross", "cross({a}, {b})",
    [_i("a", "vec3", [1.0, 0.0, 0.0]), _i("b", "vec3", [0.0, 1.0, 0.0])],
    "Cross product of two vec3.", out_type="vec3", category="Vector",
    mtlx=_bin("crossproduct"),
    numpy=lambda ctx, a, b: (np.cross(a, b),))


def _normalize(ctx, value):
    if value.ndim == 1:
        return (np.sign(value),)
    len2 = np.sum(value * value, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = value * _col(1.0 / np.sqrt(len2))
    return (np.where(_col(len2 > 0.0), unit, value),)


def _normalize_vector(b: MxBuilder) -> Makers | None:
    if b.arg_type(0) == "float":
        return None  # the stdlib normalizes vectors only: a float's sign bakes
    return [lambda: b.node("normalize", None, "", ("in", b.arg(0)))]


_op("normalize", "Normalize", None, [_i("value", T, 1.0)],
    "Unit vector in the direction of value (zero stays zero).", category="Vector",
    glsl="node_normalize", mtlx=MxRecipe("normalize_vector", _normalize_vector),
    reads=_un("normalize"),
    numpy=_normalize)


def _magnitude_or_absval(b: MxBuilder) -> Makers:  # magnitude, or absval of a float
    category = "absval" if b.arg_type(0) == "float" else "magnitude"
    return [lambda: b.node(category, "float", "", ("in", b.arg(0)))]


_op("length", "Length", "length({value})", [_i("value", T)], "Euclidean length.",
    out_type="float", category="Vector", mtlx=MxRecipe("magnitude_or_absval", _magnitude_or_absval),
    reads=_un("magnitude"),  # magnitude, or absval
    numpy=lambda ctx, value: (np.sqrt(_dot(value, value)),))


def _sqrt(ctx, value):
    return (np.sqrt(np.maximum(value, 0.0)),)


def _positive_sqrt(b: MxBuilder) -> Makers:  # sqrt(max(value, 0))
    return [lambda: b.node("sqrt", None, "", (
        "in", b.node("max", None, "max", ("in1", b.arg(0)), ("in2", b.value(0.0)))))]


_op("sqrt", "Square Root", "sqrt(max({value}, 0.0))", [_i("value", T, 1.0)],
    "Square root; negative input clamps to 0.",
    mtlx=MxRecipe("positive_sqrt", _positive_sqrt), reads=_un("sqrt"),  # sqrt(max(value, 0))
    numpy=_sqrt)
_op("sin", "Sine", "sin({value})", [_i("value", T)], "Sine of radians.", mtlx=_un("sin"),
    numpy=lambda ctx, value: (np.sin(value),))
_op("cos", "Cosine", "cos({value})", [_i("value", T)], "Cosine of radians.", mtlx=_un("cos"),
    numpy=lambda ctx, value: (np.cos(value),))
_op("frac", "Frac", "fract({value})", [_i("value", T)], "Fractional part, value − floor(value).",
    mtlx=MxNode("modulo", (("value", "in1"),), (("in2", 1.0),)),  # x - floor(x)
    numpy=lambda ctx, value: (value - np.floor(value),))
_op("floor", "Floor", "floor({value})", [_i("value", T)], "Largest integer not above value.",
    mtlx=_un("floor"),
    numpy=lambda ctx, value: (np.floor(value),))


def _floor_step(b: MxBuilder) -> Makers:  # clamp(floor(value - edge) + 1, 0, 1)
    def make() -> Ref:
        d = b.node("subtract", None, "d", ("in1", b.arg(1)), ("in2", b.arg(0)))
        f = b.node("floor", None, "floor", ("in", d))
        a = b.node("add", None, "add", ("in1", f), ("in2", b.value(1.0)))
        return b.node("clamp", None, "", ("in", a), ("low", b.value(0.0)),
                      ("high", b.value(1.0)))
    return [make]


# GLSL step(edge, x): 0 where x < edge, else 1.
_op("step", "Step", "step({edge}, {value})", [_i("edge", T, 0.5), _i("value", T)],
    "0 below edge, 1 at or above it.",
    mtlx=MxRecipe("floor_step", _floor_step),
    numpy=lambda ctx, edge, value: (np.where(value < edge, 0.0, 1.0).astype(value.dtype),))
_op("smoothstep", "Smooth Step", "smoothstep({edge0}, {edge1}, {value})",
    [_i("edge0", T, 0.0), _i("edge1", T, 1.0), _i("value", T)],
    "Hermite ramp from 0 at edge0 to 1 at edge1.",
    mtlx=MxNode("smoothstep", (("value", "in"), ("edge0", "low"), ("edge1", "high"))),
    numpy=lambda ctx, e0, e1, value: (_smoothstep(e0, e1, value),))


def _remap(ctx, value, in_min, in_max, out_min, out_max):
    with np.errstate(divide="ignore", invalid="ignore"):
        return (out_min + (value - in_min) / (in_max - in_min) * (out_max - out_min),)


_op("remap", "Remap", None,
    [_i("value", T), _i("in_min", T, 0.0), _i("in_max", T, 1.0),
     _i("out_min", T, 0.0), _i("out_max", T, 1.0)],
    "Maps value linearly from [in_min, in_max] to [out_min, out_max], unclamped.",
    glsl="node_remap",
    mtlx=MxNode("remap", (("value", "in"), ("in_min", "inlow"), ("in_max", "inhigh"),
                          ("out_min", "outlow"), ("out_max", "outhigh"))),
    numpy=_remap)
_op("atan2", "Atan2", "atan({y}, {x})", [_i("y", T), _i("x", T, 1.0)],
    "Angle of the point (x, y) in radians, in (−π, π].",
    mtlx=MxNode("atan2", (("y", "iny"), ("x", "inx"))),
    numpy=lambda ctx, y, x: (np.arctan2(y, x),))
_op("exp", "Exp", "exp({value})", [_i("value", T)], "e raised to value.", mtlx=_un("exp"),
    numpy=lambda ctx, value: (np.exp(value),))


def _floored_log(b: MxBuilder) -> Makers:  # ln(max(value, 1e-30))
    return [lambda: b.node("ln", None, "", (
        "in", b.node("max", None, "max", ("in1", b.arg(0)), ("in2", b.value(1e-30)))))]


_op("log", "Log", "log(max({value}, 1e-30))", [_i("value", T, 1.0)],
    "Natural logarithm; values at or below 0 read as 1e-30.",
    mtlx=MxRecipe("floored_log", _floored_log), reads=_un("ln"),  # ln(max(value, 1e-30))
    numpy=lambda ctx, value: (np.log(np.maximum(value, 1e-30)),))
_op("mod", "Modulo", "mod({a}, {b})", [_i("a", T), _i("b", T, 1.0)],
    "a − b floor(a / b): the remainder with the sign of b.", mtlx=_bin("modulo"),
    numpy=lambda ctx, a, b: (a - b * np.floor(a / b),))
_op("sign", "Sign", "sign({value})", [_i("value", T)], "−1, 0 or 1.", mtlx=_un("sign"),
    numpy=lambda ctx, value: (np.sign(value),))


def _floor_of_half_up(b: MxBuilder) -> Makers:
    # floor(value + 0.5): GLSL's round may go either way
    return [lambda: b.node("floor", None, "", (
        "in", b.node("add", None, "half", ("in1", b.arg(0)), ("in2", b.value(0.5)))))]


_op("round", "Round", "floor({value} + 0.5)", [_i("value", T)],
    "Nearest integer; halves round up.",
    mtlx=MxRecipe("floor_of_half_up", _floor_of_half_up),
    numpy=lambda ctx, value: (np.floor(value + 0.5),))
_op("ceil", "Ceil", "ceil({value})", [_i("value", T)], "Smallest integer not below value.",
    mtlx=_un("ceil"),
    numpy=lambda ctx, value: (np.ceil(value),))


def _signed_floor_of_abs(b: MxBuilder) -> Makers:
    # sign(value) floor(|value|): the stdlib has no trunc
    return [lambda: b.node(
        "multiply", None, "", ("in1", b.node("sign", None, "sign", ("in", b.arg(0)))),
        ("in2", b.node("floor", None, "floor", (
            "in", b.node("absval", None, "abs", ("in", b.arg(0)))))))]


_op("trunc", "Truncate", "trunc({value})", [_i("value", T)],
    "Integer part, rounding towards zero.",
    mtlx=MxRecipe("signed_floor_of_abs", _signed_floor_of_abs),
    numpy=lambda ctx, value: (np.trunc(value),))
_op("negate", "Negate", "(-{value})", [_i("value", T)], "−value.",
    mtlx=MxNode("multiply", (("value", "in1"),), (("in2", -1.0),)),
    numpy=lambda ctx, value: (-value,))


def _reciprocal(ctx, value):
    with np.errstate(divide="ignore"):
        return (1.0 / value,)


_op("reciprocal", "Reciprocal", "(1.0 / {value})", [_i("value", T, 1.0)],
    "1 ÷ value (zero gives the GPU's infinity).",
    mtlx=MxNode("divide", (("value", "in2"),), (("in1", 1.0),)),
    numpy=_reciprocal)
_op("tan", "Tangent", "tan({value})", [_i("value", T)], "Tangent of radians.", mtlx=_un("tan"),
    numpy=lambda ctx, value: (np.tan(value),))


def _clamped(category: str):
    """`category` (asin, acos) of the operand clamped into [-1, 1]."""
    def recipe(b: MxBuilder) -> Makers:
        return [lambda: b.node(category, None, "", ("in", b.node(
            "clamp", None, "clamp", ("in", b.arg(0)), ("low", b.value(-1.0)),
            ("high", b.value(1.0)))))]
    return recipe


_op("asin", "Arcsine", "asin(clamp({value}, -1.0, 1.0))", [_i("value", T)],
    "Arcsine in radians; input clamped to [−1, 1].",
    mtlx=MxRecipe("clamped_asin", _clamped("asin")), reads=_un("asin"),
    numpy=lambda ctx, value: (np.arcsin(_clamp(value, -1.0, 1.0)),))
_op("acos", "Arccosine", "acos(clamp({value}, -1.0, 1.0))", [_i("value", T)],
    "Arccosine in radians; input clamped to [−1, 1].",
    mtlx=MxRecipe("clamped_acos", _clamped("acos")), reads=_un("acos"),
    numpy=lambda ctx, value: (np.arccos(_clamp(value, -1.0, 1.0)),))
_op("radians", "To Radians", "radians({value})", [_i("value", T)], "Degrees to radians.",
    mtlx=MxNode("multiply", (("value", "in1"),), (("in2", math.pi / 180.0),)),
    numpy=lambda ctx, value: (np.radians(value),))
_op("degrees", "To Degrees", "degrees({value})", [_i("value", T)], "Radians to degrees.",
    mtlx=MxNode("multiply", (("value", "in1"),), (("in2", 180.0 / math.pi),)),
    numpy=lambda ctx, value: (np.degrees(value),))


def multiply_then_add(b: MxBuilder) -> Makers:
    """x y + z, on the first three operands (multiply_add, tiling_offset)."""
    return [lambda: b.node("add", None, "", (
        "in1", b.node("multiply", None, "mul", ("in1", b.arg(0)), ("in2", b.arg(1)))),
        ("in2", b.arg(2)))]


_op("multiply_add", "Multiply Add", "({a} * {b} + {c})",
    [_i("a", T), _i("b", T, 1.0), _i("c", T)], "a × b + c.",
    mtlx=MxRecipe("multiply_then_add", multiply_then_add),
    numpy=lambda ctx, a, b, c: (a * b + c,))


def _posterize(ctx, value, steps):
    s = np.maximum(steps, 1.0)
    return (np.floor(value * s) / s,)


def _floor_in_steps(b: MxBuilder) -> Makers:  # floor(value s) / s, s = max(steps, 1)
    def make() -> Ref:
        st = b.node("max", None, "steps", ("in1", b.arg(1)), ("in2", b.value(1.0)))
        f = b.node("floor", None, "floor", (
            "in", b.node("multiply", None, "scaled", ("in1", b.arg(0)), ("in2", st))))
        return b.node("divide", None, "", ("in1", f), ("in2", st))
    return [make]


_op("posterize", "Posterize", "(floor({value} * max({steps}, 1.0)) / max({steps}, 1.0))",
    [_i("value", T), _i("steps", T, 4.0, "levels per unit (at least 1)", (1.0, 64.0))],
    "Quantises value into steps levels per unit.",
    mtlx=MxRecipe("floor_in_steps", _floor_in_steps),
    numpy=_posterize)


def _smooth_min(ctx, a, b, smoothness):
    k = np.maximum(smoothness, 1e-6)
    h = _clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return (_mix(b, a, h) - smoothness * h * (1.0 - h),)


_op("smooth_min", "Soft Minimum", None,
    [_i("a", T), _i("b", T), _i("smoothness", T, 0.1, "blend radius", (0.0, 1.0))],
    "The smaller of a and b with a rounded join (polynomial smooth minimum).",
    glsl="node_smooth_min",
    numpy=_smooth_min)


def _distance_or_absval(b: MxBuilder) -> Makers:  # |a - b| for floats
    if b.arg_type(0) == "float":
        return [lambda: b.node("absval", "float", "", (
            "in", b.node("subtract", "float", "d", ("in1", b.arg(0)), ("in2", b.arg(1)))))]
    return [lambda: b.node("distance", "float", "", ("in1", b.arg(0)), ("in2", b.arg(1)))]


_op("distance", "Distance", "distance({a}, {b})", [_i("a", T), _i("b", T)],
    "Euclidean distance between a and b.", out_type="float", category="Vector",
    mtlx=MxRecipe("distance_or_absval", _distance_or_absval), reads=_bin("distance"),
    numpy=lambda ctx, a, b: (np.sqrt(_dot(a - b, a - b)),))


def _reflect(ctx, incident, normal):
    return (incident - 2.0 * _col(_dot(normal, incident)) * normal,)


_op("reflect", "Reflect", "reflect({incident}, {normal})",
    [_i("incident", "vec3", [0.0, 0.0, -1.0]), _i("normal", "vec3", [0.0, 0.0, 1.0], "unit")],
    "Mirror direction of incident about normal.", out_type="vec3", category="Vector",
    mtlx=MxNode("reflect", (("incident", "in"), ("normal", "normal"))),
    numpy=_reflect)


def _refract(ctx, incident, normal, eta):
    d = _dot(normal, incident)
    k = 1.0 - eta * eta * (1.0 - d * d)
    out = _col(eta) * incident - _col(eta * d + np.sqrt(np.maximum(k, 0.0))) * normal
    return (np.where(_col(k < 0.0), 0.0, out).astype(incident.dtype, copy=False),)


_op("refract", "Refract", "refract({incident}, {normal}, {eta})",
    [_i("incident", "vec3", [0.0, 0.0, -1.0], "unit"),
     _i("normal", "vec3", [0.0, 0.0, 1.0], "unit"),
     _i("eta", "float", 0.67, "ratio of indices of refraction", (0.0, 3.0))],
    "Refracted direction (zero on total internal reflection).", out_type="vec3",
    category="Vector",
    mtlx=MxNode("refract", (("incident", "in"), ("normal", "normal"), ("eta", "ior"))),
    numpy=_refract)


def _if_greater(ctx, a, b, if_true, if_false):
    return (_where(a > b, if_true, if_false),)


_op("if_greater", "If Greater", "({a} > {b} ? {if_true} : {if_false})",
    [_i("a", "float"), _i("b", "float"), _i("if_true", T, 1.0), _i("if_false", T, 0.0)],
    "if_true where a > b, else if_false.", category="Logic",
    mtlx=MxNode("ifgreater", (("a", "value1"), ("b", "value2"), ("if_true", "in1"),
                              ("if_false", "in2"))),
    numpy=_if_greater)


def _if_equal(ctx, a, b, tolerance, if_true, if_false):
    return (_where(np.abs(a - b) <= tolerance, if_true, if_false),)


def _within_tolerance(b: MxBuilder) -> Makers:
    def make() -> Ref:
        diff = b.node("absval", "float", "diff", (
            "in", b.node("subtract", "float", "d", ("in1", b.arg(0)), ("in2", b.arg(1)))))
        # |a - b| > tolerance picks if_false: the same as |a - b| <= tolerance picking if_true
        return b.node("ifgreater", None, "", ("value1", diff), ("value2", b.arg(2)),
                      ("in1", b.arg(4)), ("in2", b.arg(3)))
    return [make]


_op("if_equal", "If Equal", "(abs({a} - {b}) <= {tolerance} ? {if_true} : {if_false})",
    [_i("a", "float"), _i("b", "float"), _i("tolerance", "float", 1e-4, "", (0.0, 1.0)),
     _i("if_true", T, 1.0), _i("if_false", T, 0.0)],
    "if_true where |a − b| ≤ tolerance, else if_false.", category="Logic",
    mtlx=MxRecipe("within_tolerance", _within_tolerance),
    numpy=_if_equal)
_op("fwidth", "Pixel Footprint", "fwidth({value})", [_i("value", T)],
    "How much value changes across one pixel (|d/dx| + |d/dy|): the width to filter "
    "an edge of value over.", category="Utility",
    numpy=lambda ctx, value: (fwidth(ctx, value),))
