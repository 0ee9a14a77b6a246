"""Model edits through commands: apply/revert, events, layer stack."""

from __future__ import annotations

import pytest
from graphs_util import function, link, node, simple_material
from hypothesis import given, settings
from hypothesis import strategies as st

from matedit.graph.commands import (
    AddNode,
    CommandError,
    Connect,
    Disconnect,
    Macro,
    MoveNodes,
    PutComment,
    RemoveNode,
    SetSetting,
    SetValue,
)
from matedit.graph.layers import Layer, LayerStack
from matedit.graph.model import ChangeKind, Comment, Link, Node
from matedit.graph.validate import validate
from matedit.io.document import FileResolver, save


def test_value_edit_emits_value_event_and_reverts():
    d = simple_material()
    events = []
    d.graph.subscribe(events.append)
    cmd = SetValue("r", "value", 0.9)
    cmd.apply(d.graph)
    assert d.graph.nodes["r"].values["value"] == 0.9
    assert [e.kind for e in events] == [ChangeKind.VALUE]
    cmd.revert(d.graph)
    assert d.graph.nodes["r"].values["value"] == 0.4


def test_structural_edits_emit_structural_events():
    d = simple_material()
    events = []
    d.graph.subscribe(events.append)
    AddNode(Node("k", "constant", settings={"type": "float", "value": 2.0})).apply(d.graph)
    Connect(Link("k", "value", "m", "b")).apply(d.graph)
    assert {e.kind for e in events} == {ChangeKind.STRUCTURAL}
    events.clear()
    MoveNodes({"k": (10.0, 20.0)}).apply(d.graph)
    assert [e.kind for e in events] == [ChangeKind.LAYOUT]


def test_texture_path_setting_is_a_value_edit():
    d = simple_material()
    node(d, "tex", "texture_parameter", {"name": "albedo", "path": "a.png"})
    cmd = SetSetting("tex", "path", "b.png")
    cmd.apply(d.graph)
    assert cmd.kind == ChangeKind.VALUE
    cmd2 = SetSetting("m", "nothing", 1)
    cmd2.apply(d.graph)
    assert cmd2.kind == ChangeKind.STRUCTURAL


def test_connect_replaces_existing_link_and_revert_restores_it():
    d = simple_material()
    node(d, "k", "constant", {"type": "float", "value": 0.2})
    before = d.graph.snapshot()
    cmd = Connect(Link("k", "value", "m", "a"))
    cmd.apply(d.graph)
    assert d.graph.incoming("m", "a").src == "k"
    cmd.revert(d.graph)
    assert d.graph.snapshot() == before


def test_remove_node_restores_links_on_revert():
    d = simple_material()
    before = d.graph.snapshot()
    cmd = RemoveNode("make")
    cmd.apply(d.graph)
    assert "make" not in d.graph.nodes and not d.graph.links_of("make")
    cmd.revert(d.graph)
    assert d.graph.snapshot() == before


def test_failed_macro_rolls_back():
    d = simple_material()
    before = d.graph.snapshot()
    bad = Macro([SetValue("r", "value", 0.1), RemoveNode("missing")])
    with pytest.raises(CommandError):
        bad.apply(d.graph)
    assert d.graph.snapshot() == before


def test_new_ids_come_from_a_counter():
    d = simple_material()
    assert d.graph.new_id("m") == "m1"
    node(d, "m1", "add")
    assert d.graph.new_id("m") == "m2"


# --- property test: random command sequences, reverted, restore the document ---------------

def _random_command(draw, graph):
    ids = sorted(graph.nodes)
    choice = draw(st.integers(0, 7))
    if choice == 0 or not ids:
        nid = graph.new_id("h")
        kind = draw(st.sampled_from(["add", "multiply", "constant", "lerp", "scalar_parameter"]))
        return AddNode(Node(nid, kind, (draw(st.floats(-500, 500)), 0.0)))
    nid = draw(st.sampled_from(ids))
    if choice == 1:
        return RemoveNode(nid)
    if choice == 2:
        return SetValue(nid, draw(st.sampled_from(["a", "b", "value"])),
                        draw(st.floats(-10, 10, allow_nan=False)))
    if choice == 3:
        return SetSetting(nid, draw(st.sampled_from(["name", "type", "x"])),
                          draw(st.sampled_from(["p", "float", "vec3", None])))
    if choice == 4:
        other = draw(st.sampled_from(ids))
        return Connect(Link(nid, draw(st.sampled_from(["result", "value"])), other,
                            draw(st.sampled_from(["a", "b", "value"]))))
    if choice == 5 and graph.links:
        return Disconnect(draw(st.sampled_from(sorted(graph.links))))
    if choice == 6:
        return PutComment(draw(st.sampled_from(["c1", "c2"])),
                          draw(st.sampled_from([None, Comment("x", "note")])))
    return MoveNodes({nid: (draw(st.floats(-1e3, 1e3)), draw(st.floats(-1e3, 1e3)))})


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_random_command_sequences_reverted_restore_the_document(data):
    d = simple_material()
    original = d.snapshot()
    done = []
    for _ in range(data.draw(st.integers(1, 25))):
        cmd = _random_command(data.draw, d.graph)
        try:
            cmd.apply(d.graph)
        except CommandError:
            continue
        done.append(cmd)
    for cmd in reversed(done):
        cmd.revert(d.graph)
    assert d.snapshot() == original


# --- layer stack -----------------------------------------------------------------------------

