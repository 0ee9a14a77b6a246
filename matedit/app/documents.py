"""Several materials in one window: a tab per open material document, over the canvas.

The window has one material controller, canvas and set of panels; a document tab holds what
is its own (the document, its undo stack, its untitled autosave key) and the controller
shows the active one (`DocumentController.swap`). Switching tabs autosaves the tab left
behind if it has unsaved work, so that a crash loses no tab's edits. File › New and Open
make a tab (an untouched Untitled tab is reused); Close, Close All and Save All act on the
tabs; closing the window asks about each tab with unsaved work.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import shiboken6
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QTabBar, QVBoxLayout, QWidget

from matedit.app.controller import DocumentController
from matedit.app.document_actions import (
    DocumentActions,
    display_name,
    new_material,
    new_untitled_key,
    no_mnemonic,
)
from matedit.app.recovery import recovery_path
from matedit.app.theme import icon
from matedit.graph.model import MaterialDocument


@dataclass
class DocumentSession:
    """A material document tab's own state, kept while another tab is active."""

    document: MaterialDocument
    undo_stack: QUndoStack
    untitled_key: str
    autosaved_index: int | None = None

    @property
    def dirty(self) -> bool:
        return not self.undo_stack.isClean()

    @property
    def untouched(self) -> bool:
        """A new Untitled document nobody has edited: File › Open may reuse its tab."""
        return self.document.path is None and self.undo_stack.count() == 0


