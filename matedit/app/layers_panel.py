"""The layer stack as a painting program shows it: top layer first.

A view over the document's `layer_stack` node (`LayerStack.find`); every edit
is a LayerStack command through the controller, and the list is rebuilt from
the graph on each change, so it can never disagree with the canvas. Rows can
be reordered by drag, and layer files dropped from the library (or a file
manager) are added on top.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QMimeData, Qt, Signal
from PySide6.QtGui import QStandardItem, QStandardItemModel
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QMenu,
    QPushButton,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.controller import DocumentController
from matedit.app.fields import FloatField
from matedit.app.paths import reference_for
from matedit.app.theme import icon
from matedit.app.turns import turns
from matedit.graph.commands import (
    AddNode,
    CommandError,
    Connect,
    Disconnect,
    Macro,
    MoveNodes,
    SetSetting,
    SetValue,
)
from matedit.graph.layers import Layer, LayerStack, parked_wires
from matedit.graph.model import ChangeEvent, ChangeKind, Link, Node
from matedit.graph.nodes import Role, kind_for, role_of
from matedit.graph.ports import COLOR_LAYER_BLENDS, LAYER_BLENDS
from matedit.io.document import FormatError, load
from matedit.resources import graphs_dir

# The base layer "Create layer stack" makes of what the output showed: one
# MaterialAttributes input, passed through.
GRAPH_LAYER = graphs_dir() / "layers" / "graph_input.json"
STACK_SHIFT = 300.0  # how far the output moves right for the new stack

LAYER_MIME = "application/x-matedit-layer"  # absolute path of a layer file (from the library)
ROW_MIME = "application/x-matedit-layer-row"  # id of a layer being reordered


STRUCTURAL_BLENDS = {
    "alpha": ("Alpha", "Lerps every field by mask × opacity"),
    "height": ("Height", "Shows the layer where its height rises above the base's"),
    "coat": ("Coat", "Lays the layer over the ones below as a clear coat: its roughness, "
             "colour, IOR and normal become the coat's, mask × opacity its weight"),
    "film": ("Thin film", "Lays the layer's thin film (thickness, IOR) over the ones below by "
             "mask × opacity, keeping their other fields: an oil film on a metal"),
}


def blend_modes() -> list[tuple[str, str, str]]:
    """(mode, title, tooltip) of every layer blend mode, in the menu's order: alpha, height,
    coat, then the catalogue's colour Blend nodes (their titles and descriptions)."""
    from matedit.graph import nodes

    out = [(m, *STRUCTURAL_BLENDS[m]) for m in LAYER_BLENDS if m in STRUCTURAL_BLENDS]
    for mode in COLOR_LAYER_BLENDS:
        d = nodes.definition(f"blend_{mode}")
        title = d.title.split(":", 1)[-1].strip()
        out.append((mode, title, f"Base colour: {d.description.split(' Mixed')[0]} "
                    "Other fields by mask × opacity"))
    return out


def layer_files() -> list[Path]:
    return sorted((graphs_dir() / "layers").glob("*.json"))


def layer_title(path: Path) -> str:
    try:
        doc = load(path)
        return doc.name or path.stem.replace("_", " ").title()
    except FormatError:
        return path.stem


def wire_report(cmd) -> str:
    """What a layer edit did to wires, in words ("" when it touched none): no layer edit
    cuts a wire without saying so."""
    subs = cmd.commands if isinstance(cmd, Macro) else [cmd]
    cut = [c.link for c in subs if isinstance(c, Disconnect)]
    back = [c.link for c in subs if isinstance(c, Connect)]
    parked_ports: set[str] = set()
    for c in subs:
        if isinstance(c, SetSetting) and c.name == "layers" and c.value and \
                isinstance(c.value[0], dict):
            base = c.value[0]
            parked_ports = {f"{base.get('id')}_{w.get('port')}" for w in parked_wires(base)}
    parts = []
    parked_now = sum(1 for lk in cut if lk.dst_port in parked_ports)
    if parked_now:
        parts.append(f"{parked_now} wire{'s' if parked_now != 1 else ''} parked on the base "
                     "layer (they come back when it is moved up)")
    if len(cut) > parked_now:
        n = len(cut) - parked_now
        parts.append(f"{n} wire{'s' if n != 1 else ''} removed: "
                     + ", ".join(sorted(lk.dst_port for lk in cut)[:4]))
    if back:
        parts.append(f"{len(back)} parked wire{'s' if len(back) != 1 else ''} reconnected")
    return "; ".join(parts)


