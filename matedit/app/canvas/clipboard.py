"""Copy and paste of nodes as JSON, on the system clipboard.

A clipboard payload is an ordinary material document (the file format, through
`matedit.io.document`) holding the copied nodes, the links among them and the
copied comments; it travels as `application/x-matedit-nodes` and as plain text,
so nodes paste between editors and from a material file's text. Pasting makes
commands only: AddNode for each node (fresh ids where the old ones are taken),
Connect for each kept link, PutComment for each comment.
"""

from __future__ import annotations

import json
import re

from PySide6.QtCore import QMimeData

from matedit.graph.commands import AddNode, Command, Connect, PutComment
from matedit.graph.model import (
    Comment,
    DocumentKind,
    Link,
    MaterialDocument,
    MaterialGraph,
    Node,
)
from matedit.graph.nodes import is_value_parameter
from matedit.io.document import FormatError, from_dict, to_dict

MIME = "application/x-matedit-nodes"


def copy_payload(doc: MaterialDocument, node_ids, comment_ids=()) -> dict:
    """The selected nodes, the links among them, and the selected comments, as a document dict."""
    keep = set(node_ids) & set(doc.graph.nodes)
    sub = MaterialDocument(DocumentKind.MATERIAL, MaterialGraph(), name="clipboard")
    for nid in keep:
        sub.graph.nodes[nid] = doc.graph.nodes[nid].clone()
    sub.graph.links = {l for l in doc.graph.links if l.src in keep and l.dst in keep}
    for cid in comment_ids:
        if cid in doc.graph.comments:
            sub.graph.comments[cid] = doc.graph.comments[cid]
    return to_dict(sub)


def to_mime(payload: dict) -> QMimeData:
    text = json.dumps(payload, sort_keys=True, indent=2)
    mime = QMimeData()
    mime.setData(MIME, text.encode("utf-8"))
    mime.setText(text)
    return mime


def from_mime(mime: QMimeData | None) -> MaterialDocument | None:
    """The document on the clipboard, or None if it holds no matedit nodes."""
    if mime is None:
        return None
    if mime.hasFormat(MIME):
        text = bytes(mime.data(MIME).data()).decode("utf-8", "replace")
    elif mime.hasText():
        text = mime.text()
    else:
        return None
    if not text.lstrip().startswith("{"):
        return None
    try:
        return from_dict(json.loads(text), "clipboard")
    except (ValueError, FormatError, RecursionError):
        return None


def _stem(node_id: str) -> str:
    return re.sub(r"\d+$", "", node_id) or "n"


def fresh_id(graph: MaterialGraph, wanted: str, reserved: set[str]) -> str:
    """`wanted` if it is free, else a new counter id on its stem (from `graph.new_id`)."""

    def taken(s: str) -> bool:
        return s in graph.nodes or s in graph.comments or s in reserved

    if not taken(wanted):
        return wanted
    candidate = graph.new_id(_stem(wanted))
    if not taken(candidate):
        return candidate
    base, i = _stem(candidate), 1  # new_id does not know the ids reserved by this paste
    while taken(f"{base}{i}"):
        i += 1
    return f"{base}{i}"


def paste_commands(graph: MaterialGraph, clip: MaterialDocument,
                   offset: tuple[float, float]) -> tuple[list[Command], list[str]]:
    """Commands that add `clip`'s nodes to `graph` moved by `offset`, and the new node ids."""
    reserved: set[str] = set()
    ids: dict[str, str] = {}
    commands: list[Command] = []
    dx, dy = offset
    # A parameter's name is its uniform: a pasted or duplicated one whose name the graph
    # already has gets the next free "name_2", "name_3"... (two would stop the material).
    names = {str(n.settings.get("name")) for n in graph.nodes.values()
             if is_value_parameter(n.kind)}
    for old in sorted(clip.graph.nodes):
        n = clip.graph.nodes[old]
        new = fresh_id(graph, old, reserved)
        reserved.add(new)
        ids[old] = new
        settings = dict(n.settings)
        if is_value_parameter(n.kind) and isinstance(settings.get("name"), str):
            settings["name"] = _free_name(settings["name"], names)
            names.add(settings["name"])
        commands.append(AddNode(Node(new, n.kind, (n.position[0] + dx, n.position[1] + dy),
                                     settings, dict(n.values), n.label),
                                text="paste"))
    for l in sorted(clip.graph.links):
        if l.src in ids and l.dst in ids:
            commands.append(Connect(Link(ids[l.src], l.src_port, ids[l.dst], l.dst_port)))
    for cid in sorted(clip.graph.comments):
        c = clip.graph.comments[cid]
        new = fresh_id(graph, cid, reserved)
        reserved.add(new)
        x, y, w, h = c.rect
        commands.append(PutComment(new, Comment(new, c.text, (x + dx, y + dy, w, h), c.color)))
    return commands, [ids[k] for k in sorted(ids)]


def _free_name(name: str, taken: set[str]) -> str:
    """`name`, or with its numeric suffix moved on (roughness -> roughness_2, tint_2 -> tint_3)
    until no other parameter has it."""
    if name not in taken:
        return name
    stem, _, tail = name.rpartition("_")
    stem, i = (stem, int(tail)) if stem and tail.isdigit() else (name, 1)
    while f"{stem}_{i}" in taken or i == 1:
        i += 1
    return f"{stem}_{i}"


def payload_bounds(clip: MaterialDocument) -> tuple[float, float] | None:
    """The top-left corner of what the clipboard holds (node positions and comment rects)."""
    xs = [n.position[0] for n in clip.graph.nodes.values()]
    ys = [n.position[1] for n in clip.graph.nodes.values()]
    xs += [c.rect[0] for c in clip.graph.comments.values()]
    ys += [c.rect[1] for c in clip.graph.comments.values()]
    return (min(xs), min(ys)) if xs else None
