"""The editor's process never draws: the viewport's renderer runs in a process of its own
(matedit.render.server), so no GL call, and no frame, holds the UI thread (real window under
Xvfb, in a child process so that this test's own imports do not count)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.gui

CHILD = textwrap.dedent("""
    import json, os, sys, time
    from PySide6.QtCore import QStandardPaths
    QStandardPaths.setTestModeEnabled(True)
    from matedit.app.app import make_application
    from matedit.app.main_window import MainWindow
    app = make_application()
    w = MainWindow(None, restore_layout=False)
    w.show()
    view = w.viewport.view
    end = time.monotonic() + 120
    while not (view.environment_ready and view.frame_info is not None
               and view.frame_info.has_material and view.frame_info.environment_name):
        app.processEvents()
        if view.problem or time.monotonic() > end:
            break
    print(json.dumps({
        "problem": view.problem, "frames": view.frames,
        "server": view._proc._proc.pid, "editor": os.getpid(),
        "gl_modules": sorted(m for m in sys.modules
                             if m.split(".")[0] in ("moderngl", "glcontext")
                             or m == "matedit.render.renderer"),
    }))
    w.close()
""")


def test_the_editor_process_imports_no_gl_and_the_picture_comes_from_the_render_process(
        tmp_path):
    env = dict(os.environ, HOME=str(tmp_path), XDG_CACHE_HOME=str(tmp_path / "cache"),
               QT_QPA_PLATFORM="xcb")
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True,
                         env=env, timeout=240)
    line = next((x for x in out.stdout.splitlines() if x.startswith("{")), None)
    assert line is not None, out.stderr[-2000:]
    got = json.loads(line)
    assert not got["problem"]
    assert got["frames"] >= 1  # pictures painted: the material lit by the environment
    assert got["server"] != got["editor"]
    assert got["gl_modules"] == []  # neither moderngl nor the renderer in the editor
