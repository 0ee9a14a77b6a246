"""Material and material-function files: JSON load, save, and path resolution.

Loading parses JSON only: it never executes anything from the file. Structural
problems (not JSON, wrong shapes, a newer version) raise `FormatError` naming
the file, node and field; graph-level problems are left to validation.
Saving writes sorted keys and two-space indent, atomically, with paths stored
relative to the saved file.
"""

from __future__ import annotations

import json
import os
import stat
import threading
import time
from collections import OrderedDict
from pathlib import Path
from typing import Any

from matedit.graph.model import Comment, DocumentKind, Link, MaterialDocument, Node, valid_id
from matedit.graph.nodes import Role, role_of
from matedit.io import library
from matedit.io.bounded import UnsafeFileError, read_bounded
from matedit.io.errors import FormatError
from matedit.io.jsontext import JSONTextError, check_json_value, parse_json
from matedit.io.migrations import CURRENT_VERSION, MigrationError, migrate

FORMATS = {"matedit.material": DocumentKind.MATERIAL, "matedit.function": DocumentKind.FUNCTION}
FORMAT_OF = {v: k for k, v in FORMATS.items()}
INSTANCE_FORMAT = "matedit.instance"  # matedit.io.instance's files (named here for readers
# that tell the kinds apart without importing that module)
MAX_FILE_BYTES = 64 * 1024 * 1024


def _where(raw: Any, path: list) -> tuple[str | None, str]:
    """(node id, field) for a position inside the raw document, for error messages."""
    node, rest = None, path
    if len(path) >= 2 and path[0] in ("nodes", "comments") and isinstance(path[1], int):
        try:
            nid = raw[path[0]][path[1]].get("id")
        except (AttributeError, IndexError, KeyError, TypeError):
            nid = None
        if isinstance(nid, str):
            node, rest = nid, path[2:]
    parts: list[str] = []
    for p in rest:
        parts.append(f"[{p}]" if isinstance(p, int) else ("." if parts else "") + str(p))
    return node, "".join(parts) or "<top>"


def _located(exc: JSONTextError, file: str | None) -> FormatError:
    """A FormatError naming the node and field where `parse_json`'s rules failed."""
    if exc.path and exc.value is not None:
        node, fld = _where(exc.value, exc.path)
        return FormatError(file, exc.reason, node, fld)
    return FormatError(file, exc.reason, field=exc.field)


def _check_numbers(raw: Any, file: str | None) -> None:
    """Depth and 64-bit numbers of a dict from elsewhere (matedit.io.jsontext's rules)."""
    try:
        check_json_value(raw)
    except JSONTextError as exc:
        raise _located(exc, file) from None


def parse_json_text(text: str, file: str | None = None) -> Any:
    """The JSON value of a document's text (matedit.io.jsontext.parse_json: no BOM, no
    duplicate keys, no NaN/infinity, bounded nesting, every number a 64-bit float), shared by
    materials, functions and instances; raises FormatError naming the node and field."""
    try:
        return parse_json(text)
    except JSONTextError as exc:
        raise _located(exc, file) from None


def loads(text: str, file: str | None = None, path: Path | None = None) -> MaterialDocument:
    """Parse a document from JSON text (`path` anchors its relative references)."""
    # parse_json checked depth and numbers already: from_dict's check, without its walk
    return _from_dict(parse_json_text(text, file), file, path)


