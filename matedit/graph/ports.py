"""The ports of a node: static ones from its definition, dynamic ones from its settings,
from the material function it calls, or from its layer stack.

Material functions are found through a `FunctionResolver` the caller provides
(the format layer resolves paths relative to the file that uses them).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from matedit.graph import nodes
from matedit.graph.model import MaterialDocument, Node
from matedit.graph.names import identifier_problem
from matedit.graph.nodes import GENERIC, MA, Port, PortsRule, Role, role_of
from matedit.graph.types import PortType, parse_type


@dataclass(frozen=True)
class NodePorts:
    inputs: tuple[Port, ...]
    outputs: tuple[Port, ...]
    _by_input: dict[str, Port] = field(init=False, repr=False, compare=False)
    _by_output: dict[str, Port] = field(init=False, repr=False, compare=False)
    # whether any input has hard bounds (Port.limits): values of the others are not checked
    limited: bool = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # first match wins, as a linear scan would (duplicates are reported elsewhere)
        object.__setattr__(self, "_by_input", {p.name: p for p in reversed(self.inputs)})
        object.__setattr__(self, "_by_output", {p.name: p for p in reversed(self.outputs)})
        object.__setattr__(self, "limited", any(p.limits is not None for p in self.inputs))

    def input(self, name: str) -> Port | None:
        return self._by_input.get(name)

    def output(self, name: str) -> Port | None:
        return self._by_output.get(name)


class PortError(ValueError):
    """A node whose settings do not define valid ports (names the setting)."""

    def __init__(self, node_id: str, field: str, message: str) -> None:
        super().__init__(message)
        self.node_id = node_id
        self.field = field


class FunctionResolver(Protocol):
    def resolve(self, ref: str, owner: MaterialDocument | None) -> MaterialDocument:
        """The function document `ref` names, relative to `owner`; raise LookupError if missing."""
        ...


# The catalogue's colour Blend nodes (blend_<mode>: base, blend, opacity) as layer blend
# modes: the layer's base colour is composited over the stack's by that node, the other
# fields blend by the mask (matedit.compiler.lower). In catalogue order.
COLOR_LAYER_BLENDS = tuple(
    kind[len("blend_"):] for kind, d in nodes.REGISTRY.items()
    if kind.startswith("blend_") and [i.name for i in d.inputs] == ["base", "blend", "opacity"])
# alpha: a lerp by mask x opacity; height: by the heights; coat: laid over as a clear coat;
# film: the layer's thin film laid over the stack.
LAYER_BLENDS = ("alpha", "height", "coat", "film", *COLOR_LAYER_BLENDS)
_VALID_CHANNELS = "xyzw"
_CHANNEL_ALIASES = str.maketrans("rgba", "xyzw")


def normalize_channels(channels: object) -> str:
    if not isinstance(channels, str) or not 1 <= len(channels) <= 4:
        raise ValueError(f"channels must be 1 to 4 letters of xyzw or rgba, got {channels!r}")
    norm = channels.lower().translate(_CHANNEL_ALIASES)
    if any(c not in _VALID_CHANNELS for c in norm):
        raise ValueError(f"channels must be letters of xyzw or rgba, got {channels!r}")
    return norm


def function_interface(doc: MaterialDocument) -> NodePorts:
    """A function's inputs and outputs, from its function_input/function_output nodes."""
    ins, outs = [], []
    for node in doc.graph.nodes.values():
        role = role_of(node.kind)
        if role not in (Role.FUNCTION_INPUT, Role.FUNCTION_OUTPUT):
            continue
        s = {**nodes.REGISTRY[node.kind].setting_defaults(), **node.settings}
        try:
            t = parse_type(str(s["type"])).value
        except ValueError as exc:
            raise PortError(node.id, "type", str(exc)) from None
        order = s.get("order", 0)
        order = order if isinstance(order, (int, float)) else 0
        key = (order, str(s["name"]), node.id)
        why = identifier_problem(s["name"])
        if why:
            where = f" in {Path(doc.path).name}" if doc.path else ""
            side = "input" if role == Role.FUNCTION_INPUT else "output"
            raise PortError(node.id, "name", f"function {side} name "
                            f"{s['name']!r}{where} {why}")
        if role == Role.FUNCTION_INPUT:
            ins.append((key, Port(str(s["name"]), t, s.get("default"),
                                  doc=f"function input {s['name']}",
                                  required=t in (MA, "texture2d")
                                  and s.get("default") is None)))
        else:
            outs.append((key, Port(str(s["name"]), t)))
    return NodePorts(tuple(p for _, p in sorted(ins, key=lambda kp: kp[0])),
                     tuple(p for _, p in sorted(outs, key=lambda kp: kp[0])))


