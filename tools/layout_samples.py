"""Lay out the shipped sample graphs left to right, outputs on the right (a developer tool).

    QT_QPA_PLATFORM=offscreen python tools/layout_samples.py [graphs/materials/x.json ...]

A layered (Sugiyama-style) layout with networkx: each node's column is its longest path to
an output, so outputs sit in the rightmost column and a parameter sits just left of its
first consumer; wires that skip columns get a placeholder in every column they cross; the
order within a column comes from barycentre sweeps, starting from the author's own
top-to-bottom order; heights align each node's wired ports with the ports they join, then
any node a wire still runs through is moved clear of it. Node sizes are the editor's own
(the real canvas scene, thumbnails included, as tests/test_sample_layouts.py checks).
Only node positions (and comment frames, refitted round the nodes they framed) change.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import networkx as nx  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from test_sample_layouts import SAMPLES, layout_problems, with_thumbnails  # noqa: E402

from matedit.app.canvas import NodeCanvasView  # noqa: E402
from matedit.app.canvas.wire_item import wire_path  # noqa: E402
from matedit.app.controller import DocumentController  # noqa: E402
from matedit.io.document import load, save  # noqa: E402

H_GAP = 90.0  # between columns: room for the wires' curves
V_GAP = 36.0  # between nodes in a column
LANE = 22.0  # the height a wire crossing a column reserves there
GRID = 10.0  # positions are rounded to this


def _scene(doc):
    view = NodeCanvasView(DocumentController(doc))
    return view, with_thumbnails(view.scene())


def _columns(graph: nx.DiGraph) -> dict[str, int]:
    """Column 0 is the outputs'; every node sits at least one column left of its consumers."""
    col: dict[str, int] = {}
    for n in reversed(list(nx.lexicographical_topological_sort(graph))):
        succ = list(graph.successors(n))
        col[n] = 1 + max(col[s] for s in succ) if succ else (0 if graph.in_degree(n) else 1)
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


def layout(doc, view, scene) -> dict[str, int]:
    g = doc.graph
    items = scene.node_items
    size = {}
    for nid, it in items.items():
        r = it.mapRectToScene(it.shape().boundingRect())
        size[nid] = (r.width(), r.height(), r.left() - it.pos().x(), r.top() - it.pos().y())
    graph = nx.DiGraph()
    graph.add_nodes_from(g.nodes)
    graph.add_edges_from((lk.src, lk.dst) for lk in g.links)
    col = _columns(graph)
    # A chain of placeholders for each wire that skips a column (one per wire source and
    # column: wires from one output share their lane).
    members: dict[int, list[str]] = {}
    for n in sorted(g.nodes, key=lambda n: (g.nodes[n].position[1], g.nodes[n].position[0], n)):
        members.setdefault(col[n], []).append(n)
    segments: set[tuple[str, str | None, str, str | None]] = set()  # (a, out, b, in)
    lane_of: dict[tuple[str, str, int], str] = {}
    for lk in sorted(g.links, key=str):
        prev, prev_port = lk.src, lk.src_port
        for c in range(col[lk.src] - 1, col[lk.dst], -1):
            key = (lk.src, lk.src_port, c)
            if key not in lane_of:
                d = f"~{lk.src}.{lk.src_port}@{c}"
                lane_of[key] = d
                members[c].append(d)
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
        order = cols if sweep % 2 == 0 else cols[::-1]
        for c in order:
            def bary(n, c=c, sweep=sweep):
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
    for n, node in g.nodes.items():
        c = col[n]
        node.position = (round((x_of[c] - size[n][2]) / GRID) * GRID,
                         round((top[n] - size[n][3]) / GRID) * GRID)
        items[n].setPos(*node.position)
    return col


