"""A wire: a cubic curve from an output port to an input port, coloured by what it carries."""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPainterPathStroker, QPen
from PySide6.QtWidgets import QGraphicsItem, QStyleOptionGraphicsItem

from matedit.app.canvas import constants as C
from matedit.graph.model import Link


def wire_path(p1: QPointF, p2: QPointF) -> QPainterPath:
    """A horizontal-tangent cubic from p1 (an output) to p2 (an input).

    The handles grow with the horizontal distance, and more when the wire runs
    backwards, so a wire to a node on the left loops round instead of folding flat.
    """
    dx = p2.x() - p1.x()
    dy = abs(p2.y() - p1.y())
    handle = max(30.0, abs(dx) * 0.5) if dx >= 0 else max(60.0, min(-dx * 0.6 + dy * 0.25, 300.0))
    path = QPainterPath(p1)
    path.cubicTo(QPointF(p1.x() + handle, p1.y()), QPointF(p2.x() - handle, p2.y()), p2)
    return path


class WireItem(QGraphicsItem):
    """The view of one model `Link`; its path follows the two node items it joins."""

    def __init__(self, link: Link, src_item, dst_item) -> None:
        super().__init__()
        self.link = link
        self.src_item = src_item
        self.dst_item = dst_item
        self.type_name = "T"
        self.error = False
        self._path = QPainterPath()
        self._shape: QPainterPath | None = None
        self._bounds = QRectF()
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIsSelectable)
        self.setZValue(C.Z_WIRE)
        self.setAcceptedMouseButtons(Qt.MouseButton.LeftButton)
        self.update_path()

    def update_path(self) -> None:
        p1 = self.src_item.port_scene_pos(self.link.src_port, True)
        p2 = self.dst_item.port_scene_pos(self.link.dst_port, False)
        self.prepareGeometryChange()
        self._path = wire_path(p1, p2)
        self._shape = None
        m = C.WIRE_WIDTH_STRUCT + 3
        self._bounds = self._path.controlPointRect().adjusted(-m, -m, m, m)

    def set_style(self, type_name: str, error: bool) -> None:
        if (type_name, error) != (self.type_name, self.error):
            self.type_name, self.error = type_name, error
            self.update()

    def path(self) -> QPainterPath:
        return self._path

    def boundingRect(self) -> QRectF:
        return self._bounds

    def shape(self) -> QPainterPath:
        if self._shape is None:
            stroker = QPainterPathStroker()
            stroker.setWidth(C.WIRE_HIT_WIDTH)
            self._shape = stroker.createStroke(self._path)
        return self._shape

    def itemChange(self, change, value):
        # A rubber band selects nodes, not the wires that happen to cross it.
        if (change == QGraphicsItem.GraphicsItemChange.ItemSelectedChange and value
                and getattr(self.scene(), "rubber_banding", False)):
            return False
        return super().itemChange(change, value)

    def paint(self, painter: QPainter, option: QStyleOptionGraphicsItem, widget=None) -> None:
        lod = QStyleOptionGraphicsItem.levelOfDetailFromTransform(painter.worldTransform())
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, lod > 0.25)
        width = C.wire_width(self.type_name)
        color = QColor(C.port_color(self.type_name))
        if self.isSelected():
            painter.setPen(QPen(C.WIRE_SELECTED, width + 3.0, Qt.PenStyle.SolidLine,
                                Qt.PenCapStyle.RoundCap))
            painter.drawPath(self._path)
        if self.error:
            pen = QPen(C.ERROR, width, Qt.PenStyle.DashLine, Qt.PenCapStyle.RoundCap)
        else:
            pen = QPen(color, width, Qt.PenStyle.SolidLine, Qt.PenCapStyle.RoundCap)
        painter.setPen(pen)
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawPath(self._path)
