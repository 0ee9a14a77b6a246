"""Lay out the shipped sample graphs left to right, outputs on the right (a developer tool).

    QT_QPA_PLATFORM=offscreen python tools/layout_samples.py [graphs/materials/x.json ...]

The layout is the editor's Edit › Arrange (`matedit/app/canvas/arrange.py`) over every node,
on the real canvas scene with thumbnails, as tests/test_sample_layouts.py checks it; the
top-left node then sits at the origin. Only node positions and comment frames change.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtWidgets import QApplication  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from test_sample_layouts import SAMPLES, with_thumbnails  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas.arrange import layout, refit_comments, repair  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.io.document import load, save  # noqa: E402


def main(argv: list[str]) -> int:
    QApplication.instance() or QApplication([])
    paths = [Path(a).resolve() for a in argv] or SAMPLES
    bad = 0
    for path in paths:
        doc = load(path)
        before = {n: node.position for n, node in doc.graph.nodes.items()}
        view = NodeCanvasView(DocumentController(doc))
        scene = with_thumbnails(view.scene())
        items = scene.node_items
        sizes = {n: (it.sceneBoundingRect().width(), it.sceneBoundingRect().height())
                 for n, it in items.items()}
        left = repair(scene, layout(scene, list(items)))
        x0 = min(it.pos().x() for it in items.values())
        y0 = min(it.pos().y() for it in items.values())
        after = {n: (it.pos().x() - x0, it.pos().y() - y0) for n, it in items.items()}
        frames = refit_comments(doc.graph, before, after, sizes)
        for n, p in after.items():
            doc.graph.nodes[n].position = p
        for cid, rect in frames.items():
            doc.graph.comments[cid].rect = rect
        save(doc, path)
        print(f"{path.relative_to(ROOT)}: {len(left)} problems left", *left, sep="\n  ")
        bad += bool(left)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
