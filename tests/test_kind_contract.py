"""One contract per node kind, in data (issue 15): code outside the catalogue never names a
kind; it asks the definition (roles, flags, MaterialX mapping).

The grep test parses every module of matedit/ (not the catalogue, the category modules of
matedit/nodes/) and fails on any string constant equal to a registered kind. A kind's numpy
twin and MaterialX recipe are referenced from its definition, so nothing outside the
catalogue binds a kind by name. What it allows, and why:
  - in the MaterialX modules (interop/mtlx_*.py), strings that are MaterialX stdlib node
    categories ("add", "normalize", "time"...): MaterialX's names, not ours, read from
    MaterialX's own libraries;
  - ALLOWED: a few words that are kind names by coincidence (an icon, a light's field, a
    JSON key), each listed with its reason; an entry no longer needed fails the test.
Pieces of f-strings are not whole strings and are not checked.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import matedit
from matedit.graph import nodes
from matedit.graph.nodes import (
    BAKE,
    LOWERED,
    MxNode,
    MxRecipe,
    NodeDef,
    OutputDef,
    Role,
    Thumbnail,
)

PACKAGE = Path(matedit.__file__).parent
CATALOGUE = "nodes/"  # matedit/nodes/*.py
MATERIALX_MODULES = {"interop/mtlx_export.py", "interop/mtlx_import.py",
                     "interop/mtlx_map.py"}
ALLOWED = {
    ("app/layers_panel.py", "add"): "icon name",
    ("app/lights_panel.py", "add"): "icon name",
    ("app/canvas/actions.py", "add"): "icon name",
    ("app/lights_panel.py", "length"): "a tube light's length field",
    ("io/rig.py", "length"): "a tube light's length field in the rig file",
    ("app/recovery.py", "time"): "the recovery file's timestamp key",
}


def _strings(tree: ast.AST):
    """(string constant node, enclosing call's function name or None), skipping f-strings."""
    skip: set[int] = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.JoinedStr):
            skip.update(id(v) for v in ast.walk(n))
    calls: dict[int, str] = {}
    for n in ast.walk(tree):
        if isinstance(n, ast.Call):
            f = n.func
            name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(
                f, ast.Attribute) else None
            for a in n.args:
                calls[id(a)] = name
    for n in ast.walk(tree):
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in skip:
            yield n, calls.get(id(n))


def _hits(rel: str, text: str, allowed_extra: frozenset[str] = frozenset()):
    kinds = set(nodes.REGISTRY)
    return [(rel, n.lineno, n.value) for n, _ in _strings(ast.parse(text))
            if n.value in kinds and n.value not in allowed_extra]


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if not rel.startswith(CATALOGUE):
            yield rel, path.read_text(encoding="utf-8")


def test_no_kind_names_outside_the_catalogue():
    found, used = [], set()
    for rel, text in _modules():
        if rel in MATERIALX_MODULES:
            continue  # test_materialx_modules_name_only_materialx_nodes
        for h in _hits(rel, text):
            if (rel, h[2]) in ALLOWED:
                used.add((rel, h[2]))
            else:
                found.append(h)
    assert not found, "kind names outside the catalogue (ask nodes.definition / role_of / " \
        f"kind_for instead): {found}"
    assert used == set(ALLOWED), f"allow-list entries no longer needed: {set(ALLOWED) - used}"


def test_every_kind_the_compiler_does_not_lower_has_its_numpy_twin():
    from matedit.compiler.cpu_nodes import COMPILER_HANDLED, IMPLS

    # the twin is the definition's; IMPLS is the registry's view of them
    assert set(IMPLS) == set(nodes.REGISTRY) - COMPILER_HANDLED
    for kind, d in nodes.REGISTRY.items():
        assert (d.numpy is None) == d.lowered, kind
        if d.numpy is not None:
            assert IMPLS[kind] is d.numpy
    twinless = NodeDef("test_twinless", "Twinless", "Math", "No numpy twin.",
                       outputs=(OutputDef("value", "float"),), glsl="node_test_twinless")
    with pytest.raises(ValueError, match="test_twinless.*numpy"):
        nodes.register(twinless)
    assert "test_twinless" not in nodes.REGISTRY


