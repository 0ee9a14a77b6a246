"""Lowering: a validated document (and the functions it calls) to the typed IR.

Top-level unconnected inputs become uniforms (`u_<node>_<port>`), parameter nodes
uniforms named after the parameter (`p_<name>`); inside material functions
unconnected inputs are literals of the function's own file. Implicit
conversions (a float splatted to a vector) are made explicit here.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from matedit.compiler.ir import (
    Expr,
    Lit,
    MaterialIR,
    Op,
    Param,
    Scope,
    Splat,
    SurfaceUV,
    TextureInfo,
    Uni,
    UniformInfo,
    Var,
)
from matedit.graph import nodes
from matedit.graph.model import Link, MaterialDocument
from matedit.graph.names import mangle
from matedit.graph.nodes import (
    ATTRIBUTE_FIELDS,
    ATTRIBUTE_NAMES,
    MA,
    MESH_UV,
    THIN_WALLED,
    Role,
    kind_for,
    lobe_value_is_default,
)
from matedit.graph.ports import (
    COLOR_LAYER_BLENDS,
    FunctionResolver,
    function_interface,
    layer_entries,
)
from matedit.graph.types import PortType, coerce_value
from matedit.graph.validate import Analysis, Diagnostic, Severity, analyse

ALL_FIELDS = frozenset(ATTRIBUTE_NAMES)


class CompileError(Exception):
    """The document does not compile; carries the diagnostics (node, port, message)."""

    def __init__(self, diagnostics: list[Diagnostic]) -> None:
        self.diagnostics = diagnostics
        first = diagnostics[0] if diagnostics else None
        msg = first.format() if first else "compile error"
        if first and first.file:
            msg = f"{first.file}: {msg}"
        super().__init__(msg)


def _doc_key(doc: MaterialDocument) -> str:
    return os.path.realpath(doc.path) if doc.path else f"<unsaved {id(doc)}>"


def literal(t: PortType, value: Any) -> Lit:
    v = coerce_value(t, value)
    return Lit(v if isinstance(v, float) else tuple(v), t)


def convert(expr: Expr, to: PortType) -> Expr:
    if expr.type == to:
        return expr
    if expr.type == PortType.FLOAT and to.is_numeric:
        if isinstance(expr, Lit):
            return Lit((expr.value,) * to.components, to)
        return Splat(expr, to)
    raise TypeError(f"no implicit conversion from {expr.type} to {to}")


THIN_WALLED_DEFINE = "MATERIAL_THIN_WALLED"  # the Material Output's thin_walled setting


@dataclass
class _Ctx:
    resolver: FunctionResolver | None
    functions: dict[str, Scope] = field(default_factory=dict)  # doc key -> scope
    function_written: dict[str, dict[str, frozenset]] = field(default_factory=dict)
    order: list[str] = field(default_factory=list)
    names: set[str] = field(default_factory=set)
    uniforms: dict[str, UniformInfo] = field(default_factory=dict)
    textures: dict[str, TextureInfo] = field(default_factory=dict)
    kinds: set[str] = field(default_factory=set)
    input_uniforms: dict[tuple[str, str], str] = field(default_factory=dict)
    input_uniform_names: set[str] = field(default_factory=set)  # its values, to look up
    switches: dict[str, tuple[bool, str]] = field(default_factory=dict)  # name -> (on, node)
    thin_walled: bool = False  # the top Material Output's thin_walled setting


class _Lowerer:
    def __init__(self, ctx: _Ctx, doc: MaterialDocument, analysis: Analysis, top: bool,
                 scope: Scope) -> None:
        self.ctx, self.doc, self.a, self.top, self.scope = ctx, doc, analysis, top, scope
        self.alias: dict[tuple[str, str], Expr] = {}
        self.written: dict[str, frozenset] = {}  # expr key -> fields written (MA values)
        # the analysis's: with no error, every link passed its checks (read, never changed)
        self.incoming: dict[str, dict[str, Link]] = analysis.incoming
        if len(self.incoming) != len(doc.graph.nodes):  # an Analysis made without them
            self.incoming = {nid: {} for nid in doc.graph.nodes}
            for l in doc.graph.links:
                self.incoming[l.dst][l.dst_port] = l

    # --- operands --------------------------------------------------------------------------
    def source(self, nid: str, port: str) -> Expr:
        if (nid, port) in self.alias:
            return self.alias[(nid, port)]
        return Var(f"{nid}.{port}", self.a.out_types[nid][port])

    def arg(self, nid: str, port: str, t: PortType, default: Any) -> Expr:
        link = self.incoming[nid].get(port)
        if link is not None:
            src, src_port = link.src, link.src_port
            e = self.alias.get((src, src_port))
            if e is None:  # self.source, inlined: most operands are another op's output
                e = Var(f"{src}.{src_port}", self.a.out_types[src][src_port])
            return e if e.type == t else convert(e, t)
        node = self.doc.graph.nodes[nid]
        value = node.values.get(port, default)
        if value == MESH_UV:
            return SurfaceUV()
        if t == MA:
            return Lit(None, PortType.MATERIAL)  # defaultMaterialAttributes()
        if t == PortType.TEXTURE:  # unconnected: a texture with no image, shown as a checker
            name = f"u_{nid}_{port}" if self.top else f"u_{self.scope.name}_{nid}_{port}"
            self.ctx.textures.setdefault(
                name, TextureInfo(name, nid if self.top else "", "", False, ""))
            return Uni(name, PortType.TEXTURE)
        if not t.is_numeric:
            raise CompileError([Diagnostic(Severity.ERROR, f"input {port!r} must be connected",
                                           nid, port, self.file)])
        if value is None:
            value = 0.0
        if self.top:
            name = self._input_uniform_name(nid, port)
            self._uniform(UniformInfo(name, t, coerce_value(t, value), nid, port))
            return Uni(name, t)
        return literal(t, value)

    @property
    def file(self) -> str | None:
        return str(self.doc.path) if self.doc.path else None

    def _input_uniform_name(self, nid: str, port: str) -> str:
        """`u_<node>_<port>`, with a numbered suffix where two (node, port) pairs would meet
        (node `a_b` port `c` and node `a` port `b_c`): one name per pair, never shared."""
        key = (nid, port)
        taken = self.ctx.input_uniforms
        if key in taken:
            return taken[key]
        base = f"u_{nid}_{port}"
        name, i = base, 2
        names = self.ctx.input_uniform_names
        while name in self.ctx.uniforms or name in names:
            name, i = f"{base}_{i}", i + 1
        taken[key] = name
        names.add(name)
        return name

    def _uniform(self, info: UniformInfo) -> None:
        old = self.ctx.uniforms.get(info.name)
        if old is not None and (old.type != info.type or old.node != info.node):
            raise CompileError([Diagnostic(
                Severity.ERROR, f"uniform name {info.name!r} is used twice "
                f"(by {old.node} and {info.node}); rename the parameter", info.node, "name",
                self.file)])
        if old is None:
            self.ctx.uniforms[info.name] = info

    def emit(self, op: Op) -> Op:
        scope = self.scope
        scope.ops.append(op)
        sockets, node = scope.sockets, op.node
        for port, var in op.out_vars().items():
            sockets[(node, port)] = var
        return op

    # --- nodes -------------------------------------------------------------------------------
    def lower(self) -> None:
        gnodes = self.doc.graph.nodes
        role_of = nodes.role_of
        handlers: dict[str, Any] = {}  # kind -> the method that lowers its nodes
        for nid in self.a.order:
            node = gnodes[nid]
            if not node.muted:
                handler = handlers.get(node.kind)
                if handler is None:
                    role = role_of(node.kind)
                    special = getattr(self, f"_k_{role.name.lower()}", None) if role else None
                    handler = handlers[node.kind] = special or self._generic
                handler(nid, node)
                continue
            role = role_of(node.kind)
            if role == Role.LAYER_STACK:
                # A bypassed stack is its base layer: every layer above it hidden.
                layers = node.settings.get("layers")
                if isinstance(layers, list):
                    node = dataclasses.replace(node, settings={**node.settings, "layers": [
                        e if i == 0 or not isinstance(e, dict) else {**e, "visible": False}
                        for i, e in enumerate(layers)]})
            elif nodes.can_bypass(node.kind):
                self._bypass(nid)
                continue
            special = getattr(self, f"_k_{role.name.lower()}", None) if role else None
            (special or self._generic)(nid, node)
        for (nid, port), e in self.alias.items():
            # An alias is what the node outputs (a layer stack's blended result), even where
            # the node also emitted ops under its id (the layers' calls).
            self.scope.sockets[(nid, port)] = e

    def _bypass(self, nid: str) -> None:
        """A bypassed (muted) node emits nothing: each output is its first input of the
        output's type, as wired or at its value (still a uniform, so its slider works), or
        the type's zero (a default MaterialAttributes) when it has no such input."""
        ins, ports = self.a.in_types[nid], self.a.ports[nid]
        for o in ports.outputs:
            t = self.a.out_types[nid][o.name]
            through = next((p for p in ports.inputs if ins[p.name] == t), None)
            if through is not None:
                self.alias[(nid, o.name)] = self.arg(nid, through.name, t, through.default)
            elif t == MA:
                self.alias[(nid, o.name)] = Lit(None, PortType.MATERIAL)
            elif t.is_numeric:
                self.alias[(nid, o.name)] = convert(literal(PortType.FLOAT, 0.0), t)
            else:
                raise CompileError([Diagnostic(
                    Severity.ERROR, f"a bypassed node has no {t.value} input to pass through to "
                    f"{o.name!r}; un-bypass it", nid, o.name, self.file)])

    def _inputs(self, nid: str) -> list[Expr]:
        ins = self.a.in_types[nid]
        arg = self.arg
        return [arg(nid, p.name, ins[p.name], p.default) for p in self.a.ports[nid].inputs]

    def _generic(self, nid, node) -> None:
        d = nodes.REGISTRY[node.kind]
        role = d.role
        a = self.a
        sockets = self.scope.sockets
        if role == Role.MAKE_ATTRIBUTES:
            # A field left at its default is compiled in as a literal, with no uniform.
            unwritten = self._unwritten_fields(nid, node)
            ins = a.in_types[nid]
            args = [literal(PortType(f.type), f.default) if f.name in unwritten
                    else self.arg(nid, f.name, ins[f.name], f.default) for f in ATTRIBUTE_FIELDS]
        else:
            # self._inputs, inlined: an operand wired from another op's output is that op's
            # variable (its socket), made once when the op was emitted
            ins = a.in_types[nid]
            into = self.incoming[nid]
            alias, types = self.alias, a.out_types
            args = []
            for p in a.ports[nid].inputs:
                name = p.name
                t = ins[name]
                link = into.get(name)
                if link is None:
                    args.append(self.arg(nid, name, t, p.default))
                    continue
                key = (link.src, link.src_port)
                e = alias.get(key)
                if e is None:
                    var = f"{link.src}.{link.src_port}"
                    src_type = types[link.src][link.src_port]
                    e = sockets.get(key)
                    if type(e) is not Var or e.name != var or e.type != src_type:
                        e = Var(var, src_type)
                args.append(e if e.type == t else convert(e, t))
        # the outputs, their variables (Op.out_vars) and sockets (self.emit), in one walk
        out_types = a.out_types[nid]
        outs = []
        out_vars: dict[str, Var] = {}
        for p in a.ports[nid].outputs:
            name = p.name
            t = out_types[name]
            outs.append((name, t))
            out_vars[name] = sockets[(nid, name)] = Var(f"{nid}.{name}", t)
        self.ctx.kinds.add(node.kind)
        op = Op(nid, nid, node.kind, args, outs, None, out_vars)
        self.scope.ops.append(op)
        if role == Role.MAKE_ATTRIBUTES:
            self.written[op.out("attributes").key()] = ALL_FIELDS - unwritten
        elif role in (Role.MASK_BLEND, Role.HEIGHT_BLEND):
            self.written[op.out("result").key()] = self._w(args[0]) | self._w(args[1])

    def _unwritten_fields(self, nid: str, node) -> frozenset:
        """Fields a Make Attributes leaves at their defaults, compiled in as literals: the
        tangent-space normal when unconnected (MATERIAL_HAS_NORMAL), and each lobe input that
        is unconnected at its default (its lobe compiled out; graph.commands makes moving it
        off the default structural)."""
        out = set()
        for f in ATTRIBUTE_FIELDS:
            if f.name in self.incoming[nid]:
                continue
            if f.name == "normal" or (f.lobe and lobe_value_is_default(node, f)):
                out.add(f.name)
        return frozenset(out)

    def _w(self, e: Expr) -> frozenset:
        if isinstance(e, Param):
            return frozenset({"@" + e.name})
        if isinstance(e, Lit):
            return frozenset()
        return self.written.get(e.key(), ALL_FIELDS)

    def _k_constant(self, nid, node) -> None:
        t = self.a.out_types[nid]["value"]
        self.alias[(nid, "value")] = literal(t, node.settings.get("value", 0.0))

    def _parameter(self, nid, node, port: str, t: PortType, default: Any) -> None:
        pname = str(node.settings.get("name", nid))
        name = f"p_{pname}"
        value = coerce_value(t, node.values.get("value", default))
        self._uniform(UniformInfo(name, t, value, nid, "value", pname))
        self.alias[(nid, port)] = Uni(name, t)

    def _k_scalar_parameter(self, nid, node) -> None:
        self._parameter(nid, node, "value", PortType.FLOAT, 0.5)

    def _k_color_parameter(self, nid, node) -> None:
        self._parameter(nid, node, "color", PortType.VEC3, [0.5, 0.5, 0.5])

    def _k_vector_parameter(self, nid, node) -> None:
        pname = str(node.settings.get("name", nid))
        name = f"p_{pname}"
        value = coerce_value(PortType.VEC4, node.values.get("value", [0.0, 0.0, 0.0, 1.0]))
        self._uniform(UniformInfo(name, PortType.VEC4, value, nid, "value", pname))
        self.ctx.kinds.add(node.kind)
        self.emit(Op(nid, nid, node.kind, [Uni(name, PortType.VEC4)],
                     [("value", PortType.VEC4), ("xyz", PortType.VEC3)]))

    def _k_texture_parameter(self, nid, node) -> None:
        pname = str(node.settings.get("name", nid))
        name = f"t_{pname}"
        path = str(node.settings.get("path", ""))
        if path and self.doc.path is not None and not Path(path).is_absolute():
            # joined, not normalised: `lnk/../t.png` is the file the system reaches through
            # the link, as validate and the overwrite check see it, not `t.png` beside it
            path = str(Path(os.path.abspath(Path(self.doc.path).parent)) / path)
        if name not in self.ctx.textures:
            self.ctx.textures[name] = TextureInfo(name, nid, path,
                                                  bool(node.settings.get("srgb", True)), pname,
                                                  str(node.settings.get("path", "")),
                                                  str(node.settings.get("color_space", "")))
        self.alias[(nid, "texture")] = Uni(name, PortType.TEXTURE)

    def _k_static_switch(self, nid, node) -> None:
        """Compile-time choice: only the chosen input is read, so the other branch is dead
        code (removed with its uniforms and textures by optimise and prune)."""
        from matedit.graph.names import identifier_problem

        name = node.settings.get("name", nid)
        on = node.settings.get("value", True)
        bad = identifier_problem(name) if isinstance(name, str) else "must be a string"
        if bad or not isinstance(on, bool):
            field_, why = ("name", f"switch name {name!r} {bad}") if bad else (
                "value", f"switch value must be true or false, got {on!r}")
            raise CompileError([Diagnostic(Severity.ERROR, why, nid, field_, self.file)])
        if self.top:
            other = self.ctx.switches.get(name)
            if other is not None and other[1] != nid:
                raise CompileError([Diagnostic(
                    Severity.ERROR, f"static switch name {name!r} is used by {other[1]} too",
                    nid, "name", self.file)])
            self.ctx.switches[name] = (on, nid)
        port = "true" if on else "false"
        spec = self.a.ports[nid].input(port)
        t = self.a.out_types[nid]["result"]
        self.alias[(nid, "result")] = self.arg(nid, port, t, spec.default if spec else 0.0)

    def _k_reroute(self, nid, node) -> None:
        t = self.a.in_types[nid]["value"]
        self.alias[(nid, "value")] = self.arg(nid, "value", t, 0.0)

    def _k_component_mask(self, nid, node) -> None:
        from matedit.graph.ports import normalize_channels

        (arg,) = self._inputs(nid)
        channels = normalize_channels(node.settings.get("channels", "xy"))
        t = self.a.out_types[nid]["result"]
        self.emit(Op(nid, nid, "mask", [arg], [("result", t)], {"channels": channels}))

    def _k_append(self, nid, node) -> None:
        args = self._inputs(nid)
        t = self.a.out_types[nid]["result"]
        self.emit(Op(nid, nid, node.kind, args, [("result", t)], {}))

    def _k_set_attributes(self, nid, node) -> None:
        args = self._inputs(nid)
        fields = [p.name for p in self.a.ports[nid].inputs[1:]]
        op = self.emit(Op(nid, nid, node.kind, args, [("attributes", PortType.MATERIAL)],
                          {"fields": tuple(fields)}))
        self.written[op.out("attributes").key()] = self._w(args[0]) | frozenset(fields)

    def _k_material_output(self, nid, node) -> None:
        (arg,) = self._inputs(nid)
        self.scope.outputs.append(("attributes", PortType.MATERIAL, arg))
        if self.top and node.settings.get(THIN_WALLED) is True:
            self.ctx.thin_walled = True

    def _k_function_input(self, nid, node) -> None:
        t = self.a.out_types[nid]["value"]
        self.alias[(nid, "value")] = Param(f"in_{node.settings.get('name', nid)}", t)

    def _k_function_output(self, nid, node) -> None:
        t = self.a.in_types[nid]["value"]
        name = str(node.settings.get("name", nid))
        self.scope.outputs.append((name, t, self.arg(nid, "value", t, None)))

    def _resolve(self, ref: str, nid: str) -> MaterialDocument:
        """The material function `ref` that node `nid` calls; without a resolver a
        CompileError on that node (validation reports it first for the top document)."""
        if self.ctx.resolver is None:
            raise CompileError([Diagnostic(
                Severity.ERROR, f"cannot resolve function {ref!r} without a resolver", nid,
                None, self.file)])
        return self.ctx.resolver.resolve(ref, self.doc)

    def _call(self, nid: str, var: str, ref: str, args: dict[str, Expr]) -> tuple[Op, Scope]:
        callee_doc = self._resolve(ref, nid)
        callee = lower_function(self.ctx, callee_doc)
        iface = function_interface(callee_doc)
        ordered = []
        for p in iface.inputs:
            ordered.append(args[p.name])
        outs = [(o.name, PortType(o.type)) for o in iface.outputs]
        op = self.emit(Op(var, nid, "call", ordered, outs, {"function": callee.name}))
        fw = self.ctx.function_written.get(callee.name, {})
        params = {f"in_{p.name}": e for p, e in zip(iface.inputs, ordered)}
        for name, t in outs:
            if t == PortType.MATERIAL:
                w = fw.get(name, ALL_FIELDS)
                resolved: set[str] = set()
                for f in w:
                    if f.startswith("@"):
                        resolved |= self._w(params[f[1:]]) if f[1:] in params else ALL_FIELDS
                    else:
                        resolved.add(f)
                self.written[op.out(name).key()] = frozenset(resolved)
        return op, callee

    def _k_function_call(self, nid, node) -> None:
        if not node.settings.get("function"):
            return  # no function chosen yet: no ports, nothing to call (validate warns)
        ins = self.a.in_types[nid]
        args = {p.name: self.arg(nid, p.name, ins[p.name], p.default)
                for p in self.a.ports[nid].inputs}
        self._call(nid, nid, node.settings["function"], args)

    def _color_layer(self, nid, lid, mode, acc, value, blended, w) -> Op:
        """A layer in a colour blend mode: `blended` (every field by the mask) with its base
        colour replaced by the catalogue's Blend node of that mode (blend_<mode>) of the
        layer's base colour over the stack's, mixed by the same weight: what a painting
        program's layer mode does to colour; roughness, normal and the rest stay the mask's."""
        brk = nodes.definition(nodes.BREAK_ATTRIBUTES)
        fields = [(f.name, PortType(f.type)) for f in ATTRIBUTE_FIELDS]
        self.ctx.kinds.add(brk.kind)
        below = self.emit(Op(f"{nid}.{lid}.below", nid, brk.kind, [acc], fields))
        above = self.emit(Op(f"{nid}.{lid}.above", nid, brk.kind, [value], fields))
        d = nodes.definition(f"blend_{mode}")
        self.ctx.kinds.add(d.kind)
        color = self.emit(Op(f"{nid}.{lid}.color", nid, d.kind,
                             [below.out("baseColor"), above.out("baseColor"), w],
                             [("result", PortType.VEC3)]))
        set_kind = kind_for(Role.SET_ATTRIBUTES)
        self.ctx.kinds.add(set_kind)
        return self.emit(Op(f"{nid}.{lid}.mode", nid, set_kind,
                            [blended.out("result"), color.out("result")],
                            [("attributes", PortType.MATERIAL)], {"fields": ("baseColor",)}))

    def _k_layer_stack(self, nid, node) -> None:
        ins = self.a.in_types[nid]
        specs = {p.name: p for p in self.a.ports[nid].inputs}

        def port(name: str) -> Expr:
            return self.arg(nid, name, ins[name], specs[name].default)

        acc: Expr | None = None
        for i, layer in enumerate(layer_entries(node)):
            lid = layer["id"]
            iface = function_interface(self._resolve(layer["function"], nid))
            args = {p.name: port(f"{lid}_{p.name}") for p in iface.inputs}
            op, _ = self._call(nid, f"{nid}.{lid}", layer["function"], args)
            ma_out = next(o for o, t in op.outs if t == PortType.MATERIAL)
            value = op.out(ma_out)
            if not layer.get("visible", True) and i > 0:
                self.scope.ops.pop()  # hidden: compiled out entirely
                continue
            if acc is None:
                acc = value
                continue
            blend = layer.get("blend", "alpha")
            opacity = port(f"{lid}_opacity")
            written = self._w(acc) | self._w(value)
            if blend in ("alpha", "coat", "film") or blend in COLOR_LAYER_BLENDS:
                w = self.emit(Op(f"{nid}.{lid}.w", nid, "weight", [port(f"{lid}_mask"), opacity],
                                 [("result", PortType.FLOAT)], {}))
                if blend == "coat":
                    blended = self.emit(Op(f"{nid}.{lid}.blend", nid, "coat",
                                           [acc, value, w.out("result")],
                                           [("result", PortType.MATERIAL)], {}))
                    written = self._w(acc) | _coat_written(self._w(value))
                elif blend == "film":
                    blended = self.emit(Op(f"{nid}.{lid}.blend", nid, "film",
                                           [acc, value, w.out("result")],
                                           [("result", PortType.MATERIAL)], {}))
                    written = self._w(acc) | _film_written(self._w(value))
                else:
                    blended = self.emit(Op(f"{nid}.{lid}.blend", nid, "blend",
                                           [acc, value, w.out("result")],
                                           [("result", PortType.MATERIAL)], {}))
                if blend in COLOR_LAYER_BLENDS:
                    blended = self._color_layer(nid, lid, blend, acc, value, blended,
                                                w.out("result"))
            else:
                if blend == "height":
                    hb = nodes.definition(kind_for(Role.HEIGHT_BLEND))
                    self.ctx.kinds.add(hb.kind)
                    shaped = self.emit(Op(
                        f"{nid}.{lid}.h", nid, hb.kind,
                        [acc, value, port(f"{lid}_base_height"), port(f"{lid}_mask"),
                         port(f"{lid}_contrast")],
                        [("result", PortType.MATERIAL)]))
                else:
                    biface = function_interface(self._resolve(blend, nid))
                    mas = [p.name for p in biface.inputs if p.type == MA][:2]
                    bargs = {mas[0]: acc, mas[1]: value}
                    for p in biface.inputs:
                        if p.name not in bargs:
                            bargs[p.name] = port(f"{lid}_{p.name}")
                    shaped, _ = self._call(nid, f"{nid}.{lid}.b", blend, bargs)
                out_name = next(o for o, t in shaped.outs if t == PortType.MATERIAL)
                blended = self.emit(Op(f"{nid}.{lid}.blend", nid, "blend",
                                       [acc, shaped.out(out_name), convert(opacity,
                                                                           PortType.FLOAT)],
                                       [("result", PortType.MATERIAL)], {}))
            self.ctx.kinds.add(kind_for(Role.MASK_BLEND))
            out = blended.outs[0][0]
            self.written[blended.out(out).key()] = written
            acc = blended.out(out)
        if acc is None:
            acc = Lit(None, PortType.MATERIAL)
        self.alias[(nid, "attributes")] = acc
        # keep "written" for the alias
        if isinstance(acc, Var):
            self.written.setdefault(acc.key(), ALL_FIELDS)


