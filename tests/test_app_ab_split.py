"""View › A/B Split: the material before the last structural edit left of the divider, the
material now right of it, in the real window's viewport under Xvfb."""

from __future__ import annotations

import numpy as np
import pytest
from test_app_support import app_env, settle  # noqa: F401
from test_app_viewport import frame, window  # noqa: F401, F811 - the shown sample

from matedit.graph.commands import SetValue

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def _edited(qtbot, w, edit):
    """Applies a structural edit and waits for its material in the view."""
    before = w.compiler.current
    edit()
    settle(qtbot, w)
    qtbot.waitUntil(lambda: w.compiler.latest is not None and w.compiler.latest is not before,
                    timeout=20000)
    settle(qtbot, w, 50)


def test_split_shows_the_material_before_the_last_edit_on_the_left(window, qtbot):  # noqa: F811
    w = window
    vp = w.viewport
    assert "view.ab_split" in [a.objectName() for a in w.menus.view.actions()]
    original = frame(qtbot, vp.view)
    canvas = w.tabs.material.canvas
    canvas.select_nodes(["mask"])
    _edited(qtbot, w, canvas.toggle_bypass)  # the rust mask bypassed: a structural edit
    edited = frame(qtbot, vp.view)
    h, wd, _ = edited.shape
    assert np.abs(edited - original).mean() > 0.005  # the edit shows on the sphere

    vp.ab_button.click()
    assert vp.comparing and vp.divider.isVisibleTo(vp)
    assert vp.a_label.text() == "A · before the last edit" and vp.b_label.text() == "B · now"
    split = frame(qtbot, vp.view)
    cut = int(round(vp.view.split * wd))
    margin = 2  # the divider's columns aside (8-bit frames: 1/255 tolerance)
    np.testing.assert_allclose(split[:, :cut - margin], original[:, :cut - margin],
                               atol=1.5 / 255)
    np.testing.assert_allclose(split[:, cut + margin:], edited[:, cut + margin:],
                               atol=1.5 / 255)

    # dragging the divider moves where A ends
    g = vp.view.geometry()
    vp.divider.moved.emit(g.x() + int(0.25 * g.width()))
    assert vp.view.split == pytest.approx(0.25, abs=0.01)
    assert abs(vp.divider.geometry().center().x() - (g.x() + 0.25 * g.width())) <= 3
    split = frame(qtbot, vp.view)
    cut = int(round(vp.view.split * wd))
    np.testing.assert_allclose(split[:, cut + margin:], edited[:, cut + margin:],
                               atol=1.5 / 255)
    assert np.abs(split[:, cut // 2] - original[:, cut // 2]).max() <= 1.5 / 255

    # a value edit changes B only: A is the past
    vp.view.set_split(0.5)
    w.controller.push(SetValue("stack", "paint_color", [0.6, 0.05, 0.02]))
    settle(qtbot, w, 50)
    repainted = frame(qtbot, vp.view)
    cut = int(round(0.5 * wd))
    np.testing.assert_allclose(repainted[:, :cut - margin], original[:, :cut - margin],
                               atol=1.5 / 255)
    assert np.abs(repainted[:, cut + margin:] - edited[:, cut + margin:]).mean() > 0.005

    vp.set_comparing(False)
    assert not vp.divider.isVisibleTo(vp)
    off = frame(qtbot, vp.view)
    assert np.abs(off[:, :cut - margin] - original[:, :cut - margin]).mean() > 0.005
    assert w.controller.document.graph.nodes["mask"].muted  # the split never edits
