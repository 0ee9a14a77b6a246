"""A plain stand-in for the node canvas, behind the same names as `NodeCanvasView`.

Used only while `matedit.app.canvas` is not installed: it draws the graph as boxes
and straight wires (rebuilt from the model on every change), selects, and adds
nodes through commands, so the rest of the editor can be built and tested.
"""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont, QImage, QPainter, QPainterPath, QPen
from PySide6.QtWidgets import (
    QGraphicsItem,
    QGraphicsPathItem,
    QGraphicsRectItem,
    QGraphicsScene,
    QGraphicsSimpleTextItem,
    QGraphicsView,
    QMenu,
)

from matedit.app.controller import DocumentController
from matedit.graph import nodes
from matedit.graph.commands import AddNode
from matedit.graph.model import ChangeKind, Node

NODE_W, NODE_H = 170.0, 54.0


class _NodeBox(QGraphicsRectItem):
    def __init__(self, node: Node) -> None:
        super().__init__(0, 0, NODE_W, NODE_H)
        self.node_id = node.id
        self.setPos(node.position[0], node.position[1])
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIsSelectable)
        self.setBrush(QBrush(QColor("#2f3440")))
        self.setPen(QPen(QColor("#4b5468"), 1.2))
        d = nodes.REGISTRY.get(node.kind)
        title = QGraphicsSimpleTextItem(node.label or (d.title if d else node.kind), self)
        f = QFont()
        f.setBold(True)
        title.setFont(f)
        title.setBrush(QColor("#d5d9e0"))
        title.setPos(8, 6)
        sub = QGraphicsSimpleTextItem(node.id, self)
        sub.setBrush(QColor("#8a91a0"))
        sub.setPos(8, 28)
        self.error = ""

    def paint(self, painter: QPainter, option, widget=None) -> None:
        pen = QPen(QColor("#e0605a") if self.error else
                   QColor("#7aa2f7") if self.isSelected() else QColor("#4b5468"),
                   2.0 if (self.error or self.isSelected()) else 1.2)
        painter.setPen(pen)
        painter.setBrush(self.brush())
        painter.drawRoundedRect(self.rect(), 5, 5)