def layer_entries(node: Node) -> list[dict]:
    layers = node.settings.get("layers", [])
    return layers if isinstance(layers, list) else []


STATIC_RULES = (PortsRule.CHANNELS, PortsRule.COMPONENTS, PortsRule.CONCATENATION,
                 PortsRule.PASSTHROUGH)
_STATIC: dict[str, NodePorts] = {}


def static_ports(kind: str) -> NodePorts:
    """Ports that depend on nothing but the kind, built once per kind (NodePorts is frozen)."""
    hit = _STATIC.get(kind)
    if hit is None:
        d = nodes.REGISTRY[kind]
        hit = _STATIC[kind] = NodePorts(d.inputs, d.outputs)
    return hit


def node_ports(
    node: Node, resolver: FunctionResolver | None = None, owner: MaterialDocument | None = None
) -> NodePorts:
    """The ports of `node`; raises PortError/LookupError when they cannot be determined."""
    d = nodes.REGISTRY.get(node.kind)
    if d is None:
        raise PortError(node.id, "kind", f"unknown node kind {node.kind!r}")
    rule = d.ports_rule
    if rule is None or rule in STATIC_RULES:
        return static_ports(node.kind)
    ins = d.inputs
    outs = d.outputs
    s = {**d.setting_defaults(), **node.settings}
    if rule == PortsRule.TYPE_SETTING:
        try:
            t = parse_type(str(s["type"]))
        except ValueError as exc:
            raise PortError(node.id, "type", str(exc)) from None
        if not t.is_numeric:
            raise PortError(node.id, "type", "a constant must be float, vec2, vec3 or vec4")
        return NodePorts((), (Port("value", t.value),))
    if rule == PortsRule.FUNCTION_INPUT:
        try:
            type_name = parse_type(str(s["type"])).value
        except ValueError as exc:
            raise PortError(node.id, "type", str(exc)) from None
        return NodePorts((), (Port("value", type_name),))
    if rule == PortsRule.FUNCTION_OUTPUT:
        try:
            type_name = parse_type(str(s["type"])).value
        except ValueError as exc:
            raise PortError(node.id, "type", str(exc)) from None
        return NodePorts((Port("value", type_name, None, required=True),), ())
    if rule == PortsRule.ATTRIBUTE_FIELDS:
        fields = s.get("fields")
        if not isinstance(fields, list) or not all(isinstance(f, str) for f in fields):
            raise PortError(node.id, "fields", "fields must be a list of attribute names")
        extra = []
        for f in fields:
            fd = next((a for a in nodes.ATTRIBUTE_FIELDS if a.name == f), None)
            if fd is None:
                raise PortError(node.id, "fields", f"unknown attribute {f!r} (expected one of "
                                f"{', '.join(nodes.ATTRIBUTE_NAMES)})")
            extra.append(fd)
        return NodePorts(ins + tuple(extra), outs)
    if rule == PortsRule.FUNCTION_SIGNATURE:
        ref = s.get("function")
        if ref is None or ref == "":
            # A call just placed, before its function is chosen: no ports yet, so nothing
            # can be wired to it and the material compiles without it (validate warns).
            return NodePorts((), ())
        if not isinstance(ref, str):
            raise PortError(node.id, "function", "the function must be a file name")
        if resolver is None:
            raise LookupError(f"cannot resolve function {ref!r} without a resolver")
        fn = resolver.resolve(ref, owner)
        return function_interface(fn)
    if rule == PortsRule.LAYERS:
        return NodePorts(tuple(_layer_stack_inputs(node, resolver, owner)), outs)
    raise PortError(node.id, "kind", f"node kind {node.kind!r} has an unknown ports rule")


