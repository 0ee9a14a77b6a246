"""Work the editor leaves until its viewport has drawn its first frame, so that the window
shows at once: `after_first_frame(view, *steps)` runs each step, in order and each from the
event loop, once the view has drawn a frame, or after FALLBACK_MS when it draws none (no
OpenGL, or a window that is never shown)."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QObject, QTimer

FALLBACK_MS = 4000


class _FirstFrame(QObject):
    def __init__(self, view, steps: tuple[Callable[[], object], ...]) -> None:
        super().__init__(view)
        self._view = view
        self._steps = list(steps)
        view.frameDrawn.connect(self._drawn)
        QTimer.singleShot(FALLBACK_MS, self, self._run)

    @property
    def done(self) -> bool:
        """Whether every step has run."""
        return not self._steps

    def _drawn(self) -> None:
        self._view.frameDrawn.disconnect(self._drawn)
        QTimer.singleShot(0, self, self._run)  # not from inside paintGL

    def _run(self) -> None:
        if self._steps:
            step = self._steps.pop(0)
            step()
            QTimer.singleShot(0, self, self._run)  # the event loop between steps


def after_first_frame(view, *steps: Callable[[], object]) -> _FirstFrame:
    """Runs `steps` once `view` (a ViewportWidget) has drawn its first frame; the returned
    object, a child of `view`, holds them (`done` once they have run)."""
    return _FirstFrame(view, steps)

