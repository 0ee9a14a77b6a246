"""A node on the canvas: a category-coloured header, typed ports in rows, a badge, a preview.

The item is dumb on purpose: the scene tells it what to show (`set_content`,
`set_types`, `set_connected`, `set_diagnostics`, `set_preview`) from the model's
events and the analysis, and it never reads or edits the model. It paints into
a device-coordinate cache, so a frame of a big graph is mostly pixmap blits.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from html import escape

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import (
    QBrush,
    QColor,
    QImage,
    QLinearGradient,
    QPainter,
    QPainterPath,
    QPen,
    QPixmap,
)
from PySide6.QtWidgets import QGraphicsItem, QGraphicsRectItem, QStyleOptionGraphicsItem

from matedit.app.canvas import constants as C
from matedit.app.canvas.port_item import PortItem, port_shape


@dataclass(frozen=True)
class PortRow:
    """What a node shows for one port: its name, display type and one-line doc."""

    name: str
    type: str
    doc: str = ""
    generic: bool = False  # declared `T`: takes any float or vector until wired
    group: str = ""  # the pin group it folds into ("" : always shown)


@dataclass(frozen=True)
class GroupHeader:
    """A foldable pin group's header row: its name, how many pins, which side, open or not."""

    group: str
    count: int
    is_output: bool
    expanded: bool

    @property
    def label(self) -> str:
        arrow = "\u25be" if self.expanded else "\u25b8"  # down: open, right: folded
        return f"{arrow} {self.group} ({self.count})"


@dataclass
class NodeLayout:
    width: float
    height: float
    top: float  # y of the first port row's top
    inputs: dict[str, QPointF] = field(default_factory=dict)
    outputs: dict[str, QPointF] = field(default_factory=dict)
    preview: QRectF | None = None
    # Foldable groups: the header rows (with the y of their centre) and the pins a folded
    # group hides; a hidden pin's entry in inputs/outputs is its header's point, so wires
    # to it end on the header.
    headers: list[tuple[GroupHeader, float]] = field(default_factory=list)
    hidden: dict[tuple[str, bool], str] = field(default_factory=dict)
    # What each side shows, top to bottom: a PortRow or a GroupHeader per row.
    in_rows: list[PortRow | GroupHeader] = field(default_factory=list)
    out_rows: list[PortRow | GroupHeader] = field(default_factory=list)

    def header_at(self, local: QPointF) -> GroupHeader | None:
        """The header row under a point in node coordinates (the whole row is the button)."""
        for header, y in self.headers:
            if abs(local.y() - y) <= C.ROW_HEIGHT / 2 and 0.0 <= local.x() <= self.width:
                return header
        return None


def fold_rows(rows: list[PortRow], is_output: bool, expanded: frozenset[str] | None
              ) -> tuple[list[PortRow | GroupHeader], dict[str, str]]:
    """One side's rows with its pin groups folded: ungrouped pins first, then each group (in
    the order its first pin comes) as a header row followed, if expanded, by its pins.
    Also the hidden pins, name -> group. `expanded` None: the node has no groups."""
    if expanded is None or not any(r.group for r in rows):
        return list(rows), {}
    out: list[PortRow | GroupHeader] = [r for r in rows if not r.group]
    order = list(dict.fromkeys(r.group for r in rows if r.group))
    hidden: dict[str, str] = {}
    for g in order:
        members = [r for r in rows if r.group == g]
        is_open = g in expanded
        out.append(GroupHeader(g, len(members), is_output, is_open))
        if is_open:
            out.extend(members)
        else:
            hidden.update((r.name, g) for r in members)
    return out, hidden


def _row_label(row: PortRow | GroupHeader) -> str:
    return row.label if isinstance(row, GroupHeader) else row.name


