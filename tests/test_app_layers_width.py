"""The Layers panel's blend-mode menu reads in a narrow dock (issue 23).

Real widgets under Xvfb: the varnished oak sample (a coat layer over the oak stack) in a
Layers panel as narrow as the default window's left dock gives it.
"""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import pytest  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matedit.app.controller import DocumentController  # noqa: E402
from matedit.app.layers_panel import LayersPanel, _LayerRow, blend_modes  # noqa: E402
from matedit.io.document import load  # noqa: E402

pytestmark = pytest.mark.gui
SAMPLE = os.path.join(os.path.dirname(__file__), "..", "graphs", "materials",
                      "varnished_oak.json")


@pytest.mark.parametrize("width", [240, 300])
def test_the_blend_menu_has_its_own_row_and_its_list_shows_whole_titles(qtbot, width):
    panel = LayersPanel(DocumentController(load(SAMPLE)))
    qtbot.addWidget(panel)
    panel.resize(width, 500)
    panel.show()
    qtbot.waitExposed(panel)
    QApplication.processEvents()
    rows = [r for r in panel.findChildren(_LayerRow) if r.blend.isEnabled()]
    assert rows, "the sample has layers above its base"
    titles = [t for _, t, _ in blend_modes()]
    for row in rows:
        combo = row.blend
        fm = combo.fontMetrics()
        # Below the name, not beside it: the combo starts under the eye button's row.
        assert combo.geometry().top() >= row.name.geometry().bottom()
        # The current mode's title fits the closed combo (30 px for the arrow and frame).
        assert combo.width() >= fm.horizontalAdvance(combo.currentText()) + 30
        assert combo.view().minimumWidth() >= max(fm.horizontalAdvance(t) for t in titles)
