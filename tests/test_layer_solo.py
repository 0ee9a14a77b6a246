"""Solo a layer: it alone over the base; again, every layer back."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from PySide6.QtCore import QPoint, Qt
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.graph.layers import LayerStack
from matedit.io.document import FileResolver, load
from matedit.nodes.twin import sphere_surface
from matedit.resources import graphs_dir

SURFACE, _ = sphere_surface(16)
THREE = graphs_dir() / "materials" / "worn_painted_steel.json"  # three layers


def _visible(doc, sid) -> dict[str, bool]:
    return {e["id"]: e.get("visible", True) for e in doc.graph.nodes[sid].settings["layers"]}


def test_solo_hides_the_others_and_again_shows_every_layer():
    doc = load(THREE)
    stack = LayerStack.find(doc.graph)
    ids = [l.id for l in stack.layers]
    assert len(ids) >= 3
    top = ids[-1]
    stack.solo(top).apply(doc.graph)
    assert _visible(doc, stack.node_id) == {i: (i in (ids[0], top)) for i in ids}
    assert stack.is_solo(top)
    stack.solo(top).apply(doc.graph)  # again: every layer
    assert all(_visible(doc, stack.node_id).values())
    stack.solo(ids[0]).apply(doc.graph)  # the base alone
    assert _visible(doc, stack.node_id) == {i: i == ids[0] for i in ids}


def test_a_solo_layer_renders_as_the_stack_with_only_it_over_the_base():
    doc = load(THREE)
    stack = LayerStack.find(doc.graph)
    ids = [l.id for l in stack.layers]
    stack.solo(ids[1]).apply(doc.graph)
    got = evaluate(lower_document(doc, FileResolver()), SURFACE)
    ref = load(THREE)  # the reference: the other layers removed from the stack outright
    keep = {ids[0], ids[1]}
    node = LayerStack.find(ref.graph).node_id
    for lid in ids:
        if lid not in keep:
            LayerStack(ref.graph, node).remove(lid).apply(ref.graph)
    want = evaluate(lower_document(ref, FileResolver()), SURFACE)
    for f in ("baseColor", "roughness", "normal"):
        np.testing.assert_allclose(got[f], want[f], rtol=0, atol=1e-12, err_msg=f)


@pytest.mark.usefixtures("app_env")
def test_alt_click_on_an_eye_solos_and_the_row_menu_offers_it(qtbot):
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    panel = w.layers
    settle(qtbot, w)
    ids = [l.id for l in panel.stack.layers]  # paint (base), rust
    row = next(panel.list.itemWidget(panel.list.item(i)) for i in range(panel.list.count())
               if panel.list.itemWidget(panel.list.item(i)).layer_id == ids[0])
    qtbot.mouseClick(row.eye, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.AltModifier)
    doc = w.controller.document
    assert _visible(doc, panel.stack.node_id) == {ids[0]: True, ids[1]: False}
    assert w.controller.undo_stack.undoText() == f"solo layer {ids[0]}"
    settle(qtbot, w)
    menus = []
    panel.run_menu = lambda menu, at: menus.append([a.text() for a in menu.actions()])
    row = next(panel.list.itemWidget(panel.list.item(i)) for i in range(panel.list.count())
               if panel.list.itemWidget(panel.list.item(i)).layer_id == ids[0])
    from PySide6.QtGui import QContextMenuEvent

    row.contextMenuEvent(QContextMenuEvent(QContextMenuEvent.Reason.Mouse, QPoint(5, 5),
                                           row.mapToGlobal(QPoint(5, 5))))
    assert menus == [["Show every layer"]]
    w.controller.undo_stack.undo()
    assert all(_visible(doc, panel.stack.node_id).values())