def test_materialx_modules_name_only_materialx_nodes():
    mx = pytest.importorskip("MaterialX")
    from matedit.interop.mtlx_colorspace import stdlib

    categories = frozenset(nd.getNodeString() for nd in stdlib().getNodeDefs())
    assert {"add", "normalize", "image"} <= categories  # the libraries did load
    found = []
    for rel, text in _modules():
        if rel in MATERIALX_MODULES:
            found += _hits(rel, text, categories)
    assert not found, f"kind names in the MaterialX modules: {found}"
    del mx


def test_the_grep_finds_a_kind_name():
    """The scanner itself: a comparison with a kind name, in any module, is found."""
    src = 'def f(node):\n    return node.kind == "layer_stack" or f"{node}texcoord"\n'
    assert _hits("app/example.py", src) == [("app/example.py", 2, "layer_stack")]


# --- the contract's data ---------------------------------------------------------------------

def test_every_role_names_one_kind_and_back():
    for role in Role:
        kind = nodes.kind_for(role)
        assert nodes.role_of(kind) == role
    assert nodes.role_of("no such kind") is None
    with pytest.raises(KeyError, match="no such kind"):
        nodes.definition("no such kind")


def test_lowered_kinds_have_no_glsl_and_others_exactly_one():
    for kind, d in nodes.REGISTRY.items():
        if d.lowered:  # the compiler lowers it: no template that is never emitted
            assert d.glsl is None and d.inline is None, kind
        else:
            assert (d.glsl is None) != (d.inline is None), kind


def test_materialx_mapping_is_the_catalogue():
    from matedit.interop import mtlx_map

    for kind, d in nodes.REGISTRY.items():
        assert isinstance(d.mtlx, (MxNode, MxRecipe)) or d.mtlx in (BAKE, LOWERED), kind
        assert mtlx_map.mapping(kind) is d.mtlx
        # a lowered kind never reaches the exporter: the compiler handles it
        assert (d.mtlx == LOWERED) <= d.lowered, kind
        if isinstance(d.mtlx, MxNode):
            names = {i.name for i in d.inputs}
            assert {ours for ours, _ in d.mtlx.ports} <= names, kind
    for category, (kind, ports) in mtlx_map.direct().items():
        assert set(ports.values()) <= {i.name for i in nodes.definition(kind).inputs}
        d = nodes.definition(kind)
        if d.mtlx_reads is not None and d.mtlx_reads.category == category:
            continue  # read back from the stdlib node, exported by a recipe
        assert mtlx_map.kind_mapped_to(category) == kind, category
    assert mtlx_map.mapping("no such kind") == BAKE


def test_parameters_and_flags():
    from matedit.io.instance import TYPE_OF_KIND, TYPES

    assert set(TYPE_OF_KIND.values()) == set(TYPES)
    for kind in nodes.PARAMETER_KINDS:
        assert nodes.is_parameter(kind)
        assert nodes.definition(kind).setting("name") is not None, kind
    assert not nodes.is_value_parameter(nodes.kind_for(Role.STATIC_SWITCH))
    assert nodes.is_value_parameter(nodes.kind_for(Role.TEXTURE_PARAMETER))
    # geometry readers are never folded; the output node never shows a thumbnail
    for kind, d in nodes.REGISTRY.items():
        assert d.impure or not d.geometry, kind
    out = nodes.definition(nodes.kind_for(Role.MATERIAL_OUTPUT))
    assert out.thumbnail == Thumbnail.NEVER


def test_the_materialx_doc_matches_the_catalogue():
    """docs/materialx.md is what docs/materialx.py writes from the catalogue today."""
    from matedit.interop import mtlx_map

    doc = Path(__file__).resolve().parent.parent / "docs" / "materialx.md"
    text = doc.read_text(encoding="utf-8")
    measured = text.find("\n## Round trip\n")  # tools/roundtrip_table.py's, kept at the end
    generated = text[:measured] if measured >= 0 else text
    # then the import tally (tests/test_interop_mtlx_examples.py checks it)
    assert generated.startswith(mtlx_map.document() + "\n## "), \
        "docs/materialx.md is stale: run docs/materialx.py"
    for kind in mtlx_map.mapped_kinds() + mtlx_map.baked_kinds() + mtlx_map.lowered_kinds():
        assert f"`{kind}`" in text
    assert len(mtlx_map.mapped_kinds() + mtlx_map.baked_kinds()
               + mtlx_map.lowered_kinds()) == len(nodes.REGISTRY)


