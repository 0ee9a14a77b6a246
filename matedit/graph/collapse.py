"""Collapse a selection into a material function, and expand a function call back inline.

Collapse: the selected nodes move into a new function document. Every wire cut on the way
in becomes a Function Input (one per outside output that feeds the selection, typed as that
output), every wire cut on the way out a Function Output (one per selected output read
outside, typed as that output), and a Function Call replaces the selection, wired where the
selection was. Parameters, outputs and function inputs/outputs stay in the material (a
parameter is what an artist or an instance sets, so it feeds the function from outside).

Expand: a Function Call's nodes are copied into the graph under fresh ids; what fed the
call's inputs feeds the nodes its Function Inputs fed (an unwired input gives those nodes
the call's value, or the input's default), and what read the call's outputs reads what fed
its Function Outputs. File references inside the function are the caller's to rebase
for the material's folder first (matedit.io.document.rebase_references).

Both build plain commands (one undo step through `Macro`); nothing here reads or writes a
file.
"""

from __future__ import annotations

import copy

from matedit.graph.commands import AddNode, Command, Connect, RemoveNode, SetValue
from matedit.graph.model import DocumentKind, Link, MaterialDocument, Node
from matedit.graph.nodes import Role, is_value_parameter, kind_for, role_of
from matedit.graph.validate import Analysis

# What a collapse leaves in the material: what artists set or what ends the graph.
STAYS = frozenset({Role.SCALAR_PARAMETER, Role.VECTOR_PARAMETER, Role.COLOR_PARAMETER,
                   Role.TEXTURE_PARAMETER, Role.STATIC_SWITCH, Role.MATERIAL_OUTPUT,
                   Role.FUNCTION_INPUT, Role.FUNCTION_OUTPUT})
FUNCTION_TYPES = frozenset({"float", "vec2", "vec3", "vec4", "MaterialAttributes",
                            "texture2d"})


class CollapseError(ValueError):
    """A selection that cannot become a function, with the reason shown to the artist."""


def collapsible(doc: MaterialDocument, node_ids: list[str]) -> list[str]:
    """The selected nodes a collapse moves (sorted): not parameters, switches or outputs."""
    return sorted(nid for nid in node_ids if nid in doc.graph.nodes
                  and role_of(doc.graph.nodes[nid].kind) not in STAYS)


def between(doc: MaterialDocument, node_ids) -> list[str]:
    """Nodes outside `node_ids` on a path from one of them to another (sorted): a collapse
    would wire the call into itself through them, so it refuses while there are any."""
    inside = set(node_ids)
    downstream: dict[str, set[str]] = {}
    upstream: dict[str, set[str]] = {}
    for lk in doc.graph.links:
        downstream.setdefault(lk.src, set()).add(lk.dst)
        upstream.setdefault(lk.dst, set()).add(lk.src)

    def reach(start: set[str], edges: dict[str, set[str]]) -> set[str]:
        seen: set[str] = set()
        todo = list(start)
        while todo:
            for b in edges.get(todo.pop(), ()):
                if b not in seen:
                    seen.add(b)
                    todo.append(b)
        return seen

    return sorted((reach(inside, downstream) & reach(inside, upstream)) - inside)


def _between_error(nodes: list[str]) -> CollapseError:
    shown = ", ".join(nodes[:4]) + (f" and {len(nodes) - 4} more" if len(nodes) > 4 else "")
    return CollapseError(f"{shown} {'sits' if len(nodes) == 1 else 'sit'} between selected "
                         "nodes (a wire leaves the selection and comes back through "
                         f"{'it' if len(nodes) == 1 else 'them'}): select "
                         f"{'it' if len(nodes) == 1 else 'them'} too, or fewer nodes")


def check_collapsible(doc: MaterialDocument, node_ids) -> None:
    """Raises CollapseError naming what stands in the way of collapsing `node_ids`."""
    inside = collapsible(doc, list(node_ids))
    if not inside:
        raise CollapseError("nothing to collapse: select nodes other than parameters and "
                            "outputs")
    stuck = between(doc, inside)
    if stuck:
        raise _between_error(stuck)


def _unique(name: str, taken: set[str]) -> str:
    out, i = name, 2
    while out in taken:
        out, i = f"{name}_{i}", i + 1
    taken.add(out)
    return out