def measure(title: str, subtitle: str, inputs: list[PortRow], outputs: list[PortRow],
            preview: bool = False, expanded: frozenset[str] | None = None) -> NodeLayout:
    """The size of a node and where its ports sit (pure geometry, usable before an item exists).

    Inputs and outputs share rows, left and right, as in Unreal's material editor:
    a node is as tall as its longer side, not the sum of both. With `expanded` (the open
    pin groups), grouped pins fold under header rows (see `fold_rows`).
    """
    in_rows, in_hidden = fold_rows(inputs, False, expanded)
    out_rows, out_hidden = fold_rows(outputs, True, expanded)
    width_of = C.text_width
    head = 2 * 8.0 + width_of("title", title)
    if subtitle:
        head = max(head, 16.0 + width_of("subtitle", subtitle))
    ins = [width_of("port", _row_label(p)) for p in in_rows]
    outs = [width_of("port", _row_label(p)) for p in out_rows]
    rows_w = 0.0
    for i in range(max(len(ins), len(outs))):
        a = ins[i] if i < len(ins) else 0.0
        b = outs[i] if i < len(outs) else 0.0
        rows_w = max(rows_w, a + b + 2 * C.LABEL_GAP + (16.0 if a and b else 6.0))
    width = max(C.NODE_MIN_WIDTH, head, rows_w, (C.PREVIEW_SIZE + 16) if preview else 0.0)
    width = min(C.NODE_MAX_WIDTH, float(round(width / 4.0 + 0.49) * 4))
    top = C.HEADER_HEIGHT + (C.SUBTITLE_HEIGHT if subtitle else 0.0) + 3.0
    lay = NodeLayout(width, 0.0, top, in_rows=in_rows, out_rows=out_rows)
    for rows, hidden, table, x, out in ((in_rows, in_hidden, lay.inputs, 0.0, False),
                                        (out_rows, out_hidden, lay.outputs, width, True)):
        at: dict[str, QPointF] = {}
        for i, r in enumerate(rows):
            y = top + (i + 0.5) * C.ROW_HEIGHT
            if isinstance(r, GroupHeader):
                lay.headers.append((r, y))
                at[r.group] = QPointF(x, y)
            else:
                table[r.name] = QPointF(x, y)
        for name, g in hidden.items():
            table[name] = at[g]
            lay.hidden[(name, out)] = g
    y = top + max(len(in_rows), len(out_rows)) * C.ROW_HEIGHT
    if preview:
        y += 4.0
        lay.preview = QRectF((width - C.PREVIEW_SIZE) / 2, y, C.PREVIEW_SIZE, C.PREVIEW_SIZE)
        y += C.PREVIEW_SIZE
    lay.height = y + C.BODY_PAD
    return lay


class BadgeItem(QGraphicsItem):
    """The diagnostic badge in a node's header; its tooltip lists the messages."""

    def __init__(self, parent: QGraphicsItem) -> None:
        super().__init__(parent)
        self.color = C.ERROR
        self.setAcceptHoverEvents(True)

    def set(self, color: QColor, messages: list[str]) -> None:
        self.color = color
        self.setToolTip("<br>".join(escape(m) for m in messages))
        self.update()

    def boundingRect(self) -> QRectF:
        r = C.BADGE_RADIUS + 1
        return QRectF(-r, -r, 2 * r, 2 * r)

    def paint(self, painter: QPainter, option, widget=None) -> None:
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.setPen(QPen(C.NODE_BODY_EDGE, 1.0))
        painter.setBrush(self.color)
        painter.drawEllipse(QPointF(0, 0), C.BADGE_RADIUS, C.BADGE_RADIUS)
        painter.setPen(QPen(QColor("#ffffff"), 2.0, Qt.PenStyle.SolidLine, Qt.PenCapStyle.RoundCap))
        painter.drawLine(QPointF(0, -3.6), QPointF(0, 1.0))
        painter.drawPoint(QPointF(0, 3.8))


