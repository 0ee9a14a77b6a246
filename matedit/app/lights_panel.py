"""Analytic lights of the preview: add, remove and edit sphere, tube, point and directional
lights. Lights are viewport state, not part of the material, so edits are not undo steps."""

from __future__ import annotations

import dataclasses
import math

from PySide6.QtCore import QSize, Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMenu,
    QScrollArea,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app.fields import ColorField, FloatField, VectorField
from matedit.app.theme import icon
from matedit.shading.lights import LIGHT_TYPES, Light

KINDS = ("sphere", "tube", "point", "directional")
MAX_LIST_ROWS = 8  # the lights list grows to this many rows, then scrolls


def default_light(kind: str) -> Light:
    """A light of `kind` placed where it shows on the preview mesh."""
    if kind == "directional":
        return Light("directional", direction=(-0.5, -0.7, -0.5), intensity=3.0)
    return Light(kind, position=(2.0, 2.5, 3.0), intensity=40.0,
                 influence_radius=20.0,
                 source_radius=0.3 if kind in ("sphere", "tube") else 0.0,
                 source_length=1.0 if kind == "tube" else 0.0,
                 direction=(0.0, 1.0, 0.0) if kind == "tube" else (0.0, 0.0, -1.0))


def describe(light: Light) -> str:
    r, g, b = light.color
    return f"{light.kind}  ·  {light.intensity:g}  ·  ({r:.2f}, {g:.2f}, {b:.2f})"


def _unit(v: list[float]) -> tuple[float, float, float]:
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v) if n > 1e-9 else (0.0, 0.0, -1.0)


