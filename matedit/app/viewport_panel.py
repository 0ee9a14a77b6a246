"""The viewport panel: the GL view (`matedit.app.viewport`) under its tool bar (mesh, IBL
mode, shading view, environment, exposure, save, camera reset), with the notices laid over
it (previewing a socket, a material that does not compile) and the view state kept across
restarts and stored with documents."""

from __future__ import annotations

import copy
import os
from pathlib import Path

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QMenu,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.compile_service import (
    VIEWPORT_TARGET,
    MaterialCompiler,
    uniform_values,
    uniforms_by_port,
)
from matedit.app.controller import ValueChange
from matedit.app.environment import ENVIRONMENTS, EnvironmentChoice, environment_combo
from matedit.app.node_preview import PreviewTarget
from matedit.app.paths import texture_paths
from matedit.app.theme import icon
from matedit.app.viewport import ViewportWidget
from matedit.shading.views import VIEWS

MESHES = ("sphere", "cube", "plane", "cylinder")
VIEW_TIPS = {
    "lit": "Every lobe",
    "base": "The base's diffuse and specular only",
    "coat": "The clear coat's reflection only",
    "sheen": "The sheen only",
    "subsurface": "The subsurface diffuse only: wrapped, and transmitted from behind",
    "transmission": "The specular transmission only: the environment and lights seen through",
    "specular": "Every specular reflection: the base's and the coat's",
    "roughness": "Roughness as a grey level (linear)",
    "normal": "The world shading normal, N / 2 + 1/2",
    "coat-weight": "The clear coat's weight as a grey level (linear)",
    "anisotropy": "Stripes along the anisotropy direction over the dimmed surface; grey to "
                  "amber with the anisotropy",
    "thin-film": "The thin film's thickness in micrometres as a grey level (linear)",
}
OBJ_ITEM = "OBJ file…"
OBJ_FILTER = "Wavefront OBJ (*.obj)"
MODES = {"Split-sum": "splitsum", "Reference": "reference", "Difference": "difference"}
SAVE_FILTER = "PNG image, as shown (*.png);;OpenEXR, linear radiance (*.exr)"