def _layer_stack_inputs(node, resolver, owner) -> list[Port]:
    ports: list[Port] = []
    seen: set[str] = set()
    for index, layer in enumerate(layer_entries(node)):
        if not isinstance(layer, dict):
            raise PortError(node.id, f"layers[{index}]", "a layer must be an object")
        lid = layer.get("id")
        why = identifier_problem(lid)
        if why or not isinstance(lid, str) or lid in seen:
            raise PortError(node.id, f"layers[{index}].id",
                            f"layer id {lid!r} {why}" if why else f"duplicate layer id {lid!r}")
        seen.add(lid)
        ref = layer.get("function")
        if not isinstance(ref, str) or not ref:
            raise PortError(node.id, f"layers[{index}].function", "no layer function chosen")
        if resolver is None:
            raise LookupError(f"cannot resolve layer {ref!r} without a resolver")
        iface = function_interface(resolver.resolve(ref, owner))
        if not any(o.type == MA for o in iface.outputs):
            raise PortError(node.id, f"layers[{index}].function",
                            f"{ref} is not a material layer: it has no MaterialAttributes output")
        for p in iface.inputs:
            ports.append(Port(f"{lid}_{p.name}", p.type, p.default, range=p.range,
                              doc=f"{layer.get('name', lid)}: {p.doc or p.name}",
                              required=p.required))
        if index == 0:
            continue
        blend = layer.get("blend", "alpha")
        label = layer.get("name", lid)
        ports.append(Port(f"{lid}_opacity", "float", 1.0, range=(0.0, 1.0),
                          doc=f"{label}: overall strength"))
        if blend == "alpha" or blend in COLOR_LAYER_BLENDS:
            ports.append(Port(f"{lid}_mask", "float", 1.0, range=(0.0, 1.0),
                              doc=f"{label}: where the layer covers the ones below"))
        elif blend == "coat":
            ports.append(Port(f"{lid}_mask", "float", 1.0, range=(0.0, 1.0),
                              doc=f"{label}: where the coat lies (its weight)"))
        elif blend == "film":
            ports.append(Port(f"{lid}_mask", "float", 1.0, range=(0.0, 1.0),
                              doc=f"{label}: where the thin film lies"))
        elif blend == "height":
            ports.append(Port(f"{lid}_mask", "float", 0.5, range=(0.0, 1.0),
                              doc=f"{label}: layer height"))
            ports.append(Port(f"{lid}_base_height", "float", 0.5, range=(0.0, 1.0),
                              doc=f"{label}: height of the layers below"))
            ports.append(Port(f"{lid}_contrast", "float", 0.1, range=(0.001, 1.0),
                              doc=f"{label}: transition width"))
        elif isinstance(blend, str) and blend.endswith(".json"):
            if resolver is None:
                raise LookupError(f"cannot resolve blend {blend!r} without a resolver")
            biface = function_interface(resolver.resolve(blend, owner))
            mas = [p for p in biface.inputs if p.type == MA]
            if len(mas) < 2 or not any(o.type == MA for o in biface.outputs):
                raise PortError(node.id, f"layers[{index}].blend",
                                f"{blend} is not a layer blend: it needs two MaterialAttributes "
                                "inputs and a MaterialAttributes output")
            for p in biface.inputs:
                if p.type != MA:
                    ports.append(Port(f"{lid}_{p.name}", p.type, p.default, range=p.range,
                                      doc=f"{label}: {p.name}"))
        else:
            raise PortError(node.id, f"layers[{index}].blend",
                            f"unknown blend {blend!r} ({', '.join(LAYER_BLENDS)}, "
                            "or a blend function file)")
    names: set[str] = set()
    for p in ports:
        if p.name in names:
            raise PortError(node.id, "layers", f"two layer inputs would both be named {p.name!r}; "
                            "rename a layer or the function input")
        names.add(p.name)
    return ports


