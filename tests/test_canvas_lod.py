"""Zoomed out, node titles stay readable: they are drawn larger, and port labels are hidden.

Real items under Xvfb. What the item paints is recorded through a painter that forwards every
call to a real QPainter (so the drawing itself is Qt's), and the pixels are checked as well.
"""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import pytest  # noqa: E402
from PySide6.QtGui import QColor, QImage, QPainter  # noqa: E402
from PySide6.QtWidgets import QStyleOptionGraphicsItem  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas import constants as C  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.graph.model import Link, MaterialDocument, Node  # noqa: E402

pytestmark = pytest.mark.gui


class RecordingPainter:
    """Forwards to a QPainter and notes each drawText with the pixel size of the font in use."""

    def __init__(self, painter: QPainter) -> None:
        self._p = painter
        self.texts: list[tuple[str, int]] = []

    def drawText(self, *args):  # noqa: N802 (Qt's name)
        self.texts.append((str(args[-1]), self._p.font().pixelSize()))
        return self._p.drawText(*args)

    def __getattr__(self, name):
        return getattr(self._p, name)


def _material() -> MaterialDocument:
    doc = MaterialDocument(name="lod")
    g = doc.graph
    g.nodes["p"] = Node("p", "scalar_parameter", (0, 0), {"name": "p"}, {"value": 0.5})
    g.nodes["mul"] = Node("mul", "multiply", (250, 0))
    g.links.add(Link("p", "value", "mul", "a"))
    return doc


@pytest.fixture
def item(qtbot):
    v = NodeCanvasView(DocumentController(_material()))
    qtbot.addWidget(v)
    v.resize(600, 400)
    v.show()
    qtbot.waitExposed(v)
    return v.scene().node_items["mul"]


def _paint(item, zoom: float) -> tuple[QImage, list[tuple[str, int]]]:
    """The item painted alone at `zoom` (device pixels per scene unit) on black."""
    r = item.boundingRect()
    img = QImage(int(r.width() * zoom) + 4, int(r.height() * zoom) + 4,
                 QImage.Format.Format_ARGB32)
    img.fill(QColor("black"))
    p = QPainter(img)
    p.scale(zoom, zoom)
    p.translate(-r.left(), -r.top())
    rec = RecordingPainter(p)
    item.paint(rec, QStyleOptionGraphicsItem())
    p.end()
    return img, rec.texts


def _text_rows(img: QImage) -> int:
    """Rows holding title-coloured pixels (near white; the block and ports are darker)."""
    rows = 0
    for y in range(img.height()):
        if any(QColor(img.pixel(x, y)).lightness() > 200 for x in range(img.width())):
            rows += 1
    return rows


def test_zoomed_out_title_is_larger_and_port_labels_hidden(item):
    port_names = {"a", "b", "result"}
    _, near = _paint(item, 1.0)
    drawn = {t for t, _ in near}
    assert port_names <= drawn  # at zoom 1 every port is labelled
    assert ("Multiply", C.TITLE_PX) in near

    zoom = 0.35
    img, far = _paint(item, zoom)
    assert far, "zoomed out, the title is still drawn"
    assert not port_names & {t for t, _ in far}
    # Every title line is at least LOD_TITLE_MIN_PX on screen (font size in scene units
    # times the zoom), where the header font would be 12 * 0.35 = 4.2 px.
    for _, px in far:
        assert px * zoom >= C.LOD_TITLE_MIN_PX - 0.5
    assert " ".join(t for t, _ in far).replace("…", "") in "Multiply"
    # The pixels agree: the title's glyphs span at least 6 device rows (cap height of a
    # 8.5 px DejaVu face is about 6 px; the 4 px header font would give 3 or 4).
    assert _text_rows(img) >= 6


def test_overview_title_wraps_to_fit_and_elides_only_as_a_last_resort(item):
    zoom = 0.35
    px, lines = item.overview_title(zoom)
    fm = C.overview_metrics(px)
    inner_w = item.layout.width - 2 * max(C.PORT_RADIUS + 1.0, 2.0 / zoom)
    assert all(fm.horizontalAdvance(t) <= inner_w + 0.5 for t in lines)
    item.set_content("Very Long Title Of Many Words", "", "Math", item.inputs, item.outputs)
    px2, lines2 = item.overview_title(zoom)
    assert lines2 and len(lines2) * C.overview_metrics(px2).lineSpacing() <= item.layout.height
    assert px2 <= px or len(lines2) > 1


def test_detail_zoom_header_title_keeps_a_minimum_screen_size():
    for lod in (1.0, 0.8, 0.6):
        px = C.header_title_px(lod)
        assert px >= C.TITLE_PX
        assert px <= C.HEADER_HEIGHT - 4
        assert px * lod >= min(C.LOD_TITLE_MIN_PX, (C.HEADER_HEIGHT - 4) * lod) - 1
