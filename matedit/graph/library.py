"""The node library artists reach for: noise, patterns, colour, maths, UV and space, normals
and masks. Registered into `matedit.graph.nodes.REGISTRY` when that module is imported.

Every kind here has a GLSL function in `shaders/nodes/<kind>.glsl` or an inline template,
a numpy twin in `matedit.compiler.cpu_nodes`, port ranges, and the facts of
`matedit.graph.nodes.NodeDef`: patterns show a thumbnail always, kinds that read the
surface's geometry or time are impure. Their MaterialX mapping is the default, BAKE (the
MaterialX exporter bakes them), except where a stdlib node computes the same values: a
stdlib node is mapped only once MaterialX's own shader generator is shown to agree with our
CPU evaluator (tests/test_interop_mtlx.py, every mapped kind in one material).

Pattern edges are band-limited: kinds with a `filter_width` input box-filter their edges
over `filter_width` pixels of screen-space footprint (`fwidth`); the numpy twins take the
same footprint from the evaluator's pixel grid (`SurfaceArrays.grid`).
"""

from __future__ import annotations

import math

from matedit.graph.nodedef import (
    BAKE,
    GENERIC,
    MESH_UV,
    REGISTRY,
    MxNode,
    MxRecipe,
    NodeDef,
    Role,
    Thumbnail,
    _bin,
    _i,
    _o,
    _op,
    _un,
    register,
)

_BEFORE = frozenset(REGISTRY)
T = GENERIC
UNIT = (0.0, 1.0)
_FILTER = ("filter_width", "float", 1.0, "edge blur in pixels (0: hard edges)", (0.0, 4.0))
_SEED = ("seed", "float", 0.0, "integer seed: another seed, another pattern", (0.0, 1000.0))


def _fn(kind, title, category, description, inputs, outputs, **facts):
    """A kind with a GLSL function `node_<kind>`; `facts` are further NodeDef fields
    (thumbnail, geometry...)."""
    register(NodeDef(kind, title, category, description, inputs=tuple(inputs),
                     outputs=tuple(outputs), glsl=f"node_{kind}", **facts))


# --- maths -----------------------------------------------------------------------------------
_op("atan2", "Atan2", "atan({y}, {x})", [_i("y", T), _i("x", T, 1.0)],
    "Angle of the point (x, y) in radians, in (−π, π].",
    mtlx=MxNode("atan2", (("y", "iny"), ("x", "inx"))))
_op("exp", "Exp", "exp({value})", [_i("value", T)], "e raised to value.", mtlx=_un("exp"))
_op("log", "Log", "log(max({value}, 1e-30))", [_i("value", T, 1.0)],
    "Natural logarithm; values at or below 0 read as 1e-30.",
    mtlx=MxRecipe("floored_log"), reads=_un("ln"))  # ln(max(value, 1e-30))
_op("mod", "Modulo", "mod({a}, {b})", [_i("a", T), _i("b", T, 1.0)],
    "a − b floor(a / b): the remainder with the sign of b.", mtlx=_bin("modulo"))
_op("sign", "Sign", "sign({value})", [_i("value", T)], "−1, 0 or 1.", mtlx=_un("sign"))
_op("round", "Round", "floor({value} + 0.5)", [_i("value", T)],
    "Nearest integer; halves round up.",
    mtlx=MxRecipe("floor_of_half_up"))  # floor(value + 0.5): GLSL's round may go either way
_op("ceil", "Ceil", "ceil({value})", [_i("value", T)], "Smallest integer not below value.",
    mtlx=_un("ceil"))
_op("trunc", "Truncate", "trunc({value})", [_i("value", T)],
    "Integer part, rounding towards zero.",
    mtlx=MxRecipe("signed_floor_of_abs"))  # sign(value) floor(|value|): no stdlib trunc
_op("negate", "Negate", "(-{value})", [_i("value", T)], "−value.",
    mtlx=MxNode("multiply", (("value", "in1"),), (("in2", -1.0),)))
