"""Where a new node goes: near where it was asked for, never on another node.

A node added from the palette, pasted or duplicated is nudged into the nearest free space
(searched on square rings of growing size around the asked-for place, down and right
first), so it never lands on a node already there. Sizes come from the same geometry the
node items use (`measure`), before any item exists.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from PySide6.QtCore import QPointF, QRectF

from matedit.app.canvas import constants as C
from matedit.app.canvas.interaction import kind_ports
from matedit.app.canvas.node_item import NodeItem, measure
from matedit.app.canvas.scene import describe, expanded_groups, port_rows
from matedit.graph.model import Node

GAP = 16.0  # the clear space kept around a placed node
STEP = 24.0  # the search's grid
MAX_RINGS = 60  # about 1,400 scene units each way; past that the asked-for place is kept


def node_rect(node: Node) -> QRectF:
    """The scene rectangle a node will take (its kind's fresh ports; a minimum size where
    the ports need a function file first)."""
    ports = kind_ports(node.kind)
    title, sub, _, _ = describe(node)
    if ports is None:
        w, h = C.NODE_MIN_WIDTH, C.HEADER_HEIGHT + 3 * C.ROW_HEIGHT
    else:
        lay = measure(title, sub, port_rows(node.kind, ports.inputs),
                      port_rows(node.kind, ports.outputs), expanded=expanded_groups(node))
        w, h = lay.width, lay.height
    return QRectF(node.position[0], node.position[1], w, h)


def taken_rects(scene, exclude: Iterable[str] = ()) -> list[QRectF]:
    """The scene rectangles of the nodes already on `scene` (but `exclude`)."""
    skip = set(exclude)
    return [it.sceneBoundingRect() for it in scene.items()
            if isinstance(it, NodeItem) and it.node_id not in skip]


def _forbidden(rects: list[QRectF], taken: list[QRectF]) -> np.ndarray:
    """(n, 4) open intervals of shifts, x0 < dx < x1 and y0 < dy < y1, each of which puts
    one of `rects` (grown by GAP) over one `taken` rectangle: QRectF.intersects, an overlap
    of non-zero area, as inequalities on the shift."""
    r = np.array([(q.left(), q.top(), q.right(), q.bottom()) for q in rects], float)
    t = np.array([(q.left(), q.top(), q.right(), q.bottom()) for q in taken], float)
    x0 = t[None, :, 0] - r[:, None, 2] - GAP  # left of t, minus the moved right edge
    x1 = t[None, :, 2] - r[:, None, 0] + GAP
    y0 = t[None, :, 1] - r[:, None, 3] - GAP
    y1 = t[None, :, 3] - r[:, None, 1] + GAP
    f = np.stack([x0, x1, y0, y1], -1).reshape(-1, 4)
    return f[(f[:, 1] > f[:, 0]) & (f[:, 3] > f[:, 2])]  # empty rectangles hit nothing


def _ring(ring: int) -> np.ndarray:
    """The grid shifts on the square ring `ring` steps out, nearest first; at equal distance
    below, then right, of the asked-for place."""
    k = np.arange(-ring, ring + 1, dtype=float)
    inner = k[1:-1]  # the columns' corners are the rows' ends
    pts = np.concatenate([np.stack([k, np.full_like(k, -ring)], 1),
                          np.stack([k, np.full_like(k, ring)], 1),
                          np.stack([np.full_like(inner, -ring), inner], 1),
                          np.stack([np.full_like(inner, ring), inner], 1)]) * STEP
    order = np.lexsort((-pts[:, 0], -pts[:, 1], pts[:, 0] ** 2 + pts[:, 1] ** 2))
    return pts[order]


def free_offset(rects: list[QRectF], taken: list[QRectF]) -> QPointF:
    """The smallest shift that keeps every one of `rects` GAP clear of every `taken` one
    (the rects move together: a pasted group keeps its shape). The shifts a ring offers are
    tested at once against every pair's forbidden interval (a pasted copy of a whole graph
    searches thousands of shifts against hundreds of pairs)."""
    if not rects or not taken:
        return QPointF(0.0, 0.0)
    f = _forbidden(rects, taken)

    def clear(pts: np.ndarray) -> np.ndarray:
        dx, dy = pts[:, None, 0], pts[:, None, 1]
        hit = (dx > f[:, 0]) & (dx < f[:, 1]) & (dy > f[:, 2]) & (dy < f[:, 3])
        return ~hit.any(axis=1)

    if clear(np.zeros((1, 2)))[0]:
        return QPointF(0.0, 0.0)
    for ring in range(1, MAX_RINGS + 1):
        pts = _ring(ring)
        ok = np.flatnonzero(clear(pts))
        if len(ok):
            dx, dy = pts[ok[0]]
            return QPointF(float(dx), float(dy))
    return QPointF(0.0, 0.0)


def place(node: Node, scene) -> Node:
    """`node` moved into free space on `scene` (the same node where it is free already)."""
    shift = free_offset([node_rect(node)], taken_rects(scene))
    if shift.isNull():
        return node
    node.position = (round(node.position[0] + shift.x(), 1),
                     round(node.position[1] + shift.y(), 1))
    return node


def make_room(scene, node_id: str) -> dict[str, tuple[float, float]]:
    """New positions for the nodes that `node_id`'s item (grown: a layer stack with a new
    layer) now covers: each moves straight down until it is GAP clear of it, and of the
    nodes moved before it (top first), so nothing lands on anything. {} when nothing is
    covered."""
    item = scene.node_items.get(node_id)
    if item is None:
        return {}
    grown = item.sceneBoundingRect()
    rects = {nid: it.sceneBoundingRect() for nid, it in scene.node_items.items()
             if nid != node_id}
    shifts: dict[str, float] = {}
    blockers = [grown.adjusted(-GAP, -GAP, GAP, GAP)]
    for nid in sorted(rects, key=lambda n: (rects[n].top(), rects[n].left())):
        r = rects[nid]
        dy = 0.0
        for _ in range(len(blockers) + 1):  # each pass clears one more blocker, or stops
            hit = [b for b in blockers if r.translated(0.0, dy).intersects(b)]
            if not hit:
                break
            dy = max(b.bottom() for b in hit) - r.top()
        if dy > 0.0:
            shifts[nid] = dy
            blockers.append(r.translated(0.0, dy).adjusted(-GAP, -GAP, GAP, GAP))
    graph = scene.graph
    return {nid: (graph.nodes[nid].position[0], round(graph.nodes[nid].position[1] + dy, 1))
            for nid, dy in shifts.items() if nid in graph.nodes}