class _LayerRow(QWidget):
    """Eye, name, blend and opacity of one layer."""

    def contextMenuEvent(self, ev) -> None:  # noqa: N802 - Qt's
        s = self.panel.stack
        menu = QMenu(self)
        solo = s is not None and s.is_solo(self.layer_id)
        act = menu.addAction("Show every layer" if solo else "Solo (alone over the base)")
        act.triggered.connect(lambda _=False: self.panel.solo(self.layer_id))
        self.panel.run_menu(menu, ev.globalPos())

    def __init__(self, panel: LayersPanel, layer: Layer, is_base: bool, opacity: float,
                 parked: list[dict] | None = None):
        super().__init__()
        self.setObjectName("layerRow")
        self.layer_id = layer.id
        self.panel = panel
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 3, 4, 3)
        lay.setSpacing(2)
        top = QHBoxLayout()
        top.setSpacing(4)
        self.eye = QToolButton()
        self.eye.setCheckable(True)
        self.eye.setChecked(layer.visible)
        self.eye.setIcon(icon("eye" if layer.visible else "eye-off"))
        self.eye.setToolTip("Show or hide this layer (Alt+click: this layer alone over the "
                            "base, again: every layer)")
        self.eye.clicked.connect(lambda on: panel.eye_clicked(layer.id, on))
        self.name = QLineEdit(layer.name or layer.id)
        self.name.setObjectName("layerName")  # ui/style.qss: bold on the row's background
        self.name.setFrame(False)
        self.name.setToolTip(f"{layer.function}\nEdit to rename")
        self.name.editingFinished.connect(lambda: panel.rename(layer.id, self.name.text()))
        # the cost column (LayersPanel.set_costs), next to the eye: a narrow dock scrolls the
        # row's right-hand side out of view
        self.cost = QLabel("")
        self.cost.setObjectName("layerCost")
        self.cost.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        self.cost.setMinimumWidth(self.cost.fontMetrics().horizontalAdvance("100 %") + 2)
        top.addWidget(self.eye)
        top.addWidget(self.cost)
        top.addWidget(self.name, 1)
        self.blend = QComboBox()
        extra: str | None = None  # a blend function file's path: its own list
        if is_base:
            self.blend.addItem("base")
            self.blend.setEnabled(False)
            self.blend.setToolTip("The bottom layer is the base: nothing to blend over")
        else:
            extra = None if layer.blend in LAYER_BLENDS else str(layer.blend)
            self.blend.setModel(panel.blend_model(extra))  # one list of modes for every row
            self.blend.setCurrentIndex(self.blend.findData(layer.blend))
            self.blend.setToolTip("How this layer blends over the ones below")
            self.blend.currentIndexChanged.connect(
                lambda i: panel.set_blend(layer.id, self.blend.itemData(i)))
        # The mode menu has its own row, under the name, so it keeps the panel's whole width
        # even in a narrow dock; its list opens as wide as its longest title.
        self.blend.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.blend.setMinimumContentsLength(6)
        view = self.blend.view()
        view.setMinimumWidth(view.sizeHintForColumn(0) + 24 if is_base
                             else panel.blend_list_width(extra, view))
        lay.addLayout(top)
        row = QHBoxLayout()
        lab = QLabel("blend")
        lab.setObjectName("fieldLabel")
        row.addSpacing(26)
        row.addWidget(lab)
        row.addWidget(self.blend, 1)
        lay.addLayout(row)
        self.parked = None
        if is_base and parked:
            n = len(parked)
            self.parked = QLabel(f"{n} blend wire{'s' if n != 1 else ''} parked")
            self.parked.setObjectName("fieldLabel")
            self.parked.setToolTip(
                "The base layer blends over nothing, so these wires wait here and come back "
                "when the layer is moved up:\n" + "\n".join(
                    f"{w['from'][0]}.{w['from'][1]} → {w.get('port')}" for w in parked
                    if isinstance(w.get("from"), list) and len(w["from"]) == 2))
            row = QHBoxLayout()
            row.addSpacing(26)
            row.addWidget(self.parked, 1)
            lay.addLayout(row)
        self.opacity: FloatField | None = None
        if not is_base:
            row = QHBoxLayout()
            lab = QLabel("opacity")
            lab.setObjectName("fieldLabel")
            self.opacity = FloatField(opacity, (0.0, 1.0))
            self.opacity.setToolTip("Overall strength of the layer (its opacity port)")
            self.opacity.edited.connect(lambda v, m: panel.set_opacity(layer.id, v, m))
            row.addSpacing(26)
            row.addWidget(lab)
            row.addWidget(self.opacity, 1)
            lay.addLayout(row)


