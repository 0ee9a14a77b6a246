"""Bypass (mute): a bypassed node passes its first input of each output's type through."""

from __future__ import annotations

import json

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE, link, node, simple_material
from hostile import glslang_ok

from matedit.compiler import compile_document
from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.graph.commands import CommandError, Connect, Disconnect, SetMuted, SetSetting
from matedit.graph.model import Link
from matedit.graph.nodes import ATTRIBUTE_FIELDS
from matedit.io.document import FileResolver, FormatError, dumps, load, loads
from matedit.nodes.twin import sphere_surface

SURFACE, _ = sphere_surface(24)


def _attrs(doc, resolver=None) -> dict[str, np.ndarray]:
    return evaluate(lower_document(doc, resolver or FileResolver()), SURFACE)


def test_a_bypassed_multiply_equals_the_graph_rewired_around_it():
    doc = simple_material()  # rough -> multiply(a, b = 0.5) -> make.roughness
    SetMuted(("m",), True).apply(doc.graph)
    bypassed = _attrs(doc)["roughness"]
    rewired = simple_material()
    Disconnect(Link("m", "result", "make", "roughness")).apply(rewired.graph)
    Connect(Link("r", "value", "make", "roughness")).apply(rewired.graph)
    np.testing.assert_array_equal(bypassed, _attrs(rewired)["roughness"])
    assert np.allclose(bypassed, 0.4)  # the parameter itself, not 0.4 * 0.5
    SetMuted(("m",), False).apply(doc.graph)
    assert np.allclose(_attrs(doc)["roughness"], 0.2)


def test_an_unwired_first_input_passes_its_value_as_a_uniform():
    doc = simple_material()
    node(doc, "m2", "multiply", values={"a": 0.7, "b": 0.1})
    Disconnect(Link("m", "result", "make", "roughness")).apply(doc.graph)
    link(doc, "m2", "result", "make", "roughness")
    SetMuted(("m2",), True).apply(doc.graph)
    ir = lower_document(doc, FileResolver())
    assert np.allclose(evaluate(ir, SURFACE)["roughness"], 0.7)
    # the value stays a slider: its uniform is in the IR and changing it changes the result
    names = [u.name for u in ir.uniforms if u.node == "m2"]
    assert names, [u.name for u in ir.uniforms]
    assert np.allclose(evaluate(ir, SURFACE, uniforms={names[0]: 0.3})["roughness"], 0.3)


def test_a_bypassed_layer_stack_is_its_base_layer():
    doc = load(EDITOR_SAMPLE)
    resolver = FileResolver()
    stack = next(nid for nid, n in doc.graph.nodes.items() if n.kind == "layer_stack")
    layers = doc.graph.nodes[stack].settings["layers"]
    assert len(layers) >= 2
    layered = _attrs(doc, resolver)
    SetMuted((stack,), True).apply(doc.graph)
    bypassed = _attrs(doc, resolver)
    # The reference: the same stack with every layer above the base hidden by hand.
    bare = load(EDITOR_SAMPLE)
    hidden = [layers[0], *({**e, "visible": False} for e in layers[1:])]
    SetSetting(stack, "layers", hidden).apply(bare.graph)
    base_only = _attrs(bare, resolver)
    for f in ("baseColor", "roughness", "metallic"):
        np.testing.assert_array_equal(bypassed[f], base_only[f], err_msg=f)
    assert not np.allclose(bypassed["baseColor"], layered["baseColor"])
    assert doc.graph.nodes[stack].settings["layers"] == layers  # the document is untouched


def test_bypass_is_saved_undone_and_refused_where_nothing_passes_through(tmp_path):
    doc = simple_material()
    cmd = SetMuted(("m", "make"), True)
    cmd.apply(doc.graph)
    raw = json.loads(dumps(doc))
    muted = {n["id"]: n.get("muted") for n in raw["nodes"]}
    assert muted == {"col": None, "r": None, "m": True, "make": True, "out": None}
    again = loads(dumps(doc))
    assert again.graph.nodes["m"].muted and not again.graph.nodes["r"].muted
    assert again.graph.snapshot() == doc.graph.snapshot()
    cmd.revert(doc.graph)
    assert not doc.graph.nodes["m"].muted and "muted" not in dumps(doc)
    # a bypassed Make Attributes gives the default material (no MaterialAttributes input)
    SetMuted(("make",), True).apply(doc.graph)
    defaults = {f.name: f.default for f in ATTRIBUTE_FIELDS}
    got = _attrs(doc)
    for f in ("baseColor", "roughness", "metallic"):
        assert np.allclose(got[f], defaults[f]), (f, got[f][:1], defaults[f])
    for nid in ("out", "r", "col"):  # outputs and sources have nothing to pass through
        with pytest.raises(CommandError, match="cannot be bypassed"):
            SetMuted((nid,), True).apply(doc.graph)
    bad = json.loads(dumps(simple_material()))
    bad["nodes"][0]["muted"] = "yes"
    with pytest.raises(FormatError) as info:
        loads(json.dumps(bad), file="bad.json")
    assert "bad.json" in str(info.value) and "node col" in str(info.value) \
        and "field muted" in str(info.value)


def test_a_bypassed_material_compiles_for_every_target_and_glslang_accepts_it(tmp_path):
    doc = load(EDITOR_SAMPLE)
    assert any(op.node == "mask_noise" for op in compile_document(doc).ir.main.ops)
    SetMuted(("mask_noise",), True).apply(doc.graph)  # the sample's only noise
    for target in ("glsl330", "glsl450", "essl300"):
        cm = compile_document(doc, FileResolver(), target=target)
        assert all(op.node != "mask_noise" for op in cm.ir.main.ops)  # nothing emitted
        frag = tmp_path / f"m.{target}.frag"
        frag.write_text(cm.fragment_text)
        ok, log = glslang_ok(frag, target)
        assert ok, log
