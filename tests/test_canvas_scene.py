"""The node canvas mirrors the model: build, events, undo/redo, delete, clipboard, framing.

Real widgets under Xvfb (pytest-xvfb starts the server; pytest-qt drives the widgets).
"""

from __future__ import annotations

import math
import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import pytest  # noqa: E402
from graphs_util import EDITOR_SAMPLE
from PySide6.QtCore import QPointF, Qt  # noqa: E402
from PySide6.QtGui import QColor, QImage  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas.clipboard import MIME  # noqa: E402
from matedit.app.canvas.node_item import BadgeItem, NodeItem  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.graph.commands import (  # noqa: E402
    AddNode,
    Connect,
    Disconnect,
    MoveNodes,
    PutComment,
    RemoveNode,
    SetSetting,
)
from matedit.graph.model import Comment, Link, MaterialDocument, Node  # noqa: E402
from matedit.io.document import load  # noqa: E402

pytestmark = pytest.mark.gui


def small_material() -> MaterialDocument:
    """p (float) -> multiply -> roughness; colour -> baseColor; attributes -> output."""
    doc = MaterialDocument(name="test")
    g = doc.graph
    for node in (
        Node("p", "scalar_parameter", (0, 0), {"name": "p"}, {"value": 0.5}),
        Node("col", "color_parameter", (0, 150), {"name": "col"}),
        Node("mul", "multiply", (250, 0)),
        Node("make", "make_attributes", (500, 0)),
        Node("out", "material_output", (800, 0)),
    ):
        g.nodes[node.id] = node
    g.links |= {Link("p", "value", "mul", "a"), Link("mul", "result", "make", "roughness"),
                Link("col", "color", "make", "baseColor"),
                Link("make", "attributes", "out", "attributes")}
    return doc


def assert_mirrors(view: NodeCanvasView) -> None:
    scene, graph = view.scene(), view.controller.document.graph
    assert set(scene.node_items) == set(graph.nodes)
    assert set(scene.wire_items) == set(graph.links)
    assert set(scene.comment_items) == set(graph.comments)
    for nid, item in scene.node_items.items():
        assert (item.pos().x(), item.pos().y()) == graph.nodes[nid].position
    for link, wire in scene.wire_items.items():
        src = scene.node_items[link.src].port_scene_pos(link.src_port, True)
        assert wire.path().pointAtPercent(0.0) == src


@pytest.fixture
def view(qtbot):
    controller = DocumentController(small_material())
    v = NodeCanvasView(controller)
    qtbot.addWidget(v)
    v.resize(1000, 700)
    v.show()
    qtbot.waitExposed(v)
    v.frame_all()
    return v


def test_scene_builds_one_item_per_node_link_and_comment(view):
    assert_mirrors(view)
    assert isinstance(view.scene().node_items["mul"], NodeItem)
    names = [p.name for p in view.scene().node_items["make"].ports() if not p.is_output]
    assert "baseColor" in names and "roughness" in names


def test_scene_follows_add_remove_connect_and_undo_redo(view):
    c = view.controller
    c.push(AddNode(Node("n1", "one_minus", (300, 300))))
    c.push(Connect(Link("p", "value", "n1", "value")))
    c.push(PutComment("note", Comment("note", "hello", (-50, -80, 400, 300))))
    assert_mirrors(view)
    assert Link("p", "value", "n1", "value") in view.scene().wire_items
    c.push(RemoveNode("mul"))
    assert "mul" not in view.scene().node_items
    assert_mirrors(view)
    for _ in range(4):
        c.undo_stack.undo()
        assert_mirrors(view)
    assert "n1" not in view.scene().node_items
    for _ in range(4):
        c.undo_stack.redo()
        assert_mirrors(view)
    assert "mul" not in view.scene().node_items


def test_moves_update_only_the_wires_of_the_moved_node(view):
    c = view.controller
    c.push(MoveNodes({"mul": (260.0, 90.0)}))
    assert_mirrors(view)
    wire = view.scene().wire_items[Link("mul", "result", "make", "roughness")]
    assert wire.path().pointAtPercent(0.0) == view.scene().node_items["mul"].port_scene_pos(
        "result", True)


