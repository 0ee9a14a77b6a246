"""The node catalogue, read by the rest of the package: a facade over `matedit.nodes`.

Each kind is written once, in its category module of `matedit.nodes` (definition, GLSL,
numpy twin, MaterialX mapping); `matedit.nodes.kind` holds the data of a kind and the
registry. Code asks the definition (`definition(kind)`, `role_of(kind)`, `kind_for(role)`),
never compares kind names, so adding a node kind touches no compiler, editor or exporter
code.

Types are PortType names or `T`, a generic float-or-vector type resolved per node from its
connected inputs (a float input splats). A few kinds have ports that depend on their
settings or on a material function (`ports_rule`); those rules live in
`matedit.graph.ports`.
"""

from __future__ import annotations

import matedit.nodes  # noqa: F401  (registers every kind)
from matedit.nodes.colour import LUMA_REC709, RAMP_STOPS
from matedit.nodes.kind import (
    BAKE,
    GENERIC,
    LOWERED,
    MESH_UV,
    REGISTRY,
    InputDef,
    Mtlx,
    MxBuilder,
    MxNode,
    MxRecipe,
    NodeDef,
    OutputDef,
    Port,
    PortsRule,
    Ref,
    Role,
    SettingDef,
    Thumbnail,
    can_bypass,
    categories,
    definition,
    get,
    is_impure,
    is_parameter,
    is_value_parameter,
    kind_for,
    kinds_where,
    limit_problem,
    register,
    role_of,
)
from matedit.nodes.material import (
    ATTRIBUTE_FIELDS,
    ATTRIBUTE_NAMES,
    BREAK_ATTRIBUTES,
    EXPANDED_GROUPS,
    EXPANDED_GROUPS_SETTING,
    MA,
    THIN_WALLED,
    attribute_group,
    lobe_input,
    lobe_value_is_default,
    port_group,
)
from matedit.nodes.parameters import PARAMETER_KINDS

__all__ = [
    "ATTRIBUTE_FIELDS", "ATTRIBUTE_NAMES", "BAKE", "BREAK_ATTRIBUTES", "EXPANDED_GROUPS",
    "EXPANDED_GROUPS_SETTING", "GENERIC", "LOWERED", "MA", "MESH_UV", "PARAMETER_KINDS",
    "THIN_WALLED",
    "LUMA_REC709", "RAMP_STOPS", "REGISTRY", "InputDef", "Mtlx", "MxBuilder", "MxNode", "MxRecipe",
    "NodeDef", "OutputDef", "Port", "PortsRule", "Ref", "Role", "SettingDef", "Thumbnail",
    "attribute_group", "can_bypass", "categories", "definition", "get", "is_impure", "is_parameter",
    "is_value_parameter", "kind_for", "kinds_where", "limit_problem", "lobe_input",
    "lobe_value_is_default",
    "port_group", "register", "role_of",
]
