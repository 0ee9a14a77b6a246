"""A port: the hit target and hover highlight at one input or output of a node.

The port's resting shape is drawn by its node (inside the node's cached pixmap),
so a thousand-node canvas does not paint four thousand little items per frame;
the port item itself draws only while highlighted (hover, or as a wire's target).
"""

from __future__ import annotations

from functools import cache

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QGraphicsItem

from matedit.app.canvas import constants as C


def port_shape(painter: QPainter, center: QPointF, type_name: str, radius: float,
               filled: bool) -> None:
    """Draw a port marker: a circle, or a diamond (MaterialAttributes), or a square (texture)."""
    painter.setPen(_port_pen(type_name))
    painter.setBrush(_port_brush(type_name, filled))
    shape = C.PORT_SHAPES.get(type_name, "circle")
    x, y, r = center.x(), center.y(), radius
    if shape == "diamond":
        r += 0.8
        painter.drawPolygon(QPolygonF([QPointF(x, y - r), QPointF(x + r, y), QPointF(x, y + r),
                                       QPointF(x - r, y)]))
    elif shape == "square":
        painter.drawRect(QRectF(x - r + 0.6, y - r + 0.6, 2 * r - 1.2, 2 * r - 1.2))
    else:
        painter.drawEllipse(center, r, r)


@cache
def _port_pen(type_name: str) -> QPen:
    """The outline of a port of this type (made once: every node paint draws its ports)."""
    return QPen(C.port_color(type_name), 1.4)


@cache
def _port_brush(type_name: str, filled: bool) -> QBrush:
    """A port's fill: its type's colour where wired, the node's body where not."""
    return QBrush(C.port_color(type_name)) if filled else QBrush(C.NODE_BODY)


class PortItem(QGraphicsItem):
    """One input or output of a node; a child of its NodeItem, centred on the port."""

    NONE, HOVER, ALLOWED, REFUSED = range(4)

    def __init__(self, parent: QGraphicsItem, node_id: str, name: str, is_output: bool,
                 type_name: str, doc: str = "") -> None:
        super().__init__(parent)
        self.node_id = node_id
        self.name = name
        self.is_output = is_output
        self.type_name = type_name
        self.doc = doc
        self.generic = False  # declared `T` (the scene's analysis resolves type_name)
        self._state = PortItem.NONE
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemHasNoContents, True)
        self.setAcceptHoverEvents(True)
        self.setCursor(Qt.CursorShape.CrossCursor)

    def tooltip_text(self) -> str:
        """Made when asked (the scene's help event): thousands of ports, few tooltips."""
        side = "output" if self.is_output else "input"
        tip = f"<b>{self.name}</b> &nbsp;<i>{self.type_name}</i> {side}"
        if self.doc:
            tip += f"<br>{self.doc}"
        return tip

    def set_type(self, type_name: str) -> None:
        self.type_name = type_name

    @property
    def key(self) -> tuple[str, str, bool]:
        return (self.node_id, self.name, self.is_output)

    def set_state(self, state: int) -> None:
        if state == self._state:
            return
        self._state = state
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemHasNoContents, state == PortItem.NONE)
        self.update()

    def state(self) -> int:
        return self._state

    # --- QGraphicsItem -----------------------------------------------------------------------
    def boundingRect(self) -> QRectF:
        r = C.PORT_RADIUS + 4.0
        return QRectF(-r, -r, 2 * r, 2 * r)

    def hoverEnterEvent(self, event) -> None:
        if self._state == PortItem.NONE:
            self.set_state(PortItem.HOVER)
        super().hoverEnterEvent(event)

    def hoverLeaveEvent(self, event) -> None:
        if self._state == PortItem.HOVER:
            self.set_state(PortItem.NONE)
        super().hoverLeaveEvent(event)

    def paint(self, painter: QPainter, option, widget=None) -> None:
        ring = {PortItem.HOVER: C.port_color(self.type_name), PortItem.ALLOWED: C.ALLOWED,
                PortItem.REFUSED: C.REFUSED}.get(self._state)
        if ring is None:
            return
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        port_shape(painter, QPointF(0, 0), self.type_name, C.PORT_RADIUS + 1.0, True)
        painter.setPen(QPen(QColor(ring), 2.0))
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawEllipse(QPointF(0, 0), C.PORT_RADIUS + 3.0, C.PORT_RADIUS + 3.0)
