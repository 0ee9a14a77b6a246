"""`matedit stats --measure`: what a node costs on this GL, timed.

The material is rendered offscreen (matedit.render, EGL) at SIZE x SIZE; then, for each layer
and for the 10 nodes with the most counted instructions, a variant whose subtree is replaced
by a constant of its mean value is rendered the same way. The frames are timed with
`glFinish` after each; the variants are timed in rounds (every variant once per round, the
full material first), so that drift of a shared machine falls on all of them alike. A
variant's cost in one round is the full frame's time minus the variant's; the report gives
the median and interquartile range over the rounds, clamped at 0 (a subtree cannot make the
frame faster; a negative difference is noise, and is said to be clamped).

The mean value of a node's output is its average over the visible pixels of the preview
sphere, evaluated by the CPU twin of the graph (`matedit.compiler.cpu_eval`). A layer is
replaced by leaving it out of the stack (hidden, as the layer panel's eye does); the base
layer, which cannot be hidden, by the default MaterialAttributes.
"""

from __future__ import annotations

import copy
import os
import time
from typing import Any

import numpy as np

TOP_NODES = 10
PROBE_SIZE = 48


FRAMES_PER_RUN = 3  # frames a program draws in each round; the fastest is its time


def mean_values(doc, resolver) -> dict[str, Any]:
    """'node.port' -> the mean of that top-level output over the visible preview sphere."""
    from matedit.compiler.cpu_eval import evaluate
    from matedit.compiler.lower import lower_document
    from matedit.nodes.twin import sphere_surface

    surface, inside = sphere_surface(PROBE_SIZE)
    ir = lower_document(doc, resolver)
    probe: dict[str, Any] = {}
    with np.errstate(all="ignore"):
        evaluate(ir, surface, probe=probe)
    out: dict[str, Any] = {}
    for key, v in probe.items():
        if isinstance(v, dict):
            continue  # MaterialAttributes: not a constant node's type
        a = np.asarray(v, dtype=np.float64)
        if a.ndim == 0:
            out[key] = float(a)
            continue
        if a.shape[0] != inside.shape[0] or a.ndim > 2:
            continue
        m = np.nanmean(a[inside], axis=0)
        out[key] = float(m) if m.ndim == 0 else [float(x) for x in m]
    return out


_TYPES = {1: "float", 2: "vec2", 3: "vec3", 4: "vec4"}


def replaced_by_constant(doc, node_id: str, means: dict[str, Any]):
    """A copy of `doc` whose links out of `node_id` come from constant nodes of each output's
    mean instead; None when an output it feeds has no mean (a material or a texture)."""
    d = copy.deepcopy(doc)
    from matedit.graph.model import Link, Node
    from matedit.nodes.kind import Role, kind_for

    outs = sorted({lk.src_port for lk in d.graph.links if lk.src == node_id})
    if not outs:
        return None
    for port in outs:
        value = means.get(f"{node_id}.{port}")
        if value is None:
            return None
        cid = f"__mean_{node_id}_{port}"
        comps = 1 if isinstance(value, float) else len(value)
        if comps not in _TYPES:
            return None
        d.graph.nodes[cid] = Node(cid, kind_for(Role.CONSTANT), (0.0, 0.0),
                                  {"type": _TYPES[comps], "value": value}, {})
        for lk in list(d.graph.links):
            if (lk.src, lk.src_port) == (node_id, port):
                d.graph.links.discard(lk)
                d.graph.links.add(Link(cid, "value", lk.dst, lk.dst_port))
    return d


def layer_removed(doc, stack: str, layer_id: str):
    """A copy of `doc` without the layer (hidden), or with the base layer's function replaced
    by the default attributes (its entry pointed at no function is not allowed, so the
    layer stack is cut off at the material output instead: None then)."""
    d = copy.deepcopy(doc)
    node = d.graph.nodes[stack]
    entries = node.settings.get("layers") or []
    if not entries or entries[0].get("id") == layer_id:
        return None
    for e in entries:
        if e.get("id") == layer_id:
            e["visible"] = False
    return d


def _counted_differences(full: int, variants, resolver) -> list[int]:
    """glsl450 instructions of the full material minus each variant's (the counted cost of
    what the variant takes out, to compare with the measured one)."""
    import tempfile
    from pathlib import Path

    from matedit.compiler import compile_document, cost, trips
    from matedit.interop.stats import spirv_text, uniform_values

    out = []
    with tempfile.TemporaryDirectory(prefix="matedit-measure-") as tmp:
        for _, _, d in variants:
            cm = compile_document(d, resolver, "glsl450")
            m = cost.parse(spirv_text(cm.fragment_text, "glsl450", False, Path(tmp)))
            w = trips.weights(m.body, m.globals, uniform_values(cm, d)).weights
            out.append(full - cost.count(m, w).figures.instructions)
    return out


