"""Edit › Arrange: the selection (or everything) laid out in columns, outputs on the right,
with no overlaps and no wire through a node, as one undo step. Real widgets under Xvfb."""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import pytest  # noqa: E402
from graphs_util import EDITOR_SAMPLE  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas.arrange import layout_problems  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.graph.model import Comment  # noqa: E402
from matedit.io.document import load  # noqa: E402

pytestmark = pytest.mark.gui


def _view(qtbot, doc) -> NodeCanvasView:
    view = NodeCanvasView(DocumentController(doc))
    qtbot.addWidget(view)
    view.resize(1200, 800)
    return view


def _piled(doc):
    """Every node on one spot, a few units apart: a pile an artist cannot read."""
    for i, nid in enumerate(sorted(doc.graph.nodes)):
        doc.graph.nodes[nid].position = (100.0 + 3 * i, 100.0 + 2 * i)
    return doc


def test_arrange_all_clears_a_pile_with_the_output_rightmost_and_undoes_in_one_step(qtbot):
    doc = _piled(load(EDITOR_SAMPLE))
    view = _view(qtbot, doc)
    scene = view.scene()
    before = {n: node.position for n, node in doc.graph.nodes.items()}
    assert layout_problems(scene)  # the pile overlaps: the check can fail
    depth = view.controller.undo_stack.count()
    moved = view.arrange_selection()
    assert moved, "nothing moved"
    assert view.controller.undo_stack.count() == depth + 1
    assert layout_problems(scene) == []
    graph = doc.graph
    out = next(n for n, node in graph.nodes.items() if node.kind == "material_output")
    assert all(graph.nodes[out].position[0] >= node.position[0]
               for n, node in graph.nodes.items() if n != out)
    for link in graph.links:  # every wire runs left to right
        assert graph.nodes[link.src].position[0] < graph.nodes[link.dst].position[0], link
    for nid, item in scene.node_items.items():  # the items show the model
        assert (item.pos().x(), item.pos().y()) == graph.nodes[nid].position
    view.controller.undo_stack.undo()
    assert {n: node.position for n, node in graph.nodes.items()} == before


def test_arrange_a_selection_moves_only_it_and_keeps_it_clear_of_the_rest(qtbot):
    doc = load(EDITOR_SAMPLE)
    graph = doc.graph
    # a chain of three nodes feeding each other, piled onto one spot
    chain = []
    for link in sorted(graph.links, key=str):
        if not chain:
            chain = [link.src, link.dst]
        elif link.src == chain[-1] and link.dst not in chain:
            chain.append(link.dst)
        if len(chain) == 3:
            break
    assert len(chain) == 3, chain
    x, y = graph.nodes[chain[0]].position
    for i, nid in enumerate(chain):
        graph.nodes[nid].position = (x + 5 * i, y + 5 * i)
    others = {n: node.position for n, node in graph.nodes.items() if n not in chain}
    view = _view(qtbot, doc)
    view.select_nodes(chain)
    moved = view.arrange_selection()
    assert set(moved) <= set(chain) and moved
    assert {n: node.position for n, node in graph.nodes.items() if n not in chain} == others
    xs = [graph.nodes[n].position[0] for n in chain]
    assert xs == sorted(xs) and len(set(xs)) == 3, xs  # upstream to the left
    scene = view.scene()
    rects = {n: scene.node_items[n].sceneBoundingRect() for n in graph.nodes}
    for a in chain:
        for b in graph.nodes:
            if a != b:
                assert not rects[a].intersects(rects[b]), (a, b)


def test_arranging_twice_changes_nothing_and_says_so(qtbot):
    doc = _piled(load(EDITOR_SAMPLE))
    view = _view(qtbot, doc)
    messages = []
    view.message.connect(messages.append)
    assert view.arrange_selection()
    depth = view.controller.undo_stack.count()
    assert view.arrange_selection() == []
    assert view.controller.undo_stack.count() == depth
    assert messages[-1] == "Already arranged"


def test_a_comment_frames_its_nodes_again_after_arrange(qtbot):
    doc = load(EDITOR_SAMPLE)
    graph = doc.graph
    ids = sorted(graph.nodes)[:2]
    xs = [graph.nodes[n].position for n in ids]
    left, top = min(p[0] for p in xs) - 10, min(p[1] for p in xs) - 10
    right, bottom = max(p[0] for p in xs) + 10, max(p[1] for p in xs) + 10
    graph.comments["c"] = Comment("c", "Two", (left, top, right - left, bottom - top),
                                  (0.3, 0.3, 0.4))
    _piled(doc)
    for n, p in zip(ids, xs, strict=True):  # the two framed nodes stay where the frame is
        graph.nodes[n].position = p
    view = _view(qtbot, doc)
    view.arrange_selection()
    x, y, w, h = graph.comments["c"].rect
    for n in ids:
        px, py = graph.nodes[n].position
        assert x <= px <= x + w and y <= py <= y + h, (n, (px, py), graph.comments["c"].rect)


def test_arrange_is_in_the_edit_menu_and_the_canvas_menu():
    from matedit.app.canvas.actions import CONTEXT_MENU, EDIT_MENU, TABLE

    assert "arrange" in EDIT_MENU and "arrange" in CONTEXT_MENU
    assert next(c for c in TABLE if c.id == "arrange").keys == ("L",)
