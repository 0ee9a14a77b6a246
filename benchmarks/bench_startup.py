"""Start-up: `matedit validate FILE` as a subprocess, and the editor from launch to its first
viewport frame under Xvfb.

Run: .venv/bin/python benchmarks/bench_startup.py

The editor offers no exit-after-first-frame hook, so the editor side is measured by a driver:
this file, run as a child (`--editor-child`), does what `matedit.app.app.run()` does
(make_application, compiles off the UI thread, MainWindow on the built-in sample, show, exec)
and connects the viewport's `frameDrawn` signal; it prints the CLOCK_MONOTONIC time of the
first frame, of the first frame drawn with the material's program (the start-up figure), and
of the first frame with the environment's image-based lighting (the editor bakes or loads
it once its first frame is on screen), then quits. The parent reads the clock just before it
starts the child, so the figure covers interpreter start, imports, window construction, GL
and renderer start-up, compile, link, JIT and the first draw.
One Xvfb server (xvfb-run) hosts all launches so that its own start-up is not counted.
Python's bytecode cache is on for them, in one fresh folder (PYTHONPYCACHEPREFIX; a
PYTHONDONTWRITEBYTECODE of the environment is dropped). Three kinds of launch, in this order:
- cold (the start-up goal's): a fresh HOME (settings, recovery files, IBL cache), a fresh
  empty Mesa shader cache (MESA_SHADER_CACHE_DIR; MESA_SHADER_CACHE_DISABLE is dropped) and
  the empty bytecode folder: the studio environment is baked, every shader compiled, and
  Python compiles every module it imports, the standard library's and numpy's included
  (their installed bytecode is not under the prefix);
- cold with installed bytecode (for comparison): another fresh HOME and Mesa shader cache,
  the bytecode written by the launch before, as on a user's machine, where matedit, Python
  and numpy come with their bytecode (a wheel or the .deb compiles it at install, the bundle
  carries it);
- warm: that second HOME again, every cache filled.
`matedit validate` is timed with the bytecode folder too, its warm-up run writing it.
"""

from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve()
ROOT = HERE.parent.parent


def matedit_command() -> list[str]:
    script = Path(sys.executable).parent / "matedit"
    return [str(script)] if script.exists() else [sys.executable, "-m", "matedit"]


def bytecode_env(env: dict, folder: Path) -> dict:
    """`env` with Python's bytecode cache on, in `folder` (PYTHONPYCACHEPREFIX): as on a
    user's machine, where an installed matedit has its bytecode (a wheel or the .deb compiles
    it at install, the bundle carries it), and a source checkout writes it at its first run.
    A development environment that sets PYTHONDONTWRITEBYTECODE would otherwise measure
    Python compiling every module it imports, on every launch."""
    env = dict(env)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = str(folder)
    return env


def validate_times(path: Path, repeat: int = 5) -> dict:
    """Median wall time of `matedit validate path` (one unmeasured warm-up run first, which
    also writes the bytecode cache: bytecode_env)."""
    cmd = [*matedit_command(), "validate", str(path)]
    with tempfile.TemporaryDirectory(prefix="matedit-bench-pycache-") as cache:
        env = bytecode_env(dict(os.environ), Path(cache))
        subprocess.run(cmd, check=True, capture_output=True, env=env)
        times = []
        for _ in range(repeat):
            t = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True, env=env)
            times.append(time.perf_counter() - t)
    return {"median": statistics.median(times), "all": times, "command": " ".join(cmd)}


IMPORTS_OF_INTEREST = ("matedit.commands", "matedit.commands.validate",
                       "matedit.commands.compile", "matedit.commands.render",
                       "matedit.commands.bake_ibl", "matedit.commands.brdf_lut",
                       "matedit.graph.validate", "networkx", "numpy", "jsonschema", "moderngl")


def import_breakdown(path: Path) -> dict:
    """One `python -X importtime -m matedit validate path`: the cumulative import time (ms)
    of the top-level imports, and of a few packages wherever they are first imported."""
    cmd = [sys.executable, "-X", "importtime", "-m", "matedit", "validate", str(path)]
    t = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    top, named = 0.0, {}
    for line in proc.stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        _, cumulative, name = line.split("|")
        if not cumulative.strip().isdigit():
            continue
        us = int(cumulative)
        module = name.strip()
        if not name[1:].startswith(" "):  # indentation 0: a top-level import
            top += us
        if module in IMPORTS_OF_INTEREST and module not in named:
            named[module] = us / 1000
    return {"wall_ms": wall * 1000, "imports_ms": top / 1000, "named_ms": named}


def editor_available() -> bool:
    app = ROOT / "matedit" / "app" / "app.py"
    return app.exists() and "def run(" in app.read_text()


# -- the child: the editor with a first-frame probe ---------------------------------------------