def test_setting_change_rebuilds_ports(view):
    c = view.controller
    c.push(AddNode(Node("sa", "set_attributes", (0, 400), {"fields": ["baseColor"]})))
    item = view.scene().node_items["sa"]
    assert [r.name for r in item.inputs] == ["attributes", "baseColor"]
    c.push(SetSetting("sa", "fields", ["baseColor", "roughness"]))
    assert [r.name for r in item.inputs] == ["attributes", "baseColor", "roughness"]
    assert item.port("roughness", False) is not None


def test_analysis_resolves_generic_port_types_and_colours_wires(view):
    c = view.controller
    c.push(AddNode(Node("cv", "constant", (0, 300), {"type": "vec3", "value": [1, 0, 0]})))
    c.push(AddNode(Node("ad", "add", (200, 300))))
    c.push(Connect(Link("cv", "value", "ad", "a")))
    c.flush()
    item = view.scene().node_items["ad"]
    assert item.port_type("result", True) == "vec3"
    assert view.scene().wire_items[Link("cv", "value", "ad", "a")].type_name == "vec3"


def test_delete_key_removes_selection_and_undo_restores_links(view):
    c = view.controller
    before = c.document.graph.snapshot()
    view.select_nodes(["mul"])
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert "mul" not in c.document.graph.nodes
    assert not any("mul" in (l.src, l.dst) for l in c.document.graph.links)
    assert_mirrors(view)
    c.undo_stack.undo()
    assert c.document.graph.snapshot() == before
    assert Link("p", "value", "mul", "a") in view.scene().wire_items
    assert Link("mul", "result", "make", "roughness") in view.scene().wire_items
    assert_mirrors(view)


def test_copy_paste_between_two_documents_keeps_inner_links_with_fresh_ids(view, qtbot):
    other = DocumentController(small_material())
    v2 = NodeCanvasView(other)
    qtbot.addWidget(v2)
    v2.resize(800, 600)
    v2.show()
    qtbot.waitExposed(v2)
    view.select_nodes(["p", "mul"])
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_C, Qt.KeyboardModifier.ControlModifier)
    from PySide6.QtWidgets import QApplication
    mime = QApplication.clipboard().mimeData()
    assert mime.hasFormat(MIME) and mime.hasText()
    n_before = len(other.document.graph.nodes)
    steps = other.undo_stack.count()
    v2.setFocus()
    QTest.keyClick(v2, Qt.Key.Key_V, Qt.KeyboardModifier.ControlModifier)
    g = other.document.graph
    assert len(g.nodes) == n_before + 2
    assert other.undo_stack.count() == steps + 1  # one macro
    new = sorted(set(g.nodes) - {"p", "col", "mul", "make", "out"})
    assert len(new) == 2
    kinds = {g.nodes[n].kind: n for n in new}
    assert set(kinds) == {"scalar_parameter", "multiply"}
    assert Link(kinds["scalar_parameter"], "value", kinds["multiply"], "a") in g.links
    assert v2.selected_ids() == sorted(new)
    assert_mirrors(v2)
    other.undo_stack.undo()
    assert len(g.nodes) == n_before
    assert_mirrors(v2)


def _overlaps(view, node_id):
    from PySide6.QtWidgets import QApplication

    QApplication.processEvents()
    items = view.scene().node_items
    mine = items[node_id].sceneBoundingRect()
    return [nid for nid, it in items.items()
            if nid != node_id and it.sceneBoundingRect().intersects(mine)]


def test_duplicate_offsets_the_copy_into_free_space(view):
    """The copy goes 40 right and down of the original, then on to the nearest place where
    it covers no node (it used to land half over the original)."""
    view.select_nodes(["mul"])
    ids = view.duplicate_selection()
    assert len(ids) == 1 and ids[0] != "mul"
    g = view.controller.document.graph
    x, y = g.nodes[ids[0]].position
    assert math.hypot(x - 290.0, y - 40.0) < 300
    assert not _overlaps(view, ids[0])
    assert view.selected_ids() == ids


