"""Validation of material documents: a list of diagnostics, never an exception.

Checks unknown node kinds, bad settings, links to missing nodes or ports, type
mismatches, missing required links, cycles (inside a graph, and through
function calls across files), calls to missing functions, and the document's
output nodes. `check_connect` answers, before a link is made, whether it may be.

The valid path orders the graph by its own in-degree counts (`stable_order`: the order
graphlib's TopologicalSorter gives, with graphlib's CycleError); networkx, whose import (with
its backend scan) costs more than the rest of `matedit validate`, is loaded only to name a
cycle that was found and for `check_connect`'s reachability question.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import Enum
from graphlib import CycleError
from operator import attrgetter, itemgetter
from pathlib import Path
from typing import TYPE_CHECKING

from matedit.graph import nodes
from matedit.graph.model import Link, MaterialDocument
from matedit.graph.names import identifier_problem
from matedit.graph.numbers import gpu_number_problem
from matedit.graph.ports import (
    STATIC_RULES,
    TYPE_PLANS,
    FunctionResolver,
    NodePorts,
    PortError,
    generic_types,
    layer_entries,
    node_ports,
    resolve_types,
    static_ports,
    type_plan,
)
from matedit.graph.types import PortType, coerce_value, conversion_reason

if TYPE_CHECKING:
    import networkx as nx


class Severity(str, Enum):
    ERROR = "error"
    WARNING = "warning"


@dataclass(frozen=True)
class Diagnostic:
    severity: Severity
    message: str
    node_id: str | None = None
    port: str | None = None
    file: str | None = None

    def format(self) -> str:
        where = []
        if self.node_id:
            where.append(f"node {self.node_id}")
        if self.port:
            where.append(f"field {self.port}")
        loc = (", ".join(where) + ": ") if where else ""
        return f"{loc}{self.message}"


# What an unconnected required input of these types becomes (the compiler lowers it so),
# instead of an error that stops the whole material; reroutes and function outputs pass a
# value through, so they have none of their own.
_UNCONNECTED_DEFAULT = {PortType.MATERIAL: "the default material attributes",
                        PortType.TEXTURE: "a checker texture"}
_NO_DEFAULT = {nodes.Role.REROUTE, nodes.Role.FUNCTION_OUTPUT}


def error(msg, node=None, port=None, file=None) -> Diagnostic:
    return Diagnostic(Severity.ERROR, msg, node, port, file)


def warning(msg, node=None, port=None, file=None) -> Diagnostic:
    return Diagnostic(Severity.WARNING, msg, node, port, file)


@dataclass
class Analysis:
    """What validation learned: ports and concrete types of every node, in evaluation order."""

    ports: dict[str, NodePorts]
    in_types: dict[str, dict[str, PortType]]
    out_types: dict[str, dict[str, PortType]]
    order: list[str]
    diagnostics: list[Diagnostic]
    # node id -> input port -> the link into it, of the links that passed the checks (every
    # link, where there is no error)
    incoming: dict[str, dict[str, Link]] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not any(d.severity == Severity.ERROR for d in self.diagnostics)


def _file(doc: MaterialDocument) -> str | None:
    return str(doc.path) if doc.path else None


def dependency_graph(doc: MaterialDocument) -> nx.DiGraph:
    import networkx as nx

    g = nx.DiGraph()
    g.add_nodes_from(doc.graph.nodes)
    for link in doc.graph.links:
        g.add_edge(link.src, link.dst)
    return g


def stable_order(vertices: Iterable[str], edges: Iterable[tuple[str, str]]) -> list[str]:
    """Topological order independent of the file's order: generation by generation (nodes
    whose inputs are all in earlier generations), ids sorted within each generation.
    Raises graphlib.CycleError when the edges close a cycle.

    Kahn's algorithm with in-degree counts (the order graphlib's TopologicalSorter gives when
    each generation is marked done at once, at a fraction of its cost per edge)."""
    succ: dict[str, list[str]] = {v: [] for v in vertices}
    indeg = dict.fromkeys(succ, 0)
    for src, dst in edges:
        out = succ.get(src)
        if out is None:
            out = succ[src] = []
            indeg[src] = 0
        if dst not in indeg:
            succ[dst] = []
            indeg[dst] = 0
        out.append(dst)
        indeg[dst] += 1
    generation = sorted([v for v, k in indeg.items() if k == 0])
    order: list[str] = []
    while generation:
        order.extend(generation)
        ready = []
        for v in generation:
            for w in succ[v]:
                k = indeg[w] - 1
                indeg[w] = k
                if k == 0:
                    ready.append(w)
        ready.sort()
        generation = ready
    if len(order) != len(indeg):
        raise CycleError("nodes are in a cycle")
    return order


def _cycle(vertices: Iterable[str], edges: Iterable[tuple[str, str]],
           source: str | None = None) -> list[tuple[str, str]]:
    """The edges of one cycle, named the way networkx's find_cycle walks it (only called
    once stable_order has found that there is one)."""
    import networkx as nx

    g = nx.DiGraph()
    g.add_nodes_from(vertices)
    g.add_edges_from(edges)
    return list(nx.find_cycle(g, source=source))


MAX_CALL_DEPTH = 64  # material functions nested deeper than this are refused


def analyse(doc: MaterialDocument, resolver: FunctionResolver | None = None, *,
            calls: bool = True) -> Analysis:
    """Ports, types, evaluation order and diagnostics of one document. `calls=False` skips
    the walk over the functions it calls (done once for the top document by the compiler)."""
    f = _file(doc)
    diags: list[Diagnostic] = []
    graph = doc.graph
    ports: dict[str, NodePorts] = {}

    # Node kinds, settings and ports.
    registry = nodes.REGISTRY
    gnodes = graph.nodes
    for nid in sorted(gnodes):
        node = gnodes[nid]
        d = registry.get(node.kind)
        if d is None:
            diags.append(error(f"unknown node kind {node.kind!r}", nid, "kind", f))
            continue
        settings = node.settings
        if settings:
            for s in d.settings:  # ranges, curves: the float32 rule
                if s.kind == "number" and s.name in settings:
                    why = gpu_number_problem(settings[s.name])
                    if why:
                        diags.append(error(why, nid, s.name, f))
        if d.role == nodes.Role.FUNCTION_CALL and settings.get("function") in (None, ""):
            diags.append(warning("no function chosen yet: the call does nothing until one is",
                                 nid, "function", f))
        try:
            rule = d.ports_rule  # node_ports' fast path: most kinds' ports are the kind's own
            p = ports[nid] = static_ports(node.kind) if rule is None or rule in STATIC_RULES \
                else node_ports(node, resolver, doc)
            if node.values and p.limited:
                diags.extend(_limit_warnings(node, p, f))
        except PortError as exc:
            diags.append(error(str(exc), nid, exc.field, f))
        except LookupError as exc:
            diags.append(error(f"missing function: {exc}", nid, "function", f))
        except ValueError as exc:
            diags.append(error(str(exc), nid, None, f))

    # Links: ends exist, ports exist, one link per input. Walked in the set's order with the
    # answer of a walk in sorted order: of two links into one input the smaller stays, and the
    # diagnostics are sorted by their link. Sorting every link cost more a link the larger the
    # graph (a tenth of the analysis of 10,000 nodes); nothing reads the order of an input's
    # links in `incoming`.
    incoming: dict[str, dict[str, Link]] = {nid: {} for nid in gnodes}
    edges: list[tuple[str, str]] = []  # (src, dst) of each link kept
    link_diags: list[tuple[Link, Diagnostic]] = []
    for link in graph.links:
        src, src_port, dst, dst_port = link
        if src not in gnodes or dst not in gnodes:
            missing = src if src not in gnodes else dst
            link_diags.append((link, error(f"link refers to missing node {missing!r}",
                                           dst if dst in gnodes else None, dst_port, f)))
            continue
        # NodePorts.output and .input, inlined (two lookups a link)
        src_ports = ports.get(src)
        if src_ports is not None and src_port not in src_ports._by_output:
            link_diags.append((link, error(f"node {src} has no output {src_port!r}", src,
                                           src_port, f)))
            continue
        dst_ports = ports.get(dst)
        if dst_ports is not None and dst_port not in dst_ports._by_input:
            link_diags.append((link, error(f"node {dst} has no input {dst_port!r}", dst,
                                           dst_port, f)))
            continue
        into = incoming[dst]
        other = into.get(dst_port)
        if other is not None:
            if link < other:  # the first in sorted order stays
                into[dst_port], link = link, other
            link_diags.append((link, error("input has more than one link", dst, dst_port, f)))
            continue
        into[dst_port] = link
        edges.append((src, dst))
    if link_diags:
        link_diags.sort(key=itemgetter(0))  # one diagnostic a link at most
        diags.extend(d for _, d in link_diags)
        # a link that stayed in place of another came after it: its edge, not the other's
        edges = [(l.src, l.dst) for into in incoming.values() for l in into.values()]

    # Cycles.
    order: list[str] = []
    try:
        order = stable_order(gnodes, edges)  # the same whatever the edges' order
    except CycleError:
        # the cycle named is the one networkx finds first: the edges in link order
        edges = [(l.src, l.dst) for l in sorted(l for into in incoming.values()
                                                for l in into.values())]
        cycle = _cycle(gnodes, edges)
        path = " -> ".join([a for a, _ in cycle] + [cycle[0][0]])
        diags.append(error(f"cycle: {path}", cycle[0][0], None, f))

    # Types, in evaluation order.
    in_types: dict[str, dict[str, PortType]] = {}
    out_types: dict[str, dict[str, PortType]] = {}
    for nid in order:
        if nid not in ports:
            continue
        p = ports[nid]
        node = gnodes[nid]
        into = incoming[nid]
        connected: dict[str, PortType] = {}
        blocked = False
        for port, link in into.items():
            src_types = out_types.get(link.src)
            t = src_types.get(link.src_port) if src_types is not None else None
            if t is None:
                blocked = True  # upstream already reported
                continue
            connected[port] = t
        kind = node.kind
        fixed, plan = TYPE_PLANS.get(kind) or type_plan(kind)
        try:  # resolve_types, its common cases inlined
            if fixed is not None:
                ins, outs = fixed
            elif plan is not None and plan[0] is p:
                ins, outs = generic_types(node, plan, connected)
            else:
                ins, outs = resolve_types(node, p, connected)
        except ValueError as exc:
            diags.append(error(str(exc), nid, None, f))
            continue
        in_types[nid], out_types[nid] = ins, outs
        wrong: list[tuple[Link, Diagnostic]] | None = None
        for port, t in connected.items():
            if t != ins[port]:  # an equal type always converts
                reason = conversion_reason(t, ins[port])
                if reason:
                    wrong = wrong or []
                    wrong.append((into[port], error(reason, nid, port, f)))
        if wrong:
            wrong.sort(key=itemgetter(0))  # in their links' order (`into` is in none)
            diags.extend(d for _, d in wrong)
        values = node.values
        d = registry[node.kind]
        for spec in p.inputs:
            name = spec.name
            if name in into:
                continue
            t = ins.get(name)
            if spec.required or (t is not None and not t.is_numeric):
                if blocked:
                    continue
                passes_on = d.role in _NO_DEFAULT
                fallback = None if passes_on or t is None else _UNCONNECTED_DEFAULT.get(t)
                if fallback is not None:  # the rest of the graph keeps compiling
                    diags.append(warning(f"input {name!r} ({t}) is not connected: it "
                                         f"uses {fallback}", nid, name, f))
                else:
                    diags.append(error(f"input {name!r} ({t}) must be connected",
                                       nid, name, f))
                continue
            if t is None:
                continue
            if name in values:
                try:
                    coerce_value(t, values[name])
                except ValueError as exc:
                    diags.append(error(str(exc), nid, name, f))
            elif t.is_numeric:  # a function file's default becomes a uniform
                why = _default_number_problem(spec.default)
                if why:
                    diags.append(error(f"the default of input {name!r}: {why}", nid,
                                       name, f))
        if d.values:
            for vf in d.values:
                if vf.name in values:
                    try:
                        coerce_value(PortType(vf.type), values[vf.name])
                    except ValueError as exc:
                        diags.append(error(str(exc), nid, vf.name, f))
        if d.role == nodes.Role.CONSTANT:
            try:
                coerce_value(outs["value"], node.settings.get("value", 0.0))
            except ValueError as exc:
                diags.append(error(str(exc), nid, "value", f))
        if d.values:
            for name in values:
                if p.input(name) is None and not any(v.name == name for v in d.values):
                    diags.append(warning(f"stored value for unknown field {name!r} is ignored",
                                         nid, name, f))

    diags.extend(_document_rules(doc, ports, f))
    if calls:
        diags.extend(_call_cycles(doc, resolver))
    return Analysis(ports, in_types, out_types, order, diags, incoming)


def _document_rules(doc: MaterialDocument, ports, f) -> list[Diagnostic]:
    diags = []
    R = nodes.Role
    registry = nodes.REGISTRY
    by_id = sorted(doc.graph.nodes.values(), key=attrgetter("id"))
    # each node's definition (None: an unknown kind), in id order
    defs = [(n, registry.get(n.kind)) for n in by_id]
    roles = [d.role for _, d in defs if d is not None]
    io_roles = (R.FUNCTION_INPUT, R.FUNCTION_OUTPUT)
    if doc.is_function:
        if R.FUNCTION_OUTPUT not in roles:
            diags.append(error("a material function needs at least one Function Output node",
                               file=f))
        if R.MATERIAL_OUTPUT in roles:
            diags.append(error("a material function cannot contain a Material Output node",
                               file=f))
        names: dict[tuple[str, str], str] = {}
        for n, d in defs:
            if d is not None and d.role in io_roles:
                key = (n.kind, str(n.settings.get("name", "")))
                if key in names:
                    diags.append(error(f"two {n.kind.replace('_', ' ')}s named {key[1]!r} "
                                       f"({names[key]} and {n.id})", n.id, "name", f))
                names[key] = n.id
                why = identifier_problem(n.settings.get("name", ""))
                if why:
                    diags.append(error(f"name {key[1]!r} {why}", n.id, "name", f))
                if d.role == R.FUNCTION_INPUT:
                    diags.extend(_check_input_default(n, f))
    else:
        outputs = roles.count(R.MATERIAL_OUTPUT)
        if outputs != 1:
            diags.append(error(f"a material needs exactly one Material Output node, "
                               f"found {outputs}", file=f))
        if R.FUNCTION_INPUT in roles or R.FUNCTION_OUTPUT in roles:
            for n in doc.graph.nodes.values():
                if nodes.role_of(n.kind) in io_roles:
                    diags.append(error("function inputs and outputs belong in material "
                                       "functions", n.id, None, f))
    params: dict[str, str] = {}
    for n, d in defs:
        if d is None:
            continue
        if d.role == R.TEXTURE_PARAMETER:
            tex = n.settings.get("path", "")
            if isinstance(tex, str) and tex:
                base = Path(doc.path).parent if doc.path else Path.cwd()
                try:
                    if "\0" in tex:
                        raise ValueError("the path holds a NUL character")
                    found = os.path.isfile(base / tex)
                    os.path.realpath(base / tex)
                    if len(os.fsencode(tex)) > 4095 or any(
                            len(part) > 255 for part in os.fsencode(tex).split(b"/")):
                        raise ValueError("the path is longer than the system allows")
                except (OSError, ValueError) as exc:
                    diags.append(error(f"texture path cannot be used: "
                                       f"{getattr(exc, 'strerror', None) or exc}",
                                       n.id, "path", f))
                    found = True
                if not found:
                    diags.append(warning(f"texture file {tex!r} not found; it shows as a checker",
                                         n.id, "path", f))
        if d.parameter is not None and d.role != R.STATIC_SWITCH:  # nodes.is_value_parameter
            name = str(n.settings.get("name", ""))
            why = identifier_problem(n.settings.get("name", ""))
            if why:
                diags.append(error(f"parameter name {name!r} {why}", n.id, "name", f))
            elif name in params:
                diags.append(error(f"parameter name {name!r} is used by {params[name]} too",
                                   n.id, "name", f))
            params[name] = n.id
    return diags


def _default_number_problem(default) -> str | None:
    """The float32 rule for the numbers of a port's default (a function file's input)."""
    values = default if isinstance(default, (list, tuple)) else [default]
    for x in values:
        if isinstance(x, (int, float)) and not isinstance(x, bool):
            why = gpu_number_problem(x)
            if why:
                return why
    return None


def _limit_warnings(node, ports: NodePorts, f) -> list[Diagnostic]:
    """A value beyond its port's hard bounds (Port.limits): a warning naming the node and the
    field; the material still compiles (the editor clamps what an artist types)."""
    out = []
    for name, value in sorted(node.values.items()):
        port = ports.input(name)
        problem = nodes.limit_problem(port, value) if port is not None else None
        if problem is not None:
            out.append(warning(problem[0], node.id, name, f))
    return out


def _check_input_default(n, f) -> list[Diagnostic]:
    """A function input's default must suit its type (the mesh UVs may default a vec2)."""
    t_name = str(n.settings.get("type", "float"))
    default = n.settings.get("default")
    try:
        t = PortType(t_name)
    except ValueError:
        return []  # reported with the ports
    if default is None or not t.is_numeric:
        return []
    if default == nodes.MESH_UV:
        if t == PortType.VEC2:
            return []
        return [error(f"only a vec2 input can default to {nodes.MESH_UV!r}", n.id, "default", f)]
    try:
        coerce_value(t, default)
    except ValueError as exc:
        return [error(f"default does not suit type {t}: {exc}", n.id, "default", f)]
    return []