_op("reciprocal", "Reciprocal", "(1.0 / {value})", [_i("value", T, 1.0)],
    "1 ÷ value (zero gives the GPU's infinity).",
    mtlx=MxNode("divide", (("value", "in2"),), (("in1", 1.0),)))
_op("tan", "Tangent", "tan({value})", [_i("value", T)], "Tangent of radians.", mtlx=_un("tan"))
_op("asin", "Arcsine", "asin(clamp({value}, -1.0, 1.0))", [_i("value", T)],
    "Arcsine in radians; input clamped to [−1, 1].",
    mtlx=MxRecipe("clamped_asin"), reads=_un("asin"))
_op("acos", "Arccosine", "acos(clamp({value}, -1.0, 1.0))", [_i("value", T)],
    "Arccosine in radians; input clamped to [−1, 1].",
    mtlx=MxRecipe("clamped_acos"), reads=_un("acos"))
_op("radians", "To Radians", "radians({value})", [_i("value", T)], "Degrees to radians.",
    mtlx=MxNode("multiply", (("value", "in1"),), (("in2", math.pi / 180.0),)))
_op("degrees", "To Degrees", "degrees({value})", [_i("value", T)], "Radians to degrees.",
    mtlx=MxNode("multiply", (("value", "in1"),), (("in2", 180.0 / math.pi),)))
_op("multiply_add", "Multiply Add", "({a} * {b} + {c})",
    [_i("a", T), _i("b", T, 1.0), _i("c", T)], "a × b + c.",
    mtlx=MxRecipe("multiply_then_add"))
_op("posterize", "Posterize", "(floor({value} * max({steps}, 1.0)) / max({steps}, 1.0))",
    [_i("value", T), _i("steps", T, 4.0, "levels per unit (at least 1)", (1.0, 64.0))],
    "Quantises value into steps levels per unit.",
    mtlx=MxRecipe("floor_in_steps"))  # floor(value s) / s, s = max(steps, 1)
_op("smooth_min", "Soft Minimum", None,
    [_i("a", T), _i("b", T), _i("smoothness", T, 0.1, "blend radius", (0.0, 1.0))],
    "The smaller of a and b with a rounded join (polynomial smooth minimum).",
    glsl="node_smooth_min")
_op("distance", "Distance", "distance({a}, {b})", [_i("a", T), _i("b", T)],
    "Euclidean distance between a and b.", out_type="float", category="Vector",
    mtlx=MxRecipe("distance_or_absval"), reads=_bin("distance"))  # |a - b| for floats
_op("reflect", "Reflect", "reflect({incident}, {normal})",
    [_i("incident", "vec3", [0.0, 0.0, -1.0]), _i("normal", "vec3", [0.0, 0.0, 1.0], "unit")],
    "Mirror direction of incident about normal.", out_type="vec3", category="Vector",
    mtlx=MxNode("reflect", (("incident", "in"), ("normal", "normal"))))
_op("refract", "Refract", "refract({incident}, {normal}, {eta})",
    [_i("incident", "vec3", [0.0, 0.0, -1.0], "unit"),
     _i("normal", "vec3", [0.0, 0.0, 1.0], "unit"),
     _i("eta", "float", 0.67, "ratio of indices of refraction", (0.0, 3.0))],
    "Refracted direction (zero on total internal reflection).", out_type="vec3",
    category="Vector",
    mtlx=MxNode("refract", (("incident", "in"), ("normal", "normal"), ("eta", "ior"))))
_op("if_greater", "If Greater", "({a} > {b} ? {if_true} : {if_false})",
    [_i("a", "float"), _i("b", "float"), _i("if_true", T, 1.0), _i("if_false", T, 0.0)],
    "if_true where a > b, else if_false.", category="Logic",
    mtlx=MxNode("ifgreater", (("a", "value1"), ("b", "value2"), ("if_true", "in1"),
                              ("if_false", "in2"))))
