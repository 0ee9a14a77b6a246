"""The editor's side of the render server (matedit.render.server): a child process that owns
the preview's GL context and renderer, so that no GL call, and no frame, ever runs in the
editor's process (moderngl holds Python's interpreter lock through each of them).

`RenderProcess.post(op, *args)` sends a message and returns a Future of its reply; messages
go out in order from a writer thread (a busy server never blocks the UI thread's send), and a
reader thread resolves the futures and hands frames, progress and the start-up report to the
callbacks, on that thread (the viewport forwards them to the UI thread). `RemoteRenderer`
reads and calls the server's renderer attribute by attribute (tests and tools; each is a round
trip after the messages sent before it). No Qt here.
"""

from __future__ import annotations

import itertools
import queue
import subprocess
import sys
import threading
import weakref
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

from matedit.render.pipe import child_command, encode, end_child, recv, write


class RendererStopped(RuntimeError):
    """The render process is not running (any more): what was sent to it was not done."""


def _nothing(*_args) -> None:
    """A callback not bound yet."""


class RenderProcess:
    """The render server's client (the module docstring). `on_frame(pixels, info, ms)`,
    `on_started(problem, lights)` and `on_ended(problem)` are called on the reader thread."""

    def __init__(self, on_frame: Callable[..., None] | None = None,
                 on_started: Callable[..., None] | None = None,
                 on_ended: Callable[[str], None] | None = None) -> None:
        self.bind(on_frame, on_started, on_ended)
        self._ids = itertools.count(1)
        self._lock = threading.Lock()
        self._futures: dict[int, tuple[Future, Callable[[float], None] | None]] = {}
        self._outbox: queue.Queue = queue.Queue()
        self._held: list[bytes] | None = []  # messages posted before `start`
        self._proc: subprocess.Popen | None = None
        self._closed = False

    def bind(self, on_frame, on_started, on_ended) -> None:
        """The callbacks (before `start`: nothing comes back until the server has its init)."""
        self._on_frame = on_frame or _nothing
        self._on_started = on_started or _nothing
        self._on_ended = on_ended or _nothing

    @property
    def started(self) -> bool:
        return self._proc is not None

    @property
    def alive(self) -> bool:
        return self._proc is not None and self._proc.poll() is None and not self._closed

    def launch(self) -> None:
        """Starts the server process without waiting: it imports and makes its GL context
        while the editor builds its window; `start` then sends what it draws with."""
        if self._proc is not None:
            return
        from matedit.render.server import SERVER_ENV

        # the editor's own module path: what it sends unpickles there
        cmd, env = child_command("matedit.render.server", SERVER_ENV,
                                 [p for p in sys.path if p])
        self._proc = proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                             env=env)
        weakref.finalize(self, end_child, proc)  # a client dropped without stop(): no orphan
        threading.Thread(target=self._write, args=(proc,), daemon=True,
                         name="matedit-render-send").start()
        threading.Thread(target=self._read, args=(proc,), daemon=True,
                         name="matedit-render-receive").start()

    @property
    def initialised(self) -> bool:
        return self._held is None

    def start(self, init: dict) -> None:
        """Sends `init` (matedit.render.server.Server.start), launching the server first if
        it is not running, then the messages posted before."""
        self.launch()
        held, self._held = self._held or [], None
        self._outbox.put(encode(("init", init)))
        for message in held:
            self._outbox.put(message)

    def post(self, op: str, *args, frame: bool = True,
             progress: Callable[[float], None] | None = None) -> Future:
        """Sends (op, args); with `frame`, the server draws a frame after it. The Future has
        the reply (or the server's exception)."""
        future: Future = Future()
        if self._closed or (self._proc is not None and self._proc.poll() is not None):
            future.set_exception(RendererStopped("the renderer is not running"))
            return future
        mid = next(self._ids)
        future.mid = mid  # type: ignore[attr-defined]
        try:  # here, so that what cannot be sent fails its own future, not the pipe
            message = encode((mid, op, args, frame))
        except Exception as exc:  # noqa: BLE001 - pickle raises several kinds
            future.set_exception(RuntimeError(f"cannot send {op} to the renderer: {exc}"))
            return future
        with self._lock:
            self._futures[mid] = (future, progress)
            if self._held is not None:  # before `start`: sent after the init
                self._held.append(message)
                return future
        self._outbox.put(message)
        return future

    def call(self, op: str, *args, timeout: float | None = 300.0) -> Any:
        """post(...) without a frame, waited for (its exception raised here)."""
        return self.post(op, *args, frame=False).result(timeout)

    def sync(self, timeout: float | None = 300.0) -> None:
        """Waits until the server has served every message sent so far."""
        if self.alive:
            self.call("get", "", timeout=timeout)

    def stop(self) -> None:
        """Ends the server (its stdin closes; it releases its context and exits)."""
        self._closed = True
        self._outbox.put(None)

    # --- the threads ------------------------------------------------------------------------
    def _write(self, proc: subprocess.Popen) -> None:
        while True:
            message = self._outbox.get()
            try:
                if message is None:
                    proc.stdin.close()
                    return
                write(proc.stdin, message)
            except (OSError, ValueError):  # the server has gone: the reader says so
                return

    def _read(self, proc: subprocess.Popen) -> None:
        why = ""
        while True:
            try:
                message = recv(proc.stdout)
            except (EOFError, OSError):
                break
            except Exception as exc:  # noqa: BLE001 - a garbled reply: end, and say so
                why = f"{type(exc).__name__}: {exc}"
                break
            kind = message[0]
            if kind == "frame":
                self._on_frame(*message[1:])
            elif kind == "done":
                _, mid, ok, value = message
                with self._lock:
                    future, _progress = self._futures.pop(mid, (None, None))
                if future is not None:
                    if ok:
                        future.set_result(value)
                    else:
                        future.set_exception(value)
            elif kind == "progress":
                with self._lock:
                    _future, progress = self._futures.get(message[1], (None, None))
                if progress is not None:
                    progress(message[2])
            elif kind == "started":
                self._on_started(message[1], message[2])
        with self._lock:
            futures, self._futures = list(self._futures.values()), {}
        for future, _progress in futures:
            future.set_exception(RendererStopped("the renderer has stopped"))
        try:
            code = proc.wait(timeout=10)  # reaped: no zombie left behind
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait()
        if not self._closed:
            self._closed = True
            self._on_ended(why or f"the render process ended (exit status {code})")


