"""Node definitions as data: the catalogue of node kinds.

Each kind declares typed inputs (default, range, one-line doc), typed outputs, a
category and a description for the palette, and the names of its GLSL function
(`shaders/nodes/<kind>.glsl`) or inline template, and its numpy implementation.
Adding a node kind touches no compiler code.

Types are PortType names or `T`, a generic float-or-vector type resolved per
node from its connected inputs (a float input splats). A few kinds have ports
that depend on their settings or on a material function (`ports_rule`); those
rules live in `matedit.graph.ports`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

GENERIC = "T"
# Default marker: an unconnected input with this default reads the mesh's first UV set.
MESH_UV = "mesh_uv"


@dataclass(frozen=True)
class InputDef:
    name: str
    type: str
    default: Any = 0.0
    doc: str = ""
    range: tuple[float, float] | None = None
    required: bool = False


@dataclass(frozen=True)
class OutputDef:
    name: str
    type: str
    doc: str = ""


@dataclass(frozen=True)
class SettingDef:
    """A node property that is not a port: a parameter's name, a mask's channels, a path.

    `structural` settings change the generated code; the others (a texture's
    file, a slider's range) are value edits and never recompile.
    """

    name: str
    kind: str  # "string" | "type" | "channels" | "path" | "bool" | "number" | "value" | "list"
    default: Any = None
    doc: str = ""
    structural: bool = True
    choices: tuple[str, ...] = ()


@dataclass(frozen=True)
class NodeDef:
    kind: str
    title: str
    category: str
    description: str
    inputs: tuple[InputDef, ...] = ()
    outputs: tuple[OutputDef, ...] = ()
    settings: tuple[SettingDef, ...] = ()
    glsl: str | None = None  # GLSL function name in shaders/nodes/<kind>.glsl
    inline: str | None = None  # inline GLSL template, e.g. "({a} + {b})"
    numpy: str | None = None  # name of the numpy implementation
    ports_rule: str | None = None  # dynamic ports, see matedit.graph.ports
    # Extra value fields that are not ports (a parameter's value): edits are value edits.
    values: tuple[InputDef, ...] = ()
    # Output type rule for generic nodes: "T" (same as inputs) or fixed per output.
    keywords: tuple[str, ...] = field(default_factory=tuple)
    # MaterialX standard-library equivalent: a node name (same port names) or
    # {"node": name, "inputs": {our port: its input}, "outputs": {...}}; None: not expressible.
    mtlx: str | dict[str, Any] | None = None

    def input(self, name: str) -> InputDef | None:
        return next((i for i in self.inputs if i.name == name), None)

    def output(self, name: str) -> OutputDef | None:
        return next((o for o in self.outputs if o.name == name), None)

    def setting(self, name: str) -> SettingDef | None:
        return next((s for s in self.settings if s.name == name), None)

    def setting_defaults(self) -> dict[str, Any]:
        return {s.name: s.default for s in self.settings}


REGISTRY: dict[str, NodeDef] = {}


def register(defn: NodeDef) -> NodeDef:
    if defn.kind in REGISTRY:
        raise ValueError(f"node kind {defn.kind!r} registered twice")
    if (defn.glsl is None) == (defn.inline is None) and defn.ports_rule is None:
        raise ValueError(f"node kind {defn.kind!r} needs exactly one of glsl= or inline=")
    REGISTRY[defn.kind] = defn
    return defn


def get(kind: str) -> NodeDef | None:
    return REGISTRY.get(kind)


def categories() -> dict[str, list[NodeDef]]:
    """Node kinds by palette category, sorted by title."""
    out: dict[str, list[NodeDef]] = {}
    for d in sorted(REGISTRY.values(), key=lambda d: (d.category, d.title)):
        out.setdefault(d.category, []).append(d)
    return out


# --- helpers to keep the table short -------------------------------------------------------

def _i(name, type_, default=0.0, doc="", rng=None, required=False) -> InputDef:
    return InputDef(name, type_, default, doc, rng, required)


def _o(name, type_, doc="") -> OutputDef:
    return OutputDef(name, type_, doc)


def _op(kind, title, inline, inputs, doc, out_type=GENERIC, category="Math", glsl=None,
        mtlx=None):
    register(NodeDef(
        kind=kind, title=title, category=category, description=doc,
        inputs=tuple(inputs), outputs=(_o("result", out_type),),
        inline=inline if glsl is None else None, glsl=glsl, numpy=kind, mtlx=mtlx,
    ))


T = GENERIC
UNIT = (0.0, 1.0)

# --- constants and parameters ---------------------------------------------------------------
register(NodeDef(
    "constant", "Constant", "Constants", "A fixed value, folded into the shader.",
    outputs=(_o("value", T),),
    settings=(SettingDef("type", "type", "float", "float, vec2, vec3 or vec4",
                         choices=("float", "vec2", "vec3", "vec4")),
              SettingDef("value", "value", 0.0, "the constant (a number or a list)")),
    inline="{value}", numpy="constant", ports_rule="constant",
))
_PARAM_SETTINGS = (
    SettingDef("name", "string", "param", "uniform name shown to artists"),
    SettingDef("group", "string", "", "inspector group", structural=False),
)
register(NodeDef(
    "scalar_parameter", "Scalar Parameter", "Parameters",
    "A named number artists tune; compiles to a uniform, so edits never recompile.",
    outputs=(_o("value", "float"),),
    settings=_PARAM_SETTINGS + (
        SettingDef("ui_min", "number", 0.0, "slider minimum", structural=False),
        SettingDef("ui_max", "number", 1.0, "slider maximum", structural=False),
    ),
    values=(_i("value", "float", 0.5, "current value"),),
    inline="{value}", numpy="parameter",
))
register(NodeDef(
    "vector_parameter", "Vector Parameter", "Parameters", "A named vec4 uniform.",
    outputs=(_o("value", "vec4"), _o("xyz", "vec3")),
    settings=_PARAM_SETTINGS,
    values=(_i("value", "vec4", [0.0, 0.0, 0.0, 1.0], "current value"),),
    glsl="node_vector_parameter", numpy="vector_parameter",
))
register(NodeDef(
    "color_parameter", "Colour Parameter", "Parameters",
    "A named linear RGB colour uniform (HDR: components may exceed 1).",
    outputs=(_o("color", "vec3"),),
    settings=_PARAM_SETTINGS,
    values=(_i("value", "vec3", [0.5, 0.5, 0.5], "linear RGB"),),
    inline="{value}", numpy="parameter",
))
register(NodeDef(
    "texture_parameter", "Texture Parameter", "Parameters",
    "A named texture; the file is a value edit and never recompiles.",
    outputs=(_o("texture", "texture2d"),),
    settings=_PARAM_SETTINGS + (
        SettingDef("path", "path", "", "image file, relative to the material", structural=False),
        SettingDef("srgb", "bool", True, "colour data stored as sRGB (decoded to linear "
                   "before filtering); off for data: normals, roughness, masks"),
        SettingDef("color_space", "string", "", "colour space: srgb, linear or an "
                   "OpenColorIO space of OpenImageIO's built-in config (e.g. ACEScg); "
                   "empty: the srgb setting decides"),
    ),
    inline="{texture}", numpy="texture_parameter",
))

# --- maths -----------------------------------------------------------------------------------
_op("add", "Add", "({a} + {b})", [_i("a", T), _i("b", T)], "a + b, per component.")
_op("subtract", "Subtract", "({a} - {b})", [_i("a", T), _i("b", T)], "a − b, per component.")
_op("multiply", "Multiply", "({a} * {b})", [_i("a", T, 1.0), _i("b", T, 1.0)],
    "a × b, per component.")
_op("divide", "Divide", "({a} / {b})", [_i("a", T, 1.0), _i("b", T, 1.0)],
    "a ÷ b, per component (division by zero gives the GPU's infinity).")
_op("lerp", "Lerp", "mix({a}, {b}, {alpha})",
    [_i("a", T), _i("b", T, 1.0), _i("alpha", T, 0.5, "blend factor", UNIT)],
    "Linear interpolation: a at alpha 0, b at alpha 1.")
_op("clamp", "Clamp", "clamp({value}, {min}, {max})",
    [_i("value", T), _i("min", T, 0.0), _i("max", T, 1.0)], "Clamps value into [min, max].")
_op("saturate", "Saturate", "clamp({value}, 0.0, 1.0)", [_i("value", T)],
    "Clamps value into [0, 1].")
_op("one_minus", "One Minus", "(1.0 - {value})", [_i("value", T)], "1 − value.")
_op("power", "Power", "pow(max({base}, 0.0), {exponent})",
    [_i("base", T, 1.0), _i("exponent", T, 1.0)],
    "base raised to exponent; negative bases clamp to 0 (GLSL's pow is undefined there).")
_op("abs", "Abs", "abs({value})", [_i("value", T)], "Absolute value.")
_op("min", "Min", "min({a}, {b})", [_i("a", T), _i("b", T)], "Smaller of a and b.")
_op("max", "Max", "max({a}, {b})", [_i("a", T), _i("b", T)], "Larger of a and b.")
_op("dot", "Dot", "dot({a}, {b})", [_i("a", T), _i("b", T)], "Dot product.", out_type="float",
    category="Vector")
_op("cross", "Cross", "cross({a}, {b})",
    [_i("a", "vec3", [1.0, 0.0, 0.0]), _i("b", "vec3", [0.0, 1.0, 0.0])],
    "Cross product of two vec3.", out_type="vec3", category="Vector")
_op("normalize", "Normalize", None, [_i("value", T, 1.0)],
    "Unit vector in the direction of value (zero stays zero).", category="Vector",
    glsl="node_normalize")
_op("length", "Length", "length({value})", [_i("value", T)], "Euclidean length.",
    out_type="float", category="Vector")
_op("sqrt", "Square Root", "sqrt(max({value}, 0.0))", [_i("value", T, 1.0)],
    "Square root; negative input clamps to 0.")
_op("sin", "Sine", "sin({value})", [_i("value", T)], "Sine of radians.")
_op("cos", "Cosine", "cos({value})", [_i("value", T)], "Cosine of radians.")
_op("frac", "Frac", "fract({value})", [_i("value", T)], "Fractional part, value − floor(value).")
_op("floor", "Floor", "floor({value})", [_i("value", T)], "Largest integer not above value.")
_op("step", "Step", "step({edge}, {value})", [_i("edge", T, 0.5), _i("value", T)],
    "0 below edge, 1 at or above it.")
_op("smoothstep", "Smooth Step", "smoothstep({edge0}, {edge1}, {value})",
    [_i("edge0", T, 0.0), _i("edge1", T, 1.0), _i("value", T)],
    "Hermite ramp from 0 at edge0 to 1 at edge1.")
_op("remap", "Remap", None,
    [_i("value", T), _i("in_min", T, 0.0), _i("in_max", T, 1.0),
     _i("out_min", T, 0.0), _i("out_max", T, 1.0)],
    "Maps value linearly from [in_min, in_max] to [out_min, out_max], unclamped.",
    glsl="node_remap")

# --- vectors ---------------------------------------------------------------------------------
register(NodeDef(
    "component_mask", "Component Mask", "Vector",
    "Keeps the chosen channels of a vector (e.g. 'xy', 'b', 'rgb').",
    inputs=(_i("value", T),), outputs=(_o("result", T),),
    settings=(SettingDef("channels", "channels", "xy", "up to 4 of x y z w (or r g b a)"),),
    inline="{value}.{channels}", numpy="component_mask", ports_rule="component_mask",
))
register(NodeDef(
    "split", "Split", "Vector", "Splits a vector into its components (missing ones read 0).",
    inputs=(_i("value", "vec4"),),
    outputs=(_o("x", "float"), _o("y", "float"), _o("z", "float"), _o("w", "float")),
    glsl="node_split", numpy="split", ports_rule="split",
))
register(NodeDef(
    "append", "Append", "Vector", "Concatenates two values into a longer vector (up to 4).",
    inputs=(_i("a", T), _i("b", T)), outputs=(_o("result", T),),
    inline="{result_type}({a}, {b})", numpy="append", ports_rule="append",
))
register(NodeDef(
    "combine", "Combine", "Vector", "Builds vectors from four scalars.",
    inputs=(_i("x", "float"), _i("y", "float"), _i("z", "float"), _i("w", "float", 1.0)),
    outputs=(_o("xy", "vec2"), _o("xyz", "vec3"), _o("xyzw", "vec4")),
    glsl="node_combine", numpy="combine",
))
register(NodeDef(
    "reroute", "Reroute", "Utility", "A wire waypoint; passes its value through.",
    inputs=(_i("value", T),), outputs=(_o("value", T),),
    inline="{value}", numpy="reroute", ports_rule="reroute",
))

# --- geometry --------------------------------------------------------------------------------
register(NodeDef(
    "texcoord", "Texture Coordinate", "Coordinates",
    "The mesh's UV set, tiled and offset.",
    inputs=(_i("tiling", "vec2", [1.0, 1.0], "repeats across the surface"),
            _i("offset", "vec2", [0.0, 0.0], "shift in UV units")),
    outputs=(_o("uv", "vec2"),),
    glsl="node_texcoord", numpy="texcoord",
))
register(NodeDef("world_position", "World Position", "Coordinates",
                 "Surface position in world space (metres).",
                 outputs=(_o("position", "vec3"),), glsl="node_world_position",
                 numpy="world_position"))
register(NodeDef("world_normal", "World Normal", "Coordinates",
                 "Interpolated geometric normal in world space (before normal maps).",
                 outputs=(_o("normal", "vec3"),), glsl="node_world_normal",
                 numpy="world_normal"))
register(NodeDef("view_direction", "View Direction", "Coordinates",
                 "Unit vector from the surface towards the camera, world space.",
                 outputs=(_o("direction", "vec3"),), glsl="node_view_direction",
                 numpy="view_direction"))
register(NodeDef("time", "Time", "Coordinates", "Seconds since the preview started.",
                 outputs=(_o("seconds", "float"),), glsl="node_time", numpy="time"))

# --- textures and procedurals ----------------------------------------------------------------
register(NodeDef(
    "texture_sample", "Texture Sample", "Texture", "Samples a texture at uv (mesh UVs if unset).",
    inputs=(_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
            _i("uv", "vec2", MESH_UV, "texture coordinates")),
    outputs=(_o("rgba", "vec4"), _o("rgb", "vec3"), _o("r", "float"), _o("g", "float"),
             _o("b", "float"), _o("a", "float")),
    glsl="node_texture_sample", numpy="texture_sample",
))
register(NodeDef(
    "value_noise", "Value Noise", "Procedural",
    "Smooth value noise in [0, 1] over uv, summed over octaves.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("scale", "float", 8.0, "cells per UV unit", (0.0, 64.0)),
            _i("octaves", "float", 3.0, "detail levels (1-6)", (1.0, 6.0))),
    outputs=(_o("value", "float"),),
    glsl="node_value_noise", numpy="value_noise",
))
register(NodeDef(
    "checker", "Checker", "Procedural",
    "A two-colour checkerboard over uv; edges box-filtered over the pixel footprint.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("scale", "float", 8.0, "squares per UV unit"),
            _i("color_a", "vec3", [0.9, 0.9, 0.9]), _i("color_b", "vec3", [0.1, 0.1, 0.1]),
            _i("filter_width", "float", 1.0, "edge blur in pixels (0: hard edges)", (0.0, 4.0))),
    outputs=(_o("color", "vec3"), _o("mask", "float")),
    glsl="node_checker", numpy="checker",
))
register(NodeDef(
    "gradient", "Gradient", "Procedural", "Linear ramp 0→1 across uv along an angle.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("angle", "float", 0.0, "degrees", (0.0, 360.0))),
    outputs=(_o("value", "float"),),
    glsl="node_gradient", numpy="gradient",
))

# --- normals ---------------------------------------------------------------------------------
register(NodeDef(
    "unpack_normal", "Unpack Normal", "Normal",
    "Tangent-space normal from a normal-map texel in [0, 1] (OpenGL convention, +Y up).",
    inputs=(_i("packed", "vec3", [0.5, 0.5, 1.0]), _i("strength", "float", 1.0, "", (0.0, 2.0))),
    outputs=(_o("normal", "vec3"),),
    glsl="node_unpack_normal", numpy="unpack_normal",
))
register(NodeDef(
    "blend_normals", "Blend Normals", "Normal",
    "Detail normal on a base normal by reoriented normal mapping (Barré-Brisebois & Hill 2012).",
    inputs=(_i("base", "vec3", [0.0, 0.0, 1.0]), _i("detail", "vec3", [0.0, 0.0, 1.0])),
    outputs=(_o("normal", "vec3"),),
    glsl="node_blend_normals", numpy="blend_normals",
))
register(NodeDef(
    "flatten_normal", "Flatten Normal", "Normal",
    "Moves a tangent-space normal towards (0, 0, 1) by flatness.",
    inputs=(_i("normal", "vec3", [0.0, 0.0, 1.0]), _i("flatness", "float", 0.5, "", UNIT)),
    outputs=(_o("normal", "vec3"),),
    glsl="node_flatten_normal", numpy="flatten_normal",
))

# --- material attributes ---------------------------------------------------------------------
MA = "MaterialAttributes"
ATTRIBUTE_FIELDS: tuple[InputDef, ...] = (
    _i("baseColor", "vec3", [0.5, 0.5, 0.5], "albedo of dielectrics, F0 of metals", UNIT),
    _i("metallic", "float", 0.0, "0 dielectric, 1 metal", UNIT),
    _i("roughness", "float", 0.5, "perceptual roughness", UNIT),
    _i("cavity", "float", 1.0, "small-scale shadowing, multiplies all lighting", UNIT),
    _i("normal", "vec3", [0.0, 0.0, 1.0], "tangent-space normal"),
    _i("emissive", "vec3", [0.0, 0.0, 0.0], "linear HDR emission"),
    _i("opacity", "float", 1.0, "coverage", UNIT),
)
ATTRIBUTE_NAMES = tuple(f.name for f in ATTRIBUTE_FIELDS)
register(NodeDef(
    "make_attributes", "Make Material Attributes", "Material",
    "Builds a MaterialAttributes from its seven fields.",
    inputs=ATTRIBUTE_FIELDS, outputs=(_o("attributes", MA),),
    glsl="node_make_attributes", numpy="make_attributes",
))
register(NodeDef(
    "break_attributes", "Break Material Attributes", "Material",
    "Splits a MaterialAttributes into its fields.",
    inputs=(_i("attributes", MA, None, required=True),),
    outputs=tuple(_o(f.name, f.type) for f in ATTRIBUTE_FIELDS),
    glsl="node_break_attributes", numpy="break_attributes",
))
register(NodeDef(
    "set_attributes", "Set Material Attributes", "Material",
    "Overrides the chosen fields of a MaterialAttributes, keeping the others.",
    inputs=(_i("attributes", MA, None, required=True),),
    outputs=(_o("attributes", MA),),
    settings=(SettingDef("fields", "list", ["baseColor"], "fields to override"),),
    inline="", numpy="set_attributes", ports_rule="set_attributes",
))
register(NodeDef(
    "layer_blend", "Layer Blend (mask)", "Layers",
    "Blends layer over base by mask, field by field; normals by normalized lerp (nlerp).",
    inputs=(_i("base", MA, None, required=True), _i("layer", MA, None, required=True),
            _i("mask", "float", 1.0, "layer coverage", UNIT)),
    outputs=(_o("result", MA),),
    glsl="node_layer_blend", numpy="layer_blend",
))
register(NodeDef(
    "height_blend", "Layer Blend (height)", "Layers",
    "Blends layer over base where the layer's height rises above the base's, with a soft "
    "transition of width contrast.",
    inputs=(_i("base", MA, None, required=True), _i("layer", MA, None, required=True),
            _i("base_height", "float", 0.5, "height of the base surface", UNIT),
            _i("layer_height", "float", 0.5, "height of the layer (e.g. its mask)", UNIT),
            _i("contrast", "float", 0.1, "transition width", (0.001, 1.0))),
    outputs=(_o("result", MA),),
    glsl="node_height_blend", numpy="height_blend",
))

# --- functions, layers, output ---------------------------------------------------------------
register(NodeDef(
    "function_input", "Function Input", "Function",
    "An input of the material function this graph defines.",
    outputs=(_o("value", T),),
    settings=(SettingDef("name", "string", "input", "input name"),
              SettingDef("type", "type", "float", "input type",
                         choices=("float", "vec2", "vec3", "vec4", MA, "texture2d")),
              SettingDef("default", "value", 0.0, "value when the caller leaves it unconnected"),
              SettingDef("order", "number", 0, "position among the inputs", structural=True)),
    inline="", numpy="function_input", ports_rule="function_input",
))
register(NodeDef(
    "function_output", "Function Output", "Function",
    "An output of the material function this graph defines.",
    inputs=(_i("value", T),),
    settings=(SettingDef("name", "string", "result", "output name"),
              SettingDef("type", "type", "float", "output type",
                         choices=("float", "vec2", "vec3", "vec4", MA)),
              SettingDef("order", "number", 0, "position among the outputs")),
    inline="", numpy="function_output", ports_rule="function_output",
))
register(NodeDef(
    "function_call", "Function Call", "Function",
    "Calls a material function stored in its own file.",
    settings=(SettingDef("function", "path", "", "function file, relative to this file"),),
    inline="", numpy="function_call", ports_rule="function_call",
))
register(NodeDef(
    "layer_stack", "Layer Stack", "Layers",
    "Material layers bottom to top, each blended over the ones below by its mask; "
    "compiles to blends of attributes and one shading evaluation.",
    outputs=(_o("attributes", MA),),
    settings=(SettingDef("layers", "list", [], "base layer first, then the layers above"),),
    inline="", numpy="layer_stack", ports_rule="layer_stack",
))
register(NodeDef(
    "material_output", "Material Output", "Output",
    "The material's result: one MaterialAttributes, shaded once.",
    inputs=(_i("attributes", MA, None, required=True),),
    inline="", numpy="material_output",
))

# --- instances: static switches and parameter presentation (issue 14) ----------------------
# A static switch is a parameter an instance may override, fixed at compile time: the
# compiler keeps the chosen input and drops the other branch with its uniforms and textures.
register(NodeDef(
    "static_switch", "Static Switch", "Parameters",
    "Chooses one of two inputs when the shader is compiled (a named bool an instance may "
    "override); the unused branch is compiled out with its uniforms and textures.",
    inputs=(_i("true", T, 1.0, "used when the switch is on"),
            _i("false", T, 0.0, "used when the switch is off")),
    outputs=(_o("result", T),),
    settings=_PARAM_SETTINGS + (
        SettingDef("value", "bool", True, "on: use the 'true' input; structural"),),
    inline="{true}",  # never emitted: matedit.compiler.lower chooses the branch
))
PARAMETER_KINDS = ("scalar_parameter", "vector_parameter", "color_parameter",
                   "texture_parameter", "static_switch")
_PRESENTATION = {
    "*": (SettingDef("order", "number", 0, "position within its group", structural=False),
          SettingDef("tooltip", "string", "", "help shown in parameter panels",
                     structural=False)),
    "scalar_parameter": (
        SettingDef("slider", "bool", True, "edit with a slider between ui_min and ui_max",
                   structural=False),
        SettingDef("exponent", "number", 1.0, "slider curve: value = lo + (hi - lo) * t^e",
                   structural=False)),
    "vector_parameter": (
        SettingDef("usage", "string", "data", "data or color (a colour picker for xyz)",
                   structural=False, choices=("data", "color")),
        SettingDef("ui_min", "number", 0.0, "field minimum", structural=False),
        SettingDef("ui_max", "number", 1.0, "field maximum", structural=False)),
}
for _kind in PARAMETER_KINDS:
    _d = REGISTRY[_kind]
    _have = {s.name for s in _d.settings}
    _more = tuple(s for s in _PRESENTATION["*"] + _PRESENTATION.get(_kind, ())
                  if s.name not in _have)
    REGISTRY[_kind] = NodeDef(**{**_d.__dict__, "settings": _d.settings + _more})
del _kind, _d, _have, _more

# The library beyond the basics lives in its own module, registered on import.
from matedit.graph import library as _library  # noqa: E402,F401
