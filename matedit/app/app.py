"""`run(path)`: start the editor on a file, or on the built-in sample material."""

from __future__ import annotations

import sys
from pathlib import Path

from PySide6.QtCore import QCoreApplication
from PySide6.QtWidgets import QApplication

ORGANISATION = APPLICATION = "matedit"


def configure_application_names() -> None:
    """QSettings("matedit", "matedit") and AppDataLocation/matedit for the whole app."""
    QCoreApplication.setOrganizationName(ORGANISATION)
    QCoreApplication.setApplicationName(APPLICATION)


def make_application(argv: list[str] | None = None) -> QApplication:
    configure_application_names()
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


def quit_after_first_frame(setting: str) -> None:
    """MATEDIT_QUIT_AFTER_FIRST_FRAME=SECONDS: the editor exits with status 0 once its
    viewport has drawn a frame with the material's program, or with status 1 and an
    `error:` line when it has not within SECONDS (a non-number means 120). For smoke tests
    of an installed build; it changes nothing else."""
    from PySide6.QtCore import QTimer

    from matedit.app.main_window import MainWindow
    from matedit.app.viewport import ViewportWidget

    try:
        limit = float(setting)
    except ValueError:
        limit = 120.0
    if not limit > 1:
        limit = 120.0
    app = make_application()  # run() reuses this instance

    def arm() -> None:
        windows = [w for w in app.topLevelWidgets() if isinstance(w, MainWindow)]
        if not windows:
            QTimer.singleShot(20, arm)
            return
        window = windows[0]
        view = window.viewport.view

        def on_frame() -> None:
            # A compiled material reaches the renderer before the frame after it is drawn.
            if view.running and view.has_material and window.compiler.current is not None:
                print(f"matedit: viewport frame drawn, {view.width()}x{view.height()}",
                      file=sys.stderr)
                app.exit(0)

        view.frameDrawn.connect(on_frame)
        view.update()  # the first frame may already be on screen: ask for one more

    def give_up() -> None:
        view = next((v for w in app.topLevelWidgets() for v in w.findChildren(ViewportWidget)),
                    None)
        why = (view.problem if view is not None else "") or "no viewport frame"
        print(f"error: no first frame within {limit:g} s: {why}", file=sys.stderr)
        app.exit(1)

    QTimer.singleShot(0, arm)
    QTimer.singleShot(int(limit * 1000), give_up)