class LightsPanel(QWidget):
    """Edits a list of `Light`s and emits `lightsChanged(list)` after each change."""

    lightsChanged = Signal(list)
    rigMessage = Signal(str)  # a light-rig file could not be loaded or saved

    def __init__(self, lights: list[Light] | None = None, parent=None) -> None:
        super().__init__(parent)
        self._lights: list[Light] = [dataclasses.replace(x) for x in (lights or [])]
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(4)
        bar = QHBoxLayout()
        title = QLabel("Lights")
        title.setObjectName("sectionHeader")
        self.add_button = QToolButton()
        self.add_button.setIcon(icon("add"))
        self.add_button.setToolTip("Add a light")
        self.add_button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
        menu = QMenu(self)
        for k in KINDS:
            menu.addAction(f"{k.title()} light", lambda k=k: self.add_light(k))
        self.add_button.setMenu(menu)
        self.remove_button = QToolButton()
        self.remove_button.setIcon(icon("delete"))
        self.remove_button.setToolTip("Remove the selected light")
        self.remove_button.clicked.connect(self.remove_selected)
        bar.addWidget(title, 1)
        bar.addWidget(self.add_button)
        bar.addWidget(self.remove_button)
        from matedit.app.rig_actions import install_rig_actions

        install_rig_actions(self, bar)  # load / save the rig as a file (matedit.io.rig)
        lay.addLayout(bar)
        self.list = QListWidget()
        self.list.setIconSize(QSize(16, 16))  # compact rows: the form below must fit too
        self.list.setUniformItemSizes(True)
        self.list.currentRowChanged.connect(self._show_keeping_scroll)
        lay.addWidget(self.list)
        self.form_host = QWidget()
        self.form = QFormLayout(self.form_host)
        self.form.setContentsMargins(0, 0, 0, 0)
        self.form.setLabelAlignment(Qt.AlignmentFlag.AlignRight)
        lay.addWidget(self.form_host)
        lay.addStretch(1)
        self._fill()

    @property
    def lights(self) -> list[Light]:
        return [dataclasses.replace(x) for x in self._lights]

    def set_lights(self, lights: list[Light], emit: bool = False) -> None:
        self._lights = [dataclasses.replace(x) for x in lights]
        self._fill()
        if emit:
            self.lightsChanged.emit(self.lights)

    def add_light(self, kind: str) -> None:
        if kind not in LIGHT_TYPES:
            raise ValueError(f"unknown light kind {kind!r}")
        self._lights.append(default_light(kind))
        self._fill(len(self._lights) - 1)
        self.lightsChanged.emit(self.lights)

    def remove_selected(self) -> None:
        row = self.list.currentRow()
        if 0 <= row < len(self._lights):
            del self._lights[row]
            self._fill(min(row, len(self._lights) - 1))
            self.lightsChanged.emit(self.lights)

    def _fill(self, select: int = 0) -> None:
        self.list.blockSignals(True)
        self.list.clear()
        for light in self._lights:
            QListWidgetItem(icon("light"), describe(light), self.list)
        self.list.blockSignals(False)
        self.remove_button.setEnabled(bool(self._lights))
        self._fit_list()
        if self._lights:
            self.list.setCurrentRow(max(0, select))
            self._show(max(0, select))
        else:
            self._show(-1)

    def _fit_list(self) -> None:
        """The list as tall as its lights (3 rows at least, 8 at most, then it scrolls)."""
        row = self.list.sizeHintForRow(0) if self.list.count() else 0
        row = max(row, self.list.fontMetrics().height() + 6)
        rows = min(max(self.list.count(), 3), MAX_LIST_ROWS)
        self.list.setFixedHeight(row * rows + 2 * self.list.frameWidth())

    def _show_keeping_scroll(self, row: int) -> None:
        """Another light's form, with the panel's scroll position where it was: rebuilding
        the form would otherwise scroll the dock back to its top."""
        area = self._scroll_area()
        bar = area.verticalScrollBar() if area is not None else None
        at = bar.value() if bar is not None else 0
        self._show(row)
        if bar is not None:
            bar.setValue(at)
            QTimer.singleShot(0, self, lambda: bar.setValue(at))  # after the relayout

    def _scroll_area(self) -> QScrollArea | None:
        w = self.parentWidget()
        while w is not None and not isinstance(w, QScrollArea):
            w = w.parentWidget()
        return w

    def _clear_form(self) -> None:
        while self.form.rowCount():
            self.form.removeRow(0)

    def _show(self, row: int) -> None:
        self._clear_form()
        if not 0 <= row < len(self._lights):
            return
        light = self._lights[row]
        kind = QComboBox()
        kind.addItems(list(KINDS))
        kind.setCurrentText(light.kind)
        kind.currentTextChanged.connect(lambda k: self._edit(row, kind=k, rebuild=True))
        self.form.addRow("type", kind)
        if light.kind != "directional":
            pos = VectorField(list(light.position))
            pos.edited.connect(lambda v, _m: self._edit(row, position=tuple(v)))
            self.form.addRow("position", pos)
        if light.kind in ("directional", "tube"):
            d = VectorField(list(light.direction))
            d.setToolTip("travel direction" if light.kind == "directional" else "tube axis")
            d.edited.connect(lambda v, _m: self._edit(row, direction=_unit(v)))
            self.form.addRow("direction" if light.kind == "directional" else "axis", d)
        col = ColorField(list(light.color))
        col.edited.connect(lambda v, _m: self._edit(row, color=tuple(v)))
        self.form.addRow("colour", col)
        inten = FloatField(light.intensity, (0.0, 10.0 if light.kind == "directional" else 200.0))
        inten.edited.connect(lambda v, _m: self._edit(row, intensity=float(v)))
        self.form.addRow("intensity", inten)
        if light.kind in ("sphere", "tube"):
            rad = FloatField(light.source_radius, (0.0, 2.0))
            rad.edited.connect(lambda v, _m: self._edit(row, source_radius=max(0.0, float(v))))
            self.form.addRow("radius", rad)
        if light.kind == "tube":
            ln = FloatField(light.source_length, (0.0, 5.0))
            ln.edited.connect(lambda v, _m: self._edit(row, source_length=max(0.0, float(v))))
            self.form.addRow("length", ln)
        if light.kind != "directional":
            inf = FloatField(light.influence_radius, (0.1, 100.0))
            inf.setToolTip("distance at which the light fades to nothing")
            inf.edited.connect(lambda v, _m: self._edit(row, influence_radius=max(0.01,
                                                                                   float(v))))
            self.form.addRow("reach", inf)

    def _edit(self, row: int, rebuild: bool = False, **changes) -> None:
        if not 0 <= row < len(self._lights):
            return
        light = self._lights[row]
        if "kind" in changes and changes["kind"] != light.kind:
            fresh = default_light(changes["kind"])
            fresh.color, fresh.position = light.color, light.position
            self._lights[row] = fresh
        else:
            self._lights[row] = dataclasses.replace(light, **changes)
        item = self.list.item(row)
        if item is not None:
            item.setText(describe(self._lights[row]))
        if rebuild:  # not inside the combo's own signal: the form is rebuilt later
            QTimer.singleShot(0, self, lambda: self._show(row))
        self.lightsChanged.emit(self.lights)
