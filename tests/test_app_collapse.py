"""Edit › Collapse to Function and Expand Function in the editor: files, undo, the look."""

from __future__ import annotations

import json

import numpy as np
import pytest
from graphs_util import EDITOR_GRAPHS
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.io.document import FileResolver, load
from matedit.nodes.twin import sphere_surface

pytestmark = pytest.mark.usefixtures("app_env")
SURFACE, _ = sphere_surface(16)


def _render(doc) -> np.ndarray:
    return evaluate(lower_document(doc, FileResolver()), SURFACE)["baseColor"]


def test_collapse_writes_a_function_undo_brings_the_nodes_back_and_expand_inlines(
        qtbot, tmp_path):
    import shutil

    shutil.copytree(EDITOR_GRAPHS, tmp_path / "g")
    path = tmp_path / "g" / "materials" / "rusty_painted_metal.json"
    w = make_window(qtbot, path, show=True)
    settle(qtbot, w)
    canvas = w.tabs.material.canvas
    doc = w.controller.document
    want = _render(load(path))
    asked: list[str] = []
    target = tmp_path / "mine" / "rust_mask.json"
    target.parent.mkdir()
    canvas.ask_function_path = lambda s: asked.append(s) or str(target)
    canvas.select_nodes(["mask_noise", "edge", "hi", "mask", "amount"])
    call = canvas.collapse_selection()
    assert call and asked and asked[0].endswith("_function.json")
    fn = json.loads(target.read_text())
    assert fn["format"] == "matedit.function"
    assert {n["kind"] for n in fn["nodes"]} >= {"value_noise", "smoothstep", "function_input",
                                                "function_output"}
    node = doc.graph.nodes[call]
    assert node.kind == "function_call"
    assert node.settings["function"] == "../../mine/rust_mask.json"
    assert canvas.selected_ids() == [call]
    assert w.controller.undo_stack.undoText().startswith("collapse 4 nodes")
    np.testing.assert_allclose(_render(doc), want, rtol=0, atol=1e-12)
    settle(qtbot, w)
    assert w.compiler.current is not None  # the material compiles with the call

    w.controller.undo_stack.undo()
    assert {"mask_noise", "edge", "hi", "mask"} <= set(doc.graph.nodes)
    assert call not in doc.graph.nodes and target.is_file()  # the file stays: it was written
    w.controller.undo_stack.redo()
    canvas.select_nodes([call])
    new = canvas.expand_selected_call()
    assert len(new) == 4 and call not in doc.graph.nodes
    assert w.controller.undo_stack.undoText() == "expand Rust mask"
    np.testing.assert_allclose(_render(doc), want, rtol=0, atol=1e-12)

    canvas.select_nodes(["amount"])  # a parameter alone: nothing to collapse, no edit
    steps = w.controller.undo_stack.count()
    assert canvas.collapse_selection() == "" and w.controller.undo_stack.count() == steps
