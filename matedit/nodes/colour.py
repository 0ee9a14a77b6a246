"""Colour kinds: luminance, HSV, grading, the blend modes and the colour ramp."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    BAKE,
    UNIT,
    Makers,
    MxBuilder,
    MxNode,
    MxRecipe,
    NodeDef,
    Ref,
    Role,
    Thumbnail,
    _fn,
    _i,
    _o,
    register,
)
from matedit.nodes.maths import positive_power
from matedit.nodes.twin import _clamp, _col, _mix

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np


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
    "lighten": lambda a, b: np.maximum(a, b),
    "darken": lambda a, b: np.minimum(a, b),
}


def _blend_impl(mode):
    def impl(ctx, base, blend, opacity):
        r = np.asarray(mode(base, blend), dtype=base.dtype)
        return (_mix(base, r, _col(opacity)),)  # from the unclamped base, as the GLSL

    return impl


# --- colour ----------------------------------------------------------------------------------
_C = ("color", "vec3", [0.5, 0.5, 0.5], "linear RGB")


def _rec709_dot(b: MxBuilder) -> Makers:
    return [lambda: b.node("dotproduct", "float", "", (
        "in1", b.arg(0)), ("in2", b.value(tuple(LUMA_REC709), "vector3")))]


_fn("luminance", "Luminance", "Colour", "Rec. 709 luminance of a linear colour.",
    [_i(*_C)], [_o("value", "float")], mtlx=MxRecipe("rec709_dot", _rec709_dot),
    numpy=lambda ctx, color: (_luminance(color),))
_fn("rgb_to_hsv", "RGB to HSV", "Colour", "Hue (turns), saturation and value of a colour.",
    [_i(*_C)], [_o("hsv", "vec3")],
    # MaterialX's rgbtohsv: the same hue (turns), saturation and value (the import reads it;
    # tests/test_interop_mtlx_textures.py checks it against MaterialX's GLSL)
    mtlx_reads=MxNode("rgbtohsv", (("color", "in"),)),
    numpy=lambda ctx, color: (rgb_to_hsv(color),))


def _hsvtorgb_on_color3(b: MxBuilder) -> Makers:
    return [lambda: b.node("convert", "vector3", "", ("in", b.node(
        "hsvtorgb", "color3", "rgb", ("in", b.node("convert", "color3", "hsv",
                                                   ("in", b.arg(0)))))))]


_fn("hsv_to_rgb", "HSV to RGB", "Colour", "The colour of a hue (turns), saturation, value.",
    [_i("hsv", "vec3", [0.0, 1.0, 1.0])], [_o("color", "vec3")],
    # hsvtorgb on color3: the same sectors; below saturation 1e-4 it returns grey (v, v, v),
    # ours v mix(1, c, s): they differ there by at most 1e-4 v
    mtlx=MxRecipe("hsvtorgb_on_color3", _hsvtorgb_on_color3),
    mtlx_reads=MxNode("hsvtorgb", (("hsv", "in"),)),
    numpy=lambda ctx, hsv: (hsv_to_rgb(hsv),))


def _hsv_adjust(ctx, color, hue, saturation, value):
    hsv = rgb_to_hsv(color)
    h = hsv[:, 0] + hue
    h = h - np.floor(h)
    s = _clamp(hsv[:, 1] * saturation, 0.0, 1.0)
    v = hsv[:, 2] * value
    return (hsv_to_rgb(np.stack([h, s, v], -1)),)


_fn("hsv_adjust", "HSV Adjust", "Colour",
    "Rotates hue, scales saturation and value (in HSV space).",
    [_i(*_C), _i("hue", "float", 0.0, "hue shift in turns", (-0.5, 0.5)),
     _i("saturation", "float", 1.0, "saturation multiplier", (0.0, 2.0)),
     _i("value", "float", 1.0, "value multiplier", (0.0, 2.0))],
    [_o("result", "vec3")],
    numpy=_hsv_adjust)


def _brightness_contrast(ctx, color, brightness, contrast):
    a = 1.0 + contrast
    b = brightness - contrast * 0.5
    return (np.maximum(_col(a) * color + _col(b), 0.0),)


def _scale_about_mid_grey(b: MxBuilder) -> Makers:  # max((1 + c) color + b − c / 2, 0)
    def make() -> Ref:
        gain = b.node("add", "float", "gain", ("in1", b.value(1.0, "float")),
                      ("in2", b.arg(2)))
        lift = b.node("subtract", "float", "lift", ("in1", b.arg(1)), (
            "in2", b.node("multiply", "float", "half", ("in1", b.arg(2)),
                          ("in2", b.value(0.5, "float")))))
        y = b.node("add", "vector3", "lifted", ("in1", b.node(
            "multiply", "vector3", "scaled", ("in1", b.arg(0)), ("in2", gain))),
            ("in2", lift))
        return b.node("max", "vector3", "", ("in1", y), ("in2", b.value(0.0, "float")))
    return [make]


_fn("brightness_contrast", "Brightness / Contrast", "Colour",
    "Adds brightness and scales contrast about mid grey; never below 0.",
    [_i(*_C), _i("brightness", "float", 0.0, "", (-1.0, 1.0)),
     _i("contrast", "float", 0.0, "", (-1.0, 1.0))], [_o("result", "vec3")],
    mtlx=MxRecipe("scale_about_mid_grey", _scale_about_mid_grey),
    numpy=_brightness_contrast)
_fn("gamma", "Gamma", "Colour", "color raised to gamma (negative components read 0).",
    [_i(*_C), _i("gamma", "float", 1.0, "", (0.01, 10.0))], [_o("result", "vec3")],
    mtlx=MxRecipe("positive_power", positive_power),  # power(max(color, 0), gamma)
    numpy=lambda ctx, color, gamma: (np.power(np.maximum(color, 0.0), _col(gamma)),))


def _mix_towards_inverse(b: MxBuilder) -> Makers:  # mix(color, 1 − color, amount)
    return [lambda: b.node("mix", "vector3", "", ("bg", b.arg(0)), (
        "fg", b.node("subtract", "vector3", "inverse",
                     ("in1", b.value((1.0, 1.0, 1.0), "vector3")), ("in2", b.arg(0)))),
        ("mix", b.arg(1)))]


_fn("invert", "Invert", "Colour", "1 − color, by amount.",
    [_i(*_C), _i("amount", "float", 1.0, "", UNIT)], [_o("result", "vec3")],
    mtlx=MxRecipe("mix_towards_inverse", _mix_towards_inverse),
    numpy=lambda ctx, color, amount: (_mix(color, 1.0 - color, _col(amount)),))


def _levels(ctx, color, in_black, in_white, gamma, out_black, out_white):
    rng = np.maximum(in_white - in_black, 1e-5)
    t = _clamp((color - _col(in_black)) / _col(rng), 0.0, 1.0)
    t = np.power(t, _col(1.0 / np.maximum(gamma, 1e-3)))
    return (_mix(_col(out_black), _col(out_white), t),)


_fn("levels", "Levels", "Colour",
    "Input black/white points, midtone gamma and output range, like an image editor's.",
    [_i(*_C), _i("in_black", "float", 0.0, "", UNIT), _i("in_white", "float", 1.0, "", UNIT),
     _i("gamma", "float", 1.0, "midtone gamma (>1 brightens)", (0.1, 10.0)),
     _i("out_black", "float", 0.0, "", UNIT), _i("out_white", "float", 1.0, "", UNIT)],
    [_o("result", "vec3")],
    numpy=_levels)


def _mix_from_grey(b: MxBuilder) -> Makers:  # mix(rec709 luminance, color, amount)
    def make() -> Ref:
        y = b.node("dotproduct", "float", "luma", ("in1", b.arg(0)),
                   ("in2", b.value(tuple(LUMA_REC709), "vector3")))
        grey = b.node("convert", "vector3", "grey", ("in", y))
        return b.node("mix", "vector3", "", ("bg", grey), ("fg", b.arg(0)), ("mix", b.arg(1)))
    return [make]


_fn("saturation", "Saturation", "Colour", "Mixes between grey (0) and the colour (1) and past.",
    [_i(*_C), _i("amount", "float", 1.0, "", (0.0, 2.0))], [_o("result", "vec3")],
    mtlx=MxRecipe("mix_from_grey", _mix_from_grey),
    numpy=lambda ctx, color, amount: (_mix(_col(_luminance(color)), color, _col(amount)),))


def _srgb_to_linear(ctx, color):
    c = np.maximum(color, 0.0)
    return (np.where(c <= 0.04045, c / 12.92, np.power((c + 0.055) / 1.055, 2.4)),)


def _srgb(decode: bool):
    """The sRGB transfer function (IEC 61966-2-1) per component: ifgreater on max(c, 0)."""
    def recipe(b: MxBuilder) -> Makers:
        def make() -> Ref:
            def v3(category, suffix, *ins):
                return b.node(category, "vector3", suffix,
                              *zip(("in1", "in2"), ins))

            def f(x):
                return b.value(x, "float")
            c = v3("max", "positive", b.arg(0), f(0.0))
            if decode:
                edge = 0.04045
                linear = v3("divide", "linear", c, f(12.92))
                curve = v3("power", "curve", v3("divide", "scaled", v3(
                    "add", "offset", c, f(0.055)), f(1.055)), f(2.4))
            else:
                edge = 0.0031308
                linear = v3("multiply", "linear", c, f(12.92))
                curve = v3("subtract", "curve", v3("multiply", "scaled", v3(
                    "power", "root", c, f(1.0 / 2.4)), f(1.055)), f(0.055))
            # c <= edge is the linear segment: c > edge picks the curve
            parts = [b.node("ifgreater", "float", "xyz"[i], ("value1", b.extract(c, i)),
                            ("value2", f(edge)), ("in1", b.extract(curve, i)),
                            ("in2", b.extract(linear, i))) for i in range(3)]
            return b.combine(parts, "vector3")
        return [make]
    return recipe


_fn("srgb_to_linear", "sRGB to Linear", "Colour", "Decodes sRGB-encoded values (IEC 61966-2-1).",
    [_i("color", "vec3", [0.5, 0.5, 0.5], "sRGB-encoded")], [_o("result", "vec3")],
    mtlx=MxRecipe("srgb_decode_per_component", _srgb(decode=True)),
    numpy=_srgb_to_linear)


def _linear_to_srgb(ctx, color):
    c = np.maximum(color, 0.0)
    return (np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1.0 / 2.4) - 0.055),)


_fn("linear_to_srgb", "Linear to sRGB", "Colour", "Encodes linear values as sRGB.",
    [_i(*_C)], [_o("result", "vec3")],
    mtlx=MxRecipe("srgb_encode_per_component", _srgb(decode=False)),
    numpy=_linear_to_srgb)


def _composite(mode: str):
    """A blend mode that is a stdlib node or two (composite_<mode>), mixed over base by
    opacity."""
    def recipe(b: MxBuilder) -> Makers:
        def make() -> Ref:
            def v3(category, suffix, *ins):
                names = ("in1", "in2") if len(ins) == 2 else ("in",)
                return b.node(category, "vector3", suffix, *zip(names, ins))
            base, blend = b.arg(0), b.arg(1)
            one3 = b.value((1.0, 1.0, 1.0), "vector3")
            if mode == "screen":
                r = v3("subtract", "screen", one3, v3(
                    "multiply", "darks", v3("subtract", "base_inv", one3, base),
                    v3("subtract", "blend_inv", one3, blend)))
            elif mode == "difference":
                r = v3("absval", "difference", v3("subtract", "d", base, blend))
            else:
                r = v3({"lighten": "max", "darken": "min"}.get(mode, mode), mode, base, blend)
            return b.node("mix", "vector3", "", ("bg", base), ("fg", r), ("mix", b.arg(2)))
        return [make]
    return recipe


_BLENDS = {
    "multiply": ("Multiply", "base × blend: darkens."),
    "screen": ("Screen", "1 − (1 − base)(1 − blend): lightens."),
    "overlay": ("Overlay", "Multiply in the darks, screen in the lights of base."),
    "soft_light": ("Soft Light", "A gentle overlay (the W3C compositing formula)."),
    "add": ("Add", "base + blend."),
    "subtract": ("Subtract", "base − blend."),
    "difference": ("Difference", "|base − blend|."),
    "dodge": ("Colour Dodge", "Brightens base by dividing by 1 − blend."),
    "burn": ("Colour Burn", "Darkens base: 1 − (1 − base) / blend."),
    "lighten": ("Lighten", "The larger of base and blend."),
    "darken": ("Darken", "The smaller of base and blend."),
}
# The modes that are a stdlib node or two before the mix by opacity; overlay, soft light,
# dodge and burn bake (their branches and guards differ from MaterialX's).
_COMPOSITED = ("multiply", "screen", "add", "subtract", "difference", "lighten", "darken")
for _name, (_title, _doc) in _BLENDS.items():
    _fn(f"blend_{_name}", f"Blend: {_title}", "Colour",
        f"{_doc} Mixed over base by opacity.",
        [_i("base", "vec3", [0.5, 0.5, 0.5]), _i("blend", "vec3", [0.5, 0.5, 0.5]),
         _i("opacity", "float", 1.0, "", UNIT)], [_o("result", "vec3")],
        mtlx=MxRecipe(f"composite_{_name}", _composite(_name)) if _name in _COMPOSITED
        else BAKE,
        numpy=_blend_impl(BLEND_MODES[_name]))
RAMP_STOPS = 6
_GREYS = (0.0, 1.0, 1.0, 1.0, 1.0, 1.0)


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


register(NodeDef(
    "color_ramp", "Colour Ramp", "Colour",
    "Maps a value through colour stops (position, colour), linearly between them; edit the "
    "stops in the inspector. Stops past `stops` are ignored.",
    inputs=(_i("value", "float", 0.5, "", UNIT),
            _i("stops", "float", 2.0, "number of stops in use", (2.0, float(RAMP_STOPS))))
    + tuple(_i(f"position{k}", "float", float(min(k, 1)), f"stop {k} position", UNIT)
            for k in range(RAMP_STOPS))
    + tuple(_i(f"color{k}", "vec3", [_GREYS[k]] * 3, f"stop {k} colour", UNIT)
            for k in range(RAMP_STOPS)),
    outputs=(_o("color", "vec3"),), glsl="node_color_ramp", role=Role.COLOR_RAMP,
    thumbnail=Thumbnail.ALWAYS,
    numpy=_color_ramp,
))
