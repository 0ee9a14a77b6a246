"""Where a new node goes: near where it was asked for, never on another node.

A node added from the palette, pasted or duplicated is nudged into the nearest free space
(searched on square rings of growing size around the asked-for place, down and right
first), so it never lands on a node already there. Sizes come from the same geometry the
node items use (`measure`), before any item exists.
"""

from __future__ import annotations

from collections.abc import Iterable

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


def _clear(rects: list[QRectF], taken: list[QRectF], dx: float, dy: float) -> bool:
    for r in rects:
        moved = r.translated(dx, dy).adjusted(-GAP, -GAP, GAP, GAP)
        if any(moved.intersects(t) for t in taken):
            return False
    return True


def free_offset(rects: list[QRectF], taken: list[QRectF]) -> QPointF:
    """The smallest shift that keeps every one of `rects` GAP clear of every `taken` one
    (the rects move together: a pasted group keeps its shape)."""
    if not rects or _clear(rects, taken, 0.0, 0.0):
        return QPointF(0.0, 0.0)
    for ring in range(1, MAX_RINGS + 1):
        d = ring * STEP
        spots = {(x * STEP, y * STEP) for x in range(-ring, ring + 1)
                 for y in (-ring, ring)} | {(x * STEP, y * STEP) for x in (-ring, ring)
                                            for y in range(-ring, ring + 1)}
        # nearest first; at equal distance below, then right, of the asked-for place
        for dx, dy in sorted(spots, key=lambda p: (p[0] ** 2 + p[1] ** 2, -p[1], -p[0])):
            if abs(dx) <= d and abs(dy) <= d and _clear(rects, taken, dx, dy):
                return QPointF(dx, dy)
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
