"""The editor's preview renderer in a process of its own: `python -m matedit.render.server`.

On llvmpipe a frame of the default view takes 100-350 ms and a program's first draw longer,
and moderngl holds Python's interpreter lock through every GL call: drawn in the editor's
process, on its UI thread or on any other thread, each frame froze the UI for as long (measured
by benchmarks/bench_ui_block.py: combo popups opened seconds after the click during reference
accumulation). So the viewport (matedit.app.viewport, through matedit.app.render_client)
sends what changes to this process and paints the pictures it sends back.

The protocol, over stdin and stdout (matedit.render.pipe):
- in: ("init", settings dict) first, then (id, op, args, frame): `op` one of OPS, run in
  order; `frame` asks for a frame after it;
- out: ("started", problem, lights) once the renderer is up (problem "" when it is), then
  ("done", id, ok, value or exception) for every message, ("progress", id, fraction) while an
  environment bakes, and ("frame", pixels, FrameInfo, ms) for every picture: (H, W, 4) uint8
  sRGB, top row first.

After the messages that have arrived it draws a frame when one was asked for; reference and
difference mode accumulate in bands of `budget_ms` (Renderer.advance), reading the messages
between bands, and send their picture when a frame is complete or DISPLAY_INTERVAL_S after the
last one. Once it has been idle FORWARD_WHEN_IDLE_S (the init's "forward_when_idle_s"; None:
never) with a material on the deferred path, it draws that material forward from then on
(Renderer.promote_forward: a frame in about half the time, for the program's link and JIT
once); the next structural edit draws deferred again. The process ends when its stdin closes.
No Qt here.
"""

from __future__ import annotations

import itertools
import pickle
import queue
import sys
import threading
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from matedit.render.pipe import recv, send

DISPLAY_INTERVAL_S = 0.25  # reference accumulation sends its progress this often
BUDGET_MS = 40.0  # GL work between two looks at the messages while accumulating
# Idle time before a deferred material is drawn forward (the viewport's; its link and JIT
# then hold the server for a few hundred ms, so not while an artist is still at work)
FORWARD_WHEN_IDLE_S = 1.0
KEPT = 64  # objects returned by calls that the server keeps for the editor to read
SERVER_ENV = "MATEDIT_RENDER_SERVER"  # set for a frozen bundle's child: serve, not the CLI


@dataclass(frozen=True)
class FrameInfo:
    """What the editor shows beside a picture, read when it was drawn."""

    mode: str
    accumulated_frames: int
    reference_frames: int
    reference_samples: int
    converged: bool
    difference_mean: float | None
    has_material: bool
    environment_name: str
    size: tuple[int, int]
    serial: int  # the last message served before the frame was drawn: it shows all up to it


@dataclass(frozen=True)
class Remote:
    """A reply to `get` whose value stays in the server (an object, not data): its path."""

    path: str
    type_name: str


_PLAIN = (type(None), bool, int, float, str, bytes, np.ndarray, np.generic)


def _plain(value: Any) -> bool:
    """Whether `value` is data to send back (numbers, text, arrays, records and containers of
    them), not an object of the server's (a program, a GL resource)."""
    if isinstance(value, _PLAIN):
        return True
    if isinstance(value, (list, tuple)):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(_plain(k) and _plain(v) for k, v in value.items())
    fields = getattr(type(value), "__dataclass_fields__", None)
    return fields is not None and all(_plain(getattr(value, f)) for f in fields)


def _resolve(s: Server, path: str) -> Any:
    """The renderer's attribute at a dotted path; a path that starts with `@N.` starts from
    the object a call returned (kept by `_keep`)."""
    head, _, rest = path.partition(".")
    if head.startswith("@"):
        obj, path = s.kept[int(head[1:])], rest
    else:
        obj = s.r
    for part in filter(None, path.split(".")):
        obj = getattr(obj, part)
    return obj


def _keep(s: Server, value: Any, path: str) -> Any:
    """`value` if it is data, else a Remote naming it (an object a call returned is kept, the
    last KEPT of them, so that the editor can read it further)."""
    if _plain(value):
        return value
    if not path.startswith("@") and "(" not in path:
        return Remote(path, type(value).__name__)
    key = next(s.keys)
    s.kept[key] = value
    while len(s.kept) > KEPT:
        s.kept.pop(next(iter(s.kept)))
    return Remote(f"@{key}", type(value).__name__)


def apply_settings(r, intensity: float, background: bool, blur: float, energy: bool) -> None:
    """The viewport's render settings (matedit.app.viewport.RenderSettings) on a renderer."""
    r.environment_intensity = float(intensity)
    r.show_background = bool(background)
    r.background_blur = float(blur)
    r.set_energy_compensation(bool(energy))


