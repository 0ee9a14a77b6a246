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
    """An operand. The frozen subclasses write their two fields into `__dict__` in their own
    `__init__` (dataclass keeps a class's own): the generated one sets each through
    `object.__setattr__`, twice the cost, and a large graph makes thousands of them."""

    type: PortType

    def key(self) -> str:
        """A canonical string; equal keys mean equal values (used by CSE)."""
        raise NotImplementedError


@dataclass(frozen=True, init=False)  # its own __init__ (see Expr)
class Var(Expr):
    name: str
    type: PortType

    def __init__(self, name: str, type: PortType) -> None:
        d = self.__dict__  # frozen: the fields are set once, here
        d["name"] = name
        d["type"] = type

    def key(self) -> str:
        return self.name


@dataclass(frozen=True, init=False)  # its own __init__ (see Expr)
class Param(Expr):
    name: str
    type: PortType

    def __init__(self, name: str, type: PortType) -> None:
        d = self.__dict__
        d["name"] = name
        d["type"] = type

    def key(self) -> str:
        return self.name


@dataclass(frozen=True, init=False)  # its own __init__ (see Expr)
class Lit(Expr):
    value: Any  # float or tuple of floats, or None for MaterialAttributes defaults
    type: PortType

    def __init__(self, value: Any, type: PortType) -> None:
        d = self.__dict__
        d["value"] = value
        d["type"] = type

    def key(self) -> str:
        return f"lit:{self.type}:{self.value!r}"


@dataclass(frozen=True, init=False)  # its own __init__ (see Expr)
class Uni(Expr):
    name: str
    type: PortType

    def __init__(self, name: str, type: PortType) -> None:
        d = self.__dict__
        d["name"] = name
        d["type"] = type

    def key(self) -> str:
        return self.name


@dataclass(frozen=True)
class SurfaceUV(Expr):
    type: PortType = PortType.VEC2

    def key(self) -> str:
        return "surface:uv"  # no `node.port` name has a colon


@dataclass(frozen=True, init=False)  # its own __init__ (see Expr)
class Splat(Expr):
    expr: Expr
    type: PortType

    def __init__(self, expr: Expr, type: PortType) -> None:
        d = self.__dict__
        d["expr"] = expr
        d["type"] = type

    def key(self) -> str:
        return f"{self.type}({self.expr.key()})"


@dataclass(init=False)  # its own __init__
class Op:
    """One evaluation: a catalogue node kind, or one of the compiler's own ops.

    `kind` is a node kind from the registry or a compiler op (`matedit.compiler.ops`: mask,
    append, set_attributes, weight, blend, call); either way its implementations are the row
    `ops.implementation(kind)`.
    """

    var: str  # stem of the output names
    node: str  # node id the op came from (source map)
    kind: str
    args: list[Expr]
    outs: list[tuple[str, PortType]]
    data: dict[str, Any] = field(default_factory=dict)

    def __init__(self, var: str, node: str, kind: str, args: list[Expr],
                 outs: list[tuple[str, PortType]], data: dict[str, Any] | None = None,
                 out_vars: dict[str, Var] | None = None) -> None:
        # the generated __init__'s work, without its default-factory sentinel test
        self.var, self.node, self.kind, self.args, self.outs = var, node, kind, args, outs
        self.data = {} if data is None else data
        if out_vars is not None:  # what out_vars() would make, made by the caller already
            self.__dict__["_out_vars"] = out_vars

    def out(self, port: str) -> Var:
        cache = self.__dict__.get("_out_vars")
        if cache is None:
            cache = self.out_vars()
        return cache[port]

    def out_vars(self) -> dict[str, Var]:
        """Each output's variable, by port, in `outs` order (made once, then kept)."""
        cache = self.__dict__.get("_out_vars")
        if cache is None:
            var = self.var
            cache = {name: Var(f"{var}.{name}", t) for name, t in self.outs}
            self.__dict__["_out_vars"] = cache
        return cache

    def key(self) -> str:
        if not self.data:
            data = ""  # a registry kind's implementation follows from its kind
        else:
            data = repr(sorted((k, repr(v)) for k, v in self.data.items()))
        return f"{self.kind}|{data}|{','.join([a.key() for a in self.args])}"


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
