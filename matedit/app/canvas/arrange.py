"""Edit › Arrange: a layered layout of the selection (or of the whole graph), left to right.

A Sugiyama-style layout: each node's column is its longest path to a node
that nothing downstream of it (inside the arranged set) reads, so outputs sit in the
rightmost column and a parameter sits just left of its first consumer. A wire that skips
columns gets a placeholder lane in every column it crosses; the order within a column comes
from barycentre sweeps that start from the author's own top-to-bottom order; heights align
each node's wired ports with the ports they join (least squares, keeping the order, by pool
adjacent violators); then any node a wire still runs through, or that still overlaps
another, is moved clear of it.

Sizes and port heights are the canvas's own, read from the scene's node items, so the
layout is what the editor draws. The layout runs on the items and is then put back: the
caller gets new positions (and comment frames refitted round the nodes they framed) to push
as one undoable edit. tools/layout_samples.py lays out the shipped samples with the same
functions, and tests/test_sample_layouts.py checks them with `layout_problems`.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from graphlib import TopologicalSorter

from PySide6.QtCore import QRectF

from matedit.app.canvas.placement import free_offset, taken_rects
from matedit.app.canvas.wire_item import wire_path
from matedit.graph.model import Link

H_GAP = 90.0  # between columns: room for the wires' curves
V_GAP = 36.0  # between nodes in a column
LANE = 22.0  # the height a wire crossing a column reserves there
GRID = 10.0  # positions are rounded to this
REPAIR_LIMIT = 400  # moves tried by `repair` before it gives up
REPAIR_SECONDS = 2.0  # and the time it may take (a large imported graph)

NODE_MARGIN = 6.0  # scene units kept clear around each node's bounding rect (ports included)
WIRE_STEPS = 200  # samples along each wire
END_ALLOWANCE = 0.03  # the first and last 3 % of a wire sit at its ports: not checked
BODY_INSET = 1.0  # a wire grazing a body's edge by under a unit is not "through" it


def layout_problems(scene, ids: Iterable[str] | None = None) -> list[str]:
    """Overlapping node pairs and wires through foreign node bodies, as readable lines
    ('nodes a and b overlap', 'wire a.out -> b.in crosses node c'); with `ids`, only the
    problems that involve one of those nodes."""
    items = dict(sorted(scene.node_items.items()))
    keep = set(items) if ids is None else set(ids)
    rects = {nid: it.sceneBoundingRect().adjusted(-NODE_MARGIN, -NODE_MARGIN, NODE_MARGIN,
                                                  NODE_MARGIN) for nid, it in items.items()}
    problems = []
    order = list(rects)
    for i, a in enumerate(order):
        for b in order[i + 1:]:
            if (a in keep or b in keep) and rects[a].intersects(rects[b]):
                problems.append(f"nodes {a} and {b} overlap")
    bodies = {nid: it.mapRectToScene(it.shape().boundingRect()).adjusted(
        BODY_INSET, BODY_INSET, -BODY_INSET, -BODY_INSET) for nid, it in items.items()}
    lo, hi = int(END_ALLOWANCE * WIRE_STEPS), int((1 - END_ALLOWANCE) * WIRE_STEPS)
    for link, wire in sorted(scene.wire_items.items(), key=lambda kv: str(kv[0])):
        path = wire.mapToScene(wire.path())
        box = path.boundingRect()  # only the bodies the wire's box reaches can be crossed
        near = [(nid, body) for nid, body in bodies.items()
                if nid not in (link.src, link.dst) and body.intersects(box)]
        if not near:
            continue
        hit = set()
        for k in range(lo, hi + 1):
            pt = path.pointAtPercent(k / WIRE_STEPS)
            for nid, body in near:
                if body.contains(pt):
                    hit.add(nid)
        for nid in sorted(hit):
            if nid in keep or link.src in keep or link.dst in keep:
                problems.append(f"wire {link.src}.{link.src_port} -> {link.dst}.{link.dst_port}"
                                f" crosses node {nid}")
    return problems


def _columns(ids: set[str], links: list[Link]) -> dict[str, int]:
    """Column 0 is the outputs'; every node sits at least one column left of its consumers
    (a node with neither inputs nor consumers sits in column 1, beside the outputs). The
    graph is acyclic (validation refuses a cycle), so its order comes from graphlib."""
    succ: dict[str, set[str]] = {n: set() for n in ids}
    fed: set[str] = set()
    for lk in links:
        succ[lk.src].add(lk.dst)
        fed.add(lk.dst)
    col: dict[str, int] = {}
    # consumers first: a sorter over "n depends on its consumers"
    for n in TopologicalSorter({n: succ[n] for n in sorted(ids)}).static_order():
        col[n] = 1 + max(col[s] for s in succ[n]) if succ[n] else (0 if n in fed else 1)
    return col


def _isotonic(want: list[float], heights: list[float], gap: float) -> list[float]:
    """Tops nearest (least squares) to `want` that keep the order without overlap: pool
    adjacent violators on the offsets-removed targets."""
    off, acc = [], 0.0
    for h in heights:
        off.append(acc)
        acc += h + gap
    target = [w - o for w, o in zip(want, off, strict=True)]
    blocks: list[list[float]] = []  # [sum, count]
    for t in target:
        blocks.append([t, 1.0])
        while len(blocks) > 1 and blocks[-2][0] / blocks[-2][1] > blocks[-1][0] / blocks[-1][1]:
            s, c = blocks.pop()
            blocks[-1][0] += s
            blocks[-1][1] += c
    out: list[float] = []
    for s, c in blocks:
        out += [s / c] * int(c)
    return [v + o for v, o in zip(out, off, strict=True)]


def _inner_links(graph, ids: set[str]) -> list[Link]:
    return sorted((lk for lk in graph.links if lk.src in ids and lk.dst in ids), key=str)


def layout(scene, ids: Iterable[str]) -> dict[str, int]:
    """Lay out the items of `ids` on `scene` (their wires follow); their columns. The
    arranged block's right edge is at x = 0 and its first row at y = 0."""
    g = scene.graph
    chosen = set(ids)
    items = scene.node_items
    size = {}
    for nid in chosen:
        it = items[nid]
        r = it.mapRectToScene(it.shape().boundingRect())
        size[nid] = (r.width(), r.height(), r.left() - it.pos().x(), r.top() - it.pos().y())
    links = _inner_links(g, chosen)
    col = _columns(chosen, links)
    # A chain of placeholders for each wire that skips a column (one per wire source and
    # column: wires from one output share their lane).
    members: dict[int, list[str]] = {}
    for n in sorted(chosen, key=lambda n: (g.nodes[n].position[1], g.nodes[n].position[0], n)):
        members.setdefault(col[n], []).append(n)
    segments: set[tuple[str, str | None, str, str | None]] = set()  # (a, out, b, in)
    lane_of: dict[tuple[str, str, int], str] = {}
    for lk in links:
        prev, prev_port = lk.src, lk.src_port
        for c in range(col[lk.src] - 1, col[lk.dst], -1):
            key = (lk.src, lk.src_port, c)
            if key not in lane_of:
                d = f"~{lk.src}.{lk.src_port}@{c}"
                lane_of[key] = d
                members.setdefault(c, []).append(d)
                size[d] = (0.0, LANE, 0.0, 0.0)
            segments.add((prev, prev_port, lane_of[key], None))
            prev, prev_port = lane_of[key], None
        segments.add((prev, prev_port, lk.dst, lk.dst_port))
    down: dict[str, list] = {n: [] for c in members for n in members[c]}
    up: dict[str, list] = {n: [] for n in down}
    for a_, ap, b_, bp in sorted(segments, key=str):
        down[a_].append((b_, ap, bp))
        up[b_].append((a_, ap, bp))

    def port_y(n: str, port: str | None, out: bool) -> float:
        if port is None:
            return LANE / 2
        it = items[n]
        return it.port_scene_pos(port, out).y() - it.pos().y()

    cols = sorted(members)
    # Barycentre ordering sweeps (right to left, then left to right).
    index = {n: i for c in cols for i, n in enumerate(members[c])}
    for sweep in range(8):
        for c in (cols if sweep % 2 == 0 else cols[::-1]):
            def bary(n, sweep=sweep):
                nb = [m for m, _a, _b in (down[n] if sweep % 2 == 0 else up[n])]
                nb = [m for m in nb if m in index]
                return sum(index[m] for m in nb) / len(nb) if nb else index[n]
            members[c].sort(key=lambda n: (bary(n), index[n]))
            for i, n in enumerate(members[c]):
                index[n] = i
    # Columns' x, from the right; nodes in a column share their left edge.
    x_of: dict[int, float] = {}
    x = 0.0
    for c in cols:
        width = max(size[n][0] for n in members[c])
        x -= width if c else 0.0
        x_of[c] = x
        x -= H_GAP
    top: dict[str, float] = {}
    for c in cols:
        y = 0.0
        for n in members[c]:
            top[n] = y
            y += size[n][1] + V_GAP
    # Heights: each node's ports level with the ports they join, columns alternately.
    for sweep in range(12):
        for c in (cols if sweep % 2 else cols[::-1]):
            want = []
            for n in members[c]:
                pairs = [top[m] + port_y(m, bp, False) - port_y(n, ap, True)
                         for m, ap, bp in down[n]]
                pairs += [top[m] + port_y(m, ap, True) - port_y(n, bp, False)
                          for m, ap, bp in up[n]]
                want.append(sum(pairs) / len(pairs) if pairs else top[n])
            tops = _isotonic(want, [size[n][1] for n in members[c]], V_GAP)
            for n, t in zip(members[c], tops, strict=True):
                top[n] = t
    for n in chosen:
        c = col[n]
        items[n].setPos(round((x_of[c] - size[n][2]) / GRID) * GRID,
                        round((top[n] - size[n][3]) / GRID) * GRID)
    return col


