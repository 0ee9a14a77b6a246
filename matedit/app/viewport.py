"""The 3D preview: a QOpenGLWidget hosting `matedit.render.Renderer`, and its tool bar.

The moderngl context is created once in `initializeGL` and every frame draws into
Qt's framebuffer (`detect_framebuffer(defaultFramebufferObject())`). A structural
edit arrives as a new `CompiledMaterial` (`set_material`): when it fails to link,
the renderer keeps its last good program, and the errors, located on nodes, go
out through `glErrors`. A value edit only sets uniforms and redraws.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from PySide6.QtCore import QPointF, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMessageBox,
    QProgressDialog,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app.compile_service import MaterialCompiler, texture_paths, uniform_values
from matedit.app.theme import icon

MESHES = ("sphere", "cube", "plane", "cylinder")
MODES = {"Split-sum": "splitsum", "Reference": "reference", "Difference": "difference"}
ENVIRONMENTS = {"Studio": "studio", "Sky": "sky"}
OPEN_ENV = "Open HDR/EXR…"
ENV_FILTER = "HDR environments (*.hdr *.exr);;All files (*)"


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
        self._exposure = 0.0
        self._lights = None
        self._last = QPointF()
        self._button = Qt.MouseButton.NoButton
        self.frames = 0
        self.last_frame_time = 0.0
        self._fbo = None
        self._fbo_glo = -1
        self._options: dict[str, Any] = {}

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
        for name, value in self._options.items():
            if hasattr(r, name):
                setattr(r, name, value)
        if self._lights is not None:
            r.set_lights(list(self._lights))
        else:
            self._lights = list(getattr(r, "lights", []) or [])
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
        if getattr(self.renderer, "needs_redraw", False):
            QTimer.singleShot(0, self, self.update)  # reference mode accumulates until converged

    def _paint_message(self, text: str) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor("#17191e"))
        p.setPen(QColor("#8a91a0"))
        p.drawText(self.rect().adjusted(12, 12, -12, -12),
                   Qt.AlignmentFlag.AlignCenter | Qt.TextFlag.TextWordWrap, text)
        p.end()

    # --- material and values ---------------------------------------------------------------
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
        ok = bool(getattr(status, "ok", True))
        if not ok:
            self.glErrors.emit(list(getattr(status, "errors", []) or []))
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

    def set_exposure(self, ev: float) -> None:
        self._exposure = float(ev)
        if self.renderer is not None:
            self.renderer.exposure = float(ev)
            self.update()

    def set_render_option(self, name: str, value) -> None:
        """A renderer attribute that needs no GL work (background, blur, IBL intensity)."""
        self._options[name] = value
        if self.renderer is not None and hasattr(self.renderer, name):
            setattr(self.renderer, name, value)
            if hasattr(self.renderer, "reset_accumulation"):
                self.renderer.reset_accumulation()
            self.update()

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
        self.env_combo = QComboBox()
        self.env_combo.addItems([*ENVIRONMENTS, OPEN_ENV])
        self.env_combo.setToolTip("Environment lighting")
        self.exposure = QSlider(Qt.Orientation.Horizontal)
        self.exposure.setRange(-60, 60)  # tenths of EV
        self.exposure.setFixedWidth(90)
        self.exposure.setToolTip("Exposure (EV)")
        self.exposure_label = QLabel("0.0 EV")
        self.exposure_label.setMinimumWidth(44)
        self.diff_label = QLabel("")
        self.diff_label.setObjectName("diffMean")
        reset = QToolButton()
        reset.setIcon(icon("reset"))
        reset.setToolTip("Reset the camera (or double-click the view)")
        for w in (self.mesh_combo, self.mode_combo, self.env_combo):
            bl.addWidget(w)
        bl.addWidget(self.exposure)
        bl.addWidget(self.exposure_label)
        bl.addWidget(self.diff_label)
        bl.addStretch(1)
        bl.addWidget(reset)
        lay.addWidget(bar)
        self.view = ViewportWidget()
        lay.addWidget(self.view, 1)
        self._env_index = 0
        self._custom_envs: list[str] = []
        self.env_dialog = QFileDialog.getOpenFileName  # tests replace it
        self.mesh_combo.currentTextChanged.connect(self.view.set_mesh)
        self.mode_combo.currentTextChanged.connect(self._mode_changed)
        self.exposure.valueChanged.connect(self._exposure_changed)
        self.env_combo.activated.connect(self._env_activated)
        reset.clicked.connect(lambda: self.view.renderer and (self.view.renderer.camera.reset(),
                                                              self.view.update()))
        self.view.frameDrawn.connect(self._frame_drawn)
        self.view.statusMessage.connect(self.statusMessage)
        compiler.compiled.connect(self.on_compiled)
        self.controller.valuesChanged.connect(self.push_values)

    # --- material --------------------------------------------------------------------------
    def on_compiled(self, compiled) -> None:
        self.view.set_material(compiled)
        self.push_values()

    def push_values(self) -> None:
        cm = self.compiler.latest  # never waits for a compile in flight
        if cm is None:
            return
        doc = self.controller.document
        self.view.set_values(uniform_values(cm, doc), texture_paths(cm, doc))

    # --- bar -------------------------------------------------------------------------------
    def _mode_changed(self, text: str) -> None:
        self.view.set_mode(MODES[text])
        self.diff_label.setText("")

    def _exposure_changed(self, tenths: int) -> None:
        ev = tenths / 10.0
        self.exposure_label.setText(f"{ev:+.1f} EV")
        self.view.set_exposure(ev)

    def _frame_drawn(self) -> None:
        r = self.view.renderer
        if r is not None and getattr(r, "mode", "") == "difference":
            mean = getattr(r, "difference_mean", None)
            if mean is not None:
                self.diff_label.setText(f"mean |Δ| {float(mean):.4f}")

    def set_preview(self, preview: dict) -> None:
        """Mesh and environment stored with a document."""
        mesh = preview.get("mesh")
        if isinstance(mesh, str) and mesh in MESHES:
            self.mesh_combo.setCurrentText(mesh)
        env = preview.get("environment")
        if isinstance(env, str) and env in ENVIRONMENTS.values() and \
                env != self.view._environment:
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
            lambda v, _m: viewport.view.set_render_option("environment_intensity", float(v)))
        form.addRow("intensity", self.intensity)
        self.background = QCheckBox("show behind the mesh")
        self.background.setChecked(True)
        self.background.toggled.connect(
            lambda on: viewport.view.set_render_option("show_background", bool(on)))
        form.addRow("background", self.background)
        self.blur = FloatField(0.0, (0.0, 1.0))
        self.blur.setToolTip("Blurs the background only (lighting is unchanged)")
        self.blur.edited.connect(
            lambda v, _m: viewport.view.set_render_option("background_blur", float(v)))
        form.addRow("blur", self.blur)
        lay.addLayout(form)

    def _chosen(self, index: int) -> None:
        self.viewport.env_combo.setCurrentIndex(index)
        self.viewport._env_activated(index)
        self.combo.setCurrentIndex(self.viewport.env_combo.currentIndex())
