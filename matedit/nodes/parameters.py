"""Constants and the parameters artists tune (uniforms, textures, static switches)."""

from __future__ import annotations

from matedit.nodes.kind import (
    LOWERED,
    REGISTRY,
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

# --- constants and parameters ---------------------------------------------------------------
register(NodeDef(
    "constant", "Constant", "Constants", "A fixed value, folded into the shader.",
    outputs=(_o("value", T),),
    settings=(SettingDef("type", "type", "float", "float, vec2, vec3 or vec4",
                         choices=("float", "vec2", "vec3", "vec4")),
              SettingDef("value", "value", 0.0, "the constant (a number or a list)")),
    ports_rule=PortsRule.TYPE_SETTING,
    role=Role.CONSTANT, lowered=True, mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
))
_PARAM_SETTINGS = (
    SettingDef("name", "string", "param", "uniform name shown to artists"),
    SettingDef("group", "string", "", "inspector group", structural=False),
)
# How parameter panels present every parameter (issue 14); value edits, never recompiles.
_PRESENTATION = (
    SettingDef("order", "number", 0, "position within its group", structural=False),
    SettingDef("tooltip", "string", "", "help shown in parameter panels", structural=False),
)
register(NodeDef(
    "scalar_parameter", "Scalar Parameter", "Parameters",
    "A named number artists tune; compiles to a uniform, so edits never recompile.",
    outputs=(_o("value", "float"),),
    settings=_PARAM_SETTINGS + (
        SettingDef("ui_min", "number", 0.0, "slider minimum", structural=False),
        SettingDef("ui_max", "number", 1.0, "slider maximum", structural=False),
    ) + _PRESENTATION + (
        SettingDef("slider", "bool", True, "edit with a slider between ui_min and ui_max",
                   structural=False),
        SettingDef("exponent", "number", 1.0, "slider curve: value = lo + (hi - lo) * t^e",
                   structural=False)),
    values=(_i("value", "float", 0.5, "current value"),),
    role=Role.SCALAR_PARAMETER, parameter="scalar", lowered=True, mtlx=LOWERED,
    thumbnail=Thumbnail.NEVER,
))


def _vector_parameter(ctx, value):
    return value, value[:, :3]


def _vector_and_xyz(b: MxBuilder) -> Makers:  # the interface input, and its xyz
    def xyz() -> Ref:
        v = b.arg(0)
        c = b.constant(v)
        if c is not None:
            return b.value(tuple(c[:3]), "vector3")
        return b.node("convert", "vector3", "xyz", ("in", v))
    return [lambda: b.arg(0), xyz]


register(NodeDef(
    "vector_parameter", "Vector Parameter", "Parameters", "A named vec4 uniform.",
    outputs=(_o("value", "vec4"), _o("xyz", "vec3")),
    settings=_PARAM_SETTINGS + _PRESENTATION + (
        SettingDef("usage", "string", "data", "data or color (a colour picker for xyz)",
                   structural=False, choices=("data", "color")),
        SettingDef("ui_min", "number", 0.0, "field minimum", structural=False),
        SettingDef("ui_max", "number", 1.0, "field maximum", structural=False)),
    values=(_i("value", "vec4", [0.0, 0.0, 0.0, 1.0], "current value"),),
    glsl="node_vector_parameter", role=Role.VECTOR_PARAMETER, parameter="vector",
    mtlx=MxRecipe("vector_and_xyz", _vector_and_xyz), impure=True, thumbnail=Thumbnail.NEVER,
    numpy=_vector_parameter,
))
register(NodeDef(
    "color_parameter", "Colour Parameter", "Parameters",
    "A named linear RGB colour uniform (HDR: components may exceed 1).",
    outputs=(_o("color", "vec3"),),
    settings=_PARAM_SETTINGS + _PRESENTATION,
    values=(_i("value", "vec3", [0.5, 0.5, 0.5], "linear RGB"),),
    role=Role.COLOR_PARAMETER, parameter="color", lowered=True, mtlx=LOWERED,
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
    ) + _PRESENTATION,
    role=Role.TEXTURE_PARAMETER, parameter="texture", lowered=True,
    mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
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
        SettingDef("value", "bool", True, "on: use the 'true' input; structural"),
    ) + _PRESENTATION,  # matedit.compiler.lower chooses the branch
    role=Role.STATIC_SWITCH, parameter="switch", lowered=True, mtlx=LOWERED,
))
PARAMETER_KINDS = tuple(k for k, d in REGISTRY.items() if d.parameter is not None)
