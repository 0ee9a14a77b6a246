"""Node definitions as data: the catalogue of node kinds.

Each kind declares typed inputs (default, range, one-line doc), typed outputs, a
category and a description for the palette, its implementations per target (the name
of its GLSL function in `shaders/nodes/<kind>.glsl` or an inline template; its numpy
twin is `matedit.compiler.cpu_nodes.IMPLS[kind]`; its MaterialX mapping, `mtlx`), and
the facts code elsewhere needs: whether it is impure (not constant-foldable), when it
shows a thumbnail, whether it is a parameter, and for the structural kinds whose
semantics code must know, a `Role`. Code asks the definition (`definition(kind)`,
`role_of(kind)`, `kind_for(role)`), never compares kind names, so adding a node kind
touches no compiler, editor or exporter code.

Types are PortType names or `T`, a generic float-or-vector type resolved per
node from its connected inputs (a float input splats). A few kinds have ports
that depend on their settings or on a material function (`ports_rule`); those
rules live in `matedit.graph.ports`.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

# The data of a kind and the registry (matedit.graph.nodedef), read through this module.
from matedit.graph.nodedef import (  # noqa: F401
    BAKE,
    GENERIC,
    LOWERED,
    MESH_UV,
    REGISTRY,
    InputDef,
    Mtlx,
    MxNode,
    MxRecipe,
    NodeDef,
    OutputDef,
    PortsRule,
    Role,
    SettingDef,
    Thumbnail,
    _bin,
    _i,
    _o,
    _op,
    _un,
    categories,
    definition,
    get,
    is_impure,
    is_parameter,
    is_value_parameter,
    kind_for,
    kinds_where,
    register,
    role_of,
)


def _lobe(name, type_, default, doc, rng, group) -> InputDef:
    return InputDef(name, type_, default, doc, rng, group=group, lobe=True)

T = GENERIC
UNIT = (0.0, 1.0)
IOR_RANGE = (1.0, 3.0)

# --- constants and parameters ---------------------------------------------------------------
register(NodeDef(
    "constant", "Constant", "Constants", "A fixed value, folded into the shader.",
    outputs=(_o("value", T),),
    settings=(SettingDef("type", "type", "float", "float, vec2, vec3 or vec4",
                         choices=("float", "vec2", "vec3", "vec4")),
              SettingDef("value", "value", 0.0, "the constant (a number or a list)")),
    inline="{value}", ports_rule=PortsRule.TYPE_SETTING,
    role=Role.CONSTANT, lowered=True, mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
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
    inline="{value}", role=Role.SCALAR_PARAMETER, parameter="scalar", lowered=True, mtlx=LOWERED,
    thumbnail=Thumbnail.NEVER,
))
register(NodeDef(
    "vector_parameter", "Vector Parameter", "Parameters", "A named vec4 uniform.",
    outputs=(_o("value", "vec4"), _o("xyz", "vec3")),
    settings=_PARAM_SETTINGS,
    values=(_i("value", "vec4", [0.0, 0.0, 0.0, 1.0], "current value"),),
    glsl="node_vector_parameter", role=Role.VECTOR_PARAMETER, parameter="vector",
    mtlx=MxRecipe("vector_and_xyz"), impure=True, thumbnail=Thumbnail.NEVER,
))
register(NodeDef(
    "color_parameter", "Colour Parameter", "Parameters",
    "A named linear RGB colour uniform (HDR: components may exceed 1).",
    outputs=(_o("color", "vec3"),),
    settings=_PARAM_SETTINGS,
    values=(_i("value", "vec3", [0.5, 0.5, 0.5], "linear RGB"),),
    inline="{value}", role=Role.COLOR_PARAMETER, parameter="color", lowered=True, mtlx=LOWERED,
    thumbnail=Thumbnail.NEVER,
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
    inline="{texture}", role=Role.TEXTURE_PARAMETER, parameter="texture", lowered=True,
    mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
))

# --- maths -----------------------------------------------------------------------------------
_op("add", "Add", "({a} + {b})", [_i("a", T), _i("b", T)], "a + b, per component.",
    mtlx=_bin("add"))
_op("subtract", "Subtract", "({a} - {b})", [_i("a", T), _i("b", T)], "a − b, per component.",
    mtlx=_bin("subtract"))
_op("multiply", "Multiply", "({a} * {b})", [_i("a", T, 1.0), _i("b", T, 1.0)],
    "a × b, per component.", mtlx=_bin("multiply"))
_op("divide", "Divide", "({a} / {b})", [_i("a", T, 1.0), _i("b", T, 1.0)],
    "a ÷ b, per component (division by zero gives the GPU's infinity).",
    mtlx=_bin("divide"))
_op("lerp", "Lerp", "mix({a}, {b}, {alpha})",
    [_i("a", T), _i("b", T, 1.0), _i("alpha", T, 0.5, "blend factor", UNIT)],
    "Linear interpolation: a at alpha 0, b at alpha 1.",
    mtlx=MxNode("mix", (("a", "bg"), ("b", "fg"), ("alpha", "mix"))))
_op("clamp", "Clamp", "clamp({value}, {min}, {max})",
    [_i("value", T), _i("min", T, 0.0), _i("max", T, 1.0)], "Clamps value into [min, max].",
    mtlx=MxNode("clamp", (("value", "in"), ("min", "low"), ("max", "high"))))
_op("saturate", "Saturate", "clamp({value}, 0.0, 1.0)", [_i("value", T)],
    "Clamps value into [0, 1].",
    mtlx=MxNode("clamp", (("value", "in"),), (("low", 0.0), ("high", 1.0))))
_op("one_minus", "One Minus", "(1.0 - {value})", [_i("value", T)], "1 − value.",
    mtlx=MxRecipe("subtract_from_one"))  # subtract(1, value)
_op("power", "Power", "pow(max({base}, 0.0), {exponent})",
    [_i("base", T, 1.0), _i("exponent", T, 1.0)],
    "base raised to exponent; negative bases clamp to 0 (GLSL's pow is undefined there).",
    mtlx=MxRecipe("positive_power"),
    reads=MxNode("power", (("base", "in1"), ("exponent", "in2"))))  # power(max(base, 0), exponent)
_op("abs", "Abs", "abs({value})", [_i("value", T)], "Absolute value.", mtlx=_un("absval"))
_op("min", "Min", "min({a}, {b})", [_i("a", T), _i("b", T)], "Smaller of a and b.",
    mtlx=_bin("min"))
_op("max", "Max", "max({a}, {b})", [_i("a", T), _i("b", T)], "Larger of a and b.",
    mtlx=_bin("max"))
_op("dot", "Dot", "dot({a}, {b})", [_i("a", T), _i("b", T)], "Dot product.", out_type="float",
    category="Vector", mtlx=MxRecipe("dot_or_multiply"), reads=_bin("dotproduct"))
_op("cross", "Cross", "cross({a}, {b})",
    [_i("a", "vec3", [1.0, 0.0, 0.0]), _i("b", "vec3", [0.0, 1.0, 0.0])],
    "Cross product of two vec3.", out_type="vec3", category="Vector",
    mtlx=_bin("crossproduct"))
_op("normalize", "Normalize", None, [_i("value", T, 1.0)],
    "Unit vector in the direction of value (zero stays zero).", category="Vector",
    glsl="node_normalize", mtlx=MxRecipe("normalize_vector"),
    reads=_un("normalize"))
_op("length", "Length", "length({value})", [_i("value", T)], "Euclidean length.",
    out_type="float", category="Vector", mtlx=MxRecipe("magnitude_or_absval"),
    reads=_un("magnitude"))  # magnitude, or absval
_op("sqrt", "Square Root", "sqrt(max({value}, 0.0))", [_i("value", T, 1.0)],
    "Square root; negative input clamps to 0.",
    mtlx=MxRecipe("positive_sqrt"), reads=_un("sqrt"))  # sqrt(max(value, 0))
_op("sin", "Sine", "sin({value})", [_i("value", T)], "Sine of radians.", mtlx=_un("sin"))
_op("cos", "Cosine", "cos({value})", [_i("value", T)], "Cosine of radians.", mtlx=_un("cos"))
_op("frac", "Frac", "fract({value})", [_i("value", T)], "Fractional part, value − floor(value).",
    mtlx=MxNode("modulo", (("value", "in1"),), (("in2", 1.0),)))  # x - floor(x)
_op("floor", "Floor", "floor({value})", [_i("value", T)], "Largest integer not above value.",
    mtlx=_un("floor"))
_op("step", "Step", "step({edge}, {value})", [_i("edge", T, 0.5), _i("value", T)],
    "0 below edge, 1 at or above it.",
    mtlx=MxRecipe("floor_step"))  # clamp(floor(value - edge) + 1, 0, 1)
_op("smoothstep", "Smooth Step", "smoothstep({edge0}, {edge1}, {value})",
    [_i("edge0", T, 0.0), _i("edge1", T, 1.0), _i("value", T)],
    "Hermite ramp from 0 at edge0 to 1 at edge1.",
    mtlx=MxNode("smoothstep", (("value", "in"), ("edge0", "low"), ("edge1", "high"))))
_op("remap", "Remap", None,
    [_i("value", T), _i("in_min", T, 0.0), _i("in_max", T, 1.0),
     _i("out_min", T, 0.0), _i("out_max", T, 1.0)],
    "Maps value linearly from [in_min, in_max] to [out_min, out_max], unclamped.",
    glsl="node_remap",
    mtlx=MxNode("remap", (("value", "in"), ("in_min", "inlow"), ("in_max", "inhigh"),
                          ("out_min", "outlow"), ("out_max", "outhigh"))))

# --- vectors ---------------------------------------------------------------------------------
register(NodeDef(
    "component_mask", "Component Mask", "Vector",
    "Keeps the chosen channels of a vector (e.g. 'xy', 'b', 'rgb').",
    inputs=(_i("value", T),), outputs=(_o("result", T),),
    settings=(SettingDef("channels", "channels", "xy", "up to 4 of x y z w (or r g b a)"),),
    inline="{value}.{channels}", ports_rule=PortsRule.CHANNELS,
    role=Role.COMPONENT_MASK, lowered=True, mtlx=MxRecipe("mask"),  # extract / combineN
))
register(NodeDef(
    "split", "Split", "Vector", "Splits a vector into its components (missing ones read 0).",
    inputs=(_i("value", "vec4"),),
    outputs=(_o("x", "float"), _o("y", "float"), _o("z", "float"), _o("w", "float")),
    glsl="node_split", ports_rule=PortsRule.COMPONENTS,
    mtlx=MxRecipe("extract_each"),  # extract per component
))
register(NodeDef(
    "append", "Append", "Vector", "Concatenates two values into a longer vector (up to 4).",
    inputs=(_i("a", T), _i("b", T)), outputs=(_o("result", T),),
    inline="{result_type}({a}, {b})", ports_rule=PortsRule.CONCATENATION,
    role=Role.APPEND, lowered=True, mtlx=MxRecipe("concatenate"),  # extract / combineN
))
register(NodeDef(
    "combine", "Combine", "Vector", "Builds vectors from four scalars.",
    inputs=(_i("x", "float"), _i("y", "float"), _i("z", "float"), _i("w", "float", 1.0)),
    outputs=(_o("xy", "vec2"), _o("xyz", "vec3"), _o("xyzw", "vec4")),
    glsl="node_combine", mtlx=MxRecipe("combine_n"),  # combine2/3/4
))
register(NodeDef(
    "reroute", "Reroute", "Utility", "A wire waypoint; passes its value through.",
    inputs=(_i("value", T),), outputs=(_o("value", T),),
    inline="{value}", ports_rule=PortsRule.PASSTHROUGH,
    role=Role.REROUTE, lowered=True, mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
))

# --- geometry --------------------------------------------------------------------------------
register(NodeDef(
    "texcoord", "Texture Coordinate", "Coordinates",
    "The mesh's UV set, tiled and offset.",
    inputs=(_i("tiling", "vec2", [1.0, 1.0], "repeats across the surface"),
            _i("offset", "vec2", [0.0, 0.0], "shift in UV units")),
    outputs=(_o("uv", "vec2"),),
    glsl="node_texcoord", impure=True,
    mtlx=MxRecipe("tiled_texcoord"),  # texcoord * tiling + offset
))
register(NodeDef("world_position", "World Position", "Coordinates",
                 "Surface position in world space (metres).",
                 outputs=(_o("position", "vec3"),), glsl="node_world_position",
                 impure=True, geometry=True, mtlx=MxNode("position", ())))
register(NodeDef("world_normal", "World Normal", "Coordinates",
                 "Interpolated geometric normal in world space (before normal maps).",
                 outputs=(_o("normal", "vec3"),), glsl="node_world_normal",
                 impure=True, geometry=True, mtlx=MxNode("normal", ())))
register(NodeDef("view_direction", "View Direction", "Coordinates",
                 "Unit vector from the surface towards the camera, world space.",
                 outputs=(_o("direction", "vec3"),), glsl="node_view_direction",
                 impure=True, geometry=True,
                 mtlx=MxRecipe("negated_viewdirection")))  # -viewdirection: ours points at the eye
register(NodeDef("time", "Time", "Coordinates", "Seconds since the preview started.",
                 outputs=(_o("seconds", "float"),), glsl="node_time",
                 impure=True, geometry=True, thumbnail=Thumbnail.NEVER,
                 mtlx=MxNode("time", ())))

# --- textures and procedurals ----------------------------------------------------------------
register(NodeDef(
    "texture_sample", "Texture Sample", "Texture", "Samples a texture at uv (mesh UVs if unset).",
    inputs=(_i("texture", "texture2d", None, "from a Texture Parameter", required=True),
            _i("uv", "vec2", MESH_UV, "texture coordinates")),
    outputs=(_o("rgba", "vec4"), _o("rgb", "vec3"), _o("r", "float"), _o("g", "float"),
             _o("b", "float"), _o("a", "float")),
    glsl="node_texture_sample", role=Role.TEXTURE_SAMPLE, impure=True,
    thumbnail=Thumbnail.ALWAYS, mtlx=MxRecipe("image_read"),  # image (vector4)
))
register(NodeDef(
    "value_noise", "Value Noise", "Procedural",
    "Smooth value noise in [0, 1] over uv, summed over octaves.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("scale", "float", 8.0, "cells per UV unit", (0.0, 64.0)),
            _i("octaves", "float", 3.0, "detail levels (1-6)", (1.0, 6.0))),
    outputs=(_o("value", "float"),),
    glsl="node_value_noise", thumbnail=Thumbnail.ALWAYS,
    mtlx=BAKE,  # our PCG-hash lattice noise: the stdlib has no integer hash
))
register(NodeDef(
    "checker", "Checker", "Procedural",
    "A two-colour checkerboard over uv; edges box-filtered over the pixel footprint.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("scale", "float", 8.0, "squares per UV unit"),
            _i("color_a", "vec3", [0.9, 0.9, 0.9]), _i("color_b", "vec3", [0.1, 0.1, 0.1]),
            _i("filter_width", "float", 1.0, "edge blur in pixels (0: hard edges)", (0.0, 4.0))),
    outputs=(_o("color", "vec3"), _o("mask", "float")),
    glsl="node_checker", thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("checkerboard"),  # modulo(floor(u s) + floor(v s), 2) into a mix
))
register(NodeDef(
    "gradient", "Gradient", "Procedural", "Linear ramp 0→1 across uv along an angle.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("angle", "float", 0.0, "degrees", (0.0, 360.0))),
    outputs=(_o("value", "float"),),
    glsl="node_gradient", thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("linear_ramp"),  # clamp(dot(uv - 0.5, d) / (|dx| + |dy|) + 0.5)
))

# --- normals ---------------------------------------------------------------------------------
register(NodeDef(
    "unpack_normal", "Unpack Normal", "Normal",
    "Tangent-space normal from a normal-map texel in [0, 1] (OpenGL convention, +Y up).",
    inputs=(_i("packed", "vec3", [0.5, 0.5, 1.0]), _i("strength", "float", 1.0, "", (0.0, 2.0))),
    outputs=(_o("normal", "vec3"),),
    glsl="node_unpack_normal",
    mtlx=MxRecipe("decode_normal"),  # normalize((2 p - 1) * (s, s, 1))
))
register(NodeDef(
    "blend_normals", "Blend Normals", "Normal",
    "Detail normal on a base normal by reoriented normal mapping (Barré-Brisebois & Hill 2012).",
    inputs=(_i("base", "vec3", [0.0, 0.0, 1.0]), _i("detail", "vec3", [0.0, 0.0, 1.0])),
    outputs=(_o("normal", "vec3"),),
    glsl="node_blend_normals", mtlx=MxRecipe("reoriented_normals"),  # reoriented normal mapping
))
register(NodeDef(
    "flatten_normal", "Flatten Normal", "Normal",
    "Moves a tangent-space normal towards (0, 0, 1) by flatness.",
    inputs=(_i("normal", "vec3", [0.0, 0.0, 1.0]), _i("flatness", "float", 0.5, "", UNIT)),
    outputs=(_o("normal", "vec3"),),
    glsl="node_flatten_normal",
    mtlx=MxRecipe("mix_towards_z"),  # normalize(mix(n, +Z, flatness))
))

# --- material attributes ---------------------------------------------------------------------
MA = "MaterialAttributes"
_BASE_FIELDS = (
    _i("baseColor", "vec3", [0.5, 0.5, 0.5], "albedo of dielectrics, F0 of metals", UNIT),
    _i("metallic", "float", 0.0, "0 dielectric, 1 metal", UNIT),
    _i("roughness", "float", 0.5, "perceptual roughness", UNIT),
    _i("cavity", "float", 1.0, "small-scale shadowing, multiplies all lighting", UNIT),
    _i("normal", "vec3", [0.0, 0.0, 1.0], "tangent-space normal"),
    _i("emissive", "vec3", [0.0, 0.0, 0.0], "linear HDR emission"),
    _i("opacity", "float", 1.0, "coverage", UNIT),
)
ATTRIBUTE_FIELDS: tuple[InputDef, ...] = tuple(replace(f, group="Base") for f in _BASE_FIELDS) + (
    # Beyond the talk: each default turns its lobe off (docs/shading.md, Lobes beyond the talk).
    _lobe("specularColor", "vec3", [1.0, 1.0, 1.0], "tint of the dielectric F0", UNIT,
          "Specular"),
    _lobe("ior", "float", 1.5, "index of refraction of dielectrics: F0 = ((ior-1)/(ior+1))^2",
          IOR_RANGE, "Specular"),
    _lobe("coat", "float", 0.0, "clear coat weight", UNIT, "Coat"),
    _lobe("coatRoughness", "float", 0.0, "perceptual roughness of the coat", UNIT, "Coat"),
    _lobe("coatColor", "vec3", [1.0, 1.0, 1.0], "transmittance tint of the coat", UNIT,
          "Coat"),
    _lobe("coatIor", "float", 1.5, "index of refraction of the coat", IOR_RANGE, "Coat"),
    _lobe("coatNormal", "vec3", [0.0, 0.0, 1.0],
          "tangent-space normal of the coat (unconnected: the geometric normal)", None, "Coat"),
    _lobe("sheenColor", "vec3", [0.0, 0.0, 0.0], "sheen colour (black: no sheen)", UNIT,
          "Sheen"),
    _lobe("sheenRoughness", "float", 0.3, "sheen roughness", UNIT, "Sheen"),
    _lobe("anisotropy", "float", 0.0, "stretch of the highlight along the direction", UNIT,
          "Anisotropy"),
    _lobe("anisotropyDirection", "vec3", [1.0, 0.0, 0.0],
          "tangent-space direction the highlight stretches along (+X: the mesh tangent)",
          None, "Anisotropy"),
    _lobe("subsurface", "float", 0.0,
          "weight of the subsurface diffuse (wrapped diffuse and transmission from behind)",
          UNIT, "Subsurface"),
    _lobe("subsurfaceColor", "vec3", [1.0, 1.0, 1.0], "albedo of the subsurface diffuse",
          UNIT, "Subsurface"),
    _lobe("subsurfaceRadius", "vec3", [1.0, 1.0, 1.0],
          "mean free path per channel, metres (scene units)", (0.0, 2.0), "Subsurface"),
    _lobe("thickness", "float", 1.0,
          "thickness of the part, metres: wraps and transmits against the radius",
          (0.0, 2.0), "Subsurface"),
)
ATTRIBUTE_NAMES = tuple(f.name for f in ATTRIBUTE_FIELDS)


def _as_floats(value: Any) -> tuple[float, ...] | None:
    try:
        seq = value if isinstance(value, (list, tuple)) else [value]
        return tuple(float(x) for x in seq)
    except (TypeError, ValueError):
        return None


def lobe_value_is_default(node: Any, field_def: InputDef) -> bool:
    """Whether a Make Attributes' unconnected lobe input holds its off default (the lobe is
    then compiled out). A value that does not read as numbers counts as not default."""
    value = node.values.get(field_def.name, field_def.default)
    got, want = _as_floats(value), _as_floats(field_def.default)
    if got is None or want is None:
        return False
    return got == want or (len(got) == 1 and got * len(want) == want)


def lobe_input(kind: str, port: str) -> InputDef | None:
    """The definition of a Make Attributes' lobe input (see InputDef.lobe), else None."""
    d = REGISTRY.get(kind)
    if d is None or d.role != Role.MAKE_ATTRIBUTES:
        return None
    return next((i for i in d.inputs if i.name == port and i.lobe), None)
