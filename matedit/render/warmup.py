"""Warming the viewport's programs in a helper process, so the UI thread's link is cheap.

On llvmpipe most of a structural edit's cost is not our compile but the driver's: the GLSL
link, and above all the JIT of the fragment shader's variant at its first draw. Mesa's shader
cache (per user, ~/.cache/mesa_shader_cache unless MESA_SHADER_CACHE_DIR says otherwise) hands
both between GL contexts, EGL or GLX, and processes (it is on disk). So one that links and draws
the new program once,
in its own headless context, into a small target set up like the viewport's (the same
framebuffer formats and sample count, the same texture formats and sampler state, the same entry
variant and lighting pass), leaves the UI thread's link and first draw about one plain frame.
With the cache disabled (MESA_SHADER_CACHE_DISABLE=true) a warm-up would only delay the edit, so
the editor does none (`shader_cache_enabled`) and the UI thread pays what it paid before.

The warm-up runs in a child process (`WarmupClient`, serving `python -m matedit.render.warmup`),
not on a thread of the editor's: moderngl holds Python's GIL through every GL call, and the link
and first draw of a material are single calls of 100-900 ms on llvmpipe, during which a thread of
the editor would stop the UI thread too (measured: benchmarks/bench_ui_block.py). Mesa's cache is
on disk, so a child writes what the editor reads. The child gets the same environment (the same
MESA_SHADER_CACHE_DIR, or the per-user default) and ends when the editor closes its pipe.

moderngl only, no Qt. One `Warmer` per thread: its context is current on the thread that made it.
"""

from __future__ import annotations

import os
import select
import subprocess
import sys
import threading
import time
import weakref
from dataclasses import dataclass, field

from matedit.render.pipe import child_command, end_child
from matedit.render.pipe import recv as _recv
from matedit.render.pipe import send as _send

# Small: the variant key of llvmpipe's fragment shaders does not depend on the target's size
# (measured: warmed at 16², 64² or the viewport's own size, the viewport's first draw of
# rusty_painted_metal cost one plain frame each time; benchmarks/bench_ui_block.py at 64²).
WARM_SIZE = (64, 64)


@dataclass(frozen=True)
class ViewportState:
    """What of the viewport decides which programs it draws and the driver's variants of them
    (the UI thread takes it when it submits an edit; the worker reads only this record)."""

    samples: int = 4
    deferred: bool = True
    environment: str = "studio"
    mode: str = "splitsum"
    mesh: str = "sphere"
    energy_compensation: bool = False
    show_background: bool = True
    textures: dict = field(default_factory=dict)  # texture name -> file (None: the checker)


class Warmer:
    """A headless context and a small Renderer like the viewport's, made on first use on the
    calling thread and kept for the next edits (its environment, mesh, lighting pass and
    textures stay loaded: a warm-up after the first links and draws only the new program)."""

    def __init__(self, size: tuple[int, int] = WARM_SIZE) -> None:
        self.size = size
        self.ctx = None
        self.renderer = None
        self.thread: threading.Thread | None = None
        self._key: tuple | None = None
        self.count = 0  # warm-ups done (tests)
        self.last_program = ""  # the structure hash of the variant drawn last

    def _renderer_for(self, state: ViewportState):
        from matedit.render.context import headless_context
        from matedit.render.renderer import Renderer

        if self.thread is not None and self.thread is not threading.current_thread():
            raise RuntimeError("a Warmer must be used on the thread that made it")
        key = (state.samples, state.deferred)
        if self.renderer is None or self._key != key:
            self.release()
            self.thread = threading.current_thread()
            self.ctx = headless_context()
            self.renderer = Renderer(self.ctx, self.size, samples=state.samples,
                                     environment=state.environment, deferred=state.deferred)
            self._key = key
        r = self.renderer
        if getattr(r, "environment_name", None) != str(state.environment):
            r.set_environment(state.environment)
        if r.mesh_name != str(state.mesh):
            r.set_mesh(state.mesh)
        r.mode = state.mode
        r.show_background = state.show_background
        r.set_energy_compensation(state.energy_compensation)
        return r

    def warm(self, compiled, state: ViewportState) -> bool:
        """Links and draws `compiled` once as the viewport will; False when it does not link
        (the viewport reports that itself, with the located errors)."""
        r = self._renderer_for(state)
        if not r.set_material(compiled).ok:
            return False
        for name, path in state.textures.items():
            try:
                r.set_texture(name, str(path) if path else None)
            except ValueError:
                pass  # the viewport shows the message; a checker stands in here
        r.render()
        self.ctx.finish()
        self.count += 1
        self.last_program = next((h for h, p in r.programs.table.items() if p is r._program), "")
        return True

    def release(self) -> None:
        """Frees the context; call it on the thread that made it (or at process exit)."""
        if self.renderer is not None:
            self.renderer.release()
            self.renderer = None
        if self.ctx is not None:
            self.ctx.release()
            self.ctx = None
        self._key = None


@dataclass
class WarmReply:
    ok: bool  # linked and drawn
    ms: float = 0.0  # the warm-up's time in the child
    pid: int = 0  # the process that did it
    program: str = ""  # the structure hash of the variant drawn ("" when none)
    error: str = ""
    starting: bool = False  # not tried: the child is not ready yet (or would not start)


