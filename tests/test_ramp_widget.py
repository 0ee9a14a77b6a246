"""The Colour Ramp stops editor: add, move (clamped between neighbours), recolour, remove,
each an undoable value edit of the node, and the bar shows the node's own evaluation."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import material, node
from PySide6.QtCore import QPoint, Qt

from matedit.app.controller import MANY_VALUES, DocumentController
from matedit.app.ramp_widget import RampEditor, RampStops

pytestmark = pytest.mark.gui


@pytest.fixture
def editor(qtbot):
    doc = material()
    node(doc, "ramp", "color_ramp", values={
        "stops": 3.0, "position0": 0.0, "position1": 0.5, "position2": 1.0,
        "color0": [1.0, 0.0, 0.0], "color1": [0.0, 1.0, 0.0], "color2": [0.0, 0.0, 1.0]})
    controller = DocumentController(doc)
    e = RampEditor(controller, "ramp")
    qtbot.addWidget(e)
    e.resize(320, 90)
    e.show()
    qtbot.waitExposed(e)
    return e


def _values(e):
    return e.controller.document.graph.nodes["ramp"].values


def test_stops_evaluate_like_the_node():
    s = RampStops({"stops": 3.0, "position1": 0.25, "color1": [0.0, 1.0, 0.0]})
    out = s.evaluate(np.array([0.0, 0.125, 0.25, 0.625, 1.0]))
    np.testing.assert_allclose(out[:, 1], [0.0, 0.5, 1.0, 1.0, 1.0])  # to green, then white
    np.testing.assert_allclose(out[:, 0], [0.0, 0.0, 0.0, 0.5, 1.0])


def test_double_click_adds_a_stop_with_the_ramp_colour_there(editor, qtbot):
    x = int(editor.bar.x_of(0.25))
    qtbot.mouseDClick(editor.bar, Qt.MouseButton.LeftButton, pos=QPoint(x, 10))
    v = _values(editor)
    assert v["stops"] == 4.0
    assert abs(v["position1"] - 0.25) < 0.01 and v["position2"] == 0.5
    np.testing.assert_allclose(v["color1"], [0.5, 0.5, 0.0], atol=0.02)  # red-green halfway
    assert editor.bar.current == 1
    editor.controller.undo_stack.undo()
    assert _values(editor)["stops"] == 3.0 and _values(editor)["position1"] == 0.5


def test_drag_moves_a_stop_between_its_neighbours_as_one_undo_step(editor, qtbot):
    bar = editor.bar
    y = int(bar.height() - 6)
    start = QPoint(int(bar.x_of(0.5)), y)
    qtbot.mousePress(bar, Qt.MouseButton.LeftButton, pos=start)
    for pos in (0.6, 0.8, 1.2):  # past the last stop: stops at its neighbour
        qtbot.mouseMove(bar, QPoint(int(bar.x_of(min(pos, 1.0)) + (40 if pos > 1 else 0)), y))
    qtbot.mouseRelease(bar, Qt.MouseButton.LeftButton, pos=QPoint(int(bar.x_of(1.0)), y))
    assert _values(editor)["position1"] == pytest.approx(1.0, abs=0.01)
    editor.controller.undo_stack.undo()
    assert _values(editor)["position1"] == 0.5


def test_remove_and_recolour(editor):
    editor.bar.current = 1
    editor.remove_stop()
    v = _values(editor)
    assert v["stops"] == 2.0 and v["position1"] == 1.0 and v["color1"] == [0.0, 0.0, 1.0]
    assert not editor.remove_button.isEnabled()
    editor.remove_stop()  # two stops stay
    assert _values(editor)["stops"] == 2.0
    editor.bar.current = 0
    editor._recolour([0.2, 0.3, 0.4])
    assert _values(editor)["color0"] == [0.2, 0.3, 0.4]


def test_inspector_shows_the_editor_for_ramps(qtbot, tmp_path):
    from matedit.app.inspector import InspectorPanel

    doc = material()
    node(doc, "ramp", "color_ramp")
    controller = DocumentController(doc)
    panel = InspectorPanel(controller)
    qtbot.addWidget(panel)
    panel.show_node("ramp")
    assert panel.findChild(RampEditor) is not None
    panel.resize(340, 700)
    panel.show()
    qtbot.waitExposed(panel)
    panel.grab().save(str(tmp_path / "ramp_inspector.png"))


def test_a_closed_editor_ignores_later_edits(qtbot):
    from PySide6.QtWidgets import QApplication

    doc = material()
    node(doc, "ramp", "color_ramp")
    controller = DocumentController(doc)
    e = RampEditor(controller, "ramp")
    e.deleteLater()
    QApplication.processEvents()
    from PySide6.QtCore import QCoreApplication, QEvent

    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    controller.valuesChanged.emit(MANY_VALUES)  # must not reach the deleted widget
    del e
