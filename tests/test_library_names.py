"""The built-in library: stable `library:` names in documents outside it, and read-only."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from test_app_support import app_env, make_window  # noqa: F401 - fixture

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.io import library
from matedit.io.document import FileResolver, load, reference_fields, save
from matedit.io.instance import load_instance, resolve, save_instance
from matedit.nodes.twin import sphere_surface
from matedit.resources import graphs_dir

SURFACE, _ = sphere_surface(16)
SAMPLE = graphs_dir() / "materials" / "mossy_stone.json"  # a layer stack of library layers


def _refs(doc) -> list[str]:
    return [c[k] for c, k in reference_fields(doc)]


def _layer_refs(doc) -> list[str]:
    return [e["function"] for n in doc.graph.nodes.values() if n.kind == "layer_stack"
            for e in n.settings["layers"]]


def test_a_copy_of_a_sample_names_the_library_and_draws_the_same(tmp_path):
    original = load(SAMPLE)
    assert _refs(original) and all(r.startswith("../") for r in _refs(original))
    want = evaluate(lower_document(original, FileResolver()), SURFACE)
    copy = load(SAMPLE)
    (tmp_path / "deep").mkdir()
    save(copy, tmp_path / "deep" / "my_stone.json")
    raw = json.loads((tmp_path / "deep" / "my_stone.json").read_text())
    refs = [e["function"] for n in raw["nodes"] if n["kind"] == "layer_stack"
            for e in n["settings"]["layers"]]
    assert refs and all(r.startswith("library:layers/") for r in refs), refs
    assert str(graphs_dir()) not in json.dumps(raw) and "/.." not in json.dumps(raw)
    again = load(tmp_path / "deep" / "my_stone.json")
    got = evaluate(lower_document(again, FileResolver()), SURFACE)
    for f in ("baseColor", "roughness", "normal"):
        np.testing.assert_array_equal(got[f], want[f], err_msg=f)
    # moved again, elsewhere: library names stay as they are
    save(again, tmp_path / "elsewhere.json")
    assert _refs(load(tmp_path / "elsewhere.json")) == _refs(again)


def test_a_path_into_the_install_migrates_to_the_library_name_on_save(tmp_path):
    doc = load(SAMPLE)
    save(doc, tmp_path / "stone.json")
    raw = json.loads((tmp_path / "stone.json").read_text())
    install_rel = os.path.relpath(graphs_dir() / "layers", tmp_path)  # the old form
    for n in raw["nodes"]:
        for e in n.get("settings", {}).get("layers", []):
            e["function"] = e["function"].replace("library:layers", install_rel)
    (tmp_path / "stone.json").write_text(json.dumps(raw))
    old = load(tmp_path / "stone.json")
    assert _layer_refs(old) and all(r.startswith("..") for r in _layer_refs(old))
    lower_document(old, FileResolver())  # the old form still resolves
    save(old)  # a plain save, same folder
    assert all(r.startswith("library:layers/")
               for r in _layer_refs(load(tmp_path / "stone.json")))


def test_an_instance_copied_out_names_its_parent_in_the_library(tmp_path):
    src = graphs_dir() / "instances" / "worn_paint_red.json"
    inst = load_instance(src)
    save_instance(inst, tmp_path / "red.json")
    copy = load_instance(tmp_path / "red.json")
    assert copy.parent == "library:materials/worn_painted_steel.json"
    assert resolve(copy).material is not None


@pytest.mark.parametrize("name", ["library:", "library:../materials/x.json",
                                  "library:/etc/passwd", "library:layers\\gold.json",
                                  "library:./layers/gold.json", "library:a/../../x.json"])
def test_names_that_leave_the_library_are_refused(name):
    with pytest.raises(ValueError, match="library"):
        library.library_path(name)
    assert library.library_path("library:layers/gold.json") == \
        graphs_dir().resolve() / "layers" / "gold.json"


def test_a_link_planted_in_the_library_cannot_lead_out_of_it(tmp_path, monkeypatch):
    lib = tmp_path / "graphs"
    (lib / "layers").mkdir(parents=True)
    outside = tmp_path / "secret.json"
    outside.write_text("{}")
    (lib / "layers" / "trap.json").symlink_to(outside)
    monkeypatch.setattr(library, "graphs_dir", lambda: lib)
    with pytest.raises(ValueError, match="out of the library"):
        library.library_path("library:layers/trap.json")
    resolver = FileResolver()
    with pytest.raises(LookupError):
        resolver.resolve("library:layers/trap.json", None)


def test_shipped_samples_are_saved_as_copies_never_into_the_library(
        qtbot, tmp_path, monkeypatch):
    from matedit.app import document_actions

    monkeypatch.setattr(document_actions, "user_documents_dir", lambda: tmp_path)
    before = SAMPLE.read_bytes()
    w = make_window(qtbot, SAMPLE)
    asked: list[str] = []
    answer = {"path": str(SAMPLE)}  # first: the artist insists on the shipped file
    w.actions.ask_save_path = lambda suggestion: asked.append(suggestion) or answer["path"]
    w.controller.document.description = "edited"
    assert not w.actions.save()  # Ctrl+S on a shipped file asks where; there: refused
    assert asked == [str(tmp_path / SAMPLE.name)]
    assert w.shown_errors and "read-only" in w.shown_errors[-1][0]
    assert SAMPLE.read_bytes() == before
    answer["path"] = str(tmp_path / SAMPLE.name)
    assert w.actions.save()  # the suggested copy
    assert SAMPLE.read_bytes() == before
    saved = load(tmp_path / SAMPLE.name)
    assert all(r.startswith("library:") for r in _layer_refs(saved))
    asked.clear()
    assert w.actions.save() and asked == []  # the copy is the artist's: saved in place
