"""Foldable pin groups on Make / Break / Set Material Attributes (issue 23).

Real widgets under Xvfb; clicks go through `view.viewport()` like a user's. A group's header
row folds or unfolds its pins through the undo stack as a change of the non-structural
EXPANDED_GROUPS setting: the node's height and visible pins follow, wires to folded pins end
on the header, nothing recompiles, and the setting is saved with the document.
"""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import pytest  # noqa: E402
from PySide6.QtCore import QEvent, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QMouseEvent  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas import constants as C  # noqa: E402
from matedit.app.canvas.node_item import GroupHeader, NodeItem  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.graph import nodes  # noqa: E402
from matedit.graph.commands import AddNode  # noqa: E402
from matedit.graph.model import Link, MaterialDocument, Node  # noqa: E402
from matedit.io.document import dumps, loads  # noqa: E402

pytestmark = pytest.mark.gui
LEFT = Qt.MouseButton.LeftButton
GROUP_SIZES = {"Base": 7, "Specular": 2, "Coat": 5, "Sheen": 2, "Anisotropy": 2,
               "Subsurface": 4, "Thin film": 2, "Transmission": 4}


def coat_material() -> MaterialDocument:
    """coat weight and base colour wired into a Make Attributes, then a Break and the output."""
    doc = MaterialDocument(name="pins")
    g = doc.graph
    for node in (
        Node("w", "scalar_parameter", (0, 0), {"name": "w"}, {"value": 0.5}),
        Node("col", "color_parameter", (0, 150), {"name": "col"}),
        Node("make", "make_attributes", (300, 0)),
        Node("brk", "break_attributes", (600, 0)),
        Node("out", "material_output", (900, 0)),
    ):
        g.nodes[node.id] = node
    g.links |= {Link("w", "value", "make", "coat"), Link("col", "color", "make", "baseColor"),
                Link("make", "attributes", "brk", "attributes"),
                Link("make", "attributes", "out", "attributes")}
    return doc


@pytest.fixture
def view(qtbot):
    controller = DocumentController(coat_material())
    v = NodeCanvasView(controller)
    qtbot.addWidget(v)
    v.resize(1200, 800)
    v.show()
    qtbot.waitExposed(v)
    v.frame_all()
    QApplication.processEvents()
    return v


def item(view, nid: str) -> NodeItem:
    return view.scene().node_items[nid]


def header(it: NodeItem, group: str) -> tuple[GroupHeader, float]:
    return next((h, y) for h, y in it.layout.headers if h.group == group)


def visible_inputs(it: NodeItem) -> set[str]:
    return {p.name for p in it.ports() if not p.is_output and p.isVisible()}


def click_header(view, nid: str, group: str) -> None:
    it = item(view, nid)
    _, y = header(it, group)
    pt = view.mapFromScene(it.pos() + QPointF(it.layout.width / 2, y))
    QTest.mouseClick(view.viewport(), LEFT, Qt.KeyboardModifier.NoModifier, pt)
    QApplication.processEvents()


def test_a_default_node_shows_base_open_and_each_other_group_as_a_header(view):
    it = item(view, "make")
    assert it.expanded == frozenset({"Base"})
    heads = [(h.group, h.count, h.expanded) for h, _ in it.layout.headers]
    assert heads == [(g, n, g == "Base") for g, n in GROUP_SIZES.items()]
    base = {f.name for f in nodes.ATTRIBUTE_FIELDS if f.group == "Base"}
    assert visible_inputs(it) == base
    # One row per header and per open pin: a header per group + 7 Base pins.
    rows = len(GROUP_SIZES) + GROUP_SIZES["Base"]
    assert it.layout.height == pytest.approx(it.layout.top + rows * C.ROW_HEIGHT + C.BODY_PAD)
    assert header(it, "Coat")[0].label == "\u25b8 Coat (5)"
    # A Break folds its outputs the same way; the Material Output has one pin, no groups.
    assert [h.group for h, _ in item(view, "brk").layout.headers] == list(GROUP_SIZES)
    assert all(h.is_output for h, _ in item(view, "brk").layout.headers)
    assert item(view, "out").expanded is None and not item(view, "out").layout.headers


