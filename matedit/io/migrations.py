"""Schema migrations of material files: one function per version step, each tested.

`MIGRATIONS[n]` turns a version-n document (a plain dict) into version n + 1.
"""

from __future__ import annotations

from collections.abc import Callable

CURRENT_VERSION = 2


class MigrationError(ValueError):
    pass


def _v1_to_v2(doc: dict) -> dict:
    """Version 1 (the first drafts) wrote links as "node.port" strings under "connections",
    input values under "params" and positions as "pos"; version 2 uses
    {"from": [node, port], "to": [node, port]}, "values" and "position"."""
    out = {k: v for k, v in doc.items() if k not in ("connections", "nodes")}
    nodes = []
    for n in doc.get("nodes", []):
        if not isinstance(n, dict):
            nodes.append(n)
            continue
        n = dict(n)
        if "pos" in n:
            n["position"] = n.pop("pos")
        if "params" in n:
            n["values"] = n.pop("params")
        nodes.append(n)
    out["nodes"] = nodes
    links = []
    for i, c in enumerate(doc.get("connections", [])):
        try:
            src, dst = c["src"], c["dst"]
            s_node, s_port = src.split(".", 1)
            d_node, d_port = dst.split(".", 1)
        except (TypeError, KeyError, ValueError, AttributeError):
            raise MigrationError(f"connections[{i}]: expected {{'src': 'node.port', "
                                 f"'dst': 'node.port'}}, got {c!r}") from None
        links.append({"from": [s_node, s_port], "to": [d_node, d_port]})
    out["links"] = links
    out["version"] = 2
    return out


MIGRATIONS: dict[int, Callable[[dict], dict]] = {1: _v1_to_v2}


def migrate(doc: dict) -> dict:
    """Bring a document dict up to CURRENT_VERSION, one step at a time."""
    version = doc.get("version")
    if not isinstance(version, int):
        raise MigrationError(f"'version' must be an integer, got {version!r}")
    while version < CURRENT_VERSION:
        step = MIGRATIONS.get(version)
        if step is None:
            raise MigrationError(f"no migration from version {version}")
        doc = step(doc)
        if doc.get("version") != version + 1:
            raise MigrationError(f"migration from version {version} did not advance")
        version = doc["version"]
    return doc
