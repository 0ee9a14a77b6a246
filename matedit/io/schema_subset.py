"""A check of the few JSON Schema keywords matedit's schemas use, without `jsonschema`.

`matedit validate` on a valid file spent more time importing `jsonschema` (and its
`referencing`, `attrs` and `rpds`) than checking the file. `check_document_shape` first asks
this module whether a document is valid; only when the answer is not a plain yes does it load
the `jsonschema` validator, which decides and words the error. The answer must therefore
never be yes where `jsonschema` says no; it may say no where `jsonschema` says yes (the
library then decides):

- The schemas are read once and every keyword in them must be one this module knows
  (`KNOWN`); a schema with any other keyword turns this check off (`compile_schemas`
  returns None) and every document goes to `jsonschema`.
- Only the plain Python values JSON parses to are judged (dict, list, str, int, float, bool,
  None); any other value (a tuple, a numpy number) is a no, for the library to decide.
- Each keyword follows draft 2020-12 as `jsonschema` implements it: `type` "integer" takes a
  float with an integral value, `pattern` is `re.search`, `minimum` and `required` apply only
  to numbers and objects, `$ref` is `#/...` inside a schema or another schema's file name.

tests/test_schema_subset.py compares the two on every sample and on generated documents.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

# The keywords judged here, and the annotations (no effect on validity) passed over.
ASSERTIONS = frozenset({"type", "required", "properties", "additionalProperties", "enum",
                        "const", "minimum", "pattern", "minLength", "items", "minItems",
                        "maxItems", "allOf", "$ref"})
ANNOTATIONS = frozenset({"$schema", "$id", "$defs", "$comment", "title", "description"})
KNOWN = ASSERTIONS | ANNOTATIONS

_PLAIN = (dict, list, str, int, float, bool, type(None))


def _is_integer(x: Any) -> bool:
    return (type(x) is int) or (type(x) is float and x.is_integer())


_TYPES: dict[str, Callable[[Any], bool]] = {
    "object": lambda x: type(x) is dict,
    "array": lambda x: type(x) is list,
    "string": lambda x: type(x) is str,
    "integer": _is_integer,
    "number": lambda x: type(x) in (int, float),
    "boolean": lambda x: type(x) is bool,
    "null": lambda x: x is None,
}


class _Unsupported(Exception):
    """A schema uses something this module does not judge."""


def _keywords_known(schema: Any) -> None:
    """Raise _Unsupported unless every keyword at every level is known and well formed."""
    stack = [schema]
    while stack:
        s = stack.pop()
        if not isinstance(s, dict):
            raise _Unsupported("a subschema that is not an object")
        unknown = set(s) - KNOWN
        if unknown:
            raise _Unsupported(", ".join(sorted(unknown)))
        if s.get("additionalProperties", True) is not True:
            raise _Unsupported("additionalProperties other than true")
        t = s.get("type")
        if t is not None and t not in _TYPES:
            raise _Unsupported(f"type {t!r}")
        for key in ("enum", "const"):
            values = s.get("enum", []) if key == "enum" else [s["const"]] if key in s else []
            if not all(type(v) is str for v in values):
                raise _Unsupported(f"{key} of values other than strings")
        for key in ("minimum",):
            if key in s and type(s[key]) not in (int, float):
                raise _Unsupported(key)
        for key in ("minLength", "minItems", "maxItems"):
            if key in s and type(s[key]) is not int:
                raise _Unsupported(key)
        if "required" in s and not all(type(k) is str for k in s["required"]):
            raise _Unsupported("required")
        if "pattern" in s:
            re.compile(s["pattern"])
        if "$ref" in s and not isinstance(s["$ref"], str):
            raise _Unsupported("$ref")
        stack.extend(s.get("properties", {}).values())
        stack.extend(s.get("$defs", {}).values())
        stack.extend(s.get("allOf", []))
        if "items" in s:
            stack.append(s["items"])


class SubsetChecker:
    """Says whether a value is valid against schema `root` of `resources` (file name ->
    schema); built by `compile_schemas`."""

    def __init__(self, resources: dict[str, dict], root: str) -> None:
        self._resources, self._root = resources, root

    def _target(self, ref: str, here: str) -> tuple[dict, str]:
        name, _, pointer = ref.partition("#")
        name = name or here
        if name not in self._resources:
            raise _Unsupported(f"$ref {ref!r}")
        node: Any = self._resources[name]
        for part in (p for p in pointer.split("/") if p):
            if not isinstance(node, dict) or part not in node:
                raise _Unsupported(f"$ref {ref!r}")
            node = node[part]
        return node, name

    def is_valid(self, value: Any) -> bool:
        try:
            return self._ok(self._resources[self._root], value, self._root)
        except _Unsupported:
            return False

    def _ok(self, s: dict, x: Any, here: str) -> bool:
        if type(x) not in _PLAIN:
            return False  # not a value JSON parses to: the library decides
        if "type" in s and not _TYPES[s["type"]](x):
            return False
        if "const" in s and not (type(x) is str and x == s["const"]):
            return False
        if "enum" in s and not (type(x) is str and x in s["enum"]):
            return False
        if "$ref" in s:
            target, where = self._target(s["$ref"], here)
            if not self._ok(target, x, where):
                return False
        if not all(self._ok(sub, x, here) for sub in s.get("allOf", ())):
            return False
        kind = type(x)
        if kind in (int, float) and "minimum" in s and x < s["minimum"]:
            return False
        if kind is str:
            if "minLength" in s and len(x) < s["minLength"]:
                return False
            if "pattern" in s and not re.search(s["pattern"], x):
                return False
        if kind is dict:
            if not all(k in x for k in s.get("required", ())):
                return False
            for k, sub in s.get("properties", {}).items():
                if k in x and not self._ok(sub, x[k], here):
                    return False
        if kind is list:
            if "minItems" in s and len(x) < s["minItems"]:
                return False
            if "maxItems" in s and len(x) > s["maxItems"]:
                return False
            if "items" in s and not all(self._ok(s["items"], v, here) for v in x):
                return False
        return True


def compile_schemas(resources: dict[str, dict], root: str) -> SubsetChecker | None:
    """The checker of `root`, or None when a schema uses anything this module does not judge
    (every document then goes to the library)."""
    try:
        for schema in resources.values():
            _keywords_known(schema)
    except (_Unsupported, re.error, TypeError, AttributeError):
        return None
    return SubsetChecker(resources, root)
