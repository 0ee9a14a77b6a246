"""The document controller: one open document, its undo stack, and its signals.

Every edit from any panel goes through `push(command)`: the model command is
wrapped in a QUndoCommand on one QUndoStack, so undo/redo, the history view and
the dirty marker all follow. The controller re-emits the model's change events
as Qt signals; views subscribe and never hold graph state of their own.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QObject, QTimer, Signal
from PySide6.QtGui import QUndoCommand, QUndoStack

from matedit.graph.commands import Command, CommandError, Macro
from matedit.graph.model import ChangeEvent, ChangeKind, MaterialDocument
from matedit.graph.validate import Analysis, analyse
from matedit.io.document import FileResolver


class ModelUndoCommand(QUndoCommand):
    """A model command on the QUndoStack. `redo` applies it, `undo` reverts it."""

    def __init__(self, controller: DocumentController, command: Command) -> None:
        super().__init__(command.text)
        self.controller = controller
        self.command = command

    def redo(self) -> None:
        self.command.apply(self.controller.document.graph)

    def undo(self) -> None:
        self.command.revert(self.controller.document.graph)


class DocumentController(QObject):
    """Owns the open document. Signals:

    - `changed(ChangeEvent)`: every model change event, as it happens.
    - `structureChanged()`: after a structural edit settles (debounced, 150 ms): recompile.
    - `valuesChanged()`: after a value edit: set uniforms and redraw.
    - `documentReplaced()`: a new document was opened or created.
    - `analysed(Analysis)`: validation results after each structural change.
    """

    changed = Signal(object)
    structureChanged = Signal()
    valuesChanged = Signal()
    documentReplaced = Signal()
    analysed = Signal(object)

    def __init__(self, document: MaterialDocument | None = None, parent=None) -> None:
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.resolver = FileResolver()
        self.document = document or MaterialDocument()
        self.analysis: Analysis | None = None
        self._debounce = QTimer(self)
        self._debounce.setSingleShot(True)
        self._debounce.setInterval(150)
        self._debounce.timeout.connect(self._settle)
        self.document.graph.subscribe(self._on_event)
        self._settle()

    # --- documents -------------------------------------------------------------------------
    def replace(self, document: MaterialDocument) -> None:
        self.document.graph.unsubscribe(self._on_event)
        self.document = document
        self.document.graph.subscribe(self._on_event)
        self.undo_stack.clear()
        self.undo_stack.setClean()
        self.documentReplaced.emit()
        self._settle()

    @property
    def path(self) -> Path | None:
        return self.document.path

    @property
    def dirty(self) -> bool:
        return not self.undo_stack.isClean()

    # --- edits -----------------------------------------------------------------------------
    def push(self, command: Command) -> bool:
        """Apply `command` as one undoable edit; False (and nothing changes) if it is refused."""
        try:
            self.undo_stack.push(ModelUndoCommand(self, command))
        except CommandError:
            return False
        return True

    def push_all(self, commands: list[Command], text: str) -> bool:
        return self.push(Macro(list(commands), text=text)) if commands else False

    # --- events ----------------------------------------------------------------------------
    def _on_event(self, event: ChangeEvent) -> None:
        self.changed.emit(event)
        if event.kind == ChangeKind.STRUCTURAL:
            self._debounce.start()
        elif event.kind == ChangeKind.VALUE:
            self.valuesChanged.emit()

    def flush(self) -> None:
        """Run a pending debounced structural update now (tests, save)."""
        if self._debounce.isActive():
            self._debounce.stop()
            self._settle()

    def _settle(self) -> None:
        self.analysis = analyse(self.document, self.resolver)
        self.analysed.emit(self.analysis)
        self.structureChanged.emit()
