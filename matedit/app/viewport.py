"""The 3D preview: a widget showing the pictures `matedit.render.Renderer` draws in a process
of its own (matedit.render.server, through matedit.app.render_client), so that the UI thread
never waits for the GL.

The render process starts when the widget is first shown, with a headless context of its
own; every change (a new program, uniform values, the camera, the mesh, the environment...) is
a message sent to it in order, and after the messages it draws a frame and sends the picture
back, which `paintEvent` paints (scaled while a resize is under way). A structural edit arrives as
a new `CompiledMaterial` (`set_material`): when it fails to link, the renderer keeps its last
good program, and the errors, located on nodes, go out through `glErrors`. A value edit only
sets uniforms and redraws. `renderer` (for tests and tools) reads the server's renderer, after
the messages sent before; the editor itself never reads it.

The last good program belongs to the document: another document clears it
(`clear_material`), and until that document compiles and links the view draws the scene
without a material. The tool bar and the notices over the view are
`matedit.app.viewport_panel`; the environment choice is `matedit.app.environment`.
"""

from __future__ import annotations

import atexit
import weakref
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QCoreApplication, QEventLoop, QObject, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QImage, QPainter
from PySide6.QtWidgets import QWidget

from matedit.app.render_client import (
    RemoteRenderer,
    RendererStopped,
    RenderProcess,
    take_prelaunched,
)

if TYPE_CHECKING:
    from matedit.render.server import FrameInfo


@dataclass(frozen=True)
class RenderSettings:
    """How the viewport draws, apart from the material: renderer attributes that need no GL
    work to change (a typed record, not option names)."""

    environment_intensity: float = 1.0
    show_background: bool = True
    background_blur: float = 0.0
    # Multiple-scattering compensation (Fdez-Aguera 2019) for every material, not only those
    # whose preview asks for it: relinks the program once per change.
    energy_compensation: bool = False


_PROCESSES: weakref.WeakSet[RenderProcess] = weakref.WeakSet()


@atexit.register
def _stop_render_processes() -> None:
    """No render process outlives the editor."""
    for process in list(_PROCESSES):
        process.stop()


def _emit(signal, *args) -> None:
    """Emits from a thread of the render client; nothing when the viewport has gone."""
    try:
        signal.emit(*args)
    except RuntimeError:  # its bridge was deleted with the viewport
        pass


class _Bridge(QObject):
    """Carries what the render process says to the UI thread (queued: the slots run there)."""

    frame = Signal(object, object, float)  # pixels, FrameInfo, the frame's GL ms
    started = Signal(str, object)  # "" or the problem; the renderer's lights
    ended = Signal(str)  # why the render process has gone
    call = Signal(object)  # a callable to run on the UI thread


