"""Driving the node canvas with the mouse and keyboard: wires, moves, the palette.

Real widgets under Xvfb; mouse events go through `view.viewport()` like a user's.
"""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import pytest  # noqa: E402
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QMouseEvent  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas.palette import catalogue, search  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.graph.model import Link, MaterialDocument, Node  # noqa: E402

pytestmark = pytest.mark.gui
LEFT = Qt.MouseButton.LeftButton


def small_material() -> MaterialDocument:
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


@pytest.fixture
def view(qtbot):
    controller = DocumentController(small_material())
    v = NodeCanvasView(controller)
    qtbot.addWidget(v)
    v.resize(1100, 700)
    v.show()
    qtbot.waitExposed(v)
    v.frame_all()
    QApplication.processEvents()
    return v


def port_pos(view: NodeCanvasView, node: str, port: str, output: bool) -> QPoint:
    item = view.scene().node_items[node]
    return view.mapFromScene(item.port_scene_pos(port, output))


def drag(view: NodeCanvasView, a: QPoint, b: QPoint, steps: int = 6,
         mods=Qt.KeyboardModifier.NoModifier) -> None:
    """Press at a, move in steps with the button held, release at b (all on the viewport)."""
    vp = view.viewport()
    QTest.mousePress(vp, LEFT, mods, a)
    for i in range(1, steps + 1):
        p = QPointF(a) + (QPointF(b) - QPointF(a)) * (i / steps)
        ev = QMouseEvent(QEvent.Type.MouseMove, p, QPointF(vp.mapToGlobal(p.toPoint())),
                         Qt.MouseButton.NoButton, LEFT, mods)
        QApplication.sendEvent(vp, ev)
    QTest.mouseRelease(vp, LEFT, mods, b)


def test_dragging_a_wire_between_ports_connects_them(view):
    c = view.controller
    steps = c.undo_stack.count()
    drag(view, port_pos(view, "p", "value", True), port_pos(view, "make", "metallic", False))
    link = Link("p", "value", "make", "metallic")
    assert link in c.document.graph.links
    assert link in view.scene().wire_items
    assert c.undo_stack.count() == steps + 1
    assert view.scene().items() and not any(
        type(it).__name__ == "LiveWire" for it in view.scene().items())


def test_dragging_from_an_input_to_an_output_connects_too(view):
    drag(view, port_pos(view, "make", "metallic", False), port_pos(view, "p", "value", True))
    assert Link("p", "value", "make", "metallic") in view.controller.document.graph.links


def test_incompatible_drag_is_refused_with_the_reason(view, qtbot):
    c = view.controller
    before = c.document.graph.snapshot()
    with qtbot.waitSignal(view.message) as sig:
        drag(view, port_pos(view, "col", "color", True), port_pos(view, "make", "metallic",
                                                                     False))
    assert "vec3" in sig.args[0] and "float" in sig.args[0]
    assert c.document.graph.snapshot() == before
    assert view.toast.isVisible() and "vec3" in view.toast.text()


def test_a_drag_that_would_close_a_cycle_is_refused(view, qtbot):
    from matedit.graph.commands import AddNode, Connect
    c = view.controller
    c.push(AddNode(Node("om", "one_minus", (250, 150))))
    c.push(Connect(Link("mul", "result", "om", "value")))
    before = c.document.graph.snapshot()
    with qtbot.waitSignal(view.message) as sig:
        drag(view, port_pos(view, "om", "result", True), port_pos(view, "mul", "b", False))
    assert "cycle" in sig.args[0]
    assert c.document.graph.snapshot() == before


def test_lifting_a_wire_off_an_input_moves_it_as_one_step(view):
    c = view.controller
    steps = c.undo_stack.count()
    drag(view, port_pos(view, "make", "roughness", False), port_pos(view, "make", "metallic",
                                                                     False))
    g = c.document.graph
    assert Link("mul", "result", "make", "metallic") in g.links
    assert Link("mul", "result", "make", "roughness") not in g.links
    assert c.undo_stack.count() == steps + 1
    c.undo_stack.undo()
    assert Link("mul", "result", "make", "roughness") in g.links
    assert Link("mul", "result", "make", "roughness") in view.scene().wire_items


