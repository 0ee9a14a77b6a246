"""A Texture Sample's texture slot: a file field in the Inspector and an image dropped on the
node make (or fill) the Texture Parameter wired into it, as one undo step."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_preview import _drop
from test_app_support import app_env, make_window, settle  # noqa: F401

from matedit.app.fields import TextureField
from matedit.graph.commands import AddNode
from matedit.graph.model import Node
from matedit.graph.nodes import Role, kind_for, role_of

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def _images(tmp_path):
    from matedit.io.images import write_image

    write_image(tmp_path / "albedo.png", np.full((8, 8, 3), 0.5, np.float32))
    write_image(tmp_path / "rough.exr", np.full((8, 8, 1), 0.5, np.float32))
    return tmp_path / "albedo.png", tmp_path / "rough.exr"


def _param_of(graph, node_id):
    link = graph.incoming(node_id, "texture")
    return None if link is None else graph.nodes[link.src]


def test_the_inspectors_slot_makes_then_fills_the_parameter(qtbot, tmp_path):
    albedo, rough = _images(tmp_path)
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    graph = w.controller.document.graph
    assert w.controller.push(AddNode(Node("ts", kind_for(Role.TEXTURE_SAMPLE), (0.0, 900.0))))
    settle(qtbot, w)
    w.select_node("ts")
    settle(qtbot, w, 50)
    slot = w.inspector._fields[("slot", "texture")]
    assert isinstance(slot, TextureField) and slot.path_edit.text() == ""

    steps = w.controller.undo_stack.count()
    slot.edited.emit(str(albedo), None)  # chosen in the field's file dialog
    settle(qtbot, w)
    tp = _param_of(graph, "ts")
    assert tp is not None and role_of(tp.kind) == Role.TEXTURE_PARAMETER
    assert tp.settings["path"] == "albedo.png" or tp.settings["path"].endswith("albedo.png")
    assert tp.settings["srgb"] is True and w.controller.undo_stack.count() == steps + 1
    names = [n.settings.get("name") for n in graph.nodes.values()
             if role_of(n.kind) == Role.TEXTURE_PARAMETER]
    assert len(names) == len(set(names))  # the new parameter's name is its own
    settle(qtbot, w, 50)
    slot = w.inspector._fields[("slot", "texture")]
    assert slot.path_edit.text() == tp.settings["path"]

    slot.edited.emit(str(rough), None)  # the slot has a parameter now: it takes the file
    settle(qtbot, w, 50)
    assert _param_of(graph, "ts") is tp and tp.settings["path"].endswith("rough.exr")
    assert tp.settings["srgb"] is False  # float data: linear
    assert w.inspector._fields[("slot", "texture")].path_edit.text().endswith("rough.exr")
    w.controller.undo_stack.undo()
    assert tp.settings["path"].endswith("albedo.png")
    w.controller.undo_stack.undo()
    assert _param_of(graph, "ts") is None and tp.id not in graph.nodes


def test_an_image_dropped_on_a_texture_sample_fills_its_slot(qtbot, tmp_path):
    albedo, rough = _images(tmp_path)
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    graph = w.controller.document.graph
    assert w.controller.push(AddNode(Node("ts", kind_for(Role.TEXTURE_SAMPLE), (0.0, 900.0))))
    settle(qtbot, w)
    item = canvas.scene().node_items["ts"]
    canvas.centerOn(item)
    qtbot.wait(5)
    before = set(graph.nodes)
    at = canvas.mapFromScene(item.sceneBoundingRect().center())
    assert _drop(qtbot, canvas.viewport(), [albedo], at)[1]
    tp = _param_of(graph, "ts")
    assert tp is not None and set(graph.nodes) - before == {tp.id}  # no second sample
    # the new parameter sits clear of the other nodes
    rect = canvas.scene().node_items[tp.id].sceneBoundingRect()
    assert not any(rect.intersects(o.sceneBoundingRect()) for nid, o in
                   canvas.scene().node_items.items() if nid != tp.id)
    settle(qtbot, w)
    ptem = canvas.scene().node_items[tp.id]
    assert _drop(qtbot, canvas.viewport(), [rough],
                 canvas.mapFromScene(ptem.sceneBoundingRect().center()))[1]
    assert tp.settings["path"].endswith("rough.exr")  # dropped on the parameter: its file
    assert set(graph.nodes) - before == {tp.id}
