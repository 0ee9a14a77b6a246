"""Structural edits compile off the UI thread (matedit.app.compile_worker): the event loop keeps
running during a slow compile, the viewport keeps the last good program until the new one
arrives, and a newer edit supersedes a pending one; the viewport's program is warmed in the
warm-up child process (matedit.render.warmup) before the UI thread gets it, and a superseded
result is not warmed. Real widgets and GL under Xvfb; nothing here depends on Mesa's shader
cache (whether it hits is the benchmark's business: benchmarks/bench_ui_block.py)."""

from __future__ import annotations

import threading
import time

import pytest
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401

from matedit.graph.commands import SetSetting
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = graphs_dir() / "materials" / "rusty_painted_metal.json"
SLOW_S = 2.0  # each compile sleeps this long on the worker (longer than a frame of the
# render process on a loaded 2-core machine, so a frame is drawn meanwhile)


@pytest.fixture
def window(qtbot, request, monkeypatch):
    from matedit.app.compile_service import MaterialCompiler

    request.getfixturevalue("app_env")
    monkeypatch.setattr(MaterialCompiler, "asynchronous", True)
    w = make_window(qtbot, SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    return w


def _slow_compiles(window, threads: list, warm_up: bool = False):
    """Each compile sleeps SLOW_S on the worker; the warm-up is off unless asked (the child's
    start-up would only slow these tests)."""
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
    c.worker.warm_up = warm_up
    if warm_up and c.worker.warming:  # its child takes seconds to start: wait for it
        c.worker.prepare_warm_up()
        end = time.monotonic() + 120
        while not c.worker.warm_up_ready(0.5):
            assert time.monotonic() < end, "the warm-up process never got ready"


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
    old = renderer._compiled.structure_hash  # the program drawn before the edit
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
    assert renderer._compiled.structure_hash == old  # nothing swapped yet
    view.update()
    qtbot.waitUntil(lambda: view.frames > frames, timeout=5000)  # drawn meanwhile, old program
    assert renderer._compiled.structure_hash == old
    qtbot.waitUntil(lambda: bool(delivered), timeout=10000)
    timer.stop()
    assert threads and all(t is not threading.main_thread() for t in threads)
    # the event loop ran throughout the compile (a blocked UI thread would tick ~once)
    assert len(ticks) >= 10
    assert renderer._compiled.structure_hash == delivered[-1].structure_hash
    assert renderer._compiled.structure_hash != old
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
    assert window.viewport.view.renderer._compiled.structure_hash == \
        delivered[0].structure_hash
    # reading `current` waits for nothing now, and is the delivered one
    assert window.compiler.current is delivered[0]


def _viewport_program_hash(renderer) -> str:
    from matedit.compiler.emit import PREVIEW_DEFINES, Entry

    # the sample is opaque: the edit's program is the deferred GBUFFER entry (drawn forward
    # since where the viewport has been idle: Renderer.promote_forward)
    assert not renderer.is_forward or renderer.promoted
    return renderer._compiled.variant(Entry.GBUFFER, PREVIEW_DEFINES).structure_hash


def test_the_warm_up_runs_off_the_ui_thread_before_the_viewport_swaps(window, qtbot,
                                                                      monkeypatch):
    import os

    monkeypatch.setenv("MESA_SHADER_CACHE_DISABLE", "false")  # the warm-up's condition
    from PySide6.QtCore import QTimer

    from matedit.render.warmup import WarmupClient

    view = window.viewport.view
    renderer = view.renderer
    old = renderer._compiled.structure_hash  # the program drawn before the edit
    threads: list = []
    _slow_compiles(window, threads, warm_up=True)
    order: list[str] = []
    warming = threading.Event()

    def slow_warm(client, compiled, state):
        warming.set()
        time.sleep(SLOW_S)  # the viewport must keep the old program meanwhile
        reply = WarmupClient.warm(client, compiled, state)
        order.append("warmed")
        return reply

    window.compiler.worker.warm_fn = slow_warm
    window.compiler.compiled.connect(lambda cm: order.append("delivered"))
    ticks: list[float] = []
    timer = QTimer()
    timer.setInterval(10)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start()
    _structural_edit(window, "warmed_name")
    qtbot.waitUntil(warming.is_set, timeout=30000)
    frames = view.frames
    view.update()
    qtbot.waitUntil(lambda: view.frames > frames, timeout=10000)
    assert renderer._compiled.structure_hash == old  # drawn while warming: the last good one
    qtbot.waitUntil(lambda: "delivered" in order, timeout=120000)  # the child starts first
    timer.stop()
    assert order == ["warmed", "delivered"]  # swapped only once the warm-up was done
    assert len(ticks) >= 10  # the event loop ran during the compile and the warm-up
    (gen, asking, reply), = window.compiler.worker.warmed
    assert gen == window.compiler.worker.generation
    assert asking is not threading.main_thread()
    assert reply.ok, reply.error
    assert reply.pid not in (0, os.getpid())  # another process: no GIL shared with the UI
    assert renderer._compiled.structure_hash != old
    assert any(u.name == "p_warmed_name" for u in renderer._compiled.ir.uniforms)
    # the child drew the very program the viewport now draws
    assert reply.program == _viewport_program_hash(renderer)


def test_a_superseded_result_is_not_warmed(window, qtbot, monkeypatch):
    monkeypatch.setenv("MESA_SHADER_CACHE_DISABLE", "false")  # the warm-up's condition
    threads: list = []
    _slow_compiles(window, threads, warm_up=True)
    delivered = []
    window.compiler.compiled.connect(delivered.append)
    _structural_edit(window, "stale_name")
    _structural_edit(window, "fresh_name")  # while the first one compiles
    worker = window.compiler.worker
    qtbot.waitUntil(lambda: not worker.pending, timeout=120000)
    qtbot.wait(2 * int(SLOW_S * 1000))
    assert len(threads) == 2  # both compiled (the first was running when superseded)
    assert [g for g, _, _ in worker.warmed] == [worker.generation]  # the first never warmed
    (_, _, reply), = worker.warmed
    assert reply.ok, reply.error
    assert len(delivered) == 1
    assert "p_fresh_name" in {u.name for u in delivered[0].ir.uniforms}
    assert reply.program == _viewport_program_hash(window.viewport.view.renderer)


def test_no_warm_up_while_mesas_shader_cache_is_disabled(window, qtbot, monkeypatch):
    monkeypatch.setenv("MESA_SHADER_CACHE_DISABLE", "true")
    threads: list = []
    _slow_compiles(window, threads, warm_up=True)  # asked for, but useless without the cache
    delivered = []
    window.compiler.compiled.connect(delivered.append)
    _structural_edit(window, "uncached_name")
    qtbot.waitUntil(lambda: bool(delivered), timeout=60000)
    assert window.compiler.worker.warmed == []
    assert not window.compiler.worker.warm_up_started  # no child process either
    assert "p_uncached_name" in {u.name for u in delivered[0].ir.uniforms}


def test_another_documents_first_compile_starts_after_the_event_that_opened_it(window, qtbot,
                                                                              monkeypatch):
    """Opening a file into a new tab: the worker gets the new document's compile only once
    the opening event is over (its Python would otherwise share the interpreter lock with
    that event's and stretch it), on a 1 ms timer; asking for the compiled material before
    then starts it at once."""
    from matedit.app.compile_worker import CompileWorker

    c = window.compiler
    submitted: list[str] = []
    real = CompileWorker.submit
    monkeypatch.setattr(CompileWorker, "submit",
                        lambda self, doc, *a, **k: (submitted.append(doc.name or "?"),
                                                    real(self, doc, *a, **k)))
    assert window.open_material(graphs_dir() / "materials" / "worn_painted_steel.json")
    assert submitted == [] and c._first.isActive()  # not inside the opening event
    qtbot.waitUntil(lambda: len(submitted) == 1, timeout=5000)
    qtbot.waitUntil(lambda: c.latest is not None, timeout=60000)
    assert "p_rust_amount" in {u.name for u in c.latest.ir.uniforms}  # the worn sample's

    # asked at once: the deferred compile is started and waited for
    assert window.open_material(graphs_dir() / "materials" / "car_paint.json")
    assert c._first.isActive()
    current = c.current
    assert current is not None and not c._first.isActive() and len(submitted) == 2
