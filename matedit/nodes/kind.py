"""The data of a node kind (`NodeDef` and its parts), the registry of kinds, and the
helpers that keep the category modules' tables short.

The category modules of `matedit.nodes` build the catalogue from these and register it;
code reads the catalogue through `matedit.graph.nodes`, which exports every name here.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum, auto
from typing import Any, Protocol

GENERIC = "T"
# Default marker: an unconnected input with this default reads the mesh's first UV set.
MESH_UV = "mesh_uv"


@dataclass(frozen=True)
class Port:
    """A port of a node: an input (with its default and range) or an output. The one record
    for ports, from a kind's definition or from the dynamic rules of `matedit.graph.ports`."""

    name: str
    type: str  # a PortType value or "T"
    default: Any = None
    doc: str = ""
    range: tuple[float, float] | None = None
    required: bool = False
    # Where an editor shows the port: ports sharing a group fold together (the material
    # attributes: Base, Specular, Coat, Sheen, Anisotropy). Empty: ungrouped.
    group: str = ""
    # A lobe input of the material attributes: unconnected at its default it turns its lobe
    # off, and the lobe's code is compiled out. Moving it off or back to its default is
    # therefore a structural edit (one recompile), any other value edit a uniform.
    lobe: bool = False
    # Hard bounds (None: unbounded on that side): a value beyond them means nothing to the
    # shader, which clamps it; the editor clamps it visibly and validation warns. `range` is
    # only the slider's span and may be typed past.
    limits: tuple[float | None, float | None] | None = None


def limit_problem(port: Port, value: Any) -> tuple[str, Any] | None:
    """(why, the value clamped into `port.limits`) where a number, or any component of a
    vector, is beyond them; None where it is within (or the port has none)."""
    if port.limits is None or isinstance(value, (str, bool)) or value is None:
        return None
    lo, hi = port.limits
    many = isinstance(value, (list, tuple))
    comps = list(value) if many else [value]
    if not all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in comps):
        return None
    fixed = [float(c) for c in comps]
    if lo is not None:
        fixed = [max(c, lo) for c in fixed]
    if hi is not None:
        fixed = [min(c, hi) for c in fixed]
    if fixed == [float(c) for c in comps]:
        return None
    bound = ("at least " + _num(lo) if lo is not None else "") + \
        (" and " if lo is not None and hi is not None else "") + \
        ("at most " + _num(hi) if hi is not None else "")
    shown = "(" + ", ".join(_num(c) for c in comps) + ")" if many else _num(comps[0])
    return f"{port.name} {shown} is out of bounds: it must be {bound}", \
        (fixed if many else fixed[0])


def _num(x: float) -> str:
    return f"{float(x):g}"


# The names the catalogue uses for the two sides (one type).
InputDef = Port
OutputDef = Port


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


class Role(Enum):
    """The structural kinds whose meaning code must know (most kinds have no role)."""

    CONSTANT = auto()
    SCALAR_PARAMETER = auto()
    VECTOR_PARAMETER = auto()
    COLOR_PARAMETER = auto()
    TEXTURE_PARAMETER = auto()
    STATIC_SWITCH = auto()
    COMPONENT_MASK = auto()
    APPEND = auto()
    REROUTE = auto()
    TEXTURE_SAMPLE = auto()
    ADDRESSED_TEXTURE_SAMPLE = auto()  # MaterialX image's address modes and filter
    HEX_TILED_TEXTURE = auto()  # MaterialX hextiledimage
    COLOR_RAMP = auto()
    MAKE_ATTRIBUTES = auto()
    SET_ATTRIBUTES = auto()
    MASK_BLEND = auto()  # blends two MaterialAttributes by a mask
    HEIGHT_BLEND = auto()  # ... by height
    FUNCTION_INPUT = auto()
    FUNCTION_OUTPUT = auto()
    FUNCTION_CALL = auto()
    LAYER_STACK = auto()
    MATERIAL_OUTPUT = auto()


class Thumbnail(Enum):
    """When the canvas shows a node's live preview thumbnail."""

    NEVER = auto()  # the same everywhere, or not an image
    SELECTED = auto()  # only while selected (most kinds: they would crowd the graph)
    ALWAYS = auto()  # patterns, textures, materials


