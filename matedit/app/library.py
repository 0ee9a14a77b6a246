"""The library: materials, layers and functions from graphs/ and the artist's folders.

A searchable tree. Double-clicking a material opens it, a function opens it in a
tab, and layers can be dragged onto the Layers panel (or double-clicked to add
on top). User folders are remembered in QSettings.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

from PySide6.QtCore import QMimeData, QSettings, Qt, Signal
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHBoxLayout,
    QLineEdit,
    QToolButton,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.layers_panel import LAYER_MIME
from matedit.app.theme import icon
from matedit.app.turns import turns
from matedit.io.document import FormatError, load_shared
from matedit.resources import graphs_dir

PATH_ROLE = Qt.ItemDataRole.UserRole
KIND_ROLE = Qt.ItemDataRole.UserRole + 1
SECTIONS = (("Materials", "materials", "material"), ("Layers", "layers", "layer"),
            ("Functions", "functions", "function"))
USER_FOLDERS_KEY = "library/folders"
# folders of the built-in library that hold matedit's own templates, not samples for artists
INTERNAL = frozenset({"interop"})
# reading a turn of `LibraryPanel.list_in_turns` (a file takes about 1 ms to classify)
LIST_BUDGET_S = 0.006


def classify(path: Path) -> tuple[str, str, str] | None:
    """(kind, title, description) of a graph file; kind is material, layer or function."""
    try:
        doc = load_shared(path)  # a function read here is not read again by a compile
    except FormatError:
        return None
    title = doc.name or path.stem.replace("_", " ").title()
    if not doc.is_function:
        return "material", title, doc.description
    from matedit.graph.ports import PortError, function_interface

    try:
        iface = function_interface(doc)
    except PortError:
        return "function", title, doc.description
    is_layer = any(o.type == "MaterialAttributes" for o in iface.outputs) and \
        sum(1 for i in iface.inputs if i.type == "MaterialAttributes") == 0
    return ("layer" if is_layer else "function"), title, doc.description


class LibraryTree(QTreeWidget):
    def __init__(self) -> None:
        super().__init__()
        self.setHeaderHidden(True)
        self.setDragEnabled(True)
        self.setDragDropMode(QAbstractItemView.DragDropMode.DragOnly)

    def mimeData(self, items) -> QMimeData:  # noqa: N802 - Qt's name
        data = QMimeData()
        for it in items:
            path = it.data(0, PATH_ROLE)
            if path and it.data(0, KIND_ROLE) == "layer":
                data.setData(LAYER_MIME, str(path).encode())
                break
        return data


class LibraryPanel(QWidget):
    materialOpenRequested = Signal(str)
    functionOpenRequested = Signal(str)
    layerAddRequested = Signal(str)
    instanceOpenRequested = Signal(str)  # see matedit.app.instance_editor
    instanceCreateRequested = Signal(str)  # a material or instance to make an instance of
    # after each refresh, the .json files listed (matedit.app.instance_editor hangs the
    # instances among them under their parents' items)
    refreshed = Signal(list)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(4)
        bar = QHBoxLayout()
        self.search = QLineEdit()
        self.search.setPlaceholderText("Search materials, layers, functions…")
        self.search.setClearButtonEnabled(True)
        self.search.textChanged.connect(self.filter)
        add = QToolButton()
        add.setIcon(icon("folder-add"))
        add.setToolTip("Add a folder of your own graphs to the library")
        add.clicked.connect(self._add_folder_dialog)
        bar.addWidget(self.search, 1)
        bar.addWidget(add)
        lay.addLayout(bar)
        self.tree = LibraryTree()
        self.tree.itemDoubleClicked.connect(self._activated)
        lay.addWidget(self.tree, 1)
        self.tree.setContextMenuPolicy(Qt.ContextMenuPolicy.CustomContextMenu)
        self.tree.customContextMenuRequested.connect(self._context_menu)
        self.folder_dialog = file_dialogs.existing_folder  # tests replace it
        # the files are read (and the tree filled) by the first `refresh` or `ensure_listed`;
        # the main window has it done once its viewport shows the first frame
        self.files: list[Path] = []
        self.listed = False
        self._listing: Iterator[tuple[str, Path]] | None = None  # list_in_turns under way
        self._sections: dict[str, QTreeWidgetItem] = {}
        self._files: list[Path] = []  # what the listing under way found (`_begin`)

    def ensure_listed(self) -> None:
        """The tree filled, if no `refresh` has filled it yet (a listing in turns under way
        is finished at once)."""
        if not self.listed:
            self.refresh()

    # --- folders ---------------------------------------------------------------------------
    def user_folders(self) -> list[Path]:
        raw = QSettings().value(USER_FOLDERS_KEY, [])
        if isinstance(raw, str):
            raw = [raw]
        return [Path(p) for p in (raw or []) if p]

    def add_folder(self, folder: str | Path) -> None:
        folders = [str(p) for p in self.user_folders()]
        if str(folder) not in folders:
            folders.append(str(folder))
            QSettings().setValue(USER_FOLDERS_KEY, folders)
        self.refresh()

    def _add_folder_dialog(self) -> None:
        folder = self.folder_dialog(self, "Add a library folder")
        if folder:
            self.add_folder(folder)

    # --- tree ------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Reads every file of the library's folders now and fills the tree."""
        self._listing = None  # a listing in turns under way is replaced
        listing = self._begin()
        for origin, path in listing:
            self._add(origin, path)
        self._end()

    def list_in_turns(self) -> None:
        """Fills the tree as `refresh` does, a few files a turn (at most about LIST_BUDGET_S
        of reading a turn of the UI work queue, matedit.app.turns, so that ticks and paints
        run between turns): the start-up step. `listed` turns true, and `refreshed` is
        emitted, at its end; a `refresh` or `ensure_listed` meanwhile reads the rest at once."""
        if self.listed or self._listing is not None:
            return
        self._listing = iter(self._begin())
        turns().add(self, "list", self._list_turn)

    def _list_turn(self) -> None:
        listing = self._listing
        if listing is None:
            return
        end = time.perf_counter() + LIST_BUDGET_S
        for origin, path in listing:
            self._add(origin, path)
            if time.perf_counter() > end:
                turns().add(self, "list", self._list_turn)
                return
        self._listing = None
        self._end()

    def _begin(self) -> list[tuple[str, Path]]:
        """Clears the tree to its sections; (origin, path) of each file to classify."""
        self.tree.clear()
        self._sections = {}
        for title, _sub, kind in SECTIONS:
            top = QTreeWidgetItem(self.tree, [title])
            top.setIcon(0, icon(kind))
            top.setFlags(top.flags() & ~Qt.ItemFlag.ItemIsDragEnabled)
            top.setExpanded(True)
            self._sections[kind] = top
        roots = [("", graphs_dir())] + [(p.name, p) for p in self.user_folders()]
        found = [(origin, root, sorted(root.rglob("*.json"))) for origin, root in roots
                 if root.is_dir()]
        self._files = [path for _, _, paths in found for path in paths]
        return [(origin, path) for origin, root, paths in found for path in paths
                if origin or path.relative_to(root).parts[0] not in INTERNAL]

    def _add(self, origin: str, path: Path) -> None:
        info = classify(path)
        if info is None:
            return
        kind, title, desc = info
        it = QTreeWidgetItem(self._sections[kind], [title + (f"  ({origin})" if origin else "")])
        it.setIcon(0, icon(kind))
        it.setData(0, PATH_ROLE, str(path.resolve()))
        it.setData(0, KIND_ROLE, kind)
        tip = f"{desc}\n{path}" if desc else str(path)
        if kind == "layer":
            tip += "\nDrag onto the Layers panel, or double-click, to add it"
        it.setToolTip(0, tip)

    def _end(self) -> None:
        self.listed = True
        self.files = self._files  # every .json file of the folders, the internal ones too
        self.refreshed.emit(self.files)
        for top in self._sections.values():
            top.setExpanded(True)
        self.filter(self.search.text())

    def filter(self, text: str) -> None:
        words = text.lower().split()
        for i in range(self.tree.topLevelItemCount()):
            top = self.tree.topLevelItem(i)
            shown = 0
            for j in range(top.childCount()):
                it = top.child(j)
                hay = (it.text(0) + " " + it.toolTip(0)).lower()
                ok = all(w in hay for w in words)
                it.setHidden(not ok)
                shown += ok
            top.setHidden(bool(words) and shown == 0)

    def items(self, kind: str | None = None) -> list[QTreeWidgetItem]:
        self.ensure_listed()
        out = []
        for i in range(self.tree.topLevelItemCount()):
            top = self.tree.topLevelItem(i)
            for j in range(top.childCount()):
                it = top.child(j)
                if kind is None or it.data(0, KIND_ROLE) == kind:
                    out.append(it)
        return out

    def _activated(self, item: QTreeWidgetItem, _col: int = 0) -> None:
        path = item.data(0, PATH_ROLE)
        kind = item.data(0, KIND_ROLE)
        if not path:
            return
        if kind == "material":
            self.materialOpenRequested.emit(path)
        elif kind == "function":
            self.functionOpenRequested.emit(path)
        elif kind == "layer":
            self.layerAddRequested.emit(path)
        elif kind == "instance":
            self.instanceOpenRequested.emit(path)

    def _context_menu(self, pos) -> None:
        item = self.tree.itemAt(pos)
        if item is not None and item.data(0, KIND_ROLE) in ("material", "instance"):
            from PySide6.QtWidgets import QMenu

            menu = QMenu(self)
            act = menu.addAction("Create Instance…")
            if menu.exec(self.tree.viewport().mapToGlobal(pos)) is act:
                self.instanceCreateRequested.emit(item.data(0, PATH_ROLE))
