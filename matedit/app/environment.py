"""The viewport's environment: one `EnvironmentChoice` owns which environment lights the
view and the list the choosers show (the built-ins, the files opened so far, "Open…"), for
both the viewport's tool bar and the Lights & Environment dock (`EnvironmentPanel`)."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QObject, Qt, Signal
from PySide6.QtGui import QStandardItem, QStandardItemModel
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QComboBox,
    QFormLayout,
    QLabel,
    QMessageBox,
    QProgressDialog,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.fields import FloatField
from matedit.app.viewport import RenderSettings, ViewportWidget

ENVIRONMENTS = {"Studio": "studio", "Sky": "sky"}
OPEN_ENV = "Open HDR/EXR…"
ENV_FILTER = "HDR environments (*.hdr *.exr);;All files (*)"
SPEC_ROLE = Qt.ItemDataRole.UserRole


class EnvironmentChoice(QObject):
    """The current environment of one view, and the list to choose it from (`model`, shared
    by every chooser). `choose(spec)` bakes it into the view; a chooser calls `activate(row)`
    and follows `indexChanged`. `changed(spec)` follows a successful choice."""

    changed = Signal(str)
    indexChanged = Signal(int)

    def __init__(self, view: ViewportWidget, dialog_parent: QWidget, parent=None) -> None:
        super().__init__(parent)
        self.view = view
        self.dialog_parent = dialog_parent  # the progress dialog's and warnings' parent
        self.model = QStandardItemModel(self)
        for text in [*ENVIRONMENTS, OPEN_ENV]:
            item = QStandardItem(text)
            item.setData(ENVIRONMENTS.get(text), SPEC_ROLE)
            self.model.appendRow(item)
        self._current = view.environment
        self._index = 0
        self.env_dialog = file_dialogs.open_file  # tests replace it

    @property
    def current(self) -> str:
        """The spec that lights the view: a built-in's name or an HDR/EXR file's path."""
        return self._current

    @property
    def index(self) -> int:
        """The list's row of the current environment."""
        return self._index

    def is_file(self) -> bool:
        return self._current not in ENVIRONMENTS.values()

    def activate(self, row: int) -> bool:
        """A chooser picked `row`: a built-in, a file opened before, or Open… (a dialog)."""
        text = self.model.item(row).text() if 0 <= row < self.model.rowCount() else ""
        if text == OPEN_ENV:
            path, _ = self.env_dialog(self.dialog_parent, "Open an HDR environment", "",
                                      ENV_FILTER)
            if not path:
                self.indexChanged.emit(self._index)
                return False
            return self.choose(path)
        spec = ENVIRONMENTS.get(text) or self.model.item(row).data(SPEC_ROLE) or text
        return self.choose(spec)

    def choose(self, spec: str) -> bool:
        """Bakes `spec` (studio, sky or a file) with a progress dialog; False on a bad file
        (the environment before it stays)."""
        label = next((k for k, v in ENVIRONMENTS.items() if v == spec), Path(spec).name)
        dlg = QProgressDialog(f"Baking environment {label}…", "", 0, 100, self.dialog_parent)
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
            QMessageBox.warning(self.dialog_parent, "Environment", f"Cannot use {spec}:\n{exc}")
            self.indexChanged.emit(self._index)
            return False
        finally:
            dlg.setValue(100)
            dlg.close()
        if spec in ENVIRONMENTS.values():
            row = next(i for i in range(self.model.rowCount())
                       if self.model.item(i).text() == label)
        else:
            row = self._row_of(spec)
            if row < 0:
                item = QStandardItem(Path(spec).name)
                item.setData(spec, SPEC_ROLE)
                self.model.insertRow(self.model.rowCount() - 1, item)
                row = self._row_of(spec)
        self._current, self._index = spec, row
        self.indexChanged.emit(row)
        self.changed.emit(spec)
        return True

    def _row_of(self, spec: str) -> int:
        return next((i for i in range(self.model.rowCount())
                     if self.model.item(i).data(SPEC_ROLE) == spec), -1)


def environment_combo(choice: EnvironmentChoice) -> QComboBox:
    """A chooser on `choice`'s list, following its current row."""
    combo = QComboBox()
    combo.setModel(choice.model)
    combo.setCurrentIndex(choice.index)
    combo.activated.connect(choice.activate)
    choice.indexChanged.connect(combo.setCurrentIndex)
    return combo


class EnvironmentPanel(QWidget):
    """The environment half of the Lights & Environment dock: the same choice as the viewport
    bar (one `EnvironmentChoice`), the background, its blur, and the IBL intensity."""

    def __init__(self, choice: EnvironmentChoice, parent=None) -> None:
        super().__init__(parent)
        view = choice.view
        self.choice = choice
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 0)
        title = QLabel("Environment")
        title.setObjectName("sectionHeader")
        lay.addWidget(title)
        form = QFormLayout()
        form.setLabelAlignment(Qt.AlignmentFlag.AlignRight)
        self.combo = environment_combo(choice)
        form.addRow("image", self.combo)
        self.intensity = FloatField(1.0, (0.0, 4.0))
        self.intensity.setToolTip("Multiplies the environment's light")
        self.intensity.edited.connect(
            lambda v, _m: view.change_settings(environment_intensity=float(v)))
        form.addRow("intensity", self.intensity)
        self.background = QCheckBox("show behind the mesh")
        self.background.setChecked(True)
        self.background.toggled.connect(
            lambda on: view.change_settings(show_background=bool(on)))
        form.addRow("background", self.background)
        self.blur = FloatField(0.0, (0.0, 1.0))
        self.blur.setToolTip("Blurs the background only (lighting is unchanged)")
        self.blur.edited.connect(
            lambda v, _m: view.change_settings(background_blur=float(v)))
        form.addRow("blur", self.blur)
        self.energy = QCheckBox("energy compensation")
        self.energy.setToolTip("Adds back the light that single-scattering GGX loses on rough "
                               "surfaces (multiple scattering), for every material")
        self.energy.setChecked(view.settings.energy_compensation)
        self.energy.toggled.connect(
            lambda on: view.change_settings(energy_compensation=bool(on)))
        view.settingsChanged.connect(self._settings_changed)
        form.addRow("shading", self.energy)
        lay.addLayout(form)

    def _settings_changed(self, settings: RenderSettings) -> None:
        if self.energy.isChecked() != settings.energy_compensation:
            self.energy.blockSignals(True)
            self.energy.setChecked(settings.energy_compensation)
            self.energy.blockSignals(False)
