"""The parameter panel: a material's parameters grouped, ordered and collapsible.

Groups and orders come from each parameter node's `group` and `order` settings
(`matedit.io.instance.sorted_groups`), sliders from `ui_min`/`ui_max`, help from `tooltip`,
and a vector parameter whose `usage` is "color" gets a colour picker. In an instance every
row has an override checkbox and a "reset to parent" button, and an overridden row is marked
(bold name, accent bar). The panel never touches files: it emits signals, and the instance
editor (or a material's inspector) turns them into edits.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QFormLayout,
    QFrame,
    QGraphicsOpacityEffect,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app.fields import (
    SLIDER_STEPS,
    ColorField,
    FloatField,
    TextureField,
    VectorField,
)
from matedit.app.turns import turns
from matedit.io.instance import ParameterInfo, sorted_groups

OVERRIDDEN_STYLE = "QLabel { font-weight: bold; color: #f0b45a; }"
LABEL_WIDTH = 110
MARK_STYLE = "QFrame { background: #f0b45a; border: none; }"
UNMARKED_STYLE = "QFrame { background: transparent; }"


class CurveFloatField(FloatField):
    """A FloatField whose slider follows value = lo + (hi - lo) * t^exponent (finer control
    near ui_min for exponent > 1); with `slider` off only the number box shows."""

    def __init__(self, value: float, rng, exponent: float = 1.0, slider: bool = True) -> None:
        self.exponent = exponent if exponent > 0 else 1.0
        super().__init__(value, rng)
        self.slider.setVisible(slider)

    def _to_steps(self, v: float) -> int:
        lo, hi = self.range
        t = (v - lo) / (hi - lo) if hi > lo else 0.0
        t = max(0.0, min(1.0, t)) ** (1.0 / self.exponent)
        return int(round(t * SLIDER_STEPS))

    def _from_steps(self, s: int) -> float:
        lo, hi = self.range
        return round(lo + (hi - lo) * (s / SLIDER_STEPS) ** self.exponent, 4)


class _ColourVector(QWidget):
    """A vec4 parameter whose usage is colour: a colour picker for xyz, a number for w."""

    edited = Signal(object, object)

    def __init__(self, value: list[float]) -> None:
        super().__init__()
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        self.colour = ColorField(list(value[:3]))
        self.w = FloatField(float(value[3]), (0.0, 1.0))
        self.w.slider.hide()
        lay.addWidget(self.colour, 1)
        lay.addWidget(self.w)
        self.colour.edited.connect(lambda *_: self.edited.emit(self.value(), None))
        self.w.edited.connect(lambda *_: self.edited.emit(self.value(), None))

    def value(self) -> list[float]:
        return [*self.colour.value(), self.w.value()]

    def set_value(self, value: list[float]) -> None:
        self.colour.set_value(list(value[:3]))
        self.w.set_value(float(value[3]))


class _Row(QWidget):
    def __init__(self, info: ParameterInfo, value: Any, base: Path | None,
                 instance: bool) -> None:
        super().__init__()
        self.info = info
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(4)
        self.mark = QFrame()  # its colour: ParameterPanel._mark
        self.mark.setFixedWidth(3)
        self.check = QCheckBox()
        self.check.setToolTip("Override the parent's value")
        self.reset = QToolButton()
        self.reset.setText("↺")
        self.reset.setToolTip("Reset to the parent's value")
        self.reset.setAutoRaise(True)
        for w in (self.mark, self.check):
            lay.addWidget(w)
        self.field = self._field(info, value, base)
        self.field.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        lay.addWidget(self.field, 1)
        lay.addWidget(self.reset)
        for w in (self.mark, self.check, self.reset):
            w.setVisible(instance)

    @staticmethod
    def _field(info: ParameterInfo, value: Any, base: Path | None) -> QWidget:
        s = info.settings
        if info.type == "scalar":
            lo, hi = s.get("ui_min", 0.0), s.get("ui_max", 1.0)
            num = (int, float)
            ok = all(isinstance(x, num) and not isinstance(x, bool) for x in (lo, hi))
            exp = s.get("exponent", 1.0)
            exp = float(exp) if isinstance(exp, num) and not isinstance(exp, bool) else 1.0
            return CurveFloatField(float(value), (float(lo), float(hi)) if ok else None, exp,
                                   s.get("slider", True) is not False)
        if info.type == "color":
            return ColorField(list(value))
        if info.type == "vector" and s.get("usage") == "color":
            return _ColourVector(list(value))
        if info.type == "vector":
            return VectorField(list(value))
        if info.type == "texture":
            absolute = (base / value) if (base and value) else None
            return TextureField(str(value), absolute)
        box = QPushButton("On" if value else "Off")  # a static switch: compile-time choice
        box.setCheckable(True)
        box.setChecked(bool(value))
        box.toggled.connect(lambda on, b=box: b.setText("On" if on else "Off"))
        box.setToolTip("Static switch: changing it compiles a permutation of the shader")
        return box

    def value(self) -> Any:
        f = self.field
        if isinstance(f, QPushButton):
            return f.isChecked()
        if isinstance(f, TextureField):
            return f.path_edit.text().strip()
        return f.value()

    def show_value(self, value: Any, base: Path | None) -> None:
        f = self.field
        f.blockSignals(True)
        try:
            if isinstance(f, QPushButton):
                f.setChecked(bool(value))
                f.setText("On" if value else "Off")
            elif isinstance(f, TextureField):
                f.set_value(str(value), (base / value) if (base and value) else None)
            else:
                f.set_value(value)
        finally:
            f.blockSignals(False)


class ParameterPanel(QScrollArea):
    """Grouped, ordered, collapsible parameter rows."""

    valueEdited = Signal(str, object)  # parameter name, value
    overrideToggled = Signal(str, bool)  # parameter name, overridden
    resetRequested = Signal(str)  # parameter name

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setWidgetResizable(True)
        self.rows: dict[str, _Row] = {}
        self.labels: dict[str, QLabel] = {}
        self.groups: dict[str, tuple[QToolButton, QWidget]] = {}
        self.instance_mode = False
        self._base: Path | None = None
        # rows still to build (set_parameters with `per_turn`): name -> (form, info, value,
        # overridden), in display order, a few each turn of the event loop
        self._queued: dict[str, tuple[QFormLayout, ParameterInfo, Any, bool]] = {}
        self._per_turn = 0
        self._live: set[str] | None = None
        self.setWidget(QWidget())

    @property
    def building(self) -> bool:
        """Rows are still being built (a few each turn of the event loop)."""
        return bool(self._queued)

    def set_parameters(self, params: dict[str, ParameterInfo], values: dict[str, Any],
                       overridden: set[str] | None = None, base: Path | None = None,
                       per_turn: int = 0, first_now: bool = True) -> None:
        """Rebuild. `overridden` None: a material's own parameters (no override column).
        `per_turn` > 0: the groups at once, their rows that many at a time, each batch in a
        turn of the event loop of its own (a row costs the UI thread ~3 ms; a material with
        dozens of parameters would block it for longer than a frame); `building` until then.
        The first batch is built now, or with `first_now` False in a turn of its own too
        (a rebuild that is itself a deferred step: its own work and the first rows would
        be one block)."""
        self.instance_mode = overridden is not None
        self._base = base
        self.rows.clear()
        self.labels.clear()
        self._queued.clear()
        turns().cancel(self, "rows")
        self._per_turn = per_turn
        self._live = None  # set_live again for these rows
        collapsed = {g for g, (b, _) in self.groups.items() if not b.isChecked()}
        self.groups.clear()
        host = QWidget()
        lay = QVBoxLayout(host)
        lay.setContentsMargins(6, 6, 6, 6)
        lay.setSpacing(4)
        if not params:
            lay.addWidget(QLabel("This material has no parameters."))
        for group, infos in sorted_groups(params):
            title = group or "Parameters"
            head = QToolButton()
            head.setText(title)
            head.setCheckable(True)
            head.setChecked(title not in collapsed)
            head.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
            head.setArrowType(Qt.ArrowType.DownArrow if head.isChecked()
                              else Qt.ArrowType.RightArrow)
            head.setStyleSheet("QToolButton { border: none; font-weight: bold; }")
            body = QWidget()
            form = QFormLayout(body)
            form.setContentsMargins(14, 0, 0, 6)
            for info in infos:
                self._queued[info.name] = (form, info, values.get(info.name, info.default),
                                           bool(overridden and info.name in overridden))

            def toggled(on: bool, h=head, b=body) -> None:
                b.setVisible(on)
                h.setArrowType(Qt.ArrowType.DownArrow if on else Qt.ArrowType.RightArrow)

            head.toggled.connect(toggled)
            lay.addWidget(head)
            lay.addWidget(body)
            # once parented: shown without a parent, it would be a window of its own for a
            # moment (a native window made, the whole group polished as one: most of a
            # rebuild's time)
            body.setVisible(head.isChecked())
            self.groups[title] = (head, body)
        lay.addStretch(1)
        if per_turn <= 0:
            self._build_queued(len(self._queued))
        self.setWidget(host)
        if self._queued:
            if first_now:
                self._build_queued()
            else:
                turns().add(self, "rows", self._build_queued)

    def _build_queued(self, count: int = 0) -> None:
        """The next `count` queued rows (default: `per_turn`); the rest in a later turn."""
        for _ in range(count or self._per_turn):
            if not self._queued:
                break
            name = next(iter(self._queued))
            form, info, value, overridden = self._queued.pop(name)
            row = _Row(info, value, self._base, self.instance_mode)
            label = QLabel(info.name.replace("_", " "))
            label.setMinimumWidth(LABEL_WIDTH)  # one column across groups
            tip = info.settings.get("tooltip") or ""
            label.setToolTip(f"{tip}\n({info.name}, {info.type})" if tip
                             else f"{info.name} ({info.type})")
            self.rows[name] = row
            self.labels[name] = label
            self._wire(row)
            form.addRow(label, row)
            self._mark(name, overridden)
            if self._live is not None:
                self._show_live(name)
        if self._queued:
            turns().add(self, "rows", self._build_queued)

    def _wire(self, row: _Row) -> None:
        name = row.info.name
        f = row.field
        if isinstance(f, QPushButton):
            f.toggled.connect(lambda on, n=name: self._edited(n, bool(on)))
        else:
            f.edited.connect(lambda v, _m=None, n=name: self._edited(n, v))
        row.check.toggled.connect(lambda on, n=name: self.overrideToggled.emit(n, bool(on)))
        row.reset.clicked.connect(lambda _=False, n=name: self.resetRequested.emit(n))

    def _edited(self, name: str, value: Any) -> None:
        self.valueEdited.emit(name, value)

    def _mark(self, name: str, overridden: bool) -> None:
        row, label = self.rows[name], self.labels[name]
        row.check.blockSignals(True)
        row.check.setChecked(overridden)
        row.check.blockSignals(False)
        row.reset.setEnabled(overridden)
        row.mark.setVisible(self.instance_mode)
        # A style sheet of a widget's own makes every later reparenting and polish of it
        # recompute its style: set only where it changes (none on a material's own rows)
        mark = MARK_STYLE if overridden else (UNMARKED_STYLE if self.instance_mode else "")
        if row.mark.styleSheet() != mark:
            row.mark.setStyleSheet(mark)
        text = OVERRIDDEN_STYLE if overridden else ""
        if label.styleSheet() != text:
            label.setStyleSheet(text)
        label.setProperty("overridden", overridden)

    def update_row(self, name: str, value: Any, overridden: bool | None = None) -> None:
        """Show a value (and override state) without emitting edits."""
        row = self.rows.get(name)
        if row is None:
            queued = self._queued.get(name)
            if queued is not None:  # built later with this value
                form, info, _, was = queued
                self._queued[name] = (form, info, value,
                                      was if overridden is None else overridden)
            return
        row.show_value(value, self._base)
        if overridden is not None:
            self._mark(name, overridden)

    def set_live(self, live: set[str] | None) -> None:
        """Greys out parameters a static switch compiled out (None: all live)."""
        self._live = live
        for name in self.rows:
            self._show_live(name)

    def _show_live(self, name: str) -> None:
        row, live = self.rows[name], self._live
        on = live is None or name in live
        row.field.setEnabled(on)
        self.labels[name].setEnabled(on)
        row.field.setToolTip("" if on else "compiled out by a static switch")
        for w in (row.field, self.labels[name]):
            effect = None
            if not on:
                effect = QGraphicsOpacityEffect(w)
                effect.setOpacity(0.35)
            w.setGraphicsEffect(effect)

    def is_marked(self, name: str) -> bool:
        return bool(self.labels[name].property("overridden"))

    def group_order(self) -> list[tuple[str, list[str]]]:
        """(group title, parameter names) in display order: for tests and the inspector."""
        out = []
        for title, (_, body) in self.groups.items():
            form = body.layout()
            names = [form.itemAt(i, QFormLayout.ItemRole.FieldRole).widget().info.name
                     for i in range(form.rowCount())]
            out.append((title, names))
        return out
