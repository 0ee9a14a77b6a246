"""Edit › Bypass (B) on the canvas: undoable, drawn faded, and the preview recompiles."""

from __future__ import annotations

from graphs_util import EDITOR_SAMPLE
from PySide6.QtCore import Qt
from test_app_support import app_env, make_window  # noqa: F401 - fixture


def test_b_bypasses_the_selection_and_undo_brings_it_back(qtbot):
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    graph = w.controller.document.graph
    item = canvas.scene().node_items["mask_noise"]
    canvas.select_nodes(["mask_noise", "out"])  # the output cannot be bypassed: skipped
    canvas.setFocus()
    qtbot.keyClick(canvas, Qt.Key.Key_B)
    assert graph.nodes["mask_noise"].muted and not graph.nodes["out"].muted
    assert item.muted and item.subtitle.startswith("bypassed")
    assert "Bypassed" in item.toolTip()
    assert w.controller.undo_stack.undoText() == "bypass 1 node"
    w.controller.undo_stack.undo()
    assert not graph.nodes["mask_noise"].muted and not item.muted
    w.controller.undo_stack.redo()
    assert item.muted
    qtbot.keyClick(canvas, Qt.Key.Key_B)  # all bypassed already: they work again
    assert not graph.nodes["mask_noise"].muted
    edit = next(a.menu() for a in w.menuBar().actions() if a.text() == "&Edit")
    assert "&Bypass" in [a.text() for a in edit.actions()]
    canvas.select_nodes(["out"])
    assert canvas.toggle_bypass() == []  # nothing to bypass: a message, no edit
    assert w.controller.undo_stack.undoText() == "restore 1 node"
