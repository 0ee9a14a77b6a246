"""A wire: a cubic curve from an output port to an input port, coloured by what it carries.

Wires are the most numerous items, so they draw in C++: a QGraphicsPathItem whose pen
the scene sets (type colour, error dashes, selection, a hairline when zoomed far out),
with no Python `paint` or `boundingRect` called per frame. Only `shape`, for clicks,
is ours: a wider band than the stroke, so a wire is easy to pick.
"""

from __future__ import annotations

from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QColor, QPainterPath, QPainterPathStroker, QPen
from PySide6.QtWidgets import QGraphicsPathItem

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


def wire_pen(type_name: str, error: bool, selected: bool, hairline: bool) -> QPen:
    """Flat caps and hairlines matter: on the raster engine a round-capped antialiased
    stroke costs half as much again, and a wide stroke several times a hairline."""
    width = C.wire_width(type_name)
    if selected:
        pen = QPen(C.WIRE_SELECTED, width + 1.5, Qt.PenStyle.SolidLine, Qt.PenCapStyle.FlatCap)
    else:
        color = QColor(C.ERROR if error else C.port_color(type_name))
        style = Qt.PenStyle.DashLine if error else Qt.PenStyle.SolidLine
        pen = QPen(color, width, style, Qt.PenCapStyle.FlatCap)
    if hairline:
        pen.setWidthF(1.5 if selected else 1.0)
        pen.setCosmetic(True)
    return pen


class WireItem(QGraphicsPathItem):
    """The view of one model `Link`; its path follows the two node items it joins."""

    def __init__(self, link: Link, src_item, dst_item, hairline: bool = False) -> None:
        super().__init__()
        self.link = link
        self.src_item = src_item
        self.dst_item = dst_item
        self.type_name = "T"
        self.error = False
        self.selected = False  # the scene's wire selection (wires skip Qt's rubber band)
        self.hairline = hairline
        self._shape: QPainterPath | None = None
        self.setZValue(C.Z_WIRE)
        self.setAcceptedMouseButtons(Qt.MouseButton.LeftButton)
        self._restyle()
        self.update_path()

    def update_path(self) -> None:
        p1 = self.src_item.port_scene_pos(self.link.src_port, True)
        p2 = self.dst_item.port_scene_pos(self.link.dst_port, False)
        self._shape = None
        self.setPath(wire_path(p1, p2))

    def _restyle(self) -> None:
        self.setPen(wire_pen(self.type_name, self.error, self.selected, self.hairline))

    def set_style(self, type_name: str, error: bool) -> None:
        if (type_name, error) != (self.type_name, self.error):
            self.type_name, self.error = type_name, error
            self._restyle()

    def set_selected(self, selected: bool) -> None:
        if selected != self.selected:
            self.selected = selected
            self.setZValue(C.Z_WIRE + (0.5 if selected else 0.0))
            self._restyle()

    def set_hairline(self, hairline: bool) -> None:
        if hairline != self.hairline:
            self.hairline = hairline
            self._restyle()

    def shape(self) -> QPainterPath:
        if self._shape is None:
            stroker = QPainterPathStroker()
            stroker.setWidth(C.WIRE_HIT_WIDTH)
            self._shape = stroker.createStroke(self.path())
        return self._shape