def repair(scene, col: dict[str, int], limit: int = REPAIR_LIMIT) -> list[str]:
    """Move the arranged nodes (the keys of `col`) that a wire runs through, or that
    overlap, clear, one at a time, on the scene's items; each move takes its column's nodes
    beyond it along, in whichever direction leaves fewer problems. The problems left."""
    items = scene.node_items
    links = scene.graph.links
    ids = set(col)

    def shift(victim: str, dy: float) -> list[tuple[str, float]]:
        v = items[victim].pos().y()
        moved = [n for n in col if col[n] == col[victim]
                 and (items[n].pos().y() >= v if dy > 0 else items[n].pos().y() <= v)]
        for n in moved:
            items[n].setPos(items[n].pos().x(), items[n].pos().y() + dy)
        return [(n, dy) for n in moved]

    def undo(moves) -> None:
        for n, dy in moves:
            items[n].setPos(items[n].pos().x(), items[n].pos().y() - dy)

    problems = layout_problems(scene, ids)
    deadline = time.perf_counter() + REPAIR_SECONDS
    for _ in range(limit):
        if time.perf_counter() > deadline:  # a large graph: what is left stays, reported
            break
        candidates = []
        for problem in problems:
            candidates = _candidates(problem, items, links, ids)
            if candidates:
                break
        if not candidates:
            break
        best = None
        for victim, dy in candidates:
            moves = shift(victim, dy)
            after = layout_problems(scene, ids)
            undo(moves)
            if best is None or len(after) < len(best[2]):
                best = (victim, dy, after)
        assert best is not None
        shift(best[0], best[1])
        problems = best[2]
    return problems