def rank_correlation(a: list[float], b: list[float]) -> float | None:
    """Spearman's rank correlation (ties take their mean rank); None under 3 pairs or when
    either side is constant."""
    if len(a) < 3:
        return None

    def ranks(xs: list[float]) -> np.ndarray:
        x = np.asarray(xs, dtype=np.float64)
        order = np.argsort(x, kind="mergesort")
        r = np.empty(len(x))
        r[order] = np.arange(len(x), dtype=np.float64)
        for v in np.unique(x):  # ties: the mean of their ranks
            r[x == v] = r[x == v].mean()
        return r

    ra, rb = ranks(a), ranks(b)
    if ra.std() == 0 or rb.std() == 0:
        return None
    return float(np.corrcoef(ra, rb)[0, 1])


def _stats(xs: list[float]) -> dict[str, float]:
    a = np.asarray(xs, dtype=np.float64)
    q1, med, q3 = np.percentile(a, [25, 50, 75])
    return {"median": float(med), "iqr": float(q3 - q1), "q1": float(q1), "q3": float(q3)}


def measure_costs(doc, resolver, per_target: dict, size: int = 256, runs: int = 9,
                  top: int = TOP_NODES, only: list[str] | None = None) -> dict[str, Any]:
    """The timed report (see the module's docstring); `only`: time just these nodes' subtrees
    (no layers) instead of the layers and the `top` costliest nodes."""
    os.environ["MESA_SHADER_CACHE_DISABLE"] = "true"  # every variant compiled afresh
    from matedit.compiler import compile_document
    from matedit.render import Renderer
    from matedit.render.context import headless_context

    counted = per_target.get("glsl450") or next(iter(per_target.values()))
    means = mean_values(doc, resolver)
    variants: list[tuple[str, str, Any]] = []
    for layer in counted["layers"] if only is None else []:
        d = layer_removed(doc, layer["stack"], layer["id"])
        if d is not None:
            variants.append(("layer", layer["id"], d))
    from matedit.nodes.kind import Role, role_of

    skip = {Role.MAKE_ATTRIBUTES, Role.MATERIAL_OUTPUT, Role.LAYER_STACK}
    chosen = [r for r in counted["nodes"] if r["instructions"] > 0 and
              role_of(r["kind"]) not in skip][:top] if only is None else \
        [r for r in counted["nodes"] if r["id"] in only]
    for row in chosen:
        d = replaced_by_constant(doc, row["id"], means)
        if d is not None:
            variants.append(("node", row["id"], d))
    programs = [("full", "", compile_document(doc, resolver, "glsl330"))]
    for what, ident, d in variants:
        programs.append((what, ident, compile_document(d, resolver, "glsl330")))
    counted_diff = _counted_differences(counted["instructions"], variants, resolver)
    ctx = headless_context()
    try:
        renderer = Renderer(ctx, (size, size), samples=1, environment=None)
        renderer.set_environment("studio")
        times: list[list[float]] = [[] for _ in programs]
        for k, (_, _, cm) in enumerate(programs):  # link and warm each program
            if not renderer.set_material(cm).ok:
                raise RuntimeError(f"variant {programs[k][0]} {programs[k][1]} did not link")
            for _ in range(2):
                renderer.render()
            ctx.finish()
        for _ in range(runs):
            for k, (_, _, cm) in enumerate(programs):
                renderer.set_material(cm)  # linked once above: a switch of program
                ctx.finish()
                best = float("inf")
                for _ in range(FRAMES_PER_RUN):  # the fastest: a frame the OS interrupted
                    t0 = time.perf_counter()  # is not the shader's cost
                    renderer.render()
                    ctx.finish()
                    best = min(best, (time.perf_counter() - t0) * 1000.0)
                times[k].append(best)
        renderer.release()
        info = ctx.info.get("GL_RENDERER", "unknown")
    finally:
        ctx.release()
    full = times[0]
    rows = []
    for k, (what, ident, _) in enumerate(programs[1:], start=1):
        diffs = [f - v for f, v in zip(full, times[k])]
        st = _stats(diffs)
        clamped = st["median"] < 0
        q1, med, q3 = (max(0.0, st[k]) for k in ("q1", "median", "q3"))
        rows.append({"what": what, "id": ident, "counted_instructions": counted_diff[k - 1],
                     "cost_ms": {"median": med, "q1": q1, "q3": q3, "iqr": q3 - q1},
                     "clamped": bool(clamped or st["q1"] < 0),
                     "runs_ms": [round(x, 4) for x in diffs]})
    rows.sort(key=lambda r: -r["cost_ms"]["median"])
    return {"size": size, "runs": runs, "renderer": str(info), "frame_ms": _stats(full),
            "rows": rows,
            "rank_correlation": rank_correlation([r["counted_instructions"] for r in rows],
                                                 [r["cost_ms"]["median"] for r in rows]),
            "method": f"median and IQR over rounds of (full frame - variant frame), a "
                      f"program's frame in a round the fastest of {FRAMES_PER_RUN}; each "
                      f"figure clamped at 0"}
