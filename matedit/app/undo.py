"""Undo helpers for continuous edits: a slider drag becomes one undo step.

Each drag gets a fresh merge id; every intermediate value is pushed (so the
viewport follows live) and merges into the first command of the drag, which
keeps the value from before the drag for its undo.
"""

from __future__ import annotations

import itertools

from matedit.app.controller import DocumentController, ModelUndoCommand
from matedit.graph.commands import Command, CommandError, SetSetting, SetValue

_ids = itertools.count(1000)


def new_merge_id() -> int:
    """An id for one continuous edit (one drag); QUndoCommand ids must be ints."""
    return next(_ids)


class MergingUndoCommand(ModelUndoCommand):
    """A value edit that absorbs later edits of the same field carrying the same merge id."""

    def __init__(self, controller: DocumentController, command: Command, merge_id: int) -> None:
        super().__init__(controller, command)
        self._merge_id = merge_id

    def id(self) -> int:  # noqa: A003 - Qt's name
        return self._merge_id

    def mergeWith(self, other) -> bool:  # noqa: N802 - Qt's name
        if not isinstance(other, MergingUndoCommand) or other.id() != self.id():
            return False
        mine, theirs = self.command, other.command
        if type(mine) is not type(theirs):
            return False
        if isinstance(mine, SetValue) and (mine.node_id, mine.port) == (theirs.node_id,
                                                                         theirs.port):
            mine.value = theirs.value  # the model already holds it; our _old stays
            return True
        if isinstance(mine, SetSetting) and (mine.node_id, mine.name) == (theirs.node_id,
                                                                           theirs.name):
            mine.value = theirs.value
            return True
        return False


def push_value(controller: DocumentController, command: Command, merge_id: int | None) -> bool:
    """Push `command`; with a merge id, consecutive pushes with that id are one undo step."""
    if merge_id is None:
        return controller.push(command)
    try:
        controller.undo_stack.push(MergingUndoCommand(controller, command, merge_id))
    except CommandError:
        return False
    return True
