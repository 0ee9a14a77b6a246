"""Every library kind through the whole compiler: a material made of the node alone (its
inputs left to their defaults, so they become uniforms or mesh UVs), lowered, optimised,
emitted and drawn on the GPU, equals the CPU evaluator of the same document over the same
surface (a pixel grid, so filtered kinds see the same footprint). Criteria as the samples'
(tests/test_compiler_gpu.py): 99.5th percentile of |gpu - cpu| below 2e-3, median below
2e-4."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import link, material, node
from material_gpu import render_attributes, surface

from matedit.compiler import compile_document
from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.graph.nodes import GENERIC, REGISTRY
from matedit.io.document import FileResolver
from tests.library_kinds import LIBRARY_KINDS

TOL = 2e-3
KINDS = sorted(k for k in LIBRARY_KINDS
               if not any(i.type == "texture2d" for i in REGISTRY[k].inputs))


def _single(kind: str):
    d = REGISTRY[kind]
    doc = material()
    node(doc, "k", kind)
    node(doc, "make", "make_attributes")
    node(doc, "out", "material_output")
    link(doc, "make", "attributes", "out", "attributes")
    for o in d.outputs:  # the first output of each width that the attributes can carry
        t = "vec3" if o.type == GENERIC else o.type
        if t == "vec3":
            link(doc, "k", o.name, "make", "baseColor")
            break
        if t in ("float", "vec2", "vec4"):
            if t != "float":
                node(doc, "m", "component_mask", {"channels": "x"})
                link(doc, "k", o.name, "m", "value")
                link(doc, "m", "result", "make", "metallic")
            else:
                link(doc, "k", o.name, "make", "metallic")
            break
    if any(i.type == GENERIC for i in d.inputs):  # resolve T to vec3 by connecting one
        first = next(i for i in d.inputs if i.type == GENERIC)
        node(doc, "c", "constant", {"type": "vec3", "value": [0.3, 0.6, 0.9]})
        link(doc, "c", "value", "k", first.name)
    return doc


@pytest.mark.gl
@pytest.mark.parametrize("kind", KINDS)
def test_single_node_material_matches_cpu(ctx, kind):
    doc = _single(kind)
    resolver = FileResolver()
    cm = compile_document(doc, resolver, "glsl330", mode="attributes")
    gpu = render_attributes(ctx, cm, 64, 64)
    cpu = evaluate(lower_document(doc, resolver), surface(64, 64))
    for field in ("baseColor", "metallic"):
        g = gpu[field]
        c = np.asarray(cpu[field], dtype=np.float64).reshape(g.shape)
        assert np.all(np.isfinite(g)), field
        err = np.abs(g - c)
        err = err.max(axis=1) if err.ndim == 2 else err
        assert np.percentile(err, 99.5) < TOL, f"{field}: p99.5 {np.percentile(err, 99.5):.2e}"
        assert np.median(err) < TOL / 10, f"{field}: median {np.median(err):.2e}"
