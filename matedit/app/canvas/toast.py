"""A short message floating near the cursor (why a connection was refused), gone after 3 s."""

from __future__ import annotations

from PySide6.QtCore import QPoint, Qt, QTimer
from PySide6.QtWidgets import QLabel, QWidget

from matedit.app.canvas import constants as C


class Toast(QLabel):
    def __init__(self, parent: QWidget) -> None:
        super().__init__(parent)
        self.setWordWrap(True)
        self.setMaximumWidth(420)
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self.setStyleSheet(
            f"QLabel {{ background: {C.TOAST_BG}; color: {C.TOAST_FG}; border: 1px solid #8c3b3b;"
            " border-radius: 5px; padding: 5px 8px; font-size: 12px; }")
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self.hide)
        self.hide()

    def show_at(self, text: str, at: QPoint, ms: int = C.TOAST_MS) -> None:
        self.setText(text)
        self.adjustSize()
        parent = self.parentWidget()
        x = max(4, min(at.x() + 14, parent.width() - self.width() - 4))
        y = max(4, min(at.y() + 18, parent.height() - self.height() - 4))
        self.move(x, y)
        self.show()
        self.raise_()
        self._timer.start(ms)