class LayerList(QListWidget):
    """The rows; drags reorder (by command), drops of layer files add layers."""

    def __init__(self, panel: LayersPanel) -> None:
        super().__init__()
        self.panel = panel
        self.setDragDropMode(QAbstractItemView.DragDropMode.DragDrop)
        self.setDefaultDropAction(Qt.DropAction.MoveAction)
        self.setDragEnabled(True)
        self.setAcceptDrops(True)
        self.setDropIndicatorShown(True)
        self.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.setSpacing(1)

    def mimeTypes(self) -> list[str]:  # noqa: N802 - Qt's name
        return [ROW_MIME, LAYER_MIME, "text/uri-list"]

    def mimeData(self, items) -> QMimeData:  # noqa: N802 - Qt's name
        data = QMimeData()
        if items:
            data.setData(ROW_MIME, items[0].data(Qt.ItemDataRole.UserRole).encode())
        return data

    def _accepts(self, mime: QMimeData) -> bool:
        if mime.hasFormat(ROW_MIME) or mime.hasFormat(LAYER_MIME):
            return True
        return mime.hasUrls() and any(u.toLocalFile().endswith(".json") for u in mime.urls())

    def dragEnterEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self._accepts(event.mimeData()):
            event.acceptProposedAction()
        else:
            event.ignore()

    def dragMoveEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self._accepts(event.mimeData()):
            super().dragMoveEvent(event)
            event.acceptProposedAction()
        else:
            event.ignore()

    def drop_row(self, pos) -> int:
        """The list row a drop at `pos` lands before (0 = top)."""
        item = self.itemAt(pos)
        if item is None:
            return self.count()
        rect = self.visualItemRect(item)
        row = self.row(item)
        return row + 1 if pos.y() > rect.center().y() else row

    def dropEvent(self, event) -> None:  # noqa: N802 - Qt's name
        mime = event.mimeData()
        row = self.drop_row(event.position().toPoint())
        if mime.hasFormat(ROW_MIME):
            self.panel.move_to_row(bytes(mime.data(ROW_MIME)).decode(), row)
        elif mime.hasFormat(LAYER_MIME):
            self.panel.add_layer_file(Path(bytes(mime.data(LAYER_MIME)).decode()), row)
        elif mime.hasUrls():
            for url in mime.urls():
                if url.toLocalFile().endswith(".json"):
                    self.panel.add_layer_file(Path(url.toLocalFile()), row)
        else:
            event.ignore()
            return
        # The model changed by command; the list rebuilds itself, so Qt must not move items.
        event.setDropAction(Qt.DropAction.IgnoreAction)
        event.accept()


