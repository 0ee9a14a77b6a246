"""Collapse a selection into a material function, and expand a call back inline."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.graph.collapse import CollapseError, collapse, expand
from matedit.graph.commands import Macro
from matedit.graph.validate import analyse
from matedit.io.document import FileResolver, load, save
from matedit.nodes.twin import sphere_surface

SURFACE, _ = sphere_surface(24)
# The rust mask: a noise and the smoothstep band around the amount (a parameter: it stays).
MASK = ["mask_noise", "edge", "hi", "mask", "amount"]


def _render(doc) -> dict[str, np.ndarray]:
    return evaluate(lower_document(doc, FileResolver()), SURFACE)


def _collapsed(tmp_path):
    doc = load(EDITOR_SAMPLE)
    save(doc, tmp_path / "mat.json")  # a copy beside which the function is written
    doc = load(tmp_path / "mat.json")
    fn, commands, call = collapse(doc, analyse(doc, FileResolver()), MASK,
                                  "rust_mask.json", "Rust mask")
    save(fn, tmp_path / "rust_mask.json")
    macro = Macro(commands, text="collapse")
    macro.apply(doc.graph)
    return doc, fn, call, macro


def test_a_collapsed_selection_draws_the_same_and_undo_restores_it(tmp_path):
    original = load(EDITOR_SAMPLE)
    want = _render(original)
    doc, fn, call, macro = _collapsed(tmp_path)
    assert "amount" in doc.graph.nodes  # a parameter stays in the material
    assert not {"mask_noise", "edge", "hi", "mask"} & set(doc.graph.nodes)
    kinds = sorted(n.kind for n in fn.graph.nodes.values())
    assert kinds == sorted(["value_noise", "one_minus", "add", "smoothstep",
                            "function_input", "function_input", "function_output"])
    ins = {n.settings["name"]: n.settings["type"] for n in fn.graph.nodes.values()
           if n.kind == "function_input"}
    # the cut wires: uv in, and the amount, named after its parameter
    assert ins == {"uv": "vec2", "rust_amount": "float"}
    got = _render(doc)
    for f in ("baseColor", "roughness", "metallic"):
        np.testing.assert_allclose(got[f], want[f], rtol=0, atol=1e-12, err_msg=f)
    macro.revert(doc.graph)
    assert doc.graph.snapshot() == load(tmp_path / "mat.json").graph.snapshot()


def test_expanding_the_call_puts_the_nodes_back_and_draws_the_same(tmp_path):
    want = _render(load(EDITOR_SAMPLE))
    doc, fn, call, _ = _collapsed(tmp_path)
    commands, new_ids = expand(doc, call, load(tmp_path / "rust_mask.json"))
    Macro(commands).apply(doc.graph)
    assert call not in doc.graph.nodes and len(new_ids) == 4
    kinds = sorted(doc.graph.nodes[n].kind for n in new_ids)
    assert kinds == ["add", "one_minus", "smoothstep", "value_noise"]
    got = _render(doc)
    for f in ("baseColor", "roughness", "metallic"):
        np.testing.assert_allclose(got[f], want[f], rtol=0, atol=1e-12, err_msg=f)


def test_an_unwired_function_input_expands_to_the_calls_value(tmp_path):
    doc, fn, call, _ = _collapsed(tmp_path)
    amount = next(l for l in doc.graph.links if l.dst == call and l.dst_port == "rust_amount")
    doc.graph.links.discard(amount)  # the call's input unwired: its value 0.3 is used
    doc.graph.nodes[call].values["rust_amount"] = 0.3
    want = _render(doc)
    commands, new_ids = expand(doc, call, load(tmp_path / "rust_mask.json"))
    Macro(commands).apply(doc.graph)
    edge = next(n for n in new_ids if doc.graph.nodes[n].kind == "one_minus")
    assert doc.graph.nodes[edge].values["value"] == 0.3
    got = _render(doc)
    np.testing.assert_allclose(got["baseColor"], want["baseColor"], rtol=0, atol=1e-12)


def test_only_parameters_and_outputs_cannot_be_collapsed():
    doc = load(EDITOR_SAMPLE)
    with pytest.raises(CollapseError, match="nothing to collapse"):
        collapse(doc, analyse(doc, FileResolver()), ["amount", "out"], "f.json", "f")


def test_a_selection_with_an_outside_node_between_its_nodes_is_refused(tmp_path):
    """Collapsing nodes joined through an unselected node would wire the call into itself
    (call -> e0 -> call): refused, naming the nodes in between, before anything is built;
    with them selected too, the collapse draws the same (CPU evaluator, 1e-12)."""
    from matedit.graph.collapse import between
    from matedit.resources import graphs_dir

    doc = load(graphs_dir() / "materials" / "rusty_painted_metal.json")
    ids = ["mask_noise", "edge", "hi", "mask"]  # edge -> e0 -> mask: e0 (and e1) outside
    assert between(doc, ids) == ["e0", "e1"]
    before = doc.graph.snapshot()
    with pytest.raises(CollapseError, match=r"^e0, e1 sit between selected nodes"):
        collapse(doc, analyse(doc, FileResolver()), ids, "f.json", "F")
    assert doc.graph.snapshot() == before
    want = _render(doc)
    save(doc, tmp_path / "mat.json")
    doc = load(tmp_path / "mat.json")
    fn, commands, _call = collapse(doc, analyse(doc, FileResolver()), [*ids, "e0", "e1"],
                                   "f.json", "F")
    save(fn, tmp_path / "f.json")
    Macro(commands, text="collapse").apply(doc.graph)
    got = _render(doc)
    for key in want:
        np.testing.assert_allclose(got[key], want[key], rtol=0, atol=1e-12)
