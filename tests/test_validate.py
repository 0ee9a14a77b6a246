"""Validation diagnostics and connect-time refusals."""

from __future__ import annotations

from graphs_util import function, link, material, node, simple_material

from matedit.graph.model import Link
from matedit.graph.validate import Severity, analyse, check_connect, validate
from matedit.io.document import FileResolver, save


def errors(doc, resolver=None):
    return [d for d in validate(doc, resolver) if d.severity == Severity.ERROR]


def test_simple_material_is_valid():
    assert errors(simple_material()) == []


def test_unknown_kind_is_reported_on_the_node():
    d = simple_material()
    node(d, "x", "frobnicate")
    (e,) = errors(d)
    assert e.node_id == "x" and e.port == "kind" and "frobnicate" in e.message


def test_type_mismatch_vec2_into_vec3():
    d = simple_material()
    node(d, "uv", "texcoord")
    d.graph.links.discard(d.graph.incoming("make", "baseColor"))
    link(d, "uv", "uv", "make", "baseColor")
    (e,) = errors(d)
    assert (e.node_id, e.port) == ("make", "baseColor")
    assert "vec2" in e.message and "vec3" in e.message


def test_mixed_vector_sizes_in_generic_node():
    d = simple_material()
    node(d, "uv", "texcoord")
    node(d, "a", "add")
    link(d, "uv", "uv", "a", "a")
    link(d, "col", "color", "a", "b")
    (e,) = errors(d)
    assert e.node_id == "a" and "mixed vector sizes" in e.message


def test_float_splats_into_vectors():
    d = simple_material()
    node(d, "a", "add")
    link(d, "r", "value", "a", "a")
    link(d, "col", "color", "a", "b")
    d.graph.links.discard(d.graph.incoming("make", "baseColor"))
    link(d, "a", "result", "make", "baseColor")
    assert errors(d) == []


def test_missing_required_link_is_a_warning_that_names_the_default():
    # Unconnected, the output takes the default material: the rest keeps compiling (issue 18).
    d = simple_material()
    d.graph.links.discard(d.graph.incoming("out", "attributes"))
    assert errors(d) == []
    (w,) = [x for x in validate(d) if x.severity == Severity.WARNING]
    assert (w.node_id, w.port) == ("out", "attributes") and "default" in w.message


def test_unconnected_texture_sample_is_a_warning_not_an_error():
    d = simple_material()
    node(d, "ts", "texture_sample")
    assert errors(d) == []
    assert any((x.node_id, x.port, x.severity) == ("ts", "texture", Severity.WARNING)
               and "checker" in x.message for x in validate(d))


def test_cycle_is_reported():
    d = simple_material()
    node(d, "a", "add")
    node(d, "b", "add")
    link(d, "a", "result", "b", "a")
    link(d, "b", "result", "a", "a")
    assert any(e.message in ("cycle: a -> b -> a", "cycle: b -> a -> b") for e in errors(d)), \
        [e.message for e in errors(d)]


def test_links_to_missing_nodes_and_ports():
    d = simple_material()
    link(d, "ghost", "value", "m", "b")
    link(d, "r", "nope", "make", "metallic")
    msgs = [e.message for e in errors(d)]
    assert any("missing node 'ghost'" in m for m in msgs)
    assert any("no output 'nope'" in m for m in msgs)


class _InOrder(set):
    """A set of links that iterates in the order given (a set's order is its hashes')."""

    def __init__(self, links):
        super().__init__(links)
        self.order = list(links)

    def __iter__(self):
        return iter(self.order)


def test_links_are_checked_as_in_link_order_whatever_the_sets_order():
    """Of two links into one input the first in link order (source, port, destination, port)
    stays, and the links' diagnostics come in that order."""
    d = simple_material()
    node(d, "r2", "scalar_parameter", {"name": "rough2"}, {"value": 0.2})
    link(d, "r2", "value", "m", "a")  # after r's link into m.a
    link(d, "ghost", "value", "m", "b")
    link(d, "col", "nope", "make", "metallic")
    links = sorted(d.graph.links)
    for order in (links, links[::-1]):
        d.graph.links = _InOrder(order)
        a = analyse(d, FileResolver())
        assert a.incoming["m"]["a"] == Link("r", "value", "m", "a")
        assert [(e.node_id, e.port, e.message) for e in a.diagnostics] == [
            ("col", "nope", "node col has no output 'nope'"),
            ("m", "b", "link refers to missing node 'ghost'"),
            ("m", "a", "input has more than one link"),
        ]


def test_bad_value_names_node_and_field():
    d = simple_material()
    d.graph.nodes["m"].values["b"] = "lots"
    (e,) = errors(d)
    assert (e.node_id, e.port) == ("m", "b")


def test_material_needs_one_output():
    d = simple_material()
    node(d, "out2", "material_output")
    link(d, "make", "attributes", "out2", "attributes")
    assert any("exactly one Material Output" in e.message for e in errors(d))


def test_call_to_missing_function(tmp_path):
    d = simple_material(tmp_path / "m.json")
    node(d, "call", "function_call", {"function": "nowhere.json"})
    (e,) = errors(d, FileResolver())
    assert e.node_id == "call" and "nowhere.json" in e.message


def _fn_calling(tmp_path, name, callee):
    f = function(tmp_path / f"{name}.json")
    node(f, "x", "function_input", {"name": "x", "type": "float"})
    node(f, "out", "function_output", {"name": "y", "type": "float"})
    if callee:
        node(f, "call", "function_call", {"function": f"{callee}.json"})
        link(f, "x", "value", "call", "x")
        link(f, "call", "y", "out", "value")
    else:
        link(f, "x", "value", "out", "value")
    save(f)
    return f