# --- generic type resolution ----------------------------------------------------------------

def _default_type(value: Any) -> PortType:
    if isinstance(value, (list, tuple)) and 2 <= len(value) <= 4:
        return {2: PortType.VEC2, 3: PortType.VEC3, 4: PortType.VEC4}[len(value)]
    return PortType.FLOAT


_CONCRETE: dict[str, tuple | None] = {}


def _concrete_types(kind: str):
    """Types of a kind with no generic ports, computed once (callers only read them)."""
    if kind not in _CONCRETE:
        p = static_ports(kind)
        specs = p.inputs + p.outputs
        _CONCRETE[kind] = None if any(s.type == GENERIC for s in specs) else (
            {s.name: PortType(s.type) for s in p.inputs},
            {s.name: PortType(s.type) for s in p.outputs})
    return _CONCRETE[kind]


# A kind's static ports, read once for the generic rule: those ports, the (name, default) of
# its generic inputs, and (name, fixed type or None where generic) of its inputs and outputs.
_GENERIC_PLANS: dict[str, tuple] = {}


def _generic_plan(kind: str) -> tuple:
    hit = _GENERIC_PLANS.get(kind)
    if hit is None:
        p = static_ports(kind)
        hit = _GENERIC_PLANS[kind] = (
            p,
            tuple((s.name, s.default) for s in p.inputs if s.type == GENERIC),
            tuple((s.name, None if s.type == GENERIC else PortType(s.type)) for s in p.inputs),
            tuple((s.name, None if s.type == GENERIC else PortType(s.type)) for s in p.outputs))
    return hit


def _generic_types(node: Node, plan: tuple, connected: dict[str, PortType]
                   ) -> tuple[dict[str, PortType], dict[str, PortType]]:
    """resolve_types of a kind with no ports rule: its generic inputs' widest type."""
    _, generic_inputs, ins, outs = plan
    widest: PortType | None = None
    values = node.values
    for name, default in generic_inputs:
        t = connected.get(name)
        if t is None:
            t = _default_type(values.get(name, default))
        if t == PortType.FLOAT:
            continue
        if not t.is_numeric:
            raise ValueError(f"{name} takes a float or a vector, got {t}")
        if widest is None:
            widest = t
        elif widest != t:
            raise ValueError(
                f"mixed vector sizes: {widest} and {t} ({name}); "
                "use a Component Mask or Append node")
    generic = widest or PortType.FLOAT
    # the same two dicts for every node of the kind that resolves to `generic` (callers only
    # read them, as they do _concrete_types')
    key = (node.kind, generic)
    hit = _GENERIC_TYPES.get(key)
    if hit is None:
        hit = _GENERIC_TYPES[key] = (
            {name: generic if fixed is None else fixed for name, fixed in ins},
            {name: generic if fixed is None else fixed for name, fixed in outs})
    return hit


_GENERIC_TYPES: dict[tuple[str, PortType], tuple[dict, dict]] = {}

# kind -> (its fixed types or None, its generic plan or None): resolve_types' first steps,
# once a kind, for a caller that resolves many nodes (matedit.graph.validate.analyse)
TYPE_PLANS: dict[str, tuple] = {}


