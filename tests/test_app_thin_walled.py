"""The Material Output's thin_walled setting in the Inspector (docs/shading.md, Transmission)."""

from __future__ import annotations

import pytest
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def test_thin_walled_is_a_checkbox_of_the_material_output_and_recompiles(qtbot):
    from PySide6.QtCore import QPointF
    from PySide6.QtWidgets import QCheckBox

    w = make_window(qtbot)
    out = w.tabs.material.canvas.add_node_at("material_output", QPointF(0, 0))
    w.inspector.show_node(out)
    settle(qtbot, w)
    boxes = [b for b in w.inspector.widget().findChildren(QCheckBox)
             if "thin-walled" in b.toolTip()]
    assert len(boxes) == 1 and not boxes[0].isChecked()
    hits = []
    w.controller.structureChanged.connect(lambda: hits.append(1))
    boxes[0].setChecked(True)
    settle(qtbot, w, 10)
    assert w.controller.document.graph.nodes[out].settings["thin_walled"] is True
    assert hits  # structural: MATERIAL_THIN_WALLED is a define
    w.controller.undo_stack.undo()
    settle(qtbot, w, 10)
    assert not w.controller.document.graph.nodes[out].settings.get("thin_walled", False)
