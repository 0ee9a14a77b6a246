"""The graph -> GLSL step does work linear in the graph's size: Python function calls are
counted (sys.setprofile) at two sizes, never timed (the time is benchmarks/bench_compile.py's
`compile_ms`). A pass that revisits the graph once per node multiplies its calls by the size
ratio squared, and fails here whatever machine runs it."""

from __future__ import annotations

import sys
from collections import Counter

from matedit.compiler import compile_document
from matedit.graph.model import DocumentKind, Link, MaterialDocument, Node

_KINDS = ("add", "multiply", "lerp", "sin", "max", "subtract")
_PORTS = {"add": ("a", "b"), "multiply": ("a", "b"), "subtract": ("a", "b"),
          "max": ("a", "b"), "lerp": ("a", "b", "alpha"), "sin": ("value",)}


def _material(n: int) -> MaterialDocument:
    """About `n` maths nodes on the UVs, each fed by the one before it (so every node reaches
    the output) and by one further back or a stored value (a uniform)."""
    doc = MaterialDocument(kind=DocumentKind.MATERIAL)
    g = doc.graph
    g.nodes["uv"] = Node("uv", "texcoord")
    g.nodes["split"] = Node("split", "split")
    g.links.add(Link("uv", "uv", "split", "value"))
    floats = [("split", "x"), ("split", "y")]
    for i in range(n):
        kind = _KINDS[i % len(_KINDS)]
        nid = f"n{i}"
        g.nodes[nid] = Node(nid, kind)
        for k, port in enumerate(_PORTS[kind]):
            if k == 0:
                src = floats[-1]
            elif (i + k) % 3:
                src = floats[max(0, len(floats) - 1 - (i * 7 + k) % 9)]
            else:
                g.nodes[nid].values[port] = 0.25 + (i % 5) * 0.1
                continue
            g.links.add(Link(src[0], src[1], nid, port))
        floats.append((nid, "result"))
    g.nodes["make"] = Node("make", "make_attributes")
    g.nodes["out"] = Node("out", "material_output")
    g.links.add(Link(*floats[-1], "make", "roughness"))
    g.links.add(Link("make", "attributes", "out", "attributes"))
    return doc


def _calls(doc: MaterialDocument) -> Counter:
    """Python function calls of one compile, by (file, line, function)."""
    compile_document(doc)  # warm: library files read, per-kind tables built
    counts: Counter = Counter()

    def profile(frame, event, arg):
        if event == "call":
            code = frame.f_code
            counts[(code.co_filename, code.co_firstlineno, code.co_name)] += 1

    sys.setprofile(profile)
    try:
        compile_document(doc)
    finally:
        sys.setprofile(None)
    return counts


def test_compile_calls_grow_linearly_with_the_graph():
    small, large = _material(100), _material(1000)
    ratio = len(large.graph.nodes) / len(small.graph.nodes)  # about 10
    a, b = _calls(small), _calls(large)
    # linear: the calls grow by the node ratio (plus a fixed part that does not grow); a
    # quadratic pass would grow by ratio squared (about 100)
    assert sum(b.values()) <= 1.2 * ratio * sum(a.values())
    # and no single function grows faster than the graph (slack for a fixed few calls)
    worst = {k: (a.get(k, 0), n) for k, n in b.items() if n > 1.2 * ratio * a.get(k, 0) + 20}
    assert not worst, worst


def test_compile_calls_per_node_stay_low():
    # Python function calls a node of a 1,000-node compile, the fixed part included: 39.6
    # before issue 29's second pass (per-kind plans in analyse, fused operand and output
    # walks, the common GLSL line written inline), 17.9 after it; a change that brings back
    # per-node calls (a helper per operand, a per-node lookup through a function) fails here
    # before a benchmark sees it
    doc = _material(1000)
    per_node = sum(_calls(doc).values()) / len(doc.graph.nodes)
    assert per_node <= 20, per_node


def test_one_validation_and_one_order_per_compile():
    counts = _calls(_material(300))
    by_name = Counter()
    for (_, _, name), n in counts.items():
        by_name[name] += n
    assert by_name["analyse"] == 1  # the compiler validates the document once
    # the node order, and the call graph's (a document with no functions: one vertex)
    assert by_name["stable_order"] == 2


def test_a_compile_leaves_no_young_collection_pending():
    # The compile pauses the cyclic collector; what it allocated and kept (the IR, the
    # sources) then goes to the oldest generation, so the allocations after the pause do not
    # start a young-generation pass over all of it (about 12 ms at 10,000 nodes). Counted,
    # never timed: no collection runs inside the compile, gen 0's allocation count after it
    # stays below the threshold, and the collector is on again.
    import gc

    doc = _material(1500)
    compile_document(doc)
    passes: list[int] = []

    def seen(phase, info):
        if phase == "start":
            passes.append(info["generation"])

    gc.callbacks.append(seen)
    try:
        cm = compile_document(doc)
        after = gc.get_count()[0]
    finally:
        gc.callbacks.remove(seen)
    assert gc.isenabled()
    assert len(cm.ir.main.ops) > 1500  # the compile's survivors, held
    assert passes == []
    assert after < gc.get_threshold()[0]
