"""Several documents in one window: a tab per open material and per open material instance,
over the canvas.

The window has one material controller, canvas and set of panels; a material tab holds what
is its own (the document, its undo stack, its untitled autosave key) and the controller
shows the active one (`DocumentController.swap`). Switching tabs autosaves the material tab
left behind if it has unsaved work, so that a crash loses no tab's edits. An instance tab
shows its instance editor in place of the canvas, with its own undo stack in the window's
Edit › Undo; the panels keep showing the last material. File › New and Open make a tab (an
untouched Untitled tab is reused); Close, Close All and Save All act on the tabs; closing
the window asks about each tab with unsaved work.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import shiboken6
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack
from PySide6.QtWidgets import QStackedWidget, QTabBar, QVBoxLayout, QWidget

from matedit.app.controller import DocumentController
from matedit.app.document_actions import (
    CANCEL,
    SAVE,
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
    """A document tab's own state: a material's, kept while another tab is active, or an
    instance's editor (`editor`, which keeps its own)."""

    document: MaterialDocument | None
    undo_stack: QUndoStack
    untitled_key: str = ""
    autosaved_index: int | None = None
    editor: Any = None  # matedit.app.instance_editor.InstanceEditor

    @property
    def dirty(self) -> bool:
        return bool(self.editor.dirty) if self.editor is not None else \
            not self.undo_stack.isClean()

    @property
    def untouched(self) -> bool:
        """A new Untitled document nobody has edited: File › Open may reuse its tab."""
        return self.editor is None and self.document is not None and \
            self.document.path is None and self.undo_stack.count() == 0


