"""Regression tests for what an artist tripped over (issue 18, "Broken"): each failed before
its fix, through the real widgets."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_GRAPHS, EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.graph.commands import AddNode, Connect
from matedit.graph.layers import LayerStack
from matedit.graph.model import Link, Node
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = EDITOR_SAMPLE
LAYERS = EDITOR_GRAPHS / "layers"


def _stack(w) -> LayerStack:
    s = LayerStack.find(w.controller.document.graph, w.controller.resolver,
                        w.controller.document)
    assert s is not None
    return s


def _links_into(w, node_id: str) -> set[Link]:
    return {lk for lk in w.controller.document.graph.links if lk.dst == node_id}


# --- 1. reordering layers keeps the wires that belong to a layer ------------------------------

def test_moving_a_height_blended_layer_down_parks_its_mask_wire_and_moving_up_restores_it(
        qtbot):
    from matedit.graph.layers import parked_wires

    w = make_window(qtbot, SAMPLE)
    messages: list[str] = []
    w.layers.message.connect(messages.append)
    w.layers.set_blend("rust", "height")
    settle(qtbot, w)
    stack = _stack(w).node_id
    before = _links_into(w, stack)
    mask_wire = next(lk for lk in before if lk.dst_port == "rust_mask")
    steps = w.controller.undo_stack.count()

    w.layers.select_layer("rust")
    w.layers.down_button.click()  # Rust becomes the base: it has no blend inputs now
    settle(qtbot, w)
    assert [layer.id for layer in _stack(w).layers] == ["rust", "paint"]
    assert mask_wire not in w.controller.document.graph.links
    entry = w.controller.document.graph.nodes[stack].settings["layers"][0]
    assert parked_wires(entry) == [{"port": "mask", "from": ["mask", "result"]}]
    assert w.controller.undo_stack.count() == steps + 1  # one undo step
    assert any("parked" in m for m in messages), messages  # the user is told
    base_row = w.layers.list.itemWidget(w.layers.list.item(1))
    assert base_row.layer_id == "rust" and base_row.parked is not None
    assert "1 blend wire parked" in base_row.parked.text()
    assert w.compiler.current is not None, w.compiler.diagnostics

    w.layers.select_layer("rust")
    w.layers.up_button.click()  # back on top: the wire comes back
    settle(qtbot, w)
    assert [layer.id for layer in _stack(w).layers] == ["paint", "rust"]
    assert _links_into(w, stack) == before
    assert not any("parked" in e for e in
                   w.controller.document.graph.nodes[stack].settings["layers"])
    assert w.controller.undo_stack.count() == steps + 2

    w.controller.undo_stack.undo()
    w.controller.undo_stack.undo()
    settle(qtbot, w)
    assert _links_into(w, stack) == before


def test_parked_wires_are_saved_with_the_document(qtbot, tmp_path):
    from matedit.graph.layers import parked_wires
    from matedit.io.document import load

    w = make_window(qtbot, SAMPLE)
    w.layers.move_to_row("rust", 2)
    w.actions.ask_save_path = lambda _s: str(tmp_path / "m.json")
    assert w.actions.save_as()
    doc = load(tmp_path / "m.json")
    entry = doc.graph.nodes["stack"].settings["layers"][0]
    assert entry["id"] == "rust" and parked_wires(entry)


# --- 2. "Create layer stack" ------------------------------------------------------------------

def test_create_layer_stack_button_in_a_new_material_adds_a_stack(qtbot):
    w = make_window(qtbot)
    assert w.layers.stack is None
    w.layers.create_button.click()  # clicked(bool) must not reach first_layer
    settle(qtbot, w)
    assert w.layers.stack is not None
    assert any(n.kind == "layer_stack" for n in w.controller.document.graph.nodes.values())


def test_create_layer_stack_adopts_what_the_output_showed_as_its_base(qtbot, tmp_path):
    from graphs_util import simple_material

    from matedit.compiler.cpu_eval import evaluate
    from matedit.compiler.lower import lower_document
    from matedit.io.document import save
    from matedit.nodes.twin import sphere_surface

    save(simple_material(), tmp_path / "m.json")
    w = make_window(qtbot, tmp_path / "m.json")
    doc = w.controller.document
    surface, _ = sphere_surface(16)
    want = evaluate(lower_document(doc, w.controller.resolver), surface)
    before = doc.graph.snapshot()
    out_x = doc.graph.nodes["out"].position[0]
    w.layers.create_button.click()
    settle(qtbot, w)
    stack = next(n for n in doc.graph.nodes.values() if n.kind == "layer_stack")
    entries = stack.settings["layers"]
    assert [e["name"] for e in entries] == ["From the graph"]
    assert entries[0]["function"] == "library:layers/graph_input.json"  # outside the library
    assert doc.graph.incoming("out", "attributes").src == stack.id
    assert doc.graph.incoming(stack.id, "graph_attributes").src == "make"
    assert doc.graph.nodes["out"].position[0] > out_x  # made room: the stack sits between
    got = evaluate(lower_document(doc, w.controller.resolver), surface)
    for f in ("baseColor", "roughness", "metallic"):  # the material looks as it did
        np.testing.assert_array_equal(got[f], want[f], err_msg=f)
    assert w.layers.stack is not None and len(w.layers.stack.layers) == 1
    w.controller.undo_stack.undo()  # one step
    assert doc.graph.snapshot() == before


# --- 3 and 4. thumbnails show what the node outputs -------------------------------------------

def _pixels(img) -> np.ndarray:
    from PySide6.QtGui import QImage

    img = img.convertToFormat(QImage.Format.Format_RGB888)
    w, h = img.width(), img.height()
    raw = np.frombuffer(img.constBits(), np.uint8, img.bytesPerLine() * h)
    return raw.reshape(h, img.bytesPerLine())[:, :3 * w].reshape(h, w, 3).astype(float)


def _material_thumbnail(w):
    """The material's final attributes on the preview sphere, through the CPU evaluator
    directly: what a node feeding the output straight must show."""
    from matedit.app.previews import preview_sphere, to_image
    from matedit.compiler.cpu_eval import evaluate
    from matedit.compiler.lower import lower_document

    ir = lower_document(w.controller.document, w.controller.resolver)
    surface, inside = preview_sphere()
    return _pixels(to_image(evaluate(ir, surface), inside))


def test_layer_stack_thumbnail_shows_the_blend_not_the_top_layer(qtbot):
    w = make_window(qtbot, SAMPLE)
    g = w.controller.document.graph
    assert w.controller.push(AddNode(Node("zero", "constant", (-400.0, 400.0),
                                          {"value": 0.0})))
    assert w.controller.push(Connect(Link("zero", "value", "stack", "rust_opacity")))
    settle(qtbot, w)
    thumbs = w.tabs.material.previews.images()
    stack = _pixels(thumbs["stack"])
    want = _material_thumbnail(w)
    # Same evaluator, same pixels: only the 8-bit rounding of one value may differ.
    assert np.abs(stack - want).max() <= 1.0
    centre = stack[20:28, 20:28].reshape(-1, 3).mean(axis=0)
    assert centre[2] > centre[0] + 20, centre  # the blue paint, not the orange rust

    # A hidden layer keeps the thumbnail (it used to vanish).
    w.controller.document.graph  # noqa: B018 - same graph, edited through the panel
    w.layers.set_visible("rust", False)
    settle(qtbot, w)
    thumbs = w.tabs.material.previews.images()
    assert "stack" in thumbs
    assert np.abs(_pixels(thumbs["stack"]) - _material_thumbnail(w)).max() <= 1.0
    assert g is w.controller.document.graph


def test_texture_sample_thumbnail_shows_the_image_of_its_parameter(qtbot, tmp_path):
    from matedit.graph.commands import SetSetting
    from matedit.io.images import write_image

    img = np.zeros((16, 16, 3), np.float32)
    img[..., 1] = 1.0  # pure green: no checker colour comes near it
    write_image(tmp_path / "green.png", img)
    w = make_window(qtbot, SAMPLE)
    assert w.controller.push(AddNode(Node("tp", "texture_parameter", (-600.0, 500.0),
                                          {"name": "albedo"})))
    assert w.controller.push(AddNode(Node("ts", "texture_sample", (-400.0, 500.0))))
    assert w.controller.push(Connect(Link("tp", "texture", "ts", "texture")))
    settle(qtbot, w)
    before = _pixels(w.tabs.material.previews.images()["ts"])[24, 24]
    assert before[1] < 200 or before[0] > 100  # the checker
    assert w.controller.push(SetSetting("tp", "path", str(tmp_path / "green.png")))
    settle(qtbot, w)
    px = _pixels(w.tabs.material.previews.images()["ts"])[20:28, 20:28].reshape(-1, 3)
    assert px[:, 1].min() > 240 and px[:, 0].max() < 10 and px[:, 2].max() < 10, px[:4]


# --- 5. the HDR colour's intensity keeps what was typed ---------------------------------------

def test_colour_intensity_typed_stays_what_was_typed_after_the_model_round_trip(qtbot):
    from matedit.app.fields import ColorField

    w = make_window(qtbot, SAMPLE)
    w.inspector.show_node("stack")
    field = w.inspector._fields[("value", "paint_color")]
    assert isinstance(field, ColorField)
    base = list(field._base)
    field.intensity.setValue(4.0)  # typed: the model's value comes back to the field
    settle(qtbot, w)
    field = w.inspector._fields[("value", "paint_color")]
    assert field.intensity.value() == pytest.approx(4.0)
    value = w.controller.document.graph.nodes["stack"].values["paint_color"]
    assert value == pytest.approx([4.0 * c for c in base], abs=1e-5)
    field.intensity.setValue(2.0)
    settle(qtbot, w)
    assert w.inspector._fields[("value", "paint_color")].intensity.value() == pytest.approx(2.0)
    w.controller.undo_stack.undo()  # back to 4: still shown as 4, not re-split
    settle(qtbot, w)
    assert w.inspector._fields[("value", "paint_color")].intensity.value() == pytest.approx(4.0)


# --- 6. the diagnostics count is the number of rows -------------------------------------------

def test_diagnostics_title_counts_the_rows_it_lists(qtbot):
    w = make_window(qtbot, SAMPLE)
    # A link from a port that does not exist: validation and the compiler both report it.
    w.controller.document.graph.links.add(Link("mask_noise", "nope", "mask", "value"))
    w.controller.reanalyse()
    settle(qtbot, w)
    rows = [p for p in w.diagnostics.problems if p.severity == "error"]
    assert rows
    assert w.panels.diagnostics_dock.windowTitle() == f"Diagnostics ({len(rows)})"
    assert w.diagnostics.topLevelItemCount() == len(w.diagnostics.problems)


# --- 7. '&' in names ---------------------------------------------------------------------------

def test_ampersand_in_names_is_shown_not_eaten(qtbot):
    w = make_window(qtbot, SAMPLE, show=True)
    # Tabified with the inspector, its tab reads '&' as a mnemonic: escaped there; floating,
    # the title bar draws the title as it is. The View menu always reads a mnemonic.
    assert w.tabifiedDockWidgets(w.panels.lights_dock)
    assert w.panels.lights_dock.windowTitle() == "Lights && Environment"
    assert w.panels.lights_dock.toggleViewAction().text() == "Lights && Environment"
    w.panels.lights_dock.setFloating(True)
    qtbot.waitUntil(lambda: w.panels.lights_dock.windowTitle() == "Lights & Environment")
    assert w.panels.lights_dock.toggleViewAction().text() == "Lights && Environment"
    tab = w.tabs.open_function(graphs_dir() / "functions" / "uv_tile_rotate.json",
                               w.tabs.material)
    assert tab is not None
    i = w.tabs.all_tabs().index(tab)
    assert w.tabs.tabs.tabText(i) == "UV Tile && Rotate"  # Qt shows "UV Tile & Rotate"
    crumbs = [w.tabs.crumb_layout.itemAt(k).widget() for k in range(w.tabs.crumb_layout.count())]
    texts = [b.text() for b in crumbs if b is not None and hasattr(b, "isFlat")]
    assert "UV Tile && Rotate" in texts, texts
    # The call node is titled with the function's own name, not its file name.
    from matedit.graph.commands import AddNode
    from matedit.graph.model import Node

    w.tabs.material.controller.push(AddNode(Node(
        "uvcall", "function_call", (0.0, 0.0),
        {"function": "../functions/uv_tile_rotate.json"})))
    item = w.tabs.material.canvas.scene().node_items["uvcall"]
    assert item.title == "UV Tile & Rotate"


# --- 8. Save As retitles the tab ---------------------------------------------------------------

def test_save_as_renames_the_untitled_tab(qtbot, tmp_path):
    w = make_window(qtbot)
    assert w.tabs.tabs.tabText(0).startswith("Untitled")
    w.tabs.material.canvas.add_node_at("material_output", __import__(
        "PySide6.QtCore", fromlist=["QPointF"]).QPointF(0, 0))
    w.actions.ask_save_path = lambda _s: str(tmp_path / "brass_knob.json")
    assert w.save_active_as()
    assert w.tabs.tabs.tabText(0) == "brass_knob"
    assert w.windowTitle().startswith("brass_knob.json")


# --- 9. an unconnected required input takes its default --------------------------------------

def test_unconnected_texture_sample_warns_and_the_rest_keeps_compiling_and_previewing(qtbot):
    w = make_window(qtbot, SAMPLE)
    assert w.compiler.current is not None
    assert w.controller.push(AddNode(Node("ts", "texture_sample", (-400.0, 500.0))))
    assert w.controller.push(Connect(Link("ts", "r", "hi", "b")))  # used, so not dead code
    settle(qtbot, w)
    assert w.compiler.current is not None, w.compiler.diagnostics  # still compiles
    assert not [p for p in w.diagnostics.problems if p.severity == "error"]
    warned = [p for p in w.diagnostics.problems if p.node_id == "ts"]
    assert warned and warned[0].severity == "warning" and "checker" in warned[0].message
    thumbs = w.tabs.material.previews.images()
    assert {"stack", "mask_noise", "ts"} <= set(thumbs)  # nothing blanked
    (tex,) = [t for t in w.compiler.current.ir.textures if t.node == "ts"]
    assert tex.path == ""  # no image: the renderer and the evaluator show a checker
    # The GLSL is whole: the glsl330 entry declares the sampler it samples.
    assert f"uniform sampler2D {tex.name};" in w.compiler.current.fragment_text
