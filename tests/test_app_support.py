"""Shared set-up for the editor's GUI tests (pytest-qt under Xvfb; imported, holds no tests).

Importing this module before the QApplication exists asks for OpenGL 3.3 core
contexts (what the viewport's renderer needs) and isolates the
autosave folder in Qt's test locations, emptied for each test.
"""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from pathlib import Path

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QSettings, QStandardPaths  # noqa: E402

from matedit.app.app import configure_application_names  # noqa: E402

configure_application_names()
QStandardPaths.setTestModeEnabled(True)
# Recovery files of this test run only: other runs on the machine clear theirs.
if "MATEDIT_RECOVERY_DIR" not in os.environ:
    os.environ["MATEDIT_RECOVERY_DIR"] = tempfile.mkdtemp(prefix="matedit-recovery-")
    atexit.register(shutil.rmtree, os.environ["MATEDIT_RECOVERY_DIR"], True)
# QSettings of this test run only: tests/conftest.py points them at a folder per run.


@pytest.fixture
def app_env(qapp):
    """A clean QSettings and AppData (autosave) for one test; the dark theme applied."""
    from matedit.app.document_actions import recovery_dir
    from matedit.app.theme import apply_theme

    configure_application_names()
    QStandardPaths.setTestModeEnabled(True)
    QSettings().clear()
    shutil.rmtree(recovery_dir(), ignore_errors=True)
    apply_theme(qapp)
    yield qapp
    QSettings().clear()
    shutil.rmtree(recovery_dir(), ignore_errors=True)


def make_window(qtbot, path=None, *, sample: bool = False, show: bool = False,
                answers: dict | None = None, track: bool = True):
    """A main window on `path` (or an empty material). Questions are answered from
    `answers` (`save_changes`: save/discard/cancel; `recover`: bool or a callable;
    `recover_all`: the start-up list's answers), never by a modal dialog."""
    from matedit.app.main_window import MainWindow

    answers = {"save_changes": "discard", "recover": True, **(answers or {})}
    errors: list[tuple[str, str]] = []
    w = MainWindow(restore_layout=False, start=False)
    if track:
        qtbot.addWidget(w)
    w.actions.ask_save_changes = lambda name: answers["save_changes"]
    recover = answers["recover"]
    w.actions.ask_recover = recover if callable(recover) else (lambda p, rec: recover)
    if "recover_all" in answers:  # {rec: "recover"|"discard"|"keep"} from the entries found
        w.actions.ask_recover_all = answers["recover_all"]
    else:  # each entry answered as `recover` answers the one-file question
        w.actions.ask_recover_all = lambda entries: {
            e.rec: "recover" if w.actions.ask_recover(e.document or e.rec, e.rec)
            else "discard" for e in entries}
    w.actions.show_error = lambda title, text: errors.append((title, text))
    w.shown_errors = errors
    w.actions.start(path, None if not sample else Path(sample))
    w.compiler.recompile()
    if show:
        w.resize(1400, 880)
        w.show()
        qtbot.waitExposed(w)
    return w


def wait_for_renderer(qtbot, window, timeout: int = 30000):
    """The view's renderer, once it has the environment and the window has done what it
    leaves until after the first frame (matedit.app.startup)."""
    view = window.viewport.view
    startup = getattr(window, "startup", None)
    library = getattr(window, "library", None)
    qtbot.waitUntil(lambda: (view.renderer is not None and view.environment_ready
                             and (startup is None or startup.done)
                             and (library is None or library.listed))
                    or bool(view.problem), timeout=timeout)
    assert view.renderer is not None, view.problem
    return view.renderer


def settle(qtbot, window, ms: int = 5) -> None:
    """Run the debounced recompile now, let queued UI work happen, and wait for the node
    thumbnails (evaluated on a worker thread) to be on the canvas."""
    tabs = window.tabs.all_tabs()
    for tab in tabs:
        tab.controller.flush()
    for tab in tabs:
        if tab.previews is not None:
            tab.previews.flush()
    qtbot.waitUntil(lambda: all(t.previews is None or t.previews.idle for t in tabs),
                    timeout=60000)
    qtbot.wait(ms)
    layers = getattr(window, "layers", None)  # its rows are built a few a turn
    if layers is not None:
        qtbot.waitUntil(lambda: layers.settled, timeout=10000)
    # a file just opened: the canvas builds its items in a turn of their own
    qtbot.waitUntil(lambda: all(t.canvas.scene().settled for t in tabs), timeout=10000)
