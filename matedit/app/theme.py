"""The editor's look: the dark stylesheet and palette from ui/, and icons from ui/icons/."""

from __future__ import annotations

from functools import cache

from PySide6.QtGui import QColor, QIcon, QPalette
from PySide6.QtWidgets import QApplication

from matedit.resources import ui_dir


@cache
def icon(name: str) -> QIcon:
    """The SVG icon ui/icons/<name>.svg (an empty icon if it is missing)."""
    path = ui_dir() / "icons" / f"{name}.svg"
    return QIcon(str(path)) if path.is_file() else QIcon()


def stylesheet() -> str:
    """The stylesheet, with @ICONS@ standing for the icon folder (QSS urls are relative to
    the working directory otherwise)."""
    path = ui_dir() / "style.qss"
    if not path.is_file():
        return ""
    return path.read_text(encoding="utf-8").replace("@ICONS@", (ui_dir() / "icons").as_posix())


def apply_theme(app: QApplication) -> None:
    """Fusion style, a dark palette (for what the stylesheet does not reach) and the QSS."""
    app.setStyle("Fusion")
    pal = QPalette()
    colours = {
        QPalette.ColorRole.Window: "#262a33",
        QPalette.ColorRole.WindowText: "#d5d9e0",
        QPalette.ColorRole.Base: "#1e2128",
        QPalette.ColorRole.AlternateBase: "#22262e",
        QPalette.ColorRole.Text: "#d5d9e0",
        QPalette.ColorRole.Button: "#2f3440",
        QPalette.ColorRole.ButtonText: "#d5d9e0",
        QPalette.ColorRole.Highlight: "#3d5a99",
        QPalette.ColorRole.HighlightedText: "#ffffff",
        QPalette.ColorRole.ToolTipBase: "#2a2e38",
        QPalette.ColorRole.ToolTipText: "#d5d9e0",
        QPalette.ColorRole.PlaceholderText: "#6b7180",
        QPalette.ColorRole.Link: "#7aa2f7",
    }
    for role, value in colours.items():
        pal.setColor(role, QColor(value))
    pal.setColor(QPalette.ColorGroup.Disabled, QPalette.ColorRole.Text, QColor("#6b7180"))
    pal.setColor(QPalette.ColorGroup.Disabled, QPalette.ColorRole.ButtonText, QColor("#6b7180"))
    app.setPalette(pal)
    app.setStyleSheet(stylesheet())
    app.setWindowIcon(icon("matedit"))