class PortsRule(str, Enum):
    """Ports that depend on a node's settings, a material function or its connections
    (the rules live in `matedit.graph.ports`)."""

    TYPE_SETTING = "type setting"  # one output of the type the settings name
    FUNCTION_INPUT = "function input"
    FUNCTION_OUTPUT = "function output"
    FUNCTION_SIGNATURE = "function signature"  # the called function's inputs and outputs
    LAYERS = "layers"  # one input per layer mask and layer input
    ATTRIBUTE_FIELDS = "attribute fields"  # one input per overridden field
    CHANNELS = "channels"  # output width from the chosen channels
    COMPONENTS = "components"  # a float per component of the input
    CONCATENATION = "concatenation"  # output width: the sum of the input widths
    PASSTHROUGH = "passthrough"  # the output has the input's type

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class MxNode:
    """A MaterialX 1.39 stdlib node of `category`: `ports` maps our inputs to its inputs in
    order, `fixed` adds constant inputs, `output` names its output. The exporter converts
    every input to the op's result type first, so the same-type node definition is chosen."""

    category: str
    ports: tuple[tuple[str, str], ...]  # (our input, MaterialX input)
    fixed: tuple[tuple[str, float], ...] = field(default_factory=tuple)
    output: str = "out"


class MxBuilder(Protocol):
    """What a MaterialX recipe builds through (`MxRecipe.build`): the exporter passes one in,
    so a recipe names MaterialX stdlib nodes without importing MaterialX. A reference (`Ref`)
    is opaque to the recipe: an operand of the op, a node built here, or a constant; each
    carries its MaterialX type (float, vector2, vector3, vector4)."""

    @property
    def result_type(self) -> str:
        """The MaterialX type of the op's first output."""
        ...

    @property
    def data(self) -> Mapping[str, Any]:
        """The op's own data (a component mask's channels)."""
        ...

    @property
    def operands(self) -> int:
        """How many operands the op has."""
        ...

    def arg(self, port: int | str) -> Ref:
        """The op's operand: by position, or by the kind's input name."""
        ...

    def arg_type(self, port: int | str) -> str:
        """The MaterialX type of that operand."""
        ...

    def value(self, v: float | tuple[float, ...], mxtype: str | None = None) -> Ref:
        """A constant of `mxtype`; None: a number splatted to the op's result type."""
        ...

    def constant(self, ref: Ref) -> Any:
        """The value of a constant reference; None for any other."""
        ...

    def node(self, category: str, mxtype: str | None, suffix: str, *inputs: tuple[str, Ref],
             space: str | None = None) -> Ref:
        """A stdlib node of `category` and output type `mxtype` (None: the op's result type)
        on (MaterialX input, reference) pairs, named after the op plus `suffix` ("" for the
        op's own result); `space` sets a geometric node's space."""
        ...

    def extract(self, ref: Ref, index: int) -> Ref:
        """An `extract` node of component `index` of a vector reference."""
        ...

    def component(self, source: Ref | int, index: int) -> Ref:
        """Component `index` of a reference or of an operand (by position, referenced only
        if needed): a float is its own, a missing one reads 0, a constant's is a constant,
        a vector's is extracted."""
        ...

    def combine(self, parts: Sequence[Ref], mxtype: str) -> Ref:
        """A vector of `mxtype` from float references (one part: itself; constants fold)."""
        ...

    def uv(self) -> Ref:
        """The texture coordinates of the mesh's first UV set."""
        ...


# A MaterialX reference as a recipe holds it (see MxBuilder).
Ref = tuple[Any, str]
# A recipe's result: one function per output of the op (see RecipeFn).
Makers = list[Callable[[], Ref]]
# A recipe: fn(builder) -> one function per output of the op, each building that output on
# demand (so an output nothing reads builds nothing) and returning its reference; or None
# where the recipe cannot express the op's operand types (the exporter then bakes it).
RecipeFn = Callable[[MxBuilder], "Sequence[Callable[[], Ref]] | None"]