class ViewportPanel(QWidget):
    """The viewport with its bar: mesh, IBL mode (difference mean), exposure, environment."""

    environmentChanged = Signal(str)  # the EnvironmentChoice's `changed`
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
        self.mesh_combo.insertSeparator(len(MESHES))
        self.mesh_combo.addItem(OBJ_ITEM, OBJ_ITEM)
        self.mesh_combo.setToolTip("Preview mesh: a built-in one, or an OBJ file of yours")
        self._mesh_index = 0  # the entry shown (OBJ… goes back to it when cancelled)
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
        # as wide as its short names; the popup lists the long ones in full
        self.view_combo.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.view_combo.setMinimumContentsLength(9)
        self.view = ViewportWidget()
        self.environment = EnvironmentChoice(self.view, self, self)
        self.env_combo = environment_combo(self.environment)
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
        # View › Follow Selection, and its button on the bar
        # (no icon on the action: it would be drawn instead of the menu's check mark)
        self.follow_action = QAction("&Follow Selection in Viewport", self)
        self.follow_action.setObjectName("view.follow_selection")
        self.follow_action.setCheckable(True)
        self.follow_action.setToolTip("Follow the selection: the viewport previews the node you "
                                      "select (pin the banner to keep one while you select "
                                      "others)")
        self.follow_action.toggled.connect(self._follow_toggled)
        self.follow_button = QToolButton()
        self.follow_button.setObjectName("followSelection")
        self.follow_button.setIcon(icon("follow"))
        self.follow_button.setCheckable(True)
        self.follow_button.setToolTip(self.follow_action.toolTip())
        self.follow_button.toggled.connect(self.follow_action.setChecked)
        self.follow_action.toggled.connect(self.follow_button.setChecked)
        # View › A/B Split, and its button: the material before the last structural edit
        # (A, left of the divider) against the material now (B)
        self.ab_action = QAction("A/B &Split: Before the Last Edit", self)
        self.ab_action.setObjectName("view.ab_split")
        self.ab_action.setCheckable(True)
        self.ab_action.setIconText("A/B")
        self.ab_action.setToolTip("A/B split: the material before the last structural edit on "
                                  "the left, as it is now on the right (drag the divider; "
                                  "right-click to compare with an instance instead)")
        self.ab_action.toggled.connect(self._ab_toggled)
        self.ab_button = QToolButton()
        self.ab_button.setObjectName("abSplit")
        self.ab_button.setDefaultAction(self.ab_action)
        self.ab_button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        # what A is: the material before the last edit, or one of its instances (View ›
        # A/B Split Against, and the button's right-click menu: no arrow widens the bar)
        self.ab_menu = QMenu("A/B Split A&gainst", self)
        self.ab_menu.setObjectName("abSourceMenu")
        self.ab_menu.aboutToShow.connect(self._fill_ab_menu)
        self.ab_button.setContextMenuPolicy(Qt.ContextMenuPolicy.CustomContextMenu)
        self.ab_button.customContextMenuRequested.connect(
            lambda pos: self.ab_menu.popup(self.ab_button.mapToGlobal(pos)))
        # (name, path) of the instance files of the open material; set by the window
        self.instances_of = lambda: []
        self._ab_instance: tuple[str, Path] | None = None
        self._ab_refresh = QTimer(self)  # an instance as A follows the material's edits
        self._ab_refresh.setSingleShot(True)
        self._ab_refresh.setInterval(250)
        self._ab_refresh.timeout.connect(self._refresh_instance_compare)
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
        bl.addWidget(self.ab_button)
        bl.addWidget(self.follow_button)
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
        self.banner_clear.clicked.connect(self.show_material)
        self.pin_button = QToolButton()
        self.pin_button.setObjectName("pinPreview")
        self.pin_button.setIcon(icon("pin"))
        self.pin_button.setText("Pin")
        self.pin_button.setCheckable(True)
        self.pin_button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        self.pin_button.setToolTip("Keep previewing this node while you select others")
        self.pin_button.toggled.connect(lambda _on: self._preview_changed(compiler.preview))
        self.pin_button.clicked.connect(self._pin_clicked)
        self.pin_button.hide()
        bn.addWidget(self.banner_label, 1)
        bn.addWidget(self.pin_button)
        bn.addWidget(self.banner_clear)
        self.banner.hide()
        lay.addWidget(self.view, 1)
        self.failure = self._failure_notice()  # laid over the view: "does not compile"
        self.save_dialog = file_dialogs.save_file  # tests replace it
        from matedit.app.image_dialog import ImageSizeDialog

        self.size_dialog = ImageSizeDialog  # so do they
        self.setAcceptDrops(True)  # an HDR/EXR dropped here becomes the environment
        self.mesh_combo.currentIndexChanged.connect(self._mesh_chosen)
        self.mode_combo.currentTextChanged.connect(self._mode_changed)
        self.view_combo.currentIndexChanged.connect(self._view_changed)
        self.exposure.valueChanged.connect(self._exposure_changed)
        self.exposure_spin.valueChanged.connect(
            lambda ev: self.exposure.setValue(int(round(ev * 10))))
        self.environment.changed.connect(self.environmentChanged)
        reset.clicked.connect(self.view.reset_camera)
        self.view.frameDrawn.connect(self._frame_drawn)
        self.view.statusMessage.connect(self.statusMessage)
        self.view.glErrors.connect(self.glErrors)
        self.view.viewRefused.connect(self.set_view)  # a failed link: show what is drawn
        self.view.materialApplied.connect(self.materialApplied)
        compiler.compiled.connect(self.on_compiled)
        compiler.failed.connect(self._compile_failed)
        compiler.documentChanged.connect(self._document_changed)
        self.view.glErrors.connect(self._gl_failed)
        self.view.materialApplied.connect(lambda ok: ok and self._hide_failure())
        compiler.viewport_state = self.view.viewport_state
        compiler.previewChanged.connect(self._preview_changed)
        self.controller.valuesChanged.connect(self._values_changed)
        self._by_port: tuple[object, dict] = (None, {})  # (compiled, uniforms_by_port)
        # the material canvas's selection and its previewable outputs (follow_selection)
        self._selection: tuple[list[str], object] = ([], lambda _nid: "")
        # A/B split: what the view shows now, and what it showed before the last structural
        # edit: (compiled, uniform values, texture files) each
        self._shown: list = [None, {}, {}]
        self._before: tuple | None = None
        self.divider = SplitDivider(self)
        self.divider.moved.connect(self._divider_moved)
        self.a_label = _overlay_label(self, "abLabelA")
        self.b_label = _overlay_label(self, "abLabelB")
        for w in (self.divider, self.a_label, self.b_label):
            w.hide()

    # --- material --------------------------------------------------------------------------
    def on_compiled(self, compiled) -> None:
        old = self._shown[0]
        if old is not None and old.structure_hash != compiled.structure_hash:
            self._before = (old, dict(self._shown[1]), dict(self._shown[2]))
        self._shown = [compiled, {}, {}]
        self.view.set_material(compiled)
        self.push_values()
        if self.comparing:
            if self._ab_instance is not None:
                self._ab_refresh.start()
            else:
                self._apply_compare()

    def _send_values(self, uniforms: dict, textures: dict) -> None:
        """Values to the view, kept as what it shows (the A side of a later A/B split)."""
        self._shown[1].update(uniforms)
        self._shown[2].update(textures)
        self.view.set_values(uniforms, textures)

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
        self._shown, self._before = [None, {}, {}], None  # another document: no "before"
        self._ab_instance = None
        if self.comparing:
            self.ab_action.setChecked(False)

    # --- A/B split -------------------------------------------------------------------------
    @property
    def comparing(self) -> bool:
        return self.ab_action.isChecked()

    def set_comparing(self, on: bool) -> None:
        self.ab_action.setChecked(on)

    def _ab_toggled(self, on: bool) -> None:
        if on:
            self._apply_compare()
        else:
            self.view.set_compare(None)
        for w in (self.divider, self.a_label, self.b_label):
            w.setVisible(on)
        self._place_banner()

    def _fill_ab_menu(self) -> None:
        """Before the last edit, and each instance of the open material, as A."""
        self.ab_menu.clear()
        group = QActionGroup(self.ab_menu)
        entries: list[tuple[str, tuple[str, Path] | None]] = [("Before the Last Edit", None)]
        entries += [(f"Against Instance \u2018{name}\u2019", (name, Path(path)))
                    for name, path in self.instances_of()]
        for text, source in entries:
            act = self.ab_menu.addAction(text)
            act.setCheckable(True)
            act.setChecked(self.comparing and source == self._ab_instance)
            group.addAction(act)
            act.triggered.connect(lambda _c=False, s=source: self.compare_with(s))
        if len(entries) == 1:
            none = self.ab_menu.addAction("No instance of this material in the Library or "
                                          "its folder")
            none.setEnabled(False)

    def compare_with(self, instance: tuple[str, Path] | None) -> None:
        """A/B split with A the material before the last edit (None) or the instance
        (name, file) of the open material, its overrides on the material as it is now."""
        self._ab_instance = instance
        if self.comparing:
            self._apply_compare()
        else:
            self.ab_action.setChecked(True)

    def _refresh_instance_compare(self) -> None:
        if self.comparing and self._ab_instance is not None:
            self._apply_compare()

    def _instance_compare(self) -> bool:
        """A: the instance's effective material on the open document (False: it cannot be
        drawn; the status bar says why and the split falls back to before the last edit)."""
        from matedit.compiler import compile_document
        from matedit.io.instance import InstanceError, load_instance, resolve

        assert self._ab_instance is not None
        name, path = self._ab_instance
        root = copy.copy(self.controller.document)
        root.graph = root.graph.copy()  # without the editor's listeners
        try:
            r = resolve(load_instance(path), root=root)
            if r.errors:
                raise InstanceError(r.errors[0].file, r.errors[0].message,
                                    r.errors[0].parameter)
            compiled = compile_document(r.document, self.controller.resolver, VIEWPORT_TARGET)
        except Exception as exc:  # noqa: BLE001 - the split is an aid: say why, keep drawing
            self.statusMessage.emit(f"A/B split: instance {name}: {exc}")
            self._ab_instance = None
            return False
        self.view.set_compare(compiled, {}, {})
        self.a_label.setText(f"A \u00b7 instance {name}")
        self.b_label.setText("B \u00b7 the material now")
        self._place_banner()
        return True

    def _apply_compare(self) -> None:
        """A: the material before the last structural edit (the material now, until there is
        one), with the values it was drawn with; or an instance (compare_with)."""
        if self._ab_instance is not None and self._instance_compare():
            return
        before = self._before
        if before is None and self._shown[0] is not None:
            before = (self._shown[0], dict(self._shown[1]), dict(self._shown[2]))
        if before is None:
            return
        self.view.set_compare(*before)
        self.a_label.setText("A · before the last edit" if self._before is not None else
                             "A · as it was when the split began")
        self.b_label.setText("B · now")
        self._place_banner()

    def _divider_moved(self, x: int) -> None:
        g = self.view.geometry()
        self.view.set_split((x - g.x()) / max(1, g.width()))
        self._place_banner()

    def _compile_failed(self, diagnostics) -> None:
        """A compile failed: with an earlier good version of this document the view keeps
        drawing it; without one it draws no material and says why."""
        if self.compiler.latest is not None and self.view.has_material:
            return
        self.view.clear_material()
        errors = [d.format() for d in diagnostics if d.severity.value == "error"]
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
        """Every uniform and texture of the material, from the document."""
        cm = self.compiler.latest  # never waits for a compile in flight
        if cm is None:
            return
        doc = self.controller.document
        self._send_values(uniform_values(cm, doc), texture_paths(cm, doc))

    def _values_changed(self, change: ValueChange) -> None:
        """One port's edit sets the uniforms that read it; a setting (a texture's path), many
        values at once, or a view whose GL is not up yet gets everything."""
        cm = self.compiler.latest
        if cm is None:
            return
        if change.many or change.setting or not self.view.running:
            self.push_values()
            return
        if self._by_port[0] is not cm:
            self._by_port = (cm, uniforms_by_port(cm))
        uniforms = self._by_port[1].get((change.node, change.port))
        if self.comparing and self._ab_instance is not None:
            self._ab_refresh.start()  # the instance's values not overridden follow
        if uniforms:
            self._send_values(uniform_values(cm, self.controller.document, uniforms), {})

    # --- the typed interface the window uses ------------------------------------------------
    def set_lights(self, lights: list) -> None:
        self.view.set_lights(lights)

    def renderer_lights(self) -> list | None:
        """The renderer's light rig once it runs; None while it starts; [] if it cannot."""
        if self.view.running:
            return self.view.lights
        return [] if self.view.problem else None

    def gl_renderer(self) -> str:
        return self.view.gl_renderer()

    # --- saving the picture; dropped environments -------------------------------------------
    def save_image_dialog(self) -> bool:
        """File › Save Viewport Image: the size (the view's, or any other, drawn offscreen)
        and the format, then where."""
        view_size = self.view_pixels()
        dlg = self.size_dialog(view_size, self)
        if not dlg.exec():
            return False
        size, fmt = dlg.chosen()
        name = "viewport." + fmt
        path, _ = self.save_dialog(self, "Save the viewport image", name,
                                   SAVE_FILTER if fmt == "png" else
                                   ";;".join(reversed(SAVE_FILTER.split(";;"))))
        if not path:
            return False
        return self.save_image(path, None if size == view_size else size)

    def view_pixels(self) -> tuple[int, int]:
        dpr = self.view.devicePixelRatioF()
        return (max(1, int(self.view.width() * dpr)), max(1, int(self.view.height() * dpr)))

    def _inputs(self) -> dict[Path, str]:
        """Files the document reads (matedit.io.inputs: the document, its functions and
        layers, every texture, live or not), and the viewport's environment file."""
        from matedit.io.inputs import document_inputs

        out = document_inputs(self.controller.document, self.controller.resolver)
        if self.environment.is_file():
            out.setdefault(Path(os.path.realpath(self.environment.current)), "the environment")
        return out

    def save_image(self, path: str | Path, size: tuple[int, int] | None = None) -> bool:
        """The current frame as PNG (display-referred, as shown) or as EXR (scene-linear
        radiance, before exposure and display transform); with `size` (width, height), the
        view drawn offscreen at that size (reference mode converged first)."""
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
        if not self.view.running:
            self.statusMessage.emit("no image to save: the renderer is not running")
            return False
        try:
            if size is not None:
                self._save_offscreen(path, size)
            elif path.suffix.lower() == ".exr":
                from matedit.io.images import write_image

                write_image(path, self.view.read_hdr())
            else:
                self._write_png(path, self.view.current_image())
        except (OSError, ValueError) as exc:
            self.statusMessage.emit(f"cannot save {path.name}: {exc}")
            return False
        self.statusMessage.emit(f"saved the viewport image to {path}")
        return True

    def _save_offscreen(self, path: Path, size: tuple[int, int]) -> None:
        import numpy as np

        from matedit.io.images import write_image

        shown = self.view.render_offscreen(*size)
        if shown is None:
            raise OSError("the renderer is not running")
        display, linear = shown
        if path.suffix.lower() == ".exr":
            write_image(path, linear)
        else:  # 8-bit sRGB, as the view shows it
            from PySide6.QtGui import QImage

            codes = np.ascontiguousarray(np.clip(np.rint(display * 255.0), 0, 255)
                                         .astype(np.uint8))
            h, w, _ = codes.shape
            self._write_png(path, QImage(codes.data, w, h, 3 * w, QImage.Format.Format_RGB888))

    @staticmethod
    def _write_png(path: Path, image) -> None:
        from PySide6.QtCore import QBuffer, QByteArray, QIODevice

        from matedit.io.atomic import atomic_write_bytes

        data = QByteArray()
        buf = QBuffer(data)
        buf.open(QIODevice.OpenModeFlag.WriteOnly)
        if not image.save(buf, "PNG"):
            raise OSError("PNG encoding failed")
        buf.close()
        atomic_write_bytes(path, bytes(data.data()))

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

    # --- previewing a node ----------------------------------------------------------------
    @property
    def following(self) -> bool:
        """The viewport previews each node the artist selects (unless pinned)."""
        return self.follow_action.isChecked()

    @property
    def pinned(self) -> bool:
        return self.pin_button.isChecked() and self.compiler.preview is not None

    def set_following(self, on: bool) -> None:
        self.follow_action.setChecked(on)

    def pin(self, on: bool = True) -> None:
        self.pin_button.setChecked(on)

    def show_material(self) -> None:
        """Back to the whole material: the preview and its pin end."""
        self.pin_button.setChecked(False)
        self.compiler.set_preview(None)

    def follow_selection(self, node_ids: list[str], output_of) -> bool:
        """With Follow on and nothing pinned, preview the one selected node: its first
        output the viewport can show (`output_of(node_id)`, "" if none), or the material
        for a node with none (the output). True when the preview changed."""
        self._selection = (list(node_ids), output_of)
        if not self.following or self.pinned or len(node_ids) != 1:
            return False
        port = output_of(node_ids[0])
        target = PreviewTarget(node_ids[0], port) if port else None
        if target == self.compiler.preview:
            return False
        return self.compiler.set_preview(target)

    def _follow_toggled(self, on: bool) -> None:
        self.pin_button.setVisible(on)
        if not on:
            self.pin_button.setChecked(False)
        self._preview_changed(self.compiler.preview)
        if on:
            self.follow_selection(*self._selection)

    def _pin_clicked(self, on: bool) -> None:
        if not on:  # unpinned by the artist: what is selected now
            self.follow_selection(*self._selection)

    def _preview_changed(self, target) -> None:
        if target is None:
            self.banner.hide()
            self.pin_button.setChecked(False)
            return
        verb = "Pinned to" if self.pinned else "Previewing"
        self.banner_label.setText(f"{verb} {target.label()}, not the material")
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
        if self.comparing:
            x = g.x() + int(round(self.view.split * g.width()))
            self.divider.setGeometry(x - SplitDivider.GRIP // 2, g.y(), SplitDivider.GRIP,
                                     g.height())
            top = g.y() + 4 + (self.banner.height() if self.banner.isVisible() else 0)
            for label in (self.a_label, self.b_label):
                label.adjustSize()
            self.a_label.move(max(g.x() + 4, x - self.a_label.width() - 8), top)
            self.b_label.move(min(x + 8, g.x() + g.width() - self.b_label.width() - 4), top)
            for w in (self.divider, self.a_label, self.b_label):
                w.raise_()

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().resizeEvent(event)
        self._place_banner()

    # --- mesh ------------------------------------------------------------------------------
    def mesh_spec(self) -> str:
        """The mesh shown: a built-in name, or an OBJ file's absolute path."""
        data = self.mesh_combo.currentData()
        return data if isinstance(data, str) and data != OBJ_ITEM else \
            self.mesh_combo.currentText()

    def _mesh_chosen(self, index: int) -> None:
        if self.mesh_combo.itemData(index) == OBJ_ITEM:
            path, _ = file_dialogs.open_file(self, "Open an OBJ mesh", "", OBJ_FILTER)
            if not path or not self.load_mesh_file(path):
                self.mesh_combo.setCurrentIndex(self._mesh_index)
            return
        self._mesh_index = index
        self.view.set_mesh(self.mesh_spec())

    def load_mesh_file(self, path: str | Path) -> bool:
        """An OBJ file as the preview mesh (checked first: a bad file is a status message,
        and the mesh shown stays); it joins the mesh list by its file name."""
        from matedit.render.mesh import MeshError, mesh_from_spec

        path = Path(path).resolve()
        try:
            mesh_from_spec(str(path))
        except MeshError as exc:
            self.statusMessage.emit(f"{path.name}: not a mesh the viewport can show: {exc}")
            return False
        except OSError as exc:
            self.statusMessage.emit(f"{path.name}: cannot be read: {exc.strerror or exc}")
            return False
        at = self.mesh_combo.findData(str(path))
        if at < 0:
            at = self.mesh_combo.count() - 1  # before "OBJ file…"
            self.mesh_combo.insertItem(at, path.name, str(path))
            self.mesh_combo.setItemData(at, str(path), Qt.ItemDataRole.ToolTipRole)
        self.mesh_combo.setCurrentIndex(at)
        return True

    def _set_mesh_spec(self, mesh: str, doc_path: Path | None = None) -> None:
        """A mesh from settings or a document: a built-in name, or an OBJ file (relative to
        `doc_path`)."""
        from matedit.io.inputs import BUILTIN_PREFIX

        name = mesh.removeprefix(BUILTIN_PREFIX)
        if name in MESHES:
            self.mesh_combo.setCurrentText(name)
            return
        p = Path(mesh)
        if not p.is_absolute() and doc_path is not None:
            p = Path(doc_path).resolve().parent / p
        if p.suffix.lower() == ".obj" and p.is_file():
            self.load_mesh_file(p)
        else:
            self.statusMessage.emit(f"the preview mesh {mesh} is missing")

    # --- bar -------------------------------------------------------------------------------
    def _mode_changed(self, text: str) -> None:
        self.view.set_mode(MODES[text])
        self.diff_label.setText("")
        self.diff_label.setVisible(MODES[text] != "splitsum")

    def _view_changed(self, index: int) -> None:
        view = self.view_combo.itemData(index)
        if isinstance(view, str):  # not a separator
            self.view.set_view(view)

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
        r = self.view.frame_info  # read on the render thread when the frame was drawn
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
        return {"mesh": self.mesh_spec(), "mode": self.mode_combo.currentText(),
                "exposure": self.exposure.value() / 10.0,
                "environment": self.environment.current,
                "energy_compensation": self.view.settings.energy_compensation}

    def restore_view_state(self, state: dict) -> None:
        mesh, mode = state.get("mesh"), state.get("mode")
        if isinstance(mesh, str) and mesh:
            self._set_mesh_spec(mesh)
        if isinstance(mode, str) and mode in MODES:
            self.mode_combo.setCurrentText(mode)
        ev = state.get("exposure")
        if isinstance(ev, (int, float)):
            self.exposure.setValue(int(round(float(ev) * 10)))
        energy = state.get("energy_compensation")
        if isinstance(energy, bool):
            self.view.change_settings(energy_compensation=energy)
        env = state.get("environment")
        if isinstance(env, str) and env and env != self.environment.current and (
                env in ENVIRONMENTS.values() or Path(env).is_file()):
            self.choose_environment(env)

    def document_preview(self, saved_as: Path) -> dict:
        """The mesh and environment to store in a document saved as `saved_as`: a user HDR
        as a path relative to the document, like every reference it holds."""
        from matedit.io.inputs import as_reference

        env = self.environment.current
        if env not in ENVIRONMENTS.values():
            try:  # a file named like a built-in is written as ./studio
                env = as_reference(Path(os.path.relpath(Path(env).resolve(), Path(
                    saved_as).resolve().parent)).as_posix(), "environment")
            except ValueError:  # another drive
                env = Path(env).resolve().as_posix()
        mesh = self.mesh_spec()
        if mesh not in MESHES:  # an OBJ file, relative to the document like the HDR
            try:
                mesh = as_reference(Path(os.path.relpath(Path(mesh), Path(
                    saved_as).resolve().parent)).as_posix(), "mesh")
            except ValueError:
                mesh = Path(mesh).as_posix()
        return {"mesh": mesh, "environment": env}

    def set_preview(self, preview: dict, doc_path: Path | None = None) -> None:
        """Mesh and environment stored with a document (a file relative to `doc_path`)."""
        from matedit.io.inputs import BUILTIN_PREFIX

        mesh = preview.get("mesh")  # `cube`, `builtin:cube` or an OBJ file
        if isinstance(mesh, str) and mesh:
            self._set_mesh_spec(mesh, doc_path)
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
        if env != self.environment.current:
            self.choose_environment(env)

    def choose_environment(self, spec: str) -> bool:
        """Bakes `spec` (studio, sky or a file) with a progress dialog; False on a bad file."""
        return self.environment.choose(spec)


def _overlay_label(parent: QWidget, name: str) -> QLabel:
    label = QLabel("", parent)
    label.setObjectName(name)
    label.setStyleSheet("background: rgba(20, 22, 27, 190); color: #f0f2f5; padding: 1px 6px;"
                        " font-weight: bold;")
    return label


class SplitDivider(QWidget):
    """The A/B split's divider over the view: a line in a grip the artist drags sideways."""

    GRIP = 9  # px: the line is 2 px, the rest is the area that takes the mouse
    moved = Signal(int)  # the line's x in the parent's coordinates

    def __init__(self, parent: QWidget) -> None:
        super().__init__(parent)
        self.setObjectName("abDivider")
        self.setCursor(Qt.CursorShape.SplitHCursor)
        self.setToolTip("Drag to move the A/B divider")

    def paintEvent(self, _event) -> None:  # noqa: N802 - Qt's name
        from PySide6.QtGui import QColor, QPainter

        p = QPainter(self)
        p.fillRect(self.width() // 2 - 1, 0, 2, self.height(), QColor("#f0f2f5"))
        p.end()

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt's name
        if event.buttons() & Qt.MouseButton.LeftButton:
            self.moved.emit(self.mapToParent(event.position().toPoint()).x())
