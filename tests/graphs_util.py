"""Small builders for graphs in tests."""

from __future__ import annotations

from pathlib import Path

from matedit.graph.model import DocumentKind, Link, MaterialDocument, Node


def node(doc: MaterialDocument, nid: str, kind: str, settings=None, values=None, pos=(0.0, 0.0)):
    doc.graph.nodes[nid] = Node(nid, kind, pos, dict(settings or {}), dict(values or {}))
    return doc.graph.nodes[nid]


def link(doc: MaterialDocument, a: str, ap: str, b: str, bp: str) -> Link:
    l = Link(a, ap, b, bp)
    doc.graph.links.add(l)
    return l


def material(path: Path | None = None) -> MaterialDocument:
    return MaterialDocument(kind=DocumentKind.MATERIAL, path=path)


def function(path: Path | None = None) -> MaterialDocument:
    return MaterialDocument(kind=DocumentKind.FUNCTION, path=path)


def simple_material(path: Path | None = None) -> MaterialDocument:
    """color parameter -> make_attributes -> material_output, with a roughness multiply."""
    d = material(path)
    node(d, "col", "color_parameter", {"name": "tint"}, {"value": [0.8, 0.2, 0.1]})
    node(d, "r", "scalar_parameter", {"name": "rough"}, {"value": 0.4})
    node(d, "m", "multiply", values={"b": 0.5})
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "col", "color", "make", "baseColor")
    link(d, "r", "value", "m", "a")
    link(d, "m", "result", "make", "roughness")
    link(d, "make", "attributes", "out", "attributes")
    return d


# The editor's GUI tests drive a layered material node by node (its `mask_noise`, `hi`, the
# `uv` function call...). They use this frozen copy, so the shipped samples can keep getting
# better without breaking them: the sample material as the tests were written against it,
# with the layers and functions it calls.
EDITOR_GRAPHS = Path(__file__).resolve().parent / "data" / "editor_graphs"
EDITOR_SAMPLE = EDITOR_GRAPHS / "materials" / "rusty_painted_metal.json"