def test_a_node_added_on_another_lands_beside_it_selected(view):
    """Added from the palette right on top of the Make Attributes: it lands in free space
    nearby, selected (so the Inspector shows it, not what was selected before)."""
    view.select_nodes(["make"])
    make = view.controller.document.graph.nodes["make"].position
    nid = view.add_node_at("gradient_noise", QPointF(*make))
    assert nid and not _overlaps(view, nid)
    x, y = view.controller.document.graph.nodes[nid].position
    assert math.hypot(x - make[0], y - make[1]) < 400
    assert view.selected_ids() == [nid]


def test_a_wire_dropped_on_empty_canvas_joins_the_new_nodes_subject_input():
    """Smooth Step's value, not edge0 (its first input); Remap's value."""
    from matedit.app.canvas.interaction import compatible_port

    assert compatible_port("smoothstep", "float", True) == "value"
    assert compatible_port("remap", "float", True) == "value"


def test_duplicating_a_parameter_gives_the_copy_a_free_name_so_the_material_compiles(view):
    """Ctrl+D on a parameter: the copy is the next free name (p -> p_2 -> p_3), the message
    counts in the singular, and the document has no duplicate-name error."""
    from matedit.graph.validate import validate

    messages: list[str] = []
    view.message.connect(messages.append)
    c = view.controller
    view.select_nodes(["p"])
    first = view.duplicate_selection()
    view.select_nodes(["p"])
    second = view.duplicate_selection()
    g = c.document.graph
    assert g.nodes[first[0]].settings["name"] == "p_2"
    assert g.nodes[second[0]].settings["name"] == "p_3"
    assert g.nodes["p"].settings["name"] == "p"
    assert messages[-1] == "Duplicated 1 node"
    assert not [d for d in validate(c.document, c.resolver) if d.severity == "error"]


def test_frame_all_makes_every_node_visible(view):
    c = view.controller
    c.push(AddNode(Node("far1", "one_minus", (-3000, -2000))))
    c.push(AddNode(Node("far2", "one_minus", (4000, 2500))))
    view.frame_all()
    vp = view.viewport().rect()
    for item in view.scene().node_items.values():
        r = view.mapFromScene(item.sceneBoundingRect()).boundingRect()
        assert vp.contains(r), item.node_id


def test_selection_signal_lists_sorted_ids(view, qtbot):
    with qtbot.waitSignal(view.selectionChangedIds) as sig:
        view.select_nodes(["out", "mul"])
    assert sig.args == [["mul", "out"]]


def test_node_errors_show_a_badge_with_the_message(view):
    view.set_node_errors({"mul": "0:3(9): error: syntax error"})
    item = view.scene().node_items["mul"]
    assert item.has_error()
    badge = next(ch for ch in item.childItems() if isinstance(ch, BadgeItem))
    assert "syntax error" in badge.toolTip()
    view.set_node_errors({})
    assert not item.has_error()


def test_preview_image_grows_the_node(view):
    item = view.scene().node_items["mul"]
    h = item.layout.height
    img = QImage(64, 64, QImage.Format.Format_RGB32)
    img.fill(QColor("orange"))
    view.set_node_preview("mul", img)
    assert item.layout.height > h and item.has_preview()
    view.set_node_preview("mul", None)
    assert item.layout.height == h


def test_document_replaced_rebuilds(view):
    view.controller.replace(load(EDITOR_SAMPLE))
    assert_mirrors(view)
    assert "stack" in view.scene().node_items


def test_function_call_double_click_requests_the_function_file(qtbot):
    controller = DocumentController(load(EDITOR_SAMPLE))
    v = NodeCanvasView(controller)
    qtbot.addWidget(v)
    v.resize(1000, 700)
    v.show()
    qtbot.waitExposed(v)
    v.frame_all()
    item = v.scene().node_items["uv"]
    pos = v.mapFromScene(item.pos() + QPointF(40, 8))
    with qtbot.waitSignal(v.functionOpenRequested) as sig:
        QTest.mouseDClick(v.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    assert sig.args[0].endswith("uv_tile_rotate.json") and os.path.isabs(sig.args[0])


def test_disconnect_event_removes_only_that_wire(view):
    c = view.controller
    c.push(Disconnect(Link("p", "value", "mul", "a")))
    assert Link("p", "value", "mul", "a") not in view.scene().wire_items
    assert len(view.scene().wire_items) == 3
    assert_mirrors(view)

