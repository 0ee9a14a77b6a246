"""The viewport's view chooser (tool bar): every view of matedit.shading.views is listed and
switches what the renderer draws; the first showing of a view links one program, a second
showing links none (real GL under Xvfb)."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401
from test_app_viewport import frame

from matedit.shading.views import VIEWS

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


@pytest.fixture
def window(qtbot, request):
    request.getfixturevalue("app_env")
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    return w


def test_the_toolbar_lists_every_view_and_switches_the_renderer(window, qtbot):
    vp = window.viewport
    combo = vp.view_combo
    listed = [combo.itemData(i) for i in range(combo.count()) if combo.itemData(i)]
    assert listed == list(VIEWS)
    assert combo.itemText(combo.findData("coat-weight")) == "Coat weight"
    r = vp.view.renderer
    lit = frame(qtbot, vp.view)
    links = r.link_count + r.lighting.link_count
    vp.set_view("roughness")  # as the user picks it from the menu
    assert r.view == "roughness" and r.is_forward  # an attribute view draws forward
    rough = frame(qtbot, vp.view)
    assert np.abs(rough - lit).mean() > 0.02  # a grey level, not the shading
    assert r.link_count + r.lighting.link_count == links + 1  # one program, for the view
    vp.set_view("base")
    assert r.view == "base"
    frame(qtbot, vp.view)
    vp.set_view("lit")
    assert r.view == "lit"
    again = frame(qtbot, vp.view)
    np.testing.assert_allclose(again, lit, atol=2 / 255)  # back to the same image
    n = r.link_count + r.lighting.link_count
    vp.set_view("roughness")  # shown before: cached, nothing links
    frame(qtbot, vp.view)
    assert r.link_count + r.lighting.link_count == n
    vp.set_view("lit")


def test_the_view_is_kept_when_the_renderer_starts_later(qtbot, request):
    request.getfixturevalue("app_env")
    w = make_window(qtbot, EDITOR_SAMPLE, show=False)
    w.viewport.set_view("coat-weight")  # before GL is up: applied at initializeGL
    w.show()
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    assert w.viewport.view.renderer.view == "coat-weight"