def read_document_text(path: str | os.PathLike) -> str:
    """The text of a document file: a regular file of at most MAX_FILE_BYTES, in UTF-8."""
    p = Path(path)
    try:
        data = read_bounded(p, MAX_FILE_BYTES)
    except FileNotFoundError:
        raise FormatError(str(p), "file not found") from None
    except IsADirectoryError:
        raise FormatError(str(p), "is a directory, not a material file") from None
    except UnsafeFileError as exc:
        raise FormatError(str(p), str(exc).split(": ", 1)[-1]) from None
    except OSError as exc:
        raise FormatError(str(p), f"cannot read: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise FormatError(str(p), "not UTF-8 text") from None


def load(path: str | os.PathLike) -> MaterialDocument:
    p = Path(path)
    return loads(read_document_text(p), str(p), p)


def _expect(cond: bool, file, msg, node=None, field=None) -> None:
    if not cond:
        raise FormatError(file, msg, node, field)


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and x == x and abs(x) != float(
        "inf")


def from_dict(raw: Any, file: str | None = None, path: Path | None = None) -> MaterialDocument:
    """A document from parsed JSON; raises FormatError. A document that loads also saves."""
    _check_numbers(raw, file)
    return _from_dict(raw, file, path)  # which checks that the document saves


def _from_dict(raw: Any, file: str | None, path: Path | None) -> MaterialDocument:
    _expect(isinstance(raw, dict), file, "top level must be a JSON object")
    fmt = raw.get("format")
    _expect(isinstance(fmt, str) and fmt in FORMATS, file,
            f"'format' must be one of {', '.join(sorted(FORMATS))}, got {fmt!r}", field="format")
    version = raw.get("version")
    _expect(isinstance(version, int) and not isinstance(version, bool) and version >= 1, file,
            f"'version' must be a positive integer, got {version!r}", field="version")
    if version > CURRENT_VERSION:
        raise FormatError(file, f"written by a newer matedit (file version {version}, this "
                          f"build reads up to {CURRENT_VERSION}); update matedit to open it",
                          field="version")
    try:
        raw = migrate(raw)
    except MigrationError as exc:
        raise FormatError(file, f"cannot migrate from version {version}: {exc}") from None
    except (TypeError, AttributeError) as exc:
        raise FormatError(file, f"cannot migrate from version {version}: {exc}") from None

    from matedit.io.schema import check_document_shape

    check_document_shape(raw, file)  # the published JSON Schema (matedit/schemas/)
    doc = MaterialDocument(kind=FORMATS[fmt], path=Path(path) if path else None)
    doc.extra = _unknown(raw, TOP_FIELDS)
    for key in ("name", "description"):
        val = raw.get(key, "")
        _expect(isinstance(val, str), file, f"'{key}' must be a string", field=key)
        setattr(doc, key, val)
    preview = raw.get("preview", {})
    _expect(isinstance(preview, dict), file, "'preview' must be an object", field="preview")
    for key in ("mesh", "environment"):
        _expect(key not in preview or isinstance(preview[key], str), file,
                f"'preview.{key}' must be a string (a built-in name or a file path)",
                field=f"preview.{key}")
    doc.preview = preview

    nodes = raw.get("nodes", [])
    _expect(isinstance(nodes, list), file, "'nodes' must be a list", field="nodes")
    for i, n in enumerate(nodes):
        _expect(isinstance(n, dict), file, f"nodes[{i}] must be an object", field=f"nodes[{i}]")
        nid = n.get("id")
        _expect(valid_id(nid), file,
                f"nodes[{i}]: id must be an ASCII identifier of at most 64 letters, digits and _, "
                f"starting with a letter, with no '__' and no 'gl_' prefix, got {nid!r}",
                field="id")
        _expect(nid not in doc.graph.nodes, file, "duplicate node id", node=nid, field="id")
        kind = n.get("kind")
        _expect(isinstance(kind, str) and kind != "", file, "kind must be a string", nid, "kind")
        pos = n.get("position", [0, 0])
        _expect(isinstance(pos, list) and len(pos) == 2 and all(_number(x) for x in pos), file,
                "position must be two numbers", nid, "position")
        settings = n.get("settings", {})
        _expect(isinstance(settings, dict), file, "settings must be an object", nid, "settings")
        values = n.get("values", {})
        _expect(isinstance(values, dict), file, "values must be an object", nid, "values")
        label = n.get("label", "")
        _expect(isinstance(label, str), file, "label must be a string", nid, "label")
        muted = n.get("muted", False)
        _expect(isinstance(muted, bool), file, "muted must be true or false", nid, "muted")
        doc.graph.nodes[nid] = Node(nid, kind, (float(pos[0]), float(pos[1])), settings,
                                    values, label, _unknown(n, NODE_FIELDS), muted)

    links = raw.get("links", [])
    _expect(isinstance(links, list), file, "'links' must be a list", field="links")
    for i, l in enumerate(links):
        ok = (isinstance(l, dict) and all(isinstance(l.get(k), list) and len(l[k]) == 2
                                          and all(isinstance(x, str) for x in l[k])
                                          for k in ("from", "to")))
        _expect(ok, file, f"links[{i}] must be {{\"from\": [node, output], \"to\": [node, "
                f"input]}}", field=f"links[{i}]")
        link = Link(l["from"][0], l["from"][1], l["to"][0], l["to"][1])
        _expect(link not in doc.graph.links, file, f"links[{i}] is listed twice",
                node=link.dst, field=link.dst_port)
        doc.graph.links.add(link)
        extra = _unknown(l, LINK_FIELDS)
        if extra:
            doc.link_extra[link] = extra

    comments = raw.get("comments", [])
    _expect(isinstance(comments, list), file, "'comments' must be a list", field="comments")
    for i, c in enumerate(comments):
        _expect(isinstance(c, dict) and valid_id(c.get("id")), file,
                f"comments[{i}] needs an identifier id", field=f"comments[{i}]")
        rect = c.get("rect", [0, 0, 200, 120])
        color = c.get("color", [0.3, 0.3, 0.3])
        text = c.get("text", "")
        _expect(isinstance(rect, list) and len(rect) == 4 and all(_number(x) for x in rect),
                file, "rect must be four numbers", c["id"], "rect")
        _expect(isinstance(color, list) and len(color) == 3 and all(_number(x) for x in color),
                file, "color must be three numbers", c["id"], "color")
        _expect(isinstance(text, str), file, "text must be a string", c["id"], "text")
        _expect(c["id"] not in doc.graph.comments and c["id"] not in doc.graph.nodes, file,
                "duplicate id", c["id"], "id")
        x, y, w, h = (float(v) for v in rect)
        r, g, b = (float(v) for v in color)
        doc.graph.comments[c["id"]] = Comment(c["id"], text, (x, y, w, h), (r, g, b),
                                              _unknown(c, COMMENT_FIELDS))
    # here, not only in loads: a dict from elsewhere may hold an infinity in a kept field
    check_saves(to_dict(doc), file)
    return doc


def check_saves(data: dict, file: str | None) -> None:
    """FormatError unless `data` serialises as `dumps` writes it. The same encoder settings
    except the indent, which only lays out the text: without it, json uses its C encoder,
    several times faster on a large document, with the same TypeError and ValueError."""
    try:
        json.dumps(data, sort_keys=True, ensure_ascii=False, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise FormatError(file, f"holds a value that cannot be saved again: {exc}") from None


TOP_FIELDS = frozenset({"format", "version", "name", "description", "preview", "nodes",
                        "links", "comments"})
NODE_FIELDS = frozenset({"id", "kind", "position", "settings", "values", "label", "muted"})
LINK_FIELDS = frozenset({"from", "to"})
COMMENT_FIELDS = frozenset({"id", "text", "rect", "color"})


def _unknown(raw: dict, known: frozenset) -> dict[str, Any]:
    return {k: v for k, v in raw.items() if k not in known}


def to_dict(doc: MaterialDocument) -> dict:
    g = doc.graph
    out: dict[str, Any] = {**doc.extra,
        "format": FORMAT_OF[doc.kind],
        "version": CURRENT_VERSION,
        "name": doc.name,
        "description": doc.description,
        "nodes": [],
        "links": [{**doc.link_extra.get(l, {}), **l.to_json()} for l in sorted(g.links)],
    }
    for nid in sorted(g.nodes):
        n = g.nodes[nid]
        entry: dict[str, Any] = {**n.extra, "id": n.id, "kind": n.kind,
                                 "position": [_num(n.position[0]), _num(n.position[1])]}
        if n.settings:
            entry["settings"] = n.settings
        if n.values:
            entry["values"] = n.values
        if n.label:
            entry["label"] = n.label
        if n.muted:
            entry["muted"] = True
        out["nodes"].append(entry)
    if g.comments:
        out["comments"] = [
            {**c.extra, "id": c.id, "text": c.text, "rect": [_num(x) for x in c.rect],
             "color": [_num(x) for x in c.color]}
            for c in (g.comments[k] for k in sorted(g.comments))
        ]
    if doc.preview:
        out["preview"] = doc.preview
    return out


def _num(x: float) -> float | int:
    """Whole numbers are written without '.0' so files stay tidy; others as Python's repr."""
    return int(x) if float(x).is_integer() and abs(x) < 2**53 else float(x)


def dumps(doc: MaterialDocument) -> str:
    return json.dumps(to_dict(doc), sort_keys=True, indent=2, ensure_ascii=False,
                      allow_nan=False) + "\n"


# --- relative references ---------------------------------------------------------------------

def reference_fields(doc: MaterialDocument):
    """(container, key) for every stored file reference (functions, layers, textures)."""
    for n in doc.graph.nodes.values():
        role = role_of(n.kind)
        if role == Role.FUNCTION_CALL and isinstance(n.settings.get("function"), str):
            yield n.settings, "function"
        elif role == Role.TEXTURE_PARAMETER and isinstance(n.settings.get("path"), str):
            yield n.settings, "path"
        elif role == Role.LAYER_STACK and isinstance(n.settings.get("layers"), list):
            for e in n.settings["layers"]:
                if isinstance(e, dict):
                    if isinstance(e.get("function"), str):
                        yield e, "function"
                    if isinstance(e.get("blend"), str) and e["blend"].endswith(".json"):
                        yield e, "blend"


def rebase_references(doc: MaterialDocument, new_path: Path) -> None:
    """Rewrites relative references so they still point at the same files from `new_path`.
    Saved outside the built-in library, a reference to a library file becomes its stable
    `library:` name (matedit.io.library); `library:` names are kept as they are."""
    if doc.path is None:
        return
    old_dir = Path(os.path.realpath(doc.path)).parent
    new_dir = Path(os.path.realpath(new_path)).parent
    for container, key in reference_fields(doc):
        ref = container[key]
        if not ref or library.is_library_ref(ref) or Path(ref).is_absolute():
            continue
        target = Path(os.path.realpath(old_dir / ref))
        new = reference_from(target, new_dir)
        # In the same folder only a path into the library changes (to its library name: how
        # documents written before library names migrate on their next save).
        if old_dir != new_dir or library.is_library_ref(new):
            container[key] = new


def reference_from(target: Path, folder: Path) -> str:
    """How a document in `folder` refers to `target`: its library name when the target is in
    the built-in library and the document is not, else the relative path."""
    if not library.inside(folder):
        name = library.library_name(target)
        if name is not None:
            return name
    return Path(os.path.relpath(target, folder)).as_posix()


def save(doc: MaterialDocument, path: str | os.PathLike | None = None) -> Path:
    """Atomic save; with a new path, relative references are rebased first. Saved to the
    name it was opened from, a link there is followed; any other link is replaced."""
    target = Path(path) if path is not None else doc.path
    if target is None:
        raise ValueError("no path to save to")
    from matedit.io.atomic import atomic_write_text, saves_to_opened_path

    follow = saves_to_opened_path(target, doc.path)
    rebase_references(doc, target)
    atomic_write_text(target, dumps(doc), follow_link=follow)
    doc.path = Path(target)
    return Path(target)


# Material functions and layers read by any FileResolver in this process, by real path, with
# the signature of the file they were read from (device, inode, size, mtime in ns): a compile
# reads and checks an unchanged file once, and a file written since (a new mtime or size, or
# another file renamed over it) is read again, and so is one modified in the last two seconds
# (_RACY_NS). Only documents that loaded are kept; nothing
# in a document is executed, so a cached one is the same data a new read would give.
_DOCUMENT_CACHE_SIZE = 256
# A file modified this recently (ns) is read again next time, not cached: file systems stamp
# mtimes coarsely (a few ms; FAT, 2 s), and a rewrite of the same size within one tick would
# otherwise look unchanged
_RACY_NS = 2_000_000_000
_documents: OrderedDict[Path, tuple[tuple[int, int, int, int], MaterialDocument]] = \
    OrderedDict()
_documents_lock = threading.Lock()  # the editor compiles on a worker thread


def _file_signature(p: Path) -> tuple[int, int, int, int] | None:
    """(device, inode, size, mtime_ns) of a regular file; None for anything else (read, and
    refused, as before: never cached)."""
    st = p.stat()
    if not stat.S_ISREG(st.st_mode):
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def clear_document_cache() -> None:
    """Forgets every function and layer document read so far (tests; a caller that changes
    a file without changing its size or mtime)."""
    with _documents_lock:
        _documents.clear()


LOADS = 0  # function files FileResolver has read (not from its cache) in this process


class FileResolver:
    """Finds material functions relative to the file that uses them. Files that loaded are
    cached for the whole process by path, size and mtime (`_documents`): the document a
    resolver returns is shared, never to be changed by its caller."""

    def __init__(self) -> None:
        # files modified too recently for the shared cache, kept for this resolver's life
        # (one compile, or the editor's: the signature still decides)
        self._recent: dict[Path, tuple[tuple[int, int, int, int], MaterialDocument]] = {}

    def path_of(self, ref: str, owner: MaterialDocument | None) -> Path:
        if library.is_library_ref(ref):
            return library.library_path(ref)  # ValueError for a name out of the library
        base = Path(owner.path).parent if owner is not None and owner.path else Path.cwd()
        return Path(os.path.realpath(base / ref))

    def resolve(self, ref: str, owner: MaterialDocument | None) -> MaterialDocument:
        try:
            p = self.path_of(ref, owner)
            signature = _file_signature(p)
        except (OSError, ValueError):
            raise LookupError(f"{ref}: file not found") from None
        if signature is not None:
            recent = self._recent.get(p)
            if recent is not None and recent[0] == signature:
                return recent[1]
            hit = _cached(p, signature)
            if hit is not None:
                return hit
        global LOADS
        LOADS += 1
        try:
            doc = load(p)
        except FormatError as exc:
            raise LookupError(f"{ref}: {exc.reason}") from None
        if not doc.is_function:
            raise LookupError(f"{ref} is a material, not a material function")
        if signature is not None and not _keep(p, signature, doc):
            self._recent[p] = (signature, doc)
        return doc


def _cached(p: Path, signature: tuple[int, int, int, int]) -> MaterialDocument | None:
    """The shared document read from real path `p` when the file still has `signature`."""
    with _documents_lock:
        hit = _documents.get(p)
        if hit is not None and hit[0] == signature:
            _documents.move_to_end(p)
            return hit[1]
    return None


def _keep(p: Path, signature: tuple[int, int, int, int], doc: MaterialDocument) -> bool:
    """Keeps a function `doc` read from real path `p` in the shared cache; False (not kept)
    for a file modified too recently to trust its signature (_RACY_NS)."""
    if time.time_ns() - signature[3] < _RACY_NS:
        return False
    with _documents_lock:
        _documents[p] = (signature, doc)
        _documents.move_to_end(p)
        while len(_documents) > _DOCUMENT_CACHE_SIZE:
            _documents.popitem(last=False)
    return True


def load_shared(path: str | Path) -> MaterialDocument:
    """`load(path)` through the shared cache of function documents (`FileResolver`'s): a
    function file read here is not read again by a compile, nor one a compile has read here.
    The document returned may be shared, never to be changed by the caller (a listing that
    only reads names and interfaces: matedit.app.library). Raises FormatError as `load`."""
    p = Path(os.path.realpath(path))
    try:
        signature = _file_signature(p)
    except OSError:
        signature = None  # load says what is wrong with it
    if signature is not None:
        hit = _cached(p, signature)
        if hit is not None:
            return hit
    doc = load(p)
    if signature is not None and doc.is_function:
        _keep(p, signature, doc)
    return doc