def shader_cache_enabled() -> bool:
    """Whether Mesa's shader cache is on for processes started now (MESA_SHADER_CACHE_DISABLE
    as Mesa reads it). Without it a warm-up helps nothing and only delays the edit (measured:
    benchmarks/bench_ui_block.py), so the editor does none."""
    value = os.environ.get("MESA_SHADER_CACHE_DISABLE", "").strip().lower()
    return value not in ("1", "true", "y", "yes")


SERVER_ENV = "MATEDIT_WARMUP_SERVER"  # set for a frozen bundle's child: serve, not the CLI
MAX_STARTS = 5


class WarmupClient:
    """The editor's side. `start()` starts the child without waiting; it makes its context and
    renderer and says it is ready (seconds: imports, the environment from the bake cache).
    `warm()` asks it to warm one material (from one thread, the compile worker's; waiting on
    the pipe releases the GIL); until the child is ready it returns at once, unwarmed, so the
    first edits after opening are not held back by the child's start-up. Any failure (no GL
    in the child, a crash, a time-out) loses only that warm-up; the child is started again."""

    def __init__(self, timeout_s: float = 30.0) -> None:
        self.timeout_s = timeout_s
        self._proc: subprocess.Popen | None = None
        self._ready = False
        self._lock = threading.Lock()
        self.starts = 0  # children started (a crashed one is replaced, up to MAX_STARTS)

    def _start(self) -> subprocess.Popen:
        cmd, env = child_command("matedit.render.warmup", SERVER_ENV)
        self.starts += 1
        proc = subprocess.Popen(cmd,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env,
                                stderr=subprocess.DEVNULL)
        weakref.finalize(self, end_child, proc, 2.0)  # a client dropped without close()
        return proc

    def _ensure(self) -> subprocess.Popen | None:
        """The running child, started if need be; None once it has failed to start
        MAX_STARTS times (no GL for it, say): warm-ups are off for this client then."""
        if self._proc is None or self._proc.poll() is not None:
            if self.starts >= MAX_STARTS:
                return None
            self._proc = self._start()
            self._ready = False
        return self._proc

    def start(self) -> None:
        """Starts the child (if it does not run) and returns at once."""
        with self._lock:
            self._ensure()

    def _check_ready(self, timeout: float) -> bool:
        if self._ready:
            return True
        proc = self._proc
        if proc is None or proc.poll() is not None:
            return False
        readable, _, _ = select.select([proc.stdout], [], [], max(0.0, timeout))
        if not readable:
            return False
        try:
            _recv(proc.stdout)  # the child's ("ready", pid)
        except Exception:  # noqa: BLE001 - it died while starting
            self._stop(proc)
            return False
        self._ready = True
        return True

    def wait_ready(self, timeout: float = 0.0) -> bool:
        """Whether the child is ready, waiting up to `timeout` s (tests; start() first)."""
        if self._ready:
            return True
        with self._lock:
            return self._check_ready(timeout)

    def warm(self, compiled, state: ViewportState) -> WarmReply:
        with self._lock:
            proc = self._ensure()
            if proc is None:
                return WarmReply(False, error="the warm-up process failed to start",
                                 starting=True)
            if not self._check_ready(0.0):
                return WarmReply(False, error="the warm-up process is starting",
                                 starting=True)
            timer = threading.Timer(self.timeout_s, proc.kill)  # a hung driver: start over
            timer.start()
            try:
                _send(proc.stdin, (compiled, state))
                reply = _recv(proc.stdout)
            except Exception as exc:  # noqa: BLE001 - a broken pipe, a bad pickle: start over
                self._stop(proc)
                return WarmReply(False, error=f"{type(exc).__name__}: {exc}")
            finally:
                timer.cancel()
            return reply

    @property
    def pid(self) -> int | None:
        return self._proc.pid if self._proc is not None and self._proc.poll() is None else None

    def _stop(self, proc) -> None:
        try:
            proc.stdin.close()
        except OSError:
            pass
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        if self._proc is proc:
            self._proc = None
            self._ready = False

    def close(self) -> None:
        """Ends the child (it also ends by itself when the editor's process goes)."""
        with self._lock:
            if self._proc is not None:
                self._stop(self._proc)


def serve(inp, out) -> None:
    """The child's loop: ("ready", pid) out once its renderer is up (for the default
    ViewportState), then (compiled, state) in, WarmReply out, until the pipe closes."""
    warmer = Warmer()
    try:
        warmer._renderer_for(ViewportState())
    except Exception:  # noqa: BLE001 - reported at the first warm-up instead
        pass
    _send(out, ("ready", os.getpid()))
    while True:
        try:
            compiled, state = _recv(inp)
        except EOFError:
            break
        t0 = time.perf_counter()
        try:
            ok = warmer.warm(compiled, state)
            reply = WarmReply(ok, (time.perf_counter() - t0) * 1e3, os.getpid(),
                              warmer.last_program if ok else "")
        except Exception as exc:  # noqa: BLE001 - reported to the editor, which carries on
            reply = WarmReply(False, (time.perf_counter() - t0) * 1e3, os.getpid(),
                              error=f"{type(exc).__name__}: {exc}")
        _send(out, reply)
    warmer.release()


def serve_stdio() -> int:
    """The child's entry: the pipe is its stdin and stdout (print goes to stderr)."""
    inp, out = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # the pipe carries only replies
    serve(inp, out)
    return 0


if __name__ == "__main__":
    from matedit.render import warmup as _module  # replies pickle as matedit.render.warmup's

    sys.exit(_module.serve_stdio())
