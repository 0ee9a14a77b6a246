"""A reroute: a wire waypoint drawn as a small dot in the colour of what flows through it."""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF
from PySide6.QtGui import QPainter, QPainterPath, QPen
from PySide6.QtWidgets import QStyleOptionGraphicsItem

from matedit.app.canvas import constants as C
from matedit.app.canvas.node_item import NodeItem, NodeLayout


class RerouteItem(NodeItem):
    """A round node: its input on the left of the dot, its output on the right."""

    def _relayout(self) -> None:
        r = C.REROUTE_RADIUS
        super()._relayout()
        self.layout = NodeLayout(2 * r, 2 * r, 0.0)
        self.setRect(QRectF(-4, -4, 2 * r + 8, 2 * r + 8))
        self.layout.inputs = {p.name: QPointF(0.0, r) for p in self.inputs}
        self.layout.outputs = {p.name: QPointF(2 * r, r) for p in self.outputs}
        for port in self.ports():
            table = self.layout.outputs if port.is_output else self.layout.inputs
            port.setPos(table[port.name])
        if self._badge is not None:
            self._badge.setPos(r, -r)
        self.update()
        scene = self.scene()
        if scene is not None and hasattr(scene, "node_geometry_changed"):
            scene.node_geometry_changed(self.node_id)

    def _place_badge(self) -> None:
        if self._badge is not None:
            self._badge.setPos(C.REROUTE_RADIUS, -C.REROUTE_RADIUS)

    def set_preview(self, image) -> None:  # a waypoint has no preview
        return

    def shape(self) -> QPainterPath:
        path = QPainterPath()
        r = C.REROUTE_RADIUS
        path.addEllipse(QPointF(r, r), r + 3, r + 3)
        return path

    def paint(self, painter: QPainter, option: QStyleOptionGraphicsItem, widget=None) -> None:
        r = C.REROUTE_RADIUS
        t = self.outputs[0].type if self.outputs else "T"
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.setPen(QPen(C.NODE_SELECTED if self.isSelected() else
                            (C.ERROR if self.has_error() else C.NODE_BODY_EDGE), 2.0))
        painter.setBrush(C.port_color(t))
        painter.drawEllipse(QPointF(r, r), r, r)