def _layer(tmp_path, name):
    f = function(tmp_path / f"{name}.json")
    node(f, "tint", "function_input", {"name": "tint", "type": "vec3", "default": [1, 0, 0]})
    node(f, "make", "make_attributes")
    node(f, "out", "function_output", {"name": "attributes", "type": "MaterialAttributes"})
    link(f, "tint", "value", "make", "baseColor")
    link(f, "make", "attributes", "out", "value")
    save(f)


def test_layer_stack_add_reorder_remove_keeps_graph_in_step(tmp_path):
    for n in ("a", "b", "c"):
        _layer(tmp_path, n)
    d = simple_material(tmp_path / "m.json")
    node(d, "stack", "layer_stack", {"layers": [{"id": "a", "function": "a.json"}]})
    node(d, "mask", "scalar_parameter", {"name": "mask"})
    stack = LayerStack(d.graph, "stack")
    before = d.graph.snapshot()
    cmds = [stack.add(Layer("b", "b.json", "B"))]
    cmds[-1].apply(d.graph)
    cmds.append(stack.add(Layer("c", "c.json", "C", blend="height")))
    cmds[-1].apply(d.graph)
    c = Connect(Link("mask", "value", "stack", "b_mask"))
    c.apply(d.graph)
    cmds.append(c)
    assert [l.id for l in stack.layers] == ["a", "b", "c"]
    cmds.append(stack.move("c", 1))
    cmds[-1].apply(d.graph)
    assert [l.id for l in stack.layers] == ["a", "c", "b"]
    cmds.append(stack.remove("b"))
    cmds[-1].apply(d.graph)
    assert [l.id for l in stack.layers] == ["a", "c"]
    assert d.graph.incoming("stack", "b_mask") is None  # link into the removed layer cut
    for cmd in reversed(cmds):
        cmd.revert(d.graph)
    assert d.graph.snapshot() == before


def test_layer_stack_ports_follow_layers(tmp_path):
    for n in ("a", "b"):
        _layer(tmp_path, n)
    d = simple_material(tmp_path / "m.json")
    node(d, "stack", "layer_stack", {"layers": [
        {"id": "a", "function": "a.json"},
        {"id": "b", "function": "b.json", "blend": "height"}]})
    from matedit.graph.ports import node_ports

    names = [p.name for p in node_ports(d.graph.nodes["stack"], FileResolver(), d).inputs]
    assert names == ["a_tint", "b_tint", "b_opacity", "b_mask", "b_base_height", "b_contrast"]
    assert not [x for x in validate(d, FileResolver()) if x.severity.value == "error"
                and x.node_id == "stack"]


def test_changing_a_layer_blend_keeps_the_mask_link(tmp_path):
    for n in ("a", "b"):
        _layer(tmp_path, n)
    d = simple_material(tmp_path / "m.json")
    node(d, "stack", "layer_stack", {"layers": [{"id": "a", "function": "a.json"},
                                                {"id": "b", "function": "b.json"}]})
    node(d, "mask", "scalar_parameter", {"name": "mask"})
    Connect(Link("mask", "value", "stack", "b_mask")).apply(d.graph)
    Connect(Link("mask", "value", "stack", "b_tint")).apply(d.graph)  # float splats to vec3
    stack = LayerStack(d.graph, "stack", FileResolver(), d)
    stack.set("b", blend="height").apply(d.graph)
    assert d.graph.incoming("stack", "b_mask") is not None  # alpha and height both have a mask
    assert d.graph.incoming("stack", "b_tint") is not None
    Connect(Link("mask", "value", "stack", "b_contrast")).apply(d.graph)
    stack.set("b", blend="alpha").apply(d.graph)
    assert d.graph.incoming("stack", "b_contrast") is None  # the height-only port is gone
    assert d.graph.incoming("stack", "b_mask") is not None


def test_a_cloned_node_shares_no_data_with_its_original():
    """Node.clone copies file data (dicts, lists, tuples of plain values) itself, without
    copy.deepcopy; anything else still gets a deep copy."""
    from matedit.graph.model import Node, copy_data

    class Box:
        def __init__(self, v):
            self.v = v

        def __eq__(self, other):
            return isinstance(other, Box) and other.v == self.v

    n = Node("a", "color_ramp", (1.0, 2.0), settings={"stops": [[0.0, [1, 2, 3]], [1.0, [4]]],
                                                      "pair": ([1], "x"), "box": Box([7])},
             values={"value": [0.1, 0.2]}, label="L", extra={"future": {"k": [None, True]}},
             muted=True)
    c = n.clone()
    assert c == n and c is not n
    c.settings["stops"][0][1].append(9)
    c.settings["pair"][0].append(2)
    c.settings["box"].v.append(8)
    c.values["value"][0] = 5.0
    c.extra["future"]["k"].append(1)
    assert n.settings["stops"] == [[0.0, [1, 2, 3]], [1.0, [4]]]
    assert n.settings["pair"] == ([1], "x") and n.settings["box"].v == [7]
    assert n.values == {"value": [0.1, 0.2]} and n.extra == {"future": {"k": [None, True]}}
    assert (c.id, c.kind, c.position, c.label, c.muted) == ("a", "color_ramp", (1.0, 2.0),
                                                            "L", True)
    data = {"a": [1, 2.5, "s", None, False, (3, [4])]}
    out = copy_data(data)
    assert out == data and out["a"] is not data["a"] and out["a"][5][1] is not data["a"][5][1]
