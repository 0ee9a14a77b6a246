"""Preview any node in the viewport, drop files on the canvas and the viewport, and save the
viewport's picture: through the real window, its renderer under Xvfb."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401
from test_app_viewport import frame

from matedit.graph.commands import MoveNodes
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = EDITOR_SAMPLE


@pytest.fixture
def window(qtbot, request):
    request.getfixturevalue("app_env")
    w = make_window(qtbot, SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    return w


def _context_menu_actions(qtbot, canvas, node_id, monkeypatch):
    """Right-clicks a node and returns the menu's actions (the menu itself never blocks)."""
    from PySide6.QtGui import QContextMenuEvent
    from PySide6.QtWidgets import QApplication

    shown = []
    monkeypatch.setattr(canvas, "run_menu", lambda menu, at: shown.append(menu.actions()))
    item = canvas.scene().node_items[node_id]
    canvas.centerOn(item)
    qtbot.wait(5)
    pos = canvas.mapFromScene(item.sceneBoundingRect().center())
    ev = QContextMenuEvent(QContextMenuEvent.Reason.Mouse, pos, canvas.mapToGlobal(pos))
    QApplication.sendEvent(canvas.viewport(), ev)
    assert shown, "no context menu"
    return shown[-1]


def test_preview_in_viewport_shows_a_scalar_as_grey_and_leaves_the_document_alone(
        window, qtbot, monkeypatch):
    w = window
    before_doc = w.controller.document.graph.snapshot()
    steps = w.controller.undo_stack.count()
    material = frame(qtbot, w.viewport.view)
    hash_before = w.compiler.current.structure_hash

    actions = _context_menu_actions(qtbot, w.tabs.material.canvas, "mask", monkeypatch)
    (act,) = [a for a in actions if a.text().startswith("Preview in viewport")]
    assert act.isEnabled() and "result" in act.text()
    act.trigger()
    settle(qtbot, w)
    assert w.viewport.banner.isVisibleTo(w.viewport)
    assert "mask.result" in w.viewport.banner_label.text()
    shown = frame(qtbot, w.viewport.view)
    h, wd, _ = shown.shape
    centre = shown[h // 2 - 20:h // 2 + 20, wd // 2 - 20:wd // 2 + 20].reshape(-1, 3)
    # A scalar as grey: unlit emission, so the three channels agree (8-bit rounding aside).
    assert np.abs(centre - centre.mean(axis=1, keepdims=True)).max() < 2.5 / 255
    assert np.abs(shown - material).mean() > 0.02  # and it is not the material
    # Nothing happened to the document: same graph, no undo step, nothing to save.
    assert w.controller.document.graph.snapshot() == before_doc
    assert w.controller.undo_stack.count() == steps and not w.controller.dirty
    assert w.compiler.for_target("glsl330").structure_hash == hash_before  # exports: material

    # A vector output shows as false colour; a layer stack as the shaded material.
    assert w.tabs.material.canvas.preview_node("uv", "uv")
    settle(qtbot, w)
    assert w.compiler.current is not None and "uv.uv" in w.viewport.banner_label.text()

    w.viewport.banner_clear.click()
    settle(qtbot, w)
    assert not w.viewport.banner.isVisibleTo(w.viewport)
    assert w.compiler.current.structure_hash == hash_before
    again = frame(qtbot, w.viewport.view)
    assert np.abs(again - material).max() < 3 / 255


def test_preview_ends_when_its_node_is_deleted(window, qtbot):
    from matedit.graph.commands import RemoveNode

    w = window
    assert w.tabs.material.canvas.preview_node("mask_noise")
    settle(qtbot, w)
    assert w.compiler.preview is not None
    assert w.controller.push(RemoveNode("mask_noise"))
    settle(qtbot, w)
    assert w.compiler.preview is None and not w.viewport.banner.isVisibleTo(w.viewport)


def _drop(qtbot, widget, paths: list[Path], pos=None):
    from PySide6.QtCore import QMimeData, QPointF, Qt, QUrl
    from PySide6.QtGui import QDragEnterEvent, QDropEvent
    from PySide6.QtWidgets import QApplication

    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(p)) for p in paths])
    at = pos if pos is not None else widget.rect().center()
    enter = QDragEnterEvent(at, Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
                            Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(widget, enter)
    drop = QDropEvent(QPointF(at), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
                      Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(widget, drop)
    qtbot.wait(5)
    return enter.isAccepted(), drop.isAccepted()


def test_images_dropped_on_the_canvas_become_wired_textures_with_a_guessed_colour_space(
        qtbot, tmp_path):
    from matedit.io.images import write_image

    write_image(tmp_path / "albedo.png", np.full((8, 8, 3), 0.5, np.float32))
    write_image(tmp_path / "height.png", np.full((8, 8, 1), 0.5, np.float32))
    write_image(tmp_path / "light.exr", np.full((8, 8, 3), 2.0, np.float32))
    w = make_window(qtbot, SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    g = w.controller.document.graph
    for name, srgb in (("albedo.png", True), ("height.png", False), ("light.exr", False)):
        before, steps = set(g.nodes), w.controller.undo_stack.count()
        assert _drop(qtbot, canvas.viewport(), [tmp_path / name]) == (True, True)
        new = set(g.nodes) - before
        kinds = {g.nodes[n].kind: g.nodes[n] for n in new}
        assert set(kinds) == {"texture_parameter", "texture_sample"}, name
        tp, ts = kinds["texture_parameter"], kinds["texture_sample"]
        assert tp.settings["srgb"] is srgb, name
        assert Path(tp.settings["path"]).name == name
        assert g.incoming(ts.id, "texture").src == tp.id
        assert w.controller.undo_stack.count() == steps + 1  # one undo step
        # out of the way: an image dropped on a node fills that node's texture slot instead
        # (tests/test_app_texture_slot.py)
        w.controller.push(MoveNodes({n: (g.nodes[n].position[0] - 3000.0,
                                         g.nodes[n].position[1]) for n in new}))
    settle(qtbot, w)
    assert w.compiler.current is not None


def test_function_and_material_files_dropped_on_the_canvas(qtbot):
    w = make_window(qtbot, SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    g = w.controller.document.graph
    before = set(g.nodes)
    fn = graphs_dir() / "functions" / "fresnel_rim.json"
    assert _drop(qtbot, canvas.viewport(), [fn]) == (True, True)
    (call,) = set(g.nodes) - before
    assert g.nodes[call].kind == "function_call"
    # a shipped function, from a material outside the library: by its library name
    assert g.nodes[call].settings["function"] == "library:functions/fresnel_rim.json"
    settle(qtbot, w)
    assert w.compiler.current is not None  # and it resolves
    other = graphs_dir() / "materials" / "brushed_gold.json"
    _drop(qtbot, canvas.viewport(), [other])  # a material: opened (the edit is discarded)
    assert w.controller.document.path == other


def test_an_hdr_dropped_on_the_viewport_becomes_the_environment(qtbot, tmp_path, monkeypatch):
    from matedit.io.images import write_image

    env = tmp_path / "sky.exr"
    write_image(env, np.ones((8, 16, 3), np.float32))
    w = make_window(qtbot, SAMPLE, show=True)
    chosen = []
    monkeypatch.setattr(w.viewport, "choose_environment", chosen.append)
    assert _drop(qtbot, w.viewport, [env])[1]
    assert chosen == [str(env)]
    assert _drop(qtbot, w.viewport, [tmp_path / "notes.txt"]) == (False, False)
    assert chosen == [str(env)]


def test_save_viewport_image_as_png_and_linear_exr(window, qtbot, tmp_path):
    from matedit.io.images import read_image

    w = window
    shown = frame(qtbot, w.viewport.view)
    w.viewport.save_dialog = lambda *a: (str(tmp_path / "shot.png"), "")
    dialogs = []

    def size_dialog(view_size, parent):  # the options dialog, answered at the view's size
        from matedit.app.image_dialog import ImageSizeDialog

        dlg = ImageSizeDialog(view_size, parent)
        dlg.exec = lambda: True
        dialogs.append(dlg)
        return dlg

    w.viewport.size_dialog = size_dialog
    assert w.viewport.save_image_dialog()
    assert dialogs[0].chosen() == (w.viewport.view_pixels(), "png")
    png = read_image(tmp_path / "shot.png").pixels[..., :3]
    assert png.shape == shown.shape
    assert np.abs(png - shown).max() < 1.5 / 255  # the frame as shown, 8-bit
    assert w.menus.save_image in w.menus.file.actions()

    # another size: drawn offscreen, the same picture at that size; the view unchanged
    assert w.viewport.save_image(tmp_path / "big.png", (640, 480))
    big = read_image(tmp_path / "big.png").pixels[..., :3]
    assert big.shape == (480, 640, 3)
    assert w.viewport.view.renderer.size == w.viewport.view_pixels()
    assert abs(float(big.mean()) - float(shown.mean())) < 0.05  # the same scene, framed alike
    assert w.viewport.save_image(tmp_path / "big.exr", (320, 200))
    big_exr = read_image(tmp_path / "big.exr")
    assert big_exr.pixels.shape[:2] == (200, 320) and not big_exr.is_ldr
    np.testing.assert_allclose(frame(qtbot, w.viewport.view), shown, atol=1.5 / 255)

    assert w.viewport.save_image(tmp_path / "shot.exr")
    exr = read_image(tmp_path / "shot.exr")
    assert not exr.is_ldr
    hdr = w.viewport.view.read_hdr()
    assert exr.pixels.shape[:2] == hdr.shape[:2]
    assert np.allclose(exr.pixels[..., :3], hdr, atol=1e-6)  # scene-linear, as rendered
    assert np.isfinite(hdr).all() and hdr.max() > 0.0

    # Never over a file the material reads.
    texture = tmp_path / "albedo.png"
    texture.write_bytes(b"not overwritten")
    w.tabs.material.canvas.add_texture(texture, __import__(
        "PySide6.QtCore", fromlist=["QPointF"]).QPointF(0, 900))
    settle(qtbot, w)
    assert not w.viewport.save_image(texture)
    assert texture.read_bytes() == b"not overwritten"