def _candidates(problem: str, items, links, ids: set[str]) -> list[tuple[str, float]]:
    """The moves (node, dy) that could clear one problem, of arranged nodes only."""
    words = problem.split()
    if words[0] == "nodes":
        a, b = words[1], words[3]
        ra, rb = (items[n].sceneBoundingRect() for n in (a, b))
        lower = b if rb.top() >= ra.top() else a
        upper = a if lower == b else b
        if lower not in ids:
            return []
        dy = items[upper].sceneBoundingRect().bottom() + V_GAP - \
            items[lower].sceneBoundingRect().top()
        return [(lower, round(dy / GRID + 1) * GRID)]
    victim = words[-1]
    if victim not in ids:
        return []
    link = next(lk for lk in links if f"{lk.src}.{lk.src_port}" == words[1]
                and f"{lk.dst}.{lk.dst_port}" == words[3])
    body = items[victim].sceneBoundingRect()
    path = wire_path(items[link.src].port_scene_pos(link.src_port, True),
                     items[link.dst].port_scene_pos(link.dst_port, False))
    pts = [path.pointAtPercent(k / 400) for k in range(401)]
    ys = [p.y() for p in pts if body.left() - 4 <= p.x() <= body.right() + 4]
    if not ys:
        return []
    down = max(ys) + V_GAP / 2 - body.top()
    up = min(ys) - V_GAP / 2 - body.bottom()
    return [(victim, round(down / GRID + 1) * GRID), (victim, round(up / GRID - 1) * GRID)]


