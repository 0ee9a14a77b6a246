"""The typed intermediate representation between a graph and the back-ends.

A scope (the material, or one material function) is a list of `Op`s in a
stable topological order. Operands are `Expr`s: another op's output (`Var`), a
literal (`Lit`), a uniform (`Uni`), a function parameter (`Param`), the mesh UV
(`SurfaceUV`), or an implicit conversion (`Splat`). Variables are named
`<node>_<port>`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from matedit.graph.types import PortType


class Expr:
    """An operand. The subclasses are frozen and slotted: one small object each, with no
    `__dict__` (a large graph makes tens of thousands of them, and each dict more is memory
    to fill, for the cyclic collector to walk, and to free). The two-field ones set their
    fields in their own `__init__` (dataclass keeps a class's own) through the slots'
    descriptors (`_slot_setters`): the generated one goes through `object.__setattr__`, half
    again the cost."""

    __slots__ = ()
    type: PortType

    def key(self) -> str:
        """A canonical string; equal keys mean equal values (used by CSE)."""
        raise NotImplementedError


def _slot_setters(cls: type, *fields: str) -> tuple[Any, ...]:
    """The `__set__` of each field's slot: what a frozen class's own `__init__` writes with."""
    return tuple(cls.__dict__[f].__set__ for f in fields)


@dataclass(frozen=True, slots=True, init=False)  # its own __init__ (see Expr)
class Var(Expr):
    name: str
    type: PortType

    def __init__(self, name: str, type: PortType) -> None:
        _set_var(self, name)
        _set_var_type(self, type)

    def key(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True, init=False)  # its own __init__ (see Expr)
class Param(Expr):
    name: str
    type: PortType

    def __init__(self, name: str, type: PortType) -> None:
        _set_param(self, name)
        _set_param_type(self, type)

    def key(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True, init=False)  # its own __init__ (see Expr)
class Lit(Expr):
    value: Any  # float or tuple of floats, or None for MaterialAttributes defaults
    type: PortType

    def __init__(self, value: Any, type: PortType) -> None:
        _set_lit(self, value)
        _set_lit_type(self, type)

    def key(self) -> str:
        return f"lit:{self.type}:{self.value!r}"


@dataclass(frozen=True, slots=True, init=False)  # its own __init__ (see Expr)
class Uni(Expr):
    name: str
    type: PortType

    def __init__(self, name: str, type: PortType) -> None:
        _set_uni(self, name)
        _set_uni_type(self, type)

    def key(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class SurfaceUV(Expr):
    type: PortType = PortType.VEC2

    def key(self) -> str:
        return "surface:uv"  # no `node.port` name has a colon


@dataclass(frozen=True, slots=True, init=False)  # its own __init__ (see Expr)
class Splat(Expr):
    expr: Expr
    type: PortType

    def __init__(self, expr: Expr, type: PortType) -> None:
        _set_splat(self, expr)
        _set_splat_type(self, type)

    def key(self) -> str:
        return f"{self.type}({self.expr.key()})"


_set_var, _set_var_type = _slot_setters(Var, "name", "type")
_set_param, _set_param_type = _slot_setters(Param, "name", "type")
_set_lit, _set_lit_type = _slot_setters(Lit, "value", "type")
_set_uni, _set_uni_type = _slot_setters(Uni, "name", "type")
_set_splat, _set_splat_type = _slot_setters(Splat, "expr", "type")


@dataclass(slots=True, init=False)  # its own __init__
class Op:
    """One evaluation: a catalogue node kind, or one of the compiler's own ops.

    `kind` is a node kind from the registry or a compiler op (`matedit.compiler.ops`: mask,
    append, set_attributes, weight, blend, call); either way its implementations are the row
    `ops.implementation(kind)`. Slotted, as the operands are (see Expr): one object an op.
    """

    var: str  # stem of the output names
    node: str  # node id the op came from (source map)
    kind: str
    args: list[Expr]
    outs: list[tuple[str, PortType]]
    data: dict[str, Any] = field(default_factory=dict)
    # out_vars(), once made (None until then): no field of the op's value
    _out_vars: dict[str, Var] | None = field(default=None, init=False, repr=False,
                                             compare=False)

    def __init__(self, var: str, node: str, kind: str, args: list[Expr],
                 outs: list[tuple[str, PortType]], data: dict[str, Any] | None = None,
                 out_vars: dict[str, Var] | None = None) -> None:
        # the generated __init__'s work, without its default-factory sentinel test
        self.var, self.node, self.kind, self.args, self.outs = var, node, kind, args, outs
        self.data = {} if data is None else data
        self._out_vars = out_vars  # what out_vars() would make, where the caller made it

    def out(self, port: str) -> Var:
        cache = self._out_vars
        if cache is None:
            cache = self.out_vars()
        return cache[port]

    def out_vars(self) -> dict[str, Var]:
        """Each output's variable, by port, in `outs` order (made once, then kept)."""
        cache = self._out_vars
        if cache is None:
            var = self.var
            cache = self._out_vars = {name: Var(f"{var}.{name}", t) for name, t in self.outs}
        return cache

    def key(self) -> str:
        if not self.data:
            data = ""  # a registry kind's implementation follows from its kind
        else:
            data = repr(sorted((k, repr(v)) for k, v in self.data.items()))
        return f"{self.kind}|{data}|{','.join([a.key() for a in self.args])}"


def expr_vars(e: Expr):
    """The names of the variables an operand reads (a Var, or one under Splats)."""
    if isinstance(e, Var):
        yield e.name
    elif isinstance(e, Splat):
        yield from expr_vars(e.expr)


@dataclass
class UniformInfo:
    name: str
    type: PortType
    default: Any
    node: str
    port: str
    parameter: str | None = None  # the artist-facing name for parameter nodes


@dataclass
class TextureInfo:
    name: str
    node: str
    path: str
    srgb: bool
    parameter: str
    ref: str = ""  # the path as the document stores it (relative to the document)
    color_space: str = ""  # the node's color_space setting; empty: srgb decides


@dataclass
class Scope:
    """A material's graph or a function's body."""

    name: str  # GLSL function name
    ops: list[Op] = field(default_factory=list)
    params: list[tuple[str, PortType]] = field(default_factory=list)
    outputs: list[tuple[str, PortType, Expr]] = field(default_factory=list)
    source: str = ""  # file the scope came from (source map)
    # (node id, port) -> expression, for probing any socket after lowering
    sockets: dict[tuple[str, str], Expr] = field(default_factory=dict)


@dataclass
class MaterialIR:
    main: Scope
    functions: list[Scope]  # callees before callers
    uniforms: list[UniformInfo]
    textures: list[TextureInfo]
    node_kinds: set[str]  # node kinds whose GLSL files are needed
    attributes: list[str]  # MaterialAttributes fields the graph writes
    defines: list[str] = field(default_factory=list)  # extra #defines, e.g. the material's
    # MATEDIT_ENERGY_COMPENSATION option (preview "energy_compensation": true)
    switches: dict[str, bool] = field(default_factory=dict)  # static switch name -> value