class DocumentTabs(QObject):
    """The document tab bar and the sessions behind it (see the module docstring)."""

    switched = Signal()  # another document is active
    message = Signal(str)

    def __init__(self, controller: DocumentController, actions: DocumentActions,
                 parent=None) -> None:
        super().__init__(parent)
        self.controller, self.actions = controller, actions
        self.bar = QTabBar()
        self.bar.setObjectName("documentTabs")
        self.bar.setDocumentMode(True)
        self.bar.setTabsClosable(True)
        self.bar.setAutoHide(False)
        self.bar.setMovable(True)
        self.bar.setExpanding(False)
        self.bar.setUsesScrollButtons(True)
        self.bar.setElideMode(self.bar.elideMode().ElideRight)
        self.sessions: list[DocumentSession] = [self._session_of_controller()]
        self.bar.addTab(icon("material"), "")
        self._watch(controller.undo_stack)
        self._switching = False
        self._shown = 0  # the tab the controller shows
        self.bar.currentChanged.connect(self._current_changed)
        self.bar.tabCloseRequested.connect(self.close)
        self.bar.tabMoved.connect(self._moved)
        actions.opened.connect(lambda _p: self.retitle())
        actions.saved.connect(lambda _p: self.retitle())
        self.retitle()

    def over(self, widget: QWidget) -> QWidget:
        """The window's centre: the document tabs over `widget` (the canvas tabs)."""
        centre = QWidget()
        lay = QVBoxLayout(centre)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        lay.addWidget(self.bar)
        lay.addWidget(widget, 1)
        return centre

    # --- state -----------------------------------------------------------------------------
    @property
    def index(self) -> int:
        return self.bar.currentIndex()

    @property
    def current(self) -> DocumentSession:
        return self.sessions[self.index]

    def count(self) -> int:
        return len(self.sessions)

    def _session_of_controller(self) -> DocumentSession:
        return DocumentSession(self.controller.document, self.controller.undo_stack,
                               self.actions.untitled_key, self.actions._autosaved_index)

    def _watch(self, stack: QUndoStack) -> None:
        stack.cleanChanged.connect(lambda _c, s=stack: self._retitle_stack(s))

    def _park(self, index: int) -> None:
        """The state of tab `index`, shown until now, back into its session; unsaved work
        autosaved now (no tab's edits wait for the timer of a tab not shown)."""
        if 0 <= index < self.count():  # the controller shows tab `index` (replace too)
            if self.controller.dirty:
                self.actions.autosave()
            self.sessions[index] = self._session_of_controller()

    def _show(self, session: DocumentSession) -> None:
        self.actions.untitled_key = session.untitled_key
        self.actions._autosaved_index = session.autosaved_index
        self.controller.swap(session.document, session.undo_stack)
        self.switched.emit()

    # --- switching -------------------------------------------------------------------------
    def activate(self, index: int) -> None:
        if 0 <= index < self.count() and index != self.index:
            self.bar.setCurrentIndex(index)

    def _current_changed(self, index: int) -> None:
        if self._switching or not 0 <= index < self.count():
            return
        self._park(self._shown)
        self._shown = index
        if self.sessions[index].document is not self.controller.document:
            self._show(self.sessions[index])

    def _moved(self, src: int, dst: int) -> None:
        self.sessions.insert(dst, self.sessions.pop(src))
        self._shown = self.index

    # --- new, open -------------------------------------------------------------------------
    def new_tab(self, document: MaterialDocument | None = None) -> DocumentSession:
        """A new tab after the active one, showing `document` (a new material if None)."""
        self._park(self._shown)
        session = DocumentSession(document or new_material(), QUndoStack(self.controller),
                                  new_untitled_key())
        self._watch(session.undo_stack)
        at = self.index + 1
        self._switching = True
        try:
            self.sessions.insert(at, session)
            self.bar.insertTab(at, icon("material"), "")
            self.bar.setCurrentIndex(at)
        finally:
            self._switching = False
        self._shown = at
        self._show(session)
        self.retitle()
        return session

    def new(self) -> bool:
        """File › New: an Untitled material in a tab of its own."""
        self.new_tab()
        return True

    def find(self, path: str | Path) -> int:
        """The tab of the document saved at `path`, -1 if none."""
        try:
            want = Path(path).resolve()
        except OSError:
            return -1
        for i, s in enumerate(self.sessions):
            doc = s.document if i != self.index else self.controller.document
            if doc.path is not None and Path(doc.path).resolve() == want:
                return i
        return -1

    def open(self, path: str | Path) -> bool:
        """File › Open, Recent and a material dropped on the window: the tab that has it, or
        a new tab (the active one if it is an untouched Untitled). Functions and instances
        open where they always do (a canvas tab, the instance editor)."""
        from matedit.io.instance import is_instance_file

        path = Path(path)
        at = self.find(path)
        if at >= 0:
            self.activate(at)
            return True
        if is_instance_file(path) or self._is_function(path) or \
                self._session_of_controller().untouched:
            return self.actions.open(path)
        previous = self._shown
        self.new_tab()
        if self.actions.open(path, ask=False):
            return True
        self._drop(self.index, previous)  # a bad file: the new tab goes again
        return False

    @staticmethod
    def _is_function(path: Path) -> bool:
        from matedit.io.document import FormatError, load

        try:
            return load(path).is_function
        except (FormatError, OSError, ValueError):
            return False

    def open_recovered(self, entry, doc: MaterialDocument) -> None:
        """A recovered material beyond the first opens in a tab of its own, unsaved, still
        autosaving to its recovery file (deleted once it is saved or knowingly dropped);
        the tab in front stays in front."""
        shown = self.index
        self.new_tab(doc)
        self.actions.untitled_key = entry.untitled_key or self.actions.untitled_key
        self.controller.undo_stack.resetClean()
        self.activate(shown)
        self.retitle()

    def open_dialog(self) -> bool:
        path = self.actions.ask_open_path()
        return bool(path) and self.open(path)

    # --- save, close -----------------------------------------------------------------------
    def save_all(self) -> bool:
        """File › Save All: every tab with unsaved work, each through its own Save (a new
        document asks where); stops at the first that is not saved."""
        start = self.index
        for i in range(self.count()):
            if not self._dirty(i):
                continue
            self.activate(i)
            if not self.actions.save():
                return False
        self.activate(start)
        return True

    def _dirty(self, i: int) -> bool:
        return self.controller.dirty if i == self.index else self.sessions[i].dirty

    def close(self, index: int | None = None) -> bool:
        """File › Close (or a tab's ×): asks about unsaved work; the last tab closed leaves
        an Untitled one. False if the artist cancelled."""
        index = self.index if index is None else index
        if not 0 <= index < self.count():
            return False
        self.activate(index)
        if not self.actions.maybe_save():
            return False
        self.actions.discard_recovery()
        if self.count() == 1:
            self.actions.untitled_key = new_untitled_key()
            self.controller.replace(new_material())
            self.actions.opened.emit(None)
            self.sessions[0] = self._session_of_controller()
            self.retitle()
            return True
        self._drop(index, index - 1 if index > 0 else 1)
        return True

    def _drop(self, index: int, show: int) -> None:
        """Removes tab `index` (its work already saved or dropped) and shows tab `show`."""
        self._switching = True
        try:
            gone = self.sessions.pop(index)
            self.bar.removeTab(index)
            show = show - 1 if show > index else show
            self.bar.setCurrentIndex(show)
        finally:
            self._switching = False
        self._shown = show
        self._show(self.sessions[show])
        gone.undo_stack.deleteLater()
        self.retitle()

    def close_all(self) -> bool:
        """File › Close All: every tab, asking about each with unsaved work; one Untitled
        tab is left. Stops (keeping the rest) when the artist cancels."""
        while self.count() > 1:
            if not self.close(self.count() - 1):
                return False
        return self.close(0)

    def may_quit(self) -> bool:
        """Closing the window: asks about every tab with unsaved work (its answer acts, as
        Save or Discard), then forgets their autosaves. False if the artist cancelled."""
        for i in range(self.count()):
            if self._dirty(i):
                self.activate(i)
                if not self.actions.maybe_save():
                    return False
        for i in range(self.count()):
            if i != self.index:
                s = self.sessions[i]
                self.actions._remove_recovery(recovery_path(s.document.path, s.untitled_key))
        self.actions.autosave_timer.stop()
        self.actions.discard_recovery()  # the active tab's
        return True

    # --- titles ----------------------------------------------------------------------------
    def _retitle_stack(self, stack: QUndoStack) -> None:
        self.retitle()

    def retitle(self) -> None:
        stacks = [self.bar, self.controller.undo_stack, *(s.undo_stack for s in self.sessions)]
        if not all(shiboken6.isValid(x) for x in stacks):
            return  # the window is going away
        for i, s in enumerate(self.sessions):
            doc = self.controller.document if i == self.index else s.document
            self.bar.setTabText(i, no_mnemonic(display_name(doc)) +
                                ("*" if self._dirty(i) else ""))
            self.bar.setTabToolTip(i, str(doc.path) if doc.path else "not saved yet")

    def names(self) -> list[str]:
        return [self.bar.tabText(i) for i in range(self.count())]
