"""Editor widgets for one value each: float, vector, colour, texture path.

A field shows a value and emits `edited(value, merge_id)` when the artist changes
it; `merge_id` is the same for every step of one slider drag (so the drag undoes
as one step) and None for a discrete edit. Fields never touch the model: the
inspector turns their signals into commands.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QEvent, QObject, QSize, Qt, Signal
from PySide6.QtGui import QColor, QImage, QImageReader, QPixmap
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QApplication,
    QColorDialog,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.controller import new_merge_id
from matedit.app.spinbox import (  # noqa: F401 - the field kit's names, used from here too
    SPIN_LIMIT,
    NumberSpin,
    linear_to_srgb,
    split_hdr,
    srgb_to_linear,
)
from matedit.app.theme import icon

if TYPE_CHECKING:
    from matedit.app.hdr_picker import HdrColorDialog

SLIDER_STEPS = 1000
IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.tga *.tif *.tiff *.exr *.hdr *.bmp);;All files (*)"


class WheelGuard(QObject):
    """Lets the wheel change a slider, spin box or combo box only while it has focus;
    otherwise the wheel scrolls the panel around it."""

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        if event.type() == QEvent.Type.Wheel and isinstance(obj, QWidget) and not obj.hasFocus():
            area = obj.parentWidget()
            while area is not None and not isinstance(area, QAbstractScrollArea):
                area = area.parentWidget()
            if area is not None:
                QApplication.sendEvent(area.verticalScrollBar(), event)
            return True
        return False


def guard_wheel(widget: QWidget) -> QWidget:
    """`widget` with a `WheelGuard`, and focus only by click or Tab (never by the wheel)."""
    widget.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
    widget.installEventFilter(WheelGuard(widget))
    return widget


def _spin(decimals: int = 3) -> QDoubleSpinBox:
    s = NumberSpin()
    guard_wheel(s)
    s.setRange(-SPIN_LIMIT, SPIN_LIMIT)
    s.setDecimals(decimals)
    s.setSingleStep(0.01)
    s.setKeyboardTracking(False)
    s.setObjectName("field")  # the stylesheet hides its arrows (NoButtons hides its text)
    s.setAlignment(Qt.AlignmentFlag.AlignRight)
    s.setMinimumWidth(58)
    return s


def default_range(value: float, given: tuple[float, float] | None) -> tuple[float, float]:
    """The slider's range: the definition's, else one that holds the value comfortably."""
    if given is not None and given[1] > given[0]:
        lo, hi = float(given[0]), float(given[1])
    elif 0.0 <= value <= 1.0:
        lo, hi = 0.0, 1.0
    else:
        mag = 10 ** math.ceil(math.log10(abs(value) + 1e-9)) if value else 1.0
        lo, hi = (0.0, mag) if value >= 0 else (-mag, mag)
    return min(lo, value), max(hi, value)


class FloatField(QWidget):
    """A slider over the input's range plus a typed spin box; typing outside the range widens
    the slider's range to include the new value."""

    edited = Signal(object, object)  # value, merge id

    def __init__(self, value: float, rng: tuple[float, float] | None = None, parent=None):
        super().__init__(parent)
        self._lo, self._hi = default_range(float(value), rng)
        self._drag_id: int | None = None
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(6)
        self.slider = guard_wheel(QSlider(Qt.Orientation.Horizontal))
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.spin = _spin()
        self.spin.setFixedWidth(70)
        lay.addWidget(self.slider, 1)
        lay.addWidget(self.spin)
        self.set_value(value)
        self.slider.sliderPressed.connect(self._drag_start)
        self.slider.valueChanged.connect(self._slider_moved)
        self.slider.sliderReleased.connect(self._drag_end)
        self.spin.valueChanged.connect(self._typed)

    @property
    def range(self) -> tuple[float, float]:
        return self._lo, self._hi

    def value(self) -> float:
        return float(self.spin.value())

    def set_value(self, value: float) -> None:
        value = float(value)
        if value < self._lo or value > self._hi:
            self._lo, self._hi = min(self._lo, value), max(self._hi, value)
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        self.spin.setValue(value)
        self.slider.setValue(self._to_steps(value))
        for w in (self.slider, self.spin):
            w.blockSignals(False)

    def _to_steps(self, v: float) -> int:
        t = (v - self._lo) / (self._hi - self._lo) if self._hi > self._lo else 0.0
        return int(round(max(0.0, min(1.0, t)) * SLIDER_STEPS))

    def _from_steps(self, s: int) -> float:
        v = self._lo + (self._hi - self._lo) * s / SLIDER_STEPS
        return round(v, 4)

    def _drag_start(self) -> None:
        self._drag_id = new_merge_id()

    def _drag_end(self) -> None:
        self._drag_id = None

    def _slider_moved(self, steps: int) -> None:
        v = self._from_steps(steps)
        self.spin.blockSignals(True)
        self.spin.setValue(v)
        self.spin.blockSignals(False)
        # Keyboard and page steps arrive without a press: each is its own undo step.
        self.edited.emit(v, self._drag_id)

    def _typed(self, v: float) -> None:
        self.set_value(v)
        self.edited.emit(float(v), None)