FILM_FIELDS = frozenset({"thinFilmThickness", "thinFilmIor"})


def _film_written(layer: frozenset) -> frozenset:
    """The fields a `film` layer writes (filmMaterialAttributes): the thin film's, those its
    layer function writes (both where it may: a field passed through from an input, `@name`)."""
    if any(f.startswith("@") for f in layer):
        return FILM_FIELDS
    return layer & FILM_FIELDS


def _coat_written(layer: frozenset) -> frozenset:
    """The fields a `coat` layer writes, from those its layer function writes: the coat's
    weight, roughness and tint always (the layer's roughness and base colour are values even at
    their defaults); its normal and IOR where the layer writes a normal or an IOR (or may:
    a field it passes through from a function input, `@name`)."""
    out = {"coat", "coatRoughness", "coatColor"}
    unknown = any(f.startswith("@") for f in layer)
    if unknown or "normal" in layer:
        out.add("coatNormal")
    if unknown or "ior" in layer:
        out.add("coatIor")
    return frozenset(out)


def _check(doc: MaterialDocument, resolver, top: bool = True) -> Analysis:
    # the top document's check covers every callee
    return _checked(analyse(doc, resolver, calls=top))


def _checked(a: Analysis) -> Analysis:
    errors = [d for d in a.diagnostics if d.severity == Severity.ERROR]
    if errors:
        raise CompileError(errors)
    return a