def refit_comments(graph, before: dict[str, tuple[float, float]],
                   after: dict[str, tuple[float, float]],
                   sizes: dict[str, tuple[float, float]]) -> dict[str, tuple]:
    """New frames of the comments whose framed nodes moved: each frames again the nodes
    whose top-left it framed before (comments framing none of the moved nodes are kept)."""
    out = {}
    for cid, cm in graph.comments.items():
        x, y, w, h = cm.rect
        inside = [n for n, (px, py) in before.items()
                  if x <= px <= x + w and y <= py <= y + h]
        if not inside or not any(n in after for n in inside):
            continue
        boxes = [(after.get(n, before[n]), sizes[n]) for n in inside]
        left = min(p[0] for p, _ in boxes) - 20
        top = min(p[1] for p, _ in boxes) - 40
        right = max(p[0] + s[0] for p, s in boxes) + 20
        bottom = max(p[1] + s[1] for p, s in boxes) + 20
        out[cid] = (float(left), float(top), float(right - left), float(bottom - top))
    return out


def arrange(scene, ids: Iterable[str]) -> tuple[dict[str, tuple[float, float]], dict[str, tuple],
                                                 list[str]]:
    """The new positions of `ids` (the top-left of the arranged block where the top-left of
    their bounding box was, nudged clear of every node not arranged), the comment frames
    to refit, and the problems the layout could not clear. The items are put back."""
    chosen = sorted(set(ids) & set(scene.node_items))
    items = scene.node_items
    old = {n: (items[n].pos().x(), items[n].pos().y()) for n in items}
    sizes = {n: (it.sceneBoundingRect().width(), it.sceneBoundingRect().height())
             for n, it in items.items()}
    if not chosen:
        return {}, {}, []
    anchor = _bounds([items[n].sceneBoundingRect() for n in chosen]).topLeft()
    try:
        col = layout(scene, chosen)
        left = repair(scene, col)
        block = _bounds([items[n].sceneBoundingRect() for n in chosen])
        shift = anchor - block.topLeft()
        moved_rects = [items[n].sceneBoundingRect().translated(shift) for n in chosen]
        shift += free_offset(moved_rects, taken_rects(scene, exclude=chosen))
        dx, dy = round(shift.x() / GRID) * GRID, round(shift.y() / GRID) * GRID
        new = {n: (items[n].pos().x() + dx, items[n].pos().y() + dy) for n in chosen}
    finally:
        for n, p in old.items():
            items[n].setPos(*p)
    moved = {n: p for n, p in new.items() if p != old[n]}
    frames = refit_comments(scene.graph, old, moved, sizes) if moved else {}
    return moved, frames, left


def _bounds(rects: list[QRectF]) -> QRectF:
    r = QRectF(rects[0])
    for other in rects[1:]:
        r = r.united(other)
    return r


