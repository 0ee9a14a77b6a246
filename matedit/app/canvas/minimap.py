"""The minimap: the whole graph in miniature with the visible rectangle; click to go there.

The nodes are drawn once into a pixmap, redrawn (debounced) only when the scene
changes, so scrolling the canvas repaints just the visible-rectangle frame.
"""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, Qt, QTimer
from PySide6.QtGui import QColor, QPainter, QPen, QPixmap
from PySide6.QtWidgets import QGraphicsView, QWidget

from matedit.app.canvas import constants as C


class MiniMap(QWidget):
    def __init__(self, view: QGraphicsView) -> None:
        super().__init__(view)
        self.view = view
        self.resize(200, 130)
        self.setCursor(Qt.CursorShape.PointingHandCursor)
        self.setToolTip("Overview: click or drag to move the view")
        self._pixmap: QPixmap | None = None
        self._world = QRectF()
        self._dirty = QTimer(self)
        self._dirty.setSingleShot(True)
        self._dirty.setInterval(120)
        self._dirty.timeout.connect(self._render)
        self._dragging = False

    def invalidate(self) -> None:
        self._dirty.start()

    def _mapping(self) -> tuple[float, QPointF]:
        """Scale and offset from scene to minimap coordinates."""
        w = self._world
        if w.isEmpty():
            return 1.0, QPointF()
        pad = 6.0
        s = min((self.width() - 2 * pad) / w.width(), (self.height() - 2 * pad) / w.height())
        off = QPointF((self.width() - w.width() * s) / 2 - w.left() * s,
                      (self.height() - w.height() * s) / 2 - w.top() * s)
        return s, off

    def _render(self) -> None:
        scene = self.view.scene()
        world = scene.nodes_bounding_rect()
        if world.isEmpty():
            world = QRectF(-200, -150, 400, 300)
        m = max(world.width(), world.height()) * 0.05 + 40
        self._world = world.adjusted(-m, -m, m, m)
        s, off = self._mapping()
        pm = QPixmap(self.size())
        pm.fill(Qt.GlobalColor.transparent)
        p = QPainter(pm)
        p.translate(off)
        p.scale(s, s)
        for c in scene.comment_items.values():
            col = QColor(c.color)
            col.setAlpha(70)
            p.fillRect(c.scene_rect(), col)
        for item in scene.node_items.values():
            r = item.sceneBoundingRect()
            p.fillRect(r, C.category_color(item.category).lighter(120))
        p.end()
        self._pixmap = pm
        self.update()

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self.invalidate()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        p.setPen(QPen(QColor("#3d4350"), 1.0))
        p.setBrush(C.MINIMAP_BG)
        p.drawRoundedRect(QRectF(self.rect()).adjusted(0.5, 0.5, -0.5, -0.5), 5, 5)
        if self._pixmap is not None:
            p.drawPixmap(0, 0, self._pixmap)
        s, off = self._mapping()
        vis = self.view.mapToScene(self.view.viewport().rect()).boundingRect()
        r = QRectF(vis.left() * s + off.x(), vis.top() * s + off.y(), vis.width() * s,
                   vis.height() * s).intersected(QRectF(self.rect()).adjusted(1, 1, -1, -1))
        p.setPen(QPen(C.MINIMAP_VIEW, 1.5))
        view_fill = QColor(C.MINIMAP_VIEW)
        view_fill.setAlpha(30)
        p.setBrush(view_fill)
        p.drawRect(r)

    def _go(self, pos: QPointF) -> None:
        s, off = self._mapping()
        self.view.centerOn((pos - off) / s)

    def mousePressEvent(self, event) -> None:
        if event.button() == Qt.MouseButton.LeftButton:
            self._dragging = True
            self._go(event.position())
        event.accept()

    def mouseMoveEvent(self, event) -> None:
        if self._dragging:
            self._go(event.position())
        event.accept()

    def mouseReleaseEvent(self, event) -> None:
        self._dragging = False
        event.accept()