def editor_child(timeout_s: float = 90.0) -> int:
    from PySide6.QtCore import QTimer

    from matedit.app.render_client import prelaunch

    prelaunch()  # as `matedit` does before it imports the editor
    from matedit.app.app import make_application
    from matedit.app.compile_service import MaterialCompiler
    from matedit.app.main_window import MainWindow

    app = make_application()
    MaterialCompiler.asynchronous = True  # as run() has it
    window = MainWindow(None)
    view = window.viewport.view
    marks: dict[str, float] = {}

    def on_frame() -> None:
        now = time.monotonic()
        marks.setdefault("first_frame", now)
        info = view.frame_info  # what the picture painted shows, read as it was drawn
        if info is not None and info.has_material:
            marks.setdefault("material_frame", now)
            if info.environment_name and "environment_frame" not in marks:
                marks["environment_frame"] = now
                QTimer.singleShot(0, app.quit)  # not from inside the paint

    view.frameDrawn.connect(on_frame)
    QTimer.singleShot(int(timeout_s * 1000), app.quit)
    marks["show"] = time.monotonic()  # the window is built; show() may paint at once
    window.show()
    if "environment_frame" not in marks:
        app.exec()
    marks["problem"] = view.problem  # type: ignore[assignment]
    print("STARTUP " + json.dumps(marks), flush=True)
    return 0


# -- the launcher (runs under xvfb-run) ---------------------------------------------------------


def _home_env(home: Path, pycache: Path) -> dict:
    """The launch environment of one HOME: its settings, caches and Mesa shader cache."""
    env = dict(os.environ, HOME=str(home), XDG_CONFIG_HOME=str(home / ".config"),
               XDG_DATA_HOME=str(home / ".local/share"), XDG_CACHE_HOME=str(home / ".cache"))
    env.pop("MATEDIT_CACHE_DIR", None)
    env.pop("MESA_SHADER_CACHE_DISABLE", None)  # warm launches have their shaders cached
    env["MESA_SHADER_CACHE_DIR"] = str(home / "mesa-shader-cache")
    return bytecode_env(env, pycache)


def launch_editor(repeat: int) -> int:
    """Starts the editor child `repeat + 2` times: cold (every cache empty, bytecode too),
    cold with the bytecode the first wrote (a fresh HOME and Mesa shader cache), then
    `repeat` warm ones in the second launch's HOME."""
    tmp = Path(tempfile.mkdtemp(prefix="matedit-bench-home-"))
    pycache = tmp / "pycache"
    cold_env = _home_env(tmp / "cold", pycache)
    env = _home_env(tmp / "home", pycache)
    runs = []
    try:
        for i in range(repeat + 2):
            t0 = time.monotonic()
            proc = subprocess.run([sys.executable, str(HERE), "--editor-child"],
                                  env=cold_env if i == 0 else env,
                                  capture_output=True, text=True, timeout=180, cwd=ROOT)
            line = next((x for x in proc.stdout.splitlines() if x.startswith("STARTUP ")), None)
            if line is None:
                runs.append({"error": (proc.stderr or proc.stdout).strip()[-800:]})
                continue
            marks = json.loads(line[len("STARTUP "):])
            runs.append({k: (v - t0 if isinstance(v, float) else v) for k, v in marks.items()})
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("EDITOR " + json.dumps(runs), flush=True)
    return 0


def editor_times(repeat: int = 3) -> dict:
    """Launch → first viewport frame with the material, under one xvfb-run server."""
    if not editor_available():
        return {"skipped": "matedit/app/app.py with run() not found"}
    xvfb = shutil.which("xvfb-run")
    if xvfb is None and not os.environ.get("DISPLAY"):
        return {"skipped": "xvfb-run not found (apt-get install xvfb)"}
    cmd = [sys.executable, str(HERE), "--launch-editor", str(repeat)]
    if xvfb and not os.environ.get("DISPLAY"):
        cmd = [xvfb, "-a", "-s", "-screen 0 1920x1080x24", *cmd]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, cwd=ROOT)
    line = next((x for x in proc.stdout.splitlines() if x.startswith("EDITOR ")), None)
    if line is None:
        return {"skipped": "editor launcher failed: " + (proc.stderr or proc.stdout)[-800:]}
    runs = json.loads(line[len("EDITOR "):])
    cold, installed, warm = runs[0], runs[1], runs[2:]
    ok = [r for r in warm if "material_frame" in r]
    result = {"cold": cold, "cold_installed": installed, "warm": warm, "runs": len(warm)}
    if ok:
        result["material_frame"] = statistics.median(r["material_frame"] for r in ok)
        result["first_frame"] = statistics.median(r["first_frame"] for r in ok)
        result["show"] = statistics.median(r["show"] for r in ok)
        env = [r["environment_frame"] for r in ok if "environment_frame" in r]
        if env:
            result["environment_frame"] = statistics.median(env)
    return result


def main(argv: list[str]) -> int:
    if argv[:1] == ["--editor-child"]:
        return editor_child()
    if argv[:1] == ["--launch-editor"]:
        return launch_editor(int(argv[1]))
    from matedit.resources import graphs_dir

    v = validate_times(graphs_dir() / "materials" / "worn_painted_steel.json")
    print(f"matedit validate worn_painted_steel.json: {v['median'] * 1000:.0f} ms (median of 5)")
    e = editor_times()
    print(json.dumps(e, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
