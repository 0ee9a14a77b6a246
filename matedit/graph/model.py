"""The material graph model: nodes, links, comments, documents and change events.

Pure Python. The model changes only through command objects
(`matedit.graph.commands`); each mutation primitive here emits a `ChangeEvent`
so that views (the Qt scene, the viewport) follow the model and hold no graph
state of their own.
"""

from __future__ import annotations

import copy
import dataclasses
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any, NamedTuple

_ID = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}\Z", re.ASCII)


def valid_id(s: object) -> bool:
    """Node ids are ASCII identifiers of at most 64 characters with no '__': they take part
    in generated names (always behind a prefix, so a keyword such as `out` is a fine id)."""
    return (isinstance(s, str) and bool(_ID.match(s)) and "__" not in s
            and not s.startswith("gl_"))


class ChangeKind(str, Enum):
    STRUCTURAL = "structural"  # the generated code changes: recompile
    VALUE = "value"  # a uniform or texture changes: set it and redraw
    LAYOUT = "layout"  # positions, comments, labels: nothing to recompile or redraw


@dataclass(frozen=True)
class ChangeEvent:
    kind: ChangeKind
    what: str  # "node_added", "node_removed", "link_added", "value", "setting", ...
    node_ids: tuple[str, ...] = ()
    port: str | None = None


_IMMUTABLE = (str, int, float, bool, type(None))


def copy_data(value: Any) -> Any:
    """A deep copy of file data (dicts, lists and tuples of numbers, strings, booleans and
    None), several times faster than copy.deepcopy, which a duplicate or a compile's snapshot
    of the graph runs over every node; anything else is deep-copied by copy.deepcopy."""
    t = type(value)
    if t is dict:
        return {k: copy_data(v) for k, v in value.items()}
    if t is list:
        return [copy_data(v) for v in value]
    if t is tuple:
        return tuple(copy_data(v) for v in value)
    if t in _IMMUTABLE:
        return value
    return copy.deepcopy(value)


@dataclass
class Node:
    id: str
    kind: str
    position: tuple[float, float] = (0.0, 0.0)
    settings: dict[str, Any] = field(default_factory=dict)
    values: dict[str, Any] = field(default_factory=dict)
    label: str = ""
    # Fields of the file's node object this version does not know: kept and written back.
    extra: dict[str, Any] = field(default_factory=dict)
    # Bypassed: its first input of each output's type passes through (graph.bypass)
    muted: bool = False

    def clone(self) -> Node:
        """An independent copy (edits to either never reach the other)."""
        return dataclasses.replace(self, settings=copy_data(self.settings),
                                   values=copy_data(self.values), extra=copy_data(self.extra))


class Link(NamedTuple):
    """An output feeding an input. A tuple, so sorting and hashing run at C speed."""

    src: str
    src_port: str
    dst: str
    dst_port: str

    def to_json(self) -> dict:
        return {"from": [self.src, self.src_port], "to": [self.dst, self.dst_port]}


@dataclass
class Comment:
    """A comment frame on the canvas: layout only."""

    id: str
    text: str = ""
    rect: tuple[float, float, float, float] = (0.0, 0.0, 200.0, 120.0)
    color: tuple[float, float, float] = (0.3, 0.3, 0.3)
    extra: dict[str, Any] = field(default_factory=dict)  # unknown fields, kept on save


Listener = Callable[[ChangeEvent], None]