class VectorField(QWidget):
    """2 to 4 typed components in a row."""

    edited = Signal(object, object)

    def __init__(self, value: list[float], parent=None):
        super().__init__(parent)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(3)
        self.spins = []
        for i, v in enumerate(value):
            s = _spin()
            s.setToolTip("xyzw"[i])
            s.setValue(float(v))
            s.valueChanged.connect(self._typed)
            lay.addWidget(s)
            self.spins.append(s)

    def value(self) -> list[float]:
        return [float(s.value()) for s in self.spins]

    def set_value(self, value: list[float]) -> None:
        for s, v in zip(self.spins, value):
            s.blockSignals(True)
            s.setValue(float(v))
            s.blockSignals(False)

    def _typed(self, _v: float) -> None:
        self.edited.emit(self.value(), None)


class ColorField(QWidget):
    """A swatch (opens the float HDR picker; stored linear) and an intensity multiplier, so
    HDR colours (components above 1) stay editable."""

    edited = Signal(object, object)

    def __init__(self, value: list[float], parent=None):
        super().__init__(parent)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(6)
        self.swatch = QPushButton()
        self.swatch.setObjectName("swatch")
        self.swatch.setFixedHeight(20)
        self.swatch.setToolTip("Pick a colour")
        self.swatch.clicked.connect(self.pick)
        self.intensity = _spin(2)
        self.intensity.setRange(0.0, SPIN_LIMIT)
        self.intensity.setFixedWidth(60)
        self.intensity.setToolTip("Intensity: multiplies the colour (values above 1 are HDR)")
        self.intensity.valueChanged.connect(self._intensity_typed)
        self.rgb_label = QLabel()
        self.rgb_label.setObjectName("fieldLabel")
        lay.addWidget(self.swatch, 1)
        lay.addWidget(QLabel("×"))
        lay.addWidget(self.intensity)
        self._base: list[float] = []  # the first value is split afresh
        self.set_value(value)
        self.dialog_factory = QColorDialog.getColor  # replaced: a modal dialog (tests)
        self.live_dialog: HdrColorDialog | None = None

    def value(self) -> list[float]:
        k = float(self.intensity.value())
        return [round(c * k, 6) for c in self._base]

    def set_value(self, value: list[float]) -> None:
        rgb = [float(x) for x in value]
        k = self._same_hue_intensity(rgb)
        if k is None:  # a new colour: split it afresh
            self._base, k = split_hdr(rgb)
        self.intensity.blockSignals(True)
        self.intensity.setValue(k)
        self.intensity.blockSignals(False)
        self._paint()

    def _same_hue_intensity(self, rgb: list[float]) -> float | None:
        """The intensity that makes the shown colour `rgb`, if `rgb` is the shown colour
        scaled (an intensity edit coming back from the model, or its undo): the field keeps
        what the artist typed instead of re-splitting (4 must stay 4)."""
        peak = max(self._base) if self._base else 0.0
        if peak <= 0.0 or len(rgb) != len(self._base):
            return None
        k = max(rgb) / peak
        if k == 0.0 and self.intensity.value() != 0.0:
            return None  # black from elsewhere (a ramp's other stop): a black swatch at x 1
        if k < 0 or any(abs(b * k - c) > 1e-5 * max(1.0, abs(c)) for b, c in zip(self._base,
                                                                                rgb)):
            return None
        return k

    def _unmute(self) -> None:
        """A colour picked at intensity 0 would change nothing the artist can see: back to 1."""
        if self.intensity.value() == 0.0:
            self.intensity.blockSignals(True)
            self.intensity.setValue(1.0)
            self.intensity.blockSignals(False)

    def _paint(self) -> None:
        # the swatch is the colour itself where it is not HDR (an intensity below 1 darkens
        # it), else its hue at full brightness beside the multiplier
        k = min(float(self.intensity.value()), 1.0)
        r, g, b = (int(round(linear_to_srgb(c * k) * 255)) for c in self._base)
        self.swatch.setStyleSheet(f"background: rgb({r},{g},{b});")
        v = self.value()
        self.swatch.setToolTip("linear RGB " + ", ".join(f"{c:.3f}" for c in v))

    def pick(self) -> HdrColorDialog | None:
        """A float, HDR colour picker (matedit.app.hdr_picker) that stays open beside the
        canvas and edits live (one undo step for the whole pick). A replaced
        `dialog_factory` (a modal dialog returning a QColor) is used instead where set."""
        r, g, b = (int(round(linear_to_srgb(c) * 255)) for c in self._base)
        if self.dialog_factory is QColorDialog.getColor:
            return self._pick_live(QColor(r, g, b))
        chosen = self.dialog_factory(QColor(r, g, b), self, "Colour")
        if chosen is None or not chosen.isValid():
            return
        self._base = [round(srgb_to_linear(x), 6) for x in
                      (chosen.redF(), chosen.greenF(), chosen.blueF())]
        self._unmute()
        self._paint()
        self.edited.emit(self.value(), None)

    def _pick_live(self, _start: QColor) -> HdrColorDialog:
        from matedit.app.hdr_picker import HdrColorDialog

        if self.live_dialog is not None:
            self.live_dialog.raise_()
            return self.live_dialog
        dlg = HdrColorDialog(self.value(), self, (list(self._base),
                                                  float(self.intensity.value())))
        merge = new_merge_id()

        def changed(v: list[float]) -> None:  # Cancel comes back here too, in the same step
            self.set_value(v)
            self.edited.emit(self.value(), merge)

        dlg.colorChanged.connect(changed)
        dlg.finished.connect(lambda _r: setattr(self, "live_dialog", None))
        dlg.show()
        self.live_dialog = dlg
        return dlg

    def _intensity_typed(self, _v: float) -> None:
        self._paint()
        self.edited.emit(self.value(), None)


