"""Dragging wires: from an output to an input (or back), lifting a wire off an input.

`WireDrag` follows the cursor with a live wire, finds the port under it, and asks
`check_connect` whether the link may be made (once per port, cached), so the
target port lights green or red while hovered. It decides nothing on its own:
`finish` says what the drop means and the view turns that into commands.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from PySide6.QtCore import QPointF, QRectF

from matedit.app.canvas import constants as C
from matedit.app.canvas.live_wire import LiveWire
from matedit.app.canvas.node_item import NodeItem
from matedit.app.canvas.port_item import PortItem
from matedit.app.canvas.reroute_item import RerouteItem
from matedit.graph.model import Link, Node
from matedit.graph.ports import NodePorts, node_ports
from matedit.graph.types import PortType, can_convert
from matedit.graph.validate import check_connect, type_error_keys

GENERIC = "T"


def type_accepts(src: str, dst: str) -> bool:
    """Whether a value of display type `src` may flow into a port of type `dst` (T: generic)."""
    try:
        if src == GENERIC and dst == GENERIC:
            return True
        if src == GENERIC:
            return PortType(dst).is_numeric
        if dst == GENERIC:
            return PortType(src).is_numeric
        return can_convert(PortType(src), PortType(dst))
    except ValueError:
        return False


@cache
def kind_ports(kind: str) -> NodePorts | None:
    """The ports a fresh node of `kind` has (None when they need a function file first)."""
    try:
        return node_ports(Node("probe", kind), None, None)
    except (LookupError, ValueError):
        return None


# Input names that say "what this node works on", as opposed to its controls (Smooth Step's
# value rather than edge0, Remap's value rather than in_min): a wire dropped on empty canvas
# joins one of these first.
SUBJECT_INPUTS = ("value", "in", "input", "color", "base", "a", "uv", "normal", "attributes",
                  "vector", "x", "height", "mask")


def compatible_port(kind: str, anchor_type: str, anchor_is_output: bool) -> str | None:
    """The port of a new `kind` node that a wire from the anchor would join: among the ports
    whose type fits (the exact type before a conversion), the node's subject input before a
    control (SUBJECT_INPUTS), else the first."""
    ports = kind_ports(kind)
    if ports is None:
        return None
    if anchor_is_output:
        pairs = [(p.name, anchor_type, p.type) for p in ports.inputs]
    else:
        pairs = [(p.name, p.type, anchor_type) for p in ports.outputs]
    fits = [(n, s == d and s != GENERIC) for n, s, d in pairs if type_accepts(s, d)]
    if not fits:
        return None

    def rank(item: tuple[str, bool]) -> tuple[int, int]:
        name, exact = item
        subject = anchor_is_output and name in SUBJECT_INPUTS
        return (0 if exact else 1, 0 if subject else 1)
    return min(fits, key=rank)[0]


def port_at(scene, scene_pos: QPointF, radius: float, *, want_output: bool | None = None,
            exclude_node: str | None = None, for_press: bool = False) -> PortItem | None:
    """The port nearest `scene_pos` within `radius` (scene units), optionally filtered."""
    rect = QRectF(scene_pos.x() - radius, scene_pos.y() - radius, 2 * radius, 2 * radius)
    best, best_d = None, radius * radius
    for it in scene.items(rect):
        if not isinstance(it, PortItem) or _folded(it):
            continue
        if want_output is not None and it.is_output != want_output:
            continue
        if exclude_node is not None and it.node_id == exclude_node:
            continue
        parent = it.parentItem()
        if for_press and isinstance(parent, RerouteItem):
            centre = parent.pos() + QPointF(C.REROUTE_RADIUS, C.REROUTE_RADIUS)
            # The middle of a reroute's dot moves it; its sides start wires.
            if abs(scene_pos.x() - centre.x()) < C.REROUTE_RADIUS * 0.45:
                continue
        d = it.scenePos() - scene_pos
        dd = d.x() * d.x() + d.y() * d.y()
        if dd <= best_d:
            best, best_d = it, dd
    return best


def _folded(port: PortItem) -> bool:
    """Whether the port is folded away under its node's pin group header."""
    parent = port.parentItem()
    return isinstance(parent, NodeItem) and parent.is_hidden(port.name, port.is_output)