class MaterialGraph:
    """Nodes with stable string ids, links into inputs (at most one each), comments."""

    def __init__(self) -> None:
        self.nodes: dict[str, Node] = {}
        self.links: set[Link] = set()
        self.comments: dict[str, Comment] = {}
        self._listeners: list[Listener] = []

    # --- events -------------------------------------------------------------------------
    def subscribe(self, listener: Listener) -> None:
        self._listeners.append(listener)

    def unsubscribe(self, listener: Listener) -> None:
        if listener in self._listeners:
            self._listeners.remove(listener)

    def emit(self, event: ChangeEvent) -> None:
        for listener in list(self._listeners):
            listener(event)

    # --- queries ------------------------------------------------------------------------
    def node(self, node_id: str) -> Node:
        return self.nodes[node_id]

    def incoming(self, node_id: str, port: str) -> Link | None:
        for link in self.links:
            if link.dst == node_id and link.dst_port == port:
                return link
        return None

    def links_of(self, node_id: str) -> list[Link]:
        return sorted(l for l in self.links if node_id in (l.src, l.dst))

    def inputs_of(self, node_id: str) -> dict[str, Link]:
        return {l.dst_port: l for l in self.links if l.dst == node_id}

    def new_id(self, stem: str = "n") -> str:
        """A fresh id from a counter: `stem1`, `stem2`, ... (never a memory address)."""
        stem = re.sub(r"[^A-Za-z0-9]", "", stem) or "n"
        if not stem[0].isalpha():
            stem = "n" + stem
        taken = set(self.nodes) | set(self.comments)
        i = 1
        while f"{stem}{i}" in taken:
            i += 1
        return f"{stem}{i}"

    def copy(self) -> MaterialGraph:
        g = MaterialGraph()
        g.nodes = {k: v.clone() for k, v in self.nodes.items()}
        g.links = set(self.links)
        g.comments = {k: dataclasses.replace(c, extra=copy_data(c.extra))
                      for k, c in self.comments.items()}
        return g

    def snapshot(self) -> tuple:
        """A comparable value of the whole graph (tests, undo checks)."""
        return (
            sorted(
                (n.id, n.kind, n.position, repr(sorted(n.settings.items())),
                 repr(sorted(n.values.items())), n.label, n.muted)
                for n in self.nodes.values()
            ),
            sorted(self.links),
            sorted((c.id, c.text, c.rect, c.color) for c in self.comments.values()),
        )

    # --- mutation primitives (called by commands) -------------------------------------
    def _add_node(self, node: Node) -> None:
        if node.id in self.nodes:
            raise KeyError(f"duplicate node id {node.id!r}")
        self.nodes[node.id] = node
        self.emit(ChangeEvent(ChangeKind.STRUCTURAL, "node_added", (node.id,)))

    def _remove_node(self, node_id: str) -> Node:
        node = self.nodes.pop(node_id)
        self.emit(ChangeEvent(ChangeKind.STRUCTURAL, "node_removed", (node_id,)))
        return node

    def _add_link(self, link: Link) -> None:
        self.links.add(link)
        self.emit(ChangeEvent(ChangeKind.STRUCTURAL, "link_added", (link.src, link.dst),
                              link.dst_port))

    def _remove_link(self, link: Link) -> None:
        self.links.discard(link)
        self.emit(ChangeEvent(ChangeKind.STRUCTURAL, "link_removed", (link.src, link.dst),
                              link.dst_port))

    def _set_value(self, node_id: str, port: str, value: Any,
                   kind: ChangeKind = ChangeKind.VALUE) -> None:
        node = self.nodes[node_id]
        if value is None:
            node.values.pop(port, None)
        else:
            node.values[port] = copy.deepcopy(value)
        self.emit(ChangeEvent(kind, "value", (node_id,), port))

    def _set_setting(self, node_id: str, name: str, value: Any, kind: ChangeKind) -> None:
        node = self.nodes[node_id]
        if value is None:
            node.settings.pop(name, None)
        else:
            node.settings[name] = copy.deepcopy(value)
        self.emit(ChangeEvent(kind, "setting", (node_id,), name))

    def _set_position(self, node_id: str, pos: tuple[float, float]) -> None:
        self.nodes[node_id].position = (float(pos[0]), float(pos[1]))
        self.emit(ChangeEvent(ChangeKind.LAYOUT, "moved", (node_id,)))

    def _set_muted(self, node_id: str, muted: bool) -> None:
        self.nodes[node_id].muted = bool(muted)
        self.emit(ChangeEvent(ChangeKind.STRUCTURAL, "muted", (node_id,)))

    def _set_label(self, node_id: str, label: str) -> None:
        self.nodes[node_id].label = label
        self.emit(ChangeEvent(ChangeKind.LAYOUT, "label", (node_id,)))

    def _put_comment(self, comment: Comment | None, comment_id: str) -> None:
        if comment is None:
            self.comments.pop(comment_id, None)
        else:
            self.comments[comment_id] = copy.deepcopy(comment)
        self.emit(ChangeEvent(ChangeKind.LAYOUT, "comment", (comment_id,)))


class DocumentKind(str, Enum):
    MATERIAL = "material"
    FUNCTION = "function"


@dataclass
class MaterialDocument:
    """A material or a material function: one graph plus file-level metadata.

    A material function (kind FUNCTION) defines its interface with
    function_input / function_output nodes; a material has a material_output.
    """

    kind: DocumentKind = DocumentKind.MATERIAL
    graph: MaterialGraph = field(default_factory=MaterialGraph)
    name: str = ""
    description: str = ""
    path: Path | None = None  # where it was loaded from / saved to
    # Preview settings stored with the file (environment, mesh); layout-only for the compiler.
    preview: dict[str, Any] = field(default_factory=dict)
    # Fields this version does not know, kept and written back on save: at the top level,
    # and per link (links are plain tuples, so theirs are held here, keyed by the link).
    extra: dict[str, Any] = field(default_factory=dict)
    link_extra: dict[Link, dict[str, Any]] = field(default_factory=dict)
    # An instance's effective material (matedit.io.instance.resolve) remembers the files it
    # was made from, for matedit.io.inputs.document_inputs: its parents (real paths), and
    # its texture overrides as spelled. Empty for any other document; never saved.
    instance_chain: list[Path] = field(default_factory=list, compare=False, repr=False)
    instance_textures: list[Path] = field(default_factory=list, compare=False, repr=False)

    @property
    def is_function(self) -> bool:
        return self.kind == DocumentKind.FUNCTION

    def snapshot(self) -> tuple:
        return (self.kind, self.name, self.description, repr(sorted(self.preview.items())),
                self.graph.snapshot())