def lower_function(ctx: _Ctx, doc: MaterialDocument) -> Scope:
    key = _doc_key(doc)
    if key in ctx.functions:
        return ctx.functions[key]
    stem = "fn_" + mangle(Path(doc.path).stem if doc.path else doc.name or "function")
    name, i = stem, 2
    while name in ctx.names:
        name, i = f"{stem}_{i}", i + 1
    ctx.names.add(name)
    a = _check(doc, ctx.resolver, top=False)
    scope = Scope(name=name, source=str(doc.path or doc.name))
    iface = function_interface(doc)
    scope.params = [(f"in_{p.name}", PortType(p.type)) for p in iface.inputs]
    low = _Lowerer(ctx, doc, a, top=False, scope=scope)
    low.lower()
    # outputs in interface order
    by_name = {n: (n, t, e) for n, t, e in scope.outputs}
    scope.outputs = [by_name[o.name] for o in iface.outputs]
    ctx.function_written[name] = {n: low._w(e) for n, t, e in scope.outputs
                                  if t == PortType.MATERIAL}
    ctx.functions[key] = scope
    ctx.order.append(key)
    return scope


def lower_document(doc: MaterialDocument, resolver: FunctionResolver | None,
                   analysis: Analysis | None = None) -> MaterialIR:
    """Validate and lower a material document; raises CompileError with diagnostics.
    `analysis`: the document's analysis (graph.validate.analyse with its calls), made of the
    document as it is, which the editor has already: not made again."""
    if doc.is_function:
        raise CompileError([Diagnostic(Severity.ERROR, "a material function is compiled through "
                                       "the materials that call it", None, None,
                                       str(doc.path) if doc.path else None)])
    ctx = _Ctx(resolver)
    a = _check(doc, resolver) if analysis is None else _checked(analysis)
    scope = Scope(name="evaluateMaterial", source=str(doc.path or doc.name))
    low = _Lowerer(ctx, doc, a, top=True, scope=scope)
    try:
        low.lower()
    except LookupError as exc:
        raise CompileError([Diagnostic(Severity.ERROR, str(exc), None, None, low.file)]) from None
    written = low._w(scope.outputs[0][2]) if scope.outputs else frozenset()
    attributes = [f for f in ATTRIBUTE_NAMES if f in written]
    params = {u.parameter: u.node for u in ctx.uniforms.values() if u.parameter}
    params.update({t.parameter: t.node for t in ctx.textures.values()})
    for name, (_, nid) in sorted(ctx.switches.items()):
        if name in params:
            raise CompileError([Diagnostic(
                Severity.ERROR, f"static switch name {name!r} is a parameter of "
                f"{params[name]} too", nid, "name", low.file)])
    return MaterialIR(
        main=scope,
        functions=[ctx.functions[k] for k in ctx.order],
        uniforms=sorted(ctx.uniforms.values(), key=lambda u: u.name),
        textures=sorted(ctx.textures.values(), key=lambda t: t.name),
        node_kinds=ctx.kinds,
        attributes=attributes,
        switches={k: on for k, (on, _) in sorted(ctx.switches.items())},
        # thin-walled transmission (transmission.glsl), only where the material transmits
        defines=[THIN_WALLED_DEFINE] if ctx.thin_walled and "transmission" in attributes
        else [],
    )
