"""The viewport's mesh list takes an OBJ file: drawn, remembered with the document as a path
relative to it, and a bad file is a message with the mesh shown kept."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from test_app_support import app_env, make_window, settle, wait_for_renderer  # noqa: F401
from test_app_viewport import frame

from matedit.app import file_dialogs
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

# a flat square facing the camera, larger than the sphere's silhouette
SQUARE = ("v -1.4 -1.4 0\nv 1.4 -1.4 0\nv 1.4 1.4 0\nv -1.4 1.4 0\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
          "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")


def test_an_obj_file_is_drawn_saved_with_the_document_and_reopened(qtbot, tmp_path,
                                                                   monkeypatch):
    root = tmp_path / "graphs"
    shutil.copytree(graphs_dir(), root)
    doc = root / "materials" / "car_paint.json"
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    obj = meshes / "square.obj"
    obj.write_text(SQUARE)
    w = make_window(qtbot, doc, show=True)
    wait_for_renderer(qtbot, w)
    settle(qtbot, w)
    vp = w.viewport
    sphere = frame(qtbot, vp.view)

    picked = {"path": str(obj)}
    monkeypatch.setattr(file_dialogs, "open_file", lambda *a, **k: (picked["path"], ""))
    combo = vp.mesh_combo
    combo.setCurrentIndex(combo.findData("OBJ file…"))
    assert combo.currentText() == "square.obj" and vp.mesh_spec() == str(obj.resolve())
    assert vp.view.renderer.mesh_name == str(obj.resolve())
    square = frame(qtbot, vp.view)
    h, wd, _ = square.shape
    # the square covers the corners of the sphere's bounding box: the mesh drawn changed
    corner = (slice(h // 2 - 60, h // 2 - 50), slice(wd // 2 - 60, wd // 2 - 50))
    assert np.abs(square[corner] - sphere[corner]).mean() > 0.02

    bad = meshes / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 7\n")
    picked["path"] = str(bad)
    messages = []
    vp.statusMessage.connect(messages.append)
    combo.setCurrentIndex(combo.findData("OBJ file…"))
    assert combo.currentText() == "square.obj"  # kept
    assert messages and "bad.obj" in messages[-1]
    picked["path"] = ""  # a cancelled dialog: the mesh shown stays too
    combo.setCurrentIndex(combo.findData("OBJ file…"))
    assert combo.currentText() == "square.obj"

    assert w.actions.save()
    saved = json.loads(doc.read_text())
    assert saved["preview"]["mesh"] == "../../meshes/square.obj"  # relative to the document
    w2 = make_window(qtbot, doc, show=True)
    wait_for_renderer(qtbot, w2)
    settle(qtbot, w2)
    assert w2.viewport.mesh_combo.currentText() == "square.obj"
    assert w2.viewport.view.renderer.mesh_name == str(obj.resolve())
    w2.viewport.mesh_combo.setCurrentText("sphere")
    assert w2.viewport.view.renderer.mesh_name == "sphere"
