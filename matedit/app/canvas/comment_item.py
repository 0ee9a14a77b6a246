"""A comment frame: a titled, tinted rectangle behind nodes.

Dragging its title bar moves the frame and the nodes inside it; the grip in the
bottom-right corner resizes it. The item only previews the drag: on release it
hands the new rectangle and node positions to the scene, which pushes one undo
command, and the model's events then place everything for good.
"""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import QGraphicsItem, QStyleOptionGraphicsItem

from matedit.app.canvas import constants as C
from matedit.graph.model import Comment

_BORDER = 6.0


class CommentItem(QGraphicsItem):
    """The view of one model `Comment`; positioned at its rectangle's top-left corner."""

    def __init__(self, comment_id: str) -> None:
        super().__init__()
        self.comment_id = comment_id
        self.text = ""
        self.color = QColor(80, 80, 80)
        self.size = (200.0, 120.0)
        self._drag: dict | None = None
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIsSelectable)
        self.setZValue(C.Z_COMMENT)
        self.setCacheMode(QGraphicsItem.CacheMode.DeviceCoordinateCache)

    def set_content(self, comment: Comment) -> None:
        self.prepareGeometryChange()
        x, y, w, h = comment.rect
        self.setPos(x, y)
        self.size = (max(w, 60.0), max(h, C.COMMENT_HEADER + 20))
        self.text = comment.text
        r, g, b = (min(max(float(c), 0.0), 1.0) for c in comment.color)
        self.color = QColor.fromRgbF(r, g, b)
        self.update()

    def scene_rect(self) -> QRectF:
        return QRectF(self.pos(), QPointF(self.pos().x() + self.size[0],
                                          self.pos().y() + self.size[1]))

    # --- geometry ----------------------------------------------------------------------------
    def boundingRect(self) -> QRectF:
        return QRectF(-1, -1, self.size[0] + 2, self.size[1] + 2)

    def _grip(self) -> QRectF:
        w, h = self.size
        return QRectF(w - C.COMMENT_GRIP, h - C.COMMENT_GRIP, C.COMMENT_GRIP, C.COMMENT_GRIP)

    def shape(self) -> QPainterPath:
        """Title bar, frame and grip: a click inside the frame reaches the canvas (rubber band)."""
        w, h = self.size
        outer = QPainterPath()
        outer.addRect(QRectF(0, 0, w, h))
        inner = QPainterPath()
        inner.addRect(QRectF(_BORDER, C.COMMENT_HEADER, w - 2 * _BORDER,
                             h - C.COMMENT_HEADER - _BORDER))
        path = outer.subtracted(inner)
        path.addRect(self._grip())
        return path

    # --- dragging ----------------------------------------------------------------------------
    def mousePressEvent(self, event) -> None:
        if event.button() != Qt.MouseButton.LeftButton:
            event.ignore()
            return
        scene = self.scene()
        if not (event.modifiers() & Qt.KeyboardModifier.ControlModifier):
            scene.clearSelection()
        self.setSelected(True)
        resize = self._grip().contains(event.pos())
        inside = [] if resize else scene.node_items_in(self.scene_rect())
        self._drag = {"start": event.scenePos(), "pos": QPointF(self.pos()),
                      "size": self.size, "resize": resize,
                      "nodes": {it.node_id: QPointF(it.pos()) for it in inside}}
        event.accept()

    def mouseMoveEvent(self, event) -> None:
        if self._drag is None:
            return
        delta = event.scenePos() - self._drag["start"]
        if self._drag["resize"]:
            w0, h0 = self._drag["size"]
            self.prepareGeometryChange()
            self.size = (max(80.0, w0 + delta.x()), max(C.COMMENT_HEADER + 30, h0 + delta.y()))
            self.update()
            return
        self.setPos(self._drag["pos"] + delta)
        items = self.scene().node_items
        for nid, p0 in self._drag["nodes"].items():
            item = items.get(nid)
            if item is not None:
                item.setPos(p0 + delta)

    def mouseReleaseEvent(self, event) -> None:
        drag, self._drag = self._drag, None
        if drag is None:
            return
        moved = (self.pos() != drag["pos"]) or (self.size != drag["size"])
        if moved:
            positions = {nid: (it.pos().x(), it.pos().y())
                         for nid, it in self.scene().node_items.items() if nid in drag["nodes"]}
            r = self.scene_rect()
            self.scene().request_comment_edit(self.comment_id,
                                              (r.x(), r.y(), r.width(), r.height()), positions)

    def mouseDoubleClickEvent(self, event) -> None:
        if event.pos().y() <= C.COMMENT_HEADER:
            self.scene().request_comment_text(self.comment_id)
        event.accept()

    # --- painting ----------------------------------------------------------------------------
    def paint(self, painter: QPainter, option: QStyleOptionGraphicsItem, widget=None) -> None:
        lod = QStyleOptionGraphicsItem.levelOfDetailFromTransform(painter.worldTransform())
        w, h = self.size
        body = QColor(self.color)
        body.setAlpha(48)
        head = QColor(self.color)
        head.setAlpha(150)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.setPen(QPen(C.NODE_SELECTED if self.isSelected() else self.color.lighter(130),
                            2.0 if self.isSelected() else 1.0))
        painter.setBrush(body)
        painter.drawRoundedRect(QRectF(0, 0, w, h), 4, 4)
        painter.setPen(Qt.PenStyle.NoPen)
        painter.setBrush(head)
        painter.drawRoundedRect(QRectF(1, 1, w - 2, C.COMMENT_HEADER - 1), 3, 3)
        if lod > C.LOD_TEXT * 0.5 and self.text:
            painter.setFont(C.comment_font())
            painter.setPen(C.NODE_TEXT)
            text = C.metrics("comment").elidedText(self.text, Qt.TextElideMode.ElideRight, w - 16)
            painter.drawText(QRectF(8, 0, w - 16, C.COMMENT_HEADER),
                             Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft, text)
        g = self._grip()
        painter.setBrush(self.color.lighter(150))
        painter.drawPolygon(QPolygonF([g.bottomLeft(), g.topRight(), g.bottomRight()]))