class PlaceholderCanvasView(QGraphicsView):
    """Boxes-and-wires view of the model with the canvas API the main window uses."""

    selectionChangedIds = Signal(list)
    functionOpenRequested = Signal(str)
    message = Signal(str)

    def __init__(self, controller: DocumentController, parent=None) -> None:
        super().__init__(parent)
        self.controller = controller
        self._scene = QGraphicsScene(self)
        self._scene.setBackgroundBrush(QColor("#1b1e24"))
        self.setScene(self._scene)
        self.setRenderHint(QPainter.RenderHint.Antialiasing)
        self.setDragMode(QGraphicsView.DragMode.RubberBandDrag)
        self._boxes: dict[str, _NodeBox] = {}
        self._errors: dict[str, str] = {}
        self._previews: dict[str, QImage | None] = {}
        self._rebuilding = False
        self._scene.selectionChanged.connect(self._emit_selection)
        controller.changed.connect(self._on_change)
        controller.documentReplaced.connect(self._rebuild)
        self._rebuild()

    # --- model mirror ----------------------------------------------------------------------
    def _on_change(self, event) -> None:
        if event.kind in (ChangeKind.STRUCTURAL, ChangeKind.LAYOUT):
            self._rebuild()

    def _rebuild(self) -> None:
        selected = self.selected_ids()
        self._rebuilding = True
        self._scene.clear()
        self._boxes.clear()
        graph = self.controller.document.graph
        for nid in sorted(graph.nodes):
            box = _NodeBox(graph.nodes[nid])
            box.error = self._errors.get(nid, "")
            if box.error:
                box.setToolTip(box.error)
            self._scene.addItem(box)
            self._boxes[nid] = box
        pen = QPen(QColor("#8a91a0"), 1.5)
        for link in sorted(graph.links):
            a, b = self._boxes.get(link.src), self._boxes.get(link.dst)
            if a is None or b is None:
                continue
            p0 = a.pos() + QPointF(NODE_W, NODE_H / 2)
            p1 = b.pos() + QPointF(0, NODE_H / 2)
            path = QPainterPath(p0)
            dx = max(40.0, abs(p1.x() - p0.x()) / 2)
            path.cubicTo(p0 + QPointF(dx, 0), p1 - QPointF(dx, 0), p1)
            wire = QGraphicsPathItem(path)
            wire.setPen(pen)
            wire.setZValue(-1)
            self._scene.addItem(wire)
        for nid in selected:
            if nid in self._boxes:
                self._boxes[nid].setSelected(True)
        self._rebuilding = False
        self._scene.setSceneRect(self._scene.itemsBoundingRect().adjusted(-400, -300, 400, 300))

    def _emit_selection(self) -> None:
        if not self._rebuilding:
            self.selectionChangedIds.emit(self.selected_ids())

    def selected_ids(self) -> list[str]:
        return sorted(i.node_id for i in self._scene.selectedItems() if isinstance(i, _NodeBox))

    # --- the canvas API --------------------------------------------------------------------
    def frame_all(self) -> None:
        rect = self._scene.itemsBoundingRect()
        if not rect.isNull():
            self.fitInView(rect.adjusted(-60, -60, 60, 60), Qt.AspectRatioMode.KeepAspectRatio)

    def frame_selection(self) -> None:
        items = [self._boxes[i] for i in self.selected_ids()]
        if not items:
            return self.frame_all()
        rect = QRectF()
        for it in items:
            rect = rect.united(it.sceneBoundingRect())
        self.fitInView(rect.adjusted(-80, -80, 80, 80), Qt.AspectRatioMode.KeepAspectRatio)

    def select_nodes(self, ids: list[str]) -> None:
        self._rebuilding = True
        self._scene.clearSelection()
        for nid in ids:
            if nid in self._boxes:
                self._boxes[nid].setSelected(True)
        self._rebuilding = False
        if ids and ids[0] in self._boxes:
            self.centerOn(self._boxes[ids[0]])
        self.selectionChangedIds.emit(self.selected_ids())

    def add_node_at(self, kind: str, scene_pos: QPointF | tuple[float, float],
                    settings: dict | None = None) -> str | None:
        graph = self.controller.document.graph
        d = nodes.REGISTRY.get(kind)
        if d is None:
            self.message.emit(f"unknown node kind {kind!r}")
            return None
        x, y = (scene_pos.x(), scene_pos.y()) if isinstance(scene_pos, QPointF) else scene_pos
        nid = graph.new_id(kind.split("_")[0])
        node = Node(nid, kind, (float(x), float(y)), dict(settings or {}))
        if not self.controller.push(AddNode(node, text=f"add {d.title}")):
            return None
        return nid

    def set_node_errors(self, errors: dict[str, str]) -> None:
        self._errors = dict(errors)
        for nid, box in self._boxes.items():
            box.error = self._errors.get(nid, "")
            box.setToolTip(box.error)
            box.update()

    def set_node_preview(self, node_id: str, image: QImage | None) -> None:
        self._previews[node_id] = image

    def open_palette(self, scene_pos: QPointF | None = None) -> None:
        pos = scene_pos or self.mapToScene(self.viewport().rect().center())
        menu = QMenu(self)
        for category, defs in nodes.categories().items():
            sub = menu.addMenu(category)
            for d in defs:
                act = sub.addAction(d.title)
                act.setToolTip(d.description)
                act.triggered.connect(lambda _=False, k=d.kind: self.add_node_at(k, pos))
        menu.popup(self.mapToGlobal(self.mapFromScene(pos)))

    # --- input -----------------------------------------------------------------------------
    def contextMenuEvent(self, event) -> None:  # noqa: N802 - Qt's name
        self.open_palette(self.mapToScene(event.pos()))

    def mouseDoubleClickEvent(self, event) -> None:  # noqa: N802 - Qt's name
        item = self.itemAt(event.pos())
        while item is not None and not isinstance(item, _NodeBox):
            item = item.parentItem()
        if isinstance(item, _NodeBox):
            node = self.controller.document.graph.nodes.get(item.node_id)
            if node is not None and node.kind == "function_call":
                ref = node.settings.get("function")
                if ref:
                    path = self.controller.resolver.path_of(ref, self.controller.document)
                    self.functionOpenRequested.emit(str(path))
                    return
        super().mouseDoubleClickEvent(event)

    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt's name
        factor = 1.15 if event.angleDelta().y() > 0 else 1 / 1.15
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.AnchorUnderMouse)
        self.scale(factor, factor)