_op("if_equal", "If Equal", "(abs({a} - {b}) <= {tolerance} ? {if_true} : {if_false})",
    [_i("a", "float"), _i("b", "float"), _i("tolerance", "float", 1e-4, "", (0.0, 1.0)),
     _i("if_true", T, 1.0), _i("if_false", T, 0.0)],
    "if_true where |a − b| ≤ tolerance, else if_false.", category="Logic",
    mtlx=MxRecipe("within_tolerance"))  # ifgreater(|a - b|, tolerance, if_false, if_true)
_op("fwidth", "Pixel Footprint", "fwidth({value})", [_i("value", T)],
    "How much value changes across one pixel (|d/dx| + |d/dy|): the width to filter "
    "an edge of value over.", category="Utility")

# --- colour ----------------------------------------------------------------------------------
_C = ("color", "vec3", [0.5, 0.5, 0.5], "linear RGB")
_fn("luminance", "Luminance", "Colour", "Rec. 709 luminance of a linear colour.",
    [_i(*_C)], [_o("value", "float")], mtlx=MxRecipe("rec709_dot"))
_fn("rgb_to_hsv", "RGB to HSV", "Colour", "Hue (turns), saturation and value of a colour.",
    [_i(*_C)], [_o("hsv", "vec3")])
_fn("hsv_to_rgb", "HSV to RGB", "Colour", "The colour of a hue (turns), saturation, value.",
    [_i("hsv", "vec3", [0.0, 1.0, 1.0])], [_o("color", "vec3")],
    # hsvtorgb on color3: the same sectors; below saturation 1e-4 it returns grey (v, v, v),
    # ours v mix(1, c, s): they differ there by at most 1e-4 v
    mtlx=MxRecipe("hsvtorgb_on_color3"), mtlx_reads=MxNode("hsvtorgb", (("hsv", "in"),)))
_fn("hsv_adjust", "HSV Adjust", "Colour",
    "Rotates hue, scales saturation and value (in HSV space).",
    [_i(*_C), _i("hue", "float", 0.0, "hue shift in turns", (-0.5, 0.5)),
     _i("saturation", "float", 1.0, "saturation multiplier", (0.0, 2.0)),
     _i("value", "float", 1.0, "value multiplier", (0.0, 2.0))],
    [_o("result", "vec3")])
_fn("brightness_contrast", "Brightness / Contrast", "Colour",
    "Adds brightness and scales contrast about mid grey; never below 0.",
    [_i(*_C), _i("brightness", "float", 0.0, "", (-1.0, 1.0)),
     _i("contrast", "float", 0.0, "", (-1.0, 1.0))], [_o("result", "vec3")],
    mtlx=MxRecipe("scale_about_mid_grey"))  # max((1 + c) color + b − c / 2, 0)
_fn("gamma", "Gamma", "Colour", "color raised to gamma (negative components read 0).",
    [_i(*_C), _i("gamma", "float", 1.0, "", (0.01, 10.0))], [_o("result", "vec3")],
    mtlx=MxRecipe("positive_power"))  # power(max(color, 0), gamma)
_fn("invert", "Invert", "Colour", "1 − color, by amount.",
    [_i(*_C), _i("amount", "float", 1.0, "", UNIT)], [_o("result", "vec3")],
    mtlx=MxRecipe("mix_towards_inverse"))  # mix(color, 1 − color, amount)
_fn("levels", "Levels", "Colour",
    "Input black/white points, midtone gamma and output range, like an image editor's.",
    [_i(*_C), _i("in_black", "float", 0.0, "", UNIT), _i("in_white", "float", 1.0, "", UNIT),
     _i("gamma", "float", 1.0, "midtone gamma (>1 brightens)", (0.1, 10.0)),
     _i("out_black", "float", 0.0, "", UNIT), _i("out_white", "float", 1.0, "", UNIT)],
    [_o("result", "vec3")])
