"""Shape checks of documents against the published JSON Schema (matedit/schemas/).

`check_document_shape(raw, file)` validates a parsed document (a plain dict, already
migrated to the current version) with the `jsonschema` library against the schema of its
``format`` and raises `matedit.io.document.FormatError` naming the file, and the node and
field where the problem is inside ``nodes[i]``. The schemas allow members they do not
know, so files from a newer minor version keep loading; graph-level rules (known node
kinds, port types, cycles) are validation's job, not the schema's.

A valid document is recognised without importing `jsonschema` (matedit.io.schema_subset
judges the few keywords the schemas use); the library is loaded only when that check does
not say yes, to decide and to word the error.
"""

from __future__ import annotations

import json
from functools import cache
from pathlib import Path
from typing import Any

from matedit.io.errors import FormatError
from matedit.io.schema_subset import SubsetChecker, compile_schemas

SCHEMA_DIR = Path(__file__).resolve().parent.parent / "schemas"
SCHEMA_FILES = {
    "matedit.material": "material.schema.json",
    "matedit.function": "function.schema.json",
    "matedit.instance": "instance.schema.json",
}
_SHARED = ("document.schema.json",)


def schema_path(fmt: str) -> Path:
    """The schema file of a document format ('matedit.material', 'matedit.function')."""
    return SCHEMA_DIR / SCHEMA_FILES[fmt]


@cache
def _schemas() -> dict[str, dict]:
    """Every schema file's contents by file name (read once)."""
    return {name: json.loads((SCHEMA_DIR / name).read_text(encoding="utf-8"))
            for name in (*_SHARED, *SCHEMA_FILES.values())}


@cache
def _subset_checker(fmt: str) -> SubsetChecker | None:
    return compile_schemas(_schemas(), schema_path(fmt).name)


@cache
def _validator(fmt: str):
    from jsonschema import Draft202012Validator
    from referencing import Registry, Resource

    resources = [(c["$id"], Resource.from_contents(c)) for c in _schemas().values()]
    registry = Registry().with_resources(resources)
    return Draft202012Validator(_schemas()[schema_path(fmt).name], registry=registry)


def _path_text(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def _located(raw: dict, path: list) -> tuple[str | None, str | None, list]:
    """(node id, field, path inside the node) of an error at `path` in the document."""
    if len(path) >= 2 and path[0] == "nodes" and isinstance(path[1], int):
        entry = raw["nodes"][path[1]]
        nid = entry.get("id") if isinstance(entry, dict) else None
        inner = path[2:]
        if inner:
            node = nid if isinstance(nid, str) and inner[0] != "id" else None
            return node, str(inner[0]), inner
        return (nid if isinstance(nid, str) else None), f"nodes[{path[1]}]", []
    if len(path) >= 2 and path[0] == "comments" and isinstance(path[1], int):
        entry = raw["comments"][path[1]]
        cid = entry.get("id") if isinstance(entry, dict) else None
        inner = path[2:]
        return (cid if isinstance(cid, str) and inner and inner[0] != "id" else None,
                str(inner[0]) if inner else f"comments[{path[1]}]", inner)
    return None, (_path_text(path[:2]) if path else None), path


def check_document_shape(raw: Any, file: str | None = None) -> None:
    """Raise FormatError when `raw` does not have the shape its format's schema describes."""
    if not isinstance(raw, dict):
        raise FormatError(file, "top level must be a JSON object")
    fmt = raw.get("format")
    if not isinstance(fmt, str) or fmt not in SCHEMA_FILES:
        raise FormatError(file, f"'format' must be one of {', '.join(sorted(SCHEMA_FILES))}, "
                          f"got {fmt!r}", field="format")
    subset = _subset_checker(fmt)
    if subset is not None and subset.is_valid(raw):  # the usual case, without jsonschema
        return
    validator = _validator(fmt)
    if validator.is_valid(raw):  # no error to rank
        return
    from jsonschema.exceptions import best_match

    error = best_match(validator.iter_errors(raw))
    if error is None:
        return
    path = list(error.absolute_path)
    text = error.message
    if error.validator == "required":  # name the missing member as the field
        missing = next(k for k in error.validator_value if k not in error.instance)
        path.append(missing)
        text = ""
    elif error.validator == "pattern":
        text = (f"must be an identifier (a letter, then letters, digits or '_', at most 64, "
                f"no '__'), got {error.instance!r}")
    node, field, inner = _located(raw, path)
    if node is None and inner and path[:1] in (["nodes"], ["comments"]):
        inner = path  # the node cannot be named: give its index
    where = _path_text(inner) if inner else _path_text(path)
    message = f"{where} is required" if not text else (f"{where}: {text}" if where else text)
    raise FormatError(file, message, node=node, field=field)