@dataclass
class DropResult:
    """What a finished drag asks for: connect `link` (replacing `lifted`), or explain a refusal,
    or (`empty`) it ended over no port."""

    link: Link | None = None
    lifted: Link | None = None
    reason: str | None = None
    empty: bool = False
    at: QPointF | None = None


class WireDrag:
    """One wire drag, from press on a port to release."""

    def __init__(self, scene, port: PortItem) -> None:
        self.scene = scene
        self.lifted: Link | None = None
        anchor = port
        if not port.is_output:
            link = next((l for l in scene._wires_of.get(port.node_id, ())
                         if l.dst == port.node_id and l.dst_port == port.name), None)
            if link is not None:
                src_item = scene.node_items[link.src]
                lifted_from = src_item.port(link.src_port, True)
                if lifted_from is not None:
                    self.lifted, anchor = link, lifted_from
                    scene.wire_items[link].setVisible(False)
        self.anchor = anchor
        self.anchor_type = anchor.type_name if (anchor.is_output or not anchor.generic) \
            else GENERIC
        self.target: PortItem | None = None
        self._verdicts: dict[tuple[str, str, bool], str | None] = {}
        self._baseline: set | None = None  # the document's own type errors, once per drag
        self.live = LiveWire(anchor.scenePos(), anchor.is_output, anchor.type_name)
        scene.addItem(self.live)

    def link_to(self, port: PortItem) -> Link:
        if self.anchor.is_output:
            return Link(self.anchor.node_id, self.anchor.name, port.node_id, port.name)
        return Link(port.node_id, port.name, self.anchor.node_id, self.anchor.name)

    def verdict(self, port: PortItem) -> str | None:
        """None if dropping on `port` would be allowed, else the reason (cached per port)."""
        key = port.key
        if key not in self._verdicts:
            link = self.link_to(port)
            if link == self.lifted:
                self._verdicts[key] = None
            else:
                c = self.scene.controller
                if self._baseline is None:
                    self._baseline = type_error_keys(c.document, c.resolver)
                self._verdicts[key] = check_connect(c.document, link, c.resolver,
                                                    self._baseline)
        return self._verdicts[key]

    def _target_at(self, scene_pos: QPointF, radius: float) -> PortItem | None:
        want = not self.anchor.is_output
        port = port_at(self.scene, scene_pos, radius, want_output=want,
                       exclude_node=self.anchor.node_id)
        if port is not None:
            return port
        # Over a node's body: its first port of the right side whose type fits.
        for it in self.scene.items(scene_pos):
            if isinstance(it, NodeItem) and it.node_id != self.anchor.node_id:
                header = it.header_at(scene_pos)
                if header is not None and not header.expanded and header.is_output == want:
                    # Hovering a folded group with a wire opens it for the drag, as a node
                    # editor's collapsed panel does, so its pins can be aimed at.
                    self.scene.peek_group(it.node_id, header.group)
                    return None
                ports = [p for p in it.ports() if p.is_output == want and not _folded(p)]
                ports.sort(key=lambda p: p.pos().y())
                for p in ports:
                    src, dst = ((self.anchor_type, GENERIC if p.generic else p.type_name)
                                if not want else (p.type_name, self.anchor_type))
                    if type_accepts(src, dst):
                        return p
                return None
        return None

    def move(self, scene_pos: QPointF, radius: float) -> None:
        port = self._target_at(scene_pos, radius)
        if port is not self.target:
            if self.target is not None:
                self.target.set_state(PortItem.NONE)
            self.target = port
        if port is None:
            self.live.set_end(scene_pos, None)
            return
        ok = self.verdict(port) is None
        port.set_state(PortItem.ALLOWED if ok else PortItem.REFUSED)
        self.live.set_end(port.scenePos(), ok)

    def finish(self, scene_pos: QPointF, radius: float) -> DropResult:
        self.move(scene_pos, radius)
        port = self.target
        if port is None:
            return DropResult(lifted=self.lifted, empty=True, at=scene_pos)
        reason = self.verdict(port)
        if reason is not None:
            return DropResult(lifted=self.lifted, reason=reason, at=scene_pos)
        return DropResult(link=self.link_to(port), lifted=self.lifted, at=scene_pos)

    def cleanup(self) -> None:
        if self.target is not None:
            self.target.set_state(PortItem.NONE)
        if self.live.scene() is not None:
            self.scene.removeItem(self.live)
        if self.lifted is not None:
            wire = self.scene.wire_items.get(self.lifted)
            if wire is not None:
                wire.setVisible(True)
