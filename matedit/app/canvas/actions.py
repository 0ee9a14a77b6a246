"""The canvas's commands, declared once: the Edit and View menus, the toolbar, the canvas's
context menu and its keys all use the QActions built here from `TABLE`.

A `CanvasActions` is built once per window (or once per stand-alone canvas) over a
function that returns the canvas its actions apply to (the active tab's). Keys: the canvas
looks a key press up in its table (`action_for_key`) and runs that entry on itself, so the
shortcuts work wherever the canvas has focus and never while another widget has it: the
QActions' own shortcut context is the canvas alone (`WidgetShortcut`), not its children,
so F1, Tab or Ctrl+D typed in the palette's search or a node's rename field stay theirs.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from PySide6.QtCore import QEvent, QKeyCombination, QObject, Qt
from PySide6.QtGui import QAction, QCursor, QKeyEvent, QKeySequence
from PySide6.QtWidgets import QMenu, QToolBar, QWidget

from matedit.app.theme import icon

if TYPE_CHECKING:
    from matedit.app.canvas.view import NodeCanvasView

K = QKeySequence.StandardKey


def _has_selection(v: NodeCanvasView) -> bool:
    return bool(v.scene().selectedItems() or v.scene().selected_wires)


def _has_nodes_selected(v: NodeCanvasView) -> bool:
    return bool(v.selected_ids())


def _one_node_selected(v: NodeCanvasView) -> bool:
    return len(v.selected_ids()) == 1


def _always(_v: NodeCanvasView) -> bool:
    return True


@dataclass(frozen=True)
class CanvasCommand:
    """One entry of the table: what the menus show and what runs on the canvas."""

    id: str
    text: str  # with its '&' mnemonic
    run: Callable[[NodeCanvasView], object]
    keys: tuple[str | QKeySequence.StandardKey, ...] = ()
    icon: str = ""
    tip: str = ""
    enabled: Callable[[NodeCanvasView], bool] = _always
    # a toggle's state on the canvas (its menu entry shows a check mark); None: not a toggle
    checked: Callable[[NodeCanvasView], bool] | None = None


TABLE: tuple[CanvasCommand, ...] = (
    CanvasCommand("add_node", "Add &Node…", lambda v: v.open_palette(), ("Tab",), "add",
                  "Add a node (the palette) at the pointer"),
    CanvasCommand("copy", "&Copy", lambda v: v.copy_selection(), (K.Copy,),
                  tip="Copy the selected nodes", enabled=_has_selection),
    CanvasCommand("cut", "Cu&t", lambda v: v.cut_selection(), (K.Cut,),
                  tip="Cut the selected nodes", enabled=_has_selection),
    CanvasCommand("paste", "&Paste", lambda v: v.paste(), (K.Paste,),
                  tip="Paste nodes at the pointer"),
    CanvasCommand("duplicate", "D&uplicate", lambda v: v.duplicate_selection(), ("Ctrl+D",),
                  tip="Duplicate the selected nodes", enabled=_has_nodes_selected),
    CanvasCommand("delete", "&Delete", lambda v: v.delete_selection(),
                  ("Del", "Backspace"), tip="Delete the selection", enabled=_has_selection),
    CanvasCommand("comment", "Co&mment Selection", lambda v: v.comment_selection(), ("C",),
                  tip="Frame the selected nodes in a comment", enabled=_has_nodes_selected),
    CanvasCommand("rename", "&Rename Node", lambda v: v.rename_selected(), ("F2",),
                  tip="Rename the selected node", enabled=_one_node_selected),
    CanvasCommand("collapse", "Collapse to &Function…", lambda v: v.collapse_selection(),
                  ("Ctrl+G",), tip="Move the selected nodes into a new material function "
                  "file; the cut wires become its inputs and outputs, and a call takes their "
                  "place", enabled=_has_nodes_selected),
    CanvasCommand("expand", "E&xpand Function", lambda v: v.expand_selected_call(),
                  ("Ctrl+Shift+G",), tip="Put the selected function call's nodes in its place",
                  enabled=_one_node_selected),
    CanvasCommand("bypass", "&Bypass", lambda v: v.toggle_bypass(), ("B",),
                  tip="Bypass the selected nodes (their first input of each output's type "
                      "passes through), or make them work again", enabled=_has_nodes_selected),
    CanvasCommand("arrange", "Arran&ge", lambda v: v.arrange_selection(), ("L",),
                  tip="Lay out the selected nodes (everything when fewer than two are "
                      "selected) in columns, outputs on the right"),
    CanvasCommand("frame_all", "Frame &All", lambda v: v.frame_all(), ("Home", "A"), "frame",
                  "Frame the whole graph"),
    CanvasCommand("frame_selection", "Frame &Selection", lambda v: v.frame_selection(),
                  ("F",), tip="Frame the selection (everything when nothing is selected)"),
    CanvasCommand("minimap", "&Minimap", lambda v: v.toggle_minimap(), ("M",),
                  tip="Show or hide the canvas minimap",
                  checked=lambda v: not v.minimap.isHidden()),
    CanvasCommand("cost_overlay", "&Cost Overlay", lambda v: v.toggle_cost_overlay(),
                  tip="Tint each node by its share of the material's instructions (glsl450, "
                  "after spirv-opt -O); the figures are in its tooltip",
                  checked=lambda v: v.cost_overlay.active),
    CanvasCommand("node_docs", "&Node Reference", lambda v: v.request_docs(), ("F1",),
                  tip="Browse and search every node kind: ports, defaults, ranges and a "
                      "thumbnail (the selected node's kind first)"),
)

EDIT_MENU = ("delete", "cut", "copy", "paste", "duplicate", "comment", "rename", "bypass",
             None, "collapse", "expand", None, "arrange", "add_node")
VIEW_MENU = ("frame_all", "frame_selection", "minimap", "cost_overlay")
CONTEXT_MENU = ("copy", "cut", "paste", "duplicate", "delete", "comment", "rename", "bypass",
                "collapse", "expand", "arrange", "frame_all")


def key_text(command: CanvasCommand) -> str:
    """'Del / Backspace': the keys as the menus write them."""
    return " / ".join(QKeySequence(k).toString(QKeySequence.SequenceFormat.NativeText)
                      for k in command.keys)


class CanvasActions(QObject):
    """The table's QActions, over the canvas `target()` returns."""

    def __init__(self, parent: QObject, target: Callable[[], NodeCanvasView]) -> None:
        super().__init__(parent)
        self._target = target
        self._commands = {c.id: c for c in TABLE}
        self._actions: dict[str, QAction] = {}
        for c in TABLE:
            a = QAction(icon(c.icon or "none"), c.text, self)
            a.setObjectName(f"canvas_{c.id}")
            a.setShortcuts([QKeySequence(k) for k in c.keys])
            a.setShortcutContext(Qt.ShortcutContext.WidgetShortcut)
            a.setCheckable(c.checked is not None)
            if c.tip:
                a.setToolTip(c.tip)
                a.setStatusTip(c.tip)
            a.triggered.connect(lambda _=False, cmd=c: self.run(cmd.id, self._target()))
            self._actions[c.id] = a

    def __getitem__(self, command_id: str) -> QAction:
        return self._actions[command_id]

    def all(self) -> list[QAction]:
        return list(self._actions.values())

    def attach(self, canvas: NodeCanvasView) -> None:
        """The canvas is where the actions' shortcuts apply; its selection changes what is
        enabled (menus refresh again as they open: a wire's selection has no signal)."""
        canvas.addActions(self.all())
        canvas.selectionChangedIds.connect(lambda _ids: self.refresh())

    def run(self, command_id: str, canvas: NodeCanvasView) -> bool:
        """Runs the command on `canvas` if it applies there now; whether it ran."""
        c = self._commands[command_id]
        if not c.enabled(canvas):
            return False
        c.run(canvas)
        if c.checked is not None:
            self._actions[command_id].setChecked(c.checked(canvas))
        return True

    def refresh(self, canvas: NodeCanvasView | None = None) -> None:
        """Enabled states for `canvas` (default: the target), before a menu shows."""
        canvas = canvas if canvas is not None else self._target()
        for cid, a in self._actions.items():
            c = self._commands[cid]
            a.setEnabled(c.enabled(canvas))
            if c.checked is not None:
                a.setChecked(c.checked(canvas))

    def action_for_key(self, event) -> str:
        """The id of the command a key press stands for ('' if none)."""
        mods = event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        try:
            seq = QKeySequence(QKeyCombination(mods, Qt.Key(event.key())))
        except ValueError:  # a key code Qt has no name for
            return ""
        for cid, a in self._actions.items():
            if any(s.matches(seq) == QKeySequence.SequenceMatch.ExactMatch
                   for s in a.shortcuts()):
                return cid
        return ""

    def fill(self, menu: QMenu | QToolBar, ids: Iterable[str | None]) -> None:
        """Adds the named actions to a menu or toolbar (None: a separator)."""
        for cid in ids:
            if cid is None:
                menu.addSeparator()
            else:
                menu.addAction(self._actions[cid])
        if isinstance(menu, QMenu):
            menu.aboutToShow.connect(self.refresh)


class PaletteOnTab(QObject):
    """Tab opens the palette whenever the pointer is over the active canvas, wherever the
    keyboard focus is in `window`. A QAction shortcut follows the focus, not the pointer,
    so this part of the Tab key is an application event filter."""

    def __init__(self, window: QWidget, canvas: Callable[[], NodeCanvasView]) -> None:
        super().__init__(window)
        self._window = window
        self._canvas = canvas

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        # Every event of the application comes here (thousands when a document opens): the
        # wrapper's class says whether it is a key event without reading its type (a
        # Python enum made for each event); the others go on as they came.
        if not isinstance(event, QKeyEvent):
            return False
        if event.type() == QEvent.Type.KeyPress and event.key() == Qt.Key.Key_Tab and \
                event.modifiers() == Qt.KeyboardModifier.NoModifier and \
                isinstance(obj, QWidget) and obj.window() is self._window:
            canvas = self._canvas()
            vp = canvas.viewport()
            inside = vp.rect().contains(vp.mapFromGlobal(QCursor.pos()))
            palette = canvas.node_palette
            if inside and canvas.isVisible() and obj is not palette and \
                    not palette.isAncestorOf(obj):
                canvas.open_palette()
                return True
        return False