class DocumentTabs(QObject):
    """The document tab bar and the sessions behind it (see the module docstring)."""

    switched = Signal()  # another document is active
    opening = Signal(bool)  # True while `open` opens a file (the window defers what it can)
    undoStackChosen = Signal(object)  # the stack Edit › Undo should follow now
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
        self.pages = QStackedWidget()  # page 0: the canvas; then one per instance editor
        self.sessions: list[DocumentSession] = [self._session_of_controller()]
        self.bar.addTab(icon("material"), "")
        self._watch(controller.undo_stack)
        self._switching = False
        self._shown = 0  # the material tab the controller shows
        self.bar.currentChanged.connect(self._current_changed)
        self.bar.tabCloseRequested.connect(self.close)
        self.bar.tabMoved.connect(self._moved)
        actions.opened.connect(lambda _p: self.retitle())
        actions.saved.connect(lambda _p: self.retitle())
        self.retitle()

    def over(self, widget: QWidget) -> QWidget:
        """The window's centre: the document tabs over `widget` (the canvas tabs) or the
        active instance's editor."""
        self.pages.insertWidget(0, widget)
        self.pages.setCurrentIndex(0)
        centre = QWidget()
        lay = QVBoxLayout(centre)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        lay.addWidget(self.bar)
        lay.addWidget(self.pages, 1)
        return centre

    def follow_undo(self, group, canvas_controller) -> None:
        """Edit › Undo (`group`) follows the active tab: an instance's own stack, or the
        active canvas tab's (`canvas_controller()`) on a material tab."""
        def choose(stack) -> None:
            stack = stack or canvas_controller().undo_stack
            if stack not in group.stacks():
                group.addStack(stack)
            group.setActiveStack(stack)
        self.undoStackChosen.connect(choose)

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
        stack.cleanChanged.connect(self._clean_changed)  # a slot: Qt disconnects it with us

    def _clean_changed(self, _clean: bool) -> None:
        self.retitle()

    def _park(self, index: int) -> None:
        """The state of material tab `index`, shown until now, back into its session;
        unsaved work autosaved now (no tab's edits wait for a timer of a tab not shown)."""
        if 0 <= index < self.count() and self.sessions[index].editor is None:
            if self.controller.dirty:
                self.actions.autosave()
            self.sessions[index] = self._session_of_controller()

    def _show(self, index: int) -> None:
        """Tab `index` in front: an instance's editor, or a material in the controller."""
        session = self.sessions[index]
        if session.editor is not None:
            self.pages.setCurrentWidget(session.editor)
            self.undoStackChosen.emit(session.undo_stack)
            self.switched.emit()
            return
        self.pages.setCurrentIndex(0)
        if index != self._shown:  # the controller holds the shown one's live state
            self._park(self._shown)
            self._shown = index
            self.actions.untitled_key = session.untitled_key
            self.actions._autosaved_index = session.autosaved_index
            self.controller.swap(session.document, session.undo_stack)
        self.undoStackChosen.emit(None)  # the canvas tab's own
        self.switched.emit()

    # --- switching -------------------------------------------------------------------------
    def activate(self, index: int) -> None:
        if 0 <= index < self.count() and index != self.index:
            self.bar.setCurrentIndex(index)

    def _current_changed(self, index: int) -> None:
        if not self._switching and 0 <= index < self.count():
            self._show(index)

    def _moved(self, src: int, dst: int) -> None:
        shown = self.sessions[self._shown]
        self.sessions.insert(dst, self.sessions.pop(src))
        self._shown = self.sessions.index(shown)

    def _insert(self, session: DocumentSession) -> int:
        """A new tab after the active one, shown."""
        at = self.index + 1
        self._switching = True
        try:
            self.sessions.insert(at, session)
            if at <= self._shown:
                self._shown += 1
            self.bar.insertTab(at, icon("material" if session.editor is None else "layer"),
                               "")
            self.bar.setCurrentIndex(at)
        finally:
            self._switching = False
        self._show(at)
        self.retitle()
        return at

    # --- new, open -------------------------------------------------------------------------
    def new_tab(self, document: MaterialDocument | None = None) -> DocumentSession:
        """A new material tab after the active one, showing `document` (a new material)."""
        session = DocumentSession(document or new_material(), QUndoStack(self.controller),
                                  new_untitled_key())
        self._watch(session.undo_stack)
        self._insert(session)
        return session

    def add_instance(self, editor) -> DocumentSession:
        """An instance editor in a tab of its own (matedit.app.instance_editor)."""
        editor.embed()
        self.pages.addWidget(editor)
        if not self.pages.window().isVisible():  # its viewport starts once it is on screen
            self.pages.window().show()
        session = DocumentSession(None, editor.undo_stack, editor=editor)
        self._watch(editor.undo_stack)
        editor.dirtyChanged.connect(self._clean_changed)
        self._insert(session)
        return session

    def new(self) -> bool:
        """File › New: an Untitled material in a tab of its own."""
        self.new_tab()
        return True

    def _document(self, i: int) -> MaterialDocument | None:
        return self.controller.document if i == self._shown else self.sessions[i].document

    def find(self, path: str | Path) -> int:
        """The tab of the document or instance saved at `path`, -1 if none."""
        try:
            want = Path(path).resolve()
        except OSError:
            return -1
        for i, s in enumerate(self.sessions):
            p = s.editor.doc.path if s.editor is not None else self._document(i).path
            if p is not None and Path(p).resolve() == want:
                return i
        return -1

    def open(self, path: str | Path) -> bool:
        """File › Open, Recent and a material dropped on the window: the tab that has it, or
        a new tab (the active one if it is an untouched Untitled). Functions open in a
        canvas tab, instances in a tab of their own."""
        self.opening.emit(True)
        try:
            return self._open(path)
        finally:
            self.opening.emit(False)

    def _open(self, path: str | Path) -> bool:
        from matedit.io.instance import is_instance_file

        path = Path(path)
        at = self.find(path)
        if at >= 0:
            self.activate(at)
            return True
        if is_instance_file(path) or \
                self.current.editor is None and self._session_of_controller().untouched:
            return self.actions.open(path)
        doc = self.actions.read(path)  # a bad file: said here, and no tab opens
        if doc is None:
            return False
        if doc.is_function:
            return self.actions.open(path, doc=doc)
        previous = self.index
        # the tab shows the document at once (an Untitled shown first, then replaced, built
        # every panel twice and compiled an empty material on the way)
        self.new_tab(doc)
        if self.actions.open(path, ask=False, doc=doc):
            return True
        self._drop(self.index, previous)
        return False

    def open_dialog(self) -> bool:
        path = self.actions.ask_open_path()
        return bool(path) and self.open(path)

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

    # --- save, close -----------------------------------------------------------------------
    def _save(self, i: int) -> bool:
        s = self.sessions[i]
        return s.editor.save() if s.editor is not None else self.actions.save()

    def save_all(self) -> bool:
        """File › Save All: every tab with unsaved work, each through its own Save (a new
        document asks where); stops at the first that is not saved."""
        start = self.index
        for i in range(self.count()):
            if not self._dirty(i):
                continue
            self.activate(i)
            if not self._save(i):
                return False
        self.activate(start)
        return True

    def save_active(self) -> bool | None:
        """File › Save on an instance tab (None: a material tab, saved as ever)."""
        s = self.current
        return s.editor.save() if s.editor is not None else None

    def _dirty(self, i: int) -> bool:
        s = self.sessions[i]
        if s.editor is None and i == self._shown:
            return self.controller.dirty
        return s.dirty

    def _name(self, i: int) -> str:
        s = self.sessions[i]
        if s.editor is not None:
            return s.editor.name
        return display_name(self._document(i))

    def _may_close(self, i: int) -> bool:
        """Asks about tab `i`'s unsaved work (active); True to go on."""
        s = self.sessions[i]
        if s.editor is None:
            return self.actions.maybe_save()
        if not s.editor.dirty:
            return True
        answer = self.actions.ask_save_changes(s.editor.name)
        return answer != CANCEL and (answer != SAVE or s.editor.save())

    def close(self, index: int | None = None) -> bool:
        """File › Close (or a tab's ×): asks about unsaved work; the last material tab
        closed leaves an Untitled one. False if the artist cancelled."""
        index = self.index if index is None else index
        if not 0 <= index < self.count():
            return False
        self.activate(index)
        if not self._may_close(index):
            return False
        s = self.sessions[index]
        if s.editor is None:
            self.actions.discard_recovery()
            if sum(1 for x in self.sessions if x.editor is None) == 1:
                self.actions.untitled_key = new_untitled_key()
                self.controller.replace(new_material())
                self.actions.opened.emit(None)
                self.sessions[index] = self._session_of_controller()
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
            if gone.editor is None and index == self._shown:  # the controller's material
                mats = [i for i, x in enumerate(self.sessions) if x.editor is None]
                self._shown = min(mats, key=lambda i: abs(i - index))
                m = self.sessions[self._shown]
                self.actions.untitled_key = m.untitled_key
                self.actions._autosaved_index = m.autosaved_index
                self.controller.swap(m.document, m.undo_stack)
            elif index < self._shown:
                self._shown -= 1
            self.bar.setCurrentIndex(show)
        finally:
            self._switching = False
        if gone.editor is not None:
            self.pages.removeWidget(gone.editor)
            gone.editor.dirty = False  # answered already
            gone.editor.deleteLater()
        elif gone.undo_stack is not self.controller.undo_stack:
            gone.undo_stack.deleteLater()
        self._show(show)
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
                if not self._may_close(i):
                    return False
        for i, s in enumerate(self.sessions):
            if s.editor is not None:
                s.editor.dirty = False  # answered: its own close asks nothing more
            elif i != self._shown:
                self.actions._remove_recovery(recovery_path(s.document.path, s.untitled_key))
        self.actions.autosave_timer.stop()
        self.actions.discard_recovery()  # the shown material's
        return True

    # --- titles ----------------------------------------------------------------------------
    def retitle(self) -> None:
        stacks = [self.bar, self.controller.undo_stack, *(s.undo_stack for s in self.sessions)]
        if not all(shiboken6.isValid(x) for x in stacks):
            return  # the window is going away
        for i, s in enumerate(self.sessions):
            self.bar.setTabText(i, no_mnemonic(self._name(i)) + ("*" if self._dirty(i) else ""))
            if s.editor is not None:
                p = s.editor.doc.path
                self.bar.setTabToolTip(i, f"instance: {p}" if p else "instance, not saved yet")
            else:
                doc = self._document(i)
                self.bar.setTabToolTip(i, str(doc.path) if doc.path else "not saved yet")

    def names(self) -> list[str]:
        return [self.bar.tabText(i) for i in range(self.count())]