class ViewportWidget(QWidget):
    """Orbit (left drag), zoom (wheel), pan (middle or shift+left drag)."""

    glErrors = Signal(list)  # [(node_id, message)] when a program fails to build
    materialApplied = Signal(bool)  # True when the new program is live
    frameDrawn = Signal()
    statusMessage = Signal(str)
    settingsChanged = Signal(object)  # the new RenderSettings
    viewRefused = Signal(str)  # a view whose program failed to link: the view still drawn
    # GL work between two looks at the messages while reference mode accumulates (ms; None:
    # matedit.render.server.BUDGET_MS)
    slice_budget_ms: float | None = None
    # once idle a while after a structural edit, the render process draws the material
    # forward (matedit.render.server.FORWARD_WHEN_IDLE_S; Renderer.promote_forward)
    forward_when_idle = True
    # start the render process when the widget is made rather than when it is first shown
    # (off: a window never shown starts none; the editor's first viewport takes the process
    # `matedit` launched before it imported Qt, render_client.prelaunch)
    launch_early = False
    MAX_RESTARTS = 3  # a render process that dies (a driver crash) is started again so often

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setMinimumSize(160, 120)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setAttribute(Qt.WidgetAttribute.WA_OpaquePaintEvent)
        self.problem = ""
        self._bridge = _Bridge(self)
        self._bridge.frame.connect(self._on_frame, Qt.ConnectionType.QueuedConnection)
        self._bridge.started.connect(self._on_started, Qt.ConnectionType.QueuedConnection)
        self._bridge.ended.connect(self._on_ended, Qt.ConnectionType.QueuedConnection)
        self._bridge.call.connect(lambda fn: fn(), Qt.ConnectionType.QueuedConnection)
        self._proc = take_prelaunched() or RenderProcess()
        self._connect_process()
        if self.launch_early:
            self._proc.launch()  # imports and its GL context while the window is built
        self._running = False  # the renderer is up in its process
        self._restarts = 0
        self._uniforms: dict[str, Any] = {}  # every value sent, for a restarted process
        self._textures: dict[str, Path | None] = {}
        self._pending_material = None  # the last material posted (what the first frame shows)
        self._has_material = False
        self._mesh = "sphere"
        self._environment = "studio"
        # the environment is baked (or loaded from the cache) after the first frame, so that
        # the window shows at once; until then the view draws without image-based lighting:
        # "pending" until the first frame is painted, "loading", then "ready"
        self._environment_state = "pending"
        self._mode = "splitsum"
        self._view = "lit"  # matedit.shading.views: lit, a lobe view or an attribute view
        self._exposure = 0.0
        self._lights: list | None = None
        self._last = QPointF()
        self._button = Qt.MouseButton.NoButton
        self.frames = 0
        self.last_frame_time = 0.0
        self.settings = RenderSettings()
        self._image: QImage | None = None
        self._new_frame = False
        self.frame_info: FrameInfo | None = None  # what the last picture shows
        self.shown_serial = 0  # the serial of the picture painted last (request_frame)
        self._compare = None  # (compiled, uniforms, textures) of an A/B split's A side
        self._split = 0.5

    # --- the render process -----------------------------------------------------------------
    def _size_px(self) -> tuple[int, int]:
        dpr = self.devicePixelRatioF()
        return max(1, int(self.width() * dpr)), max(1, int(self.height() * dpr))

    def showEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        if not self._proc.initialised:
            self._send_init()

    def _send_init(self) -> None:
        from matedit.render.server import FORWARD_WHEN_IDLE_S

        s = self.settings
        idle = FORWARD_WHEN_IDLE_S if self.forward_when_idle else None
        try:
            self._proc.start({
                "size": self._size_px(), "warm_up": not self._first_frame_deferred(),
                "forward_when_idle_s": idle,
                "mesh": self._mesh, "mode": self._mode, "exposure": self._exposure,
                "view": self._view, "lights": self._lights, "budget_ms": self.slice_budget_ms,
                "settings": (s.environment_intensity, s.show_background, s.background_blur,
                             s.energy_compensation)})
        except OSError as exc:
            self._on_ended(f"the renderer could not start: {exc}")

    def _on_started(self, problem: str, lights) -> None:
        if problem:
            self._on_ended(problem)
            return
        self._running = True
        if self._lights is None:
            self._lights = list(lights or [])

    def _on_ended(self, problem: str) -> None:
        """The render process has gone: started again with what it drew (MAX_RESTARTS times;
        a process that fails to start is not retried), or the view says why."""
        if self._running and self._restarts < self.MAX_RESTARTS:
            self._restarts += 1
            self.statusMessage.emit(f"the viewport's renderer stopped ({problem}); restarted")
            self._restart()
            return
        self.problem = problem
        self._running = False
        super().update()

    def _restart(self) -> None:
        self._running = False
        self._proc = RenderProcess()
        self._connect_process()
        self._environment_state = "pending"  # loaded again after the first frame
        self._send_init()
        if self._pending_material is not None:
            self.set_material(self._pending_material)
        if self._uniforms or self._textures:
            self._post("values", dict(self._uniforms), dict(self._textures))
        if self._compare is not None:
            self._apply_compare()
            self._do("set_split", self._split)

    def _connect_process(self) -> None:
        bridge, proc = self._bridge, self._proc
        proc.bind(lambda *a: _emit(bridge.frame, *a), lambda *a: _emit(bridge.started, *a),
                  lambda *a: _emit(bridge.ended, *a))
        _PROCESSES.add(proc)
        self.destroyed.connect(lambda *_: proc.stop())

    def _post(self, op: str, *args, then: Callable[[Any], None] | None = None,
              failed: Callable[[BaseException], None] | None = None, frame: bool = True,
              progress: Callable[[float], None] | None = None):
        """Sends (op, args) to the render process; `then(reply)` or `failed(exception)` back
        on the UI thread."""
        future = self._proc.post(op, *args, frame=frame, progress=progress)
        if then is not None or failed is not None:
            bridge = self._bridge

            def done(f) -> None:
                exc = f.exception()
                if isinstance(exc, RendererStopped):  # said once, by `ended`
                    return
                if exc is not None:
                    if failed is not None:
                        _emit(bridge.call, lambda: failed(exc))
                elif then is not None:
                    _emit(bridge.call, lambda: then(f.result()))

            future.add_done_callback(done)
        return future

    def _do(self, path: str, *args, **kw):
        """Calls the renderer's method at `path` (e.g. "camera.orbit") in the render process."""
        return self._post("call", path, args, {}, **kw)

    @property
    def running(self) -> bool:
        """Whether the renderer is up (False before the widget is shown and when it failed)."""
        return self._running and not self.problem

    @property
    def renderer(self) -> RemoteRenderer | None:
        """The render process's renderer, read and called after every message sent so far
        (tests and tools); None while it starts or when it could not."""
        if not self.running:
            return None
        try:
            self.sync()
        except RuntimeError:
            return None
        return RemoteRenderer(self._proc)

    def sync(self) -> None:
        """Waits until the render process has served every message sent so far."""
        if self.running:
            self._proc.sync()
            # and the replies' handlers that came back meanwhile (a consistent point: what the
            # panel shows follows what the renderer has)
            QCoreApplication.sendPostedEvents(self._bridge)

    def _first_frame_deferred(self) -> bool:
        """Whether the material waiting for GL takes the deferred path: its first frame then
        warms what the renderer's start-up frame of a constant material would."""
        from matedit.render.paths import wants_forward
        from matedit.shading.views import is_attribute_view

        cm = self._pending_material
        if cm is None or is_attribute_view(self._view):
            return False
        try:
            return not wants_forward(cm, self._uniforms)
        except Exception:  # whatever it is, the renderer warms itself as it always did
            return False

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        self._do("resize", *self._size_px())

    def update(self, *args) -> None:
        """A new frame from the render process (and a repaint meanwhile)."""
        if not args:
            self.request_frame()
        super().update(*args)

    def request_frame(self) -> int:
        """Asks the render process for a frame; returns the serial number that the picture
        painted after it reaches (`shown_serial`), 0 before the process has its init."""
        if not self._proc.initialised:
            return 0
        return int(getattr(self._post("get", "", frame=True), "mid", 0))

    def _on_frame(self, pixels, info, ms: float) -> None:
        h, w = pixels.shape[:2]
        self._image = QImage(pixels.data, w, h, 4 * w, QImage.Format.Format_RGBA8888).copy()
        self._image.setDevicePixelRatio(self.devicePixelRatioF())
        self.frame_info = info
        self.last_frame_time = ms / 1e3
        self._new_frame = True
        super().update()

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt's name
        p = QPainter(self)
        if self._image is None:
            p.fillRect(self.rect(), QColor("#17191e"))
            p.setPen(QColor("#8a91a0"))
            p.drawText(self.rect().adjusted(12, 12, -12, -12),
                       Qt.AlignmentFlag.AlignCenter | Qt.TextFlag.TextWordWrap,
                       self.problem or "starting the renderer…")
            p.end()
            return
        p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform)
        target = self._image_rect()
        if target != QRectF(self.rect()):
            p.fillRect(self.rect(), QColor("#17191e"))
        p.drawImage(target, self._image)
        if self.problem:
            p.fillRect(self.rect().adjusted(0, self.height() - 28, 0, 0), QColor(23, 25, 30, 220))
            p.setPen(QColor("#e0a0a0"))
            p.drawText(self.rect().adjusted(8, 0, -8, -6),
                       Qt.AlignmentFlag.AlignBottom | Qt.AlignmentFlag.AlignLeft, self.problem)
        p.end()
        if self._new_frame:
            self._new_frame = False
            self.frames += 1
            if self.frame_info is not None:
                self.shown_serial = self.frame_info.serial
            self.frameDrawn.emit()
            if self._environment_state == "pending" and self.running:
                self._load_environment()  # once the first frame is on screen

    def _image_rect(self) -> QRectF:
        """Where the picture goes: the whole view, or while a picture of the new size is on
        its way (a resize), the last one scaled with its proportions kept, centred, the rest
        cleared to the view's background (a sphere stays round)."""
        r = QRectF(self.rect())
        size = self._image.deviceIndependentSize()
        if abs(size.width() - r.width()) < 1 and abs(size.height() - r.height()) < 1:
            return r
        scale = min(r.width() / max(size.width(), 1), r.height() / max(size.height(), 1))
        w, h = size.width() * scale, size.height() * scale
        return QRectF(r.x() + (r.width() - w) / 2, r.y() + (r.height() - h) / 2, w, h)

    def current_image(self) -> QImage:
        """The picture on screen (RGB888), a null image before the first frame."""
        if self._image is None:
            return QImage()
        return self._image.convertToFormat(QImage.Format.Format_RGB888)

    # --- material and values ---------------------------------------------------------------
    def viewport_state(self):
        """What the compile worker needs to warm this view's programs (matedit.render.warmup),
        or None before the renderer runs."""
        if not self.running:
            return None
        from matedit.render.warmup import ViewportState

        return ViewportState(samples=4, deferred=True,  # as the render process's renderer
                             environment=str(self._environment),  # the one it has or gets
                             mode=self._mode, mesh=self._mesh,
                             energy_compensation=self.settings.energy_compensation,
                             show_background=self.settings.show_background)

    @property
    def has_material(self) -> bool:
        """Whether a material is drawn, or waits to be when the renderer starts."""
        if not self.running:
            return self._pending_material is not None
        return self._has_material

    def clear_material(self) -> None:
        """Draw no material (another document: the previous one's program is not its own)."""
        self._pending_material = None
        self._uniforms, self._textures = {}, {}
        self._has_material = False
        self._do("clear_material")

    def set_material(self, compiled) -> None:
        """A new program, linked on the render thread; `materialApplied` (and `glErrors` on a
        failure) say how it went."""
        self._pending_material = compiled

        def applied(status) -> None:
            ok = bool(status.ok)
            if ok:
                self._has_material = True
            else:
                self.glErrors.emit(list(status.errors or []))
            self.materialApplied.emit(ok)

        def failed(exc: BaseException) -> None:
            self.glErrors.emit([("", f"{type(exc).__name__}: {exc}")])
            self.materialApplied.emit(False)

        self._do("set_material", compiled, then=applied, failed=failed)

    def set_values(self, uniforms: dict[str, Any], textures: dict[str, Path | None]) -> None:
        self._uniforms.update(uniforms)
        self._textures.update(textures)
        self._post("values", uniforms, dict(textures),
                   then=lambda problems: [self.statusMessage.emit(m) for m in problems])

    # --- A/B split -------------------------------------------------------------------------
    def set_compare(self, compiled, uniforms: dict[str, Any] | None = None,
                    textures: dict[str, Path | None] | None = None) -> None:
        """The A side of an A/B split (None: no split): `compiled` with these uniform values
        and texture files, left of the divider (Renderer.set_compare)."""
        self._compare = None if compiled is None else (compiled, dict(uniforms or {}),
                                                       dict(textures or {}))
        self._apply_compare()

    def _apply_compare(self) -> None:
        compare = self._compare or (None,)

        def done(status) -> None:
            if not status.ok:
                self.statusMessage.emit("A/B split: the earlier material no longer builds")

        def failed(exc: BaseException) -> None:  # the split is an aid: say it, keep drawing
            self.statusMessage.emit(f"A/B split: {type(exc).__name__}: {exc}")

        self._post("compare", *compare, then=done, failed=failed)

    @property
    def split(self) -> float:
        return self._split

    def set_split(self, fraction: float) -> None:
        """The divider, as a fraction of the width from the left."""
        self._split = min(0.95, max(0.05, float(fraction)))
        self._do("set_split", self._split)

    # --- view state ------------------------------------------------------------------------
    def set_mesh(self, name: str) -> None:
        self._mesh = name

        def failed(exc: BaseException) -> None:
            self.statusMessage.emit(f"mesh {Path(name).name}: {exc}")

        self._do("set_mesh", name, failed=failed)

    def set_mode(self, mode: str) -> None:
        self._mode = mode
        self._post("set", "mode", mode)

    def set_view(self, view: str) -> None:
        """The view chooser's view (matedit.shading.views): one relink the first time each
        view is shown for a material (the programs are cached), a redraw after. A view that
        fails to link is said (`statusMessage`), and `viewRefused` names the view kept."""
        old, self._view = self._view, view

        def failed(exc: BaseException) -> None:
            if self._view == view:
                self._view = old
            self.statusMessage.emit(f"view {view}: {type(exc).__name__}: {exc}")
            self.viewRefused.emit(self._view)

        self._do("set_view", view, failed=failed)

    def set_exposure(self, ev: float) -> None:
        self._exposure = float(ev)
        self._post("set", "exposure", self._exposure)

    def set_settings(self, settings: RenderSettings) -> None:
        """New render settings (background, blur, IBL intensity: a redraw; energy
        compensation: a relink, on the render thread)."""
        if settings == self.settings:
            return
        self.settings = settings
        self._post("settings", settings.environment_intensity, settings.show_background,
                   settings.background_blur, settings.energy_compensation)
        self.settingsChanged.emit(settings)

    def change_settings(self, **changes) -> None:
        self.set_settings(replace(self.settings, **changes))

    @property
    def lights(self) -> list:
        return list(self._lights or [])

    def set_lights(self, lights: list) -> None:
        self._lights = list(lights)
        self._do("set_lights", list(lights))

    @property
    def environment(self) -> str:
        """The environment the view is set to (baked once the renderer's first frame is in)."""
        return self._environment

    @property
    def environment_ready(self) -> bool:
        """Whether the renderer has the view's environment (False before it runs and from the
        first frame until the environment that follows it is in)."""
        return self.running and self._environment_state == "ready"

    def _load_environment(self) -> None:
        """The environment at start-up, once the first frame is on screen: baked (or loaded
        from the cache) on the render thread."""
        spec = self._environment
        self._environment_state = "loading"

        def done(_result) -> None:
            if self._environment_state == "loading":
                self._environment_state = "ready"

        def failed(exc: BaseException) -> None:  # the view says what went wrong
            self._environment_state = "ready"
            self.problem = f"renderer failed to start: {type(exc).__name__}: {exc}"
            super(ViewportWidget, self).update()

        self._post("environment", spec, then=done, failed=failed)

    def set_environment(self, spec: str, progress=None) -> None:
        """Bakes (or loads from the cache) an environment on the render thread; the UI's event
        loop runs meanwhile, `progress(fraction)` is called on the UI thread. Raises
        ValueError (or OSError) for a bad file, the environment before it staying."""
        self._environment = spec
        if not self.running:
            return
        bridge = self._bridge

        def report(fraction: float) -> None:  # on the client's reader thread
            if progress is not None:
                _emit(bridge.call, lambda: progress(fraction))

        future = self._post("environment", spec, True, progress=report)
        loop = QEventLoop()
        future.add_done_callback(lambda _f: _emit(bridge.call, loop.quit))
        if not future.done():
            loop.exec()
        future.result()
        self._environment_state = "ready"

    def gl_renderer(self) -> str:
        """The OpenGL renderer string ("" before GL is up)."""
        if not self.running:
            return ""

        try:
            return str(self._proc.call("info"))
        except Exception:  # a context that cannot answer says nothing
            return ""

    def read_hdr(self):
        """(H, W, 3) scene-linear radiance of the last frame (before exposure and display
        transform), or None without a renderer."""
        if not self.running:
            return None
        return self._proc.call("call", "read_hdr")

    def render_offscreen(self, width: int, height: int):
        """(display image, scene-linear radiance), each (H, W, 3) floats, of the view drawn
        at `width` x `height` (reference mode converged), then the view's own size again;
        None without a renderer."""
        if not self.running:
            return None

        out = self._proc.call("offscreen", int(width), int(height))
        self.update()
        return out

    def read_image(self):
        """(H, W, 3) sRGB floats of the last frame, through the renderer."""
        if not self.running:
            return None
        return self._proc.call("call", "read_image")

    # --- camera ----------------------------------------------------------------------------
    def reset_camera(self) -> None:
        self._do("camera.reset")

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt's name
        self._last = event.position()
        self._button = event.button()
        if event.button() == Qt.MouseButton.LeftButton and \
                event.modifiers() & Qt.KeyboardModifier.ShiftModifier:
            self._button = Qt.MouseButton.MiddleButton

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if not self.running:
            return
        d = event.position() - self._last
        self._last = event.position()
        dx, dy = d.x(), d.y()
        if self._button == Qt.MouseButton.LeftButton:
            self._do("camera.orbit", -dx * 0.4, -dy * 0.4)
        elif self._button == Qt.MouseButton.MiddleButton:
            h = max(1, self.height())
            self._do("camera.pan", -dx / h, dy / h)

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt's name
        self._button = Qt.MouseButton.NoButton

    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if not self.running:
            return
        steps = event.angleDelta().y() / 120.0
        self._do("camera.dolly", 0.9 ** steps)

    def mouseDoubleClickEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self.running:
            self.reset_camera()