@dataclass(frozen=True)
class MxRecipe:
    """A few stdlib nodes that compute the kind: `build` writes them through the builder the
    exporter passes in. A recipe without `build` is one of the exporter's own, for the kinds
    whose values are not one reference (material attributes and their blends) or that read
    textures. `matedit.interop.mtlx_import` reads recipes back by `name`."""

    name: str
    build: RecipeFn | None = field(default=None, compare=False, repr=False)


# A kind's MaterialX mapping when no stdlib node or recipe expresses it: the exporter bakes
# its outputs over UV space into images read by `image` nodes.
BAKE = "bake"
# ... when the compiler lowers the kind away before export (parameters become interface
# inputs, constants values, functions inlined, layer stacks blends).
LOWERED = "lowered"
Mtlx = MxNode | MxRecipe | str


@dataclass(frozen=True)
class NodeDef:
    kind: str
    title: str
    category: str
    description: str
    inputs: tuple[InputDef, ...] = ()
    outputs: tuple[OutputDef, ...] = ()
    settings: tuple[SettingDef, ...] = ()
    # Its GLSL, one of: the function's name in shaders/nodes/<kind>.glsl (called with `out`
    # parameters), or an inline template, e.g. "({a} + {b})" (the back-end reads both here).
    glsl: str | None = None
    inline: str | None = None
    ports_rule: PortsRule | None = None  # dynamic ports, see matedit.graph.ports
    # Extra value fields that are not ports (a parameter's value): edits are value edits.
    values: tuple[InputDef, ...] = ()
    # MaterialX: an MxNode, an MxRecipe, BAKE (not expressible node for node) or LOWERED.
    mtlx: Mtlx = BAKE
    # Where `mtlx` is a recipe: the one stdlib node the importer also reads back as this
    # kind (MaterialX's dotproduct as our dot, say).
    mtlx_reads: MxNode | None = None
    role: Role | None = None
    # The compiler lowers the kind from the graph itself: no GLSL function, no numpy twin.
    lowered: bool = False
    # Its value depends on more than its inputs (geometry, time, textures, uniforms), so
    # it is never constant-folded.
    impure: bool = False
    # It reads the surface's position, normal, view or time (not only its inputs and UVs).
    geometry: bool = False
    thumbnail: Thumbnail = Thumbnail.SELECTED
    # A named parameter an instance may override: its instance type ("scalar", "vector",
    # "color", "texture", "switch"); None: not a parameter.
    parameter: str | None = None
    # Its numpy twin: fn(surface, *inputs) -> its outputs, a tuple in declaration order (one
    # output may come bare); every kind the compiler does not lower has one.
    numpy: Callable[..., Any] | None = field(default=None, repr=False)

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
    if defn.lowered:
        if defn.glsl is not None or defn.inline is not None or defn.numpy is not None:
            raise ValueError(f"node kind {defn.kind!r} is lowered: no glsl=, inline= or numpy=")
    elif (defn.glsl is None) == (defn.inline is None):
        raise ValueError(f"node kind {defn.kind!r} needs exactly one of glsl= or inline=")
    elif defn.numpy is None:
        raise ValueError(f"node kind {defn.kind!r} needs its numpy twin (numpy=)")
    if defn.role is not None and any(d.role == defn.role for d in REGISTRY.values()):
        raise ValueError(f"node kind {defn.kind!r}: role {defn.role.name} taken")
    REGISTRY[defn.kind] = defn
    return defn


def get(kind: str) -> NodeDef | None:
    return REGISTRY.get(kind)


def definition(kind: str) -> NodeDef:
    """The definition of a registered kind (KeyError names an unknown one)."""
    try:
        return REGISTRY[kind]
    except KeyError:
        raise KeyError(f"unknown node kind {kind!r}") from None


def role_of(kind: str) -> Role | None:
    """The role of `kind`; None for kinds without one and for names that are no kind (the
    compiler's own op names, say)."""
    d = REGISTRY.get(kind)
    return d.role if d is not None else None


# Kinds with nothing to pass through when bypassed: sources (parameters, constants, the
# function's inputs) and the ends of a graph (outputs).
_NOT_BYPASSED = frozenset({Role.CONSTANT, Role.SCALAR_PARAMETER, Role.VECTOR_PARAMETER,
                           Role.COLOR_PARAMETER, Role.TEXTURE_PARAMETER, Role.FUNCTION_INPUT,
                           Role.FUNCTION_OUTPUT, Role.MATERIAL_OUTPUT, Role.REROUTE})


