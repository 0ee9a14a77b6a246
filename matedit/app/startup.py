"""Work the editor leaves until its viewport has drawn its first frame, so that the window
shows at once: `after_first_frame(view, *steps)` runs each step, in order and each from the
event loop, once the view has drawn a frame with its environment (the environment itself
follows the first frame: matedit.app.viewport), or, when it has no renderer FALLBACK_MS
after the window was made (no OpenGL, or a window that is never shown), then."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QObject, QTimer

FALLBACK_MS = 4000


class _FirstFrame(QObject):
    def __init__(self, view, steps: tuple[Callable[[], object], ...]) -> None:
        super().__init__(view)
        self._view = view
        self._steps = list(steps)
        self._waiting = True  # for the frame
        view.frameDrawn.connect(self._drawn)
        QTimer.singleShot(FALLBACK_MS, self, self._fallback)

    @property
    def done(self) -> bool:
        """Whether every step has run."""
        return not self._steps

    def _drawn(self) -> None:
        if not self._view.environment_ready:  # the frame with the environment comes first
            return
        self._stop_waiting()

    def _fallback(self) -> None:
        if not self._waiting:
            return
        if self._view.running:
            QTimer.singleShot(FALLBACK_MS, self, self._fallback)  # GL is up: frames will come
            return
        self._stop_waiting()

    def _stop_waiting(self) -> None:
        if self._waiting:
            self._waiting = False
            self._view.frameDrawn.disconnect(self._drawn)
            QTimer.singleShot(0, self, self._run)  # not from inside the paint

    def _run(self) -> None:
        if self._steps:
            step = self._steps.pop(0)
            step()
            QTimer.singleShot(0, self, self._run)  # the event loop between steps


def after_first_frame(view, *steps: Callable[[], object]) -> _FirstFrame:
    """Runs `steps` once `view` (a ViewportWidget) has drawn its first frame with the
    environment (see the module's docstring); the returned object, a child of `view`, holds
    them (`done` once they have run)."""
    return _FirstFrame(view, steps)