def test_a_wire_to_a_folded_pin_ends_on_its_header_and_the_header_shows_it(view):
    scene = view.scene()
    it = item(view, "make")
    _, y = header(it, "Coat")
    assert it.is_hidden("coat", False)
    assert it.port_scene_pos("coat", False) == it.pos() + QPointF(0.0, y)
    wire = scene.wire_items[Link("w", "value", "make", "coat")]
    assert wire.path().pointAtPercent(1.0) == it.pos() + QPointF(0.0, y)
    assert it.header_connected(header(it, "Coat")[0])
    assert not it.header_connected(header(it, "Sheen")[0])


def test_clicking_a_header_expands_it_through_the_undo_stack_without_recompiling(view):
    c = view.controller
    recompiles: list[int] = []
    c.structureChanged.connect(lambda: recompiles.append(1))
    it = item(view, "make")
    h0 = it.layout.height
    steps = c.undo_stack.count()
    click_header(view, "make", "Coat")
    assert c.document.graph.nodes["make"].settings[nodes.EXPANDED_GROUPS] == ["Base", "Coat"]
    assert c.undo_stack.count() == steps + 1
    assert "Coat" in c.undo_stack.undoText()
    assert it.layout.height == pytest.approx(h0 + 5 * C.ROW_HEIGHT)
    coat = {f.name for f in nodes.ATTRIBUTE_FIELDS if f.group == "Coat"}
    assert coat <= visible_inputs(it)
    assert not it.is_hidden("coat", False)
    # The wire re-routes to the pin's own row, below the header.
    wire = view.scene().wire_items[Link("w", "value", "make", "coat")]
    end = wire.path().pointAtPercent(1.0)
    assert end == it.port_scene_pos("coat", False)
    assert end.y() > it.pos().y() + header(it, "Coat")[1]
    # The click does not drag the node.
    assert c.document.graph.nodes["make"].position == (300, 0)
    c.undo_stack.undo()
    assert it.layout.height == pytest.approx(h0) and it.is_hidden("coat", False)
    assert wire.path().pointAtPercent(1.0) == it.pos() + QPointF(0.0, header(it, "Coat")[1])
    c.undo_stack.redo()
    assert not it.is_hidden("coat", False)
    click_header(view, "make", "Base")  # Base folds like any other group
    assert c.document.graph.nodes["make"].settings[nodes.EXPANDED_GROUPS] == ["Coat"]
    assert it.is_hidden("baseColor", False)
    c.flush()
    QApplication.processEvents()
    assert recompiles == []


def test_the_setting_round_trips_through_the_saved_document(view):
    c = view.controller
    view.scene().set_group_expanded("brk", "Sheen", True)
    text = dumps(c.document)
    again = loads(text)
    assert again.graph.nodes["brk"].settings[nodes.EXPANDED_GROUPS] == ["Base", "Sheen"]
    c2 = DocumentController(again)
    v2 = NodeCanvasView(c2)
    brk = v2.scene().node_items["brk"]
    assert brk.expanded == frozenset({"Base", "Sheen"})
    assert not brk.is_hidden("sheenColor", True) and brk.is_hidden("coat", True)


def test_an_old_document_without_the_setting_loads_with_base_open(view):
    text = dumps(view.controller.document)
    assert nodes.EXPANDED_GROUPS not in text  # never set, never written
    doc = loads(text)
    assert nodes.EXPANDED_GROUPS not in doc.graph.nodes["make"].settings
    v2 = NodeCanvasView(DocumentController(doc))
    assert v2.scene().node_items["make"].expanded == frozenset({"Base"})


def test_a_new_node_shows_only_base_and_copy_paste_keeps_the_setting(view, qtbot):
    c = view.controller
    c.push(AddNode(Node("m2", "make_attributes", (300, 600))))
    assert item(view, "m2").expanded == frozenset({"Base"})
    view.scene().set_group_expanded("m2", "Anisotropy", True)
    ids = view.scene().node_items
    view.select_nodes(["m2"])
    new = view.duplicate_selection()
    assert len(new) == 1 and new[0] in ids
    assert c.document.graph.nodes[new[0]].settings[nodes.EXPANDED_GROUPS] == [
        "Base", "Anisotropy"]
    assert item(view, new[0]).expanded == frozenset({"Base", "Anisotropy"})


