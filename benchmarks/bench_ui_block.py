"""How long the UI thread is blocked, in the real editor window: by a structural edit, during
reference accumulation, a slider drag, an environment change, a resize, opening a file and
deleting, undoing and duplicating a whole graph.

Run: .venv/bin/python benchmarks/bench_ui_block.py [--edits N] [--cases-only] [--json]
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
- the link (Renderer.set_material in the render process, from the compiled material's arrival
  to `materialApplied`) and that first frame's GL time.

A third child process (`--child cases`, no warm-up child: its processes would share the 2
cores with what is measured) times the other cases, each by the same 5 ms ticks, each
writing its own `ui_block_max_ms`:

- reference: the mode chooser set to Reference, at REFERENCE_SAMPLES samples a pixel, from the
  choice until the view has converged (or REFERENCE_WINDOW_S); also the time to converge and
  the number of paints (the viewport draws the accumulation in slices: more paints than frames);
- slider: a drag of the `amount` parameter, SLIDER_STEPS value edits (merged undo steps, as a
  field's drag) one every 16 ms, until the frame after the last edit;
- environment: the environment chooser to Sky, back to Studio and to Sky again (each change
  through `EnvironmentChoice.choose`, the first may bake; the IBL cache is the user's), until
  the frame after each;
- resize: the window between 1600x1000 and 1400x900, RESIZES times, until the frame after each;
- open: File > Open of each of OPEN_SAMPLES in turn (a new tab each, as a material opened over
  a saved one), until the frame of its material and OPEN_SETTLE_MS after (the panels'
  rebuilds and the compile's delivery);
- delete: every node of the open material selected and deleted (one macro), then undone, then
  every node duplicated (Ctrl+D), each until the frame after it and EDIT_SETTLE_MS after.
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
REFERENCE_SAMPLES = 512  # 16 frames of 32 samples: converges within the window on llvmpipe
REFERENCE_WINDOW_S = 120.0
SLIDER_STEPS = 30
RESIZES = 6
CASES = ("reference", "slider", "environment", "resize", "open", "delete")
OPEN_SAMPLES = ("car_paint", "chrome_rubber_grip", "mossy_stone", "worn_painted_steel")
OPEN_SETTLE_MS = 1500  # the compile, its delivery and the first frame of the new program
EDIT_SETTLE_MS = 1000


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
    # the link runs in the render process: from the compiled material's arrival to
    # `materialApplied` (the server's reply)
    view.materialApplied.connect(
        lambda _ok: "t_compiled" in state and apply_ms.append(
            (time.perf_counter() - state["t_compiled"]) * 1e3))
    state = {"compiled": False, "done": False, "serial": 0}
    loop = QEventLoop()

    def on_compiled(_cm):
        state["compiled"] = True
        state["t_compiled"] = time.perf_counter()
        # the viewport has sent the program: a picture asked for now shows it
        state["serial"] = view.request_frame()

    def on_frame():
        if state["compiled"] and not state["done"] and view.shown_serial >= state["serial"]:
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
        "viewport": list(view.renderer.size), "gl": view.gl_renderer(),
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
    return _finish(w, app, display, out)


def _finish(w, app, display, out: dict) -> dict:
    """Closes the window; in a child with its own X server, prints `out` and exits."""
    w.actions.ask_save_changes = lambda name: "discard"
    w.close()
    app.processEvents()
    if display is not None:
        print(json.dumps(out))
        sys.stdout.flush()
        display.stop()
        os._exit(0)  # Qt's own teardown would talk to the X server just stopped
    return out


def _quantile(values: list[float], q: float) -> float:
    v = sorted(values)
    return v[min(len(v) - 1, int(q * (len(v) - 1)))] if v else 0.0


class Ticks:
    """A 5 ms precise timer on the UI thread; `gaps(t0, t1)` are the gaps between ticks from
    the last tick before t0 to the first after t1 (ms), `longest` the longest of them."""

    def __init__(self) -> None:
        from PySide6.QtCore import Qt, QTimer

        self.ticks: list[float] = []
        self.timer = QTimer()
        self.timer.setTimerType(Qt.TimerType.PreciseTimer)
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(lambda: self.ticks.append(time.perf_counter()))
        self.timer.start()

    def gaps(self, t0: float, t1: float) -> list[float]:
        before = [t for t in self.ticks if t < t0]
        inside = [t for t in self.ticks if t0 <= t <= t1]
        after = [t for t in self.ticks if t > t1][:1]
        window = (before[-1:] or [t0]) + inside + (after or [t1])
        return [(b - a) * 1e3 for a, b in zip(window, window[1:])]

    def longest(self, t0: float, t1: float) -> float:
        return max(self.gaps(t0, t1), default=0.0)


def cases_child(only: tuple[str, ...] = CASES) -> dict:
    """Reference accumulation, slider drag, environment change and resize (module docstring)."""
    os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
    sys.path.insert(0, str(HERE))
    from bench_editor import open_editor, start_display

    display = start_display()
    from PySide6.QtCore import QEventLoop, QStandardPaths, QTimer

    QStandardPaths.setTestModeEnabled(True)  # keep the real settings and autosaves alone
    from matedit.app.app import make_application

    app = make_application()
    from matedit.app.compile_service import MaterialCompiler
    from matedit.app.compile_worker import CompileWorker
    from matedit.app.controller import new_merge_id
    from matedit.graph.commands import SetValue

    MaterialCompiler.asynchronous = True
    CompileWorker.warm_up = False
    w, view = open_editor(app)
    if view.renderer is None:
        return {"error": f"no renderer: {view.problem}"}
    panel = w.viewport
    loop = QEventLoop()

    def spin(ms: int) -> None:
        QTimer.singleShot(ms, loop.quit)
        loop.exec()

    def wait_frames(n0: int, until=None, limit_s: float = 60.0) -> float:
        """Runs the loop until a frame after `n0` is drawn (and `until()` holds); its end."""
        end = time.perf_counter() + limit_s
        while view.frames <= n0 or (until is not None and not until()):
            spin(2)
            if time.perf_counter() > end:
                break
        return time.perf_counter()

    def wait_shown(limit_s: float = 60.0) -> float:
        """Runs the loop until a picture drawn after every change sent so far is painted (one
        of before may be on its way from the render process); its end."""
        serial = view.request_frame()
        end = time.perf_counter() + limit_s
        while view.shown_serial < serial and time.perf_counter() < end:
            spin(2)
        return time.perf_counter()

    while not view.has_material or view.renderer.has_material is False:  # the first program
        spin(50)
    spin(500)
    ticks = Ticks()
    out: dict = {"viewport": list(view.renderer.size),
                 "gl": view.gl_renderer(), "cases": {}}
    r = view.renderer

    def info():  # what the last picture shows (read in the render process as it was drawn)
        return view.frame_info

    if "reference" in only:
        r.set_reference_samples(REFERENCE_SAMPLES)  # before any frame of reference mode
        view.sync()
        spin(200)
        paints: list[float] = []
        view.frameDrawn.connect(lambda: paints.append(view.last_frame_time * 1e3))
        n0, t0 = view.frames, time.perf_counter()
        panel.mode_combo.setCurrentText("Reference")
        t1 = wait_frames(n0, lambda: info().converged, REFERENCE_WINDOW_S)
        gaps = ticks.gaps(t0, t1)
        out["cases"]["reference"] = {
            "ui_block_max_ms": max(gaps, default=0.0), "samples": REFERENCE_SAMPLES,
            "converged": bool(info().converged), "converge_ms": (t1 - t0) * 1e3,
            "frames": info().accumulated_frames, "paints": view.frames - n0,
            "paint_median_ms": statistics.median(paints) if paints else None,
            "longest_gaps_ms": sorted(gaps)[-5:][::-1],
            "gap_p50_ms": _quantile(gaps, 0.5), "gap_p90_ms": _quantile(gaps, 0.9),
            "gap_p99_ms": _quantile(gaps, 0.99),
            "gaps_over_50_ms": sum(1 for g in gaps if g > 50.0)}
        panel.mode_combo.setCurrentText("Split-sum")
        wait_frames(view.frames)
        spin(200)

    if "slider" in only:
        node = w.controller.document.graph.nodes["amount"]
        v0 = float(node.values.get("value", 0.5))
        merge = new_merge_id()
        state = {"i": 0}
        t0 = time.perf_counter()

        def step() -> None:
            i = state["i"] = state["i"] + 1
            value = round(v0 + 0.4 * ((i % 10) / 10.0 - 0.2), 4)
            w.controller.push(SetValue("amount", "value", value, text="bench drag"),
                              merge_id=merge)
            if i < SLIDER_STEPS:
                QTimer.singleShot(16, step)

        step()
        while state["i"] < SLIDER_STEPS:
            spin(5)
        t_last = time.perf_counter()
        t1 = wait_shown()
        out["cases"]["slider"] = {"ui_block_max_ms": ticks.longest(t0, t1),
                                  "edits": SLIDER_STEPS, "drag_ms": (t_last - t0) * 1e3}
        spin(200)

    if "environment" in only:
        runs = []
        for spec in ("sky", "studio", "sky"):
            t0 = time.perf_counter()
            panel.choose_environment(spec)
            t1 = wait_shown()
            runs.append({"environment": spec, "block_ms": ticks.longest(t0, t1),
                         "ms": (t1 - t0) * 1e3})
            spin(200)
        out["cases"]["environment"] = {"ui_block_max_ms": max(x["block_ms"] for x in runs),
                                       "runs": runs}
        panel.choose_environment("studio")
        spin(200)

    if "resize" in only:
        runs = []
        for i in range(RESIZES):
            size = (1400, 900) if i % 2 == 0 else (1600, 1000)
            t0 = time.perf_counter()
            w.resize(*size)
            t1 = wait_shown()
            runs.append({"size": list(size), "block_ms": ticks.longest(t0, t1),
                         "ms": (t1 - t0) * 1e3, "viewport": list(view.renderer.size)})
            spin(200)
        out["cases"]["resize"] = {"ui_block_max_ms": max(x["block_ms"] for x in runs),
                                  "runs": runs}

    w.actions.ask_save_changes = lambda name: "discard"  # tabs left unsaved: not asked
    if "open" in only:
        from matedit.resources import graphs_dir

        runs = []
        for name in OPEN_SAMPLES:
            t0 = time.perf_counter()
            w.open_material(graphs_dir() / "materials" / f"{name}.json")
            t_call = time.perf_counter()
            wait_shown()
            spin(OPEN_SETTLE_MS)
            t1 = time.perf_counter()
            runs.append({"sample": name, "block_ms": ticks.longest(t0, t1),
                         "call_ms": (t_call - t0) * 1e3})
            spin(200)
        out["cases"]["open"] = {"ui_block_max_ms": max(x["block_ms"] for x in runs),
                                "runs": runs}

    if "delete" in only:
        canvas = w.canvas
        graph = w.controller.document.graph  # the last material opened, or the sample
        nodes = len(graph.nodes)
        runs = []
        for step in ("delete", "undo", "duplicate"):
            canvas.select_nodes(sorted(graph.nodes))
            spin(200)
            t0 = time.perf_counter()
            if step == "delete":
                canvas.delete_selection()
            elif step == "undo":
                w.controller.undo_stack.undo()
            else:
                canvas.duplicate_selection()
            wait_shown()
            spin(EDIT_SETTLE_MS)
            t1 = time.perf_counter()
            runs.append({"step": step, "block_ms": ticks.longest(t0, t1),
                         "nodes": len(graph.nodes)})
            spin(200)
        out["cases"]["delete"] = {"ui_block_max_ms": max(x["block_ms"] for x in runs),
                                  "nodes": nodes, "runs": runs}

    ticks.timer.stop()
    return _finish(w, app, display, out)


def measure(warm: bool | None, edits: int, timeout: float = 600) -> dict:
    """One child process with a fresh, empty Mesa shader cache (enabled); warm None: the
    cases child."""
    with tempfile.TemporaryDirectory(prefix="matedit-mesa-cache-") as cache:
        env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="false", MESA_SHADER_CACHE_DIR=cache)
        kind = "cases" if warm is None else "warm" if warm else "cold"
        cmd = [sys.executable, str(Path(__file__).resolve()), "--child", kind,
               "--edits", str(edits)]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env,
                                  cwd=HERE.parent)
        except subprocess.TimeoutExpired:
            return {"error": f"timed out after {timeout:.0f} s"}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        return {"error": (proc.stderr.strip().splitlines() or ["no output"])[-1]}
    return json.loads(lines[-1])


def run(edits: int = 8, cases_only: bool = False) -> dict:
    """Every run (for benchmarks/run_all.py): {"warm": ..., "cold": ..., "cases": ...}."""
    out = {} if cases_only else {"warm": measure(True, edits), "cold": measure(False, edits)}
    out["cases"] = measure(None, edits)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--edits", type=int, default=8)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--cases-only", action="store_true",
                    help="only the cases (reference, slider, environment, resize, open, delete)")
    ap.add_argument("--only", default=",".join(CASES),
                    help="with --child cases: comma-separated cases to run")
    ap.add_argument("--child", choices=("warm", "cold", "cases"))
    args = ap.parse_args(argv)
    if args.child:
        only = tuple(c for c in args.only.split(",") if c in CASES)
        out = cases_child(only) if args.child == "cases" else child(args.child == "warm",
                                                                    args.edits)
        print(json.dumps(out))
        return 0 if "error" not in out else 1
    res = run(args.edits, args.cases_only)
    if args.json:
        print(json.dumps(res))
        return 0
    print(f"UI-thread blocking by a structural edit, sample layered material, {args.edits} edits "
          f"each; Mesa shader cache enabled, fresh temporary MESA_SHADER_CACHE_DIR per run")
    for key, label in (("cold", "no warm-up (before)"), ("warm", "worker warm-up")):
        if key not in res:
            continue
        r = res[key]
        if "error" in r:
            print(f"  {label:22s} error: {r['error']}")
            continue
        print(f"  {label:22s} ui_block max {r['ui_block_max_ms']:6.0f} ms, median "
              f"{r['ui_block_median_ms']:5.0f} | edit->pixels median "
              f"{r['latency_median_ms']:5.0f} ms | link {r['apply_median_ms']:5.0f} ms, "
              f"first paint {r['first_paint_median_ms']:5.0f} ms "
              f"(plain {r['plain_paint_median_ms']:4.0f}) | compile "
              f"{r['compile_median_ms']:4.1f} ms | viewport {r['viewport'][0]}x"
              f"{r['viewport'][1]}, warmed {r['warmed']}, links/edit {r['links_per_edit']}")
    c = res["cases"]
    if "error" in c:
        print(f"  other cases: error: {c['error']}")
        return 0
    print(f"Other cases (no warm-up child), viewport {c['viewport'][0]}x{c['viewport'][1]}:")
    for name, r in c["cases"].items():
        extra = ""
        if name == "reference":
            extra = (f" | {r['samples']} samples/px {'converged' if r['converged'] else 'NOT'}"
                     f" in {r['converge_ms']:.0f} ms, {r['frames']} frames, "
                     f"{r['paints']} paints; tick gaps p50 {r['gap_p50_ms']:.0f}, p90 "
                     f"{r['gap_p90_ms']:.0f}, p99 {r['gap_p99_ms']:.0f} ms, "
                     f"{r['gaps_over_50_ms']} over 50 ms")
        elif name == "slider":
            extra = f" | {r['edits']} edits over {r['drag_ms']:.0f} ms"
        else:
            extra = " | " + ", ".join(f"{x['block_ms']:.0f}" for x in r["runs"]) + " ms"
        print(f"  {name:12s} ui_block max {r['ui_block_max_ms']:6.0f} ms{extra}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
