"""The Textures dock: a folder's images as thumbnails (made off the UI thread, an unreadable
file a placeholder), dragged as file URLs, double-clicked into the selected texture slot
or onto the canvas, and the list following the folder."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle  # noqa: F401

from matedit.graph.commands import AddNode
from matedit.graph.model import Node
from matedit.graph.nodes import Role, kind_for, role_of
from matedit.io.images import read_thumbnail, write_image

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

COLOURS = {"red.png": (1.0, 0.0, 0.0), "green.png": (0.0, 1.0, 0.0),
           "blue.png": (0.0, 0.0, 1.0)}


def _folder(tmp_path):
    d = tmp_path / "textures"
    d.mkdir()
    for name, rgb in COLOURS.items():
        write_image(d / name, np.broadcast_to(np.array(rgb, np.float32), (24, 40, 3)))
    (d / "corrupt.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"not really a png" * 8)
    (d / "notes.txt").write_text("not an image", encoding="utf-8")
    return d


def _browser(qtbot, w, folder):
    tb = w.panels.textures
    w.panels.textures_dock.show()
    w.panels.textures_dock.raise_()
    tb.set_folder(folder)
    qtbot.waitUntil(lambda: tb.isVisible() and tb.model.rowCount() > 0 and all(
        tb.model.item(r).data(tb_module().STATE_ROLE) != "loading"
        for r in range(tb.model.rowCount())), timeout=10000)
    return tb


def tb_module():
    from matedit.app import texture_browser

    return texture_browser


def _rows(tb):
    m = tb_module()
    return {tb.model.item(r).data(m.NAME_ROLE): tb.model.item(r)
            for r in range(tb.model.rowCount())}


def test_read_thumbnail_is_the_box_mean_of_the_file(tmp_path):
    rng = np.random.default_rng(3)
    px = rng.random((50, 70, 3)).astype(np.float32)
    write_image(tmp_path / "a.exr", px)
    data, size = read_thumbnail(tmp_path / "a.exr", 10)
    assert size == (70, 50) and data.pixels.shape == (7, 10, 3)  # 7x5 blocks of pixels
    rows = [np.flatnonzero(np.arange(50) * 7 // 50 == j) for j in range(7)]
    cols = [np.flatnonzero(np.arange(70) * 10 // 70 == i) for i in range(10)]
    want = np.array([[px[np.ix_(r, c)].mean(axis=(0, 1)) for c in cols] for r in rows])
    assert np.abs(data.pixels - want).max() < 1e-5  # float32 sums of 35 pixels
    small, size = read_thumbnail(tmp_path / "a.exr", 100)  # never enlarged
    assert size == (70, 50) and np.array_equal(small.pixels, px)


def test_a_folder_lists_its_images_with_thumbnails_and_a_placeholder(qtbot, tmp_path):
    folder = _folder(tmp_path)
    w = make_window(qtbot, show=True)
    tb = _browser(qtbot, w, folder)
    rows = _rows(tb)
    assert sorted(rows) == ["blue.png", "corrupt.png", "green.png", "red.png"]  # no .txt
    m = tb_module()
    for name, rgb in COLOURS.items():
        item = rows[name]
        assert item.data(m.STATE_ROLE) == "ready"
        assert item.text() == f"{name}\n40×24" and "40 × 24 pixels" in item.toolTip()
        img = item.icon().pixmap(m.THUMB, m.THUMB).toImage()
        c = img.pixelColor(img.width() // 2, img.height() // 2)
        assert max(abs(c.redF() - rgb[0]), abs(c.greenF() - rgb[1]),
                   abs(c.blueF() - rgb[2])) < 2 / 255, (name, c.getRgbF())
    bad = rows["corrupt.png"]
    assert bad.data(m.STATE_ROLE) == "unreadable" and "unreadable" in bad.text()
    tip = bad.toolTip()
    assert tip.startswith("corrupt.png cannot be read") and "Traceback" not in tip
    assert len(tip.splitlines()) >= 2  # the reason, OpenImageIO's words
    assert "4 images" in tb.status.text() and "1 unreadable" in tb.status.text()
    tb.filter_edit.setText("GRE")
    assert tb.proxy.rowCount() == 1
    tb.filter_edit.setText("*d.png")
    assert tb.proxy.rowCount() == 1  # red.png
    tb.filter_edit.setText("")


def test_the_drag_carries_the_file_url(qtbot, tmp_path):
    folder = _folder(tmp_path)
    w = make_window(qtbot, show=True)
    tb = _browser(qtbot, w, folder)
    names = [tb.proxy.index(r, 0).data(tb_module().NAME_ROLE)
             for r in range(tb.proxy.rowCount())]
    index = tb.proxy.index(names.index("red.png"), 0)
    mime = tb.proxy.mimeData([index])
    assert mime.hasUrls() and [u.toLocalFile() for u in mime.urls()] == \
        [str(folder / "red.png")]
    from test_app_preview import _drop

    canvas = w.tabs.material.canvas
    before = set(w.controller.document.graph.nodes)
    assert _drop(qtbot, canvas.viewport(), [folder / "red.png"])[1]  # what the canvas takes
    assert len(set(w.controller.document.graph.nodes) - before) == 2
    bad = tb.proxy.index(names.index("corrupt.png"), 0)
    from PySide6.QtCore import Qt

    assert not tb.proxy.flags(bad) & Qt.ItemFlag.ItemIsDragEnabled


def test_double_click_fills_the_selected_slot_or_adds_a_texture(qtbot, tmp_path):
    folder = _folder(tmp_path)
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    graph = w.controller.document.graph
    assert w.controller.push(AddNode(Node("ts", kind_for(Role.TEXTURE_SAMPLE), (0.0, 900.0))))
    settle(qtbot, w)
    tb = _browser(qtbot, w, folder)
    names = [tb.proxy.index(r, 0).data(tb_module().NAME_ROLE)
             for r in range(tb.proxy.rowCount())]
    green = tb.proxy.index(names.index("green.png"), 0)

    w.select_node("ts")
    settle(qtbot, w)
    steps = w.controller.undo_stack.count()
    before = set(graph.nodes)
    tb.view.activated.emit(green)  # a double-click or Enter
    settle(qtbot, w)
    link = graph.incoming("ts", "texture")
    assert link is not None and set(graph.nodes) - before == {link.src}
    tp = graph.nodes[link.src]
    assert role_of(tp.kind) == Role.TEXTURE_PARAMETER
    assert tp.settings["path"].endswith("green.png")
    assert w.controller.undo_stack.count() == steps + 1
    w.controller.undo_stack.undo()
    assert graph.incoming("ts", "texture") is None and set(graph.nodes) == before

    w.tabs.material.canvas.select_nodes([])
    settle(qtbot, w)
    from PySide6.QtCore import Qt

    tb.view.scrollTo(green)
    at = tb.view.visualRect(green).center()
    qtbot.mouseClick(tb.view.viewport(), Qt.MouseButton.LeftButton, pos=at)
    qtbot.mouseDClick(tb.view.viewport(), Qt.MouseButton.LeftButton, pos=at)  # a real one
    settle(qtbot, w)
    added = set(graph.nodes) - before
    assert len(added) == 2
    params = [graph.nodes[n] for n in added if role_of(graph.nodes[n].kind) ==
              Role.TEXTURE_PARAMETER]
    assert len(params) == 1 and params[0].settings["path"].endswith("green.png")
    sample = next(n for n in added if n != params[0].id)
    assert role_of(graph.nodes[sample].kind) == Role.TEXTURE_SAMPLE
    assert graph.incoming(sample, "texture").src == params[0].id


def test_a_new_file_in_the_folder_is_listed_and_unchanged_ones_are_not_read_again(
        qtbot, tmp_path, monkeypatch):
    folder = _folder(tmp_path)
    w = make_window(qtbot, show=True)
    tb = _browser(qtbot, w, folder)
    m = tb_module()
    made: list[str] = []
    real = m.make_thumb
    monkeypatch.setattr(m, "make_thumb", lambda p, *a: made.append(p.name) or real(p, *a))
    write_image(folder / "yellow.png", np.full((8, 8, 3), (1.0, 1.0, 0.0), np.float32))
    qtbot.waitUntil(lambda: "yellow.png" in _rows(tb) and
                    _rows(tb)["yellow.png"].data(m.STATE_ROLE) == "ready", timeout=10000)
    assert made == ["yellow.png"]  # the other files' thumbnails came from the cache
    assert list(_rows(tb)) == ["blue.png", "corrupt.png", "green.png", "red.png",
                               "yellow.png"]
    (folder / "red.png").unlink()
    qtbot.waitUntil(lambda: "red.png" not in _rows(tb), timeout=10000)
    assert made == ["yellow.png"]


def test_the_folder_follows_the_document(qtbot, tmp_path):
    import shutil

    w = make_window(qtbot, show=True)
    tb = w.panels.textures
    from pathlib import Path

    assert tb.folder == Path.home()  # an unsaved document
    d = tmp_path / "project"
    d.mkdir()
    shutil.copy(EDITOR_SAMPLE, d / "m.json")
    assert w.open_material(d / "m.json")
    settle(qtbot, w)
    assert tb.folder == d.resolve() and tb.folder_edit.text() == str(d.resolve())
