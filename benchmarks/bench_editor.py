"""Editor latency on the sample layered material, in the real window with its viewport.

Run: .venv/bin/python benchmarks/bench_editor.py   (starts a virtual X server when there is
no DISPLAY; prints medians, passes or fails nothing)

- parameter edit -> next frame: a SetValue through the controller (what a slider step does)
  until the viewport has drawn the frame showing it; never relinks. Then the same once the
  viewport has been idle (its render process draws the material forward by then:
  matedit.render.server.FORWARD_WHEN_IDLE_S).
- structural edit -> new program: a constant folded into the shader changes (so every edit
  is a program the cache has not seen), from the edit through validation, compile and link
  to the first frame drawn with it. The 150 ms debounce that batches structural edits while
  the artist drags is skipped (flushed) and reported apart.
"""

from __future__ import annotations

import os
import statistics
import sys
import time

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

N_VALUE, N_STRUCT = 40, 15


def open_editor(app):
    """The editor's main window on the built-in sample, shown at 1600x1000, once its viewport
    has a renderer or a problem: (window, viewport widget)."""
    from matedit.app.main_window import MainWindow

    w = MainWindow(restore_layout=False)
    w.resize(1600, 1000)
    w.show()
    view = w.viewport.view
    while view.renderer is None and not view.problem:
        app.processEvents()
    return w, view


def start_display():
    if os.environ.get("DISPLAY") or os.environ["QT_QPA_PLATFORM"] != "xcb":
        return None
    from pyvirtualdisplay import Display

    d = Display(visible=False, size=(1600, 1000), color_depth=24)
    d.start()
    return d


def wait_frame(app, view, n: int, timeout: float = 30.0) -> None:
    end = time.perf_counter() + timeout
    while view.frames <= n:
        app.processEvents()
        if time.perf_counter() > end:
            raise TimeoutError("no frame drawn")


def wait_shown(app, view, timeout: float = 30.0) -> None:
    """Until a picture drawn after every change sent so far is painted (the viewport's render
    process may have a frame of before the change on its way)."""
    serial = view.request_frame()
    end = time.perf_counter() + timeout
    while view.shown_serial < serial:
        app.processEvents()
        if time.perf_counter() > end:
            raise TimeoutError("no frame drawn")


def value_edits(app, w, view) -> tuple[list[float], list[float]]:
    """N_VALUE slider steps on the sample's `amount`: (edit -> frame shown, the renderer's
    frame) in ms, each."""
    from matedit.graph.commands import SetValue

    edit_ms, frame_ms = [], []
    for i in range(N_VALUE):
        t = time.perf_counter()
        w.controller.push(SetValue("amount", "value", 0.2 + 0.6 * (i % 2)))
        wait_shown(app, view)
        edit_ms.append((time.perf_counter() - t) * 1e3)
        frame_ms.append(view.last_frame_time * 1e3)
    return edit_ms, frame_ms


def main() -> int:
    display = start_display()
    from PySide6.QtCore import QStandardPaths

    QStandardPaths.setTestModeEnabled(True)  # keep the real settings and autosaves alone
    from matedit.app.app import make_application

    app = make_application()
    import matedit.app.main_window  # noqa: F401 - imported before the clock starts
    from matedit.graph.commands import AddNode, Connect, SetSetting
    from matedit.graph.model import Link, Node

    t0 = time.perf_counter()
    w, view = open_editor(app)
    if view.renderer is None:
        print(f"no renderer: {view.problem}")
        return 1
    wait_frame(app, view, 0)
    startup = time.perf_counter() - t0
    size = view.renderer.size
    links0 = view.renderer.link_count

    value_ms, paint_ms = value_edits(app, w, view)
    relinks = view.renderer.link_count - links0

    # The same edits once the viewport has been idle: the render process has drawn the
    # material forward since (matedit.render.server.FORWARD_WHEN_IDLE_S, one link)
    from matedit.render.server import FORWARD_WHEN_IDLE_S

    for _ in range(5):  # (asking the renderer is a message: it waits in between)
        end = time.perf_counter() + FORWARD_WHEN_IDLE_S + 1.5
        while time.perf_counter() < end:
            app.processEvents()
            time.sleep(0.02)
        promoted = bool(view.renderer.promoted)
        if promoted:
            break
    wait_shown(app, view)
    idle_ms, idle_paint_ms = value_edits(app, w, view)

    # A constant feeding the rust edge width (e1.b): its value is folded into the code.
    g = w.controller.document.graph
    w.controller.push_all([AddNode(Node("bench_k", "constant", (-450, 400),
                                        {"type": "float", "value": 0.08})),
                           Connect(Link("bench_k", "value", "e1", "b"))], "bench")
    w.controller.flush()
    wait_frame(app, view, view.frames)
    struct_ms, compile_ms = [], []
    for i in range(N_STRUCT):
        links = view.renderer.link_count
        t = time.perf_counter()
        w.controller.push(SetSetting("bench_k", "value", 0.01 + 0.001 * i))
        w.controller.flush()  # the debounce, skipped
        wait_shown(app, view)
        struct_ms.append((time.perf_counter() - t) * 1e3)
        compile_ms.append(w.compiler.last_compile_ms)
        assert view.renderer.link_count == links + 1, "expected a fresh program"
    assert "bench_k" in g.nodes

    med = statistics.median
    gpu = view.gl_renderer()
    print(f"editor latency, sample layered material, viewport {size[0]}x{size[1]} px, {gpu}, "
          f"{os.cpu_count()} cores")
    print(f"  start-up to first frame            {startup * 1e3:8.0f} ms")
    print(f"  parameter edit -> next frame       {med(value_ms):8.1f} ms median "
          f"(min {min(value_ms):.1f}, {N_VALUE} edits, {relinks} relinks)")
    print(f"    of which the renderer's frame    {med(paint_ms):8.1f} ms median")
    label = f"the same once idle ({'drawn forward' if promoted else 'not promoted'})"
    print(f"  {label:<35s}{med(idle_ms):8.1f} ms median (min {min(idle_ms):.1f})")
    print(f"    of which the renderer's frame    {med(idle_paint_ms):8.1f} ms median")
    print(f"  structural edit -> new program     {med(struct_ms):8.1f} ms median "
          f"(min {min(struct_ms):.1f}, {N_STRUCT} edits; compile {med(compile_ms):.1f} ms of it)")
    print(f"    + debounce while editing         {w.controller._debounce.interval():8d} ms")
    print(f"  ratio structural / parameter       {med(struct_ms) / med(value_ms):8.1f} x")
    w.actions.ask_save_changes = lambda name: "discard"
    w.close()
    app.processEvents()
    sys.stdout.flush()
    if display is not None:
        display.stop()
        os._exit(0)  # Qt's own teardown would talk to the X server just stopped
    return 0


if __name__ == "__main__":
    sys.exit(main())