def collapse(doc: MaterialDocument, analysis: Analysis, node_ids: list[str], function_ref: str,
             name: str) -> tuple[MaterialDocument, list[Command], str]:
    """(the function document, the material's commands, the call's id). `function_ref` is
    how the material will refer to the function's file; `analysis` is the material's (for
    the concrete types of the cut wires)."""
    check_collapsible(doc, node_ids)
    inside = set(collapsible(doc, node_ids))
    g = doc.graph
    fn = MaterialDocument(kind=DocumentKind.FUNCTION, name=name)
    for nid in sorted(inside):
        fn.graph.nodes[nid] = g.nodes[nid].clone()
    cut_in = sorted(l for l in g.links if l.dst in inside and l.src not in inside)
    cut_out = sorted(l for l in g.links if l.src in inside and l.dst not in inside)
    for l in g.links:
        if l.src in inside and l.dst in inside:
            fn.graph.links.add(l)
    xs = [g.nodes[n].position[0] for n in inside]
    ys = [g.nodes[n].position[1] for n in inside]
    left, right, top = min(xs) - 260.0, max(xs) + 260.0, min(ys)
    names: set[str] = set()
    ids = set(inside)
    inputs: dict[tuple[str, str], str] = {}  # outside (node, port) -> function input name
    input_node: dict[str, str] = {}  # function input name -> its node's id
    for l in cut_in:
        key = (l.src, l.src_port)
        if key not in inputs:
            t = str(analysis.out_types[l.src][l.src_port].value)
            if t not in FUNCTION_TYPES:
                raise CollapseError(f"the wire into {l.dst}.{l.dst_port} carries {t}, which "
                                    "a function input cannot take")
            src = g.nodes[l.src]  # a parameter names its input; anything else, the port it fed
            given = src.settings.get("name") if is_value_parameter(src.kind) else None
            port_name = _unique(given if isinstance(given, str) and given else l.dst_port,
                                names)
            inputs[key] = port_name
            nid = input_node[port_name] = _unique(f"in_{port_name}", ids)
            settings: dict = {"name": port_name, "type": t, "order": len(inputs) - 1}
            if t == "float":
                settings["default"] = 0.0
            elif t.startswith("vec"):
                settings["default"] = [0.0] * int(t[-1])
            fn.graph.nodes[nid] = Node(nid, kind_for(Role.FUNCTION_INPUT),
                                       (left, top + 110.0 * (len(inputs) - 1)), settings)
        fn.graph.links.add(Link(input_node[inputs[key]], "value", l.dst, l.dst_port))
    outputs: dict[tuple[str, str], str] = {}  # inside (node, port) -> function output name
    out_names: set[str] = set()
    for l in cut_out:
        key = (l.src, l.src_port)
        if key in outputs:
            continue
        t = str(analysis.out_types[l.src][l.src_port].value)
        if t not in FUNCTION_TYPES - {"texture2d"}:
            raise CollapseError(f"{l.src}.{l.src_port} carries {t}, which a function output "
                                "cannot give")
        port_name = _unique(l.src_port, out_names)
        outputs[key] = port_name
        nid = _unique(f"out_{port_name}", ids)
        fn.graph.nodes[nid] = Node(nid, kind_for(Role.FUNCTION_OUTPUT),
                                   (right, top + 110.0 * (len(outputs) - 1)),
                                   {"name": port_name, "type": t, "order": len(outputs) - 1})
        fn.graph.links.add(Link(l.src, l.src_port, nid, "value"))

    call = g.new_id("call")
    centre = (sum(xs) / len(xs), sum(ys) / len(ys))
    commands: list[Command] = [RemoveNode(nid) for nid in sorted(inside)]
    commands.append(AddNode(Node(call, kind_for(Role.FUNCTION_CALL), centre,
                                 {"function": function_ref})))
    wired: set[Link] = set()
    for (src_id, port), port_name in inputs.items():
        wired.add(Link(src_id, port, call, port_name))
    for l in cut_out:
        wired.add(Link(call, outputs[(l.src, l.src_port)], l.dst, l.dst_port))
    commands += [Connect(l) for l in sorted(wired)]
    return fn, commands, call


def expand(doc: MaterialDocument, call_id: str,
           function: MaterialDocument) -> tuple[list[Command], list[str]]:
    """(commands that put `function`'s nodes in place of the call `call_id`, the new ids).
    The nodes' file references are copied as `function` holds them."""
    g = doc.graph
    call = g.nodes.get(call_id)
    if call is None or role_of(call.kind) != Role.FUNCTION_CALL:
        raise CollapseError(f"{call_id} is not a function call")
    fg = function.graph
    ends = {nid for nid, n in fg.nodes.items()
            if role_of(n.kind) in (Role.FUNCTION_INPUT, Role.FUNCTION_OUTPUT)}
    taken = set(g.nodes) | set(g.comments)
    rename: dict[str, str] = {}
    for nid in sorted(set(fg.nodes) - ends):
        rename[nid] = _unique(f"{call_id}_{nid}" if len(call_id) + len(nid) < 60 else nid,
                              taken)
    cx, cy = call.position
    xs = [fg.nodes[n].position[0] for n in rename] or [0.0]
    ys = [fg.nodes[n].position[1] for n in rename] or [0.0]
    ox, oy = cx - (min(xs) + max(xs)) / 2, cy - (min(ys) + max(ys)) / 2
    commands: list[Command] = [RemoveNode(call_id)]
    for nid, new in rename.items():
        n = copy.deepcopy(fg.nodes[nid])
        n.id, n.position = new, (n.position[0] + ox, n.position[1] + oy)
        commands.append(AddNode(n))
    into = {l.dst_port: l for l in g.links if l.dst == call_id}
    read = [l for l in g.links if l.src == call_id]
    links: set[Link] = set()
    values: list[SetValue] = []
    for l in fg.links:
        if l.src in rename and l.dst in rename:
            links.add(Link(rename[l.src], l.src_port, rename[l.dst], l.dst_port))
    for nid in sorted(ends):
        n = fg.nodes[nid]
        pname = str(n.settings.get("name", ""))
        if role_of(n.kind) == Role.FUNCTION_INPUT:
            feeds = [l for l in fg.links if l.src == nid and l.dst in rename]
            outside = into.get(pname)
            for l in feeds:
                if outside is not None:
                    links.add(Link(outside.src, outside.src_port, rename[l.dst], l.dst_port))
                else:
                    value = call.values.get(pname, n.settings.get("default"))
                    if value is not None:
                        values.append(SetValue(rename[l.dst], l.dst_port, value))
        else:
            fed = next((l for l in fg.links if l.dst == nid), None)
            if fed is None or fed.src not in rename:
                continue
            for r in read:
                if r.src_port == pname:
                    links.add(Link(rename[fed.src], fed.src_port, r.dst, r.dst_port))
    commands += [Connect(l) for l in sorted(links)]
    commands += values
    return commands, sorted(rename.values())
