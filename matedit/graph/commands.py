"""Edits as command objects with `apply` and `revert`.

The only way the model changes. The editor wraps each in a QUndoCommand; the
command line and tests use them directly. Commands change the model only; the
views follow the model's change events.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any

from matedit.graph import nodes
from matedit.graph.model import ChangeKind, Comment, Link, MaterialGraph, Node


class CommandError(ValueError):
    """An edit the model refuses, with the reason (shown to the artist)."""


class Command:
    text = "edit"
    kind = ChangeKind.STRUCTURAL

    def apply(self, graph: MaterialGraph) -> None:
        raise NotImplementedError

    def revert(self, graph: MaterialGraph) -> None:
        raise NotImplementedError


@dataclass
class AddNode(Command):
    node: Node
    text: str = "add node"

    def apply(self, graph):
        if self.node.id in graph.nodes:
            raise CommandError(f"a node with id {self.node.id!r} already exists")
        if self.node.kind not in nodes.REGISTRY:
            raise CommandError(f"unknown node kind {self.node.kind!r}")
        graph._add_node(self.node.clone())

    def revert(self, graph):
        graph._remove_node(self.node.id)


@dataclass
class RemoveNode(Command):
    """Removes a node and every link touching it; revert restores both."""

    node_id: str
    text: str = "delete node"
    _node: Node | None = None
    _links: list[Link] = field(default_factory=list)

    def apply(self, graph):
        if self.node_id not in graph.nodes:
            raise CommandError(f"no node {self.node_id!r}")
        self._links = graph.links_of(self.node_id)
        for link in self._links:
            graph._remove_link(link)
        self._node = graph._remove_node(self.node_id)

    def revert(self, graph):
        graph._add_node(self._node)
        for link in self._links:
            graph._add_link(link)


@dataclass
class Connect(Command):
    """Links an output to an input, replacing what fed that input before.

    Connect does no type or cycle check itself: callers ask
    `matedit.graph.validate.check_connect` first, which gives the reason for a refusal.
    """

    link: Link
    text: str = "connect"
    _replaced: Link | None = None

    def apply(self, graph):
        for end in (self.link.src, self.link.dst):
            if end not in graph.nodes:
                raise CommandError(f"no node {end!r}")
        self._replaced = graph.incoming(self.link.dst, self.link.dst_port)
        if self._replaced is not None:
            graph._remove_link(self._replaced)
        graph._add_link(self.link)

    def revert(self, graph):
        graph._remove_link(self.link)
        if self._replaced is not None:
            graph._add_link(self._replaced)


@dataclass
class Disconnect(Command):
    link: Link
    text: str = "disconnect"

    def apply(self, graph):
        if self.link not in graph.links:
            raise CommandError("no such link")
        graph._remove_link(self.link)

    def revert(self, graph):
        graph._add_link(self.link)


@dataclass
class SetValue(Command):
    """Sets the value of an unconnected input or a parameter: a uniform, never a recompile."""

    node_id: str
    port: str
    value: Any
    text: str = "set value"
    kind: ChangeKind = ChangeKind.VALUE
    _old: Any = None

    def apply(self, graph):
        node = graph.nodes.get(self.node_id)
        if node is None:
            raise CommandError(f"no node {self.node_id!r}")
        self._old = copy.deepcopy(node.values.get(self.port))
        _put_value(graph, self.node_id, self.port, self.value)

    def revert(self, graph):
        _put_value(graph, self.node_id, self.port, self._old)


def _put_value(graph, node_id: str, port: str, value: Any) -> None:
    """A value edit is a uniform, except a lobe input of a Make Attributes moving off its
    default or back to it: that compiles the lobe in or out (nodes.InputDef.lobe)."""
    node = graph.nodes[node_id]
    kind = ChangeKind.VALUE
    fd = nodes.lobe_input(node.kind, port)
    if fd is not None:
        before = nodes.lobe_value_is_default(node, fd)
        probe = copy.copy(node)
        probe.values = {**node.values, port: fd.default if value is None else value}
        if nodes.lobe_value_is_default(probe, fd) != before:
            kind = ChangeKind.STRUCTURAL
    graph._set_value(node_id, port, value, kind)


@dataclass
class SetSetting(Command):
    """Changes a node setting; structural unless the definition marks it otherwise."""

    node_id: str
    name: str
    value: Any
    text: str = "change setting"
    _old: Any = None

    @property
    def kind(self) -> ChangeKind:  # type: ignore[override]
        return setting_kind(self._kind_of)

    _kind_of: tuple[str, str] = ("", "")

    def apply(self, graph):
        node = graph.nodes.get(self.node_id)
        if node is None:
            raise CommandError(f"no node {self.node_id!r}")
        self._kind_of = (node.kind, self.name)
        self._old = copy.deepcopy(node.settings.get(self.name))
        graph._set_setting(self.node_id, self.name, self.value, self.kind)

    def revert(self, graph):
        graph._set_setting(self.node_id, self.name, self._old, self.kind)


def setting_kind(kind_and_name: tuple[str, str]) -> ChangeKind:
    d = nodes.REGISTRY.get(kind_and_name[0])
    s = d.setting(kind_and_name[1]) if d else None
    return ChangeKind.VALUE if (s is not None and not s.structural) else ChangeKind.STRUCTURAL


@dataclass
class MoveNodes(Command):
    positions: dict[str, tuple[float, float]]
    text: str = "move nodes"
    kind: ChangeKind = ChangeKind.LAYOUT
    _old: dict[str, tuple[float, float]] = field(default_factory=dict)

    def apply(self, graph):
        self._old = {nid: graph.nodes[nid].position for nid in self.positions}
        for nid, pos in sorted(self.positions.items()):
            graph._set_position(nid, pos)

    def revert(self, graph):
        for nid, pos in sorted(self._old.items()):
            graph._set_position(nid, pos)


@dataclass
class SetLabel(Command):
    node_id: str
    label: str
    text: str = "rename node"
    kind: ChangeKind = ChangeKind.LAYOUT
    _old: str = ""

    def apply(self, graph):
        self._old = graph.nodes[self.node_id].label
        graph._set_label(self.node_id, self.label)

    def revert(self, graph):
        graph._set_label(self.node_id, self._old)


@dataclass
class SetMuted(Command):
    """Bypasses (mutes) nodes, or lets them work again: a bypassed node passes its first input
    of each output's type through (matedit.compiler.lower), so a look can be seen without
    it and brought back without rewiring. Structural: the generated code changes."""

    node_ids: tuple[str, ...]
    muted: bool
    text: str = "bypass nodes"
    _old: dict[str, bool] = field(default_factory=dict)

    def apply(self, graph):
        for nid in self.node_ids:
            node = graph.nodes.get(nid)
            if node is None:
                raise CommandError(f"no node {nid!r}")
            if self.muted and not nodes.can_bypass(node.kind):
                d = nodes.REGISTRY.get(node.kind)
                raise CommandError(f"{d.title if d else node.kind} cannot be bypassed: it "
                                   "has no input to pass through")
        self._old = {nid: graph.nodes[nid].muted for nid in self.node_ids}
        for nid in self.node_ids:
            graph._set_muted(nid, self.muted)

    def revert(self, graph):
        for nid, was in self._old.items():
            graph._set_muted(nid, was)


@dataclass
class PutComment(Command):
    """Adds, edits (same id) or, with comment=None, removes a comment frame."""

    comment_id: str
    comment: Comment | None
    text: str = "edit comment"
    kind: ChangeKind = ChangeKind.LAYOUT
    _old: Comment | None = None

    def apply(self, graph):
        self._old = copy.deepcopy(graph.comments.get(self.comment_id))
        graph._put_comment(self.comment, self.comment_id)

    def revert(self, graph):
        graph._put_comment(self._old, self.comment_id)


@dataclass
class Macro(Command):
    """Several commands as one edit; revert undoes them in reverse order."""

    commands: list[Command]
    text: str = "edit"

    @property
    def kind(self) -> ChangeKind:  # type: ignore[override]
        kinds = {c.kind for c in self.commands}
        for k in (ChangeKind.STRUCTURAL, ChangeKind.VALUE):
            if k in kinds:
                return k
        return ChangeKind.LAYOUT

    def apply(self, graph):
        done: list[Command] = []
        try:
            for c in self.commands:
                c.apply(graph)
                done.append(c)
        except Exception:
            for c in reversed(done):
                c.revert(graph)
            raise

    def revert(self, graph):
        for c in reversed(self.commands):
            c.revert(graph)
