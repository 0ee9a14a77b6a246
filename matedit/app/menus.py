"""The main window's menus and toolbar. The canvas's commands (Edit, View, the toolbar's Add
node and Frame all, Help › Node Reference) are the action table's QActions
(`matedit.app.canvas.actions`); the window's own actions are made here.

`install_menus(window, host, docks)` builds them on `window`, calling `host` (a `MenuHost`:
the slots the menus need), and returns a `Menus`: the menus by name and the actions. Every
action made here carries an id (its objectName: "file.new", "file.export", …), and features
add their entries relative to one (`insert_after`), never at a position.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence, QUndoGroup
from PySide6.QtWidgets import QDockWidget, QMainWindow, QMenu, QToolBar

from matedit.app.canvas.actions import EDIT_MENU, VIEW_MENU
from matedit.app.theme import icon

if TYPE_CHECKING:
    from matedit.app.canvas_tabs import CanvasTabs
    from matedit.app.controller import DocumentController
    from matedit.app.document_actions import DocumentActions
    from matedit.app.documents import DocumentTabs
    from matedit.app.interop_actions import InteropActions

K = QKeySequence.StandardKey


class MenuHost(Protocol):
    """What the menus need of the main window: the slots they call and where they go."""

    actions: DocumentActions
    controller: DocumentController
    tabs: CanvasTabs
    documents: DocumentTabs
    undo_group: QUndoGroup

    def save_active(self) -> bool: ...
    def save_active_as(self) -> bool: ...
    def export_shaders(self) -> None: ...
    def save_viewport_image(self) -> bool: ...
    def close(self) -> bool: ...
    def reset_layout(self) -> None: ...
    def show_shortcuts(self) -> object: ...
    def show_about(self) -> None: ...
    def open_material(self, path: str | Path) -> bool: ...
    def status(self, text: str) -> None: ...



def make_action(parent, text: str, slot, shortcut=None, icon_name: str = "",
                tip: str = "", action_id: str = "") -> QAction:
    a = QAction(icon(icon_name or "none"), text, parent)
    a.setObjectName(action_id)
    if shortcut is not None:
        a.setShortcut(shortcut)
    if tip:
        a.setStatusTip(tip)
        a.setToolTip(tip)
    a.triggered.connect(slot)
    return a


class RecentMenu(QMenu):
    """File › Open Recent, filled from the recent-files list each time it opens."""

    def __init__(self, document_actions, open_path: Callable[[str], object], parent) -> None:
        super().__init__("Open &Recent", parent)
        self._actions = document_actions
        self._open = open_path
        self.aboutToShow.connect(self.fill)

    def fill(self) -> None:
        self.clear()
        files = self._actions.recent_files()
        for f in files:
            a = self.addAction(Path(f).name)
            a.setToolTip(f)
            a.setStatusTip(f)
            a.triggered.connect(lambda _=False, p=f: self._open(p))
        if not files:
            self.addAction("(none)").setEnabled(False)
        else:
            self.addSeparator()
            self.addAction("Clear", self._actions.clear_recent)


def _add(menu, actions) -> None:
    for a in actions:
        if a is None:
            menu.addSeparator()
        else:
            menu.addAction(a)


def find_action(menu: QMenu, action_id: str) -> QAction:
    """The entry of `menu` whose id (objectName) is `action_id`; KeyError if none."""
    for a in menu.actions():
        if a.objectName() == action_id:
            return a
    raise KeyError(f"no action {action_id!r} in the {menu.title()} menu")


def insert_after(menu: QMenu, action_id: str, actions: Iterable[QAction | None]) -> None:
    """Adds `actions` (None: a separator) to `menu` right after the entry `action_id`."""
    entries = menu.actions()
    i = entries.index(find_action(menu, action_id)) + 1
    before = entries[i] if i < len(entries) else None
    for a in actions:
        if before is None:  # the last entry: append
            menu.addSeparator() if a is None else menu.addAction(a)
        elif a is None:
            menu.insertSeparator(before)
        else:
            menu.insertAction(before, a)


@dataclass(frozen=True)
class Menus:
    """The menus by name, the toolbar, and the window's own actions."""

    file: QMenu
    edit: QMenu
    view: QMenu
    help: QMenu
    toolbar: QToolBar
    recent: RecentMenu
    interop: InteropActions
    new: QAction
    open: QAction
    save: QAction
    save_as: QAction
    export: QAction
    save_image: QAction
    quit: QAction
    undo: QAction
    redo: QAction
    reset_layout: QAction
    snap: QAction
    shortcuts: QAction
    about: QAction