def test_lifting_a_wire_onto_empty_canvas_disconnects_it(view):
    c = view.controller
    a = port_pos(view, "make", "roughness", False)
    drag(view, a, a + QPoint(-60, 160))
    assert Link("mul", "result", "make", "roughness") not in c.document.graph.links
    assert Link("mul", "result", "make", "roughness") not in view.scene().wire_items


def test_moving_nodes_is_one_undo_step(view):
    c = view.controller
    view.select_nodes(["p", "mul"])
    steps = c.undo_stack.count()
    item = view.scene().node_items["mul"]
    a = view.mapFromScene(item.pos() + QPointF(30, 10))  # the header
    drag(view, a, a + QPoint(80, 120), steps=10)
    g = c.document.graph
    assert c.undo_stack.count() == steps + 1
    zoom = view.zoom()
    assert g.nodes["mul"].position[0] == pytest.approx(250 + 80 / zoom, abs=2 / zoom)
    assert g.nodes["p"].position[1] == pytest.approx(120 / zoom, abs=2 / zoom)
    wire = view.scene().wire_items[Link("p", "value", "mul", "a")]
    assert wire.path().pointAtPercent(1.0) == item.port_scene_pos("a", False)
    c.undo_stack.undo()
    assert g.nodes["mul"].position == (250.0, 0.0) and g.nodes["p"].position == (0.0, 0.0)
    assert item.pos() == QPointF(250, 0)


def test_rubber_band_selects_nodes_not_wires(view):
    vp = view.viewport()
    a = view.mapFromScene(QPointF(-40, -60))
    b = view.mapFromScene(QPointF(400, 300))
    drag(view, a, b)
    assert view.selected_ids() == ["col", "mul", "p"]
    assert all(type(it).__name__ != "WireItem" for it in view.scene().selectedItems())
    assert vp is view.viewport()


def test_tab_palette_adds_a_node_at_the_cursor(view, qtbot):
    c = view.controller
    vp = view.viewport()
    spot = QPoint(300, 450)
    QTest.mouseMove(vp, spot + QPoint(7, 3))  # Qt drops a move to where the mouse already is
    QTest.mouseMove(vp, spot)
    # Under Xvfb the warped pointer's own motion events can arrive late: wait for the last.
    qtbot.waitUntil(lambda: view._last_pos == spot, timeout=2000)
    QTest.qWait(50)
    if view._last_pos != spot:  # a late event from the first move
        QTest.mouseMove(vp, spot)
        qtbot.waitUntil(lambda: view._last_pos == spot, timeout=2000)
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Tab)
    pal = view.node_palette
    assert pal.isVisible()
    QTest.keyClicks(pal.search, "noise")
    assert pal.visible_kinds()[0] == "value_noise"
    QTest.keyClick(pal.search, Qt.Key.Key_Return)
    assert not pal.isVisible()
    added = [n for n in c.document.graph.nodes.values() if n.kind == "value_noise"]
    assert len(added) == 1
    at = view.mapToScene(spot)
    assert added[0].position == pytest.approx((at.x(), at.y()), abs=1.0)
    assert added[0].id in view.scene().node_items


def test_palette_escape_adds_nothing(view):
    before = view.controller.document.graph.snapshot()
    view.open_palette(QPointF(0, 300))
    QTest.keyClicks(view.node_palette.search, "add")
    QTest.keyClick(view.node_palette.search, Qt.Key.Key_Escape)
    assert not view.node_palette.isVisible()
    assert view.controller.document.graph.snapshot() == before


def test_wire_dropped_on_empty_canvas_offers_only_compatible_kinds_and_connects(view):
    c = view.controller
    a = port_pos(view, "col", "color", True)  # a vec3 output
    drag(view, a, a + QPoint(120, 260))
    pal = view.node_palette
    assert pal.isVisible()
    kinds = pal.visible_kinds()
    assert "unpack_normal" in kinds and "add" in kinds
    assert "scalar_parameter" not in kinds and "material_output" not in kinds
    assert "texture_sample" not in kinds  # takes texture2d and vec2, not vec3
    QTest.keyClicks(pal.search, "one minus")
    QTest.keyClick(pal.search, Qt.Key.Key_Return)
    new = [n for n in c.document.graph.nodes.values() if n.kind == "one_minus"]
    assert len(new) == 1
    assert Link("col", "color", new[0].id, "value") in c.document.graph.links
    c.undo_stack.undo()  # node and link were one step
    assert not any(n.kind == "one_minus" for n in c.document.graph.nodes.values())