class LayersPanel(QWidget):
    """Layers of the document's layer stack, top first, with add/remove/reorder/hide/blend."""

    message = Signal(str)
    layerSelected = Signal(str)  # the layer stack node id, to show it in the inspector

    def __init__(self, controller: DocumentController, parent=None) -> None:
        super().__init__(parent)
        self.controller = controller
        self.costs: dict[str, tuple[float, float]] = {}  # layer id -> (instructions, share)
        self.run_menu = lambda menu, at: menu.exec(at)  # tests read the menu instead
        # node id -> new positions of the nodes a grown stack covers (the window's canvas)
        self.make_room: Callable[[str], dict] | None = None
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(4)
        bar = QHBoxLayout()
        self.add_button = QToolButton()
        self.add_button.setIcon(icon("add"))
        self.add_button.setText("Add layer")
        self.add_button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        self.add_button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
        self.add_menu = QMenu(self)
        self.add_menu.aboutToShow.connect(self._fill_add_menu)
        self.add_button.setMenu(self.add_menu)
        self.remove_button = QToolButton()
        self.remove_button.setIcon(icon("delete"))
        self.remove_button.setToolTip("Remove the selected layer")
        self.remove_button.clicked.connect(self.remove_selected)
        self.up_button = QToolButton()
        self.up_button.setText("▲")
        self.up_button.setToolTip("Move the selected layer up")
        self.up_button.clicked.connect(lambda: self._nudge(-1))
        self.down_button = QToolButton()
        self.down_button.setText("▼")
        self.down_button.setToolTip("Move the selected layer down")
        self.down_button.clicked.connect(lambda: self._nudge(1))
        bar.addWidget(self.add_button)
        bar.addStretch(1)
        for b in (self.up_button, self.down_button, self.remove_button):
            bar.addWidget(b)
        lay.addLayout(bar)
        self.list = LayerList(self)
        lay.addWidget(self.list, 1)
        self.empty = QWidget()
        el = QVBoxLayout(self.empty)
        hint = QLabel("This material has no layer stack.\nAdd a layer to create one, or drop "
                      "a layer from the Library here.")
        hint.setObjectName("emptyHint")
        hint.setWordWrap(True)
        el.addWidget(hint)
        self.create_button = QPushButton("Create layer stack")
        self.create_button.clicked.connect(lambda _checked=False: self.create_stack())
        el.addWidget(self.create_button)
        el.addStretch(1)
        lay.addWidget(self.empty)
        self.list.itemSelectionChanged.connect(self._selected)
        # rows still to build (rebuild with `per_turn`): (layer, is the base, opacity, parked
        # wires), top first, one a turn (a row costs ~10 ms; three of them were one 30 ms block)
        self._rows_left: list[tuple] = []
        self._per_turn = 0
        self._keep_selected: str | None = None
        controller.changed.connect(self._on_change)
        controller.documentReplaced.connect(self._rebuild_all)
        self._built: tuple | None = None  # what the rows were built from
        # the blend menus' lists, shared by the rows (key: a blend file of a row, or None),
        # and the width each opens at
        self._blend_models: dict[str | None, QStandardItemModel] = {}
        self._blend_widths: dict[str | None, int] = {}
        self.rebuild()

    # --- model -----------------------------------------------------------------------------
    @property
    def stack(self) -> LayerStack | None:
        return LayerStack.find(self.controller.document.graph, self.controller.resolver,
                               self.controller.document)

    def layer_ids_top_first(self) -> list[str]:
        s = self.stack
        return [layer.id for layer in reversed(s.layers)] if s else []

    def _on_change(self, event: ChangeEvent) -> None:
        s = self.stack
        if event.kind == ChangeKind.STRUCTURAL and (
                s is None or s.node_id in event.node_ids or event.what in ("node_added",
                                                                            "node_removed")):
            self._rebuild_later()
        elif event.kind == ChangeKind.VALUE and s is not None and s.node_id in event.node_ids:
            self.refresh_values()

    def blend_model(self, extra: str | None = None) -> QStandardItemModel:
        """The blend menu's items (title, mode as the item's data, tooltip): the structural
        blends, a separator, the colour blends, and `extra` (a blend function file) after
        another. Built once and shared: filling a menu item by item cost a row ~4 ms."""
        model = self._blend_models.get(extra)
        if model is not None:
            return model
        model = QStandardItemModel(self)

        def add(title: str, mode: str, tip: str) -> None:
            item = QStandardItem(title)
            item.setData(mode, Qt.ItemDataRole.UserRole)
            item.setData(tip, Qt.ItemDataRole.ToolTipRole)
            model.appendRow(item)

        def separator() -> None:  # as QComboBox.insertSeparator marks one
            item = QStandardItem()
            item.setData("separator", Qt.ItemDataRole.AccessibleDescriptionRole)
            item.setFlags(Qt.ItemFlag.NoItemFlags)
            model.appendRow(item)

        for i, (mode, title, tip) in enumerate(blend_modes()):
            if i == len(STRUCTURAL_BLENDS):
                separator()
            add(title, mode, tip)
        if extra is not None:
            separator()
            add(Path(extra).stem.replace("_", " "), extra, extra)
        self._blend_models[extra] = model
        return model

    def blend_list_width(self, extra: str | None, view) -> int:
        """The width the blend list of `blend_model(extra)`, shown in `view`, opens at: its
        longest title's, measured once."""
        width = self._blend_widths.get(extra)
        if width is None:
            width = self._blend_widths[extra] = view.sizeHintForColumn(0) + 24
        return width

    def _rebuild_all(self) -> None:
        """Another document: every row built again, once control is back in the event loop
        (opening a file into a new tab replaces the document twice in one event)."""
        self._built = None
        self._rebuild_later()

    def _rebuild_later(self) -> None:
        """`rebuild` in a turn of the UI work queue (matedit.app.turns), its rows one a turn
        after it; however many times asked before then, once."""
        turns().add(self, "rebuild", lambda: self.rebuild(per_turn=1))

    def rebuild(self, per_turn: int = 0) -> None:
        """The rows, built again only when what they show has changed (the stack, its layers
        or their settings: building a row's widgets costs ~10 ms, and a structural edit
        anywhere in the graph comes here); opacity values are set in place. `per_turn` > 0:
        that many rows a turn of the UI work queue (matedit.app.turns: the rebuilds after
        another document and after structural edits), `settled` once all are built."""
        turns().cancel(self, "rebuild")  # this one shows the document as it is
        turns().cancel(self, "rows")
        self._rows_left = []
        s = self.stack
        if s is not None:
            node = self.controller.document.graph.nodes[s.node_id]
            key = (s.node_id, repr(s.layers), repr(node.settings.get("layers", [])))
            if key == self._built and self.list.count() == len(s.layers):
                self.refresh_values()
                return
            self._built = key
        else:
            self._built = None
        self._keep_selected = self.selected_layer()
        self.list.clear()
        self.empty.setVisible(s is None)
        self.list.setVisible(s is not None)
        for b in (self.remove_button, self.up_button, self.down_button):
            b.setEnabled(s is not None and bool(s.layers))
        if s is None:
            return
        layers = s.layers
        node = self.controller.document.graph.nodes[s.node_id]
        entries = node.settings.get("layers", [])
        values = node.values
        for index in range(len(layers) - 1, -1, -1):  # the top layer first
            opacity = values.get(f"{layers[index].id}_opacity", 1.0)
            self._rows_left.append(
                (layers[index], index == 0,
                 float(opacity) if isinstance(opacity, (int, float)) else 1.0,
                 parked_wires(entries[index]) if index == 0 else None))
        self._per_turn = per_turn
        if per_turn > 0:
            turns().add(self, "rows", self._build_rows)
        else:
            self._build_rows(len(self._rows_left))

    @property
    def settled(self) -> bool:
        """The rows show the document as it is (no rebuild waiting or under way)."""
        return not (turns().pending(self, "rebuild") or self._rows_left)

    def _build_rows(self, count: int = 0) -> None:
        """The next `count` rows still to build (default: the rebuild's `per_turn`)."""
        for _ in range(count or self._per_turn):
            if not self._rows_left:
                break
            layer, base, opacity, parked = self._rows_left.pop(0)
            row = _LayerRow(self, layer, base, opacity, parked)
            item = QListWidgetItem()
            item.setData(Qt.ItemDataRole.UserRole, layer.id)
            item.setToolTip(f"{layer.name}: {layer.function}")
            self.list.addItem(item)
            self.list.setItemWidget(item, row)
            item.setSizeHint(row.sizeHint())  # once parented: the row polished once, as shown
            if layer.id == self._keep_selected:
                item.setSelected(True)
        if self._rows_left:
            turns().add(self, "rows", self._build_rows)
        else:
            self._show_costs()

    def set_costs(self, costs: dict[str, tuple[float, float]]) -> None:
        """Each layer's (instructions, share of the material's) in its row's cost column
        (matedit.app.stats_dock: computed off the UI thread); kept across rebuilds."""
        self.costs = dict(costs)
        self._show_costs()

    def _show_costs(self) -> None:
        costs = self.costs
        for i in range(self.list.count()):
            row = self.list.itemWidget(self.list.item(i))
            if not isinstance(row, _LayerRow):
                continue
            c = costs.get(row.layer_id)
            row.cost.setText("" if c is None else f"{100 * c[1]:.0f} %")
            row.cost.setToolTip("" if c is None else
                                f"{c[0]:.1f} instructions (glsl450, dynamic, the layer's "
                                f"nodes and its blend): {100 * c[1]:.1f} % of the material's")

    def refresh_values(self) -> None:
        s = self.stack
        if s is None:
            return
        values = self.controller.document.graph.nodes[s.node_id].values
        for i in range(self.list.count()):
            row = self.list.itemWidget(self.list.item(i))
            if isinstance(row, _LayerRow) and row.opacity is not None:
                v = values.get(f"{row.layer_id}_opacity", 1.0)
                if isinstance(v, (int, float)):
                    row.opacity.set_value(float(v))

    def selected_layer(self) -> str | None:
        items = self.list.selectedItems()
        return items[0].data(Qt.ItemDataRole.UserRole) if items else None

    def select_layer(self, layer_id: str) -> None:
        for i in range(self.list.count()):
            item = self.list.item(i)
            item.setSelected(item.data(Qt.ItemDataRole.UserRole) == layer_id)

    def _selected(self) -> None:
        s = self.stack
        if s is not None and self.selected_layer():
            self.layerSelected.emit(s.node_id)

    def _push(self, make) -> bool:
        s = self.stack
        if s is None:
            return False
        try:
            cmd = make(s)
        except CommandError as exc:
            self.message.emit(str(exc))
            return False
        if not self.controller.push(cmd):
            return False
        if self.make_room is not None:  # the stack grew: it never covers its neighbours
            self.controller.flush()  # its new ports, measured on the canvas
            moves = self.make_room(s.node_id)
            if moves:
                self.controller.amend(MoveNodes(moves, text="make room"))
        report = wire_report(cmd)
        if report:
            self.message.emit(report)
        return True

    # --- edits -----------------------------------------------------------------------------
    def set_visible(self, layer_id: str, on: bool) -> None:
        self._push(lambda s: s.set(layer_id, visible=bool(on)))

    def eye_clicked(self, layer_id: str, on: bool) -> None:
        """The eye: show or hide; with Alt, solo (`solo`)."""
        from PySide6.QtWidgets import QApplication

        if QApplication.keyboardModifiers() & Qt.KeyboardModifier.AltModifier:
            self.solo(layer_id)
        else:
            self.set_visible(layer_id, on)

    def solo(self, layer_id: str) -> bool:
        """This layer alone over the base; on a solo layer, every layer shown again."""
        s = self.stack
        was = s.is_solo(layer_id) if s is not None else False
        if not self._push(lambda st: st.solo(layer_id)):
            return False
        self.message.emit("Every layer shown" if was else
                          f"Solo: {layer_id} over the base (Alt+click its eye again to show "
                          "every layer)")
        return True

    def set_blend(self, layer_id: str, blend: str | None) -> None:
        if not isinstance(blend, str) or not blend:  # a separator row
            return
        self._push(lambda s: s.set(layer_id, blend=blend))

    def rename(self, layer_id: str, name: str) -> None:
        name = name.strip()
        s = self.stack
        if s is None or not name:
            return
        cur = next((layer for layer in s.layers if layer.id == layer_id), None)
        if cur is not None and cur.name != name:
            self._push(lambda s: s.set(layer_id, name=name))

    def set_opacity(self, layer_id: str, value: float, merge_id: int | None = None) -> None:
        s = self.stack
        if s is None:
            return
        port = f"{layer_id}_opacity"
        if self.controller.document.graph.nodes[s.node_id].values.get(port) == value:
            return
        self.controller.push(SetValue(s.node_id, port, float(value),
                                      text=f"set {layer_id} opacity"), merge_id=merge_id)

    def remove_layer(self, layer_id: str) -> bool:
        return self._push(lambda s: s.remove(layer_id))

    def remove_selected(self) -> None:
        lid = self.selected_layer()
        if lid:
            self.remove_layer(lid)

    def move_to_row(self, layer_id: str, row: int) -> bool:
        """Moves a layer so it lands before list row `row` (0 = top; rows count the layer)."""
        ids = self.layer_ids_top_first()
        if layer_id not in ids:
            return False
        old = ids.index(layer_id)
        new_row = row - 1 if row > old else row
        new_row = max(0, min(len(ids) - 1, new_row))
        if new_row == old:
            return False
        ok = self._push(lambda s: s.move(layer_id, len(ids) - 1 - new_row))
        if ok:
            self.rebuild()
            self.select_layer(layer_id)
        return ok

    def _nudge(self, delta: int) -> None:
        lid = self.selected_layer()
        if not lid:
            return
        row = self.layer_ids_top_first().index(lid)
        self.move_to_row(lid, row + (delta if delta < 0 else delta + 1))

    def add_layer_file(self, path: Path, row: int | None = None) -> str | None:
        """Adds the layer function at `path` above list row `row` (None: on top)."""
        path = Path(path).resolve()
        try:
            fn = load(path)
        except FormatError as exc:
            self.message.emit(str(exc))
            return None
        if not fn.is_function:
            self.message.emit(f"{path.name} is a material, not a material layer")
            return None
        ref = reference_for(self.controller.document, path)
        s = self.stack
        if s is None:
            return self.create_stack(path)
        lid = s.new_layer_id(path.stem.split("_")[0] or "layer")
        layer = Layer(lid, ref, fn.name or path.stem, "alpha", True)
        n = len(s.layers)
        index = None if row is None else max(0, min(n, n - row))
        if self._push(lambda s: s.add(layer, index)):
            return lid
        return None

    def create_stack(self, first_layer: Path | None = None) -> str | None:
        """Adds a layer stack node wired into the material output. What the output was
        wired to is adopted as the base layer (the "From the graph" layer, whose input it
        feeds), so the material looks as it did; `first_layer` goes on top of it. The id of
        `first_layer`'s entry (or of the base, without one)."""
        doc = self.controller.document
        graph = doc.graph
        out = next((n for n in sorted(graph.nodes.values(), key=lambda n: n.id)
                    if role_of(n.kind) == Role.MATERIAL_OUTPUT), None)
        fed = graph.incoming(out.id, "attributes") if out is not None else None
        entries = []
        lid = None
        if fed is not None:  # adopt the graph the output shows as the base layer
            lid = "graph"
            entries.append(Layer(lid, reference_for(doc, GRAPH_LAYER), "From the graph",
                                 "alpha").to_json())
        if first_layer is not None:
            fn = load(first_layer)
            lid = "".join(c for c in first_layer.stem.split("_")[0] if c.isalnum()) or "layer"
            lid = (lid if lid[0].isalpha() else "l" + lid) + "1"
            lid = lid if lid != "graph" else "graph2"
            entries.append(Layer(lid, reference_for(doc, first_layer),
                                 fn.name or first_layer.stem).to_json())
        sid = graph.new_id("stack")
        # The stack takes the output's place and the output moves right, so the stack sits
        # between what fed the output and the output, on neither.
        pos = out.position if out is not None else (0.0, 0.0)
        cmds: list = [AddNode(Node(sid, kind_for(Role.LAYER_STACK), pos, {"layers": entries}))]
        if out is not None:
            cmds.append(MoveNodes({out.id: (out.position[0] + STACK_SHIFT, out.position[1])}))
        if fed is not None:
            cmds += [Disconnect(fed),
                     Connect(Link(fed.src, fed.src_port, sid, f"{entries[0]['id']}_attributes"))]
        if out is not None:
            cmds.append(Connect(Link(sid, "attributes", out.id, "attributes")))
        if not self.controller.push(Macro(cmds, text="add layer stack")):
            return None
        return lid

    def _fill_add_menu(self) -> None:
        self.add_menu.clear()
        for path in layer_files():
            act = self.add_menu.addAction(icon("layer"), layer_title(path))
            act.setToolTip(str(path))
            act.triggered.connect(lambda _=False, p=path: self.add_layer_file(p))
        self.add_menu.addSeparator()
        other = self.add_menu.addAction("Other layer file…")
        other.triggered.connect(self._add_other)

    def _add_other(self) -> None:
        path, _ = file_dialogs.open_file(self, "Add a material layer",
                                         str(graphs_dir() / "layers"),
                                         "Material layers (*.json)")
        if path:
            self.add_layer_file(Path(path))
