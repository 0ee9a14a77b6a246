"""The wire being dragged from a port, before it is a link in the model."""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen
from PySide6.QtWidgets import QGraphicsItem

from matedit.app.canvas import constants as C
from matedit.app.canvas.wire_item import wire_path


class LiveWire(QGraphicsItem):
    """A curve from a fixed port to the cursor; solid while a drop would be allowed."""

    def __init__(self, anchor: QPointF, anchor_is_output: bool, type_name: str) -> None:
        super().__init__()
        self.anchor = QPointF(anchor)
        self.anchor_is_output = anchor_is_output
        self.type_name = type_name
        self.end = QPointF(anchor)
        self.verdict: bool | None = None  # None: not over a port
        self._path = QPainterPath()
        self._bounds = QRectF()
        self.setZValue(C.Z_LIVE_WIRE)
        self.setAcceptedMouseButtons(Qt.MouseButton.NoButton)
        self._rebuild()

    def set_end(self, end: QPointF, verdict: bool | None) -> None:
        self.end = QPointF(end)
        self.verdict = verdict
        self._rebuild()

    def _rebuild(self) -> None:
        self.prepareGeometryChange()
        if self.anchor_is_output:
            self._path = wire_path(self.anchor, self.end)
        else:
            self._path = wire_path(self.end, self.anchor)
        m = C.WIRE_WIDTH_STRUCT + 4
        self._bounds = self._path.controlPointRect().adjusted(-m, -m, m, m)
        self.update()

    def path(self) -> QPainterPath:
        return self._path

    def boundingRect(self) -> QRectF:
        return self._bounds

    def paint(self, painter: QPainter, option, widget=None) -> None:
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        color = QColor(C.port_color(self.type_name))
        style = Qt.PenStyle.SolidLine
        if self.verdict is False:
            color, style = QColor(C.REFUSED), Qt.PenStyle.DashLine
        elif self.verdict is None:
            style = Qt.PenStyle.DashLine
        painter.setPen(QPen(color, C.wire_width(self.type_name), style, Qt.PenCapStyle.RoundCap))
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawPath(self._path)
        painter.setBrush(color)
        painter.setPen(Qt.PenStyle.NoPen)
        painter.drawEllipse(self.end, 3.0, 3.0)
