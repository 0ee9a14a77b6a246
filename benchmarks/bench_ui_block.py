"""How long the UI thread is blocked by a structural edit, in the real editor window.

Run: .venv/bin/python benchmarks/bench_ui_block.py [--edits N] [--json]
(starts a virtual X server when there is no DISPLAY; prints figures, passes or fails nothing)

Two child processes, each on the sample layered material in MainWindow with compiles off the UI
thread (as `matedit edit` runs it), each with Mesa's shader cache enabled in a fresh, empty
temporary MESA_SHADER_CACHE_DIR: one with the compile worker's warm-up (matedit.render.warmup),
one without it (CompileWorker.warm_up = False, the behaviour before). Each makes N structural
edits through the controller's undo stack: add a constant node and wire it into the rust
edge width (`e1.b`; its value is folded into the shader, so every edit is a program never linked
before).

- ui_block_max_ms: the longest gap between ticks of a 5 ms precise QTimer on the UI thread,
  from just before the edit is pushed until the first frame with the new program is drawn
  (what the user feels as a freeze: no event, no paint meanwhile).
- edit -> pixels: from the push to the end of that frame (debounce skipped, as bench_editor.py).
- UI-thread link (Renderer.set_material in the viewport) and that first frame's paint time.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
TICK_MS = 5


def child(warm: bool, edits: int) -> dict:
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    sys.path.insert(0, str(HERE))
    from bench_editor import open_editor, start_display

    display = start_display()
    from PySide6.QtCore import QEventLoop, QStandardPaths, Qt, QTimer

    QStandardPaths.setTestModeEnabled(True)  # keep the real settings and autosaves alone
    from matedit.app.app import make_application

    app = make_application()
    from matedit.app.compile_service import MaterialCompiler
    from matedit.app.compile_worker import CompileWorker
    from matedit.graph.commands import AddNode, Connect
    from matedit.graph.model import Link, Node

    MaterialCompiler.asynchronous = True  # as matedit.app.app.run
    CompileWorker.warm_up = warm  # off: no child process at all
    w, view = open_editor(app)
    if view.renderer is None:
        return {"error": f"no renderer: {view.problem}"}

    ticks: list[float] = []
    timer = QTimer()
    timer.setTimerType(Qt.TimerType.PreciseTimer)
    timer.setInterval(TICK_MS)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start()

    apply_ms: list[float] = []
    original_apply = view._apply_material

    def timed_apply(compiled):
        t = time.perf_counter()
        try:
            return original_apply(compiled)
        finally:
            apply_ms.append((time.perf_counter() - t) * 1e3)

    view._apply_material = timed_apply
    state = {"compiled": False, "done": False}
    loop = QEventLoop()

    def on_compiled(_cm):
        state["compiled"] = True

    def on_frame():
        if state["compiled"] and not state["done"]:
            state["done"] = True
            state["t_done"] = time.perf_counter()
            state["paint_ms"] = view.last_frame_time * 1e3
            QTimer.singleShot(3 * TICK_MS, loop.quit)  # a tick after the frame closes the gap

    w.compiler.compiled.connect(on_compiled)
    view.frameDrawn.connect(on_frame)

    def spin(ms: int) -> None:
        QTimer.singleShot(ms, loop.quit)
        loop.exec()

    def plain_paint() -> float:
        n = view.frames
        view.update()
        while view.frames == n:
            spin(20)
        return view.last_frame_time * 1e3

    def edit(i: int) -> dict:
        spin(150)  # idle: the previous frame is done, the timer ticks evenly
        plain = plain_paint()
        spin(50)
        state.update(compiled=False, done=False)
        links0 = view.renderer.link_count
        t0 = time.perf_counter()
        nid = f"bench_k{i}"
        w.controller.push_all([AddNode(Node(nid, "constant", (-450, 400 + 20 * i),
                                            {"type": "float", "value": 0.01 + 0.001 * i})),
                               Connect(Link(nid, "value", "e1", "b"))], "bench edit")
        w.controller.flush()  # the debounce, skipped
        guard = QTimer.singleShot(60000, loop.quit)  # noqa: F841 - no frame: give up
        while not state["done"]:
            loop.exec()
            if time.perf_counter() - t0 > 60:
                raise TimeoutError("no frame with the new program")
        before = [t for t in ticks if t < t0]
        window = ([before[-1]] if before else [t0]) + [t for t in ticks if t >= t0]
        window = [t for t in window if t <= state["t_done"]] + \
            [t for t in window if t > state["t_done"]][:1]
        gaps = [b - a for a, b in zip(window, window[1:])]
        return {"block_ms": max(gaps) * 1e3, "latency_ms": (state["t_done"] - t0) * 1e3,
                "apply_ms": apply_ms[-1] if apply_ms else float("nan"),
                "paint_ms": state["paint_ms"], "plain_paint_ms": plain,
                "compile_ms": w.compiler.last_compile_ms,
                "links": view.renderer.link_count - links0}

    edit(0)  # the first edit makes the worker and starts the warm-up's child: not measured
    worker = w.compiler.worker
    if warm:  # edits before the child is ready are not warmed (nor held back): wait for it
        end = time.perf_counter() + 120
        while not worker.warm_up_ready(0.2) and time.perf_counter() < end:
            spin(50)
        edit(edits + 1)  # the child's first warm-up loads the textures: not measured either
    prof = None
    if os.environ.get("MATEDIT_BENCH_PROFILE"):  # the UI thread's profile, to stderr
        import cProfile

        prof = cProfile.Profile()
        prof.enable()
    runs = [edit(i) for i in range(1, edits + 1)]
    if prof is not None:
        import pstats

        prof.disable()
        pstats.Stats(prof, stream=sys.stderr).sort_stats("cumulative").print_stats(45)
    timer.stop()
    med = statistics.median
    out = {
        "warm_up": warm, "edits": edits,
        "viewport": list(view.renderer.size), "gl": view.ctx.info.get("GL_RENDERER", "?"),
        "cache_dir": os.environ.get("MESA_SHADER_CACHE_DIR"),
        "ui_block_max_ms": max(r["block_ms"] for r in runs),
        "ui_block_median_ms": med(r["block_ms"] for r in runs),
        "latency_median_ms": med(r["latency_ms"] for r in runs),
        "apply_median_ms": med(r["apply_ms"] for r in runs),
        "first_paint_median_ms": med(r["paint_ms"] for r in runs),
        "plain_paint_median_ms": med(r["plain_paint_ms"] for r in runs),
        "compile_median_ms": med(r["compile_ms"] for r in runs),
        "links_per_edit": sorted({r["links"] for r in runs}),
        "warmed": sum(1 for g, _, r in worker.warmed if r.ok),
        "runs": runs,
    }
    w.actions.ask_save_changes = lambda name: "discard"
    w.close()
    app.processEvents()
    if display is not None:
        print(json.dumps(out))
        sys.stdout.flush()
        display.stop()
        os._exit(0)  # Qt's own teardown would talk to the X server just stopped
    return out


def measure(warm: bool, edits: int, timeout: float = 600) -> dict:
    """One child process with a fresh, empty Mesa shader cache (enabled)."""
    with tempfile.TemporaryDirectory(prefix="matedit-mesa-cache-") as cache:
        env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="false", MESA_SHADER_CACHE_DIR=cache)
        cmd = [sys.executable, str(Path(__file__).resolve()), "--child",
               "warm" if warm else "cold", "--edits", str(edits)]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env,
                                  cwd=HERE.parent)
        except subprocess.TimeoutExpired:
            return {"error": f"timed out after {timeout:.0f} s"}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        return {"error": (proc.stderr.strip().splitlines() or ["no output"])[-1]}
    return json.loads(lines[-1])


def run(edits: int = 8) -> dict:
    """Both runs (for benchmarks/run_all.py): {"warm": ..., "cold": ...}."""
    return {"warm": measure(True, edits), "cold": measure(False, edits)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--edits", type=int, default=8)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", choices=("warm", "cold"))
    args = ap.parse_args(argv)
    if args.child:
        out = child(args.child == "warm", args.edits)
        print(json.dumps(out))
        return 0 if "error" not in out else 1
    res = run(args.edits)
    if args.json:
        print(json.dumps(res))
        return 0
    print(f"UI-thread blocking by a structural edit, sample layered material, {args.edits} edits "
          f"each; Mesa shader cache enabled, fresh temporary MESA_SHADER_CACHE_DIR per run")
    for key, label in (("cold", "no warm-up (before)"), ("warm", "worker warm-up")):
        r = res[key]
        if "error" in r:
            print(f"  {label:22s} error: {r['error']}")
            continue
        print(f"  {label:22s} ui_block max {r['ui_block_max_ms']:6.0f} ms, median "
              f"{r['ui_block_median_ms']:5.0f} | edit->pixels median "
              f"{r['latency_median_ms']:5.0f} ms | UI link {r['apply_median_ms']:5.0f} ms, "
              f"first paint {r['first_paint_median_ms']:5.0f} ms "
              f"(plain {r['plain_paint_median_ms']:4.0f}) | compile "
              f"{r['compile_median_ms']:4.1f} ms | viewport {r['viewport'][0]}x"
              f"{r['viewport'][1]}, warmed {r['warmed']}, links/edit {r['links_per_edit']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
