"""The number entry every field uses (`NumberSpin`: `1e9`, `2,5`, large values in full)
and the colour conversions of the colour fields and the HDR picker."""

from __future__ import annotations

import math
import re

from PySide6.QtGui import QValidator
from PySide6.QtWidgets import QDoubleSpinBox

SPIN_LIMIT = 1e12  # a typed 1e9 stays 1e9 (float32 uniforms hold it)

# What a number field reads as a number while it is typed: a sign, digits with one decimal
# separator ('.' or the locale's ','), and an exponent (1e9, 2.5E-3).
_NUMBER = re.compile(r"[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?")
_PARTIAL = re.compile(r"[+-]?(\d*([.,]\d*)?)([eE][+-]?\d*)?")


class NumberSpin(QDoubleSpinBox):
    """A spin box that reads what artists type: `1e9`, `2,5` as well as `2.5`, and shows a
    large value in full (digits, not a cut-off "100000.000")."""

    def validate(self, text: str, pos: int):  # noqa: D102 - Qt's
        t = text.strip()
        if _NUMBER.fullmatch(t):
            return QValidator.State.Acceptable, text, pos
        if _PARTIAL.fullmatch(t):
            return QValidator.State.Intermediate, text, pos
        return QValidator.State.Invalid, text, pos

    def valueFromText(self, text: str) -> float:  # noqa: N802 - Qt's name
        try:
            v = float(text.strip().replace(",", "."))
        except ValueError:
            return self.value()
        return min(max(v, self.minimum()), self.maximum()) if math.isfinite(v) else self.value()

    def textFromValue(self, value: float) -> str:  # noqa: N802 - Qt's name
        if abs(value) >= 1e4:  # no decimals past ten thousand: the digits fit the field
            return f"{value:.0f}"
        return f"{value:.{self.decimals()}f}"

    def fixup(self, text: str) -> str:
        return text.strip().replace(",", ".")



def linear_to_srgb(c: float) -> float:
    c = max(0.0, min(1.0, c))
    return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055


def srgb_to_linear(c: float) -> float:
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def split_hdr(rgb: list[float]) -> tuple[list[float], float]:
    """An HDR linear colour as (colour with components <= 1, intensity >= 1)."""
    peak = max(rgb) if rgb else 0.0
    k = peak if peak > 1.0 else 1.0
    return [c / k for c in rgb], k
