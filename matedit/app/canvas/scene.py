"""NodeScene: the graphics items that mirror the controller's document graph.

The scene holds no graph state of its own: only items, keyed by node id, link
and comment id, plus indexes to find them fast. It builds them from the model,
follows the model's change events one by one (adding, removing or updating just
the items an event touches), takes types and diagnostics from each analysis,
and rebuilds when the document is replaced. Edits the items ask for (a finished
drag, a comment resize) go back to the model as commands through the controller.
"""

from __future__ import annotations

import dataclasses
from html import escape
from pathlib import Path

from PySide6.QtCore import QLineF, QRectF, Qt, Signal
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QGraphicsScene, QToolTip

from matedit.app.canvas import constants as C
from matedit.app.canvas.comment_item import CommentItem
from matedit.app.canvas.node_item import NodeItem, PortRow
from matedit.app.canvas.port_item import PortItem
from matedit.app.canvas.reroute_item import RerouteItem
from matedit.app.canvas.wire_item import WireItem
from matedit.app.controller import DocumentController
from matedit.app.turns import turns
from matedit.graph import nodes
from matedit.graph.commands import MoveNodes, PutComment, SetSetting
from matedit.graph.model import ChangeEvent, Link, Node
from matedit.graph.nodes import Role, is_value_parameter, role_of
from matedit.graph.ports import node_ports
from matedit.graph.validate import Analysis


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:.3g}"
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(_fmt(v) for v in value) + ")"
    return str(value)


def describe(node: Node, function_name: str = "") -> tuple[str, str, str, str]:
    """(title, subtitle, category, tooltip) a node shows, from its kind, label and settings;
    a function call is titled with the function's own name when it is known."""
    d = nodes.REGISTRY.get(node.kind)
    kind_title = d.title if d else node.kind
    title = node.label or kind_title
    s = node.settings
    sub = ""
    if is_value_parameter(node.kind):
        sub = str(s.get("name", "param"))
        if role_of(node.kind) == Role.SCALAR_PARAMETER and "value" in node.values:
            sub += f" = {_fmt(node.values['value'])}"
    elif role_of(node.kind) == Role.CONSTANT:
        sub = _fmt(s.get("value", 0.0))
    elif role_of(node.kind) == Role.FUNCTION_CALL:
        stem = Path(str(s.get("function", ""))).stem
        if stem and not node.label:  # name the function, as Unreal does
            title = function_name or stem.replace("_", " ").capitalize()
        sub = f"{stem}.json" if stem else "no function chosen"
    elif role_of(node.kind) in (Role.FUNCTION_INPUT, Role.FUNCTION_OUTPUT):
        sub = f"{s.get('name', '')} : {s.get('type', 'float')}"
    elif role_of(node.kind) == Role.COMPONENT_MASK:
        sub = "." + str(s.get("channels", "xy"))
    elif role_of(node.kind) == Role.LAYER_STACK:
        layers = s.get("layers", [])
        if isinstance(layers, list):
            sub = " · ".join(str(e.get("name", e.get("id", "?"))) for e in layers
                             if isinstance(e, dict))
    if node.label and not sub:
        sub = kind_title
    if node.muted:
        sub = "bypassed" + (f" · {sub}" if sub else "")
    tip = f"<b>{escape(title)}</b> &nbsp;<i>{node.kind}</i> &nbsp;id {node.id}"
    if d is not None:
        tip += f"<br>{escape(d.description)}"
    if node.muted:
        tip += ("<br><i>Bypassed (B): its first input of each output's type passes "
                "through</i>")
    return title, sub, d.category if d else "", tip


def port_rows(kind: str, ports) -> list[PortRow]:
    """What a node of `kind` shows for these ports (a generic `T` port, its pin group)."""
    return [PortRow(p.name, p.type, p.doc, p.type == "T", nodes.port_group(kind, p.name))
            for p in ports]


