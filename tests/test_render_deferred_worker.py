"""Structural edits compile off the UI thread (matedit.app.compile_worker): the event loop keeps
running during a slow compile, the viewport keeps the last good program until the new one
arrives, and a newer edit supersedes a pending one. Real widgets and GL under Xvfb."""

from __future__ import annotations

import threading
import time

import pytest
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401

from matedit.graph.commands import SetSetting
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = graphs_dir() / "materials" / "rusty_painted_metal.json"
SLOW_S = 0.6  # each compile sleeps this long on the worker (time.sleep lets the UI run)


@pytest.fixture
def window(qtbot, request, monkeypatch):
    from matedit.app.compile_service import MaterialCompiler

    request.getfixturevalue("app_env")
    monkeypatch.setattr(MaterialCompiler, "asynchronous", True)
    w = make_window(qtbot, SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    return w


def _slow_compiles(window, threads: list):
    from matedit.compiler import compile_document

    def slow(doc, resolver, target):
        threads.append(threading.current_thread())
        time.sleep(SLOW_S)
        return compile_document(doc, resolver, target)

    c = window.compiler
    if c.worker is None:  # the first structural edit creates it; make one now
        from matedit.app.compile_worker import CompileWorker

        c.worker = CompileWorker(c)
        c.worker.finished.connect(c._finished)
    c.worker.compile_fn = slow


def _structural_edit(window, value: str):
    """A layer stack's blend-mode-like setting change through the undo stack: a new program."""
    doc = window.controller.document
    nid = next(n for n, node in doc.graph.nodes.items() if node.kind == "scalar_parameter")
    assert window.controller.push(SetSetting(nid, "name", value))
    window.controller.flush()


def test_a_slow_compile_never_blocks_the_ui_and_the_old_program_stays(window, qtbot):
    from PySide6.QtCore import QTimer

    view = window.viewport.view
    renderer = view.renderer
    old = renderer._compiled
    threads: list = []
    _slow_compiles(window, threads)
    delivered = []
    window.compiler.compiled.connect(delivered.append)
    ticks: list[float] = []
    timer = QTimer()
    timer.setInterval(10)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start()
    frames = view.frames
    _structural_edit(window, "renamed_for_test")
    assert window.compiler.worker.pending
    assert renderer._compiled is old  # nothing swapped yet
    view.update()
    qtbot.waitUntil(lambda: view.frames > frames, timeout=5000)  # drawn meanwhile, old program
    assert renderer._compiled is old
    qtbot.waitUntil(lambda: bool(delivered), timeout=10000)
    timer.stop()
    assert threads and all(t is not threading.main_thread() for t in threads)
    # the event loop ran throughout the compile (a blocked UI thread would tick ~once)
    assert len(ticks) >= 10
    assert renderer._compiled is delivered[-1]
    assert renderer._compiled.structure_hash != old.structure_hash
    assert any(u.name == "p_renamed_for_test" for u in renderer._compiled.ir.uniforms)


def test_a_newer_edit_supersedes_a_pending_one(window, qtbot):
    threads: list = []
    _slow_compiles(window, threads)
    delivered = []
    window.compiler.compiled.connect(delivered.append)
    _structural_edit(window, "first_name")
    _structural_edit(window, "second_name")
    qtbot.waitUntil(lambda: not window.compiler.worker.pending, timeout=10000)
    qtbot.wait(2 * int(SLOW_S * 1000))  # a stale result would have arrived by now
    assert len(delivered) == 1
    names = {u.name for u in delivered[0].ir.uniforms}
    assert "p_second_name" in names and "p_first_name" not in names
    assert window.viewport.view.renderer._compiled is delivered[0]
    # reading `current` waits for nothing now, and is the delivered one
    assert window.compiler.current is delivered[0]
