"""Helpers shared by the benchmarks: timing with medians, synthetic graphs, machine facts."""

from __future__ import annotations

import os
import platform
import statistics
import time

import numpy as np

from matedit.graph.model import DocumentKind, Link, MaterialDocument, Node


def median_time(fn, repeat: int = 5, warmup: int = 1) -> float:
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def synthetic_material(n: int, seed: int = 1) -> MaterialDocument:
    """A material of about `n` nodes: a random DAG of maths on UVs, noise and parameters,
    every node reaching the output (so nothing is removed as dead code)."""
    rng = np.random.default_rng(seed)
    doc = MaterialDocument(kind=DocumentKind.MATERIAL)
    g = doc.graph
    g.nodes["uv"] = Node("uv", "texcoord")
    g.nodes["p0"] = Node("p0", "scalar_parameter", settings={"name": "p0"}, values={"value": 0.5})
    g.nodes["split"] = Node("split", "split")
    g.links.add(Link("uv", "uv", "split", "value"))
    floats = [("p0", "value"), ("split", "x"), ("split", "y")]
    kinds = ["add", "multiply", "subtract", "lerp", "sin", "cos", "max", "min", "smoothstep"]
    for i in range(max(1, n - 6)):
        kind = kinds[int(rng.integers(len(kinds)))]
        nid = f"n{i}"
        g.nodes[nid] = Node(nid, kind, (float(i % 50) * 200, float(i // 50) * 120))
        ports = {"add": ["a", "b"], "multiply": ["a", "b"], "subtract": ["a", "b"],
                 "lerp": ["a", "b", "alpha"], "sin": ["value"], "cos": ["value"],
                 "max": ["a", "b"], "min": ["a", "b"], "smoothstep": ["edge0", "edge1", "value"]}
        for port in ports[kind]:
            if rng.random() < 0.8:
                # mostly recent values, so the graph is deep as well as wide
                j = len(floats) - 1 - int(min(rng.exponential(8), len(floats) - 1))
                src = floats[j]
                g.links.add(Link(src[0], src[1], nid, port))
            else:
                g.nodes[nid].values[port] = float(rng.random())
        floats.append((nid, "result"))
    # sum everything that is not yet used so no node is dead
    used = {(l.src, l.src_port) for l in g.links}
    tails = [f for f in floats if f not in used]
    acc = tails[0]
    for k, t in enumerate(tails[1:]):
        nid = f"sum{k}"
        g.nodes[nid] = Node(nid, "add")
        g.links.add(Link(acc[0], acc[1], nid, "a"))
        g.links.add(Link(t[0], t[1], nid, "b"))
        acc = (nid, "result")
    g.nodes["make"] = Node("make", "make_attributes")
    g.nodes["out"] = Node("out", "material_output")
    g.links.add(Link(acc[0], acc[1], "make", "roughness"))
    g.links.add(Link("make", "attributes", "out", "attributes"))
    return doc


def machine(ctx=None) -> str:
    """Cores, Python and GL renderer. Pass the benchmark's context if it has one: creating
    and releasing a second context would leave the first one not current."""
    renderer = "?"
    try:
        if ctx is None:
            import moderngl

            tmp = moderngl.create_standalone_context(backend="egl")
            renderer = tmp.info["GL_RENDERER"]
            tmp.release()
        else:
            renderer = ctx.info["GL_RENDERER"]
    except Exception:
        pass
    return f"{platform.node()}: {os.cpu_count()} cores, {platform.python_version()}, GL {renderer}"
