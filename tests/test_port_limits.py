"""Hard bounds of a port (Port.limits): a value beyond them is a warning naming the node and
the field (the material still compiles), and the Inspector clamps what an artist types,
saying so in the status bar and showing the bound it took."""

from __future__ import annotations

import pytest
from graphs_util import EDITOR_SAMPLE, link, material, node
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.graph import nodes
from matedit.graph.validate import Severity, validate


def _port(kind: str, name: str):
    return next(p for p in nodes.definition(kind).inputs if p.name == name)


def test_the_bound_and_the_clamped_value_are_named():
    octaves = _port("fbm", "octaves")
    assert octaves.limits == (1.0, 8.0)
    why, fixed = nodes.limit_problem(octaves, -5.0)
    assert fixed == 1.0
    assert why == "octaves -5 is out of bounds: it must be at least 1 and at most 8"
    assert nodes.limit_problem(octaves, 3.5) is None
    assert nodes.limit_problem(octaves, 8.0) is None
    ior = next(f for f in nodes.ATTRIBUTE_FIELDS if f.name == "ior")
    assert nodes.limit_problem(ior, 0.5) == ("ior 0.5 is out of bounds: it must be at least 1",
                                             1.0)
    colour = next(f for f in nodes.ATTRIBUTE_FIELDS if f.name == "baseColor")
    why, fixed = nodes.limit_problem(colour, [0.5, -0.2, 2.0])
    assert fixed == [0.5, 0.0, 2.0] and "(0.5, -0.2, 2)" in why  # no upper bound on colour
    assert nodes.limit_problem(_port("fbm", "scale"), -1e9) is None  # a port without bounds


def test_a_file_value_out_of_bounds_is_a_warning_on_its_node_and_field():
    d = material()
    node(d, "n", "fbm", values={"octaves": -5.0})
    node(d, "make", "make_attributes", values={"metallic": 1.7})
    node(d, "out", "material_output")
    link(d, "n", "value", "make", "roughness")
    link(d, "make", "attributes", "out", "attributes")
    diags = validate(d)
    assert not [x for x in diags if x.severity == Severity.ERROR], [x.format() for x in diags]
    got = {(x.node_id, x.port): x.message for x in diags if x.severity == Severity.WARNING}
    assert got[("n", "octaves")].startswith("octaves -5 is out of bounds")
    assert got[("make", "metallic")] == "metallic 1.7 is out of bounds: it must be at least 0 " \
        "and at most 1"


def test_the_inspector_clamps_a_typed_value_visibly(qtbot):
    w = make_window(qtbot, EDITOR_SAMPLE)
    graph = w.controller.document.graph
    nid = next(n for n, x in sorted(graph.nodes.items()) if x.kind == "value_noise")
    assert _port("value_noise", "octaves").limits == (1.0, 6.0)
    w.inspector.show_node(nid)
    field = w.inspector._fields[("value", "octaves")]
    messages = []
    w.inspector.message.connect(messages.append)
    field.spin.setValue(-5.0)  # typed
    settle(qtbot, w, 20)
    assert graph.nodes[nid].values["octaves"] == 1.0
    assert messages and messages[-1] == \
        f"{nid}: octaves -5 is out of bounds: it must be at least 1 and at most 6; set to 1"
    assert w.inspector._fields[("value", "octaves")].value() == pytest.approx(1.0)
    field = w.inspector._fields[("value", "octaves")]
    field.spin.setValue(5.0)  # within bounds: taken as typed, nothing said
    settle(qtbot, w, 20)
    assert graph.nodes[nid].values["octaves"] == 5.0 and len(messages) == 1