def test_recursive_functions_through_files(tmp_path):
    _fn_calling(tmp_path, "f", "g")
    g = _fn_calling(tmp_path, "g", "f")
    errs = errors(g, FileResolver())
    assert any("recursive" in e.message for e in errs)


def test_self_recursive_function(tmp_path):
    f = _fn_calling(tmp_path, "f", "f")
    assert any("recursive" in e.message for e in errors(f, FileResolver()))


def test_function_call_ports_and_types(tmp_path):
    _fn_calling(tmp_path, "leaf", None)
    d = simple_material(tmp_path / "m.json")
    node(d, "call", "function_call", {"function": "leaf.json"})
    link(d, "r", "value", "call", "x")
    d.graph.links.discard(d.graph.incoming("m", "a"))
    link(d, "call", "y", "m", "a")
    assert errors(d, FileResolver()) == []


def test_check_connect_refuses_cycles_and_types_with_reason():
    d = simple_material()
    reason = check_connect(d, Link("m", "result", "m", "a"))
    assert reason and "itself" in reason
    node(d, "a", "add")
    link(d, "m", "result", "a", "a")
    reason = check_connect(d, Link("a", "result", "m", "b"))
    assert reason and "cycle" in reason
    node(d, "uv", "texcoord")
    reason = check_connect(d, Link("uv", "uv", "make", "baseColor"))
    assert reason and "vec2" in reason and "vec3" in reason
    assert check_connect(d, Link("r", "value", "make", "metallic")) is None


def test_function_document_rules():
    f = function()
    node(f, "x", "function_input", {"name": "bad name", "type": "float"})
    msgs = [e.message for e in errors(f)]
    assert any("Function Output" in m for m in msgs)
    assert any("must be an ASCII identifier" in m for m in msgs)


def test_duplicate_parameter_names():
    d = simple_material()
    node(d, "r2", "scalar_parameter", {"name": "rough"})
    assert any("used by" in e.message for e in errors(d))


def test_empty_material_reports_missing_output():
    assert any("Material Output" in e.message for e in errors(material()))


def test_function_input_default_must_suit_its_type():
    f = function()
    node(f, "x", "function_input", {"name": "x", "type": "float", "default": "banana"})
    node(f, "uv", "function_input", {"name": "uv", "type": "vec2", "default": "mesh_uv"})
    node(f, "bad", "function_input", {"name": "c", "type": "vec3", "default": "mesh_uv"})
    node(f, "out", "function_output", {"name": "y", "type": "float"})
    link(f, "x", "value", "out", "value")
    errs = {(e.node_id, e.port) for e in errors(f)}
    assert ("x", "default") in errs and ("bad", "default") in errs
    assert ("uv", "default") not in errs


def test_layer_stack_port_name_collisions_are_errors(tmp_path):
    a = function(tmp_path / "a.json")
    node(a, "m", "function_input", {"name": "mask", "type": "float", "default": 0.5})
    node(a, "make", "make_attributes")
    node(a, "out", "function_output", {"name": "attributes", "type": "MaterialAttributes"})
    link(a, "m", "value", "make", "metallic")
    link(a, "make", "attributes", "out", "value")
    save(a)
    d = simple_material(tmp_path / "m.json")
    node(d, "stack", "layer_stack", {"layers": [{"id": "a", "function": "a.json"},
                                                {"id": "b", "function": "a.json"}]})
    errs = errors(d, FileResolver())
    assert any(e.node_id == "stack" and "b_mask" in e.message for e in errs)


def test_missing_texture_is_a_warning_not_an_error(tmp_path):
    d = simple_material(tmp_path / "m.json")
    node(d, "tex", "texture_parameter", {"name": "albedo", "path": "gone.png"})
    diags = validate(d)
    assert not [x for x in diags if x.severity == Severity.ERROR]
    (w,) = [x for x in diags if x.severity == Severity.WARNING]
    assert (w.node_id, w.port) == ("tex", "path") and "checker" in w.message


def test_a_call_without_a_function_yet_is_a_warning_and_the_material_compiles():
    """A Function Call just placed, its function not chosen: a warning on that node (it used
    to be an error that stopped the material and cleared every thumbnail), no ports, and
    the material compiles as if it were not there."""
    from matedit.compiler.api import compile_document
    from matedit.graph.model import Node
    from matedit.io.document import FileResolver, load
    from matedit.resources import graphs_dir

    doc = load(graphs_dir() / "materials" / "mossy_stone.json")
    before = compile_document(doc, FileResolver()).fragment_text
    doc.graph.nodes["call"] = Node("call", "function_call", (0, 0), {})
    diags = validate(doc, FileResolver())
    mine = [d for d in diags if d.node_id == "call"]
    assert [d.severity.value for d in mine] == ["warning"]
    assert mine[0].port == "function" and "no function chosen" in mine[0].message
    assert not [d for d in diags if d.severity.value == "error"]
    assert compile_document(doc, FileResolver()).fragment_text == before
    # a function setting that is not a file name is still an error naming the field
    doc.graph.nodes["call"] = Node("call", "function_call", (0, 0), {"function": 7})
    bad = [d for d in validate(doc, FileResolver()) if d.node_id == "call"]
    assert [(d.severity.value, d.port) for d in bad] == [("error", "function")]
