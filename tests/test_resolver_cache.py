"""FileResolver's process-wide cache of function and layer documents: a compile with unchanged
files reads and schema-checks none of them again, whichever resolver asks; a file written
since (new size, mtime or another file renamed over it) is read again."""

from __future__ import annotations

import json
import os
import shutil

import pytest

import matedit.io.document as document
import matedit.io.schema as schema
from matedit.compiler import compile_document
from matedit.io.document import FileResolver, clear_document_cache, load
from matedit.resources import graphs_dir

SAMPLE = "rusty_painted_metal"  # two layers, their blends, a function


@pytest.fixture
def sample(tmp_path):
    """The layered sample with every file it reads, copied (the copies may be changed)."""
    for sub in ("materials", "functions", "layers"):
        shutil.copytree(graphs_dir() / sub, tmp_path / sub)
    clear_document_cache()
    yield tmp_path / "materials" / f"{SAMPLE}.json"
    clear_document_cache()


@pytest.fixture
def reads(monkeypatch):
    """Paths read by document.load, and documents schema-checked, counted."""
    seen = {"read": [], "checked": 0}
    read = document.read_document_text
    check = schema.check_document_shape

    def counting_read(path):
        seen["read"].append(os.path.basename(path))
        return read(path)

    def counting_check(raw, file=None):
        seen["checked"] += 1
        return check(raw, file)

    monkeypatch.setattr(document, "read_document_text", counting_read)
    monkeypatch.setattr(schema, "check_document_shape", counting_check)
    return seen


def _wear_file(sample):
    return sample.parent.parent / "layers" / "rust.json"


def test_a_second_compile_reads_no_unchanged_file(sample, reads):
    doc = load(sample)
    reads["read"].clear()
    reads["checked"] = 0
    first = compile_document(doc, FileResolver())
    assert "rust.json" in reads["read"] and reads["checked"] == len(reads["read"])
    n = len(reads["read"])
    assert n >= 3  # the layers, their blend and the function
    second = compile_document(doc, FileResolver())  # another resolver, as every CLI command
    assert len(reads["read"]) == n and reads["checked"] == n  # nothing read or checked
    assert second.fragment.text == first.fragment.text


