"""A float colour picker for linear, HDR colours: the stock 8-bit QColorDialog cannot hold
a value above 1 or more precision than 1/255.

The colour is kept as a display colour (components at most 1, linear) times an intensity,
as the Inspector's colour field keeps it. The saturation/value square and the hue strip
edit the display colour in sRGB HSV; the linear R, G and B fields edit the whole value
(above 1 is HDR); the intensity is a multiplier, also shown in stops (EV); the hex field is
the display colour in sRGB, as paint programs write it. Every edit is live (`colorChanged`
with the linear value); Cancel goes back to the colour the picker opened with.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QLinearGradient, QMouseEvent, QPainter, QPen
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QVBoxLayout,
    QWidget,
)

from matedit.app.spinbox import SPIN_LIMIT, NumberSpin, linear_to_srgb, split_hdr, srgb_to_linear

HEX_LEN = 7  # "#rrggbb"


def hex_of(display: list[float]) -> str:
    """The sRGB hex of a display colour (linear, components clamped to 0..1)."""
    return "#" + "".join(f"{int(round(linear_to_srgb(c) * 255)):02x}" for c in display)


def parse_hex(text: str) -> list[float] | None:
    """`#rrggbb` or `rrggbb` (sRGB) as a linear display colour; None if it is not one."""
    t = text.strip().lstrip("#")
    if len(t) != 6 or any(ch not in "0123456789abcdefABCDEF" for ch in t):
        return None
    return [srgb_to_linear(int(t[i:i + 2], 16) / 255) for i in (0, 2, 4)]


class _PickArea(QWidget):
    """A widget picked by pressing or dragging the left button (`_pick` says what)."""

    def _pick(self, ev: QMouseEvent) -> None:
        raise NotImplementedError

    def mousePressEvent(self, ev: QMouseEvent) -> None:  # noqa: N802 - Qt's
        self._pick(ev)

    def mouseMoveEvent(self, ev: QMouseEvent) -> None:  # noqa: N802 - Qt's
        if ev.buttons() & Qt.MouseButton.LeftButton:
            self._pick(ev)


class _SVSquare(_PickArea):
    """Saturation (across) and value (down) of one hue, in sRGB."""

    changed = Signal(float, float)  # saturation, value in 0..1

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.hue, self.sat, self.val = 0.0, 0.0, 0.0
        self.setMinimumSize(180, 180)
        self.setCursor(Qt.CursorShape.CrossCursor)

    def set_hsv(self, h: float, s: float, v: float) -> None:
        self.hue, self.sat, self.val = h, s, v
        self.update()

    def paintEvent(self, _ev) -> None:  # noqa: N802 - Qt's
        p = QPainter(self)
        r = QRectF(self.rect()).adjusted(0.5, 0.5, -0.5, -0.5)
        p.fillRect(r, QColor.fromHsvF(self.hue, 1.0, 1.0))
        across = QLinearGradient(r.topLeft(), r.topRight())
        across.setColorAt(0.0, QColor(255, 255, 255, 255))
        across.setColorAt(1.0, QColor(255, 255, 255, 0))
        p.fillRect(r, across)
        down = QLinearGradient(r.topLeft(), r.bottomLeft())
        down.setColorAt(0.0, QColor(0, 0, 0, 0))
        down.setColorAt(1.0, QColor(0, 0, 0, 255))
        p.fillRect(r, down)
        at = QPointF(r.left() + self.sat * r.width(), r.top() + (1 - self.val) * r.height())
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        p.setPen(QPen(QColor(0, 0, 0) if self.val > 0.5 else QColor(255, 255, 255), 1.5))
        p.drawEllipse(at, 5, 5)

    def _pick(self, ev: QMouseEvent) -> None:
        w, h = max(1, self.width() - 1), max(1, self.height() - 1)
        s = min(1.0, max(0.0, ev.position().x() / w))
        v = min(1.0, max(0.0, 1.0 - ev.position().y() / h))
        self.sat, self.val = s, v
        self.update()
        self.changed.emit(s, v)


class _HueStrip(_PickArea):
    changed = Signal(float)  # hue in 0..1

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.hue = 0.0
        self.setFixedWidth(22)
        self.setMinimumHeight(180)
        self.setCursor(Qt.CursorShape.PointingHandCursor)

    def set_hue(self, h: float) -> None:
        self.hue = h
        self.update()

    def paintEvent(self, _ev) -> None:  # noqa: N802 - Qt's
        p = QPainter(self)
        r = QRectF(self.rect())
        g = QLinearGradient(r.topLeft(), r.bottomLeft())
        for i in range(7):
            g.setColorAt(i / 6, QColor.fromHsvF((i / 6) % 1.0, 1.0, 1.0))
        p.fillRect(r, g)
        y = r.top() + self.hue * r.height()
        p.setPen(QPen(QColor(255, 255, 255), 2))
        p.drawLine(QPointF(r.left(), y), QPointF(r.right(), y))

    def _pick(self, ev: QMouseEvent) -> None:
        h = min(0.9999, max(0.0, ev.position().y() / max(1, self.height())))
        self.set_hue(h)
        self.changed.emit(h)


class _Swatch(QWidget):
    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.before: list[float] = [0.0, 0.0, 0.0]
        self.now: list[float] = [0.0, 0.0, 0.0]
        self.setFixedHeight(28)

    def paintEvent(self, _ev) -> None:  # noqa: N802 - Qt's
        p = QPainter(self)
        r = QRectF(self.rect())
        half = r.width() / 2
        for i, c in enumerate((self.before, self.now)):
            shown = QColor.fromRgbF(*(linear_to_srgb(x) for x in split_hdr(c)[0]))
            p.fillRect(QRectF(r.left() + i * half, r.top(), half, r.height()), shown)


class HdrColorDialog(QDialog):
    """Not modal, so it can stay open beside the canvas; see the module's docstring."""

    colorChanged = Signal(list)  # the linear value, HDR

    def __init__(self, linear: list[float], parent: QWidget | None = None,
                 parts: tuple[list[float], float] | None = None) -> None:
        """`parts`: the (display colour, intensity) the field shows, kept as they are (an
        intensity of 3 the artist typed stays 3); else `linear` is split at its peak."""
        super().__init__(parent)
        self.setObjectName("hdrColorDialog")
        self.setWindowTitle("Colour (linear, HDR)")
        self.setModal(False)
        self.initial = [float(c) for c in linear]
        self.display, self.k = (list(parts[0]), float(parts[1])) if parts else \
            split_hdr(self.initial)
        self._hsv = list(QColor.fromRgbF(*(linear_to_srgb(c) for c in self.display)).getHsvF()[:3])
        self.square = _SVSquare()
        self.hue_strip = _HueStrip()
        self.square.changed.connect(self._sv_picked)
        self.hue_strip.changed.connect(self._hue_picked)

        def spin(tip: str, decimals: int = 4) -> NumberSpin:
            s = NumberSpin()
            s.setDecimals(decimals)
            s.setRange(0.0, SPIN_LIMIT)
            s.setSingleStep(0.01)
            s.setToolTip(tip)
            s.setKeyboardTracking(False)
            return s

        self.rgb = [spin(f"{ch} (linear; above 1 is HDR)") for ch in "RGB"]
        for s in self.rgb:
            s.valueChanged.connect(self._rgb_typed)
        self.intensity = spin("Intensity: multiplies the colour (the stops are log2 of it)", 3)
        self.intensity.valueChanged.connect(self._intensity_typed)
        self.ev = QLabel()
        self.hex = QLineEdit()
        self.hex.setMaxLength(HEX_LEN)
        self.hex.setToolTip("The colour (at intensity 1 or less) in sRGB, as #rrggbb")
        self.hex.editingFinished.connect(self._hex_typed)
        self.swatch = _Swatch()
        self.swatch.before = list(self.initial)

        rgb_row = QHBoxLayout()
        for s in self.rgb:
            rgb_row.addWidget(s)
        k_row = QHBoxLayout()
        k_row.addWidget(self.intensity)
        k_row.addWidget(self.ev)
        form = QFormLayout()
        form.addRow("Linear RGB", rgb_row)
        form.addRow("Intensity ×", k_row)
        form.addRow("Hex (sRGB)", self.hex)
        form.addRow("Before | now", self.swatch)
        pick = QHBoxLayout()
        pick.addWidget(self.square, 1)
        pick.addWidget(self.hue_strip)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                   | QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        lay = QVBoxLayout(self)
        lay.addLayout(pick, 1)
        lay.addLayout(form)
        lay.addWidget(buttons)
        self.rejected.connect(self._restore)
        self._show()

    # --- the value --------------------------------------------------------------------------
    def value(self) -> list[float]:
        return [round(c * self.k, 6) for c in self.display]

    def set_value(self, linear: list[float]) -> None:
        """Shows `linear` (re-split into display colour and intensity) and announces it."""
        self.display, self.k = split_hdr([max(0.0, float(c)) for c in linear])
        self._hsv_from_display()
        self._changed()

    def setCurrentColor(self, color: QColor) -> None:  # noqa: N802 - QColorDialog's name
        """An sRGB display colour, at the intensity shown (as dragging in the square does)."""
        self.display = [srgb_to_linear(x) for x in (color.redF(), color.greenF(), color.blueF())]
        self._hsv_from_display()
        self._unmute()
        self._changed()

    # --- edits ------------------------------------------------------------------------------
    def _unmute(self) -> None:
        """A colour picked at intensity 0 would change nothing the artist sees: back to 1."""
        if self.k == 0.0:
            self.k = 1.0

    def _sv_picked(self, s: float, v: float) -> None:
        self._hsv[1], self._hsv[2] = s, v
        self._display_from_hsv()

    def _hue_picked(self, h: float) -> None:
        self._hsv[0] = h
        self._display_from_hsv()

    def _display_from_hsv(self) -> None:
        c = QColor.fromHsvF(*self._hsv)
        self.display = [srgb_to_linear(x) for x in (c.redF(), c.greenF(), c.blueF())]
        self._unmute()
        self._changed()

    def _hsv_from_display(self) -> None:
        h, s, v = QColor.fromRgbF(*(linear_to_srgb(c) for c in self.display)).getHsvF()[:3]
        # an achromatic colour has no hue (Qt says -1): keep the one shown
        self._hsv = [h if h >= 0 else self._hsv[0], s, v]

    def _rgb_typed(self, _v: float) -> None:
        self.set_value([float(s.value()) for s in self.rgb])

    def _intensity_typed(self, v: float) -> None:
        self.k = float(v)
        self._changed()

    def _hex_typed(self) -> None:
        rgb = parse_hex(self.hex.text())
        if rgb is None:
            self.hex.setText(hex_of(self.display))  # not a colour: the shown one again
            return
        self.display = rgb
        self._hsv_from_display()
        self._unmute()
        self._changed()

    def _restore(self) -> None:
        self.set_value(self.initial)

    def _changed(self) -> None:
        self._show()
        self.colorChanged.emit(self.value())

    def _show(self) -> None:
        v = self.value()
        for s, c in zip(self.rgb, v):
            s.blockSignals(True)
            s.setValue(c)
            s.blockSignals(False)
        self.intensity.blockSignals(True)
        self.intensity.setValue(self.k)
        self.intensity.blockSignals(False)
        self.ev.setText(f"{math.log2(self.k):+.2f} EV" if self.k > 0 else "off")
        self.hex.setText(hex_of(self.display))
        self.square.set_hsv(*self._hsv)
        self.hue_strip.set_hue(self._hsv[0])
        self.swatch.now = v
        self.swatch.update()