class NodeItem(QGraphicsRectItem):
    """One graph node, positioned at the model's (top-left) position.

    A QGraphicsRectItem only so that Qt answers `boundingRect` in C++ (from the rect,
    the node plus a margin for the ports astride its edges): it is asked for thousands
    of times a frame on a big graph. The pen is NoPen and `paint` is ours.
    """

    def __init__(self, node_id: str, kind: str) -> None:
        super().__init__()
        self.node_id = node_id
        self.kind = kind
        self.title = kind
        self.subtitle = ""
        self.category = ""
        self.inputs: list[PortRow] = []
        self.outputs: list[PortRow] = []
        self.connected_inputs: set[str] = set()
        self.connected_outputs: set[str] = set()
        self.diagnostics: list[tuple[str, str]] = []  # (severity, message)
        self._tooltip = ""  # the node's own tooltip, before the cost overlay's lines
        self.cost: tuple[float, str] | None = None  # the cost overlay's (tint 0-1, text)
        self.muted = False  # bypassed: drawn faded, its pass-through drawn across it
        self._preview: QPixmap | None = None
        self._ports: dict[tuple[str, bool], PortItem] = {}
        self._badge: BadgeItem | None = None
        self._ports_visible = True
        self.expanded: frozenset[str] | None = None  # open pin groups (None: no groups)
        self.layout = NodeLayout(C.NODE_MIN_WIDTH, C.HEADER_HEIGHT + C.BODY_PAD, C.HEADER_HEIGHT)
        F = QGraphicsItem.GraphicsItemFlag
        self.setFlags(F.ItemIsMovable | F.ItemIsSelectable | F.ItemSendsGeometryChanges)
        self.setCacheMode(QGraphicsItem.CacheMode.DeviceCoordinateCache)
        self.setZValue(C.Z_NODE)
        self.setPen(Qt.PenStyle.NoPen)
        self._set_bounds()

    # --- content, from the scene -------------------------------------------------------------
    def set_content(self, title: str, subtitle: str, category: str, inputs: list[PortRow],
                    outputs: list[PortRow], tooltip: str = "",
                    expanded: frozenset[str] | None = None) -> None:
        if (title, subtitle, category, inputs, outputs, expanded) == (
                self.title, self.subtitle, self.category, self.inputs, self.outputs,
                self.expanded):
            return
        self.title, self.subtitle, self.category = title, subtitle, category
        self.inputs, self.outputs = list(inputs), list(outputs)
        self.expanded = expanded
        self._tooltip = tooltip
        self._show_tooltip()
        self._relayout()

    def set_muted(self, muted: bool) -> None:
        if muted != self.muted:
            self.muted = muted
            self.update()

    def set_cost(self, cost: tuple[float, str] | None) -> None:
        """The cost overlay: tint (0 none, 1 the costliest node) and the figures' text for the
        tooltip; None: no overlay."""
        if cost == self.cost:
            return
        self.cost = cost
        self._show_tooltip()
        self.update()

    def _show_tooltip(self) -> None:
        if self.cost is None:
            self.setToolTip(self._tooltip)
        else:
            extra = escape(self.cost[1]).replace("\n", "<br>")
            self.setToolTip(f"{self._tooltip}<br><br>{extra}" if self._tooltip else extra)

    def set_types(self, in_types: dict[str, str], out_types: dict[str, str]) -> bool:
        """Concrete types from the analysis (generic `T` ports resolve); True if any changed."""
        changed = False
        for rows, types, out in ((self.inputs, in_types, False), (self.outputs, out_types, True)):
            for i, row in enumerate(rows):
                t = types.get(row.name)
                if t and t != row.type:
                    rows[i] = PortRow(row.name, t, row.doc, row.generic, row.group)
                    port = self._ports.get((row.name, out))
                    if port is not None:
                        port.set_type(t)
                    changed = True
        if changed:
            self.layout.in_rows = [self._current(r, False) for r in self.layout.in_rows]
            self.layout.out_rows = [self._current(r, True) for r in self.layout.out_rows]
            self.update()
        return changed

    def _current(self, row: PortRow | GroupHeader, out: bool) -> PortRow | GroupHeader:
        if isinstance(row, GroupHeader):
            return row
        return next((r for r in (self.outputs if out else self.inputs) if r.name == row.name),
                    row)

    def set_connected(self, inputs: set[str], outputs: set[str]) -> None:
        if inputs != self.connected_inputs or outputs != self.connected_outputs:
            self.connected_inputs, self.connected_outputs = set(inputs), set(outputs)
            self.update()

    def set_diagnostics(self, diagnostics: list[tuple[str, str]]) -> None:
        if diagnostics == self.diagnostics:
            return
        self.diagnostics = list(diagnostics)
        if not diagnostics:
            if self._badge is not None:
                self._badge.setParentItem(None)
                if self.scene() is not None:
                    self.scene().removeItem(self._badge)
                self._badge = None
        else:
            if self._badge is None:
                self._badge = BadgeItem(self)
            error = any(s == "error" for s, _ in diagnostics)
            self._badge.set(C.ERROR if error else C.WARNING,
                            [f"{s}: {m}" for s, m in diagnostics])
            self._place_badge()
        self.update()

    def has_error(self) -> bool:
        return any(s == "error" for s, _ in self.diagnostics)

    def set_preview(self, image: QImage | None) -> None:
        had = self._preview is not None
        if image is None or image.isNull():
            self._preview = None
        else:
            size = int(C.PREVIEW_SIZE * 2)  # twice the slot: sharp at zoom 2
            self._preview = QPixmap.fromImage(image.scaled(
                size, size, Qt.AspectRatioMode.KeepAspectRatio,
                Qt.TransformationMode.SmoothTransformation))
        if had != (self._preview is not None):
            self._relayout()
        else:
            self.update()

    def has_preview(self) -> bool:
        return self._preview is not None

    # --- ports -------------------------------------------------------------------------------
    def port(self, name: str, is_output: bool) -> PortItem | None:
        return self._ports.get((name, is_output))

    def ports(self) -> list[PortItem]:
        return list(self._ports.values())

    def port_scene_pos(self, name: str, is_output: bool) -> QPointF:
        """Where a wire attaches; a port the node no longer has attaches at the node's edge."""
        table = self.layout.outputs if is_output else self.layout.inputs
        local = table.get(name)
        if local is None:
            local = QPointF(self.layout.width if is_output else 0.0, C.HEADER_HEIGHT / 2)
        return self.pos() + local

    def is_hidden(self, name: str, is_output: bool) -> bool:
        """Whether the port is folded away under its group's header."""
        return (name, is_output) in self.layout.hidden

    def header_at(self, scene_pos: QPointF) -> GroupHeader | None:
        """The pin group header row under a scene point, if any."""
        return self.layout.header_at(scene_pos - self.pos())

    def header_connected(self, header: GroupHeader) -> bool:
        """Whether a pin of the group is wired (shown on a folded header)."""
        rows = self.outputs if header.is_output else self.inputs
        wired = self.connected_outputs if header.is_output else self.connected_inputs
        return any(r.group == header.group and r.name in wired for r in rows)

    def port_type(self, name: str, is_output: bool) -> str:
        rows = self.outputs if is_output else self.inputs
        return next((r.type for r in rows if r.name == name), "T")

    # --- geometry ----------------------------------------------------------------------------
    def _set_bounds(self) -> None:
        m = C.PORT_RADIUS + 2.5  # ports sit astride the edges
        self.setRect(QRectF(-m, -m, self.layout.width + 2 * m, self.layout.height + 2 * m))

    def set_ports_visible(self, visible: bool) -> None:
        self._ports_visible = visible
        for key, port in self._ports.items():
            port.setVisible(visible and key not in self.layout.hidden)

    def _relayout(self) -> None:
        self.layout = measure(self.title, self.subtitle, self.inputs, self.outputs,
                              self._preview is not None, self.expanded)
        self._set_bounds()
        wanted: dict[tuple[str, bool], tuple[PortRow, QPointF]] = {}
        for row in self.inputs:
            wanted[(row.name, False)] = (row, self.layout.inputs[row.name])
        for row in self.outputs:
            wanted[(row.name, True)] = (row, self.layout.outputs[row.name])
        for key in list(self._ports):
            if key not in wanted:
                port = self._ports.pop(key)
                port.setParentItem(None)
                if self.scene() is not None:
                    self.scene().removeItem(port)
        for key, (row, pos) in wanted.items():
            port = self._ports.get(key)
            if port is None:
                port = PortItem(self, self.node_id, row.name, key[1], row.type, row.doc)
                port.generic = row.generic
                self._ports[key] = port
            else:
                port.set_type(row.type)
                port.doc = row.doc
            port.setVisible(self._ports_visible and key not in self.layout.hidden)
            port.setPos(pos)
        self._place_badge()
        self.update()
        scene = self.scene()
        if scene is not None and hasattr(scene, "node_geometry_changed"):
            scene.node_geometry_changed(self.node_id)

    def _place_badge(self) -> None:
        if self._badge is not None:
            # Astride the top-right corner, so it never hides the title.
            self._badge.setPos(self.layout.width - 2.0, 0.0)

    def shape(self) -> QPainterPath:
        path = QPainterPath()
        path.addRoundedRect(QRectF(0, 0, self.layout.width, self.layout.height), C.CORNER,
                            C.CORNER)
        return path

    def mousePressEvent(self, event) -> None:
        """A click on a pin group's header folds or unfolds it (through the scene, as an
        undoable setting change); anywhere else selects and drags as usual."""
        header = (self.layout.header_at(event.pos())
                  if event.button() == Qt.MouseButton.LeftButton else None)
        scene = self.scene()
        if header is not None and scene is not None and hasattr(scene, "toggle_group"):
            scene.toggle_group(self.node_id, header.group)
            event.accept()
            return
        super().mousePressEvent(event)

    def itemChange(self, change, value):
        GC = QGraphicsItem.GraphicsItemChange
        if change == GC.ItemPositionHasChanged:
            scene = self.scene()
            if scene is not None and hasattr(scene, "node_item_moved"):
                scene.node_item_moved(self.node_id)
        elif change == GC.ItemSelectedHasChanged:
            self.setZValue(C.Z_NODE_SELECTED if value else C.Z_NODE)
        return super().itemChange(change, value)

    # --- painting ----------------------------------------------------------------------------
    def paint(self, painter: QPainter, option: QStyleOptionGraphicsItem, widget=None) -> None:
        lod = QStyleOptionGraphicsItem.levelOfDetailFromTransform(painter.worldTransform())
        overview = lod < C.LOD_TEXT
        lay = self.layout
        rect = QRectF(0, 0, lay.width, lay.height)
        header = C.category_color(self.category)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, lod > 0.2)
        body = QPainterPath()
        body.addRoundedRect(rect, C.CORNER, C.CORNER)
        painter.setPen(Qt.PenStyle.NoPen)
        # Zoomed out, the whole block takes the category's colour, under a big title.
        painter.setBrush(header.darker(135) if overview else C.NODE_BODY)
        painter.drawPath(body)
        painter.save()
        painter.setClipRect(QRectF(0, 0, lay.width, C.HEADER_HEIGHT))
        grad = QLinearGradient(0, 0, 0, C.HEADER_HEIGHT)
        grad.setColorAt(0.0, header.lighter(118))
        grad.setColorAt(1.0, header)
        painter.setBrush(QBrush(grad))
        painter.drawPath(body)
        painter.restore()
        if self.cost is not None and self.cost[0] > 0:  # the cost overlay: a warm veil,
            tint = min(1.0, self.cost[0])  # denser for costlier nodes; none on free ones
            painter.setBrush(QColor(255, 96, 32, int(24 + 168 * tint)))
            painter.drawPath(body)
        if self.muted:  # bypassed: faded under a dark veil, with a dashed edge
            painter.setBrush(C.BYPASS_VEIL)
            painter.drawPath(body)
        if self.isSelected():
            edge = QPen(C.NODE_SELECTED, 2.0 if not overview else 2.0 / max(lod, 0.1))
        elif self.has_error():
            edge = QPen(C.ERROR, 1.6 if not overview else 1.6 / max(lod, 0.1))
        else:
            edge = QPen(C.NODE_BODY_EDGE, 1.2)
        if self.muted:
            edge.setStyle(Qt.PenStyle.DashLine)
        painter.setPen(edge)
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawPath(body)
        if overview:
            # No port labels, subtitle or thumbnail: only the port marks, for the wires' ends.
            self._paint_ports(painter, labels=False)
            if lod >= C.LOD_TITLE_NONE:
                self._paint_overview_title(painter, lod)
            return
        # Title, elided when the node is at its widest; it grows as the view zooms out.
        px = C.header_title_px(lod)
        painter.setFont(C.title_font(px))
        painter.setPen(C.NODE_TEXT)
        room = lay.width - 14
        title = C.title_metrics(px).elidedText(self.title, Qt.TextElideMode.ElideRight, room)
        painter.drawText(QRectF(8, 0, room, C.HEADER_HEIGHT),
                         Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft, title)
        if self.subtitle:
            painter.setFont(C.subtitle_font())
            painter.setPen(C.NODE_SUBTEXT)
            sub = C.metrics("subtitle").elidedText(self.subtitle, Qt.TextElideMode.ElideMiddle,
                                                   lay.width - 16)
            painter.drawText(QRectF(8, C.HEADER_HEIGHT, lay.width - 16, C.SUBTITLE_HEIGHT + 2),
                             Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft, sub)
        self._paint_ports(painter, labels=True)
        if self._preview is not None and lay.preview is not None:
            painter.drawPixmap(lay.preview, self._preview, QRectF(self._preview.rect()))
            painter.setPen(QPen(C.NODE_BODY_EDGE, 1.0))
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.drawRect(lay.preview)

    def overview_title(self, lod: float) -> tuple[int, list[str]]:
        """The zoomed-out title: its pixel size (scene units) and its lines, wrapped to fit the
        node's body at zoom `lod` (the largest size that fits, else the smallest, elided)."""
        inner = self._overview_rect(lod)
        return _overview_title(self.title, inner.width(), inner.height(), lod)

    def _overview_rect(self, lod: float) -> QRectF:
        pad = max(C.PORT_RADIUS + 1.0, 2.0 / max(lod, 1e-6))
        return QRectF(pad, pad, self.layout.width - 2 * pad, self.layout.height - 2 * pad)

    def _paint_overview_title(self, painter: QPainter, lod: float) -> None:
        px, lines = self.overview_title(lod)
        if not lines:
            return
        fm = C.overview_metrics(px)
        inner = self._overview_rect(lod)
        painter.save()
        painter.setClipRect(QRectF(0, 0, self.layout.width, self.layout.height))
        painter.setFont(C.overview_font(px))
        painter.setPen(C.NODE_TEXT)
        step = fm.lineSpacing()
        y = inner.center().y() - len(lines) * step / 2
        for text in lines:
            painter.drawText(QRectF(inner.left(), y, inner.width(), step),
                             Qt.AlignmentFlag.AlignCenter, text)
            y += step
        painter.restore()

    def _paint_ports(self, painter: QPainter, labels: bool) -> None:
        lay = self.layout
        fm = C.metrics("port")
        if labels:
            painter.setFont(C.port_font())
        # Labels sharing a row split the width: each side leaves the other what it needs.
        across = lay.width - 2 * C.LABEL_GAP - 10
        if labels:  # header rows first, as bands under everything else on their row
            for _, y in lay.headers:
                painter.fillRect(QRectF(1.0, y - C.ROW_HEIGHT / 2 + 1, lay.width - 2.0,
                                        C.ROW_HEIGHT - 2), C.GROUP_HEADER_FILL)
        in_w = [C.text_width("port", _row_label(r)) for r in lay.in_rows]
        out_w = [C.text_width("port", _row_label(r)) for r in lay.out_rows]
        for rows, out, connected in ((lay.in_rows, False, self.connected_inputs),
                                     (lay.out_rows, True, self.connected_outputs)):
            other_w = in_w if out else out_w
            x = lay.width if out else 0.0
            for i, row in enumerate(rows):
                pos = QPointF(x, lay.top + (i + 0.5) * C.ROW_HEIGHT)
                if isinstance(row, GroupHeader):
                    wired = self.header_connected(row)
                    if not row.expanded:  # a folded group keeps a mark where its wires end
                        self._paint_header_mark(painter, pos, wired)
                else:
                    port_shape(painter, pos, row.type, C.PORT_RADIUS, row.name in connected)
                if not labels:
                    continue
                text_of = _row_label(row)
                own = out_w[i] if out else in_w[i]
                other = other_w[i] if i < len(other_w) else 0.0
                room = max(across - other, across / 2) if other else across
                text = text_of if own <= room else fm.elidedText(
                    text_of, Qt.TextElideMode.ElideRight, room)
                if isinstance(row, GroupHeader):
                    painter.setPen(C.GROUP_HEADER_TEXT)
                else:
                    painter.setPen(C.PORT_LABEL_DIM if (not out and row.name in connected)
                                   else C.PORT_LABEL)
                r = QRectF(0, pos.y() - C.ROW_HEIGHT / 2, 0, C.ROW_HEIGHT)
                if out:
                    r.setLeft(lay.width - C.LABEL_GAP - room)
                    r.setRight(lay.width - C.LABEL_GAP)
                    align = Qt.AlignmentFlag.AlignRight
                else:
                    r.setLeft(C.LABEL_GAP)
                    r.setRight(C.LABEL_GAP + room)
                    align = Qt.AlignmentFlag.AlignLeft
                painter.drawText(r, align | Qt.AlignmentFlag.AlignVCenter, text)

    @staticmethod
    def _paint_header_mark(painter: QPainter, pos: QPointF, wired: bool) -> None:
        """A folded group's mark on the edge: filled when one of its pins is wired."""
        painter.setPen(QPen(C.GROUP_HEADER_TEXT, 1.4))
        painter.setBrush(QBrush(C.GROUP_HEADER_TEXT) if wired else QBrush(C.NODE_BODY))
        r = C.PORT_RADIUS - 1.0
        painter.drawEllipse(pos, r, r)


