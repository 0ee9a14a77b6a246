"""Material attributes, the layer blends, material functions and the output."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

from matedit.nodes.kind import (
    IOR_RANGE,
    LOWERED,
    REGISTRY,
    UNIT,
    InputDef,
    MxRecipe,
    NodeDef,
    PortsRule,
    Role,
    SettingDef,
    T,
    Thumbnail,
    _i,
    _o,
    register,
    role_of,
)
from matedit.nodes.twin import _X, _Z, Attributes, _col, _mix, _safe_normalize, _smoothstep

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



def _lobe(name, type_, default, doc, rng, group) -> InputDef:
    return InputDef(name, type_, default, doc, rng, group=group, lobe=True)


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
    _lobe("thinFilmThickness", "float", 0.0,
          "thickness of a thin film on the base, nm (0: no film): iridescence", (0.0, 2000.0),
          "Thin film"),
    _lobe("thinFilmIor", "float", 1.3, "index of refraction of the thin film", (1.0, 3.0),
          "Thin film"),
    _lobe("transmission", "float", 0.0,
          "weight of the specular transmission (glass: 1; what the reflection leaves passes)",
          UNIT, "Transmission"),
    _lobe("transmissionColor", "vec3", [1.0, 1.0, 1.0], "tint of the transmitted light",
          UNIT, "Transmission"),
    _lobe("attenuationColor", "vec3", [1.0, 1.0, 1.0],
          "colour white light takes after attenuationDistance inside (Beer-Lambert)", UNIT,
          "Transmission"),
    _lobe("attenuationDistance", "float", 0.0,
          "distance, metres (scene units), light travels inside to reach attenuationColor; "
          "0: no absorption", (0.0, 2.0), "Transmission"),
)
# The fields' hard bounds (Port.limits): weights and roughnesses in [0, 1], indices of
# refraction from 1, colours, lengths and thicknesses from 0.
_WEIGHT, _IOR, _POSITIVE = (0.0, 1.0), (1.0, None), (0.0, None)
FIELD_LIMITS: dict[str, tuple[float | None, float | None]] = {
    **dict.fromkeys(("metallic", "roughness", "cavity", "opacity", "coat", "coatRoughness",
                     "sheenRoughness", "anisotropy", "subsurface", "transmission"), _WEIGHT),
    **dict.fromkeys(("ior", "coatIor", "thinFilmIor"), _IOR),
    **dict.fromkeys(("baseColor", "emissive", "specularColor", "coatColor", "sheenColor",
                     "subsurfaceColor", "subsurfaceRadius", "thickness", "transmissionColor",
                     "attenuationColor", "attenuationDistance", "thinFilmThickness"),
                    _POSITIVE),
}
ATTRIBUTE_FIELDS = tuple(replace(f, limits=FIELD_LIMITS.get(f.name)) for f in ATTRIBUTE_FIELDS)
ATTRIBUTE_NAMES = tuple(f.name for f in ATTRIBUTE_FIELDS)


def blend_material_attributes(a: Attributes, b: Attributes, t: np.ndarray) -> Attributes:
    """blendMaterialAttributes (shaders/nodes/layer_blend.glsl): a at t = 0, b at t = 1;
    every field linearly, the tangent-space normal by nlerp (falling back to (0, 0, 1))."""
    out = {}
    for name in ATTRIBUTE_NAMES:
        x, y = a[name], b[name]
        out[name] = _mix(x, y, _col(t) if x.ndim == 2 else t)
    out["normal"] = _safe_normalize(out["normal"], _Z)
    out["coatNormal"] = _safe_normalize(out["coatNormal"], _Z)
    out["anisotropyDirection"] = _safe_normalize(out["anisotropyDirection"], _X)
    return out


def coat_layer_share(below: np.ndarray, w: np.ndarray) -> np.ndarray:
    """coatLayerShare (shaders/nodes/layer_blend.glsl): the new coat's share w / coverage of
    the coverage w + (1 - w) a of a coat of weight w over one of weight a (independent
    presences, OpenPBR's coat_weight); 0 where w = 0, so the coat below is kept exactly.
    OpenPBR 2024, "OpenPBR Surface Specification", coat_weight"""
    coverage = w + (1.0 - w) * below
    return w / np.maximum(coverage, 1e-6)


def coat_material_attributes(base: Attributes, layer: Attributes, w: np.ndarray) -> Attributes:
    """coatMaterialAttributes (shaders/nodes/layer_blend.glsl): the `coat` layer blend. The
    base's fields are kept; the layer's roughness, base colour, IOR and normal become the
    coat's roughness, tint, IOR and normal by the new coat's share, and the weights combine
    as coverages, 1 - (1 - a)(1 - w).
    glTF KHR_materials_clearcoat; OpenPBR 2024, "OpenPBR Surface Specification", coat_*"""
    out = {name: np.array(base[name], copy=True) for name in ATTRIBUTE_NAMES}
    w = np.asarray(w, dtype=base["coat"].dtype)
    s = coat_layer_share(base["coat"], w)
    out["coat"] = 1.0 - (1.0 - base["coat"]) * (1.0 - w)
    out["coatRoughness"] = _mix(base["coatRoughness"], layer["roughness"], s)
    out["coatColor"] = _mix(base["coatColor"], layer["baseColor"], _col(s))
    out["coatIor"] = _mix(base["coatIor"], layer["ior"], s)
    out["coatNormal"] = _safe_normalize(_mix(base["coatNormal"], layer["normal"], _col(s)), _Z)
    return out


def film_material_attributes(base: Attributes, layer: Attributes, w: np.ndarray) -> Attributes:
    """filmMaterialAttributes (shaders/nodes/layer_blend.glsl): the `film` layer blend. The
    layer's thin film (thickness, IOR) lerped over the base's by w; the base's other fields
    kept. glTF KHR_materials_iridescence (docs/shading.md, Thin film)"""
    out = {name: np.array(base[name], copy=True) for name in ATTRIBUTE_NAMES}
    w = np.asarray(w, dtype=base["thinFilmThickness"].dtype)
    for name in ("thinFilmThickness", "thinFilmIor"):
        out[name] = _mix(base[name], layer[name], w)
    return out


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
# The Material Output's setting: transmission through a thin wall (MATERIAL_THIN_WALLED).
THIN_WALLED = "thin_walled"


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


def _make_attributes(ctx, *fields):
    return (dict(zip(ATTRIBUTE_NAMES, fields, strict=True)),)


register(NodeDef(
    "make_attributes", "Make Material Attributes", "Material",
    "Builds a MaterialAttributes from its fields (the talk's seven, then the lobes beyond "
    "it, each off at its default).",
    inputs=ATTRIBUTE_FIELDS, outputs=(_o("attributes", MA),),
    settings=(EXPANDED_GROUPS_SETTING,),
    glsl="node_make_attributes", role=Role.MAKE_ATTRIBUTES, thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("attributes"),
    numpy=_make_attributes,
))


def _break_attributes(ctx, attributes: Attributes):
    return tuple(attributes[name] for name in ATTRIBUTE_NAMES)


register(NodeDef(
    "break_attributes", "Break Material Attributes", "Material",
    "Splits a MaterialAttributes into its fields.",
    inputs=(_i("attributes", MA, None, required=True),),
    outputs=tuple(_o(f.name, f.type, group=f.group) for f in ATTRIBUTE_FIELDS),
    settings=(EXPANDED_GROUPS_SETTING,),
    glsl="node_break_attributes", mtlx=MxRecipe("attributes"),
    numpy=_break_attributes,
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


def _layer_blend(ctx, base, layer, mask):
    return (blend_material_attributes(base, layer, mask),)


register(NodeDef(
    "layer_blend", "Layer Blend (mask)", "Layers",
    "Blends layer over base by mask, field by field; normals by normalized lerp (nlerp).",
    inputs=(_i("base", MA, None, required=True), _i("layer", MA, None, required=True),
            _i("mask", "float", 1.0, "layer coverage", UNIT)),
    outputs=(_o("result", MA),),
    glsl="node_layer_blend", role=Role.MASK_BLEND, thumbnail=Thumbnail.ALWAYS,
    mtlx=MxRecipe("blend"),
    numpy=_layer_blend,  # a mix per field, the normal normalised
))


def _height_blend(ctx, base, layer, base_height, layer_height, contrast):
    c = np.maximum(contrast, 1e-5)
    t = _smoothstep(-c, c, layer_height - base_height)
    return (blend_material_attributes(base, layer, t),)


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
    mtlx=MxRecipe("blend"),
    numpy=_height_blend,  # smoothstep(-c, c, dh) as the blend factor
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
    settings=(SettingDef(THIN_WALLED, "bool", False,
                         "thin-walled transmission: a wall of `thickness` with parallel "
                         "faces (a bubble, a window) instead of a solid part"),),
    role=Role.MATERIAL_OUTPUT, lowered=True, mtlx=LOWERED, thumbnail=Thumbnail.NEVER,
))
