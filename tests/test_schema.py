"""The published JSON Schema of the document format (matedit/schemas/) and
`matedit.io.schema.check_document_shape`, which reports its findings as FormatError."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator

from matedit.io import document as docio
from matedit.io.document import FormatError
from matedit.io.schema import SCHEMA_DIR, SCHEMA_FILES, _validator, check_document_shape

ROOT = Path(__file__).resolve().parent.parent
SAMPLES = sorted((ROOT / "graphs").rglob("*.json"))
MATERIAL = ROOT / "graphs" / "materials" / "car_paint.json"


def raw(path: Path = MATERIAL) -> dict:
    return json.loads(path.read_text())


def test_samples_exist():
    assert len(SAMPLES) >= 30
    kinds = {raw(p)["format"] for p in SAMPLES}
    assert kinds == set(SCHEMA_FILES)


@pytest.mark.parametrize("name", sorted(p.name for p in SCHEMA_DIR.glob("*.schema.json")))
def test_schema_files_are_valid_draft_2020_12(name):
    schema = json.loads((SCHEMA_DIR / name).read_text())
    Draft202012Validator.check_schema(schema)
    assert schema["$id"].endswith("/" + name)


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_sample_matches_its_schema(path):
    data = raw(path)
    errors = list(_validator(data["format"]).iter_errors(data))
    assert errors == []
    check_document_shape(data, str(path))


@pytest.mark.parametrize("path", SAMPLES[::4], ids=lambda p: p.name)
def test_what_the_saver_writes_matches_the_schema(path):
    from matedit.io import instance

    if instance.is_instance_file(path):
        data = json.loads(instance.dumps(instance.load_instance(path)))
    else:
        data = json.loads(docio.dumps(docio.load(path)))
    assert list(_validator(data["format"]).iter_errors(data)) == []


def test_a_format_is_checked_against_its_own_schema():
    data = raw()
    data["format"] = "matedit.function"
    mat = _validator("matedit.material")
    assert any(e.validator == "const" for e in mat.iter_errors(data))
    check_document_shape(data)  # as a function document it is well formed


def test_unknown_members_are_kept_everywhere():
    """Files from a newer minor version carry members this one does not know."""
    data = raw()
    data["future_top"] = {"x": 1}
    data["nodes"][0]["future_node"] = [1, 2]
    data["links"][0]["future_link"] = True
    data["comments"] = [{"id": "c1", "text": "t", "rect": [0, 0, 1, 1], "color": [0, 0, 0],
                         "future_comment": "x"}]
    data["preview"]["future_preview"] = 3
    check_document_shape(data, "new.json")


def mutated(fn) -> dict:
    data = copy.deepcopy(raw())
    fn(data)
    return data


def node_index(data: dict, nid: str) -> int:
    return next(i for i, n in enumerate(data["nodes"]) if n["id"] == nid)


CASES = [
    # (mutation, node named, field named, words in the message)
    (lambda d: d["nodes"][node_index(d, "flake")].__setitem__("position", [1, "x"]),
     "flake", "position", ["position[1]", "number"]),
    (lambda d: d["nodes"][node_index(d, "flake")].pop("kind"), "flake", "kind", ["required"]),
    (lambda d: d["nodes"][node_index(d, "flake")].__setitem__("settings", []),
     "flake", "settings", ["object"]),
    (lambda d: d["nodes"][node_index(d, "flake")].__setitem__("label", 7),
     "flake", "label", ["string"]),
    (lambda d: d["nodes"][0].__setitem__("id", "a__b"), None, "id", ["nodes[0].id", "a__b"]),
    (lambda d: d["nodes"][0].__setitem__("id", "9lives"), None, "id", ["identifier"]),
    (lambda d: d["nodes"].append(3), None, "nodes[%d]", ["object"]),
    (lambda d: d["links"][0].__setitem__("to", ["a"]), None, "links[0]", ["links[0].to"]),
    (lambda d: d.__setitem__("links", {}), None, "links", ["array"]),
    (lambda d: d.__setitem__("name", 3), None, "name", ["string"]),
    (lambda d: d.pop("version"), None, "version", ["required"]),
    (lambda d: d.__setitem__("version", "2"), None, "version", ["integer"]),
    (lambda d: d.__setitem__("preview", []), None, "preview", ["object"]),
    (lambda d: d.__setitem__("format", "other"), None, "format", ["matedit.material"]),
]


@pytest.mark.parametrize("case", range(len(CASES)))
def test_errors_name_file_node_and_field(case):
    fn, node, field, words = CASES[case]
    data = mutated(fn)
    with pytest.raises(FormatError) as info:
        check_document_shape(data, "broken.json")
    exc = info.value
    if field and "%d" in field:
        field = field % (len(data["nodes"]) - 1)
    assert (exc.file, exc.node, exc.field) == ("broken.json", node, field), str(exc)
    text = str(exc)
    assert text.startswith("broken.json: ")
    for w in words:
        assert w in text


def test_top_level_must_be_an_object():
    with pytest.raises(FormatError, match="JSON object"):
        check_document_shape([1, 2], "list.json")


@pytest.mark.parametrize("case", range(len(CASES)))
def test_schema_and_loader_agree_on_bad_shapes(case):
    """What the schema refuses, today's hand-written loader refuses too (so wiring the
    schema in changes messages, not what loads)."""
    data = mutated(CASES[case][0])
    with pytest.raises(FormatError):
        check_document_shape(data)
    with pytest.raises(FormatError):
        docio.from_dict(data, "broken.json")