class Server:
    """One renderer and the loop that serves it (the module docstring)."""

    def __init__(self, out) -> None:
        self.out = out
        self.inbox: queue.Queue = queue.Queue()
        self.ctx: Any = None
        self.r: Any = None
        self.budget_ms = BUDGET_MS
        self._fbo: Any = None
        self._dirty = False
        self._last_shown = 0.0
        self.forward_when_idle_s: float | None = None  # init's "forward_when_idle_s"
        self._message_id = 0  # the message being served (its progress replies name it)
        self.kept: dict[int, Any] = {}  # objects calls returned, read further by the editor
        self.keys = itertools.count(1)

    # --- messages ---------------------------------------------------------------------------
    def _read(self, inp) -> None:
        """The reader thread: messages into the inbox; None when the pipe closes."""
        while True:
            try:
                self.inbox.put(recv(inp))
            except (EOFError, OSError, pickle.UnpicklingError):
                self.inbox.put(None)
                return

    def _reply(self, message: tuple) -> None:
        try:
            send(self.out, message)
        except (pickle.PicklingError, TypeError, AttributeError) as exc:  # nothing was written
            send(self.out, ("done", message[1], False,
                            RuntimeError(f"cannot send the reply: {exc}")))

    def prepare(self) -> None:
        """What needs no word from the editor, done while it builds its window: the imports
        and the GL context."""
        from matedit.render.context import headless_context
        from matedit.render.renderer import Renderer  # noqa: F401 - imported now, used at start

        self.ctx = headless_context()

    def start(self, init: dict) -> None:
        from matedit.render.renderer import Renderer

        self.budget_ms = float(init.get("budget_ms") or BUDGET_MS)
        idle = init.get("forward_when_idle_s")
        self.forward_when_idle_s = None if idle is None else max(0.0, float(idle))
        if self.ctx is None:
            self.prepare()
        r = Renderer(self.ctx, size=tuple(init["size"]), samples=4, environment=None,
                     warm_up=bool(init.get("warm_up", True)))
        r.set_mesh(init.get("mesh", "sphere"))
        r.mode = init.get("mode", "splitsum")
        r.exposure = float(init.get("exposure", 0.0))
        r.set_view(init.get("view", "lit"))
        apply_settings(r, *init.get("settings", (1.0, True, 0.0, False)))
        if init.get("lights") is not None:
            r.set_lights(list(init["lights"]))
        self.r = r
        self._dirty = True

    def serve(self, inp) -> None:
        threading.Thread(target=self._read, args=(inp,), daemon=True).start()
        try:
            self.prepare()
        except Exception:  # noqa: BLE001, S110 - tried again, and reported, at start
            self.ctx = None
        init = self.inbox.get()
        if init is None:
            return
        try:
            self.start(init[1])
        except Exception as exc:  # noqa: BLE001 - said in the viewport, the editor goes on
            send(self.out, ("started", f"renderer failed to start: {type(exc).__name__}: "
                                       f"{exc}", None))
            return
        send(self.out, ("started", "", list(self.r.lights)))
        while True:
            busy = self._dirty or bool(self.r.needs_redraw)
            idle = None if busy or not self.r.can_promote else self.forward_when_idle_s
            try:
                message = self.inbox.get_nowait() if busy else self.inbox.get(timeout=idle)
            except queue.Empty:
                if not busy:  # idle long enough: the material forward, and its frame
                    self._dirty = self.r.promote_forward()
                    continue
                message = ()
            if message is None:
                return
            if message:
                self._serve(message)
                continue  # every message that has come before the next frame
            self._draw(full=self._dirty)

    def _serve(self, message: tuple) -> None:
        mid, op, args, frame = message
        self._message_id = mid
        try:
            value = OPS[op](self, *args)
        except Exception as exc:  # noqa: BLE001 - the editor reads it from its future
            try:
                pickle.dumps(exc)
            except Exception:  # noqa: BLE001 - an exception that does not pickle: its text
                exc = RuntimeError(f"{type(exc).__name__}: {exc}")
            self._reply(("done", mid, False, exc))
        else:
            self._reply(("done", mid, True, value))
        self._dirty = self._dirty or bool(frame)

    # --- drawing ----------------------------------------------------------------------------
    def _target(self) -> Any:
        size = tuple(self.r.size)
        if self._fbo is None or tuple(self._fbo.size) != size:
            if self._fbo is not None:
                self._fbo.release()
            self._fbo = self.ctx.simple_framebuffer(size, components=4)
        return self._fbo

    def _draw(self, full: bool) -> None:
        """A frame after a change (`full`), or the next bands of an accumulation, sent when a
        reference frame is complete or DISPLAY_INTERVAL_S after the last picture."""
        r = self.r
        self._dirty = False
        t0 = time.perf_counter()
        target = self._target()
        r.slice_budget_ms = self.budget_ms
        if full or r.mode == "splitsum":
            r.render(target)
        else:
            frames = r.accumulated_frames
            bands = r.advance()
            if bands and r.accumulated_frames == frames and r.needs_redraw and \
                    time.perf_counter() - self._last_shown < DISPLAY_INTERVAL_S:
                return
            r.display(target)
        data = target.read(components=4)
        w, h = target.size
        pixels = np.frombuffer(data, np.uint8).reshape(h, w, 4)[::-1]
        converged = bool(r.converged)
        mean = r.difference_mean if r.mode == "difference" and converged else None
        info = FrameInfo(r.mode, int(r.accumulated_frames), int(r.reference_frames),
                         int(r.reference_samples), converged,
                         None if mean is None else float(mean), bool(r.has_material),
                         str(r.environment_name), (w, h), self._message_id)
        self._last_shown = time.perf_counter()
        send(self.out, ("frame", np.ascontiguousarray(pixels), info,
                        (self._last_shown - t0) * 1e3))

    def release(self) -> None:
        if self._fbo is not None:
            self._fbo.release()
        if self.r is not None:
            self.r.release()
        if self.ctx is not None:
            self.ctx.release()


