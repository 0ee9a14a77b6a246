"""The float HDR colour picker: linear values above 1, intensity in stops, sRGB hex."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QPoint, Qt
from test_app_support import app_env  # noqa: F401 - fixture

pytestmark = pytest.mark.usefixtures("app_env")


def _srgb8(linear: float) -> int:
    """IEC 61966-2-1, written out: linear -> 8-bit sRGB."""
    c = 12.92 * linear if linear <= 0.0031308 else 1.055 * linear ** (1 / 2.4) - 0.055
    return int(round(c * 255))


def test_typed_linear_values_above_one_and_the_intensity_stay_hdr(qtbot):
    from matedit.app.hdr_picker import HdrColorDialog

    dlg = HdrColorDialog([0.5, 0.5, 0.5])
    qtbot.addWidget(dlg)
    got: list[list[float]] = []
    dlg.colorChanged.connect(got.append)
    assert dlg.hex.text() == "#" + f"{_srgb8(0.5):02x}" * 3  # sRGB 0.5 grey is #bcbcbc
    dlg.rgb[0].setValue(6.0)  # a red light's HDR value, typed
    assert got[-1] == pytest.approx([6.0, 0.5, 0.5])
    assert dlg.intensity.value() == pytest.approx(6.0) and dlg.ev.text() == "+2.58 EV"
    assert dlg.hex.text() == "#" + "".join(f"{_srgb8(c):02x}" for c in (1.0, 0.5 / 6,
                                                                         0.5 / 6))
    dlg.intensity.setValue(12.0)  # one stop brighter: the hue is kept
    assert got[-1] == pytest.approx([12.0, 1.0, 1.0])
    dlg.hex.setText("#ff8000")
    dlg.hex.editingFinished.emit()
    orange = ((128 / 255 + 0.055) / 1.055) ** 2.4
    assert got[-1] == pytest.approx([12.0, 12.0 * orange, 0.0], rel=1e-5)
    dlg.hex.setText("not a colour")
    dlg.hex.editingFinished.emit()
    assert dlg.hex.text() == "#ff8000" and got[-1] == pytest.approx([12.0, 12 * orange, 0])
    dlg.reject()  # Cancel: back to where the picker opened
    assert got[-1] == pytest.approx([0.5, 0.5, 0.5])


def test_the_square_and_the_hue_strip_pick_and_a_black_stop_comes_alive(qtbot):
    from matedit.app.hdr_picker import HdrColorDialog

    dlg = HdrColorDialog([0.0, 0.0, 0.0], parts=([1.0, 0.0, 0.0], 0.0))  # red at x 0
    qtbot.addWidget(dlg)
    dlg.show()
    qtbot.waitExposed(dlg)
    got: list[list[float]] = []
    dlg.colorChanged.connect(got.append)
    sq = dlg.square
    qtbot.mouseClick(sq, Qt.MouseButton.LeftButton, pos=QPoint(sq.width() - 1, 0))
    assert dlg.k == 1.0  # picking at intensity 0 would show nothing: it is raised to 1
    assert got[-1] == pytest.approx([1.0, 0.0, 0.0], abs=1e-6)  # full saturation and value
    strip = dlg.hue_strip  # a third of the way down: green
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, pos=QPoint(5, strip.height() // 3))
    r, g, b = got[-1]
    assert g == pytest.approx(1.0) and r < 0.05 and b < 0.05
    qtbot.mouseClick(sq, Qt.MouseButton.LeftButton, pos=QPoint(0, sq.height() - 1))
    assert got[-1] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)  # value 0: black


def test_the_colour_field_opens_the_hdr_picker(qtbot):
    from matedit.app.fields import ColorField
    from matedit.app.hdr_picker import HdrColorDialog

    f = ColorField([2.0, 1.0, 0.5])
    qtbot.addWidget(f)
    seen: list = []
    f.edited.connect(lambda v, merge: seen.append((v, merge)))
    dlg = f.pick()
    assert isinstance(dlg, HdrColorDialog) and not dlg.isModal()
    assert dlg.value() == pytest.approx([2.0, 1.0, 0.5])
    dlg.rgb[2].setValue(3.0)
    assert f.value() == pytest.approx([2.0, 1.0, 3.0])
    assert len({m for _v, m in seen}) == 1  # the whole pick merges into one undo step
