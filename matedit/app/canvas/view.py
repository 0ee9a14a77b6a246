"""NodeCanvasView: the node editor widget (navigation, selection, wiring, clipboard, palette).

Navigation: wheel zooms about the cursor; middle drag, Alt+left drag or Space+left
drag pans; F frames the selection, Home or A frames everything; M toggles the
minimap. Editing: drag between ports to connect (a wire dragged off a connected
input is lifted and moves or, dropped on nothing, is removed; a new wire dropped
on nothing opens the palette with only the kinds that can take it); Tab opens the
palette; Delete removes; Ctrl+C / Ctrl+X / Ctrl+V / Ctrl+D copy, cut, paste and
duplicate; C frames the selection in a comment. Every edit is a command pushed
through the controller; what the canvas shows comes back from the model's events.
"""

from __future__ import annotations

import dataclasses
import re

from PySide6.QtCore import QEvent, QPoint, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QAction, QImage, QKeySequence, QPainter, QPixmapCache, QTransform
from PySide6.QtWidgets import (
    QApplication,
    QGraphicsView,
    QInputDialog,
    QLineEdit,
    QMenu,
    QWidget,
)

from matedit.app.canvas import arrange, clipboard, functions, placement
from matedit.app.canvas import constants as C
from matedit.app.canvas.actions import CONTEXT_MENU, CanvasActions
from matedit.app.canvas.comment_item import CommentItem
from matedit.app.canvas.cost_overlay import CostOverlay
from matedit.app.canvas.drops import CanvasDrops
from matedit.app.canvas.interaction import WireDrag, compatible_port, kind_ports, port_at
from matedit.app.canvas.minimap import MiniMap
from matedit.app.canvas.node_item import NodeItem, PortRow, measure
from matedit.app.canvas.palette import NodePalette
from matedit.app.canvas.scene import NodeScene, describe
from matedit.app.canvas.toast import Toast
from matedit.app.canvas.wire_item import WireItem
from matedit.app.controller import DocumentController
from matedit.graph import nodes
from matedit.graph.commands import (
    AddNode,
    Command,
    Connect,
    Disconnect,
    MoveNodes,
    PutComment,
    RemoveNode,
    SetLabel,
    SetMuted,
)
from matedit.graph.model import Comment, Link, MaterialDocument, Node
from matedit.graph.types import PortType
from matedit.graph.validate import check_connect

_DRAG_START = 4  # pixels the mouse must travel before a press on a port becomes a drag


def _id_stem(kind: str) -> str:
    """`value_noise` -> `valueNoise`: readable ids for new nodes."""
    parts = [p for p in re.split(r"[^A-Za-z0-9]+", kind) if p]
    return (parts[0] + "".join(p[:1].upper() + p[1:] for p in parts[1:])) if parts else "n"


