"""The layer stack of a material: a view over a `layer_stack` node that makes edits.

The stack lives in the graph (the node's `layers` setting, base layer first),
so the layer panel and the canvas can never disagree. Each edit is a command;
edits that remove ports also remove the links into them, in the same macro.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

from matedit.graph.commands import Command, CommandError, Connect, Disconnect, Macro, SetSetting
from matedit.graph.model import Link, MaterialGraph
from matedit.graph.nodes import Role, role_of
from matedit.graph.ports import LAYER_BLENDS, layer_entries

# Ports a layer has only when it is not the base (the blend inputs).
BLEND_SUFFIXES = ("_mask", "_opacity", "_base_height", "_contrast")


def parked_wires(entry: dict) -> list[dict]:
    """The blend wires a base layer keeps for when it is no longer the base."""
    parked = entry.get("parked")
    return [w for w in parked if isinstance(w, dict)] if isinstance(parked, list) else []


@dataclass
class Layer:
    id: str
    function: str
    name: str = ""
    blend: str = "alpha"
    visible: bool = True

    def to_json(self) -> dict:
        return {"id": self.id, "function": self.function, "name": self.name or self.id,
                "blend": self.blend, "visible": self.visible}


class LayerStack:
    """Layers of the `layer_stack` node `node_id`, bottom (base) first."""

    def __init__(self, graph: MaterialGraph, node_id: str, resolver=None, owner=None) -> None:
        """With a function resolver (and the owning document), edits cut only the links into
        ports that the edit removes; without one, every link into an edited layer's ports."""
        if graph.nodes.get(node_id) is None or \
                role_of(graph.nodes[node_id].kind) != Role.LAYER_STACK:
            raise ValueError(f"{node_id!r} is not a layer stack node")
        self.graph = graph
        self.node_id = node_id
        self.resolver = resolver
        self.owner = owner

    @classmethod
    def find(cls, graph: MaterialGraph, resolver=None, owner=None) -> LayerStack | None:
        ids = sorted(n.id for n in graph.nodes.values() if role_of(n.kind) == Role.LAYER_STACK)
        return cls(graph, ids[0], resolver, owner) if ids else None

    def _surviving_ports(self, entries: list[dict]) -> set[str] | None:
        """Input port names after `entries` replace the layers, or None if unknown."""
        if self.resolver is None:
            return None
        from matedit.graph.model import Node
        from matedit.graph.ports import node_ports

        trial = Node(self.node_id, self.graph.nodes[self.node_id].kind,
                     settings={"layers": entries})
        try:
            return {p.name for p in node_ports(trial, self.resolver, self.owner).inputs}
        except (LookupError, ValueError):
            return None

    @property
    def layers(self) -> list[Layer]:
        out = []
        for e in layer_entries(self.graph.nodes[self.node_id]):
            out.append(Layer(e["id"], e["function"], e.get("name", e["id"]),
                             e.get("blend", "alpha"), bool(e.get("visible", True))))
        return out

    def _entries(self) -> list[dict]:
        return copy.deepcopy(layer_entries(self.graph.nodes[self.node_id]))

    def _set(self, entries: list[dict], text: str, drop_ports_of=frozenset()) -> Command:
        """The macro that makes `entries` the layers: links into ports that vanish are cut,
        except the blend wires of the layer that becomes the base, which are parked in its
        entry (`parked`) and brought back once it is no longer the base."""
        cmds: list[Command] = []
        surviving = self._surviving_ports(entries)
        base = entries[0] if entries else None
        base_id = base["id"] if base else None
        for link in sorted(self.graph.links):
            if link.dst != self.node_id:
                continue
            on_base = base_id is not None and base_id not in drop_ports_of and \
                link.dst_port.startswith(f"{base_id}_")
            if surviving is not None:
                gone = link.dst_port not in surviving
            else:
                gone = any(link.dst_port.startswith(f"{lid}_") for lid in drop_ports_of) or (
                    on_base and link.dst_port.endswith(BLEND_SUFFIXES))
            if gone and on_base and base is not None and base_id is not None:
                base.setdefault("parked", []).append(
                    {"port": link.dst_port[len(base_id) + 1:],
                     "from": [link.src, link.src_port]})
            if gone:
                cmds.append(Disconnect(link))
        restore: list[Command] = []
        for index, entry in enumerate(entries):
            parked = entry.get("parked")
            if index == 0 or not parked:
                continue
            entry.pop("parked")
            for wire in parked if isinstance(parked, list) else []:
                try:
                    src, src_port = wire["from"]
                    port = f"{entry['id']}_{wire['port']}"
                except (KeyError, TypeError, ValueError):
                    continue
                if src not in self.graph.nodes or (surviving is not None
                                                   and port not in surviving):
                    continue
                restore.append(Connect(Link(src, src_port, self.node_id, port)))
        cmds.append(SetSetting(self.node_id, "layers", entries))
        return Macro(cmds + restore, text=text)

    def new_layer_id(self, stem: str = "layer") -> str:
        taken = {e["id"] for e in self._entries()}
        stem = "".join(c for c in stem if c.isalnum()) or "layer"
        if not stem[0].isalpha():
            stem = "l" + stem
        i = 1
        while f"{stem}{i}" in taken:
            i += 1
        return f"{stem}{i}"

    def add(self, layer: Layer, index: int | None = None) -> Command:
        entries = self._entries()
        if any(e["id"] == layer.id for e in entries):
            raise CommandError(f"a layer with id {layer.id!r} already exists")
        _check_blend(layer.blend)
        entries.insert(len(entries) if index is None else index, layer.to_json())
        return self._set(entries, f"add layer {layer.name or layer.id}")

    def remove(self, layer_id: str) -> Command:
        entries = self._entries()
        if not any(e["id"] == layer_id for e in entries):
            raise CommandError(f"no layer {layer_id!r}")
        entries = [e for e in entries if e["id"] != layer_id]
        return self._set(entries, f"remove layer {layer_id}", {layer_id})

    def move(self, layer_id: str, index: int) -> Command:
        """Moves a layer to `index` (0 = base). The new base parks its blend wires."""
        entries = self._entries()
        old = next((i for i, e in enumerate(entries) if e["id"] == layer_id), None)
        if old is None:
            raise CommandError(f"no layer {layer_id!r}")
        if not 0 <= index < len(entries):
            raise CommandError(f"layer index {index} out of range 0..{len(entries) - 1}")
        entry = entries.pop(old)
        entries.insert(index, entry)
        # The layer that becomes the base parks its blend wires; the old base gets its back.
        return self._set(entries, f"move layer {layer_id}")

    def is_solo(self, layer_id: str) -> bool:
        """Whether `layer_id` is the only layer shown over the base (or the base alone)."""
        entries = self._entries()
        return any(e["id"] == layer_id for e in entries) and all(
            bool(e.get("visible", True)) == (e["id"] == layer_id)
            for e in entries[1:])  # the base always shows

    def solo(self, layer_id: str) -> Command:
        """Shows `layer_id` alone over the base (the base alone, for the base) by hiding the
        other layers; on a layer already solo, shows every layer again."""
        entries = self._entries()
        if not any(e["id"] == layer_id for e in entries):
            raise CommandError(f"no layer {layer_id!r}")
        if self.is_solo(layer_id):
            for e in entries:
                e["visible"] = True
            return self._set(entries, "show every layer")
        for e in entries[1:]:
            e["visible"] = e["id"] == layer_id
        return self._set(entries, f"solo layer {layer_id}")

    def set(self, layer_id: str, **changes) -> Command:
        """Changes a layer's name, blend, visibility or function."""
        entries = self._entries()
        entry = next((e for e in entries if e["id"] == layer_id), None)
        if entry is None:
            raise CommandError(f"no layer {layer_id!r}")
        for key, value in changes.items():
            if key not in ("name", "blend", "visible", "function"):
                raise CommandError(f"a layer has no property {key!r}")
            if key == "blend":
                _check_blend(value)
            entry[key] = value
        drop = {layer_id} if ("blend" in changes or "function" in changes) else set()
        return self._set(entries, f"edit layer {layer_id}", drop)


def _check_blend(blend: str) -> None:
    if blend not in LAYER_BLENDS and not (isinstance(blend, str) and blend.endswith(".json")):
        raise CommandError(f"unknown blend {blend!r}: {', '.join(LAYER_BLENDS)} "
                           "or a blend function file")
