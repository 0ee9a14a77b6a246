"""The document controller: one open document, its undo stack, and its signals.

Every edit from any panel goes through `push(command)`: the model command is
wrapped in a QUndoCommand on one QUndoStack, so undo/redo, the history view and
the dirty marker all follow. The controller re-emits the model's change events
as Qt signals; views subscribe and never hold graph state of their own.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtGui import QUndoCommand, QUndoStack

from matedit.graph.commands import Command, CommandError, Macro, SetSetting, SetValue
from matedit.graph.model import ChangeEvent, ChangeKind, MaterialDocument
from matedit.graph.validate import Analysis, analyse
from matedit.io import document as documents
from matedit.io.document import FileResolver


@dataclass(frozen=True)
class ValueChange:
    """What a `valuesChanged` signal carries: the node and the port (or, with `setting`, the
    non-structural setting, such as a texture's path) whose value changed. `node` None says
    many values changed at once (a macro applied or undone): receivers refresh everything."""

    node: str | None = None
    port: str | None = None
    setting: bool = False

    @property
    def many(self) -> bool:
        return self.node is None

    def touches(self, node_id: str) -> bool:
        """Whether a receiver showing node `node_id` is concerned."""
        return self.node is None or self.node == node_id


MANY_VALUES = ValueChange()


class ModelUndoCommand(QUndoCommand):
    """A model command on the QUndoStack. `redo` applies it, `undo` reverts it.

    `applied=True` means the controller already applied it (to learn whether the
    model accepts it before it goes on the stack), so the first `redo` is skipped.
    """

    def __init__(self, controller: DocumentController, command: Command,
                 applied: bool = False) -> None:
        super().__init__(command.text)
        self.controller = controller
        self.command = command
        self._skip_redo = applied

    def redo(self) -> None:
        if self._skip_redo:
            self._skip_redo = False
            return
        with self.controller.batch(isinstance(self.command, Macro)):
            self.command.apply(self.controller.document.graph)

    def undo(self) -> None:
        with self.controller.batch(isinstance(self.command, Macro)):
            self.command.revert(self.controller.document.graph)


_merge_ids = itertools.count(1000)


def new_merge_id() -> int:
    """An id for one continuous edit (a slider drag); QUndoCommand ids are ints."""
    return next(_merge_ids)


class MergingUndoCommand(ModelUndoCommand):
    """A value or setting edit that absorbs later edits of the same field with the same id:
    every step of a drag is applied (the viewport follows live) yet undoes as one."""

    def __init__(self, controller: DocumentController, command: Command, merge_id: int,
                 applied: bool = False) -> None:
        super().__init__(controller, command, applied)
        self._merge_id = merge_id

    def id(self) -> int:
        return self._merge_id

    def mergeWith(self, other: QUndoCommand) -> bool:  # noqa: N802 - Qt's name
        if not isinstance(other, MergingUndoCommand) or other.id() != self.id():
            return False
        mine, theirs = self.command, other.command
        if isinstance(mine, SetValue) and isinstance(theirs, SetValue) and \
                (mine.node_id, mine.port) == (theirs.node_id, theirs.port):
            mine.value = theirs.value  # the model holds it already; our _old stays
            return True
        if isinstance(mine, SetSetting) and isinstance(theirs, SetSetting) and \
                (mine.node_id, mine.name) == (theirs.node_id, theirs.name):
            mine.value = theirs.value
            return True
        return False


class DocumentController(QObject):
    """Owns the open document. Signals:

    - `changed(ChangeEvent)`: every model change event, as it happens.
    - `structureChanged()`: after a structural edit settles (debounced, 150 ms): recompile.
    - `valuesChanged(ValueChange)`: after a value edit, naming the node and port (set that
      uniform and redraw), or `MANY_VALUES` after a macro of value edits (set them all).
    - `documentReplaced()`: a new document was opened or created.
    - `analysed(Analysis)`: validation results after each structural change.
    - `batchEnded()`: after the last event of a macro (applied, undone or redone). A view
      that rebuilds from the document (a panel, the selection's inspector) can wait for it
      while `batching` instead of rebuilding on each of the macro's events.
    """

    changed = Signal(object)
    structureChanged = Signal()
    valuesChanged = Signal(object)  # ValueChange
    documentReplaced = Signal()
    analysed = Signal(object)
    undoStackReplaced = Signal(object)  # the stack that was the controller's (swap)
    batchEnded = Signal()

    def __init__(self, document: MaterialDocument | None = None, parent=None) -> None:
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.resolver = FileResolver()
        self.document = document or MaterialDocument()
        self.analysis: Analysis | None = None
        self._revision = 0  # counts changes to the document (events, replace, swap)
        # the revision `analysis` was made of, and the function files read by then
        self._analysed_revision: tuple[int, int] = (-1, -1)
        self._debounce = QTimer(self)
        self._debounce.setSingleShot(True)
        self._debounce.setInterval(150)
        self._debounce.timeout.connect(self._settle)
        self._batching = False
        self._batched_values = False
        self.document.graph.subscribe(self._on_event)
        self._settle()

    # --- documents -------------------------------------------------------------------------
    def replace(self, document: MaterialDocument) -> None:
        self._revision += 1
        self.document.graph.unsubscribe(self._on_event)
        self.document = document
        self.document.graph.subscribe(self._on_event)
        self.undo_stack.clear()
        self.undo_stack.setClean()
        self.documentReplaced.emit()
        self._settle()

    def swap(self, document: MaterialDocument, undo_stack: QUndoStack) -> None:
        """Shows another open document with its own undo history (a document tab): nothing
        of either is lost, and the one swapped out can be swapped back as it was."""
        self._debounce.stop()
        self._revision += 1
        self.document.graph.unsubscribe(self._on_event)
        old = self.undo_stack
        self.document, self.undo_stack = document, undo_stack
        self.document.graph.subscribe(self._on_event)
        if old is not undo_stack:
            self.undoStackReplaced.emit(old)
        self.documentReplaced.emit()
        self._settle()

    @property
    def path(self) -> Path | None:
        return self.document.path

    @property
    def dirty(self) -> bool:
        return not self.undo_stack.isClean()

    # --- edits -----------------------------------------------------------------------------
    def push(self, command: Command, merge_id: int | None = None) -> bool:
        """Apply `command` as one undoable edit; False (and nothing changes) if it is refused.

        With `merge_id` (see `new_merge_id`), consecutive value edits of one field carrying
        the same id merge into one undo step.
        """
        try:
            with self.batch(isinstance(command, Macro)):
                command.apply(self.document.graph)  # refused edits never reach the stack
        except CommandError:
            return False
        if merge_id is None:
            self.undo_stack.push(ModelUndoCommand(self, command, applied=True))
        else:
            self.undo_stack.push(MergingUndoCommand(self, command, merge_id, applied=True))
        return True

    def amend(self, extra: Command) -> bool:
        """Applies `extra` as part of the last edit, so that one undo takes back both (the
        room a node takes when it grows); a separate edit when the last one cannot take it
        (nothing pushed, a merging value edit, or undone steps above it)."""
        i = self.undo_stack.index()
        top = self.undo_stack.command(i - 1) if i > 0 else None
        if type(top) is not ModelUndoCommand or i != self.undo_stack.count():
            return self.push(extra)
        try:
            with self.batch(False):
                extra.apply(self.document.graph)
        except CommandError:
            return False
        top.command = Macro([top.command, extra], text=top.command.text)
        return True

    def push_all(self, commands: list[Command], text: str) -> bool:
        return self.push(Macro(list(commands), text=text)) if commands else False

    # --- events ----------------------------------------------------------------------------
    @contextmanager
    def batch(self, on: bool = True) -> Iterator[None]:
        """Value events inside are announced once, as `MANY_VALUES`, at the end."""
        if not on or self._batching:
            yield
            return
        self._batching, self._batched_values = True, False
        try:
            yield
        finally:
            self._batching = False
            if self._batched_values:
                self.valuesChanged.emit(MANY_VALUES)
            self.batchEnded.emit()

    @property
    def batching(self) -> bool:
        """Inside a macro's events: `batchEnded` follows its last one."""
        return self._batching

    def _on_event(self, event: ChangeEvent) -> None:
        self._revision += 1
        self.changed.emit(event)
        if event.kind == ChangeKind.STRUCTURAL:
            self._debounce.start()
        elif event.kind == ChangeKind.VALUE:
            if self._batching:
                self._batched_values = True
            else:
                self.valuesChanged.emit(ValueChange(event.node_ids[0] if event.node_ids
                                                    else None, event.port,
                                                    event.what == "setting"))

    def flush(self) -> None:
        """Run a pending debounced structural update now (tests, save)."""
        if self._debounce.isActive():
            self._debounce.stop()
            self._settle()

    def reanalyse(self) -> None:
        """Validate and announce a structural change now, with no edit: a function or layer
        file the document uses changed on disk (saved from another tab)."""
        self._debounce.stop()
        self._settle()

    @property
    def current_analysis(self) -> Analysis | None:
        """`analysis` when it was made of the document as it is now (no change since, and no
        function file read anew since: one changed on disk), else None: a compile can take
        it instead of validating the graph again."""
        fresh = self._analysed_revision == (self._revision, documents.LOADS)
        return self.analysis if fresh else None

    def _settle(self) -> None:
        self.analysis = analyse(self.document, self.resolver)
        # after it: the files it read for the first time are those it was made of
        self._analysed_revision = (self._revision, documents.LOADS)
        self.analysed.emit(self.analysis)
        self.structureChanged.emit()
