"""The Help menu's pages: a searchable keyboard reference, the node reference (an index of
every node kind of the catalogue, searchable, with each kind's ports, types, defaults and
ranges and a thumbnail), and the About box."""

from __future__ import annotations

import platform
from html import escape

from PySide6.QtCore import Qt
from PySide6.QtGui import QPixmap
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QHeaderView,
    QLabel,
    QLineEdit,
    QMessageBox,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QTextBrowser,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from matedit.graph import nodes

THUMB = 96  # the index's thumbnail, pixels

# (keys, what it does, where): what is not a canvas command. The canvas's commands come from
# its action table (`canvas_rows`), so the reference shows the keys the canvas answers to.
POINTER = (
    ("Tab over the canvas", "Add a node (the palette), wherever the keyboard focus is",
     "Canvas"),
    ("Right-click", "Node, wire and canvas menu: preview in viewport, insert reroute, …",
     "Canvas"),
    ("Drag from a port", "Connect; drop on nothing to add a connected node", "Canvas"),
    ("Double-click a wire", "Insert a reroute", "Canvas"),
    ("Double-click a node's title", "Rename the node", "Canvas"),
    ("Double-click a function call", "Open the function in a tab", "Canvas"),
    ("Middle drag, Alt+drag, Space+drag", "Pan", "Canvas"),
    ("Wheel", "Zoom about the pointer", "Canvas"),
    ("Esc", "Cancel a wire, clear the selection", "Canvas"),
    ("F1 in the palette", "Documentation of the highlighted kind", "Palette"),
)
WINDOW = (
    ("Left drag", "Orbit the camera", "Viewport"),
    ("Shift+drag, middle drag", "Pan the camera", "Viewport"),
    ("Wheel", "Dolly the camera", "Viewport"),
    ("Double-click", "Reset the camera", "Viewport"),
    ("← / → on exposure", "Exposure −/+ 0.1 EV (Page Up/Down: 1 EV)", "Viewport"),
    ("Ctrl+N", "New material", "File"),
    ("Ctrl+O", "Open a material or a function", "File"),
    ("Ctrl+S / Ctrl+Shift+S", "Save, save as (the active tab)", "File"),
    ("Ctrl+E", "Export shaders", "File"),
    ("Ctrl+Z / Ctrl+Shift+Z", "Undo, redo (the active tab)", "Edit"),
    ("Ctrl+/", "This reference", "Help"),
)


def canvas_rows() -> list[tuple[str, str, str]]:
    """The canvas action table's commands with their keys (needs a QGuiApplication: standard
    keys are the platform's)."""
    from matedit.app.canvas.actions import TABLE, key_text

    return [(key_text(c), c.tip or c.text.replace("&", ""), "Canvas") for c in TABLE if c.keys]


def shortcut_rows() -> list[tuple[str, str, str]]:
    """Every row of the reference."""
    return [*canvas_rows(), *POINTER, *WINDOW]


