"""A Layer Stack that grows with a new layer never covers its neighbours: the nodes it would
cover move down, clear of it and of each other, in the same undo step as the layer."""

from __future__ import annotations

import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle  # noqa: F401

from matedit.graph.commands import AddNode
from matedit.graph.model import Node
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def _overlaps(scene, nid):
    r = scene.node_items[nid].sceneBoundingRect()
    return [o for o, it in scene.node_items.items()
            if o != nid and it.sceneBoundingRect().intersects(r)]


def test_adding_layers_pushes_the_nodes_below_the_stack_down(qtbot):
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    scene = w.tabs.material.canvas.scene()
    graph = w.controller.document.graph
    settle(qtbot, w, 50)
    stack = scene.node_items["stack"].sceneBoundingRect()
    # two nodes right under the stack, one under the other, and one far away
    x, y = stack.left(), stack.bottom() + 30.0
    for nid, dy in (("below", 0.0), ("further", 90.0)):
        assert w.controller.push(AddNode(Node(nid, "value_noise", (x, y + dy))))
    assert w.controller.push(AddNode(Node("away", "value_noise", (x - 2000.0, y))))
    settle(qtbot, w)
    assert not _overlaps(scene, "stack")
    far = graph.nodes["away"].position
    steps = w.controller.undo_stack.count()
    before = {n: graph.nodes[n].position for n in ("below", "further")}

    for _ in range(2):
        assert w.layers.add_layer_file(graphs_dir() / "layers" / "gold.json")
        settle(qtbot, w)
    grown = scene.node_items["stack"].sceneBoundingRect()
    assert grown.height() > stack.height() + 40  # it grew
    for nid in ("stack", "below", "further"):
        assert not _overlaps(scene, nid), nid
    assert graph.nodes["below"].position[1] > before["below"][1]
    assert graph.nodes["below"].position[0] == before["below"][0]  # straight down
    assert graph.nodes["away"].position == far  # nodes not covered stay
    assert w.controller.undo_stack.count() == steps + 2  # one step a layer, moves included

    w.controller.undo_stack.undo()
    w.controller.undo_stack.undo()
    settle(qtbot, w)
    assert {n: graph.nodes[n].position for n in before} == before
    assert len(graph.nodes["stack"].settings["layers"]) == 2
    w.controller.undo_stack.redo()
    settle(qtbot, w)
    assert not _overlaps(scene, "stack") and not _overlaps(scene, "below")