def test_a_new_geometry_kind_is_its_definition_and_its_numpy_twin(monkeypatch):
    """A kind added to the catalogue (its definition, carrying its numpy twin) compiles,
    evaluates, keeps its op (impure: never folded), shows thumbnails when selected and bakes
    for MaterialX, with no other code touched."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.compiler.cpu_eval import evaluate
    from matedit.compiler.cpu_nodes import SurfaceArrays
    from matedit.graph.nodes import InputDef
    from matedit.interop import mtlx_map
    from tests.graphs_util import link, material, node

    kind = "test_height_above"
    d = NodeDef(kind, "Height Above", "Coordinates", "World height plus an offset.",
                inputs=(InputDef("offset", "float", 0.0),),
                outputs=(OutputDef("value", "float"),), glsl=f"node_{kind}",
                impure=True, geometry=True,
                numpy=lambda ctx, offset: (ctx.position[:, 1] + offset,))
    monkeypatch.setitem(nodes.REGISTRY, kind, d)
    doc = material()
    node(doc, "h", kind, values={"offset": 0.25})
    node(doc, "make", nodes.kind_for(Role.MAKE_ATTRIBUTES))
    node(doc, "out", nodes.kind_for(Role.MATERIAL_OUTPUT))
    link(doc, "h", "value", "make", "roughness")
    link(doc, "make", "attributes", "out", "attributes")
    ir = lower_and_optimise(doc, None)
    assert [op.kind for op in ir.main.ops].count(kind) == 1
    y = np.array([0.0, 0.1, 0.5])
    pos = np.stack([np.zeros(3), y, np.zeros(3)], axis=1)
    surface = SurfaceArrays(np.zeros((3, 2)), pos, np.tile([0.0, 0.0, 1.0], (3, 1)),
                            np.tile([0.0, 0.0, 1.0], (3, 1)))
    got = evaluate(ir, surface)["roughness"]
    np.testing.assert_allclose(got, y + 0.25, atol=1e-12)  # exact: one addition
    assert nodes.definition(kind).thumbnail == Thumbnail.SELECTED
    assert mtlx_map.mapping(kind) == BAKE


def _one_node_material(kind: str):
    from tests.graphs_util import link, material, node

    doc = material()
    node(doc, "n", kind, values={"value": 0.25})
    node(doc, "make", nodes.kind_for(Role.MAKE_ATTRIBUTES))
    node(doc, "out", nodes.kind_for(Role.MATERIAL_OUTPUT))
    link(doc, "n", "result", "make", "roughness")
    link(doc, "make", "attributes", "out", "attributes")
    return doc


def _kind_with(kind: str, mtlx) -> NodeDef:
    from matedit.graph.nodes import InputDef

    return NodeDef(kind, "Test", "Math", "A kind the catalogue does not hold.",
                   inputs=(InputDef("value", "float", 0.0),),
                   outputs=(OutputDef("result", "float"),), inline="(2.0 * {value})",
                   mtlx=mtlx, numpy=lambda ctx, value: (2.0 * value,))


def test_a_new_kind_exports_by_the_recipe_its_definition_carries(monkeypatch, tmp_path):
    """A kind's MaterialX recipe is written beside it, through the builder the exporter
    passes in: the exporter needs no code for it."""
    pytest.importorskip("MaterialX")
    from matedit.interop import mtlx_export

    def doubled(b):
        return [lambda: b.node("multiply", None, "", ("in1", b.arg("value")),
                               ("in2", b.value(2.0)))]

    kind = "test_doubled"
    monkeypatch.setitem(nodes.REGISTRY, kind, _kind_with(kind, MxRecipe("doubled", doubled)))
    result = mtlx_export.export(_one_node_material(kind), None, tmp_path / "d.mtlx", size=8)
    assert '<multiply name="n" type="float">' in result.text
    assert not result.baked
    ok, why = mtlx_export.validate(result.text)
    assert ok, why


def test_a_kind_with_no_mapping_the_exporter_can_write_is_refused_by_name(monkeypatch, tmp_path):
    """No default recipe: a recipe with no build (and none of the exporter's own) is an
    error that names the kind, not an export as something else."""
    pytest.importorskip("MaterialX")
    from matedit.interop import mtlx_export

    kind = "test_unmapped"
    monkeypatch.setitem(nodes.REGISTRY, kind, _kind_with(kind, MxRecipe("no_such_recipe")))
    with pytest.raises(mtlx_export.MtlxExportError,
                       match=r"node n: node kind 'test_unmapped' has no MaterialX mapping"):
        mtlx_export.export(_one_node_material(kind), None, tmp_path / "u.mtlx", size=8)