_fn("saturation", "Saturation", "Colour", "Mixes between grey (0) and the colour (1) and past.",
    [_i(*_C), _i("amount", "float", 1.0, "", (0.0, 2.0))], [_o("result", "vec3")],
    mtlx=MxRecipe("mix_from_grey"))  # mix(rec709 luminance, color, amount)
_fn("srgb_to_linear", "sRGB to Linear", "Colour", "Decodes sRGB-encoded values (IEC 61966-2-1).",
    [_i("color", "vec3", [0.5, 0.5, 0.5], "sRGB-encoded")], [_o("result", "vec3")],
    mtlx=MxRecipe("srgb_decode_per_component"))  # ifgreater per component on max(c, 0)
_fn("linear_to_srgb", "Linear to sRGB", "Colour", "Encodes linear values as sRGB.",
    [_i(*_C)], [_o("result", "vec3")], mtlx=MxRecipe("srgb_encode_per_component"))
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
        mtlx=MxRecipe(f"composite_{_name}") if _name in _COMPOSITED else BAKE)
RAMP_STOPS = 6
_GREYS = (0.0, 1.0, 1.0, 1.0, 1.0, 1.0)
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
))

# --- noise -----------------------------------------------------------------------------------
_UV = ("uv", "vec2", MESH_UV)
_SCALE = ("scale", "float", 8.0, "features per UV unit", (0.0, 64.0))
_fn("gradient_noise", "Gradient Noise", "Noise",
    "Perlin-style gradient noise over uv, in about [−1, 1], smooth (quintic fade).",
    [_i(*_UV), _i(*_SCALE), _i(*_SEED)], [_o("value", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("gradient_noise_3d", "Gradient Noise 3D", "Noise",
    "Perlin-style gradient noise over a 3D position (e.g. world position), about [−1, 1].",
    [_i("position", "vec3", [0.0, 0.0, 0.0]), _i("scale", "float", 2.0, "features per unit",
                                                 (0.0, 64.0)), _i(*_SEED)],
    [_o("value", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("cellular_noise", "Cellular Noise", "Noise",
    "Worley noise over uv: distances to the nearest (F1) and second nearest (F2) feature "
    "points, F2 − F1 (cell borders), a random value per cell, and a filtered edge mask.",
    [_i(*_UV), _i(*_SCALE), _i("jitter", "float", 1.0, "feature point randomness", UNIT),
     _i("edge_width", "float", 0.05, "border width, in cells, of the edge mask", (0.0, 0.5)),
     _i(*_SEED), _i(*_FILTER)],
    [_o("f1", "float"), _o("f2", "float"), _o("edge", "float"), _o("cell_id", "float"),
     _o("edges", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("cellular_noise_3d", "Cellular Noise 3D", "Noise",
    "Worley noise over a 3D position: F1, F2, F2 − F1 and a random value per cell.",
    [_i("position", "vec3", [0.0, 0.0, 0.0]), _i("scale", "float", 2.0, "cells per unit",
                                                 (0.0, 64.0)),
     _i("jitter", "float", 1.0, "", UNIT), _i(*_SEED)],
    [_o("f1", "float"), _o("f2", "float"), _o("edge", "float"), _o("cell_id", "float")],
    thumbnail=Thumbnail.ALWAYS)
_OCT = [_i("octaves", "float", 4.0, "detail levels (fractional fades the last in)", (1.0, 8.0)),
        _i("lacunarity", "float", 2.0, "frequency ratio between octaves", (1.0, 4.0)),
        _i("gain", "float", 0.5, "amplitude ratio between octaves", (0.0, 1.0))]
_fn("fbm", "Fractal Noise", "Noise",
    "Fractal Brownian motion: octaves of gradient noise, in about [0, 1] around 0.5.",
    [_i(*_UV), _i("scale", "float", 4.0, "base features per UV unit", (0.0, 64.0)), *_OCT,
     _i(*_SEED)], [_o("value", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("fbm_3d", "Fractal Noise 3D", "Noise",
    "Fractal Brownian motion over a 3D position, in about [0, 1] around 0.5.",
    [_i("position", "vec3", [0.0, 0.0, 0.0]), _i("scale", "float", 2.0, "", (0.0, 64.0)),
     *_OCT, _i(*_SEED)], [_o("value", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("ridged_noise", "Ridged Noise", "Noise",
    "Ridged multifractal: octaves of (1 − |noise|)², sharp crests like cracks and veins, "
    "in [0, 1].",
    [_i(*_UV), _i("scale", "float", 4.0, "", (0.0, 64.0)), *_OCT, _i(*_SEED)],
    [_o("value", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("white_noise", "White Noise", "Noise",
    "A random value (and colour) for every distinct input, from its bits: per-pixel grain, "
    "or per cell when fed a cell id.",
    [_i("value", "vec3", [0.0, 0.0, 0.0]), _i(*_SEED)],
    [_o("value", "float"), _o("color", "vec3")])
_fn("cell_hash", "Random per Cell", "Noise",
    "A random value and colour per integer cell of the input (floor of each component).",
    [_i("cell", "vec2", [0.0, 0.0]), _i(*_SEED)], [_o("value", "float"), _o("color", "vec3")])
_fn("domain_warp", "Domain Warp", "Noise",
    "Displaces uv by fractal noise, so any pattern fed the result swirls and breaks up.",
    [_i(*_UV), _i("scale", "float", 4.0, "", (0.0, 64.0)),
     _i("strength", "float", 0.1, "displacement in UV units", (0.0, 1.0)),
     _i("octaves", "float", 3.0, "", (1.0, 8.0)), _i(*_SEED)], [_o("uv", "vec2")],
    thumbnail=Thumbnail.ALWAYS)

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
     _o("tile_uv", "vec2")], thumbnail=Thumbnail.ALWAYS)
_fn("stripes", "Stripes", "Procedural",
    "Parallel stripes along an angle, band-limited so they never moiré.",
    [_i(*_UV), _i("frequency", "float", 8.0, "stripes per UV unit", (0.0, 128.0)),
     _i("width", "float", 0.5, "stripe share of each period", UNIT),
     _i("angle", "float", 0.0, "degrees", (0.0, 360.0)), _i(*_FILTER)],
    [_o("mask", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("wave", "Wave", "Procedural",
    "Bands along an angle with a sine profile, optionally distorted by noise.",
    [_i(*_UV), _i("frequency", "float", 8.0, "bands per UV unit", (0.0, 128.0)),
     _i("angle", "float", 0.0, "degrees", (0.0, 360.0)),
     _i("distortion", "float", 0.0, "noise displacement in bands", (0.0, 4.0)),
     _i("detail_scale", "float", 4.0, "noise features per UV unit", (0.0, 64.0))],
    [_o("value", "float"), _o("saw", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("rings", "Rings", "Procedural",
    "Concentric rings about a centre with a sine profile and noise distortion (wood, "
    "ripples); saw is the ramp within each ring.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5]),
     _i("frequency", "float", 8.0, "rings per UV unit", (0.0, 128.0)),
     _i("distortion", "float", 0.0, "noise displacement in rings", (0.0, 4.0)),
     _i("detail_scale", "float", 4.0, "noise features per UV unit", (0.0, 64.0))],
    [_o("value", "float"), _o("saw", "float")], thumbnail=Thumbnail.ALWAYS)
_fn("radial_gradient", "Radial Gradient", "Procedural",
    "The angle about a centre, 0 → 1 counter-clockwise from +u.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5])], [_o("value", "float")],
    thumbnail=Thumbnail.ALWAYS)
_fn("spherical_gradient", "Spherical Gradient", "Procedural",
    "1 at the centre falling to 0 at radius.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5]),
     _i("radius", "float", 0.5, "UV units", (0.0, 2.0))], [_o("value", "float")],
    thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("falloff_from_centre"))  # clamp(1 − |uv − c| / max(radius, 1e-6), 0, 1)
_fn("filtered_step", "Filtered Step", "Procedural",
    "step(edge, value) with the edge blurred over the pixel footprint of value: an "
    "anti-aliased threshold for any pattern.",
    [_i("edge", "float", 0.5), _i("value", "float"), _i(*_FILTER)], [_o("result", "float")])
_fn("filtered_smoothstep", "Filtered Smooth Step", "Procedural",
    "smoothstep(edge0, edge1, value) widened by the pixel footprint of value, so a narrow "
    "ramp never aliases.",
    [_i("edge0", "float", 0.4), _i("edge1", "float", 0.6), _i("value", "float"),
     _i(*_FILTER)], [_o("result", "float")])

# --- UV and space ----------------------------------------------------------------------------
_fn("tiling_offset", "Tiling and Offset", "Coordinates", "uv × tiling + offset.",
    [_i(*_UV), _i("tiling", "vec2", [1.0, 1.0]), _i("offset", "vec2", [0.0, 0.0])],
    [_o("uv", "vec2")], mtlx=MxRecipe("multiply_then_add"))
_fn("rotate_uv", "Rotate UV", "Coordinates", "Rotates uv about a pivot, counter-clockwise.",
    [_i(*_UV), _i("angle", "float", 0.0, "degrees", (0.0, 360.0)),
     _i("pivot", "vec2", [0.5, 0.5])], [_o("uv", "vec2")],
    mtlx=MxRecipe("rotate_about_pivot"))  # rotate2d turns clockwise: by −angle about 0
_fn("panner", "Panner", "Coordinates", "Scrolls uv over time: uv + speed × seconds.",
    [_i(*_UV), _i("speed", "vec2", [0.1, 0.0], "UV units per second")], [_o("uv", "vec2")],
    impure=True, geometry=True)
_fn("polar_coordinates", "Polar Coordinates", "Coordinates",
    "uv as (angle in turns, distance) about a centre: wraps patterns around a point.",
    [_i(*_UV), _i("center", "vec2", [0.5, 0.5])], [_o("uv", "vec2")])
_fn("object_position", "Object Position", "Coordinates",
    "Surface position in the object's own space.", [], [_o("position", "vec3")],
    impure=True, geometry=True)
_fn("tangent", "Tangent", "Coordinates",
    "World-space unit tangent (along +u), orthogonal to the normal.", [],
    [_o("tangent", "vec3")], impure=True, geometry=True)
_fn("bitangent", "Bitangent", "Coordinates",
    "World-space unit bitangent (along +v), normal × tangent with the mesh's handedness.",
    [], [_o("bitangent", "vec3")], impure=True, geometry=True)
_V3 = ("vector", "vec3", [0.0, 0.0, 1.0], "a direction")
for _a, _b in (("tangent", "world"), ("world", "tangent"), ("object", "world"),
               ("world", "object"), ("world", "view"), ("view", "world")):
    _fn(f"{_a}_to_{_b}", f"{_a.title()} to {_b.title()}", "Coordinates",
        f"Transforms a direction from {_a} space to {_b} space.", [_i(*_V3)],
        [_o("vector", "vec3")], impure=True, geometry=True)
_fn("triplanar_mapping", "Triplanar Mapping", "Coordinates",
    "Three planar projections of world position (onto YZ, XZ and XY) and their blend "
    "weights from the normal: feed each UV to a procedural, then a Triplanar Blend.",
    [_i("scale", "float", 1.0, "repeats per metre", (0.0, 64.0)),
     _i("sharpness", "float", 4.0, "blend sharpness (higher: crisper seams)", (1.0, 64.0))],
    [_o("uv_x", "vec2"), _o("uv_y", "vec2"), _o("uv_z", "vec2"), _o("weights", "vec3")],
    impure=True, geometry=True)
_op("triplanar_blend", "Triplanar Blend",
    "({x} * {weights}.x + {y} * {weights}.y + {z} * {weights}.z)",
    [_i("x", T), _i("y", T), _i("z", T), _i("weights", "vec3", [1 / 3] * 3, "", UNIT)],
    "Blends three projections by the Triplanar Mapping weights.", category="Coordinates",
    mtlx=MxRecipe("weighted_sum"))  # x w.x + y w.y + z w.z
_fn("triplanar_texture", "Triplanar Texture", "Texture",
    "Samples a texture by triplanar projection of world position, no UVs needed.",
    [_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
     _i("scale", "float", 1.0, "repeats per metre", (0.0, 64.0)),
     _i("sharpness", "float", 4.0, "", (1.0, 64.0))],
    [_o("rgba", "vec4"), _o("rgb", "vec3")], thumbnail=Thumbnail.ALWAYS, impure=True, geometry=True)

# --- normals ---------------------------------------------------------------------------------
_fn("normal_from_height", "Normal from Height", "Normal",
    "Tangent-space normal of a height field from its screen-space derivatives (bump "
    "mapping without a texture): strength is the relief depth, in UV units, of height 1.",
    [_i("height", "float", 0.0, "", UNIT),
     _i("strength", "float", 0.005, "relief depth in UV units", (0.0, 0.1))],
    [_o("normal", "vec3")], thumbnail=Thumbnail.ALWAYS)
_fn("normal_strength", "Normal Strength", "Normal",
    "Scales a tangent-space normal's tilt (0: flat, 1: unchanged, 2: twice as steep).",
    [_i("normal", "vec3", [0.0, 0.0, 1.0]), _i("strength", "float", 1.0, "", (0.0, 4.0))],
    [_o("normal", "vec3")])
_fn("flip_green", "Flip Green", "Normal",
    "Negates a tangent-space normal's Y: converts DirectX-convention normal maps to ours.",
    [_i("normal", "vec3", [0.0, 0.0, 1.0])], [_o("normal", "vec3")])

# --- masks -----------------------------------------------------------------------------------
_fn("fresnel", "Fresnel", "Mask",
    "Schlick's Fresnel of the geometric normal and view: base at normal incidence, 1 at "
    "grazing.",
    [_i("base", "float", 0.04, "reflectance facing the viewer", UNIT),
     _i("exponent", "float", 5.0, "", (0.0, 16.0))], [_o("value", "float")],
    impure=True, geometry=True)
_fn("facing_ratio", "Facing Ratio", "Mask",
    "N · V: 1 where the surface faces the camera, 0 at its silhouette.", [],
    [_o("value", "float")], impure=True, geometry=True)
_fn("slope_mask", "Slope Mask", "Mask",
    "1 where the surface faces up (world normal · up above threshold): snow, dust, moss.",
    [_i("up", "vec3", [0.0, 1.0, 0.0]), _i("threshold", "float", 0.5, "cosine", (-1.0, 1.0)),
     _i("softness", "float", 0.1, "", (0.0, 1.0))], [_o("mask", "float")],
    impure=True, geometry=True)
_fn("height_mask", "Height Mask", "Mask",
    "0 below low, 1 above high along the up axis in world space: grime at the bottom, "
    "water lines.",
    [_i("up", "vec3", [0.0, 1.0, 0.0]), _i("low", "float", -1.0, "metres", (-10.0, 10.0)),
     _i("high", "float", 1.0, "metres", (-10.0, 10.0))], [_o("mask", "float")],
    impure=True, geometry=True)
_fn("curvature", "Curvature", "Mask",
    "Mean curvature of the surface from screen-space derivatives of its normal (1/m), and "
    "its convex and concave parts scaled into [0, 1]: edge wear and cavity dirt without "
    "baked maps.",
    [_i("scale", "float", 0.5, "metres: mask reaches 1 at curvature 1/scale", (0.0, 10.0))],
    [_o("curvature", "float"), _o("convex", "float"), _o("concave", "float")],
    thumbnail=Thumbnail.ALWAYS, impure=True, geometry=True)

# The kinds this module adds, in registration order.
KINDS: tuple[str, ...] = tuple(k for k in REGISTRY if k not in _BEFORE)