def load_thumbnail(path: str | Path, size: int = 64) -> QPixmap | None:
    """A small preview of an image file (Qt's readers, then OpenImageIO for EXR/HDR)."""
    p = Path(path)
    if not p.is_file():
        return None
    reader = QImageReader(str(p))
    if reader.canRead():
        reader.setScaledSize(reader.size().scaled(QSize(size, size),
                                                  Qt.AspectRatioMode.KeepAspectRatio))
        img = reader.read()
        if not img.isNull():
            return QPixmap.fromImage(img)
    try:
        from matedit.io.images import read_image

        data = read_image(p)
    except (ValueError, OSError):
        return None
    px = data.pixels
    step = max(1, max(px.shape[:2]) // size)
    px = px[::step, ::step]
    if px.shape[2] == 1:
        px = np.repeat(px, 3, axis=2)
    rgb = np.clip(px[:, :, :3], 0, 1)
    if not data.is_ldr:
        rgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)
    arr = np.ascontiguousarray((rgb * 255 + 0.5).astype(np.uint8))
    h, w = arr.shape[:2]
    img = QImage(arr.data, w, h, 3 * w, QImage.Format.Format_RGB888).copy()
    return QPixmap.fromImage(img)


class TextureField(QWidget):
    """A thumbnail, the stored path and a browse button. Emits the absolute path chosen."""

    edited = Signal(object, object)

    def __init__(self, stored: str, absolute: Path | None, parent=None):
        super().__init__(parent)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(6)
        self.thumb = QLabel()
        self.thumb.setFixedSize(48, 48)
        self.thumb.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.thumb.setStyleSheet("border: 1px solid #3a404d; background: #1e2128;")
        col = QVBoxLayout()
        col.setSpacing(3)
        self.path_edit = QLineEdit(stored)
        self.path_edit.setPlaceholderText("no image: a checker")
        self.path_edit.editingFinished.connect(self._typed)
        row = QHBoxLayout()
        self.browse = QPushButton("Browse…")
        self.browse.clicked.connect(self._browse)
        self.clear = QToolButton()
        self.clear.setIcon(icon("remove"))
        self.clear.setToolTip("Clear the image")
        self.clear.clicked.connect(lambda: self.edited.emit("", None))
        row.addWidget(self.browse)
        row.addWidget(self.clear)
        row.addStretch(1)
        col.addWidget(self.path_edit)
        col.addLayout(row)
        lay.addWidget(self.thumb)
        lay.addLayout(col, 1)
        self.file_dialog = file_dialogs.open_file  # tests replace it
        self.set_value(stored, absolute)

    def set_value(self, stored: str, absolute: Path | None) -> None:
        self.path_edit.setText(stored)
        pm = load_thumbnail(absolute) if absolute else None
        if pm is None:
            self.thumb.setPixmap(icon("texture").pixmap(28, 28))
            if stored:
                self.thumb.setToolTip(f"{stored}: not found (renders as a checker)")
        else:
            self.thumb.setPixmap(pm.scaled(46, 46, Qt.AspectRatioMode.KeepAspectRatio,
                                           Qt.TransformationMode.SmoothTransformation))
            self.thumb.setToolTip(str(absolute))

    def _browse(self) -> None:
        path, _ = self.file_dialog(self, "Choose an image", "", IMAGE_FILTER)
        if path:
            self.edited.emit(str(Path(path).resolve()), None)

    def _typed(self) -> None:
        self.edited.emit(self.path_edit.text().strip(), None)