def type_plan(kind: str) -> tuple:
    """(fixed, plan): `fixed` the (inputs, outputs) types of a kind whose types follow from
    the kind alone; else `plan` its _generic_plan when it has no ports rule (then, for a node
    with the kind's own ports, `generic_types(node, plan, connected)` is resolve_types'
    answer); (None, None) for a kind that has a ports rule."""
    hit = TYPE_PLANS.get(kind)
    if hit is None:
        if nodes.REGISTRY[kind].ports_rule is not None:
            hit = (None, None)
        else:
            fixed = _concrete_types(kind)
            hit = (fixed, None if fixed is not None else _generic_plan(kind))
        TYPE_PLANS[kind] = hit
    return hit


generic_types = _generic_types


def resolve_types(
    node: Node, ports: NodePorts, connected: dict[str, PortType]
) -> tuple[dict[str, PortType], dict[str, PortType]]:
    """Concrete input and output types for `node` given the types wired into it.

    Raises ValueError with a reason an artist can act on (e.g. vec2 into a vec3 add).
    """
    d = nodes.REGISTRY[node.kind]
    rule = d.ports_rule
    if rule is None:
        fixed = _concrete_types(node.kind)
        if fixed is not None:
            return fixed
        plan = _generic_plan(node.kind)
        if plan[0] is ports:
            return _generic_types(node, plan, connected)

    def concrete(spec: Port) -> PortType | None:
        return None if spec.type == GENERIC else PortType(spec.type)

    in_types: dict[str, PortType] = {}
    if rule == PortsRule.CONCATENATION:
        sizes = {}
        for p in ports.inputs:
            t = connected.get(p.name) or _default_type(node.values.get(p.name, p.default))
            if not t.is_numeric:
                raise ValueError(f"append takes floats or vectors, got {t} on {p.name}")
            in_types[p.name] = t
            sizes[p.name] = t.components
        total = sum(sizes.values())
        if total > 4:
            raise ValueError(f"append makes at most 4 components, got {total}")
        return in_types, {"result": {2: PortType.VEC2, 3: PortType.VEC3,
                                     4: PortType.VEC4}[total]}
    if rule == PortsRule.PASSTHROUGH:
        t = connected.get("value") or _default_type(node.values.get("value", 0.0))
        return {"value": t}, {"value": t}

    generic_inputs = [p for p in ports.inputs if p.type == GENERIC]
    widest: PortType | None = None
    for p in generic_inputs:
        found = connected.get(p.name)
        t = found if found is not None else _default_type(node.values.get(p.name, p.default))
        if not t.is_numeric:
            raise ValueError(f"{p.name} takes a float or a vector, got {t}")
        if t == PortType.FLOAT:
            continue
        if widest is None:
            widest = t
        elif widest != t:
            raise ValueError(
                f"mixed vector sizes: {widest} and {t} ({p.name}); "
                "use a Component Mask or Append node")
    generic = widest or PortType.FLOAT
    for p in ports.inputs:
        in_types[p.name] = generic if p.type == GENERIC else PortType(p.type)

    out_types: dict[str, PortType] = {}
    if rule == PortsRule.CHANNELS:
        channels = normalize_channels(node.settings.get("channels", "xy"))
        n = generic.components
        if any(_VALID_CHANNELS.index(c) >= n for c in channels):
            raise ValueError(f"channels {channels!r} need more than the {n} of a {generic}")
        out_types["result"] = {1: PortType.FLOAT, 2: PortType.VEC2, 3: PortType.VEC3,
                               4: PortType.VEC4}[len(channels)]
        return in_types, out_types
    if rule == PortsRule.COMPONENTS:
        t = connected.get("value") or PortType.VEC4
        if not t.is_numeric:
            raise ValueError(f"split takes a float or a vector, got {t}")
        in_types["value"] = t
    for p in ports.outputs:
        out_types[p.name] = generic if p.type == GENERIC else (concrete(p) or generic)
    return in_types, out_types
