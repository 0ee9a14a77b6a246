"""The 3D preview: a QOpenGLWidget hosting `matedit.render.Renderer`, and its tool bar.

The moderngl context is created once in `initializeGL` and every frame draws into
Qt's framebuffer (`detect_framebuffer(defaultFramebufferObject())`). A structural
edit arrives as a new `CompiledMaterial` (`set_material`): when it fails to link,
the renderer keeps its last good program, and the errors, located on nodes, go
out through `glErrors`. A value edit only sets uniforms and redraws.

The last good program belongs to the document: another document clears it
(`clear_material`), and until that document compiles and links the view draws the scene
without a material, under a "does not compile" notice when it fails.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from PySide6.QtCore import QPointF, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QMessageBox,
    QProgressDialog,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.compile_service import MaterialCompiler, uniform_values
from matedit.app.paths import texture_paths
from matedit.app.theme import icon
from matedit.shading.views import VIEWS

MESHES = ("sphere", "cube", "plane", "cylinder")
VIEW_TIPS = {
    "lit": "Every lobe",
    "base": "The base's diffuse and specular only",
    "coat": "The clear coat's reflection only",
    "sheen": "The sheen only",
    "specular": "Every specular reflection: the base's and the coat's",
    "roughness": "Roughness as a grey level (linear)",
    "normal": "The world shading normal, N / 2 + 1/2",
    "coat-weight": "The clear coat's weight as a grey level (linear)",
    "anisotropy": "Stripes along the anisotropy direction over the dimmed surface; grey to "
                  "amber with the anisotropy",
}
MODES = {"Split-sum": "splitsum", "Reference": "reference", "Difference": "difference"}
ENVIRONMENTS = {"Studio": "studio", "Sky": "sky"}
OPEN_ENV = "Open HDR/EXR…"
ENV_FILTER = "HDR environments (*.hdr *.exr);;All files (*)"
SAVE_FILTER = "PNG image, as shown (*.png);;OpenEXR, linear radiance (*.exr)"


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
            try:  # bake the wanted environment once, not the default and then ours
                self.renderer = cls(self.ctx, size=size, samples=4,
                                    environment=self._environment)
                env_done = True
            except TypeError:
                self.renderer = cls(self.ctx, size=size, samples=4)
                env_done = False
            self._apply_view_state(set_environment=not env_done)
        except Exception as exc:
            self.renderer = None
            self.problem = f"renderer failed to start: {type(exc).__name__}: {exc}"
            return
        if self._pending_material is not None:
            cm, self._pending_material = self._pending_material, None
            self._apply_material(cm)
        self._flush_values()

    def _apply_view_state(self, set_environment: bool = True) -> None:
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
        if set_environment:
            self._set_environment_now(self._environment, None)

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
        self.frameDrawn.emit()
        if self.renderer.needs_redraw:
            QTimer.singleShot(0, self, self.update)  # reference mode accumulates until converged

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
                             environment=getattr(r, "environment_name", self._environment),
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

    def set_environment(self, spec: str, progress=None) -> None:
        """Bakes (or loads from cache) an environment; raises ValueError for a bad file."""
        self._environment = spec
        if self.renderer is not None:
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


class ViewportPanel(QWidget):
    """The viewport with its bar: mesh, IBL mode (difference mean), exposure, environment."""

    environmentChanged = Signal(str)
    statusMessage = Signal(str)
    glErrors = Signal(list)  # the view's: [(node id, message)] when a program fails to build
    materialApplied = Signal(bool)

    def __init__(self, compiler: MaterialCompiler, parent=None) -> None:
        super().__init__(parent)
        self.compiler = compiler
        self.controller = compiler.controller
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        bar = QWidget()
        bar.setObjectName("viewportBar")
        bl = QHBoxLayout(bar)
        bl.setContentsMargins(4, 3, 4, 3)
        bl.setSpacing(4)
        self.mesh_combo = QComboBox()
        self.mesh_combo.addItems(list(MESHES))
        self.mesh_combo.setToolTip("Preview mesh")
        self.mode_combo = QComboBox()
        self.mode_combo.addItems(list(MODES))
        self.mode_combo.setToolTip("Image-based lighting: split-sum approximation, brute-force "
                                   "reference, or their difference")
        self.view_combo = QComboBox()
        self.view_combo.setObjectName("viewChooser")
        for i, (name, (title, _, attribute)) in enumerate(VIEWS.items()):
            if attribute is not None and VIEWS[list(VIEWS)[i - 1]][2] is None:
                self.view_combo.insertSeparator(self.view_combo.count())
            self.view_combo.addItem(title, name)
            self.view_combo.setItemData(self.view_combo.count() - 1, VIEW_TIPS[name],
                                        Qt.ItemDataRole.ToolTipRole)
        self.view_combo.setToolTip("What the viewport shows: the lit material, some of its "
                                   "lobes only, or one of its fields")
        self.env_combo = QComboBox()
        self.env_combo.addItems([*ENVIRONMENTS, OPEN_ENV])
        self.env_combo.setToolTip("Environment lighting")
        self.exposure = QSlider(Qt.Orientation.Horizontal)
        self.exposure.setRange(-60, 60)  # tenths of EV: the arrow keys step 0.1 EV
        self.exposure.setSingleStep(1)
        self.exposure.setPageStep(10)
        self.exposure.setMinimumWidth(140)
        self.exposure.setToolTip("Exposure (EV); arrow keys step 0.1 EV, Page Up/Down 1 EV")
        self.exposure_spin = QDoubleSpinBox()
        self.exposure_spin.setRange(-6.0, 6.0)
        self.exposure_spin.setDecimals(1)
        self.exposure_spin.setSingleStep(0.1)
        self.exposure_spin.setSuffix(" EV")
        self.exposure_spin.setKeyboardTracking(False)
        self.exposure_spin.setToolTip("Exposure in EV (type a value; arrow keys step 0.1)")
        # Laid over the view's bottom edge (placed with the banner): its text never moves
        # anything, and it takes no room from the bar.
        self.diff_label = QLabel("", self)
        self.diff_label.setObjectName("diffMean")
        self.diff_label.setStyleSheet("background: rgba(20, 22, 27, 170); color: #d5d9e0;"
                                      " padding: 1px 6px;")
        self.diff_label.hide()
        self.diff_label.setToolTip("Reference and difference modes: samples a pixel so far, "
                                   "and the mean difference from the split-sum image")
        self.save_button = QToolButton()
        self.save_button.setIcon(icon("save"))
        self.save_button.setToolTip("Save the viewport image (PNG as shown, or linear EXR)")
        self.save_button.clicked.connect(self.save_image_dialog)
        reset = QToolButton()
        reset.setIcon(icon("reset"))
        reset.setToolTip("Reset the camera (or double-click the view)")
        for w in (self.mesh_combo, self.mode_combo, self.view_combo, self.env_combo):
            bl.addWidget(w)
        bl.addWidget(self.exposure, 1)
        bl.addWidget(self.exposure_spin)
        bl.addStretch(1)
        bl.addWidget(self.save_button)
        bl.addWidget(reset)
        lay.addWidget(bar)
        self.banner = QWidget(self)  # laid over the view's top edge: the view keeps its size
        self.banner.setObjectName("previewBanner")
        self.banner.setStyleSheet("#previewBanner { background: #6b4f12; }")
        bn = QHBoxLayout(self.banner)
        bn.setContentsMargins(8, 2, 4, 2)
        self.banner_label = QLabel("")
        self.banner_label.setStyleSheet("color: #ffe7a8; font-weight: bold;")
        self.banner_clear = QToolButton()
        self.banner_clear.setText("Show material")
        self.banner_clear.setToolTip("Stop previewing the node: show the whole material again")
        self.banner_clear.clicked.connect(lambda: compiler.set_preview(None))
        bn.addWidget(self.banner_label, 1)
        bn.addWidget(self.banner_clear)
        self.banner.hide()
        self.view = ViewportWidget()
        lay.addWidget(self.view, 1)
        self.failure = self._failure_notice()  # laid over the view: "does not compile"
        self._env_index = 0
        self.env_dialog = file_dialogs.open_file  # tests replace it
        self.save_dialog = file_dialogs.save_file  # tests replace it
        self.setAcceptDrops(True)  # an HDR/EXR dropped here becomes the environment
        self.mesh_combo.currentTextChanged.connect(self.view.set_mesh)
        self.mode_combo.currentTextChanged.connect(self._mode_changed)
        self.view_combo.currentIndexChanged.connect(self._view_changed)
        self.exposure.valueChanged.connect(self._exposure_changed)
        self.exposure_spin.valueChanged.connect(
            lambda ev: self.exposure.setValue(int(round(ev * 10))))
        self.env_combo.activated.connect(self._env_activated)
        reset.clicked.connect(lambda: self.view.renderer and (self.view.renderer.camera.reset(),
                                                              self.view.update()))
        self.view.frameDrawn.connect(self._frame_drawn)
        self.view.statusMessage.connect(self.statusMessage)
        self.view.glErrors.connect(self.glErrors)
        self.view.materialApplied.connect(self.materialApplied)
        compiler.compiled.connect(self.on_compiled)
        compiler.failed.connect(self._compile_failed)
        compiler.documentChanged.connect(self._document_changed)
        self.view.glErrors.connect(self._gl_failed)
        self.view.materialApplied.connect(lambda ok: ok and self._hide_failure())
        compiler.viewport_state = self.view.viewport_state
        compiler.previewChanged.connect(self._preview_changed)
        self.controller.valuesChanged.connect(self.push_values)

    # --- material --------------------------------------------------------------------------
    def on_compiled(self, compiled) -> None:
        self.view.set_material(compiled)
        self.push_values()

    # --- a document with nothing to draw -------------------------------------------------
    def _failure_notice(self) -> QWidget:
        box = QWidget(self)
        box.setObjectName("noMaterial")
        box.setStyleSheet("#noMaterial { background: rgba(28, 20, 22, 225);"
                          " border: 1px solid #b04a4a; border-radius: 4px; }")
        bl = QVBoxLayout(box)
        bl.setContentsMargins(14, 10, 14, 12)
        bl.setSpacing(6)
        self.failure_title = QLabel("")
        self.failure_title.setStyleSheet("color: #ff9c9c; font-weight: bold; font-size: 13pt;"
                                         " background: transparent; border: none;")
        self.failure_title.setAlignment(Qt.AlignmentFlag.AlignHCenter)
        self.failure_text = QLabel("")
        self.failure_text.setWordWrap(True)
        self.failure_text.setStyleSheet("color: #e4d6d6; background: transparent;"
                                        " border: none;")
        bl.addWidget(self.failure_title)
        bl.addWidget(self.failure_text)
        box.hide()
        return box

    def shows_material(self) -> bool:
        """Whether the view draws a material of the open document (False: the notice)."""
        return self.view.has_material and self.failure.isHidden()

    @property
    def failure_message(self) -> str:
        """The notice's title and text while it is shown, else ""."""
        if self.failure.isHidden():
            return ""
        return f"{self.failure_title.text()}\n{self.failure_text.text()}"

    def _document_changed(self) -> None:
        self.view.clear_material()
        self._hide_failure()

    def _compile_failed(self, diagnostics) -> None:
        """A compile failed: with an earlier good version of this document the view keeps
        drawing it; without one it draws no material and says why."""
        if self.compiler.latest is not None and self.view.has_material:
            return
        self.view.clear_material()
        errors = [d.format() for d in diagnostics if getattr(d.severity, "value", "") == "error"]
        self._show_failure("This material does not compile",
                           errors or [d.format() for d in diagnostics])

    def _gl_failed(self, errors) -> None:
        if self.view.has_material:
            return  # this document's last good program is still drawn
        self._show_failure("This material's GLSL does not build",
                           [f"node {nid}: {msg}" if nid else str(msg) for nid, msg in errors])

    def _show_failure(self, title: str, lines: list[str]) -> None:
        shown = [line if len(line) <= 300 else line[:297] + "…" for line in lines[:4]]
        more = len(lines) - len(shown)
        text = "\n".join(f"• {line}" for line in shown)
        if more > 0:
            text += f"\n… and {more} more"
        text += "\n\nThe viewport shows no material until it compiles. " \
                "The errors are listed in Diagnostics."
        self.failure_title.setText(title)
        self.failure_text.setText(text.strip())
        self.failure.show()
        self.failure.raise_()
        self._place_banner()

    def _hide_failure(self) -> None:
        self.failure.hide()

    def push_values(self) -> None:
        cm = self.compiler.latest  # never waits for a compile in flight
        if cm is None:
            return
        doc = self.controller.document
        self.view.set_values(uniform_values(cm, doc), texture_paths(cm, doc))

    # --- the typed interface the window uses ------------------------------------------------
    def set_lights(self, lights: list) -> None:
        self.view.set_lights(lights)

    def renderer_lights(self) -> list | None:
        """The renderer's light rig once it runs; None while it starts; [] if it cannot."""
        if self.view.renderer is not None:
            return self.view.lights
        return [] if self.view.problem else None

    def gl_renderer(self) -> str:
        return self.view.gl_renderer()

    # --- saving the picture; dropped environments -------------------------------------------
    def save_image_dialog(self) -> bool:
        path, _ = self.save_dialog(self, "Save the viewport image", "viewport.png",
                                   SAVE_FILTER)
        return bool(path) and self.save_image(path)

    def _inputs(self) -> dict[Path, str]:
        """Files the document reads (matedit.io.inputs: the document, its functions and
        layers, every texture, live or not), and the viewport's environment file."""
        from matedit.io.inputs import document_inputs

        out = document_inputs(self.controller.document, self.controller.resolver)
        if Path(self.view._environment).suffix:
            out.setdefault(Path(os.path.realpath(self.view._environment)), "the environment")
        return out

    def save_image(self, path: str | Path) -> bool:
        """The current frame as PNG (display-referred, as shown) or as EXR (scene-linear
        radiance, before exposure and display transform)."""
        path = Path(path)
        if path.suffix.lower() not in (".png", ".exr"):
            path = path.with_suffix(path.suffix + ".png") if path.suffix else \
                path.with_suffix(".png")
        from matedit.io.inputs import OverwriteError, refuse_overwrite

        try:
            refuse_overwrite([path], self._inputs())
        except OverwriteError:
            self.statusMessage.emit(f"{path.name} is a file the material reads: not "
                                    "overwritten")
            return False
        if self.view.renderer is None:
            self.statusMessage.emit("no image to save: the renderer is not running")
            return False
        try:
            if path.suffix.lower() == ".exr":
                from matedit.io.images import write_image

                write_image(path, self.view.read_hdr())
            else:
                from PySide6.QtCore import QBuffer, QByteArray, QIODevice

                from matedit.io.atomic import atomic_write_bytes

                data = QByteArray()
                buf = QBuffer(data)
                buf.open(QIODevice.OpenModeFlag.WriteOnly)
                if not self.view.grabFramebuffer().save(buf, "PNG"):
                    raise OSError("PNG encoding failed")
                buf.close()
                atomic_write_bytes(path, bytes(data.data()))
        except (OSError, ValueError) as exc:
            self.statusMessage.emit(f"cannot save {path.name}: {exc}")
            return False
        self.statusMessage.emit(f"saved the viewport image to {path}")
        return True

    @staticmethod
    def _dropped_environment(mime) -> str:
        for url in mime.urls() if mime.hasUrls() else []:
            p = url.toLocalFile()
            if p and Path(p).suffix.lower() in (".hdr", ".exr"):
                return p
        return ""

    def dragEnterEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if self._dropped_environment(event.mimeData()):
            event.acceptProposedAction()
        else:
            event.ignore()

    def dragMoveEvent(self, event) -> None:  # noqa: N802 - Qt's name
        self.dragEnterEvent(event)

    def dropEvent(self, event) -> None:  # noqa: N802 - Qt's name
        path = self._dropped_environment(event.mimeData())
        if not path:
            event.ignore()
            return
        event.acceptProposedAction()
        self.choose_environment(path)

    def _preview_changed(self, target) -> None:
        if target is None:
            self.banner.hide()
            return
        self.banner_label.setText(f"Previewing {target.label()}, not the material")
        self._place_banner()
        self.banner.show()
        self.banner.raise_()

    def _place_banner(self) -> None:
        g = self.view.geometry()
        self.banner.setGeometry(g.x(), g.y(), g.width(), self.banner.sizeHint().height())
        if not self.failure.isHidden():
            width = max(120, min(g.width() - 24, 560))
            height = min(g.height() - 16, self.failure.heightForWidth(width)
                         if self.failure.hasHeightForWidth() else
                         self.failure.sizeHint().height())
            self.failure.setGeometry(g.x() + (g.width() - width) // 2,
                                     g.y() + max(8, (g.height() - height) // 2),
                                     width, max(40, height))
        self.diff_label.adjustSize()
        self.diff_label.move(g.x() + 4, g.y() + g.height() - self.diff_label.height() - 4)

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        self._place_banner()

    # --- bar -------------------------------------------------------------------------------
    def _mode_changed(self, text: str) -> None:
        self.view.set_mode(MODES[text])
        self.diff_label.setText("")
        self.diff_label.setVisible(MODES[text] != "splitsum")

    def _view_changed(self, index: int) -> None:
        view = self.view_combo.itemData(index)
        if isinstance(view, str):  # not a separator
            self.view.set_view(view)
            if self.view.shading_view != view:  # refused (a failed link): show what is drawn
                self.set_view(self.view.shading_view)

    def set_view(self, view: str) -> None:
        """Chooses a view (matedit.shading.views name) as the chooser does."""
        self.view_combo.setCurrentIndex(self.view_combo.findData(view))

    def _exposure_changed(self, tenths: int) -> None:
        ev = tenths / 10.0
        self.exposure_spin.blockSignals(True)
        self.exposure_spin.setValue(ev)
        self.exposure_spin.blockSignals(False)
        self.view.set_exposure(ev)

    def _frame_drawn(self) -> None:
        r = self.view.renderer
        if r is None or r.mode == "splitsum":
            return
        total = r.reference_frames * r.reference_samples
        done = min(r.accumulated_frames, r.reference_frames) * r.reference_samples
        text = f"{done}/{total} samples" if not r.converged else f"{total} samples"
        if r.mode == "difference" and r.converged:
            mean = r.difference_mean
            if mean is not None:
                text += f" · mean |Δ| {float(mean):.4f}"
        self.diff_label.setText(text)
        self._place_banner()
        self.diff_label.raise_()

    def view_state(self) -> dict:
        """Mesh, mode, exposure, environment and energy compensation, as remembered across
        restarts."""
        return {"mesh": self.mesh_combo.currentText(), "mode": self.mode_combo.currentText(),
                "exposure": self.exposure.value() / 10.0,
                "environment": self.view._environment,
                "energy_compensation": self.view.settings.energy_compensation}

    def restore_view_state(self, state: dict) -> None:
        mesh, mode = state.get("mesh"), state.get("mode")
        if isinstance(mesh, str) and mesh in MESHES:
            self.mesh_combo.setCurrentText(mesh)
        if isinstance(mode, str) and mode in MODES:
            self.mode_combo.setCurrentText(mode)
        ev = state.get("exposure")
        if isinstance(ev, (int, float)):
            self.exposure.setValue(int(round(float(ev) * 10)))
        energy = state.get("energy_compensation")
        if isinstance(energy, bool):
            self.view.change_settings(energy_compensation=energy)
        env = state.get("environment")
        if isinstance(env, str) and env and env != self.view._environment and (
                env in ENVIRONMENTS.values() or Path(env).is_file()):
            self.choose_environment(env)

    def document_preview(self, saved_as: Path) -> dict:
        """The mesh and environment to store in a document saved as `saved_as`: a user HDR
        as a path relative to the document, like every reference it holds."""
        import os

        from matedit.io.inputs import as_reference

        env = self.view._environment
        if env not in ENVIRONMENTS.values():
            try:  # a file named like a built-in is written as ./studio
                env = as_reference(Path(os.path.relpath(Path(env).resolve(), Path(
                    saved_as).resolve().parent)).as_posix(), "environment")
            except ValueError:  # another drive
                env = Path(env).resolve().as_posix()
        return {"mesh": self.mesh_combo.currentText(), "environment": env}

    def set_preview(self, preview: dict, doc_path: Path | None = None) -> None:
        """Mesh and environment stored with a document (a file relative to `doc_path`)."""
        from matedit.io.inputs import BUILTIN_PREFIX

        mesh = preview.get("mesh")  # `cube` or `builtin:cube`
        if isinstance(mesh, str) and mesh.removeprefix(BUILTIN_PREFIX) in MESHES:
            self.mesh_combo.setCurrentText(mesh.removeprefix(BUILTIN_PREFIX))
        env = preview.get("environment")
        if not isinstance(env, str) or not env:
            return
        if env.removeprefix(BUILTIN_PREFIX) in ENVIRONMENTS.values():
            env = env.removeprefix(BUILTIN_PREFIX)
        else:
            p = Path(env)
            if not p.is_absolute() and doc_path is not None:
                p = Path(doc_path).resolve().parent / p
            if not p.is_file():
                self.statusMessage.emit(f"the document's environment {env} is missing")
                return
            env = str(p.resolve())
        if env != self.view._environment:
            self.choose_environment(env)

    def _env_activated(self, index: int) -> None:
        text = self.env_combo.itemText(index)
        if text == OPEN_ENV:
            path, _ = self.env_dialog(self, "Open an HDR environment", "", ENV_FILTER)
            if not path:
                self.env_combo.setCurrentIndex(self._env_index)
                return
            self.choose_environment(path)
            return
        spec = ENVIRONMENTS.get(text) or self.env_combo.itemData(index) or text
        self.choose_environment(spec)

    def choose_environment(self, spec: str) -> bool:
        """Bakes `spec` (studio, sky or a file) with a progress dialog; False on a bad file."""
        label = next((k for k, v in ENVIRONMENTS.items() if v == spec), Path(spec).name)
        dlg = QProgressDialog(f"Baking environment {label}…", "", 0, 100, self)
        dlg.setWindowTitle("Environment")
        dlg.setCancelButton(None)
        dlg.setMinimumDuration(400)
        dlg.setWindowModality(Qt.WindowModality.WindowModal)

        def progress(fraction: float) -> None:
            dlg.setValue(int(max(0.0, min(1.0, fraction)) * 100))
            QApplication.processEvents()

        try:
            self.view.set_environment(spec, progress)
        except (ValueError, OSError) as exc:
            dlg.close()
            QMessageBox.warning(self, "Environment", f"Cannot use {spec}:\n{exc}")
            self.env_combo.setCurrentIndex(self._env_index)
            return False
        finally:
            dlg.setValue(100)
            dlg.close()
        if spec not in ENVIRONMENTS.values():
            idx = self.env_combo.findData(spec)
            if idx < 0:
                self.env_combo.insertItem(self.env_combo.count() - 1, Path(spec).name, spec)
                idx = self.env_combo.findData(spec)
        else:
            idx = self.env_combo.findText(label)
        self.env_combo.setCurrentIndex(idx)
        self._env_index = idx
        self.environmentChanged.emit(spec)
        return True


class EnvironmentPanel(QWidget):
    """The environment half of the Lights & Environment dock: the same choice as the viewport
    bar (one shared list), the background, its blur, and the IBL intensity."""

    def __init__(self, viewport: ViewportPanel, parent=None) -> None:
        super().__init__(parent)
        from PySide6.QtWidgets import QCheckBox, QFormLayout

        from matedit.app.fields import FloatField

        self.viewport = viewport
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 0)
        title = QLabel("Environment")
        title.setObjectName("sectionHeader")
        lay.addWidget(title)
        form = QFormLayout()
        form.setLabelAlignment(Qt.AlignmentFlag.AlignRight)
        self.combo = QComboBox()
        self.combo.setModel(viewport.env_combo.model())
        self.combo.setCurrentIndex(viewport.env_combo.currentIndex())
        self.combo.activated.connect(self._chosen)
        viewport.env_combo.currentIndexChanged.connect(self.combo.setCurrentIndex)
        form.addRow("image", self.combo)
        self.intensity = FloatField(1.0, (0.0, 4.0))
        self.intensity.setToolTip("Multiplies the environment's light")
        self.intensity.edited.connect(
            lambda v, _m: viewport.view.change_settings(environment_intensity=float(v)))
        form.addRow("intensity", self.intensity)
        self.background = QCheckBox("show behind the mesh")
        self.background.setChecked(True)
        self.background.toggled.connect(
            lambda on: viewport.view.change_settings(show_background=bool(on)))
        form.addRow("background", self.background)
        self.blur = FloatField(0.0, (0.0, 1.0))
        self.blur.setToolTip("Blurs the background only (lighting is unchanged)")
        self.blur.edited.connect(
            lambda v, _m: viewport.view.change_settings(background_blur=float(v)))
        form.addRow("blur", self.blur)
        self.energy = QCheckBox("energy compensation")
        self.energy.setToolTip("Adds back the light that single-scattering GGX loses on rough "
                               "surfaces (multiple scattering), for every material")
        self.energy.setChecked(viewport.view.settings.energy_compensation)
        self.energy.toggled.connect(
            lambda on: viewport.view.change_settings(energy_compensation=bool(on)))
        viewport.view.settingsChanged.connect(self._settings_changed)
        form.addRow("shading", self.energy)
        lay.addLayout(form)

    def _settings_changed(self, settings: RenderSettings) -> None:
        if self.energy.isChecked() != settings.energy_compensation:
            self.energy.blockSignals(True)
            self.energy.setChecked(settings.energy_compensation)
            self.energy.blockSignals(False)

    def _chosen(self, index: int) -> None:
        self.viewport.env_combo.setCurrentIndex(index)
        self.viewport._env_activated(index)
        self.combo.setCurrentIndex(self.viewport.env_combo.currentIndex())