def install_menus(window: QMainWindow, w: MenuHost, docks: Iterable[QDockWidget]) -> Menus:
    """File, Edit, View and Help menus and the toolbar of `window`, calling `w`'s slots; the
    View menu lists `docks`."""
    from matedit.app.interop_actions import InteropActions

    canvas = w.tabs.canvas_actions
    new = make_action(window, "&New", w.documents.new, K.New, "new",
                      "New material, in a tab of its own", "file.new")
    open_ = make_action(window, "&Open…", w.documents.open_dialog, K.Open, "open",
                        "Open a material (in a tab of its own) or a material function",
                        "file.open")
    close = make_action(window, "&Close", lambda: w.documents.close(), "Ctrl+W",
                        tip="Close the material in the active document tab",
                        action_id="file.close")
    close_all = make_action(window, "Close A&ll", w.documents.close_all, "Ctrl+Shift+W",
                            tip="Close every document tab, asking about unsaved work",
                            action_id="file.close_all")
    save_all = make_action(window, "Save A&ll", w.documents.save_all, "Ctrl+Alt+S",
                           tip="Save every document tab with unsaved work",
                           action_id="file.save_all")
    save = make_action(window, "&Save", w.save_active, K.Save, "save",
                       "Save the document in the active tab", "file.save")
    save_as = make_action(window, "Save &As…", w.save_active_as, K.SaveAs, "save-as",
                          action_id="file.save_as")
    export = make_action(window, "&Export Shaders…", w.export_shaders, "Ctrl+E", "export",
                         "Write GLSL for chosen targets to a folder", "file.export")
    save_image = make_action(window, "Save &Viewport Image…", w.save_viewport_image, None, "save",
                             "The viewport's frame as PNG or linear EXR", "file.save_image")
    quit_ = make_action(window, "&Quit", w.close, K.Quit, action_id="file.quit")
    undo = w.undo_group.createUndoAction(window, "&Undo")
    undo.setObjectName("edit.undo")
    undo.setShortcut(K.Undo)
    undo.setIcon(icon("undo"))
    redo = w.undo_group.createRedoAction(window, "&Redo")
    redo.setObjectName("edit.redo")
    redo.setShortcut(K.Redo)
    redo.setIcon(icon("redo"))
    reset_layout = make_action(window, "Reset &Layout", w.reset_layout,
                               action_id="view.reset_layout")
    snap = make_action(window, "&Snap to Grid", w.tabs.set_snap_to_grid, None,
                       tip="Moved nodes land on the canvas grid", action_id="view.snap")
    snap.setCheckable(True)
    shortcuts = make_action(window, "&Keyboard Reference…", w.show_shortcuts, "Ctrl+/",
                            tip="Every shortcut, searchable", action_id="help.shortcuts")
    about = make_action(window, "&About matedit", w.show_about, action_id="help.about")

    mb = window.menuBar()
    f = mb.addMenu("&File")
    _add(f, (new, open_))
    recent = RecentMenu(w.actions, w.open_material, window)
    recent.menuAction().setObjectName("file.recent")
    f.addMenu(recent)
    _add(f, (None, save, save_as, save_all, None, close, close_all, None, export, save_image))
    interop = InteropActions(window, w)
    insert_after(f, "file.export", interop.entries())
    _add(f, (None, quit_))

    e = mb.addMenu("&Edit")
    _add(e, (undo, redo, None))
    canvas.fill(e, EDIT_MENU)

    v = mb.addMenu("&View")
    canvas.fill(v, VIEW_MENU)
    v.addSeparator()
    _add(v, [d.toggleViewAction() for d in docks])
    _add(v, (snap, None, reset_layout))

    h = mb.addMenu("&Help")
    h.addAction(shortcuts)
    canvas.fill(h, ("node_docs",))
    _add(h, (None, about))

    tb = window.addToolBar("Main")
    tb.setObjectName("mainToolBar")
    tb.setMovable(False)
    tb.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonIconOnly)
    _add(tb, (new, open_, save, None, undo, redo, None,
              canvas["add_node"], canvas["frame_all"], None, export))
    return Menus(f, e, v, h, tb, recent, interop, new, open_, save, save_as, export,
                 save_image, quit_, undo, redo, reset_layout, snap, shortcuts, about)
