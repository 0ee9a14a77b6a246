"""matedit.io.schema_subset, the check that lets a valid document skip `jsonschema`: it must
never call a document valid that the library rejects, and it must call every sample valid
(or the fast path would be dead). Compared with the library on the samples, on hand-made
edge cases of each keyword, and on documents Hypothesis mutates at random."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from matedit.io import schema
from matedit.io.schema_subset import compile_schemas

ROOT = Path(__file__).resolve().parent.parent
SAMPLES = sorted((ROOT / "graphs").rglob("*.json"))


def _both(value) -> tuple[bool, bool]:
    fmt = value.get("format") if isinstance(value, dict) else None
    fmt = fmt if isinstance(fmt, str) and fmt in schema.SCHEMA_FILES else "matedit.material"
    checker = schema._subset_checker(fmt)
    assert checker is not None, "the schemas use a keyword the subset does not judge"
    return checker.is_valid(value), schema._validator(fmt).is_valid(value)


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_sample_is_valid_to_both(path):
    assert _both(json.loads(path.read_text())) == (True, True)


def _doc() -> dict:
    return json.loads((ROOT / "graphs" / "materials" / "car_paint.json").read_text())


EDGES = [
    ("version", 1.0), ("version", 0), ("version", 0.5), ("version", True), ("version", "2"),
    ("version", 2**70), ("format", "matedit.function"), ("name", 3), ("nodes", {}),
    ("nodes", [[]]), ("nodes", [{"id": "a"}]), ("nodes", [{"id": "a", "kind": ""}]),
    ("nodes", [{"id": "a__b", "kind": "k"}]), ("nodes", [{"id": "a" * 65, "kind": "k"}]),
    ("nodes", [{"id": "a" * 64, "kind": "k"}]), ("nodes", [{"id": "a\n", "kind": "k"}]),
    ("nodes", [{"id": "1a", "kind": "k"}]), ("nodes", [{"id": "a", "kind": "k", "muted": 1}]),
    ("nodes", [{"id": "a", "kind": "k", "position": [1, 2, 3]}]),
    ("nodes", [{"id": "a", "kind": "k", "position": [1, True]}]),
    ("nodes", [{"id": "a", "kind": "k", "position": [1.5, -2]}]),
    ("nodes", [{"id": "a", "kind": "k", "settings": []}]),
    ("links", [{"from": ["a", "b"], "to": ["c"]}]), ("links", [{"from": ["a", 1], "to": []}]),
    ("links", [{"from": ["a", "b"], "to": ["c", "d"], "extra": None}]),
    ("comments", [{"id": "c", "color": [1, 2]}]), ("comments", [{"text": "t"}]),
    ("preview", {"mesh": 1}), ("preview", []), ("unknown_member", object()),
    ("nodes", (1, 2)),
]


@pytest.mark.parametrize("key,value", EDGES, ids=lambda v: repr(v)[:40])
def test_edge_cases_never_valid_where_the_library_says_no(key, value):
    d = _doc()
    d[key] = value
    fast, library = _both(d)
    assert not fast or library
    if all(type(v) in (int, float, str, bool, list, dict) for v in (value,)):
        assert fast == library  # plain JSON values: the two agree exactly


def test_missing_required_members():
    for key in ("format", "version"):
        d = _doc()
        del d[key]
        assert _both(d) == (False, False)


def test_an_unknown_keyword_turns_the_subset_off():
    resources = copy.deepcopy(schema._schemas())
    resources["document.schema.json"]["$defs"]["node"]["maxProperties"] = 3
    assert compile_schemas(resources, "material.schema.json") is None
    resources = copy.deepcopy(schema._schemas())
    resources["document.schema.json"]["additionalProperties"] = False
    assert compile_schemas(resources, "material.schema.json") is None


_json = st.recursive(st.none() | st.booleans() | st.integers(-3, 3) | st.floats(-2, 2)
                     | st.sampled_from(["", "a", "a__b", "x1", "1x", "matedit.function"]),
                     lambda inner: st.lists(inner, max_size=4)
                     | st.dictionaries(st.sampled_from(["id", "kind", "from", "to", "x"]),
                                       inner, max_size=3), max_leaves=8)


def _paths(value, prefix=()):
    yield prefix
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _paths(v, (*prefix, i))


SOURCES = [p for p in SAMPLES if p.stat().st_size < 40_000]


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_random_mutations_agree_with_the_library(data):
    doc = json.loads(data.draw(st.sampled_from(SOURCES)).read_text())
    for _ in range(data.draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p]
        path = data.draw(st.sampled_from(paths))
        parent = doc
        for part in path[:-1]:
            parent = parent[part]
        if data.draw(st.booleans()) and isinstance(parent, dict):
            del parent[path[-1]]
        else:
            parent[path[-1]] = data.draw(_json)
    fast, library = _both(doc)
    assert fast == library
