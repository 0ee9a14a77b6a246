"""The centre of the window: the material's canvas and a tab per opened material function,
with breadcrumbs back along the path of functions the artist opened.

Each function tab has its own document, controller and undo stack (all in one
QUndoGroup, so Edit > Undo follows the active tab) and its own file actions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from PySide6.QtCore import QTimer, Signal
from PySide6.QtGui import QUndoGroup
from PySide6.QtWidgets import QHBoxLayout, QLabel, QPushButton, QTabWidget, QVBoxLayout, QWidget

from matedit.app.canvas import NodeCanvasView
from matedit.app.canvas.actions import CanvasActions
from matedit.app.controller import DocumentController
from matedit.app.document_actions import DocumentActions, display_name, no_mnemonic
from matedit.app.previews import NodePreviews
from matedit.app.theme import icon
from matedit.io.document import FormatError, load


@dataclass
class CanvasTab:
    controller: DocumentController
    canvas: QWidget
    actions: DocumentActions
    parent: CanvasTab | None = None
    children: list[CanvasTab] = field(default_factory=list)
    previews: NodePreviews | None = None  # node thumbnails (material tabs)

    @property
    def is_function(self) -> bool:
        return self.controller.document.is_function


class CanvasTabs(QWidget):
    """Tabs of canvases; tab 0 is the material and cannot be closed."""

    activeChanged = Signal(object)  # CanvasTab
    selectionChanged = Signal(list)
    message = Signal(str)
    functionSaved = Signal(object)  # Path
    previewRequested = Signal(str, str)  # a node's output to show in the viewport
    materialOpenRequested = Signal(str)  # a material file dropped on a canvas
    docsRequested = Signal(str)  # a node kind's documentation (F1)

    def __init__(self, material: DocumentController, material_actions: DocumentActions,
                 undo_group: QUndoGroup, parent=None) -> None:
        super().__init__(parent)
        self.undo_group = undo_group
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        self.crumbs = QWidget()
        self.crumbs.setObjectName("breadcrumbs")
        self.crumb_layout = QHBoxLayout(self.crumbs)
        self.crumb_layout.setContentsMargins(6, 2, 6, 2)
        self.crumb_layout.setSpacing(0)
        lay.addWidget(self.crumbs)
        self.tabs = QTabWidget()
        self.tabs.setDocumentMode(True)
        self.tabs.setTabsClosable(True)
        self.tabs.setMovable(False)
        # the material's own tab is named by its document tab: this row shows with functions
        self.tabs.setTabBarAutoHide(True)
        self.tabs.tabCloseRequested.connect(self.close_tab)
        self.tabs.currentChanged.connect(self._current_changed)
        lay.addWidget(self.tabs, 1)
        self._tabs: list[CanvasTab] = []
        self.snap_to_grid = False
        # One action table for every tab: its commands apply to the active tab's canvas.
        self.canvas_actions = CanvasActions(self, lambda: self.active.canvas)
        self.tabs.currentChanged.connect(lambda _i: self.canvas_actions.refresh())
        self.material = self._add(material, material_actions, None)
        bar = self.tabs.tabBar()
        bar.setTabButton(0, bar.ButtonPosition.RightSide, None)
        bar.setTabButton(0, bar.ButtonPosition.LeftSide, None)
        material.documentReplaced.connect(self._material_replaced)
        material.undoStackReplaced.connect(self._material_stack_replaced)
        self._refresh_crumbs()

    # --- tabs ------------------------------------------------------------------------------
    def _add(self, controller: DocumentController, actions: DocumentActions,
             parent: CanvasTab | None) -> CanvasTab:
        canvas = NodeCanvasView(controller, self, self.canvas_actions)
        canvas.scene().snap_to_grid = self.snap_to_grid
        tab = CanvasTab(controller, canvas, actions, parent)
        if not controller.document.is_function:
            tab.previews = NodePreviews(controller, canvas, self)
            canvas.previewRequested.connect(self.previewRequested)
        if parent is not None:
            parent.children.append(tab)
        self._tabs.append(tab)
        self.undo_group.addStack(controller.undo_stack)
        canvas.selectionChangedIds.connect(self._selection)
        canvas.functionOpenRequested.connect(lambda p, t=tab: self.open_function(p, t))
        canvas.message.connect(self.message)
        canvas.materialOpenRequested.connect(self.materialOpenRequested)
        canvas.docsRequested.connect(self.docsRequested)
        controller.undo_stack.cleanChanged.connect(self._clean_changed)
        actions.saved.connect(lambda p, t=tab: self._saved(t, p))
        self.tabs.addTab(canvas, icon("function" if controller.document.is_function
                                      else "material"), "")
        self._retitle(tab)
        QTimer.singleShot(0, canvas, canvas.frame_all)
        return tab

    def set_snap_to_grid(self, on: bool) -> None:
        self.snap_to_grid = bool(on)
        for tab in self._tabs:
            tab.canvas.scene().snap_to_grid = self.snap_to_grid

    def all_tabs(self) -> list[CanvasTab]:
        return list(self._tabs)

    @property
    def active(self) -> CanvasTab:
        i = self.tabs.currentIndex()
        return self._tabs[i] if 0 <= i < len(self._tabs) else self.material

    def activate(self, tab: CanvasTab) -> None:
        self.tabs.setCurrentIndex(self._tabs.index(tab))

    def open_function(self, path: str | Path, parent: CanvasTab | None = None,
                      recovered=None) -> CanvasTab | None:
        """Opens a material function in a tab (or shows the tab that has it); `recovered`:
        its autosaved content, already chosen by the artist, opened as unsaved work."""
        path = Path(path).resolve()
        for tab in self._tabs:
            if tab.controller.document.path and Path(tab.controller.document.path).resolve() \
                    == path:
                self.activate(tab)
                return tab
        try:
            doc = load(path)
        except FormatError as exc:
            self.message.emit(str(exc))
            self.material.actions.show_error("Cannot open function",
                                             f"{path.name} cannot be opened.\n\n{exc}")
            return None
        if not doc.is_function:
            self.material.actions.open(path)
            return self.material
        controller = DocumentController(doc, self)
        actions = DocumentActions(self.window(), controller)
        main = self.material.actions
        actions.show_error = lambda title, text: main.show_error(title, text)
        actions.ask_save_changes = lambda name: main.ask_save_changes(name)
        actions.ask_recover = lambda p, rec: main.ask_recover(p, rec)
        if recovered is None:  # a function edited when the editor crashed
            recovered = actions._offer_recovery(path)
        if recovered is not None:
            controller.replace(recovered)
            controller.undo_stack.resetClean()
        tab = self._add(controller, actions, parent or self.active)
        self.activate(tab)
        return tab

    def close_tab(self, index: int) -> bool:
        if index <= 0 or index >= len(self._tabs):
            return False
        tab = self._tabs[index]
        for child in list(tab.children):
            if child in self._tabs and not self.close_tab(self._tabs.index(child)):
                return False
        index = self._tabs.index(tab)
        if not tab.actions.close():
            return False
        if tab.parent is not None and tab in tab.parent.children:
            tab.parent.children.remove(tab)
        self._tabs.pop(index)
        self.undo_group.removeStack(tab.controller.undo_stack)
        self.tabs.removeTab(index)
        tab.canvas.deleteLater()
        self._refresh_crumbs()
        return True

    def close_functions(self) -> bool:
        for tab in reversed(self._tabs[1:]):
            if tab in self._tabs and not self.close_tab(self._tabs.index(tab)):
                return False
        return True

    def _material_stack_replaced(self, old) -> None:
        """Another document tab: the material's undo stack is its own."""
        stack = self.material.controller.undo_stack
        self.undo_group.removeStack(old)
        old.cleanChanged.disconnect(self._clean_changed)
        self.undo_group.addStack(stack)
        stack.cleanChanged.connect(self._clean_changed)
        if self.active is self.material:
            self.undo_group.setActiveStack(stack)

    def defer_builds(self, on: bool) -> None:
        """While a file opens, the material canvas builds its items in a turn of their own
        (NodeScene.defer_rebuilds)."""
        self.material.canvas.scene().defer_rebuilds = on

    def _material_replaced(self) -> None:
        self._retitle(self.material)
        QTimer.singleShot(0, self.material.canvas, self.material.canvas.frame_all)

    def _saved(self, tab: CanvasTab, _path) -> None:
        self._retitle(tab)
        if tab.is_function:  # materials that call it must see the new file
            self.functionSaved.emit(tab.controller.document.path)

    def _clean_changed(self, _clean: bool) -> None:
        stack = self.sender()
        for tab in self._tabs:
            if tab.controller.undo_stack is stack:
                self._retitle(tab)

    def _retitle(self, tab: CanvasTab) -> None:
        if tab not in self._tabs:
            return
        i = self._tabs.index(tab)
        name = display_name(tab.controller.document)
        self.tabs.setTabText(i, no_mnemonic(name) + ("*" if tab.controller.dirty else ""))
        doc = tab.controller.document
        self.tabs.setTabToolTip(i, str(doc.path) if doc.path else "not saved yet")
        self._refresh_crumbs()

    def _current_changed(self, _index: int) -> None:
        self._refresh_crumbs()
        tab = self.active
        self.undo_group.setActiveStack(tab.controller.undo_stack)
        self.activeChanged.emit(tab)
        self.selectionChanged.emit(tab.canvas.selected_ids())

    def _selection(self, ids: list) -> None:
        if self.sender() is self.active.canvas:
            self.selectionChanged.emit(list(ids))

    # --- breadcrumbs -----------------------------------------------------------------------
    def breadcrumb_path(self) -> list[CanvasTab]:
        chain = []
        tab: CanvasTab | None = self.active
        while tab is not None:
            chain.append(tab)
            tab = tab.parent
        return list(reversed(chain))

    def _refresh_crumbs(self) -> None:
        while self.crumb_layout.count():
            item = self.crumb_layout.takeAt(0)
            if item.widget() is not None:
                item.widget().deleteLater()
        chain = self.breadcrumb_path() if self._tabs else []
        for i, tab in enumerate(chain):
            if i:
                sep = QLabel("›")
                sep.setObjectName("fieldLabel")
                self.crumb_layout.addWidget(sep)
            name = display_name(tab.controller.document)
            b = QPushButton(no_mnemonic(name))
            b.setObjectName("crumb")
            b.setIcon(icon("function" if tab.is_function else "material"))
            b.setEnabled(i < len(chain) - 1)
            b.setToolTip("Back to " + name)
            b.clicked.connect(lambda _=False, t=tab: t in self._tabs and self.activate(t))
            self.crumb_layout.addWidget(b)
        self.crumb_layout.addStretch(1)
        self.crumbs.setVisible(len(chain) > 1)  # one level: the tab says it all
