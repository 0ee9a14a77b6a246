"""View › Follow Selection in Viewport and the banner's Pin: the viewport previews the node the
artist selects, and a pinned preview stays while other nodes are selected."""

from __future__ import annotations

import pytest
from test_app_support import app_env, settle  # noqa: F401
from test_app_viewport import window  # noqa: F401, F811 - the shown sample

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def _target(w):
    t = w.compiler.preview
    return None if t is None else (t.node_id, t.port)


def test_follow_previews_each_selected_node_and_pin_keeps_one(window, qtbot):  # noqa: F811
    w = window
    canvas = w.tabs.material.canvas
    vp = w.viewport
    view_menu = [a.objectName() for a in w.menus.view.actions()]
    assert "view.follow_selection" in view_menu
    assert not vp.following and vp.pin_button.isHidden()

    canvas.select_nodes(["mask"])  # Follow off: selecting shows nothing new
    settle(qtbot, w)
    assert _target(w) is None

    vp.follow_button.click()  # the bar's button is the View menu's action
    assert vp.following and w.menus.view.actions()[view_menu.index(
        "view.follow_selection")].isChecked()
    canvas.select_nodes(["uv"])
    settle(qtbot, w)
    assert _target(w) == ("uv", "uv")
    assert "Previewing uv.uv" in vp.banner_label.text()
    assert vp.pin_button.isVisibleTo(vp)

    canvas.select_nodes(["mask"])
    settle(qtbot, w)
    assert _target(w) == ("mask", "result")

    vp.pin_button.click()
    assert vp.pinned and "Pinned to mask.result" in vp.banner_label.text()
    canvas.select_nodes(["uv"])
    settle(qtbot, w)
    assert _target(w) == ("mask", "result")  # pinned: the selection does not move it
    assert w.compiler.current is not None

    vp.pin_button.click()  # unpinned: the next selection is followed again
    canvas.select_nodes(["uv"])
    settle(qtbot, w)
    assert _target(w) == ("uv", "uv")

    canvas.select_nodes(["out"])  # the output has nothing of its own: the material
    settle(qtbot, w)
    assert _target(w) is None and not vp.banner.isVisibleTo(vp)

    canvas.select_nodes(["mask", "uv"])  # several: the preview stays as it is
    settle(qtbot, w)
    assert _target(w) is None

    canvas.select_nodes(["mask"])
    vp.pin(True)
    vp.banner_clear.click()  # Show material ends the pin too
    settle(qtbot, w)
    assert _target(w) is None and not vp.pin_button.isChecked()

    vp.set_following(False)
    canvas.select_nodes(["uv"])
    settle(qtbot, w)
    assert _target(w) is None and vp.pin_button.isHidden()
    assert not w.controller.dirty  # previews never touch the document
