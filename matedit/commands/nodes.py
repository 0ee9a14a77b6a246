"""`matedit nodes [--json] [--category NAME]`: the node catalogue, as text or as JSON.

The JSON is `catalogue()`: one record per kind with its title, category, description,
ports (types, defaults, ranges), settings, and the targets it is implemented for. The
palette, Help and the documentation read the same records. `SCHEMA` is its JSON Schema.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from matedit.cli_support import UsageError
from matedit.io.input_kinds import declare_inputs

GLSL_TARGETS = ("glsl330", "glsl450", "essl300")
SCHEMA_VERSION = 1

_PORT = {
    "type": "object",
    "required": ["name", "type", "doc"],
    "additionalProperties": False,
    "properties": {
        "name": {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
        "type": {"enum": ["float", "vec2", "vec3", "vec4", "MaterialAttributes", "texture2d",
                          "T"]},
        "default": {},
        "range": {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 2,
                  "maxItems": 2},
        # hard bounds, null on an unbounded side (the slider's `range` may be typed past)
        "limits": {"type": ["array", "null"], "items": {"type": ["number", "null"]},
                   "minItems": 2, "maxItems": 2},
        "doc": {"type": "string"},
        "required": {"type": "boolean"},
    },
}
SCHEMA: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "matedit node catalogue",
    "type": "object",
    "required": ["schema_version", "count", "nodes"],
    "additionalProperties": False,
    "properties": {
        "schema_version": {"const": SCHEMA_VERSION},
        "count": {"type": "integer", "minimum": 0},
        "nodes": {
            "type": "array",
            "items": {
                "type": "object",
                "required": ["kind", "title", "category", "description", "inputs", "outputs",
                             "settings", "targets", "implementation", "materialx"],
                "additionalProperties": False,
                "properties": {
                    "kind": {"type": "string", "pattern": "^[a-z][a-z0-9_]*$"},
                    "title": {"type": "string", "minLength": 1},
                    "category": {"type": "string", "minLength": 1},
                    "description": {"type": "string", "minLength": 1},
                    "inputs": {"type": "array", "items": _PORT},
                    "outputs": {"type": "array", "items": _PORT},
                    "settings": {"type": "array", "items": {
                        "type": "object", "required": ["name", "kind", "doc", "structural"],
                        "properties": {"name": {"type": "string"}, "kind": {"type": "string"},
                                       "default": {}, "doc": {"type": "string"},
                                       "structural": {"type": "boolean"},
                                       "choices": {"type": "array",
                                                   "items": {"type": "string"}}}}},
                    "dynamic_ports": {"type": "string"},
                    "targets": {"type": "array", "uniqueItems": True, "items": {
                        "enum": [*GLSL_TARGETS, "numpy", "materialx"]}},
                    "implementation": {"type": "object", "properties": {
                        "glsl": {"enum": ["function", "inline", "compiler"]},
                        "file": {"type": "string"},
                        "function": {"type": "string"},
                        "template": {"type": "string"},
                        "numpy": {"enum": ["function", "compiler"]}},
                        "required": ["glsl", "numpy"]},
                    "materialx": {"type": ["object", "null"], "properties": {
                        "node": {"type": "string"},
                        "recipe": {"type": "string"},
                        "inputs": {"type": "object",
                                   "additionalProperties": {"type": "string"}}}},
                },
            },
        },
    },
}


def _port(p, is_input: bool) -> dict[str, Any]:
    out: dict[str, Any] = {"name": p.name, "type": p.type, "doc": p.doc}
    if is_input:
        out["default"] = p.default
        out["range"] = list(p.range) if p.range else None
        out["limits"] = list(p.limits) if p.limits else None
        out["required"] = bool(p.required)
    return out


def _mtlx(m) -> dict[str, Any] | None:
    """The catalogue's MaterialX mapping (NodeDef.mtlx): one stdlib node and its inputs, or a
    recipe of a few nodes; None where the exporter bakes the kind or it is lowered away."""
    from matedit.graph.nodes import MxNode, MxRecipe

    if isinstance(m, MxNode):
        return {"node": m.category, "inputs": dict(m.ports)}
    if isinstance(m, MxRecipe):
        return {"recipe": m.name, "inputs": {}}
    return None


def catalogue(category: str | None = None) -> dict[str, Any]:
    """Every node kind as plain data (see SCHEMA), sorted by category then title."""
    from matedit.graph import nodes

    records = []
    for cat, defs in nodes.categories().items():
        if category is not None and cat.lower() != category.lower():
            continue
        for d in defs:
            if d.glsl:
                impl: dict[str, Any] = {"glsl": "function", "file": f"shaders/nodes/{d.kind}.glsl",
                                        "function": d.glsl}
            elif d.inline:
                impl = {"glsl": "inline", "template": d.inline}
            else:
                impl = {"glsl": "compiler"}
            impl["numpy"] = "function" if d.numpy is not None else "compiler"
            targets = list(GLSL_TARGETS)
            targets.append("numpy")  # a twin, or the compiler's own evaluation (lowered)
            if _mtlx(d.mtlx) is not None:
                targets.append("materialx")
            rec: dict[str, Any] = {
                "kind": d.kind, "title": d.title, "category": d.category,
                "description": d.description,
                "inputs": [_port(i, True) for i in d.inputs],
                "outputs": [_port(o, False) for o in d.outputs],
                "settings": [{"name": s.name, "kind": s.kind, "default": s.default,
                              "doc": s.doc, "structural": s.structural,
                              "choices": list(s.choices)} for s in d.settings],
                "targets": targets, "implementation": impl, "materialx": _mtlx(d.mtlx),
            }
            if d.ports_rule:
                rec["dynamic_ports"] = d.ports_rule
            records.append(rec)
    return {"schema_version": SCHEMA_VERSION, "count": len(records), "nodes": records}


def _fmt_default(v) -> str:
    if isinstance(v, list):
        return "(" + ", ".join(f"{x:g}" for x in v) + ")"
    if isinstance(v, float):
        return f"{v:g}"
    return "" if v is None else str(v)


def format_text(data: dict[str, Any]) -> str:
    lines = [f"{data['count']} node kinds"]
    category = None
    for rec in data["nodes"]:
        if rec["category"] != category:
            category = rec["category"]
            lines += ["", f"{category}"]
        lines.append(f"  {rec['kind']:24s} {rec['title']}")
        lines.append(f"  {'':24s} {rec['description']}")
        m = rec["materialx"]
        mx = "" if not m else f" (MaterialX {m['node']})" if "node" in m else \
            f" (MaterialX recipe {m['recipe']})"
        lines.append(f"  {'':24s}   targets: {' '.join(rec['targets'])}{mx}")
        for p in rec["inputs"]:
            rng = f" in [{p['range'][0]:g}, {p['range'][1]:g}]" if p.get("range") else ""
            default = _fmt_default(p.get("default"))
            lines.append(f"  {'':24s}   in  {p['name']}: {p['type']}"
                         + (f" = {default}" if default else "") + rng)
        for p in rec["outputs"]:
            lines.append(f"  {'':24s}   out {p['name']}: {p['type']}")
    return "\n".join(lines) + "\n"


def register(sub) -> None:
    p = sub.add_parser("nodes", help="list the node catalogue",
                       description="List every node kind: title, category, ports with types, "
                       "defaults and ranges, description, and the targets implemented.")
    p.add_argument("--json", action="store_true", help="print the catalogue as JSON")
    p.add_argument("--category", metavar="NAME", help="only this palette category")
    declare_inputs(p)  # reads only the built-in catalogue, writes stdout
    p.set_defaults(run=run)


def run(args) -> int:
    data = catalogue(args.category)
    if args.category is not None and not data["nodes"]:
        from matedit.graph import nodes

        names = ", ".join(sorted(nodes.categories()))
        raise UsageError(f"no category {args.category!r} (categories: {names})")
    text = json.dumps(data, indent=1, ensure_ascii=False) + "\n" if args.json \
        else format_text(data)
    sys.stdout.write(text)
    return 0