def test_a_wire_dragged_over_a_folded_header_opens_it_and_connects(view):
    c = view.controller
    scene = view.scene()

    def sheen_roughness(v):
        return v.mapFromScene(item(v, "make").port_scene_pos("sheenRoughness", False))
    _hover_then(view, "Sheen", sheen_roughness)  # opened while the wire hovers
    assert Link("r", "value", "make", "sheenRoughness") in c.document.graph.links
    assert Link("r", "value", "make", "sheenRoughness") in scene.wire_items
    # The group the wire went into stays open, saved with the connection as one undo step.
    assert "Sheen" in c.document.graph.nodes["make"].settings[nodes.EXPANDED_GROUPS]
    c.undo_stack.undo()
    QApplication.processEvents()
    assert Link("r", "value", "make", "sheenRoughness") not in c.document.graph.links
    assert "Sheen" not in item(view, "make").expanded


def _hover_then(view, group: str, release_at) -> None:
    """Drag a wire from a new parameter over `group`'s folded header, then release it at
    `release_at(view)` (a viewport point) or, for None, press Escape mid-drag."""
    view.controller.push(AddNode(Node("r", "scalar_parameter", (0, 400), {"name": "r"},
                                      {"value": 0.2})))
    QApplication.processEvents()
    src = view.mapFromScene(item(view, "r").port_scene_pos("value", True))
    it = item(view, "make")
    _, y = header(it, group)
    over = view.mapFromScene(it.pos() + QPointF(it.layout.width / 2, y))
    vp = view.viewport()
    QTest.mousePress(vp, LEFT, Qt.KeyboardModifier.NoModifier, src)
    for i in range(1, 7):
        p = QPointF(src) + (QPointF(over) - QPointF(src)) * (i / 6)
        QApplication.sendEvent(vp, QMouseEvent(QEvent.Type.MouseMove, p,
                                                QPointF(vp.mapToGlobal(p.toPoint())),
                                                Qt.MouseButton.NoButton, LEFT,
                                                Qt.KeyboardModifier.NoModifier))
    assert group in it.expanded
    if release_at is None:
        QTest.keyClick(vp, Qt.Key.Key_Escape)
        QTest.mouseRelease(vp, LEFT, Qt.KeyboardModifier.NoModifier, over)
    else:
        QTest.mouseRelease(vp, LEFT, Qt.KeyboardModifier.NoModifier, release_at(view))
    QApplication.processEvents()


@pytest.mark.parametrize("how", ["base pin", "escape"])
def test_a_group_a_passing_wire_opened_folds_back_without_an_undo_step(view, how):
    c = view.controller
    before = c.undo_stack.count()

    def base_pin(v):
        return v.mapFromScene(item(v, "make").port_scene_pos("roughness", False))
    _hover_then(view, "Sheen", base_pin if how == "base pin" else None)
    it = item(view, "make")
    assert "Sheen" not in it.expanded
    assert "Sheen" not in c.document.graph.nodes["make"].settings.get(
        nodes.EXPANDED_GROUPS, ["Base"])
    assert {"sheenColor", "sheenRoughness"}.isdisjoint(visible_inputs(it))
    if how == "base pin":  # the connection alone is the undo step after the new node
        assert Link("r", "value", "make", "roughness") in c.document.graph.links
        assert c.undo_stack.count() == before + 2
        c.undo_stack.undo()
        assert Link("r", "value", "make", "roughness") not in c.document.graph.links
    else:
        assert c.undo_stack.count() == before + 1


def test_folded_pins_take_no_clicks(view):
    it = item(view, "make")
    from matedit.app.canvas.interaction import port_at
    _, y = header(it, "Coat")
    at = it.pos() + QPointF(0.0, y)
    port = port_at(view.scene(), at, 8.0)
    assert port is None or not it.is_hidden(port.name, port.is_output)


def test_zooming_out_and_back_keeps_folded_pins_hidden(view):
    """The LOD hides every port item when far out; coming back shows only unfolded ones."""
    scene, it = view.scene(), item(view, "make")
    scene.set_zoom(C.LOD_PORTS / 2)
    assert visible_inputs(it) == set()
    scene.set_zoom(1.0)
    assert visible_inputs(it) == {f.name for f in nodes.ATTRIBUTE_FIELDS if f.group == "Base"}
