"""MaterialX's own example documents (tests/data/mtlx/examples, Apache-2.0), imported.

Every one imports, or imports with warnings that each name an input the file sets on the
node named (with the value shown as the file has it), or is refused with `error:` lines that
name the node; the tally of the three is docs/materialx.md's section (tests/mtlx_examples.py
writes it, through docs/materialx.py). That every input a surface sets is read or warned
about is tests/test_interop_mtlx_warnings.py's rule, over these files too.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.mtlx_examples import EXAMPLES, HEADING, files, outcomes, section

mx = pytest.importorskip("MaterialX")
DOC = Path(__file__).resolve().parent.parent / "docs" / "materialx.md"
WARNING = re.compile(r"^(?P<file>[^:]+): material (?P<mat>[^:]+): (?P<input>\S+) (?P<value>.+?)"
                     r" of (?P<cat>\w+) (?P<node>\S+) (?P<why>.+); (dropped|approximated)$")


@pytest.fixture(scope="module")
def results():
    return outcomes()


def _load(path: Path):
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(path))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    return doc


def test_the_examples_are_materialx_documents_with_their_licence():
    paths = files()
    assert 15 <= len(paths) <= 30
    assert "Apache License" in (EXAMPLES / "LICENSE").read_text(encoding="utf-8")
    readme = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    assert "MaterialX" in readme and "Apache License 2.0" in readme
    assert "resources/Materials/Examples" in readme
    surfaces = set()
    for p in paths:
        doc = _load(p)
        ok, msg = doc.validate()
        assert ok, f"{p.name}: {msg}"
        for m in doc.getMaterialNodes():
            surfaces.add(doc.getNode(m.getInput("surfaceshader").getNodeName()).getCategory())
    assert surfaces == {"standard_surface", "open_pbr_surface", "gltf_pbr",
                        "UsdPreviewSurface"}


def test_each_example_imports_or_is_refused_by_name(results):
    from matedit.interop.mtlx_import import value_text

    assert [r.name for r in results] == [p.name for p in files()]
    for r in results:
        doc = _load(EXAMPLES / r.name)
        for e in r.errors:
            assert e.startswith(f"{r.name}: node "), e
        for w in r.warnings:
            m = WARNING.match(w)
            assert m and m["file"] == r.name, w
            el = doc.getDescendant(m["node"])
            assert el is not None and el.getCategory() == m["cat"], w
            inp = el.getInput(m["input"])
            assert inp is not None, f"{w}: the node sets no such input"
            assert m["value"] == value_text(inp), w
    imported = [r for r in results if r.status != "refused"]
    assert len(imported) >= 0.8 * len(results)  # the texture nodes real files use import
    assert any(r.status == "warnings" for r in results)


def test_the_tiled_and_gltf_texture_examples_import(results):
    """The documents the texture nodes were refused in before (tiledimage, gltf_image,
    gltf_colorimage, gltf_normalmap, rgbtohsv, hextiledimage) import now."""
    by = {r.name: r for r in results}
    for name in ("standard_surface_brass_tiled.mtlx", "standard_surface_wood_tiled.mtlx",
                 "usd_preview_surface_brass_tiled.mtlx", "gltf_pbr_boombox.mtlx",
                 "standard_surface_brick_procedural.mtlx",
                 "standard_surface_onyx_hextiled.mtlx"):
        assert by[name].status != "refused", (name, by[name].errors)


def test_the_docs_tally_is_what_the_import_does(results):
    text = DOC.read_text(encoding="utf-8")
    assert HEADING in text, "docs/materialx.md has no import tally: run docs/materialx.py"
    got = text[text.index(HEADING):]
    measured = got.find("\n## Round trip\n")  # tools/roundtrip_table.py's section follows
    got = got[:measured] if measured >= 0 else got
    assert got == section(results), "docs/materialx.md's tally is stale: run docs/materialx.py"