def test_alt_drag_pans_the_view(view):
    before = view.mapToScene(QPoint(0, 0))
    drag(view, QPoint(600, 600), QPoint(500, 550), mods=Qt.KeyboardModifier.AltModifier)
    after = view.mapToScene(QPoint(0, 0))
    assert after.x() > before.x() and after.y() > before.y()
    assert not view.selected_ids()


def test_wheel_zooms_about_the_cursor_within_limits(view):
    from PySide6.QtGui import QWheelEvent
    vp = view.viewport()
    spot = QPointF(400, 300)
    anchor = view.mapToScene(spot.toPoint())
    for _ in range(60):
        ev = QWheelEvent(spot, QPointF(vp.mapToGlobal(spot.toPoint())), QPoint(0, 0),
                         QPoint(0, 120), Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier,
                         Qt.ScrollPhase.NoScrollPhase, False)
        QApplication.sendEvent(vp, ev)
    assert view.zoom() == pytest.approx(3.0)
    moved = view.mapToScene(spot.toPoint()) - anchor
    assert abs(moved.x()) < 3 and abs(moved.y()) < 3


def test_palette_search_ranks_titles_and_fuzzy_matches():
    entries = catalogue()
    assert search("noise", entries)[0].kind == "value_noise"
    assert search("lrp", entries)[0].kind == "lerp"
    assert search("smooth", entries)[0].kind == "smoothstep"
    assert search("attributes make", entries)[0].kind == "make_attributes"
    assert search("zzzz", entries) == []


def test_dragging_a_comment_moves_the_nodes_inside_as_one_step(view):
    from matedit.graph.commands import PutComment
    from matedit.graph.model import Comment
    c = view.controller
    c.push(PutComment("box", Comment("box", "Inputs", (-30, -50, 260, 300))))  # p and col
    steps = c.undo_stack.count()
    item = view.scene().comment_items["box"]
    a = view.mapFromScene(item.pos() + QPointF(100, 10))  # its title bar
    drag(view, a, a + QPoint(0, 100))
    g = c.document.graph
    dy = 100 / view.zoom()
    assert c.undo_stack.count() == steps + 1
    assert g.comments["box"].rect[1] == pytest.approx(-50 + dy, abs=2)
    assert g.nodes["p"].position[1] == pytest.approx(dy, abs=2)
    assert g.nodes["col"].position[1] == pytest.approx(150 + dy, abs=2)
    assert g.nodes["mul"].position == (250.0, 0.0)  # outside the frame
    c.undo_stack.undo()
    assert g.nodes["p"].position == (0.0, 0.0) and g.comments["box"].rect[1] == -50


def test_clicking_a_wire_and_pressing_delete_disconnects_it(view):
    c = view.controller
    wire = view.scene().wire_items[Link("mul", "result", "make", "roughness")]
    mid = view.mapFromScene(wire.path().pointAtPercent(0.5))
    QTest.mouseClick(view.viewport(), LEFT, pos=mid)
    assert view.scene().selected_wires == {wire.link}
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert wire.link not in c.document.graph.links
    assert "mul" in c.document.graph.nodes


def test_f_frames_the_selection_and_the_minimap_navigates(view):
    view.select_nodes(["out"])
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_F)
    centre = view.mapToScene(view.viewport().rect().center())
    out = view.scene().node_items["out"].sceneBoundingRect().center()
    assert abs(centre.x() - out.x()) < 5 and abs(centre.y() - out.y()) < 5
    mm = view.minimap
    mm._render()
    QTest.mouseClick(mm, LEFT, pos=QPoint(8, 8))
    moved = view.mapToScene(view.viewport().rect().center())
    assert moved.x() < centre.x() - 50
