"""`run(path)`: start the editor on a file, or on the built-in sample material."""

from __future__ import annotations

import sys
from pathlib import Path

from PySide6.QtCore import QCoreApplication, Qt
from PySide6.QtGui import QSurfaceFormat
from PySide6.QtWidgets import QApplication

ORGANISATION = APPLICATION = "matedit"


def configure_application_names() -> None:
    """QSettings("matedit", "matedit") and AppDataLocation/matedit for the whole app."""
    QCoreApplication.setOrganizationName(ORGANISATION)
    QCoreApplication.setApplicationName(APPLICATION)


def configure_gl() -> None:
    """OpenGL 3.3 core for every QOpenGLWidget (the renderer's GLSL is #version 330)."""
    fmt = QSurfaceFormat()
    fmt.setVersion(3, 3)
    fmt.setProfile(QSurfaceFormat.OpenGLContextProfile.CoreProfile)
    fmt.setDepthBufferSize(24)
    fmt.setSwapInterval(1)
    QSurfaceFormat.setDefaultFormat(fmt)


def make_application(argv: list[str] | None = None) -> QApplication:
    configure_application_names()
    configure_gl()
    QCoreApplication.setAttribute(Qt.ApplicationAttribute.AA_ShareOpenGLContexts)
    app = QApplication.instance() or QApplication(argv if argv is not None else sys.argv[:1])
    from matedit.app.theme import apply_theme

    apply_theme(app)
    return app


def run(path: str | Path | None = None) -> int:
    """Open the editor on `path` (None: the sample layered material) and run until it closes."""
    app = make_application()
    from matedit.app.compile_service import MaterialCompiler
    from matedit.app.main_window import MainWindow

    MaterialCompiler.asynchronous = True  # structural edits compile off the UI thread
    window = MainWindow(path)
    window.show()
    return int(app.exec())
