"""`matedit nodes [--json]`: the catalogue as text and as JSON that validates against its
schema and says the same as the registry."""

from __future__ import annotations

import json
import subprocess
import sys

import jsonschema
import pytest

from matedit.commands.nodes import SCHEMA, catalogue, format_text
from matedit.compiler.cpu_nodes import COMPILER_HANDLED, IMPLS
from matedit.graph.nodes import REGISTRY, MxNode, MxRecipe
from matedit.resources import shaders_dir
from tests.library_kinds import LIBRARY_KINDS


def run(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


@pytest.fixture(scope="module")
def printed():
    r = run("nodes", "--json")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_json_validates_against_the_schema(printed):
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    jsonschema.validate(printed, SCHEMA)
    assert printed == json.loads(json.dumps(catalogue()))


def test_schema_rejects_a_record_missing_its_ports(printed):
    broken = json.loads(json.dumps(printed))
    del broken["nodes"][0]["inputs"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, SCHEMA)


def test_json_says_what_the_registry_says(printed):
    by_kind = {r["kind"]: r for r in printed["nodes"]}
    assert printed["count"] == len(REGISTRY) == len(by_kind) >= 120
    for kind, d in REGISTRY.items():
        r = by_kind[kind]
        assert (r["title"], r["category"], r["description"]) == (d.title, d.category,
                                                                 d.description)
        assert [(p["name"], p["type"]) for p in r["inputs"]] == [(i.name, i.type)
                                                                 for i in d.inputs]
        assert [(p["name"], p["type"]) for p in r["outputs"]] == [(o.name, o.type)
                                                                  for o in d.outputs]
        for p, i in zip(r["inputs"], d.inputs):
            assert p["range"] == (list(i.range) if i.range else None)
            assert p["default"] == i.default
        assert {"glsl330", "glsl450", "essl300", "numpy"} <= set(r["targets"]), kind
        assert ("materialx" in r["targets"]) == isinstance(d.mtlx, (MxNode, MxRecipe))
        impl = r["implementation"]
        if impl["glsl"] == "function":
            assert (shaders_dir() / "nodes" / f"{kind}.glsl").is_file()
        assert (impl["numpy"] == "function") == (kind in IMPLS)
        assert impl["numpy"] == "function" or kind in COMPILER_HANDLED


def test_every_library_kind_has_a_description_and_ranged_numbers(printed):
    by_kind = {r["kind"]: r for r in printed["nodes"]}
    for kind in LIBRARY_KINDS:
        r = by_kind[kind]
        assert len(r["description"]) >= 5, kind
        for p in r["inputs"]:
            # every scalar knob an artist drags has a range (colours and vectors need none)
            if p["type"] == "float" and p["default"] is not None:
                assert p["range"] is not None or p["name"] in (
                    "a", "b", "edge", "edge0", "edge1", "value", "height"), (kind, p["name"])


def test_materialx_mappings_name_stdlib_nodes(printed):
    mapped = [r for r in printed["nodes"] if r["materialx"]]
    assert len(mapped) >= 30
    for r in mapped:
        names = {p["name"] for p in r["inputs"]}
        assert set(r["materialx"]["inputs"]) <= names, r["kind"]


def test_text_lists_every_kind_by_category():
    r = run("nodes")
    assert r.returncode == 0
    assert r.stdout == format_text(catalogue())
    for kind in REGISTRY:
        assert f"  {kind} " in r.stdout
    assert r.stdout.splitlines()[0] == f"{len(REGISTRY)} node kinds"


def test_category_filter_and_unknown_category():
    noise = catalogue("noise")
    assert noise["count"] >= 9 and all(r["category"] == "Noise" for r in noise["nodes"])
    r = run("nodes", "--category", "nope")
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("error: no category 'nope'")