def test_a_changed_file_is_read_again(sample, reads):
    doc = load(sample)
    base = compile_document(doc, FileResolver())
    rust = _wear_file(sample)
    raw = json.loads(rust.read_text(encoding="utf-8"))
    text = json.dumps(raw, indent=2)
    # the same document written again, a size and an mtime of its own
    st = rust.stat()
    rust.write_text(text + "\n" * 3, encoding="utf-8")
    os.utime(rust, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    reads["read"].clear()
    again = compile_document(doc, FileResolver())
    assert reads["read"] == ["rust.json"]  # only the changed file
    assert again.fragment.text == base.fragment.text

    # same size, new mtime: read again
    reads["read"].clear()
    st = rust.stat()
    os.utime(rust, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    compile_document(doc, FileResolver())
    assert reads["read"] == ["rust.json"]

    # another file renamed over it, with the size and mtime it had: read again (inode)
    st = rust.stat()
    other = rust.with_name("rust.tmp")
    other.write_bytes(rust.read_bytes())
    os.utime(other, ns=(st.st_atime_ns, st.st_mtime_ns))
    os.replace(other, rust)
    reads["read"].clear()
    compile_document(doc, FileResolver())
    assert reads["read"] == ["rust.json"]


def test_an_edit_that_changes_the_material_is_seen(sample):
    doc = load(sample)
    base = compile_document(doc, FileResolver())
    rust = _wear_file(sample)
    raw = json.loads(rust.read_text(encoding="utf-8"))
    consts = [n for n in raw["nodes"] if isinstance(n.get("values"), dict)
              and any(isinstance(v, float) for v in n["values"].values())]
    assert consts
    nd = consts[0]
    key = next(k for k, v in nd["values"].items() if isinstance(v, float))
    nd["values"][key] = nd["values"][key] + 0.125
    rust.write_text(json.dumps(raw, indent=2), encoding="utf-8")
    edited = compile_document(doc, FileResolver())
    assert edited.fragment.text != base.fragment.text or \
        [u.default for u in edited.ir.uniforms] != [u.default for u in base.ir.uniforms]


def test_a_broken_file_is_never_cached(sample, reads):
    doc = load(sample)
    rust = _wear_file(sample)
    good = rust.read_text(encoding="utf-8")
    rust.write_text('{"format": "matedit.function", "version": 1, "nodes": 3}',
                    encoding="utf-8")
    for _ in range(2):  # refused each time, from a fresh read
        reads["read"].clear()
        with pytest.raises(Exception, match="rust.json"):
            compile_document(doc, FileResolver())
        assert "rust.json" in reads["read"]
    rust.write_text(good, encoding="utf-8")
    compile_document(doc, FileResolver())


def test_a_link_resolves_to_its_target_as_before(sample, reads, tmp_path):
    """The cache is keyed by the real path: a function reached through a symbolic link is
    the file it points at, read once for both names."""
    layers = sample.parent.parent / "layers"
    os.symlink(layers / "rust.json", layers / "rust_link.json")
    r = FileResolver()
    a = r.resolve("../layers/rust.json", load(sample))
    reads["read"].clear()
    b = FileResolver().resolve("../layers/rust_link.json", load(sample))
    assert a is b and reads["read"] == [f"{SAMPLE}.json"]  # only the material, by load()


def test_a_file_rewritten_at_once_with_the_same_size_is_read_again(sample, reads):
    """mtimes are stamped coarsely: a file modified in the last two seconds is not cached, so
    a rewrite of the same size within one tick of the clock is still seen."""
    doc = load(sample)
    rust = _wear_file(sample)
    text = rust.read_text(encoding="utf-8")
    rust.write_text(text, encoding="utf-8")  # modified now
    compile_document(doc, FileResolver())
    reads["read"].clear()
    st = rust.stat()
    rust.write_text(text, encoding="utf-8")
    os.utime(rust, ns=(st.st_atime_ns, st.st_mtime_ns))  # the same size and mtime
    compile_document(doc, FileResolver())
    assert reads["read"] == ["rust.json"]


def test_no_compile_or_validation_changes_a_cached_document(sample):
    """The cache hands every resolver the same document objects: the compiler, validation and
    the input listing must only read them (a change would leak into every later compile)."""
    from matedit.commands.validate import problems
    from matedit.graph.validate import analyse

    doc = load(sample)
    compile_document(doc, FileResolver())
    cached = {p: document.dumps(d) for p, (_, d) in document._documents.items()}
    assert len(cached) >= 3  # the layers, their blends and the function
    for _ in range(2):
        compile_document(doc, FileResolver())
        analyse(doc, FileResolver())
        assert problems(sample, FileResolver()) == []
    assert {p: document.dumps(d) for p, (_, d) in document._documents.items()} == cached


def test_the_library_listing_shares_the_cache_with_compiles(sample, reads):
    """`load_shared` (the Library's reads) fills the cache a compile reads through, for
    function files only; a material is read each time (it is edited, so never shared), and a
    function file changed since is read again."""
    import time

    from matedit.io.document import load_shared

    root = sample.parent.parent
    functions = sorted((root / "functions").glob("*.json")) + \
        sorted((root / "layers").glob("*.json"))
    for path in functions:
        assert load_shared(path).is_function
    material = load_shared(sample)
    assert not material.is_function and load_shared(sample) is not material
    reads["read"].clear()
    compile_document(load(sample), FileResolver())
    assert reads["read"] == [sample.name]  # the material itself; no function read again
    assert load_shared(functions[0]) is load_shared(functions[0])

    rust = _wear_file(sample)
    old = load_shared(rust)
    raw = json.loads(rust.read_text())
    raw["description"] = "changed since the listing"
    rust.write_text(json.dumps(raw))
    past = time.time_ns() - 10 * 10**9  # older than _RACY_NS, so cached again
    os.utime(rust, ns=(past, past))
    reads["read"].clear()
    new = load_shared(rust)
    assert new is not old and new.description == "changed since the listing"
    assert reads["read"] == ["rust.json"]
    assert FileResolver().resolve(str(rust), None) is new