# --- the operations a message names: op(server, *args) -> a reply value ----------------------
def _call(s: Server, path: str, args: tuple = (), kwargs: dict | None = None) -> Any:
    value = _resolve(s, path)(*args, **(kwargs or {}))
    return None if value is None else _keep(s, value, path + "()")


def _get(s: Server, path: str) -> Any:
    return _keep(s, _resolve(s, path), path)


def _set(s: Server, path: str, value: Any) -> None:
    head, _, name = path.rpartition(".")
    setattr(_resolve(s, head), name, value)


def _values(s: Server, uniforms: dict | None, textures: dict) -> list[str]:
    """Uniform values and texture files; the texture problems, said by the editor."""
    problems = []
    if uniforms is not None:
        s.r.set_uniforms(uniforms)
    for name, path in textures.items():
        try:
            s.r.set_texture(name, str(path) if path else None)
        except ValueError as exc:
            problems.append(str(exc))
    return problems


def _settings(s: Server, *settings) -> None:
    apply_settings(s.r, *settings)
    s.r.reset_accumulation()


def _compare(s: Server, compiled, uniforms=None, textures=None):
    if compiled is None:
        return s.r.set_compare(None)
    return s.r.set_compare(compiled, uniforms or {},
                           {k: str(v) if v else None for k, v in (textures or {}).items()})


def _environment(s: Server, spec: str, progress: bool = False) -> list[str]:
    mid = s._message_id
    report = (lambda f: send(s.out, ("progress", mid, float(f)))) if progress else None
    s.r.set_environment(spec, progress=report)
    return list(s.r.environment_warnings)


def _offscreen(s: Server, width: int, height: int):
    """(display image, scene-linear radiance) of the view at width x height, converged."""
    r = s.r
    size, budget = r.size, r.slice_budget_ms
    try:
        r.resize(int(width), int(height))
        r.slice_budget_ms = None
        r.reset_accumulation()
        r.render_converged()
        return r.read_image(), r.read_hdr()
    finally:
        r.slice_budget_ms = budget
        r.resize(*size)
        r.reset_accumulation()


def _info(s: Server) -> str:
    info = s.ctx.info
    return f"{info.get('GL_RENDERER', '?')} ({info.get('GL_VERSION', '?')})"


OPS = {"call": _call, "get": _get, "set": _set, "values": _values, "settings": _settings,
       "compare": _compare, "environment": _environment, "offscreen": _offscreen,
       "info": _info}


def serve_stdio() -> int:
    """The child's entry: the pipe is its stdin and stdout (print goes to stderr)."""
    inp, out = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # the pipe carries only replies
    server = Server(out)
    try:
        server.serve(inp)
    except (BrokenPipeError, EOFError):  # the editor has gone
        pass
    finally:
        try:
            server.release()
        except Exception:  # noqa: BLE001, S110 - the process ends anyway
            pass
    return 0


if __name__ == "__main__":
    from matedit.render import server as _module  # replies pickle as matedit.render.server's

    sys.exit(_module.serve_stdio())