def expanded_groups(node: Node) -> frozenset[str] | None:
    """The pin groups a node shows open (None where its kind folds none): its
    EXPANDED_GROUPS setting, else the setting's default (a new node, an old document)."""
    d = nodes.REGISTRY.get(node.kind)
    s = d.setting(nodes.EXPANDED_GROUPS) if d is not None else None
    if s is None:
        return None
    value = node.settings.get(nodes.EXPANDED_GROUPS, s.default)
    if not isinstance(value, (list, tuple)):
        value = s.default
    return frozenset(str(g) for g in value)


class NodeScene(QGraphicsScene):
    """Items for the nodes, wires and comments of `controller.document.graph`."""

    commentTextRequested = Signal(str)  # a comment's title was double-clicked
    rebuilt = Signal()

    def __init__(self, controller: DocumentController, parent=None) -> None:
        super().__init__(parent)
        self.controller = controller
        self.node_items: dict[str, NodeItem] = {}
        self.wire_items: dict[Link, WireItem] = {}
        self.comment_items: dict[str, CommentItem] = {}
        # Pin groups a dragged wire opened by hovering their header: view state for the
        # length of the drag (peek_group / end_peeks), not the document's setting.
        self._peeked: dict[str, set[str]] = {}
        self._wires_of: dict[str, set[Link]] = {}
        self._node_errors: dict[str, str] = {}  # GLSL errors mapped to nodes, from the window
        self.snap_to_grid = False  # moves end on the minor grid
        self._previews: dict[str, QImage] = {}
        self.costs: dict[str, tuple[float, str]] = {}  # the cost overlay (set_node_costs)
        self.selected_wires: set[Link] = set()  # wires keep their own selection (see WireItem)
        self.hairline = False  # wires draw as hairlines when zoomed far out
        self.ports_visible = True  # ports hide when zoomed too far out to aim at them
        self._last_diags: dict[str, list[tuple[str, str]]] = {}
        self.setItemIndexMethod(QGraphicsScene.ItemIndexMethod.BspTreeIndex)
        self.setBackgroundBrush(C.BACKGROUND)
        controller.changed.connect(self._on_changed)
        controller.analysed.connect(self._on_analysed)
        # Opening a file builds the items in a turn of the UI work queue of their own
        # (`defer_rebuilds`, set by the window while it opens one): the open and the items
        # with their first paint are then two short blocks of the UI thread, not one long one.
        self.defer_rebuilds = False
        self._rebuild_due = False
        controller.documentReplaced.connect(self._document_replaced)
        self.rebuild()

    # --- queries -----------------------------------------------------------------------------
    @property
    def graph(self):
        return self.controller.document.graph

    def node_item(self, node_id: str) -> NodeItem | None:
        return self.node_items.get(node_id)

    def selected_node_ids(self) -> list[str]:
        return sorted(it.node_id for it in self.selectedItems() if isinstance(it, NodeItem))

    def node_items_in(self, rect: QRectF) -> list[NodeItem]:
        return [it for it in self.items(rect, Qt.ItemSelectionMode.ContainsItemBoundingRect)
                if isinstance(it, NodeItem)]

    def nodes_bounding_rect(self, items=None) -> QRectF:
        rect = QRectF()
        for it in (items if items is not None else
                   list(self.node_items.values()) + list(self.comment_items.values())):
            rect = rect.united(it.sceneBoundingRect())
        return rect

    # --- building ----------------------------------------------------------------------------
    @property
    def settled(self) -> bool:
        """The items show the document (no rebuild waiting in the UI work queue)."""
        return not self._rebuild_due

    def _document_replaced(self) -> None:
        if not self.defer_rebuilds:
            self.rebuild()
            return
        # The old document's items go now (nothing may act on them against the new one);
        # the new one's come in a later turn, built from the model as it is then.
        self._drop_items()
        self._rebuild_due = True
        turns().add(self, "rebuild", self._build_items)

    def rebuild(self) -> None:
        """Drop every item and build them again from the model (a new document)."""
        self._drop_items()
        self._build_items()

    def _drop_items(self) -> None:
        self.clear()
        self.node_items.clear()
        self.wire_items.clear()
        self.selected_wires.clear()
        self.comment_items.clear()
        self._wires_of.clear()
        self._node_errors.clear()
        self._previews.clear()

    def _build_items(self) -> None:
        turns().cancel(self, "rebuild")
        self._rebuild_due = False
        g = self.graph
        for cid in sorted(g.comments):
            self._sync_comment(cid)
        for nid in sorted(g.nodes):
            self._add_node(nid)
        for link in sorted(g.links):
            self._add_wire(link)
        if self.controller.analysis is not None:
            self._on_analysed(self.controller.analysis)
        self.rebuilt.emit()

    def _add_node(self, node_id: str) -> None:
        node = self.graph.nodes[node_id]
        item = (RerouteItem if role_of(node.kind) == Role.REROUTE else NodeItem)(node_id, node.kind)
        self.node_items[node_id] = item
        self._wires_of.setdefault(node_id, set())
        item.setPos(node.position[0], node.position[1])
        item.set_ports_visible(self.ports_visible)
        self._refresh_node(node_id, item)
        self.addItem(item)
        if node_id in self._previews:
            item.set_preview(self._previews[node_id])
        if node_id in self.costs:
            item.set_cost(self.costs[node_id])

    def _refresh_node(self, node_id: str, item: NodeItem | None = None) -> None:
        """Title, ports and subtitle from the model (a setting may add or remove ports)."""
        item = item or self.node_items.get(node_id)
        node = self.graph.nodes.get(node_id)
        if item is None or node is None:
            return
        try:
            ports = node_ports(node, self.controller.resolver, self.controller.document)
            ins, outs = port_rows(node.kind, ports.inputs), port_rows(node.kind, ports.outputs)
        except (LookupError, ValueError):
            ins, outs = [], []  # the analysis reports why, as a badge
        # Keep types the last analysis resolved for generic ports that are still there.
        a = self.controller.analysis
        if a is not None:
            it, ot = a.in_types.get(node_id, {}), a.out_types.get(node_id, {})
            ins = [dataclasses.replace(r, type=str(it[r.name])) if r.name in it else r
                   for r in ins]
            outs = [dataclasses.replace(r, type=str(ot[r.name])) if r.name in ot else r
                    for r in outs]
        title, sub, category, tip = describe(node, self.function_name(node))
        expanded = expanded_groups(node)
        if expanded is not None and node_id in self._peeked:
            expanded = expanded | self._peeked[node_id]
        item.set_content(title, sub, category, ins, outs, tip, expanded)
        item.set_muted(node.muted)
        self._update_connected(node_id)

    def function_name(self, node: Node) -> str:
        """The name a called function gives itself ("" if unknown or not a call)."""
        ref = node.settings.get("function") if role_of(node.kind) == Role.FUNCTION_CALL else None
        if not isinstance(ref, str) or not ref:
            return ""
        try:
            return self.controller.resolver.resolve(ref, self.controller.document).name or ""
        except (LookupError, ValueError, OSError):
            return ""

    def _add_wire(self, link: Link) -> None:
        if link in self.wire_items:
            return
        src, dst = self.node_items.get(link.src), self.node_items.get(link.dst)
        if src is None or dst is None:
            return
        wire = WireItem(link, src, dst, self.hairline)
        wire.set_style(src.port_type(link.src_port, True), False)
        self.wire_items[link] = wire
        self._wires_of[link.src].add(link)
        self._wires_of[link.dst].add(link)
        self.addItem(wire)
        self._update_connected(link.src)
        self._update_connected(link.dst)

    def _remove_wire(self, link: Link) -> None:
        wire = self.wire_items.pop(link, None)
        if wire is None:
            return
        self.selected_wires.discard(link)
        for end in (link.src, link.dst):
            self._wires_of.get(end, set()).discard(link)
        self.removeItem(wire)
        self._update_connected(link.src)
        self._update_connected(link.dst)

    def _update_connected(self, node_id: str) -> None:
        item = self.node_items.get(node_id)
        if item is None:
            return
        ins, outs = set(), set()
        for l in self._wires_of.get(node_id, ()):
            if l.dst == node_id:
                ins.add(l.dst_port)
            if l.src == node_id:
                outs.add(l.src_port)
        item.set_connected(ins, outs)

    def _sync_comment(self, comment_id: str) -> None:
        comment = self.graph.comments.get(comment_id)
        item = self.comment_items.get(comment_id)
        if comment is None:
            if item is not None:
                self.removeItem(self.comment_items.pop(comment_id))
            return
        if item is None:
            item = CommentItem(comment_id)
            self.comment_items[comment_id] = item
            self.addItem(item)
        item.set_content(comment)

    # --- model events ------------------------------------------------------------------------
    def _on_changed(self, ev: ChangeEvent) -> None:
        if self._rebuild_due:  # the items are built from the model as it is by then
            return
        what = ev.what
        if what == "node_added":
            self._add_node(ev.node_ids[0])
        elif what == "node_removed":
            nid = ev.node_ids[0]
            for link in list(self._wires_of.pop(nid, ())):
                self._remove_wire(link)
            item = self.node_items.pop(nid, None)
            if item is not None:
                self.removeItem(item)
            self._node_errors.pop(nid, None)
        elif what == "link_added":
            link = self._find_added_link(ev)
            if link is not None:
                self._add_wire(link)
        elif what == "link_removed":
            src, dst = ev.node_ids
            for link in list(self._wires_of.get(dst, ())):
                if (link.src, link.dst, link.dst_port) == (src, dst, ev.port) \
                        and link not in self.graph.links:
                    self._remove_wire(link)
        elif what in ("value", "setting", "label", "muted"):
            self._refresh_node(ev.node_ids[0])
        elif what == "moved":
            nid = ev.node_ids[0]
            item, node = self.node_items.get(nid), self.graph.nodes.get(nid)
            if item is not None and node is not None:
                item.setPos(node.position[0], node.position[1])
        elif what == "comment":
            self._sync_comment(ev.node_ids[0])

    def _find_added_link(self, ev: ChangeEvent) -> Link | None:
        """The link an event names, found by trying the source's outputs (no scan of all links)."""
        src, dst = ev.node_ids
        links = self.graph.links
        item = self.node_items.get(src)
        if item is not None:
            for row in item.outputs:
                link = Link(src, row.name, dst, ev.port)
                if link in links:
                    return link
        return next((l for l in links if (l.src, l.dst, l.dst_port) == (src, dst, ev.port)),
                    None)

    def _on_analysed(self, analysis: Analysis) -> None:
        """Resolved port types, diagnostics as badges, and wire colours from one analysis."""
        if self._rebuild_due:  # the build applies the controller's latest analysis
            return
        diags: dict[str, list[tuple[str, str]]] = {}
        bad_inputs: set[tuple[str, str]] = set()
        for d in analysis.diagnostics:
            if d.node_id is None:
                continue
            msg = f"{d.port}: {d.message}" if d.port else d.message
            diags.setdefault(d.node_id, []).append((d.severity.value, msg))
            if d.port and d.severity.value == "error":
                bad_inputs.add((d.node_id, d.port))
        for nid, item in self.node_items.items():
            item.set_types({k: str(v) for k, v in analysis.in_types.get(nid, {}).items()},
                           {k: str(v) for k, v in analysis.out_types.get(nid, {}).items()})
            self._apply_diagnostics(item, diags.get(nid, []))
        for link, wire in self.wire_items.items():
            wire.set_style(wire.src_item.port_type(link.src_port, True),
                           (link.dst, link.dst_port) in bad_inputs)
        self._last_diags = diags

    def _apply_diagnostics(self, item: NodeItem, diags: list[tuple[str, str]]) -> None:
        extra = self._node_errors.get(item.node_id)
        item.set_diagnostics(([("error", f"GLSL: {extra}")] if extra else []) + diags)

    # --- annotations from the window ---------------------------------------------------------
    def set_node_errors(self, errors: dict[str, str]) -> None:
        """GLSL errors mapped to nodes; replaces the previous set."""
        touched = set(self._node_errors) | set(errors)
        self._node_errors = {k: v for k, v in errors.items() if v}
        last = self._last_diags
        for nid in touched:
            item = self.node_items.get(nid)
            if item is not None:
                self._apply_diagnostics(item, last.get(nid, []))

    def set_node_costs(self, costs: dict[str, tuple[float, str]]) -> None:
        """The cost overlay: node id -> (tint 0-1, tooltip text); {} removes it."""
        for nid in set(self.costs) | set(costs):
            item = self.node_items.get(nid)
            if item is not None:
                item.set_cost(costs.get(nid))
        self.costs = dict(costs)

    def set_node_preview(self, node_id: str, image: QImage | None) -> None:
        if image is None or image.isNull():
            self._previews.pop(node_id, None)
        else:
            self._previews[node_id] = image
        item = self.node_items.get(node_id)
        if item is not None:
            item.set_preview(image)

    # --- wire selection and zoom ---------------------------------------------------------------
    def select_wire(self, link: Link, additive: bool = False) -> None:
        if not additive:
            self.clear_wire_selection()
        wire = self.wire_items.get(link)
        if wire is not None:
            wire.set_selected(True)
            self.selected_wires.add(link)

    def clear_wire_selection(self) -> None:
        for link in self.selected_wires:
            wire = self.wire_items.get(link)
            if wire is not None:
                wire.set_selected(False)
        self.selected_wires.clear()

    def set_zoom(self, zoom: float) -> None:
        """Level of detail: hairline wires below 1.3 device pixels, no port items below
        LOD_PORTS (the node still draws its ports; they just take no clicks there)."""
        hairline = zoom * C.WIRE_WIDTH < 1.3
        if hairline != self.hairline:
            self.hairline = hairline
            for wire in self.wire_items.values():
                wire.set_hairline(hairline)
        ports = zoom >= C.LOD_PORTS
        if ports != self.ports_visible:
            self.ports_visible = ports
            for item in self.node_items.values():
                item.set_ports_visible(ports)

    # --- item callbacks ----------------------------------------------------------------------
    def node_item_moved(self, node_id: str) -> None:
        for link in self._wires_of.get(node_id, ()):
            self.wire_items[link].update_path()

    node_geometry_changed = node_item_moved

    def toggle_group(self, node_id: str, group: str) -> bool:
        """Fold or unfold one pin group of a node: an undoable, non-structural setting change
        (no recompile). False if the node has no such groups or the edit is refused."""
        node = self.graph.nodes.get(node_id)
        open_now = expanded_groups(node) if node is not None else None
        if open_now is None:
            return False
        return self.set_group_expanded(node_id, group, group not in open_now)

    def set_group_expanded(self, node_id: str, group: str, expanded: bool) -> bool:
        command = self._group_command(node_id, group, expanded)
        return command is not None and self.controller.push(command)

    def _group_command(self, node_id: str, group: str, expanded: bool) -> SetSetting | None:
        """The undoable setting change that opens or folds one group (None: nothing to do)."""
        node = self.graph.nodes.get(node_id)
        open_now = expanded_groups(node) if node is not None else None
        if open_now is None or (group in open_now) == expanded:
            return None
        # Keep the groups in the order the node shows them, so the saved list is stable.
        order = [f.group for f in nodes.ATTRIBUTE_FIELDS]
        new = open_now | {group} if expanded else open_now - {group}
        value = sorted(new, key=lambda g: (order.index(g) if g in order else len(order), g))
        verb = "expand" if expanded else "collapse"
        return SetSetting(node_id, nodes.EXPANDED_GROUPS, value, text=f"{verb} {group} pins")

    def peek_group(self, node_id: str, group: str) -> None:
        """Open a folded group while a wire hovers its header, so its pins can be aimed at:
        view state only, no undo step; end_peeks folds it back when the drag ends."""
        node = self.graph.nodes.get(node_id)
        if node is None or expanded_groups(node) is None:
            return
        self._peeked.setdefault(node_id, set()).add(group)
        self._refresh_node(node_id)
        self.node_geometry_changed(node_id)

    def end_peeks(self, dropped: Link | None) -> list[SetSetting]:
        """Fold back the groups peek_group opened. The group the dropped wire connects into
        stays open: returned as the setting change to push with the connection (one undo
        step undoes both)."""
        peeked, self._peeked = self._peeked, {}
        keep: list[SetSetting] = []
        for node_id, groups in peeked.items():
            node = self.graph.nodes.get(node_id)
            if node is None:
                continue
            if dropped is not None and node_id in (dropped.src, dropped.dst):
                port = dropped.dst_port if dropped.dst == node_id else dropped.src_port
                group = nodes.port_group(node.kind, port)
                command = self._group_command(node_id, group, True) if group in groups else None
                if command is not None:
                    keep.append(command)
            self._refresh_node(node_id)
            self.node_geometry_changed(node_id)
        return keep

    def request_comment_edit(self, comment_id: str, rect, positions: dict) -> None:
        old = self.graph.comments.get(comment_id)
        if old is None:
            return
        new = dataclasses.replace(old, rect=tuple(float(x) for x in rect))
        commands = [PutComment(comment_id, new, text="move comment")]
        moved = {nid: p for nid, p in positions.items()
                 if nid in self.graph.nodes and tuple(p) != self.graph.nodes[nid].position}
        if moved:
            commands.append(MoveNodes(moved))
        if not self.controller.push_all(commands, "move comment"):
            self._resync_positions()

    def request_comment_text(self, comment_id: str) -> None:
        self.commentTextRequested.emit(comment_id)

    def commit_moves(self) -> None:
        """After a drag: one MoveNodes for every node whose item left its model position."""
        graph = self.graph
        moved = {}
        g = C.GRID_MINOR
        for it in self.selectedItems():
            if isinstance(it, NodeItem) and it.node_id in graph.nodes:
                p = (it.pos().x(), it.pos().y())
                if self.snap_to_grid:  # the top-left corner lands on the minor grid
                    p = (round(p[0] / g) * g, round(p[1] / g) * g)
                    it.setPos(*p)
                if p != graph.nodes[it.node_id].position:
                    moved[it.node_id] = p
        if moved and not self.controller.push(MoveNodes(moved)):
            self._resync_positions()

    def _resync_positions(self) -> None:
        for nid, item in self.node_items.items():
            node = self.graph.nodes.get(nid)
            if node is not None:
                item.setPos(*node.position)
        for cid in list(self.comment_items):
            self._sync_comment(cid)

    def mouseReleaseEvent(self, event) -> None:
        super().mouseReleaseEvent(event)
        if event.button() == Qt.MouseButton.LeftButton:
            self.commit_moves()

    def helpEvent(self, event) -> None:
        """Port tooltips are made on demand; other items use their stored tooltip."""
        for item in self.items(event.scenePos()):
            if isinstance(item, PortItem):
                QToolTip.showText(event.screenPos(), item.tooltip_text(), event.widget())
                event.accept()
                return
        super().helpEvent(event)

    # --- background --------------------------------------------------------------------------
    def drawBackground(self, painter: QPainter, rect: QRectF) -> None:
        painter.fillRect(rect, C.BACKGROUND)
        zoom = painter.worldTransform().m11()
        for step, color in ((C.GRID_MINOR, C.GRID_MINOR_COLOR), (C.GRID_MAJOR, C.GRID_MAJOR_COLOR)):
            if step * zoom < 8:
                continue
            painter.setPen(color)
            left = int(rect.left() // step) * step
            top = int(rect.top() // step) * step
            x = left
            lines = []
            while x < rect.right():
                lines.append(QLineF(x, rect.top(), x, rect.bottom()))
                x += step
            y = top
            while y < rect.bottom():
                lines.append(QLineF(rect.left(), y, rect.right(), y))
                y += step
            painter.drawLines(lines)

