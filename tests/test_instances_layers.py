"""Layer parameters in instances: every layer's unwired inputs and its visibility, grouped
by layer, overridable as parameter nodes are."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from test_app_support import app_env, make_window  # noqa: F401 - fixture

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.graph.commands import SetValue
from matedit.graph.layers import LayerStack
from matedit.io.document import FileResolver, load
from matedit.io.instance import material_parameters, new_instance, resolve, save_instance
from matedit.nodes.twin import sphere_surface
from matedit.resources import graphs_dir

MASTER = graphs_dir() / "materials" / "worn_painted_steel.json"  # steel, paint, rust
SURFACE, _ = sphere_surface(16)


def _render(doc) -> dict[str, np.ndarray]:
    return evaluate(lower_document(doc, FileResolver()), SURFACE)


def test_layers_expose_their_unwired_inputs_and_visibility_grouped_by_layer():
    doc = load(MASTER)
    plain = material_parameters(doc)
    params = material_parameters(doc, layers=True)
    assert set(plain) < set(params)  # the parameter nodes' are all still there, as they were
    for name in plain:
        assert params[name] == plain[name]
    stack = LayerStack.find(doc.graph)
    wired = {(l.dst, l.dst_port) for l in doc.graph.links}
    layer_ports = {n: p for n, p in params.items() if n not in plain}
    assert layer_ports
    for name, p in layer_ports.items():
        assert p.node == stack.node_id
        if name.endswith("_visible"):
            assert p.type == "switch" and p.default is True
            continue
        assert (p.node, p.port) not in wired and not name.endswith("_mask")
        lid = name.split("_", 1)[0]
        title = next(l.name for l in stack.layers if l.id == lid)
        assert p.group == title
    base = stack.layers[0].id
    assert f"{base}_visible" not in params  # the base always shows
    assert {f"{l.id}_visible" for l in stack.layers[1:]} <= set(params)


def test_an_instance_overrides_a_layer_input_and_hides_a_layer(tmp_path):
    inst = new_instance(MASTER, tmp_path / "inst.json")
    inst.parameters["rust_tint"] = [0.1, 0.5, 0.9]
    save_instance(inst, tmp_path / "inst.json")
    got = _render(resolve(inst).document)
    ref = load(MASTER)  # the reference: the value set on the stack's port by hand
    stack = LayerStack.find(ref.graph).node_id
    SetValue(stack, "rust_tint", [0.1, 0.5, 0.9]).apply(ref.graph)
    want = _render(ref)
    np.testing.assert_allclose(got["baseColor"], want["baseColor"], rtol=0, atol=1e-12)
    assert not np.allclose(want["baseColor"], _render(load(MASTER))["baseColor"])

    inst.parameters["rust_visible"] = False
    hidden = _render(resolve(inst).document)
    ref2 = copy.deepcopy(ref)
    LayerStack(ref2.graph, stack).set("rust", visible=False).apply(ref2.graph)
    np.testing.assert_allclose(hidden["baseColor"], _render(ref2)["baseColor"], rtol=0,
                               atol=1e-12)
    inst.parameters["rust_tint"] = "red"  # a wrong value names the parameter, as for others
    problems = resolve(inst).problems
    assert any(p.parameter == "rust_tint" and p.severity == "error" for p in problems)


@pytest.mark.usefixtures("app_env")
def test_the_instance_editor_shows_layer_groups_and_edits_them_as_uniforms(qtbot, tmp_path):
    w = make_window(qtbot)
    editor = w.create_instance(str(MASTER), str(tmp_path / "i.json"))
    rows = editor.panel.rows
    assert "rust_tint" in rows and "rust_visible" in rows and "steel_roughness" in rows
    compiles = editor.compile_count
    editor.set_value("rust_scale", 3.0)  # a value: a uniform update, no compile
    assert editor.compile_count == compiles
    assert editor.resolved.document.graph.nodes[editor.parameters["rust_scale"].node] \
        .values["rust_scale"] == 3.0
    editor.set_value("rust_visible", False)  # the layer compiles out: a new permutation
    assert editor.compile_count == compiles + 1
    assert "rust_scale" not in editor._uniform_names()  # hidden with its layer