def function_refs(doc: MaterialDocument) -> list[tuple[str, str]]:
    """(node id, function file) for every function a document uses directly."""
    refs = []
    registry = nodes.REGISTRY
    calling = (nodes.Role.FUNCTION_CALL, nodes.Role.LAYER_STACK)
    users = [n for n in doc.graph.nodes.values()
             if (d := registry.get(n.kind)) is not None and d.role in calling]
    for n in sorted(users, key=attrgetter("id")):
        role = nodes.role_of(n.kind)
        if role == nodes.Role.FUNCTION_CALL and isinstance(n.settings.get("function"), str):
            refs.append((n.id, n.settings["function"]))
        elif role == nodes.Role.LAYER_STACK:
            for e in layer_entries(n):
                if isinstance(e, dict):
                    for key in ("function", "blend"):
                        ref = e.get(key)
                        if isinstance(ref, str) and ref.endswith(".json"):
                            refs.append((n.id, ref))
    return refs


def _doc_key(doc: MaterialDocument) -> str:
    return os.path.realpath(doc.path) if doc.path else f"<unsaved {id(doc)}>"


def _call_cycles(doc: MaterialDocument, resolver: FunctionResolver | None) -> list[Diagnostic]:
    """Recursion through function calls, across files (a call graph of documents)."""
    if resolver is None:
        return []
    calls: dict[str, set[str]] = {}  # caller key -> callee keys
    first_hop: dict[str, str] = {}  # callee key -> calling node id in `doc`
    stack = [doc]
    seen = set()
    while stack:
        d = stack.pop()
        k = _doc_key(d)
        if k in seen:
            continue
        seen.add(k)
        calls.setdefault(k, set())
        for nid, ref in function_refs(d):
            try:
                callee = resolver.resolve(ref, d)
            except (LookupError, ValueError):
                continue  # reported where the ports are resolved
            ck = _doc_key(callee)
            calls[k].add(ck)
            if d is doc:
                first_hop.setdefault(ck, nid)
            stack.append(callee)
    edges = [(a, b) for a, callees in calls.items() for b in callees]
    try:
        order = stable_order(calls, edges)
    except CycleError:
        cycle = _cycle(calls, edges, source=_doc_key(doc))
    else:
        hops: dict[str, int] = {}  # the longest chain of calls ending at each document
        for k in order:
            hops.setdefault(k, 0)
            for callee_key in calls.get(k, ()):
                hops[callee_key] = max(hops.get(callee_key, 0), hops[k] + 1)
        depth = max(hops.values(), default=0)
        if depth > MAX_CALL_DEPTH:
            return [error(f"material functions nest {depth} calls deep; at most "
                          f"{MAX_CALL_DEPTH} levels are allowed", next(iter(first_hop.values()),
                                                                       None), "function",
                          _file(doc))]
        return []
    names = [Path(a).name for a, _ in cycle] + [Path(cycle[0][0]).name]
    node = first_hop.get(cycle[0][1]) if cycle[0][0] == _doc_key(doc) else None
    if node is None:
        node = next(iter(first_hop.values()), None)
    return [error(f"recursive function calls: {' -> '.join(names)}", node, "function",
                  _file(doc))]