@lru_cache(maxsize=4096)
def _overview_title(title: str, width: float, height: float, lod: float
                    ) -> tuple[int, tuple[str, ...]]:
    """NodeItem.overview_title for a body of `width` x `height` inside its margins. Kept for
    the next paint: the search over sizes asks Qt for the width of every trial line, and at
    one zoom the nodes of one kind share their title and size (a duplicated graph all of
    them)."""
    hi, lo = C.overview_title_px(lod)
    step = max(1, (hi - lo) // 4)
    sizes = list(range(hi, lo, -step)) + [lo]
    for px in sizes:
        fm = C.overview_metrics(px)
        lines = _wrap(title, px, width)
        if (len(lines) * fm.lineSpacing() <= height
                and all(C.overview_width(px, t) <= width for t in lines)):
            return px, tuple(lines)
    fm = C.overview_metrics(lo)
    room = max(1, int(height // fm.lineSpacing()))
    lines = _wrap(title, lo, width)
    if len(lines) > room:
        lines = lines[:room - 1] + [" ".join(lines[room - 1:])]
    return lo, tuple(fm.elidedText(t, Qt.TextElideMode.ElideRight, width) for t in lines)


def _wrap(text: str, pixel_size: int, width: float) -> list[str]:
    """Greedy word wrap in the zoomed-out title font of `pixel_size`: as many words a line
    as fit in `width` (a long word keeps its line)."""
    lines: list[str] = []
    for word in text.split():
        if lines and C.overview_width(pixel_size, lines[-1] + " " + word) <= width:
            lines[-1] += " " + word
        else:
            lines.append(word)
    return lines
