"""Deferred UI work, one job a turn of the event loop.

Panels that rebuild after another document or a macro of edits (the Layers panel's rows, the
Parameters dock's, the GLSL dock's text, the Library's listing, the instances' thumbnails)
each cost the UI thread 5-20 ms a step. Run from timers of their own, steps due at the same
moment ran back to back in one pass of Qt's timers, with no input, paint or other timer
between them: one long block. Queued here instead, they run one a turn: after each job the
queue's 1 ms timer is started again, so that whatever else became due meanwhile (input, a
paint, a timer due earlier) runs before the next job.

A job is keyed by its owner (a QObject, or None) and a name: adding a key already queued
keeps its place and takes the newer callable. A job whose owner has been deleted is dropped.
"""

from __future__ import annotations

from collections.abc import Callable

import shiboken6
from PySide6.QtCore import QCoreApplication, QObject, QTimer

_Key = tuple[int, str]


class Turns(QObject):
    """The queue (see the module's docstring); `turns()` gives the application's."""

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._jobs: dict[_Key, tuple[QObject | None, Callable[[], object]]] = {}
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(1)  # a real timer: posted events and due timers run first
        self._timer.timeout.connect(self._run)

    @staticmethod
    def _key(owner: QObject | None, name: str) -> _Key:
        return (id(owner) if owner is not None else 0, name)

    def add(self, owner: QObject | None, name: str, job: Callable[[], object]) -> None:
        """Runs `job` in a later turn (once, however often it is added before then)."""
        key = self._key(owner, name)
        self._jobs[key] = (owner, job)
        if not self._timer.isActive():
            self._timer.start()

    def cancel(self, owner: QObject | None, name: str) -> None:
        self._jobs.pop(self._key(owner, name), None)

    def pending(self, owner: QObject | None, name: str) -> bool:
        return self._key(owner, name) in self._jobs

    def run_all(self) -> None:
        """Every queued job now, in order (tests; a caller that needs the results at once)."""
        while self._jobs:
            self._run()

    def _run(self) -> None:
        while self._jobs:
            key = next(iter(self._jobs))
            owner, job = self._jobs.pop(key)
            if owner is not None and not shiboken6.isValid(owner):
                continue  # its widget is gone: nothing to do for it
            try:
                job()
            finally:
                if self._jobs and not self._timer.isActive():
                    self._timer.start()
            return


_turns: Turns | None = None


def turns() -> Turns:
    """The application's queue (made with the first use, a child of the application)."""
    global _turns
    app = QCoreApplication.instance()
    if _turns is None or not shiboken6.isValid(_turns) or _turns.parent() is not app:
        _turns = Turns(app)
    return _turns