def validate(doc: MaterialDocument, resolver: FunctionResolver | None = None) -> list[Diagnostic]:
    return analyse(doc, resolver).diagnostics


def type_error_keys(doc: MaterialDocument, resolver: FunctionResolver | None = None) -> set:
    """The document's present type errors, as `check_connect` compares them: compute it once
    and pass it as `baseline` when checking many candidate links into the same document."""
    return {(d.node_id, d.port, d.message) for d in _type_errors(doc, resolver)}


def check_connect(
    doc: MaterialDocument, link: Link, resolver: FunctionResolver | None = None,
    baseline: set | None = None,
) -> str | None:
    """None if `link` may be made now, else the reason it is refused (type or cycle).

    A link is refused for type errors it would add; `baseline` (from `type_error_keys` of
    the same document) spares re-analysing the document itself for every candidate."""
    g = doc.graph
    for end in (link.src, link.dst):
        if end not in g.nodes:
            return f"no node {end!r}"
    if link.src == link.dst:
        return "a node cannot feed itself"
    try:
        src_ports = node_ports(g.nodes[link.src], resolver, doc)
        dst_ports = node_ports(g.nodes[link.dst], resolver, doc)
    except (PortError, LookupError, ValueError) as exc:
        return str(exc)
    if src_ports.output(link.src_port) is None:
        return f"{link.src} has no output {link.src_port!r}"
    if dst_ports.input(link.dst_port) is None:
        return f"{link.dst} has no input {link.dst_port!r}"
    import networkx as nx

    dep = dependency_graph(doc)
    if nx.has_path(dep, link.dst, link.src):
        return f"connecting {link.src} to {link.dst} would close a cycle"
    # Types: analyse the graph as it would be with the link.
    trial = MaterialDocument(doc.kind, g.copy(), doc.name, doc.description, doc.path)
    old = trial.graph.incoming(link.dst, link.dst_port)
    if old is not None:
        trial.graph.links.discard(old)
    trial.graph.links.add(link)
    before = baseline if baseline is not None else type_error_keys(doc, resolver)
    for d in _type_errors(trial, resolver):
        if (d.node_id, d.port, d.message) not in before:
            return d.message
    return None


def _type_errors(doc, resolver) -> list[Diagnostic]:
    a = analyse(doc, resolver)
    return [d for d in a.diagnostics if d.severity == Severity.ERROR and "must be connected"
            not in d.message]
