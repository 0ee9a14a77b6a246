"""A short artist session in the real window, driven by keyboard and mouse events under Xvfb:
open a second document, go back to the first by its tab, collapse part of its graph into a
material function, save, make an instance of it, override a layer parameter in the
instance's tab by typing, export it with the round-trip check from the options dialog, and
close everything with the save prompts answered. What the files hold afterwards is read
back by the loaders the command line uses."""

from __future__ import annotations

import json
import re
import shutil

import pygltflib
import pytest
from PySide6.QtCore import Qt, QTimer
from PySide6.QtTest import QTest
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401

from matedit.app import file_dialogs
from matedit.io.document import load
from matedit.io.instance import load_effective, load_instance
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]
CTRL = Qt.KeyboardModifier.ControlModifier
SHIFT = Qt.KeyboardModifier.ShiftModifier


def _type_into(qtbot, spin, text: str) -> None:
    """Select the spin box's text and type `text`, then Enter, as a user does."""
    spin.setFocus()
    QTest.keyClick(spin, Qt.Key.Key_A, CTRL)
    QTest.keyClicks(spin, text)
    QTest.keyClick(spin, Qt.Key.Key_Return)
    qtbot.wait(20)


def test_an_artist_session_from_open_to_close_all(qtbot, tmp_path, monkeypatch):
    root = tmp_path / "graphs"
    shutil.copytree(graphs_dir(), root)
    first = root / "materials" / "rusty_painted_metal.json"
    second = root / "materials" / "velvet.json"
    function = tmp_path / "mine" / "rust_mask.json"
    function.parent.mkdir()
    instance = tmp_path / "mine" / "rusty_blue.json"
    w = make_window(qtbot, first, show=True, answers={"save_changes": "save"})
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    w.activateWindow()  # the window's shortcuts answer while it is the active one
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    docs = w.documents

    # File › Open (Ctrl+O) a second material: a second tab, active
    monkeypatch.setattr(file_dialogs, "open_file", lambda *a, **k: (str(second), ""))
    QTest.keyClick(w, Qt.Key.Key_O, CTRL)
    settle(qtbot, w)
    assert docs.count() == 2 and w.controller.document.path == second

    # back to the first by a click on its tab
    bar = docs.bar
    first_tab = next(i for i in range(bar.count()) if "Rusty" in bar.tabText(i))
    QTest.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(first_tab).center())
    settle(qtbot, w)
    assert w.controller.document.path == first

    # collapse the rust mask's nodes into a function (Ctrl+G on the canvas)
    canvas = w.tabs.material.canvas
    canvas.ask_function_path = lambda _suggested: str(function)
    before = set(w.controller.document.graph.nodes)
    canvas.select_nodes(["mask_noise", "edge", "hi", "mask"])  # e0 and e1 sit between
    canvas.setFocus()
    QTest.keyClick(canvas, Qt.Key.Key_G, CTRL)
    settle(qtbot, w)
    assert "Cannot collapse: e0, e1 sit between selected nodes" in \
        w.statusBar().currentMessage()
    assert set(w.controller.document.graph.nodes) == before and not function.exists()
    mask = ["mask_noise", "edge", "e0", "e1", "hi", "mask"]
    canvas.select_nodes(mask)
    QTest.keyClick(canvas, Qt.Key.Key_G, CTRL)
    settle(qtbot, w)
    graph = w.controller.document.graph
    calls = [n for n in graph.nodes.values() if n.kind == "function_call"
             and n.id not in before]
    assert len(calls) == 1 and function.is_file()
    assert not set(mask) & set(graph.nodes)
    settle(qtbot, w, 50)
    assert w.compiler.current is not None, w.compiler.diagnostics

    # save (Ctrl+S), then File › New Instance of Material… saved beside the function
    QTest.keyClick(w, Qt.Key.Key_S, CTRL)
    settle(qtbot, w)
    assert any(n["kind"] == "function_call" for n in json.loads(first.read_text())["nodes"])
    monkeypatch.setattr(file_dialogs, "save_file", lambda *a, **k: (str(instance), ""))
    w.instances.new_action.trigger()
    settle(qtbot, w)
    assert docs.count() == 3 and instance.is_file()
    editor = docs.current.editor
    assert editor is not None

    # override a layer parameter by typing into its field: the stack's rust scale
    row = editor.panel.rows["rust_scale"]
    _type_into(qtbot, row.field.spin, "21.5")
    assert editor.value("rust_scale") == pytest.approx(21.5)
    assert docs.current.dirty

    # File › Export glTF… on the instance's tab: the path typed, the round-trip check
    # ticked and Export clicked in the options dialog, which is then closed with Escape
    out = tmp_path / "out" / "rusty_blue.glb"
    out.parent.mkdir()
    seen: dict = {}

    def drive() -> None:
        dlg = w.menus.interop.dialog
        dlg.path.setFocus()
        QTest.keyClick(dlg.path, Qt.Key.Key_A, CTRL)
        QTest.keyClicks(dlg.path, str(out))
        dlg.size.setFocus()
        while dlg.size.currentData() != 256:  # the smallest bake, by the arrow keys
            QTest.keyClick(dlg.size, Qt.Key.Key_Up)
        if not dlg.check.isChecked():
            QTest.mouseClick(dlg.check, Qt.MouseButton.LeftButton,
                             pos=dlg.check.rect().center())
        QTest.mouseClick(dlg.export_button, Qt.MouseButton.LeftButton)
        seen["text"], seen["ok"] = dlg.result.toPlainText(), dlg.ok
        QTest.keyClick(dlg, Qt.Key.Key_Escape)

    QTimer.singleShot(0, drive)
    w.menus.interop.act_gltf.trigger()
    assert seen.get("ok"), seen
    assert re.search(r"round trip: mean ΔE \d+\.\d\d max ΔE", seen["text"]), seen["text"]
    gltf = pygltflib.GLTF2().load(str(out))
    assert gltf.materials[0].name == "rusty_blue"  # the instance's material, as it is named

    # close everything (Ctrl+Shift+W); every prompt is answered "save"
    w.activateWindow()  # the closed dialog hands the keyboard back to the window
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    QTest.keyClick(w, Qt.Key.Key_W, CTRL | SHIFT)
    settle(qtbot, w)
    assert docs.count() == 1 and docs.current.untouched  # an empty, untitled material
    saved = load_instance(instance)
    assert saved.parameters["rust_scale"] == pytest.approx(21.5)
    effective, warnings = load_effective(instance)
    assert not warnings
    stack = next(n for n in effective.graph.nodes.values() if n.kind == "layer_stack")
    assert stack.values["rust_scale"] == pytest.approx(21.5)
    assert any(n.kind == "function_call" for n in load(first).graph.nodes.values())