def repair(doc, scene, col: dict[str, int], limit: int = 400) -> list[str]:
    """Move nodes that a wire runs through (or that overlap) clear, one at a time, on the
    scene's items (their wires follow); each move takes its column's nodes beyond it along,
    in whichever direction leaves fewer problems. Writes the positions back to `doc`."""
    items = scene.node_items

    def shift(victim: str, dy: float) -> list[tuple[str, float]]:
        v = items[victim].pos().y()
        moved = [n for n in items if col[n] == col[victim]
                 and (items[n].pos().y() >= v if dy > 0 else items[n].pos().y() <= v)]
        for n in moved:
            items[n].setPos(items[n].pos().x(), items[n].pos().y() + dy)
        return [(n, dy) for n in moved]

    def undo(moves) -> None:
        for n, dy in moves:
            items[n].setPos(items[n].pos().x(), items[n].pos().y() - dy)

    problems = layout_problems(scene)
    for _ in range(limit):
        if not problems:
            break
        words = problems[0].split()
        if words[0] == "nodes":
            a, b = words[1], words[3]
            ra, rb = (items[n].sceneBoundingRect() for n in (a, b))
            lower = b if rb.top() >= ra.top() else a
            upper = a if lower == b else b
            dy = items[upper].sceneBoundingRect().bottom() + V_GAP - \
                items[lower].sceneBoundingRect().top()
            candidates = [(lower, round(dy / GRID + 1) * GRID)]
        else:
            victim = words[-1]
            link = next(lk for lk in doc.graph.links
                        if f"{lk.src}.{lk.src_port}" == words[1]
                        and f"{lk.dst}.{lk.dst_port}" == words[3])
            body = items[victim].sceneBoundingRect()
            path = wire_path(items[link.src].port_scene_pos(link.src_port, True),
                             items[link.dst].port_scene_pos(link.dst_port, False))
            pts = [path.pointAtPercent(k / 400) for k in range(401)]
            ys = [p.y() for p in pts if body.left() - 4 <= p.x() <= body.right() + 4]
            lo, hi = min(ys), max(ys)
            down = hi + V_GAP / 2 - body.top()
            up = lo - V_GAP / 2 - body.bottom()
            candidates = [(victim, round(down / GRID + 1) * GRID),
                          (victim, round(up / GRID - 1) * GRID)]
        best = None
        for victim, dy in candidates:
            moves = shift(victim, dy)
            after = layout_problems(scene)
            undo(moves)
            if best is None or len(after) < len(best[2]):
                best = (victim, dy, after)
        shift(best[0], best[1])
        problems = best[2]
    for n, it in items.items():
        doc.graph.nodes[n].position = (it.pos().x(), it.pos().y())
    return problems


def refit_comments(doc, before: dict[str, tuple[float, float]], sizes) -> None:
    """Each comment frames again the nodes whose top-left it framed before the layout."""
    for cm in doc.graph.comments.values():
        x, y, w, h = cm.rect
        inside = [n for n, (px, py) in before.items()
                  if x <= px <= x + w and y <= py <= y + h and n in doc.graph.nodes]
        if not inside:
            continue
        boxes = [(doc.graph.nodes[n].position, sizes[n]) for n in inside]
        left = min(p[0] for p, _ in boxes) - 20
        top = min(p[1] for p, _ in boxes) - 40
        right = max(p[0] + s[0] for p, s in boxes) + 20
        bottom = max(p[1] + s[1] for p, s in boxes) + 20
        cm.rect = (float(left), float(top), float(right - left), float(bottom - top))


def main(argv: list[str]) -> int:
    QApplication.instance() or QApplication([])
    paths = [Path(a).resolve() for a in argv] or SAMPLES
    bad = 0
    for path in paths:
        doc = load(path)
        before = {n: node.position for n, node in doc.graph.nodes.items()}
        view, scene = _scene(doc)
        sizes = {n: (it.sceneBoundingRect().width(), it.sceneBoundingRect().height())
                 for n, it in scene.node_items.items()}
        col = layout(doc, view, scene)
        left = repair(doc, scene, col)
        x0 = min(n.position[0] for n in doc.graph.nodes.values())
        y0 = min(n.position[1] for n in doc.graph.nodes.values())
        for node in doc.graph.nodes.values():  # the top-left node at the origin
            node.position = (node.position[0] - x0, node.position[1] - y0)
        refit_comments(doc, before, sizes)
        save(doc, path)
        print(f"{path.relative_to(ROOT)}: {len(left)} problems left", *left, sep="\n  ")
        bad += bool(left)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