def can_bypass(kind: str) -> bool:
    """Whether a node of `kind` can be bypassed (muted): it has outputs and inputs, or
    inputs its settings make (a layer stack's layers, a function call's signature)."""
    d = REGISTRY.get(kind)
    if d is None or d.role in _NOT_BYPASSED:
        return False
    return bool(d.outputs or d.ports_rule) and bool(d.inputs or d.ports_rule)


def kind_for(role: Role) -> str:
    """The kind that plays `role`, to create a node of it (a new material's output, say)."""
    for d in REGISTRY.values():
        if d.role == role:
            return d.kind
    raise LookupError(f"no node kind has role {role.name}")


def is_parameter(kind: str) -> bool:
    """A named parameter an instance may override (static switches included)."""
    d = REGISTRY.get(kind)
    return d is not None and d.parameter is not None


def is_value_parameter(kind: str) -> bool:
    """A parameter that compiles to a uniform or a texture (not a static switch)."""
    d = REGISTRY.get(kind)
    return d is not None and d.parameter is not None and d.role != Role.STATIC_SWITCH


def is_impure(kind: str) -> bool:
    """Never constant-folded; names that are no kind (the compiler's ops) are pure."""
    d = REGISTRY.get(kind)
    return d is not None and d.impure


def kinds_where(test) -> frozenset[str]:
    """The kinds whose definition passes `test`."""
    return frozenset(k for k, d in REGISTRY.items() if test(d))


def categories() -> dict[str, list[NodeDef]]:
    """Node kinds by palette category, sorted by title."""
    out: dict[str, list[NodeDef]] = {}
    for d in sorted(REGISTRY.values(), key=lambda d: (d.category, d.title)):
        out.setdefault(d.category, []).append(d)
    return out


# --- helpers to keep the tables short ------------------------------------------------------
T = GENERIC
UNIT = (0.0, 1.0)
IOR_RANGE = (1.0, 3.0)
# Inputs several categories share, as _i(*...) arguments.
_UV = ("uv", "vec2", MESH_UV)
_FILTER = ("filter_width", "float", 1.0, "edge blur in pixels (0: hard edges)", (0.0, 4.0))
_SEED = ("seed", "float", 0.0, "integer seed: another seed, another pattern", (0.0, 1000.0))


def _i(name: str, type_: str, default: Any = 0.0, doc: str = "",
       rng: tuple[float, float] | None = None, required: bool = False,
       limits: tuple[float | None, float | None] | None = None) -> Port:
    return Port(name, type_, default, doc, rng, required, limits=limits)


def _o(name: str, type_: str, doc: str = "", group: str = "") -> Port:
    return Port(name, type_, doc=doc, group=group)


def _op(kind: str, title: str, inline: str | None, inputs: Iterable[Port], doc: str,
        out_type: str = GENERIC, category: str = "Math", glsl: str | None = None,
        mtlx: Mtlx = BAKE, reads: MxNode | None = None,
        numpy: Callable[..., Any] | None = None) -> NodeDef:
    """A kind with one output `result`: an inline template or a GLSL function."""
    return register(NodeDef(
        kind=kind, title=title, category=category, description=doc,
        inputs=tuple(inputs), outputs=(_o("result", out_type),),
        inline=inline if glsl is None else None, glsl=glsl, mtlx=mtlx, mtlx_reads=reads,
        numpy=numpy,
    ))


def _fn(kind: str, title: str, category: str, description: str, inputs: Iterable[Port],
        outputs: Iterable[Port], **facts: Any) -> NodeDef:
    """A kind with a GLSL function `node_<kind>`; `facts` are further NodeDef fields
    (numpy, thumbnail, geometry...)."""
    return register(NodeDef(kind, title, category, description, inputs=tuple(inputs),
                            outputs=tuple(outputs), glsl=f"node_{kind}", **facts))


def _bin(category: str) -> MxNode:
    return MxNode(category, (("a", "in1"), ("b", "in2")))


def _un(category: str) -> MxNode:
    return MxNode(category, (("value", "in"),))