_SPARE: RenderProcess | None = None


def prelaunch() -> None:
    """Starts a render process now, before the editor imports Qt and builds its window, for
    the first viewport to take (`take_prelaunched`): its imports and GL context overlap the
    editor's own start-up."""
    global _SPARE
    if _SPARE is None:
        spare = RenderProcess()
        try:
            spare.launch()
        except OSError:  # the viewport starts its own, and says why if that fails too
            return
        _SPARE = spare


def take_prelaunched() -> RenderProcess | None:
    """The process `prelaunch` started (once), or None."""
    global _SPARE
    spare, _SPARE = _SPARE, None
    return spare if spare is not None and spare.alive else None


class RemoteRenderer:
    """The server's renderer (or an object within it) read and called from the editor: data
    attributes come back as values, objects as another RemoteRenderer, calls run there."""

    def __init__(self, process: RenderProcess, path: str = "") -> None:
        object.__setattr__(self, "_process", process)
        object.__setattr__(self, "_path", path)

    def _at(self, name: str) -> str:
        return f"{self._path}.{name}" if self._path else name

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return self._wrap(self._process.call("get", self._at(name)))

    def __setattr__(self, name: str, value: Any) -> None:
        self._process.call("set", self._at(name), value)

    def __call__(self, *args, **kwargs) -> Any:
        return self._wrap(self._process.call("call", self._path, args, kwargs))

    def _wrap(self, value: Any) -> Any:
        from matedit.render.server import Remote

        return RemoteRenderer(self._process, value.path) if isinstance(value, Remote) else value