class NodeCanvasView(CanvasDrops, QGraphicsView):
    """The node canvas over one DocumentController (see `matedit.app.canvas` for the API)."""

    selectionChangedIds = Signal(list)
    functionOpenRequested = Signal(str)
    message = Signal(str)
    previewRequested = Signal(str, str)  # node id, output port: show it in the viewport
    materialOpenRequested = Signal(str)  # a material file dropped on the canvas
    docsRequested = Signal(str)  # a node kind whose documentation to show (F1)

    def __init__(self, controller: DocumentController, parent: QWidget | None = None,
                 actions: CanvasActions | None = None) -> None:
        super().__init__(parent)
        self.controller = controller
        # The window's action table (menus and keys), or one of its own when stand-alone.
        self.actions = actions if actions is not None else CanvasActions(self, lambda: self)
        self.actions.attach(self)
        self._scene = NodeScene(controller, self)
        self.setScene(self._scene)
        # Node caches are pixmaps; the default 10 MB cache thrashes on a big graph.
        QPixmapCache.setCacheLimit(max(QPixmapCache.cacheLimit(), 256 * 1024))
        self.setRenderHints(QPainter.RenderHint.Antialiasing
                            | QPainter.RenderHint.TextAntialiasing
                            | QPainter.RenderHint.SmoothPixmapTransform)
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.SmartViewportUpdate)
        self.setCacheMode(QGraphicsView.CacheModeFlag.CacheBackground)
        self.setOptimizationFlag(QGraphicsView.OptimizationFlag.DontSavePainterState, True)
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setDragMode(QGraphicsView.DragMode.RubberBandDrag)
        self.setRubberBandSelectionMode(Qt.ItemSelectionMode.IntersectsItemShape)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        e = C.SCENE_EXTENT
        self.setSceneRect(-e, -e, 2 * e, 2 * e)  # the view's room to pan, not the scene's index
        self.setFrameShape(QGraphicsView.Shape.NoFrame)
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setStyleSheet("QGraphicsView { background: #1b1e24; border: none; }")
        self.setAcceptDrops(True)
        self.run_menu = lambda menu, at: menu.exec(at)  # tests read the menu instead
        # where Collapse to Function writes the new function (a save dialog; tests answer)
        self.ask_function_path = lambda suggestion: functions.ask_function_path(self,
                                                                                suggestion)

        self.node_palette = NodePalette(self)
        self.node_palette.chosen.connect(self._palette_chosen)
        self.node_palette.cancelled.connect(self._palette_cancelled)
        self.node_palette.docsRequested.connect(self.docsRequested)
        self.toast = Toast(self.viewport())
        self.minimap = MiniMap(self)

        self._wire: WireDrag | None = None
        self._wire_press: QPoint | None = None
        self._pan_last: QPoint | None = None
        self._space = False
        self._last_pos: QPoint | None = None  # last mouse position in the viewport
        self._palette_pos = QPointF()
        self._palette_anchor: tuple[str, str, bool, str] | None = None
        self._selecting = False
        self._selection_pending = False  # changed during a macro: announced at its end
        self._last_ids: list[str] = []
        self._rename_edit: QLineEdit | None = None

        self._scene.selectionChanged.connect(self._selection_changed)
        self._scene.commentTextRequested.connect(self._edit_comment_text)
        self._scene.rebuilt.connect(self.minimap.invalidate)
        self._frame_when_built = False  # frame_all asked while the items wait to be built
        self._scene.rebuilt.connect(self._built)
        controller.changed.connect(lambda _ev: self.minimap.invalidate())
        controller.documentReplaced.connect(self._document_replaced)
        controller.batchEnded.connect(self._batch_ended)
        self.horizontalScrollBar().valueChanged.connect(self.minimap.update)
        self.verticalScrollBar().valueChanged.connect(self.minimap.update)
        self.minimap.invalidate()
        self.cost_overlay = CostOverlay(self, lambda: self.controller.document)
        self.cost_overlay.ready.connect(self._scene.set_node_costs)
        self.cost_overlay.failed.connect(self.refuse)
        controller.changed.connect(lambda _ev: self.cost_overlay.document_changed())
        controller.documentReplaced.connect(self.cost_overlay.document_changed)

    # --- public API --------------------------------------------------------------------------
    def scene(self) -> NodeScene:  # type: ignore[override]
        return self._scene

    def zoom(self) -> float:
        return self.transform().m11()

    def frame_all(self) -> None:
        """Zoom and scroll so every node and comment is in view (once they are built, when
        the scene builds them in a later turn: NodeScene.defer_rebuilds)."""
        if not self._scene.settled:
            self._frame_when_built = True
            return
        self._frame_when_built = False
        self._fit(self._scene.nodes_bounding_rect())

    def _built(self) -> None:
        if self._frame_when_built:
            self.frame_all()

    def frame_selection(self) -> None:
        items = [it for it in self._scene.selectedItems()
                 if isinstance(it, (NodeItem, CommentItem))]
        if not items:
            self.frame_all()
            return
        self._fit(self._scene.nodes_bounding_rect(items))

    def select_nodes(self, ids) -> None:
        """Select exactly these nodes (unknown ids are ignored); emits selectionChangedIds once."""
        self._selecting = True
        try:
            self._scene.clearSelection()
            for nid in ids:
                item = self._scene.node_items.get(nid)
                if item is not None:
                    item.setSelected(True)
        finally:
            self._selecting = False
        self._selection_changed()

    def selected_ids(self) -> list[str]:
        return self._scene.selected_node_ids()

    def add_node_at(self, kind: str, scene_pos: QPointF, settings: dict | None = None) -> str:
        """Add a `kind` node, top-left corner at `scene_pos`; its new id ('' if refused)."""
        node = self._new_node(kind, scene_pos, settings)
        if node is None:
            return ""
        placement.place(node, self._scene)  # never on another node
        if not self.controller.push(AddNode(node)):
            return ""
        self.select_nodes([node.id])  # the Inspector shows the new node
        return node.id

    def set_node_errors(self, errors: dict[str, str]) -> None:
        """Errors mapped to nodes (GLSL compile errors), shown as red badges; replaces the last."""
        self._scene.set_node_errors(errors)

    def set_node_preview(self, node_id: str, image: QImage | None) -> None:
        self._scene.set_node_preview(node_id, image)

    def open_palette(self, scene_pos: QPointF | None = None) -> None:
        """The node palette at `scene_pos` (default: the cursor, else the middle of the view)."""
        self._palette_anchor = None
        self._show_palette(self._resolve_pos(scene_pos), None, "Add node")

    def previewable_output(self, node_id: str, port: str = "") -> str:
        """`port` if the node has that output with a value to show, else its first such
        output ("" if none: a texture object, say)."""
        a = self.controller.analysis
        outs = a.out_types.get(node_id, {}) if a is not None else {}
        ok = [p for p, t in outs.items() if t.is_numeric or t == PortType.MATERIAL]
        if port in ok:
            return port
        return ok[0] if ok else ""

    def preview_node(self, node_id: str, port: str = "") -> bool:
        """Asks the viewport to show one of the node's outputs (see `previewRequested`)."""
        port = self.previewable_output(node_id, port)
        if not port:
            self.refuse(f"{node_id} has no output the viewport can show")
            return False
        self.previewRequested.emit(node_id, port)
        return True

    def toggle_minimap(self) -> None:
        self.minimap.setVisible(not self.minimap.isVisible())

    def toggle_cost_overlay(self) -> None:
        """View ▸ Cost Overlay: tint the nodes by what they cost (computed off the UI thread)."""
        self.cost_overlay.set_active(not self.cost_overlay.active)

    def rename_selected(self) -> QLineEdit | None:
        """The inline title editor over the one selected node (None otherwise)."""
        ids = self.selected_ids()
        return self.start_rename(ids[0]) if len(ids) == 1 else None

    def request_docs(self) -> bool:
        """Opens the node reference (`docsRequested`) at the selected node's kind, or where it
        was when no single node is selected (an empty kind)."""
        ids = self.selected_ids()
        node = self.controller.document.graph.nodes.get(ids[0]) if len(ids) == 1 else None
        self.docsRequested.emit(node.kind if node is not None else "")
        return True

    # --- edits -------------------------------------------------------------------------------
    def delete_selection(self) -> bool:
        sel = self._scene.selectedItems()
        node_ids = sorted(it.node_id for it in sel if isinstance(it, NodeItem))
        gone = set(node_ids)
        commands: list[Command] = [
            Disconnect(link) for link in sorted(self._scene.selected_wires)
            if link.src not in gone and link.dst not in gone]
        commands += [RemoveNode(nid) for nid in node_ids]
        commands += [PutComment(it.comment_id, None, text="delete comment")
                     for it in sel if isinstance(it, CommentItem)]
        if not commands:
            return False
        n = len(node_ids)
        text = f"delete {n} node{'s' if n != 1 else ''}" if n else "delete"
        return self.controller.push_all(commands, text)

    def copy_selection(self) -> bool:
        sel = self._scene.selectedItems()
        node_ids = [it.node_id for it in sel if isinstance(it, NodeItem)]
        comment_ids = [it.comment_id for it in sel if isinstance(it, CommentItem)]
        if not node_ids and not comment_ids:
            self.message.emit("Nothing selected to copy")
            return False
        payload = clipboard.copy_payload(self.controller.document, node_ids, comment_ids)
        QApplication.clipboard().setMimeData(clipboard.to_mime(payload))
        self.message.emit(f"Copied {len(node_ids)} node{'s' if len(node_ids) != 1 else ''}")
        return True

    def cut_selection(self) -> bool:
        return self.copy_selection() and self.delete_selection()

    def paste(self, scene_pos: QPointF | None = None) -> list[str]:
        """Paste the clipboard's nodes (top-left at `scene_pos`, else the cursor, else offset)."""
        clip = clipboard.from_mime(QApplication.clipboard().mimeData())
        if clip is None or not (clip.graph.nodes or clip.graph.comments):
            self.message.emit("The clipboard holds no nodes")
            return []
        corner = clipboard.payload_bounds(clip)
        if scene_pos is None and self._cursor_inside():
            scene_pos = self.mapToScene(self._last_pos)
        if scene_pos is not None:
            offset = (scene_pos.x() - corner[0], scene_pos.y() - corner[1])
        else:
            offset = (40.0, 40.0)
        return self._paste_doc(clip, offset, "paste")

    def duplicate_selection(self) -> list[str]:
        sel = self._scene.selectedItems()
        node_ids = [it.node_id for it in sel if isinstance(it, NodeItem)]
        if not node_ids:
            return []
        payload = clipboard.copy_payload(self.controller.document, node_ids)
        clip = clipboard.from_mime(clipboard.to_mime(payload))
        return self._paste_doc(clip, (40.0, 40.0), "duplicate") if clip else []

    def collapse_selection(self) -> str:
        """Edit › Collapse to Function (matedit.app.canvas.functions); the call's id."""
        return functions.collapse_selection(self)

    def expand_selected_call(self) -> list[str]:
        """Edit › Expand Function: the selected call's nodes inline; the new ids."""
        return functions.expand_call(self)

    def toggle_bypass(self) -> list[str]:
        """Edit › Bypass (B): the selected nodes that can be bypassed stop working (their first
        input of each output's type passes through), or, when all of them already are, work
        again; one undo step. The ids changed."""
        graph = self.controller.document.graph
        ids = [nid for nid in self.selected_ids()
               if nid in graph.nodes and nodes.can_bypass(graph.nodes[nid].kind)]
        if not ids:
            self.message.emit("Nothing to bypass: sources and outputs have no input to pass "
                              "through")
            return []
        mute = not all(graph.nodes[nid].muted for nid in ids)
        verb = "bypass" if mute else "restore"
        text = f"{verb} {len(ids)} node{'s' if len(ids) != 1 else ''}"
        if not self.controller.push(SetMuted(tuple(ids), mute, text=text)):
            return []
        self.message.emit(("Bypassed " if mute else "Restored ") +
                          f"{len(ids)} node{'s' if len(ids) != 1 else ''}")
        return ids

    def arrange_selection(self) -> list[str]:
        """Edit › Arrange: the selected nodes (every node when fewer than two are selected)
        laid out in columns, outputs on the right, as one undo step; the ids moved."""
        ids = self.selected_ids()
        scope = ids if len(ids) >= 2 else list(self._scene.node_items)
        moved, frames, _left = arrange.arrange(self._scene, scope)
        if not moved:
            self.message.emit("Already arranged")
            return []
        graph = self.controller.document.graph
        commands: list[Command] = [MoveNodes(moved, text="arrange")]
        commands += [PutComment(cid, dataclasses.replace(graph.comments[cid], rect=rect),
                                text="arrange") for cid, rect in sorted(frames.items())]
        text = f"arrange {len(moved)} node{'s' if len(moved) != 1 else ''}"
        if not self.controller.push_all(commands, text):
            return []
        self.message.emit(f"Arranged {len(moved)} node{'s' if len(moved) != 1 else ''}")
        return sorted(moved)

    def comment_selection(self) -> str:
        """A comment frame around the selected nodes; its id ('' if nothing is selected)."""
        items = [it for it in self._scene.selectedItems() if isinstance(it, NodeItem)]
        if not items:
            return ""
        r = self._scene.nodes_bounding_rect(items).adjusted(-20, -20 - C.COMMENT_HEADER, 20, 20)
        cid = self.controller.document.graph.new_id("comment")
        comment = Comment(cid, "Comment", (r.x(), r.y(), r.width(), r.height()),
                          (0.32, 0.36, 0.45))
        return cid if self.controller.push(PutComment(cid, comment, text="add comment")) else ""

    def _paste_doc(self, clip: MaterialDocument, offset, text: str) -> list[str]:
        graph = self.controller.document.graph
        # the pasted group moves together to the nearest place where it covers no node
        dx, dy = offset
        rects = [placement.node_rect(dataclasses.replace(
            n, position=(n.position[0] + dx, n.position[1] + dy)))
            for n in clip.graph.nodes.values()]
        shift = placement.free_offset(rects, placement.taken_rects(self._scene))
        offset = (dx + shift.x(), dy + shift.y())
        commands, ids = clipboard.paste_commands(graph, clip, offset)
        if not commands or not self.controller.push_all(commands, text):
            return []
        self.select_nodes(ids)
        verb = "Pasted" if text == "paste" else "Duplicated"
        self.message.emit(f"{verb} {len(ids)} node{'s' if len(ids) != 1 else ''}")
        return ids

    def _new_node(self, kind: str, scene_pos: QPointF, settings: dict | None) -> Node | None:
        if kind not in nodes.REGISTRY:
            self.message.emit(f"Unknown node kind {kind!r}")
            return None
        graph = self.controller.document.graph
        nid = graph.new_id(_id_stem(kind))
        s = dict(settings or {})
        if nodes.is_value_parameter(kind) and "name" not in s:
            taken = {str(n.settings.get("name")) for n in graph.nodes.values()
                     if nodes.is_value_parameter(n.kind)}
            name, i = nid, 1
            while name in taken:
                i += 1
                name = f"{nid}_{i}"
            s["name"] = name
        return Node(nid, kind, (round(scene_pos.x(), 1), round(scene_pos.y(), 1)), s)

    def refuse(self, reason: str, at: QPoint | None = None) -> None:
        """Show why an edit was refused: near the cursor for a few seconds, and as `message`."""
        if at is None:
            at = self._last_pos if self._cursor_inside() else self.viewport().rect().center()
        self.toast.show_at(reason, at)
        self.message.emit(reason)

    # --- palette -----------------------------------------------------------------------------
    def _resolve_pos(self, scene_pos: QPointF | None) -> QPointF:
        if scene_pos is not None:
            return QPointF(scene_pos)
        if self._cursor_inside():
            return self.mapToScene(self._last_pos)
        return self.mapToScene(self.viewport().rect().center())

    def _cursor_inside(self) -> bool:
        return self._last_pos is not None and self.viewport().rect().contains(self._last_pos)

    def _show_palette(self, scene_pos: QPointF, accept, hint: str) -> None:
        self._palette_pos = QPointF(scene_pos)
        self.node_palette.out_of_place = frozenset(
            nodes.kinds_where(lambda d: d.role == nodes.Role.MATERIAL_OUTPUT)
            if self.controller.document.is_function
            else nodes.kinds_where(lambda d: d.role in (nodes.Role.FUNCTION_INPUT,
                                                         nodes.Role.FUNCTION_OUTPUT)))
        at = self.viewport().mapTo(self, self.mapFromScene(scene_pos))
        self.node_palette.popup(at, accept, hint)

    def _palette_chosen(self, kind: str) -> None:
        anchor, self._palette_anchor = self._palette_anchor, None
        if anchor is None:
            self.add_node_at(kind, self._palette_pos)
        else:
            self._add_connected(kind, self._palette_pos, anchor)
        self.setFocus()

    def _palette_cancelled(self) -> None:
        self._palette_anchor = None
        self.setFocus()

    def _add_connected(self, kind: str, at: QPointF, anchor: tuple[str, str, bool, str]) -> str:
        """Add a `kind` node whose compatible port sits at `at`, wired to the anchor port."""
        a_node, a_port, a_out, a_type = anchor
        port = compatible_port(kind, a_type, a_out)
        ports = kind_ports(kind)
        node = self._new_node(kind, at, None)
        if node is None or port is None or ports is None:
            return self.add_node_at(kind, at)
        title, sub, _, _ = describe(node)
        lay = measure(title, sub, [PortRow(p.name, p.type) for p in ports.inputs],
                      [PortRow(p.name, p.type) for p in ports.outputs])
        local = lay.inputs[port] if a_out else lay.outputs[port]
        node.position = (round(at.x() - local.x(), 1), round(at.y() - local.y(), 1))
        placement.place(node, self._scene)
        link = (Link(a_node, a_port, node.id, port) if a_out else
                Link(node.id, port, a_node, a_port))
        doc = self.controller.document
        trial = MaterialDocument(doc.kind, doc.graph.copy(), doc.name, doc.description, doc.path)
        AddNode(node).apply(trial.graph)
        reason = check_connect(trial, link, self.controller.resolver)
        if reason is not None:
            self.controller.push(AddNode(node))
            self.refuse(reason)
            return node.id
        ok = self.controller.push_all([AddNode(node), Connect(link)], "add connected node")
        if ok:
            self.select_nodes([node.id])
        return node.id if ok else ""

    # --- selection ---------------------------------------------------------------------------
    def _selection_changed(self) -> None:
        if self._selecting:
            return
        if self.controller.batching:  # each deleted item deselects: the inspector once
            self._selection_pending = True
            return
        self._selection_pending = False
        ids = self._scene.selected_node_ids()
        if ids != self._last_ids:
            self._last_ids = ids
            self.selectionChangedIds.emit(list(ids))

    def _batch_ended(self) -> None:
        if self._selection_pending:
            self._selection_changed()

    def _document_replaced(self) -> None:
        self._wire = None
        self.node_palette.close_palette()
        self._last_ids = []
        self.selectionChangedIds.emit([])
        self.frame_all()

    # --- view transform ----------------------------------------------------------------------
    def _fit(self, rect: QRectF) -> None:
        vp = self.viewport().rect()
        if rect.isEmpty():
            self.setTransform(QTransform())
            self.centerOn(0, 0)
            self.minimap.update()
            return
        m = 40.0
        s = min((vp.width() - 2 * m) / max(rect.width(), 1.0),
                (vp.height() - 2 * m) / max(rect.height(), 1.0))
        s = max(C.ZOOM_MIN, min(s, 1.0))
        self.setTransform(QTransform.fromScale(s, s))
        self.centerOn(rect.center())
        self.minimap.update()

    def _zoom_by(self, factor: float, vp_pos: QPointF) -> None:
        cur = self.zoom()
        new = max(C.ZOOM_MIN, min(C.ZOOM_MAX, cur * factor))
        if abs(new - cur) < 1e-9:
            return
        before = self.mapToScene(vp_pos.toPoint())
        self.scale(new / cur, new / cur)
        after = self.mapFromScene(before)
        d = after - vp_pos.toPoint()
        self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() + d.x())
        self.verticalScrollBar().setValue(self.verticalScrollBar().value() + d.y())
        self.minimap.update()

    def paintEvent(self, event) -> None:
        self._scene.set_zoom(self.zoom())  # any transform change, from here or a caller
        super().paintEvent(event)

    def wheelEvent(self, event) -> None:
        steps = event.angleDelta().y() / 120.0
        if steps:
            self._zoom_by(C.ZOOM_STEP ** steps, event.position())
        event.accept()

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        m = 10
        self.minimap.move(self.width() - self.minimap.width() - m,
                          self.height() - self.minimap.height() - m)

    # --- mouse -------------------------------------------------------------------------------
    def _hit_radius(self) -> float:
        return C.PORT_HIT_RADIUS / max(self.zoom(), 1e-3)

    def mousePressEvent(self, event) -> None:
        pos = event.position().toPoint()
        self._last_pos = pos
        if self.node_palette.isVisible():
            self.node_palette.close_palette()
        button, mods = event.button(), event.modifiers()
        if button == Qt.MouseButton.MiddleButton or (button == Qt.MouseButton.LeftButton and (
                mods & Qt.KeyboardModifier.AltModifier or self._space)):
            self._pan_last = pos
            self.viewport().setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        if button == Qt.MouseButton.LeftButton:
            sp = self.mapToScene(pos)
            port = port_at(self._scene, sp, self._hit_radius(), for_press=True)
            if port is not None:
                self._wire = WireDrag(self._scene, port)
                self._wire_press = pos
                event.accept()
                return
            item = self.itemAt(pos)
            additive = bool(mods & Qt.KeyboardModifier.ControlModifier)
            if isinstance(item, WireItem):
                if not additive:
                    self._scene.clearSelection()
                self._scene.select_wire(item.link, additive)
                event.accept()
                return
            if not additive:
                self._scene.clear_wire_selection()
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event) -> None:
        pos = event.position().toPoint()
        self._last_pos = pos
        if self._pan_last is not None:
            d = pos - self._pan_last
            self._pan_last = pos
            self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() - d.x())
            self.verticalScrollBar().setValue(self.verticalScrollBar().value() - d.y())
            event.accept()
            return
        if self._wire is not None:
            self._wire.move(self.mapToScene(pos), self._hit_radius())
            event.accept()
            return
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event) -> None:
        pos = event.position().toPoint()
        self._last_pos = pos
        if self._pan_last is not None and event.button() in (Qt.MouseButton.MiddleButton,
                                                             Qt.MouseButton.LeftButton):
            self._pan_last = None
            self.viewport().unsetCursor()
            event.accept()
            return
        if self._wire is not None and event.button() == Qt.MouseButton.LeftButton:
            self._finish_wire(pos)
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def _finish_wire(self, pos: QPoint) -> None:
        wire, self._wire = self._wire, None
        moved = (pos - self._wire_press).manhattanLength() >= _DRAG_START
        result = wire.finish(self.mapToScene(pos), self._hit_radius())
        anchor = wire.anchor
        wire.cleanup()
        keep_open = self._scene.end_peeks(result.link if moved else None)
        if not moved:
            return
        if result.link is not None:
            if result.lifted is None:
                self.controller.push_all([Connect(result.link), *keep_open], "connect")
            elif result.lifted != result.link:
                self.controller.push_all([Disconnect(result.lifted), Connect(result.link),
                                          *keep_open], "reconnect")
        elif result.reason is not None:
            self.refuse(result.reason, pos)
        elif result.lifted is not None:
            self.controller.push(Disconnect(result.lifted))
        else:
            side = "output" if anchor.is_output else "input"
            self._palette_anchor = (anchor.node_id, anchor.name, anchor.is_output,
                                    wire.anchor_type)
            a_type = wire.anchor_type
            self._show_palette(
                self.mapToScene(pos),
                lambda kind: compatible_port(kind, a_type, anchor.is_output) is not None,
                f"Connect to {anchor.node_id}.{anchor.name} ({a_type} {side})")

    def start_rename(self, node_id: str) -> QLineEdit | None:
        """An editor over the node's title: Enter renames (one undo step), Esc cancels."""
        item = self._scene.node_items.get(node_id)
        node = self.controller.document.graph.nodes.get(node_id)
        if item is None or node is None:
            return None
        if self._rename_edit is not None:
            self._rename_edit.deleteLater()
        top_left = self.mapFromScene(item.mapToScene(QPointF(0, 0)))
        width = int(item.layout.width * self.zoom())
        edit = QLineEdit(item.title, self.viewport())
        edit.setObjectName("renameNode")
        edit.setGeometry(top_left.x(), top_left.y(), max(width, 120),
                         max(22, int(C.HEADER_HEIGHT * self.zoom())))
        edit.selectAll()
        done = {"ok": False}

        def commit() -> None:
            if done["ok"]:
                return
            done["ok"] = True
            text = edit.text().strip()
            d = nodes.REGISTRY.get(node.kind)
            label = "" if d is not None and text == d.title else text
            current = self.controller.document.graph.nodes.get(node_id)
            if current is not None and label != current.label and text:
                self.controller.push(SetLabel(node_id, label))
            edit.deleteLater()
            self._rename_edit = None
            self.setFocus()

        def cancel() -> None:
            done["ok"] = True
            edit.deleteLater()
            self._rename_edit = None
            self.setFocus()

        edit.returnPressed.connect(commit)
        edit.editingFinished.connect(commit)
        edit.addAction(QAction(edit, shortcut=QKeySequence(Qt.Key.Key_Escape),
                               triggered=cancel))
        edit.show()
        edit.setFocus()
        self._rename_edit = edit
        return edit

    def insert_reroute(self, link: Link, scene_pos: QPointF) -> str:
        """A reroute on `link` at `scene_pos`, as one undo step; its id ('' if refused)."""
        node = self._new_node(nodes.kind_for(nodes.Role.REROUTE),
                              scene_pos - QPointF(C.REROUTE_RADIUS, C.REROUTE_RADIUS), None)
        if node is None or link not in self.controller.document.graph.links:
            return ""
        ok = self.controller.push_all(
            [Disconnect(link), AddNode(node), Connect(Link(link.src, link.src_port, node.id,
                                                           "value")),
             Connect(Link(node.id, "value", link.dst, link.dst_port))], "insert reroute")
        return node.id if ok else ""

    def mouseDoubleClickEvent(self, event) -> None:
        item = self.itemAt(event.position().toPoint())
        if isinstance(item, WireItem):  # a reroute where the wire was double-clicked
            self.insert_reroute(item.link, self.mapToScene(event.position().toPoint()))
            event.accept()
            return
        while item is not None and not isinstance(item, (NodeItem, CommentItem)):
            item = item.parentItem()
        if isinstance(item, NodeItem) and nodes.role_of(item.kind) != nodes.Role.FUNCTION_CALL and \
                item.mapFromScene(self.mapToScene(event.position().toPoint())).y() \
                < C.HEADER_HEIGHT:  # double-click on the title: rename
            self.start_rename(item.node_id)
            event.accept()
            return
        if isinstance(item, NodeItem) and nodes.role_of(item.kind) == nodes.Role.FUNCTION_CALL:
            node = self.controller.document.graph.nodes.get(item.node_id)
            ref = node.settings.get("function") if node else None
            if isinstance(ref, str) and ref:
                path = self.controller.resolver.path_of(ref, self.controller.document)
                self.functionOpenRequested.emit(str(path))
            event.accept()
            return
        super().mouseDoubleClickEvent(event)

    def contextMenuEvent(self, event) -> None:
        pos = event.pos()
        self._last_pos = pos
        sp = self.mapToScene(pos)
        item = self.itemAt(pos)
        while item is not None and not isinstance(item, (NodeItem, CommentItem, WireItem)):
            item = item.parentItem()
        wire = None
        if isinstance(item, WireItem):
            self._scene.clearSelection()
            self._scene.select_wire(item.link)
            wire = item.link
        elif item is not None and not item.isSelected() and isinstance(
                item, (NodeItem, CommentItem)):
            self._scene.clearSelection()
            self._scene.clear_wire_selection()
            item.setSelected(True)
        menu = QMenu(self)
        menu.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)  # a new one each time
        # Add node and Paste land where the menu was opened: both read `_last_pos`.
        menu.addAction(self.actions["add_node"])
        if wire is not None:
            menu.addAction("Insert reroute\tdouble-click",
                           lambda: self.insert_reroute(wire, sp))
        if isinstance(item, NodeItem) and not self.controller.document.is_function:
            port = port_at(self._scene, sp, self._hit_radius(), want_output=True)
            name = port.name if port is not None and port.node_id == item.node_id else ""
            name = self.previewable_output(item.node_id, name)
            act = menu.addAction(f"Preview in viewport ({name})" if name else
                                 "Preview in viewport",
                                 lambda n=item.node_id, p=name: self.preview_node(n, p))
            act.setEnabled(bool(name))
            menu.addSeparator()
        self.actions.fill(menu, CONTEXT_MENU)
        self.actions.refresh(self)
        self.run_menu(menu, event.globalPos())

    # --- keys --------------------------------------------------------------------------------
    # Commands come from the action table (`self.actions`); what is left here is state, not a
    # command: Space held down pans with the left button, Esc cancels a wire being dragged.
    def _is_state_key(self, event) -> bool:
        mods = event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        return event.key() == Qt.Key.Key_Escape or (
            mods == Qt.KeyboardModifier.NoModifier and event.key() == Qt.Key.Key_Space)

    def event(self, event) -> bool:
        t = event.type()
        if t == QEvent.Type.ShortcutOverride and (self.actions.action_for_key(event)
                                                  or self._is_state_key(event)):
            event.accept()  # the canvas's keys win over window shortcuts while it has focus
            return True
        if t == QEvent.Type.KeyPress:  # before QWidget's Tab focus chain sees Tab
            command = self.actions.action_for_key(event)
            if command:
                self.actions.run(command, self)
                event.accept()
                return True
        return super().event(event)

    def keyPressEvent(self, event) -> None:
        mods = event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        key = event.key()
        if mods == Qt.KeyboardModifier.NoModifier and key == Qt.Key.Key_Space:
            if not event.isAutoRepeat():
                self._space = True
                self.viewport().setCursor(Qt.CursorShape.OpenHandCursor)
        elif key == Qt.Key.Key_Escape:
            if self._wire is not None:
                self._wire.cleanup()
                self._wire = None
                self._scene.end_peeks(None)
            else:
                self._scene.clearSelection()
        else:
            super().keyPressEvent(event)
            return
        event.accept()

    def keyReleaseEvent(self, event) -> None:
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = False
            self.viewport().unsetCursor()
            event.accept()
            return
        super().keyReleaseEvent(event)

    # --- comments ----------------------------------------------------------------------------
    def _edit_comment_text(self, comment_id: str) -> None:
        old = self.controller.document.graph.comments.get(comment_id)
        if old is None:
            return
        text, ok = QInputDialog.getText(self, "Comment", "Text:", text=old.text)
        if ok and text != old.text:
            self.controller.push(PutComment(comment_id, dataclasses.replace(old, text=text),
                                            text="edit comment"))
