"""The main window's menus and toolbar. The canvas's commands (Edit, View, the toolbar's Add
node and Frame all, Help › Node Reference) are the action table's QActions
(`matedit.app.canvas.actions`); the window's own actions are made here.

`install_menus(window)` sets the window's actions on it as ``act_*`` attributes and its
recent-files menu as ``recent_menu``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMenu

from matedit.app.canvas.actions import EDIT_MENU, VIEW_MENU
from matedit.app.docks import panel_docks
from matedit.app.theme import icon

K = QKeySequence.StandardKey


def make_action(parent, text: str, slot, shortcut=None, icon_name: str = "",
                tip: str = "") -> QAction:
    a = QAction(icon(icon_name or "none"), text, parent)
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


def install_menus(w) -> None:
    """File, Edit, View and Help menus and the toolbar of the main window `w`."""
    canvas = w.tabs.canvas_actions
    w.act_new = make_action(w, "&New", w.actions.new, K.New, "new", "New material")
    w.act_open = make_action(w, "&Open…", w.actions.open_dialog, K.Open, "open",
                             "Open a material or a material function")
    w.act_save = make_action(w, "&Save", w.save_active, K.Save, "save",
                             "Save the document in the active tab")
    w.act_save_as = make_action(w, "Save &As…", w.save_active_as, K.SaveAs, "save-as")
    w.act_export = make_action(w, "&Export Shaders…", w.export_shaders, "Ctrl+E", "export",
                               "Write GLSL for chosen targets to a folder")
    w.act_save_image = make_action(w, "Save &Viewport Image…",
                                   lambda: w.viewport.save_image_dialog(), None, "save",
                                   "The viewport's frame as PNG or linear EXR")
    w.act_quit = make_action(w, "&Quit", w.close, K.Quit)
    w.act_undo = w.undo_group.createUndoAction(w, "&Undo")
    w.act_undo.setShortcut(K.Undo)
    w.act_undo.setIcon(icon("undo"))
    w.act_redo = w.undo_group.createRedoAction(w, "&Redo")
    w.act_redo.setShortcut(K.Redo)
    w.act_redo.setIcon(icon("redo"))
    w.act_reset_layout = make_action(w, "Reset &Layout", w.reset_layout)
    w.act_snap = make_action(w, "&Snap to Grid", w.tabs.set_snap_to_grid, None,
                             tip="Moved nodes land on the canvas grid")
    w.act_snap.setCheckable(True)
    w.act_shortcuts = make_action(w, "&Keyboard Reference…", w.show_shortcuts, "Ctrl+/",
                                  tip="Every shortcut, searchable")
    w.act_about = make_action(w, "&About matedit", w.show_about)

    mb = w.menuBar()
    f = mb.addMenu("&File")
    _add(f, (w.act_new, w.act_open))
    w.recent_menu = RecentMenu(w.actions, w.open_material, w)
    f.addMenu(w.recent_menu)
    _add(f, (None, w.act_save, w.act_save_as, None, w.act_export, w.act_save_image))
    from matedit.app.interop_actions import install as install_interop
    w.interop = install_interop(w, f, w.act_export)
    _add(f, (None, w.act_quit))

    e = mb.addMenu("&Edit")
    _add(e, (w.act_undo, w.act_redo, None))
    canvas.fill(e, EDIT_MENU)

    v = mb.addMenu("&View")
    canvas.fill(v, VIEW_MENU)
    v.addSeparator()
    _add(v, [d.toggleViewAction() for d in panel_docks(w)])
    _add(v, (w.act_snap, None, w.act_reset_layout))

    h = mb.addMenu("&Help")
    h.addAction(w.act_shortcuts)
    canvas.fill(h, ("node_docs",))
    _add(h, (None, w.act_about))

    tb = w.addToolBar("Main")
    tb.setObjectName("mainToolBar")
    tb.setMovable(False)
    tb.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonIconOnly)
    _add(tb, (w.act_new, w.act_open, w.act_save, None, w.act_undo, w.act_redo, None,
              canvas["add_node"], canvas["frame_all"], None, w.act_export))
