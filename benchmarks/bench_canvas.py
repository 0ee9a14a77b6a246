"""Node canvas responsiveness on 1,000-node graphs: building through the model, and frame times.

Run: .venv/bin/python benchmarks/bench_canvas.py   (starts a virtual X server when there is
no DISPLAY; prints figures, passes or fails nothing)

Two graphs: "typical", 1,000 nodes in 40 columns whose wires join neighbouring columns, as
a material graph is laid out; and "stress", the compiler benchmark's random DAG on the same
grid, whose wires run anywhere and mostly cross the whole view.
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("QT_QPA_PLATFORM", "xcb")

import numpy as np  # noqa: E402
from common import synthetic_material  # noqa: E402

from matedit.graph.commands import AddNode, Connect  # noqa: E402
from matedit.graph.model import Link, MaterialDocument, Node  # noqa: E402

COLS, DX, DY = 40, 230.0, 150.0
INPUTS = {"add": ["a", "b"], "multiply": ["a", "b"], "lerp": ["a", "b", "alpha"],
          "smoothstep": ["edge0", "edge1", "value"], "one_minus": ["value"], "sin": ["value"],
          "max": ["a", "b"], "subtract": ["a", "b"]}


def _display():
    """A virtual X server when none is running (the same one pytest-xvfb uses)."""
    if os.environ.get("DISPLAY") or os.environ["QT_QPA_PLATFORM"] != "xcb":
        return None
    from pyvirtualdisplay import Display

    d = Display(visible=False, size=(1600, 1000), color_depth=24)
    d.start()
    return d


def typical_graph(n: int = 1000, seed: int = 3) -> MaterialDocument:
    """n nodes, column by column; each input fed from a nearby row of the previous column."""
    rng = np.random.default_rng(seed)
    doc = MaterialDocument(name="bench")
    g = doc.graph
    rows = n // COLS
    kinds = list(INPUTS)
    for i in range(n):
        col, row = divmod(i, rows)
        nid = f"n{i}"
        if col == 0:
            g.nodes[nid] = Node(nid, "scalar_parameter", (0.0, row * DY), {"name": nid},
                                {"value": 0.5})
            continue
        kind = kinds[int(rng.integers(len(kinds)))]
        g.nodes[nid] = Node(nid, kind, (col * DX, row * DY))
        for port in INPUTS[kind]:
            if rng.random() < 0.75:
                src_row = int(np.clip(row + rng.integers(-2, 3), 0, rows - 1))
                src = f"n{(col - 1) * rows + src_row}"
                out = "value" if col == 1 else "result"
                g.links.add(Link(src, out, nid, port))
    return doc


def stress_graph(n: int = 1000) -> MaterialDocument:
    """`synthetic_material` (random links) cut to n nodes and laid out on the same grid."""
    doc = synthetic_material(n)
    keep = sorted(doc.graph.nodes, key=lambda k: (len(k), k))[:n]
    doc.graph.nodes = {k: doc.graph.nodes[k] for k in keep}
    doc.graph.links = {l for l in doc.graph.links if l.src in doc.graph.nodes
                       and l.dst in doc.graph.nodes}
    for i, nid in enumerate(keep):
        doc.graph.nodes[nid].position = (float(i % COLS) * DX, float(i // COLS) * DY)
    return doc


def _median_ms(fn, repeat: int = 30) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times) * 1000.0


def measure(app, doc: MaterialDocument) -> dict:
    from PySide6.QtCore import QPointF

    from matedit.app.canvas import NodeCanvasView
    from matedit.app.controller import DocumentController

    nodes = list(doc.graph.nodes.values())
    links = sorted(doc.graph.links)
    out: dict = {"nodes": len(nodes), "links": len(links)}

    bare = DocumentController()  # the model alone, for comparison
    t = time.perf_counter()
    bare.push_all([AddNode(n.clone()) for n in nodes], "add")
    out["model_add"] = time.perf_counter() - t

    controller = DocumentController()
    view = NodeCanvasView(controller)
    view.resize(1400, 900)
    view.show()
    app.processEvents()
    t = time.perf_counter()
    controller.push_all([AddNode(n.clone()) for n in nodes], "add nodes")
    out["add"] = time.perf_counter() - t
    t = time.perf_counter()
    controller.push_all([Connect(l) for l in links], "connect")
    out["connect"] = time.perf_counter() - t
    t = time.perf_counter()
    controller.flush()  # analysis, then the canvas takes types and diagnostics from it
    out["analysis"] = time.perf_counter() - t
    scene = view.scene()
    assert len(scene.node_items) == len(nodes) and len(scene.wire_items) == len(links)

    vp = view.viewport()
    view.frame_all()
    app.processEvents()
    for _ in range(3):
        vp.repaint()
    out["frame_all"] = _median_ms(vp.repaint)
    out["zoom_all"] = view.zoom()

    view.resetTransform()
    view.centerOn(QPointF(COLS / 2 * DX, 12 * DY))
    for _ in range(3):
        vp.repaint()
    out["frame_1"] = _median_ms(vp.repaint)

    bar = view.horizontalScrollBar()

    def pan() -> None:
        bar.setValue(bar.value() + 7)
        vp.repaint()

    out["pan"] = _median_ms(pan)

    visible = view.mapToScene(vp.rect()).boundingRect()
    ids = [nid for nid, it in scene.node_items.items()
           if visible.contains(it.sceneBoundingRect())]
    item = scene.node_items[max(ids, key=lambda k: len(scene._wires_of[k]))]
    out["degree"] = len(scene._wires_of[item.node_id])

    def drag() -> None:
        item.setPos(item.pos() + QPointF(3, 2))
        vp.repaint()

    out["drag"] = _median_ms(drag)

    t = time.perf_counter()
    controller.undo_stack.undo()
    controller.undo_stack.undo()
    out["undo"] = time.perf_counter() - t
    assert not scene.node_items
    view.close()
    view.deleteLater()
    return out


def report(name: str, r: dict) -> None:
    print(f"{name}: {r['nodes']} nodes, {r['links']} links")
    print(f"  add {r['nodes']} nodes through the model, canvas live  {r['add'] * 1e3:8.1f} ms"
          f"   (model alone {r['model_add'] * 1e3:.1f} ms)")
    print(f"  connect {r['links']} links (one macro)               {r['connect'] * 1e3:8.1f} ms")
    print(f"  analysis, then types and badges on the canvas    {r['analysis'] * 1e3:8.1f} ms")
    print(f"  median frame, all in view (zoom {r['zoom_all']:.2f})          "
          f"{r['frame_all']:8.2f} ms")
    print(f"  median frame, zoom 1                             {r['frame_1']:8.2f} ms")
    print(f"  median frame while panning, zoom 1               {r['pan']:8.2f} ms")
    print(f"  median frame while dragging a node ({r['degree']:2d} wires)   {r['drag']:8.2f} ms")
    print(f"  undo the links, then the nodes                   {r['undo'] * 1e3:8.1f} ms")


def main() -> None:
    display = _display()
    try:
        from PySide6.QtWidgets import QApplication

        import matedit.app.canvas  # noqa: F401  (applies the PySide6 6.12 guard first)

        app = QApplication.instance() or QApplication([])
        print(f"bench_canvas: view 1400x900, {os.cpu_count()} cores, "
              f"Qt platform {app.platformName()}")
        report("typical", measure(app, typical_graph()))
        report("stress ", measure(app, stress_graph()))
    finally:
        if display is not None:
            display.stop()


if __name__ == "__main__":
    main()
