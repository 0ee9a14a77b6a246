"""The 3D preview's GL widget: a QOpenGLWidget hosting `matedit.render.Renderer`.

The moderngl context is created once in `initializeGL` and every frame draws into
Qt's framebuffer (`detect_framebuffer(defaultFramebufferObject())`). A structural
edit arrives as a new `CompiledMaterial` (`set_material`): when it fails to link,
the renderer keeps its last good program, and the errors, located on nodes, go
out through `glErrors`. A value edit only sets uniforms and redraws.

The last good program belongs to the document: another document clears it
(`clear_material`), and until that document compiles and links the view draws the scene
without a material. The tool bar and the notices over the view are
`matedit.app.viewport_panel`; the environment choice is `matedit.app.environment`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from PySide6.QtCore import QPointF, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtOpenGLWidgets import QOpenGLWidget


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


def _load_renderer_class():
    """The renderer class, or the reason it cannot be had (shown in the viewport)."""
    try:
        from matedit.render import Renderer  # the lead's moderngl renderer
    except ImportError as exc:
        return None, f"renderer not available ({exc})"
    return Renderer, ""


class ViewportWidget(QOpenGLWidget):
    """Orbit (left drag), zoom (wheel), pan (middle or shift+left drag)."""

    glErrors = Signal(list)  # [(node_id, message)] when a program fails to build
    materialApplied = Signal(bool)  # True when the new program is live
    frameDrawn = Signal()
    statusMessage = Signal(str)
    settingsChanged = Signal(object)  # the new RenderSettings
    # GL work a paint does for reference accumulation (ms; None: the renderer's default,
    # matedit.render.slicing.DEFAULT_BUDGET_MS); the next paint is queued behind the events
    # that came meanwhile
    slice_budget_ms: float | None = None
    DISPLAY_INTERVAL_S = 0.25  # reference accumulation shows its progress this often

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setMinimumSize(160, 120)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.ctx = None
        self.renderer = None
        self.problem = ""
        self._pending_material = None
        self._pending_uniforms: dict[str, Any] | None = None
        self._pending_textures: dict[str, Path | None] = {}
        self._mesh = "sphere"
        self._environment = "studio"
        # the environment is baked (or loaded from the cache) after the first frame, so that
        # the window shows at once; until then the view draws without image-based lighting
        self._environment_pending = False
        self._mode = "splitsum"
        self._view = "lit"  # matedit.shading.views: lit, a lobe view or an attribute view
        self._exposure = 0.0
        self._lights = None
        self._last = QPointF()
        self._button = Qt.MouseButton.NoButton
        self.frames = 0
        self.last_frame_time = 0.0
        self._fbo = None
        self._fbo_glo = -1
        self.settings = RenderSettings()
        self._last_paint = 0.0
        self._slicer = QTimer(self)  # reference accumulation between paints (_advance)
        self._slicer.setSingleShot(True)
        self._slicer.setInterval(0)
        self._slicer.timeout.connect(self._advance)
        self._compare = None  # (compiled, uniforms, textures) of an A/B split's A side
        self._split = 0.5

    # --- GL lifecycle ----------------------------------------------------------------------
    def initializeGL(self) -> None:  # noqa: N802 - Qt's name
        try:
            import moderngl

            self.ctx = moderngl.create_context()
        except Exception as exc:
            self.problem = f"no OpenGL 3.3 context: {exc}"
            return
        cls, why = _load_renderer_class()
        if cls is None:
            self.problem = why
            return
        dpr = self.devicePixelRatioF()
        size = (max(1, int(self.width() * dpr)), max(1, int(self.height() * dpr)))
        try:
            try:  # no environment yet: it follows the first frame (_load_environment)
                self.renderer = cls(self.ctx, size=size, samples=4, environment=None,
                                    warm_up=not self._first_frame_deferred())
                self._environment_pending = True
            except TypeError:  # a renderer class without the keyword bakes its default
                self.renderer = cls(self.ctx, size=size, samples=4)
                self._environment_pending = self._environment != "studio"
            self._apply_view_state()
            # reference accumulation in bands of rows, a paint's worth at a time, so that
            # the event loop runs between them (matedit.render.slicing)
            from matedit.render.slicing import DEFAULT_BUDGET_MS

            self.renderer.slice_budget_ms = self.slice_budget_ms or DEFAULT_BUDGET_MS
        except Exception as exc:
            self.renderer = None
            self.problem = f"renderer failed to start: {type(exc).__name__}: {exc}"
            return
        if self._pending_material is not None:
            cm, self._pending_material = self._pending_material, None
            self._apply_material(cm)
        self._flush_values()
        if hasattr(self.renderer, "set_split"):
            self.renderer.set_split(self._split)
        if self._compare is not None:
            self._apply_compare()

    def _first_frame_deferred(self) -> bool:
        """Whether the material waiting for GL takes the deferred path: its first frame then
        warms what the renderer's start-up frame of a constant material would."""
        from matedit.render.deferred import wants_forward
        from matedit.shading.views import is_attribute_view

        cm = self._pending_material
        if cm is None or is_attribute_view(self._view):
            return False
        try:
            return not wants_forward(cm, self._pending_uniforms)
        except Exception:  # whatever it is, the renderer warms itself as it always did
            return False

    def _apply_view_state(self) -> None:
        r = self.renderer
        r.set_mesh(self._mesh)
        r.mode = self._mode
        r.exposure = self._exposure
        self._set_renderer_view(r, self._view)
        self._apply_settings(r)
        if self._lights is not None:
            r.set_lights(list(self._lights))
        else:
            self._lights = list(r.lights)

    def resizeGL(self, w: int, h: int) -> None:  # noqa: N802 - Qt's name
        self._fbo = None
        if self.renderer is not None:
            dpr = self.devicePixelRatioF()
            self.renderer.resize(max(1, int(w * dpr)), max(1, int(h * dpr)))

    def paintGL(self) -> None:  # noqa: N802 - Qt's name
        t0 = time.perf_counter()
        if self.renderer is None or self.ctx is None:
            self._paint_message(self.problem or "starting the renderer…")
            return
        try:
            glo = self.defaultFramebufferObject()
            if self._fbo is None or self._fbo_glo != glo:  # Qt recreates it on resize
                self._fbo, self._fbo_glo = self.ctx.detect_framebuffer(glo), glo
            self.renderer.render(self._fbo)
        except Exception as exc:  # keep the editor alive; show what went wrong
            self.problem = f"render failed: {type(exc).__name__}: {exc}"
            self.renderer = None
            self._paint_message(self.problem)
            return
        self.frames += 1
        self.last_frame_time = time.perf_counter() - t0
        self._last_paint = time.perf_counter()
        if self._environment_pending:
            QTimer.singleShot(0, self, self._load_environment)
        self.frameDrawn.emit()
        if self.renderer.needs_redraw:  # reference mode accumulates until converged
            self._slicer.start()

    def _advance(self) -> None:
        """Reference accumulation between paints: one budget's worth of bands
        (Renderer.advance), then the event loop; a paint when a frame is complete, or
        DISPLAY_INTERVAL_S after the last one (the first frame shows as it is drawn)."""
        r = self.renderer
        if r is None or not r.needs_redraw:
            return
        frames = r.accumulated_frames
        self.makeCurrent()
        try:
            bands = r.advance()
        except Exception as exc:  # as paintGL: keep the editor alive, say what went wrong
            self.problem = f"render failed: {type(exc).__name__}: {exc}"
            self.renderer = None
            self.update()
            return
        finally:
            self.doneCurrent()
        if not r.needs_redraw:  # converged: shown (and said) before anyone asks
            self.repaint()
        elif not bands or r.accumulated_frames != frames or \
                time.perf_counter() - self._last_paint >= self.DISPLAY_INTERVAL_S:
            self.update()
        else:
            self._slicer.start()

    def _paint_message(self, text: str) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor("#17191e"))
        p.setPen(QColor("#8a91a0"))
        p.drawText(self.rect().adjusted(12, 12, -12, -12),
                   Qt.AlignmentFlag.AlignCenter | Qt.TextFlag.TextWordWrap, text)
        p.end()

    # --- material and values ---------------------------------------------------------------
    def viewport_state(self):
        """What the compile worker needs to warm this view's programs (matedit.render.warmup),
        or None before the renderer runs."""
        r = self.renderer
        if r is None:
            return None
        from matedit.render.warmup import ViewportState

        return ViewportState(samples=r.samples, deferred=r.deferred,
                             environment=str(self._environment),  # the one it has or gets
                             mode=r.mode, mesh=r.mesh_name,
                             energy_compensation=r.energy_compensation,
                             show_background=r.show_background)

    @property
    def has_material(self) -> bool:
        """Whether a material is drawn, or waits to be at initializeGL."""
        if self.renderer is None:
            return self._pending_material is not None
        return bool(self.renderer.has_material)

    def clear_material(self) -> None:
        """Draw no material (another document: the previous one's program is not its own)."""
        self._pending_material = None
        self._pending_uniforms, self._pending_textures = None, {}
        if self.renderer is not None:
            self.makeCurrent()
            try:
                self.renderer.clear_material()
            finally:
                self.doneCurrent()
            self.update()

    def set_material(self, compiled) -> bool | None:
        """A new program; None while GL is not up yet (applied at initializeGL)."""
        if self.renderer is None:
            self._pending_material = compiled
            return None
        return self._apply_material(compiled)

    def _apply_material(self, compiled) -> bool:
        self.makeCurrent()
        try:
            status = self.renderer.set_material(compiled)
        except Exception as exc:
            self.doneCurrent()
            self.glErrors.emit([("", f"{type(exc).__name__}: {exc}")])
            self.materialApplied.emit(False)
            return False
        self.doneCurrent()
        ok = bool(status.ok)
        if not ok:
            self.glErrors.emit(list(status.errors or []))
        self.materialApplied.emit(ok)
        self.update()
        return ok

    def set_values(self, uniforms: dict[str, Any], textures: dict[str, Path | None]) -> None:
        self._pending_uniforms = uniforms
        self._pending_textures = textures
        if self.renderer is not None:
            self._flush_values()
            self.update()

    def _flush_values(self) -> None:
        if self.renderer is None:
            return
        self.makeCurrent()
        try:
            if self._pending_uniforms is not None:
                self.renderer.set_uniforms(self._pending_uniforms)
            for name, path in self._pending_textures.items():
                try:
                    self.renderer.set_texture(name, str(path) if path else None)
                except ValueError as exc:
                    self.statusMessage.emit(str(exc))
            self._pending_textures = {}
        finally:
            self.doneCurrent()

    # --- A/B split -------------------------------------------------------------------------
    def set_compare(self, compiled, uniforms: dict[str, Any] | None = None,
                    textures: dict[str, Path | None] | None = None) -> bool:
        """The A side of an A/B split (None: no split): `compiled` with these uniform values
        and texture files, left of the divider (Renderer.set_compare)."""
        self._compare = None if compiled is None else (compiled, dict(uniforms or {}),
                                                       dict(textures or {}))
        return self._apply_compare()

    def _apply_compare(self) -> bool:
        r = self.renderer
        if r is None or not hasattr(r, "set_compare"):
            return False
        self.makeCurrent()
        try:
            if self._compare is None:
                status = r.set_compare(None)
            else:
                cm, uniforms, textures = self._compare
                status = r.set_compare(cm, uniforms, {k: str(v) if v else None
                                                      for k, v in textures.items()})
        except Exception as exc:  # noqa: BLE001 - the split is an aid: say it, keep drawing
            self.statusMessage.emit(f"A/B split: {type(exc).__name__}: {exc}")
            return False
        finally:
            self.doneCurrent()
        if not status.ok:
            self.statusMessage.emit("A/B split: the earlier material no longer builds")
        self.update()
        return bool(status.ok)

    @property
    def split(self) -> float:
        return self._split

    def set_split(self, fraction: float) -> None:
        """The divider, as a fraction of the width from the left."""
        self._split = min(0.95, max(0.05, float(fraction)))
        if self.renderer is not None and hasattr(self.renderer, "set_split"):
            self.renderer.set_split(self._split)
            self.update()

    # --- view state ------------------------------------------------------------------------
    def set_mesh(self, name: str) -> None:
        self._mesh = name
        if self.renderer is not None:
            self.makeCurrent()
            try:
                self.renderer.set_mesh(name)
            finally:
                self.doneCurrent()
            self.update()

    def set_mode(self, mode: str) -> None:
        self._mode = mode
        if self.renderer is not None:
            self.renderer.mode = mode
            self.update()

    @property
    def shading_view(self) -> str:
        return self._view

    def set_view(self, view: str) -> None:
        """The view chooser's view (matedit.shading.views): one relink the first time each
        view is shown for a material (the programs are cached), a redraw after."""
        self._view = view
        if self.renderer is not None:
            self.makeCurrent()
            try:
                self._set_renderer_view(self.renderer, view)
            finally:
                self.doneCurrent()
            self.update()

    def _set_renderer_view(self, r, view: str) -> None:
        try:
            r.set_view(view)
        except Exception as exc:  # a link failure keeps the view the renderer had
            self._view = r.view
            self.statusMessage.emit(f"view {view}: {type(exc).__name__}: {exc}")

    def set_exposure(self, ev: float) -> None:
        self._exposure = float(ev)
        if self.renderer is not None:
            self.renderer.exposure = float(ev)
            self.update()

    def set_settings(self, settings: RenderSettings) -> None:
        """New render settings (background, blur, IBL intensity: a redraw; energy
        compensation: a relink, in the widget's context)."""
        if settings == self.settings:
            return
        self.settings = settings
        if self.renderer is not None:
            self.makeCurrent()
            try:
                self._apply_settings(self.renderer)
            finally:
                self.doneCurrent()
            self.renderer.reset_accumulation()
            self.update()
        self.settingsChanged.emit(settings)

    def change_settings(self, **changes) -> None:
        self.set_settings(replace(self.settings, **changes))

    def _apply_settings(self, r) -> None:
        s = self.settings
        r.environment_intensity = s.environment_intensity
        r.show_background = s.show_background
        r.background_blur = s.background_blur
        r.set_energy_compensation(s.energy_compensation)

    @property
    def lights(self) -> list:
        return list(self._lights or [])

    def set_lights(self, lights: list) -> None:
        self._lights = list(lights)
        if self.renderer is not None:
            self.makeCurrent()
            try:
                self.renderer.set_lights(list(lights))
            finally:
                self.doneCurrent()
            self.update()

    @property
    def environment(self) -> str:
        """The environment the view is set to (baked at initializeGL if GL is not up yet)."""
        return self._environment

    @property
    def environment_ready(self) -> bool:
        """Whether the renderer has the view's environment (False before GL is up and from
        the first frame until the environment that follows it is in)."""
        return self.renderer is not None and not self._environment_pending

    def _load_environment(self) -> None:
        """The environment at start-up, once the first frame is on screen."""
        if not self._environment_pending or self.renderer is None:
            return
        self._environment_pending = False
        self.makeCurrent()
        try:
            self._set_environment_now(self._environment, None)
        except Exception as exc:  # as at start-up before: the view says what went wrong
            self.problem = f"renderer failed to start: {type(exc).__name__}: {exc}"
            self.renderer = None
        finally:
            self.doneCurrent()
        self.update()

    def set_environment(self, spec: str, progress=None) -> None:
        """Bakes (or loads from cache) an environment; raises ValueError for a bad file."""
        self._environment = spec
        if self.renderer is not None:
            self._environment_pending = False
            self.makeCurrent()
            try:
                self._set_environment_now(spec, progress)
            finally:
                self.doneCurrent()
            self.update()

    def _set_environment_now(self, spec: str, progress) -> None:
        self.renderer.set_environment(spec, progress=progress)

    def gl_renderer(self) -> str:
        """The OpenGL renderer string ("" before GL is up)."""
        if self.ctx is None:
            return ""
        try:
            info = self.ctx.info
            return f"{info.get('GL_RENDERER', '?')} ({info.get('GL_VERSION', '?')})"
        except Exception:  # a context that cannot answer says nothing
            return ""

    def read_hdr(self):
        """(H, W, 3) scene-linear radiance of the last frame (before exposure and display
        transform), or None without a renderer."""
        if self.renderer is None:
            return None
        self.makeCurrent()
        try:
            return self.renderer.read_hdr()
        finally:
            self.doneCurrent()

    def render_offscreen(self, width: int, height: int):
        """(display image, scene-linear radiance), each (H, W, 3) floats, of the view drawn
        at `width` x `height` (reference mode converged), then the view's own size again;
        None without a renderer."""
        r = self.renderer
        if r is None:
            return None
        self.makeCurrent()
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
            self._fbo = None
            self.doneCurrent()
            self.update()

    def read_image(self):
        """(H, W, 3) sRGB floats of the last frame, through the renderer."""
        if self.renderer is None:
            return None
        self.makeCurrent()
        try:
            return self.renderer.read_image()
        finally:
            self.doneCurrent()

    # --- camera ----------------------------------------------------------------------------
    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt's name
        self._last = event.position()
        self._button = event.button()
        if event.button() == Qt.MouseButton.LeftButton and \
                event.modifiers() & Qt.KeyboardModifier.ShiftModifier:
            self._button = Qt.MouseButton.MiddleButton

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self.renderer is None:
            return
        d = event.position() - self._last
        self._last = event.position()
        cam = self.renderer.camera
        if self._button == Qt.MouseButton.LeftButton:
            cam.orbit(-d.x() * 0.4, -d.y() * 0.4)
        elif self._button == Qt.MouseButton.MiddleButton:
            h = max(1, self.height())
            cam.pan(-d.x() / h, d.y() / h)
        else:
            return
        self.update()

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt's name
        self._button = Qt.MouseButton.NoButton

    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self.renderer is None:
            return
        steps = event.angleDelta().y() / 120.0
        self.renderer.camera.dolly(0.9 ** steps)
        self.update()

    def mouseDoubleClickEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self.renderer is not None:
            self.renderer.camera.reset()
            self.update()
