"""The shipped sample graphs are laid out for humans: no two nodes overlap, and no wire runs
through the body of a node other than the two it joins.

Each sample is loaded into the real canvas scene, so node sizes are the editor's own, and
every node of a kind that always shows a thumbnail gets one (its tallest size: a node without
its thumbnail is shorter, with its ports where they were, so it can only clear more room).
The check is geometric, on the scene's items (`layout_problems`, which Edit › Arrange also
uses). tools/layout_samples.py writes the layouts.
"""

from __future__ import annotations

import os

os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

from pathlib import Path  # noqa: E402

import pytest  # noqa: E402
from PySide6.QtGui import QColor, QImage  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas.arrange import layout_problems  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.app.previews import SIZE  # noqa: E402
from matedit.graph.nodes import Thumbnail, definition  # noqa: E402
from matedit.io.document import load  # noqa: E402

pytestmark = pytest.mark.gui

GRAPHS = Path(__file__).resolve().parent.parent / "graphs"
SAMPLES = sorted(p for sub in ("materials", "functions", "layers", "instances")
                 for p in (GRAPHS / sub).glob("*.json") if '"position"' in p.read_text())

def with_thumbnails(scene):
    """Give each node that always shows a thumbnail in the editor a (grey) one."""
    image = QImage(SIZE, SIZE, QImage.Format.Format_RGB32)
    image.fill(QColor(90, 90, 90))
    for nid, item in scene.node_items.items():
        if definition(item.kind).thumbnail == Thumbnail.ALWAYS:
            scene.set_node_preview(nid, image)
    return scene


def sample_scene(qtbot, path: Path):
    view = NodeCanvasView(DocumentController(load(path)))
    qtbot.addWidget(view)
    return with_thumbnails(view.scene())


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_sample_has_no_overlapping_nodes_or_wires_through_nodes(qtbot, path):
    problems = layout_problems(sample_scene(qtbot, path))
    assert not problems, f"{path.name}:\n" + "\n".join(problems)


def test_the_checker_sees_an_overlap_and_a_crossing(qtbot):
    """The check can fail: a node moved onto another, and one placed across a wire."""
    path = GRAPHS / "materials" / "brushed_gold.json"
    doc = load(path)
    out = doc.graph.nodes["out"]
    make = doc.graph.nodes["make"]
    out.position = (make.position[0] + 10, make.position[1] + 10)
    view = NodeCanvasView(DocumentController(doc))
    qtbot.addWidget(view)
    problems = layout_problems(with_thumbnails(view.scene()))
    assert any("overlap" in p for p in problems)
    doc = load(path)
    link = next(iter(sorted(doc.graph.links, key=str)))
    victim = next(n for n in sorted(doc.graph.nodes) if n not in (link.src, link.dst))
    view = NodeCanvasView(DocumentController(doc))
    qtbot.addWidget(view)
    scene = view.scene()
    # the victim's body centred on the wire's midpoint, wherever folded pin groups put it
    wire = scene.wire_items[link]
    mid = wire.mapToScene(wire.path()).pointAtPercent(0.5)
    item = scene.node_items[victim]
    item.setPos(item.pos() + mid - item.sceneBoundingRect().center())
    assert any(f"crosses node {victim}" in p for p in layout_problems(scene))