# The pin groups (InputDef.group) a Make / Break / Set Material Attributes shows expanded on
# the canvas; the others fold into a header row. View state kept with the document: changing
# it is undoable and never recompiles. A new node shows only Base.
EXPANDED_GROUPS = "expanded_groups"
EXPANDED_GROUPS_SETTING = SettingDef(EXPANDED_GROUPS, "list", ["Base"],
                                     "pin groups shown expanded on the canvas",
                                     structural=False)
BREAK_ATTRIBUTES = "break_attributes"  # the kind that splits a MaterialAttributes (no role)


def attribute_group(name: str) -> str:
    """The pin group of a material attribute field ("" for any other name)."""
    return next((f.group for f in ATTRIBUTE_FIELDS if f.name == name), "")


def port_group(kind: str, port: str) -> str:
    """The pin group a port of `kind` folds into ("" where the kind has no groups): the
    attribute fields of Make, Break and Set Material Attributes."""
    if kind != BREAK_ATTRIBUTES and role_of(kind) not in (Role.MAKE_ATTRIBUTES,
                                                         Role.SET_ATTRIBUTES):
        return ""
    return attribute_group(port) if port != "attributes" else ""


register(NodeDef(
    "make_attributes", "Make Material Attributes", "Material",
    "Builds a MaterialAttributes from its fields (the talk's seven, then the lobes beyond "
    "it, each off at its default).",
    inputs=ATTRIBUTE_FIELDS, outputs=(_o("attributes", MA),),
    settings=(EXPANDED_GROUPS_SETTING,),
    glsl="node_make_attributes", role=Role.MAKE_ATTRIBUTES, thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("attributes"),
))
register(NodeDef(
    "break_attributes", "Break Material Attributes", "Material",
    "Splits a MaterialAttributes into its fields.",
    inputs=(_i("attributes", MA, None, required=True),),
    outputs=tuple(_o(f.name, f.type, group=f.group) for f in ATTRIBUTE_FIELDS),
    settings=(EXPANDED_GROUPS_SETTING,),
    glsl="node_break_attributes", mtlx=MxRecipe("attributes"),
))
register(NodeDef(
    "set_attributes", "Set Material Attributes", "Material",
    "Overrides the chosen fields of a MaterialAttributes, keeping the others.",
    inputs=(_i("attributes", MA, None, required=True),),
    outputs=(_o("attributes", MA),),
    settings=(SettingDef("fields", "list", ["baseColor"], "fields to override"),
              EXPANDED_GROUPS_SETTING),
    ports_rule=PortsRule.ATTRIBUTE_FIELDS, role=Role.SET_ATTRIBUTES, lowered=True,
    mtlx=MxRecipe("attributes"),
))
register(NodeDef(
    "layer_blend", "Layer Blend (mask)", "Layers",
    "Blends layer over base by mask, field by field; normals by normalized lerp (nlerp).",
    inputs=(_i("base", MA, None, required=True), _i("layer", MA, None, required=True),
            _i("mask", "float", 1.0, "layer coverage", UNIT)),
    outputs=(_o("result", MA),),
    glsl="node_layer_blend", role=Role.MASK_BLEND, thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("blend"),  # a mix per field, the normal normalised
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
    glsl="node_height_blend", role=Role.HEIGHT_BLEND, thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("blend"),  # smoothstep(-c, c, dh) as the blend factor
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
    ports_rule=PortsRule.FUNCTION_INPUT, role=Role.FUNCTION_INPUT, lowered=True, mtlx=LOWERED,
))
register(NodeDef(
    "function_output", "Function Output", "Function",
    "An output of the material function this graph defines.",
    inputs=(_i("value", T),),
    settings=(SettingDef("name", "string", "result", "output name"),
              SettingDef("type", "type", "float", "output type",
                         choices=("float", "vec2", "vec3", "vec4", MA)),
              SettingDef("order", "number", 0, "position among the outputs")),
    ports_rule=PortsRule.FUNCTION_OUTPUT, role=Role.FUNCTION_OUTPUT, lowered=True, mtlx=LOWERED,
    thumbnail=Thumbnail.NEVER,
))
register(NodeDef(
    "function_call", "Function Call", "Function",
    "Calls a material function stored in its own file.",
    settings=(SettingDef("function", "path", "", "function file, relative to this file"),),
    ports_rule=PortsRule.FUNCTION_SIGNATURE, role=Role.FUNCTION_CALL, lowered=True, mtlx=LOWERED,
    thumbnail=Thumbnail.ALWAYS,
))
register(NodeDef(
    "layer_stack", "Layer Stack", "Layers",
    "Material layers bottom to top, each blended over the ones below by its mask; "
    "compiles to blends of attributes and one shading evaluation.",
    outputs=(_o("attributes", MA),),
    settings=(SettingDef("layers", "list", [], "base layer first, then the layers above"),),
    ports_rule=PortsRule.LAYERS, role=Role.LAYER_STACK, lowered=True, mtlx=LOWERED,
    thumbnail=Thumbnail.ALWAYS,
))
register(NodeDef(
    "material_output", "Material Output", "Output",
    "The material's result: one MaterialAttributes, shaded once.",
    inputs=(_i("attributes", MA, None, required=True),),
    role=Role.MATERIAL_OUTPUT, lowered=True, mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
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
    role=Role.STATIC_SWITCH, parameter="switch", lowered=True, mtlx=LOWERED,
))
PARAMETER_KINDS = tuple(k for k, d in REGISTRY.items() if d.parameter is not None)
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
