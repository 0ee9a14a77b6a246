"""JSON format: round trips, migrations, newer versions, atomic saves, relative paths, fuzzing."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from graphs_util import node, simple_material
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from matedit.graph.validate import validate
from matedit.io import document as fmt
from matedit.io.migrations import CURRENT_VERSION, MIGRATIONS, migrate
from matedit.resources import graphs_dir

SAMPLES = sorted(p for p in graphs_dir().rglob("*.json")
                 if p.parent.name != "instances")  # instances: tests/test_instances.py
FUZZ_EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "300"))


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.name)
def test_save_load_save_is_byte_identical(path, tmp_path):
    original = path.read_bytes()
    doc = fmt.load(path)
    again = fmt.dumps(doc).encode()
    assert again == original
    out = tmp_path / path.name
    fmt.save(fmt.loads(again.decode(), path=path), out)


def test_round_trip_preserves_the_model(tmp_path):
    d = simple_material(tmp_path / "m.json")
    fmt.save(d)
    back = fmt.load(tmp_path / "m.json")
    assert back.snapshot() == d.snapshot()


def test_node_order_in_file_does_not_matter(tmp_path):
    d = simple_material()
    raw = fmt.to_dict(d)
    raw["nodes"].reverse()
    raw["links"].reverse()
    assert fmt.dumps(fmt.from_dict(raw)) == fmt.dumps(d)


def test_every_migration_step_is_tested():
    assert sorted(MIGRATIONS) == list(range(1, CURRENT_VERSION))


def test_migrate_v1_links_and_values():
    v1 = {
        "format": "matedit.material", "version": 1,
        "nodes": [{"id": "a", "kind": "scalar_parameter", "pos": [1, 2],
                   "settings": {"name": "a"}},
                  {"id": "m", "kind": "multiply", "params": {"b": 2.0}}],
        "connections": [{"src": "a.value", "dst": "m.a"}],
    }
    v2 = migrate(v1)
    assert v2["version"] == 2
    assert v2["links"] == [{"from": ["a", "value"], "to": ["m", "a"]}]
    assert v2["nodes"][0]["position"] == [1, 2] and v2["nodes"][1]["values"] == {"b": 2.0}
    doc = fmt.from_dict(v1)
    assert doc.graph.incoming("m", "a").src == "a"


def test_migrate_v1_bad_connection_is_a_clear_error():
    with pytest.raises(fmt.FormatError, match=r"connections\[0\]"):
        fmt.from_dict({"format": "matedit.material", "version": 1,
                       "connections": [{"src": "nodot", "dst": "m.a"}]}, "old.json")


def test_newer_version_is_a_clear_error():
    with pytest.raises(fmt.FormatError, match="newer matedit"):
        fmt.from_dict({"format": "matedit.material", "version": CURRENT_VERSION + 1}, "f.json")


@pytest.mark.parametrize("text,needle", [
    ("", "not valid JSON"),
    ("{", "not valid JSON"),
    ("[]", "top level"),
    ('{"format": "png", "version": 2}', "format"),
    ('{"format": "matedit.material", "version": "2"}', "version"),
    ('{"format": "matedit.material", "version": 2, "nodes": [{"id": "a", "kind": "add"},'
     ' {"id": "a", "kind": "add"}]}', "duplicate node id"),
    ('{"format": "matedit.material", "version": 2, "nodes": [{"id": "1a", "kind": "add"}]}',
     "identifier"),
    ('{"format": "matedit.material", "version": 2, "links": [{"from": ["a"]}]}', "links[0]"),
    ('{"format": "matedit.material", "version": 2, "nodes": [{"id": "a", "kind": "add",'
     ' "position": [0, NaN]}]}', "not valid JSON"),
])
def test_malformed_files_give_clear_errors(text, needle):
    with pytest.raises(fmt.FormatError) as info:
        fmt.loads(text, "bad.json")
    assert needle in str(info.value) and "bad.json" in str(info.value)


def test_save_is_atomic_and_keeps_old_file_on_failure(tmp_path, monkeypatch):
    d = simple_material(tmp_path / "m.json")
    fmt.save(d)
    before = (tmp_path / "m.json").read_bytes()

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", boom)
    node(d, "extra", "add")
    with pytest.raises(OSError):
        fmt.save(d)
    assert (tmp_path / "m.json").read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["m.json"]  # no temp file left


def test_save_as_rebases_relative_references(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "a" / "b").mkdir(parents=True)
    d = simple_material(tmp_path / "a" / "m.json")
    node(d, "call", "function_call", {"function": "../lib/f.json"})
    node(d, "tex", "texture_parameter", {"name": "t", "path": "../lib/t.png"})
    fmt.save(d)
    fmt.save(d, tmp_path / "a" / "b" / "m2.json")
    raw = json.loads((tmp_path / "a" / "b" / "m2.json").read_text())
    settings_by_id = {n["id"]: n.get("settings", {}) for n in raw["nodes"]}
    assert settings_by_id["call"]["function"] == "../../lib/f.json"
    assert settings_by_id["tex"]["path"] == "../../lib/t.png"


def test_files_are_sorted_with_two_space_indent(tmp_path):
    d = simple_material(tmp_path / "m.json")
    fmt.save(d)
    text = (tmp_path / "m.json").read_text()
    raw = json.loads(text)
    assert text == json.dumps(raw, sort_keys=True, indent=2, ensure_ascii=False) + "\n"


# --- fuzzing the loader: random and mutated JSON yield documents, or clean errors ------------

_json = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 5) | st.floats(allow_nan=False)
    | st.text(max_size=6),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.text(max_size=8), children, max_size=4),
    max_leaves=20,
)


def _check_loads(raw):
    try:
        doc = fmt.from_dict(raw, "fuzz.json")
    except fmt.FormatError as exc:
        assert str(exc).startswith("fuzz.json")
        return
    validate(doc)  # must produce diagnostics, never raise
    fmt.dumps(doc)


@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_json)
def test_fuzz_random_json(raw):
    _check_loads(raw)


def _mutations():
    base = fmt.to_dict(fmt.load(SAMPLES[0])) if SAMPLES else {}
    keys = ["format", "version", "nodes", "links", "comments", "id", "kind", "settings",
            "values", "position", "from", "to", "type", "name", "function", "layers"]
    return base, keys


@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_fuzz_mutated_sample(data):
    base, keys = _mutations()
    raw = json.loads(json.dumps(base))
    for _ in range(data.draw(st.integers(1, 4))):
        # Walk to a random container and replace or delete something in it.
        target = raw
        for _ in range(data.draw(st.integers(0, 3))):
            if isinstance(target, dict) and target:
                k = data.draw(st.sampled_from(sorted(target)))
                if isinstance(target[k], (dict, list)) and target[k]:
                    target = target[k]
            elif isinstance(target, list) and target:
                i = data.draw(st.integers(0, len(target) - 1))
                if isinstance(target[i], (dict, list)) and target[i]:
                    target = target[i]
        value = data.draw(_json)
        if isinstance(target, dict):
            k = data.draw(st.sampled_from(keys + sorted(target)))
            if data.draw(st.booleans()):
                target.pop(k, None)
            else:
                target[k] = value
        elif isinstance(target, list) and target:
            target[data.draw(st.integers(0, len(target) - 1))] = value
    _check_loads(raw)


def test_load_errors_name_the_file(tmp_path):
    with pytest.raises(fmt.FormatError, match="file not found"):
        fmt.load(tmp_path / "none.json")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(fmt.FormatError, match="UTF-8"):
        fmt.load(tmp_path / "bin.json")
    with pytest.raises(fmt.FormatError, match="directory"):
        fmt.load(tmp_path)


def test_samples_exist():
    kinds = {p.parent.name for p in SAMPLES}
    assert {"functions", "layers", "materials"} <= kinds
    assert Path(graphs_dir()).is_dir()