class ShortcutReference(QDialog):
    """Every shortcut in one table, filtered as you type."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("shortcutReference")
        self.setWindowTitle("Keyboard and mouse reference")
        lay = QVBoxLayout(self)
        self.search = QLineEdit()
        self.search.setPlaceholderText("Search shortcuts…")
        self.search.setClearButtonEnabled(True)
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["Keys", "Does", "Where"])
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
        head = self.table.horizontalHeader()
        head.setSectionResizeMode(0, QHeaderView.ResizeMode.ResizeToContents)
        head.setSectionResizeMode(1, QHeaderView.ResizeMode.Stretch)
        head.setSectionResizeMode(2, QHeaderView.ResizeMode.ResizeToContents)
        lay.addWidget(self.search)
        lay.addWidget(self.table, 1)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.close)
        lay.addWidget(buttons)
        self.search.textChanged.connect(self.fill)
        self.fill("")
        self.resize(680, 560)

    def fill(self, query: str) -> None:
        words = query.lower().split()
        rows = [r for r in shortcut_rows() if all(w in " ".join(r).lower() for w in words)]
        self.table.setRowCount(len(rows))
        for i, row in enumerate(rows):
            for j, text in enumerate(row):
                self.table.setItem(i, j, QTableWidgetItem(text))

    def shown_rows(self) -> list[tuple[str, str, str]]:
        return [tuple(self.table.item(i, j).text() for j in range(3))
                for i in range(self.table.rowCount())]


def _fmt(value) -> str:
    if value is None:
        return "—"
    if value == nodes.MESH_UV:
        return "mesh UVs"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(_fmt(v) for v in value) + ")"
    return str(value)


def node_doc_html(kind: str) -> str:
    """A node kind's page, from its catalogue entry: what it does, its ports with types,
    defaults and ranges, and its settings."""
    d = nodes.REGISTRY.get(kind)
    if d is None:
        return f"<h2>{escape(kind)}</h2><p>Unknown node kind.</p>"
    out = [f"<h2>{escape(d.title)}</h2>",
           f"<p><i>{escape(d.category)}</i> · <code>{escape(d.kind)}</code></p>",
           f"<p>{escape(d.description)}</p>"]

    def table(title: str, rows: list[list[str]], head: list[str]) -> None:
        if not rows:
            return
        out.append(f"<h3>{escape(title)}</h3><table cellspacing='0' cellpadding='3' "
                   "border='1' style='border-collapse: collapse'>")
        out.append("<tr>" + "".join(f"<th align='left'>{escape(h)}</th>" for h in head) +
                   "</tr>")
        for r in rows:
            out.append("<tr>" + "".join(f"<td>{escape(c)}</td>" for c in r) + "</tr>")
        out.append("</table>")

    generic = "T (any numeric type, resolved from the wires)"
    ins = [[i.name, generic if i.type == "T" else i.type, _fmt(i.default),
            f"{_fmt(i.range[0])} … {_fmt(i.range[1])}" if i.range else "",
            ("required. " if i.required else "") + i.doc] for i in d.inputs]
    table("Inputs", ins, ["name", "type", "default", "range", "about"])
    outs = [[o.name, generic if o.type == "T" else o.type, o.doc] for o in d.outputs]
    table("Outputs", outs, ["name", "type", "about"])
    vals = [[v.name, v.type, _fmt(v.default),
             f"{_fmt(v.range[0])} … {_fmt(v.range[1])}" if v.range else "", v.doc]
            for v in d.values]
    table("Values", vals, ["name", "type", "default", "range", "about"])
    sets = [[s.name, s.kind, _fmt(s.default), ", ".join(s.choices), s.doc] for s in d.settings]
    table("Settings", sets, ["name", "kind", "default", "choices", "about"])
    if d.ports_rule:
        out.append(f"<p>Its ports depend on its settings ({escape(d.ports_rule)}).</p>")
    return "\n".join(out)


def kind_matches(kind: str, words: list[str]) -> bool:
    """Whether every search word is in the kind's title, id, category, description or port
    names (case-insensitive)."""
    d = nodes.REGISTRY.get(kind)
    if d is None:
        return False
    hay = " ".join([d.title, d.kind, d.category, d.description,
                    *(p.name for p in (*d.inputs, *d.outputs, *d.values)),
                    *(s.name for s in d.settings)]).lower()
    return all(w in hay for w in words)


class NodeDocs(QDialog):
    """Help › Node Reference: every node kind of the catalogue, by category, searchable by
    name, category, description and port, with the kind's page and a thumbnail of its first
    output at its defaults (the CPU evaluator on the preview sphere). Not modal, so it can
    stay open beside the canvas."""

    def __init__(self, kind: str = "", parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("nodeDocs")
        self.setWindowFlag(Qt.WindowType.Tool, True)
        self.kind = ""
        self._thumbs: dict[str, QPixmap | None] = {}
        self.search = QLineEdit()
        self.search.setPlaceholderText("Search nodes: name, category, port…")
        self.search.setClearButtonEnabled(True)
        self.search.textChanged.connect(self._filter)
        self.tree = QTreeWidget()
        self.tree.setHeaderHidden(True)
        self.tree.setObjectName("nodeIndex")
        self.count = QLabel()
        self.thumbnail = QLabel()
        self.thumbnail.setFixedSize(THUMB + 4, THUMB + 4)
        self.thumbnail.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.browser = QTextBrowser()
        left = QWidget()
        ll = QVBoxLayout(left)
        ll.setContentsMargins(0, 0, 0, 0)
        ll.addWidget(self.search)
        ll.addWidget(self.tree, 1)
        ll.addWidget(self.count)
        right = QWidget()
        rl = QVBoxLayout(right)
        rl.setContentsMargins(0, 0, 0, 0)
        rl.addWidget(self.thumbnail)
        rl.addWidget(self.browser, 1)
        split = QSplitter()
        split.addWidget(left)
        split.addWidget(right)
        split.setSizes([240, 560])
        lay = QVBoxLayout(self)
        lay.addWidget(split)
        self.resize(860, 600)
        self._items: dict[str, QTreeWidgetItem] = {}
        by_cat: dict[str, list] = {}
        for d in nodes.REGISTRY.values():
            by_cat.setdefault(d.category, []).append(d)
        for cat in sorted(by_cat):
            top = QTreeWidgetItem([cat])
            top.setFlags(Qt.ItemFlag.ItemIsEnabled)
            self.tree.addTopLevelItem(top)
            for d in sorted(by_cat[cat], key=lambda d: d.title.lower()):
                it = QTreeWidgetItem([d.title])
                it.setData(0, Qt.ItemDataRole.UserRole, d.kind)
                it.setToolTip(0, d.kind)
                top.addChild(it)
                self._items[d.kind] = it
        self.tree.expandAll()
        self.tree.currentItemChanged.connect(self._picked)
        self._filter("")
        self.show_kind(kind or min(self._items, key=lambda k: self._items[k].text(0).lower()))

    def show_kind(self, kind: str) -> None:
        """Shows `kind`'s page; an unknown kind gets its own "unknown" page."""
        self.kind = kind
        d = nodes.REGISTRY.get(kind)
        self.setWindowTitle(f"{d.title if d else kind} — node reference")
        self.browser.setHtml(node_doc_html(kind))
        self._show_thumbnail(kind)
        it = self._items.get(kind)
        if it is not None and self.tree.currentItem() is not it:
            if it.isHidden():
                self.search.clear()
            self.tree.setCurrentItem(it)
            self.tree.scrollToItem(it)

    def shown_kinds(self) -> list[str]:
        """The kinds the search leaves in the index, in its order."""
        out = []
        for i in range(self.tree.topLevelItemCount()):
            top = self.tree.topLevelItem(i)
            out += [top.child(j).data(0, Qt.ItemDataRole.UserRole)
                    for j in range(top.childCount()) if not top.child(j).isHidden()]
        return out

    def _filter(self, text: str) -> None:
        words = text.lower().split()
        shown = 0
        for i in range(self.tree.topLevelItemCount()):
            top = self.tree.topLevelItem(i)
            any_shown = False
            for j in range(top.childCount()):
                it = top.child(j)
                ok = kind_matches(it.data(0, Qt.ItemDataRole.UserRole), words)
                it.setHidden(not ok)
                any_shown |= ok
                shown += ok
            top.setHidden(not any_shown)
        self.count.setText(f"{shown} of {len(self._items)} node kinds")
        kinds = self.shown_kinds()
        if words and kinds and self.kind not in kinds:
            self.show_kind(kinds[0])

    def _picked(self, item: QTreeWidgetItem | None, _previous=None) -> None:
        kind = item.data(0, Qt.ItemDataRole.UserRole) if item is not None else None
        if kind and kind != self.kind:
            self.show_kind(kind)

    def _show_thumbnail(self, kind: str) -> None:
        if kind not in self._thumbs:
            from matedit.app.previews import kind_thumbnail

            img = kind_thumbnail(kind, THUMB)
            self._thumbs[kind] = QPixmap.fromImage(img) if img is not None else None
        pix = self._thumbs[kind]
        if pix is None:
            self.thumbnail.clear()
            self.thumbnail.setText("no preview")
        else:
            self.thumbnail.setPixmap(pix)

    def has_thumbnail(self) -> bool:
        return self._thumbs.get(self.kind) is not None


def _version(dist: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(dist)
    except PackageNotFoundError:
        return "not installed"


def about_text(gl_renderer: str = "") -> str:
    """Versions of matedit and what it stands on, and the OpenGL renderer in use."""
    from PySide6 import __version__ as pyside_version
    from PySide6.QtCore import qVersion

    rows = [("matedit", _version("matedit")),
            ("Python", platform.python_version()),
            ("Qt / PySide6", f"{qVersion()} / {pyside_version}"),
            ("moderngl", _version("moderngl")),
            ("numpy", _version("numpy")),
            ("OpenImageIO", _version("OpenImageIO")),
            ("networkx", _version("networkx")),
            ("OpenGL renderer", gl_renderer or "not started")]
    body = "".join(f"<tr><td><b>{escape(k)}</b></td><td>{escape(v)}</td></tr>" for k, v in rows)
    return ("<h3>matedit</h3><p>A node-based material editor after Karis, "
            "“Real Shading in Unreal Engine 4”.</p>"
            f"<table cellpadding='2'>{body}</table>")


def show_about(parent: QWidget | None, gl_renderer: str = "") -> None:
    QMessageBox.about(parent, "About matedit", about_text(gl_renderer))
