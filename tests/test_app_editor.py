"""Building, editing, saving and undoing a layered material through the editor's widgets."""

from __future__ import annotations

from pathlib import Path

import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.graph.layers import LayerStack
from matedit.graph.model import MaterialDocument
from matedit.io.document import dumps, load
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

LAYERS = graphs_dir() / "layers"


def _stack(window) -> LayerStack:
    s = LayerStack.find(window.controller.document.graph)
    assert s is not None
    return s


def test_two_layer_material_built_from_empty_saves_reopens_and_undoes_to_empty(qtbot, tmp_path):
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QColor

    from matedit.app.document_actions import new_material
    from matedit.app.fields import ColorField, FloatField

    w = make_window(qtbot)
    empty = new_material().graph.snapshot()  # a new material holds its Material Output
    assert w.controller.document.graph.snapshot() == empty
    assert MaterialDocument(name="Untitled").graph.snapshot() != empty
    canvas = w.tabs.material.canvas

    # The output node is there; the layers come through the layer panel.
    (out,) = [n.id for n in w.controller.document.graph.nodes.values()
              if n.kind == "material_output"]
    assert canvas.add_node_at("noise", QPointF(400, 0)) == ""  # unknown kinds: refused
    base = w.layers.add_layer_file(LAYERS / "painted_metal.json")
    top = w.layers.add_layer_file(LAYERS / "rust.json")
    assert base and top
    settle(qtbot, w)
    stack = _stack(w)
    assert [layer.id for layer in stack.layers] == [base, top]
    assert w.controller.document.graph.incoming(out, "attributes").src == stack.node_id
    assert w.compiler.current is not None, w.compiler.diagnostics
    assert w.layers.layer_ids_top_first() == [top, base]  # a painting program's order

    # A mask for the top layer: a noise node wired in through commands (the canvas's drag).
    from matedit.graph.commands import Connect
    from matedit.graph.model import Link

    noise = canvas.add_node_at("value_noise", QPointF(0, 200))
    assert w.controller.push(Connect(Link(noise, "value", stack.node_id, f"{top}_mask")))

    # Layer panel: blend, rename, hide and show, opacity drag as one undo step.
    w.layers.set_blend(top, "height")
    w.layers.rename(top, "Rust on top")
    w.layers.set_visible(base, False)
    w.layers.set_visible(base, True)
    settle(qtbot, w)
    assert _stack(w).layers[1].blend == "height"
    assert _stack(w).layers[1].name == "Rust on top"
    row = w.layers.list.itemWidget(w.layers.list.item(0))
    assert row.layer_id == top and row.opacity is not None
    before = w.controller.undo_stack.count()
    row.opacity.slider.sliderPressed.emit()
    for steps in (900, 700, 600):
        row.opacity.slider.setValue(steps)
    row.opacity.slider.sliderReleased.emit()
    assert w.controller.undo_stack.count() == before + 1
    node = w.controller.document.graph.nodes[stack.node_id]
    assert node.values[f"{top}_opacity"] == pytest.approx(0.6)

    # Inspector on the stack node: the paint colour through the swatch (HDR via intensity).
    w.tabs.material.canvas.select_nodes([stack.node_id])
    w.inspector.show_node(stack.node_id)
    colour = w.inspector._fields[("value", f"{base}_color")]
    assert isinstance(colour, ColorField)
    colour.dialog_factory = lambda initial, parent, title: QColor(255, 0, 0)
    colour.pick()
    colour.intensity.setValue(2.0)
    assert node.values[f"{base}_color"] == pytest.approx([2.0, 0.0, 0.0])
    rough = w.inspector._fields[("value", f"{base}_roughness")]
    assert isinstance(rough, FloatField)
    rough.spin.setValue(0.8)  # typed: one step; outside-range values widen the slider
    rough.spin.setValue(3.0)
    assert rough.range[1] >= 3.0
    assert node.values[f"{base}_roughness"] == 3.0

    # Reorder by the panel (what a drag does): the base layer goes on top.
    assert w.layers.move_to_row(base, 0)
    assert [layer.id for layer in _stack(w).layers] == [top, base]
    settle(qtbot, w)
    assert w.compiler.current is not None, w.compiler.diagnostics

    # Save, reopen, compare.
    target = tmp_path / "two_layers.json"
    w.actions.ask_save_path = lambda suggestion: str(target)
    assert w.actions.save()
    assert not w.controller.dirty and not w.isWindowModified()
    saved = dumps(w.controller.document)  # canonical: sorted keys all the way down
    reopened = load(target)
    assert dumps(reopened) == saved
    for e in reopened.graph.nodes[stack.node_id].settings["layers"]:
        assert not Path(e["function"]).is_absolute()  # references relative to the file
    w2 = make_window(qtbot, target)
    assert dumps(w2.controller.document) == saved
    assert w2.compiler.current is not None
    assert w2.layers.layer_ids_top_first() == [base, top]

    # Undo everything: back to the empty document.
    stack_ = w.controller.undo_stack
    while stack_.canUndo():
        stack_.undo()
    settle(qtbot, w)
    assert w.controller.document.graph.snapshot() == empty
    assert w.layers.stack is None and w.layers.empty.isVisibleTo(w.layers)


def test_inspector_slider_drag_is_one_undo_step_and_never_recompiles(qtbot):
    from matedit.app.fields import FloatField

    w = make_window(qtbot, EDITOR_SAMPLE)
    settle(qtbot, w)
    compiled = w.compiler.current
    assert compiled is not None
    hits = []
    w.controller.structureChanged.connect(lambda: hits.append(1))
    w.inspector.show_node("amount")
    f = w.inspector._fields[("value", "value")]
    assert isinstance(f, FloatField)
    count = w.controller.undo_stack.count()
    f.slider.sliderPressed.emit()
    for s in (100, 200, 300, 800):
        f.slider.setValue(s)
    f.slider.sliderReleased.emit()
    settle(qtbot, w, 50)
    assert w.controller.undo_stack.count() == count + 1
    assert w.controller.document.graph.nodes["amount"].values["value"] == pytest.approx(0.8)
    assert hits == [] and w.compiler.current is compiled
    assert w.compiler.uniforms()["p_rust_amount"] == pytest.approx(0.8)
    w.controller.undo_stack.undo()
    assert w.controller.document.graph.nodes["amount"].values["value"] == pytest.approx(0.45)
    assert f.value() == pytest.approx(0.45)  # the widget follows the undo


def test_settings_editors_and_texture_picker_push_commands(qtbot, tmp_path):
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QColor, QImage
    from PySide6.QtWidgets import QComboBox, QLineEdit

    from matedit.app.fields import TextureField

    w = make_window(qtbot)
    canvas = w.tabs.material.canvas
    c = canvas.add_node_at("constant", QPointF(0, 0))
    w.inspector.show_node(c)
    settle(qtbot, w)
    combo = next(x for x in w.inspector.widget().findChildren(QComboBox))
    combo.setCurrentText("vec3")
    settle(qtbot, w, 10)
    assert w.controller.document.graph.nodes[c].settings["type"] == "vec3"
    assert ("setting", "value") in w.inspector._fields  # a vec3 editor now

    tex = canvas.add_node_at("texture_parameter", QPointF(0, 200))
    w.inspector.show_node(tex)
    img = tmp_path / "albedo.png"
    q = QImage(8, 8, QImage.Format.Format_RGB32)
    q.fill(QColor(200, 40, 40))
    assert q.save(str(img))
    settle(qtbot, w)
    field = w.inspector._fields[("setting", "path")]
    assert isinstance(field, TextureField)
    field.file_dialog = lambda *a: (str(img), "")
    hits = []
    w.controller.structureChanged.connect(lambda: hits.append(1))
    field.browse.click()
    settle(qtbot, w, 10)
    assert Path(w.controller.document.graph.nodes[tex].settings["path"]) == img.resolve()
    assert hits == []  # a texture file is a value edit
    field = w.inspector._fields[("setting", "path")]
    assert field.thumb.toolTip() == str(img.resolve())  # the thumbnail shows the image

    w.inspector.show_node(c)
    title = w.inspector.widget().findChild(QLineEdit, "inspectorTitle")
    title.setText("Tint")
    title.editingFinished.emit()
    assert w.controller.document.graph.nodes[c].label == "Tint"


def test_layer_dropped_from_library_and_rows_reordered_by_drop(qtbot):
    from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt
    from PySide6.QtGui import QDropEvent

    from matedit.app.layers_panel import LAYER_MIME, ROW_MIME

    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    lib_layers = w.library.items("layer")
    mud = next(it for it in lib_layers if "mud" in it.data(0, Qt.ItemDataRole.UserRole))
    mime = w.library.tree.mimeData([mud])
    assert mime.hasFormat(LAYER_MIME)
    lst = w.layers.list

    def drop(data: QMimeData, pos: QPoint) -> None:
        ev = QDropEvent(QPointF(pos), Qt.DropAction.CopyAction | Qt.DropAction.MoveAction,
                        data, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier)
        lst.dropEvent(ev)

    drop(mime, QPoint(10, 2))  # above the top row
    settle(qtbot, w, 10)
    ids = w.layers.layer_ids_top_first()
    assert len(ids) == 3 and ids[0].startswith("mud")
    # Drag the base (last row) to the top.
    row = QMimeData()
    row.setData(ROW_MIME, ids[-1].encode())
    drop(row, QPoint(10, 2))
    settle(qtbot, w, 10)
    assert w.layers.layer_ids_top_first() == [ids[-1], *ids[:-1]]
    assert w.compiler.current is not None, w.compiler.diagnostics


def test_library_function_opens_in_a_tab_with_breadcrumbs_back(qtbot):
    from PySide6.QtWidgets import QPushButton

    w = make_window(qtbot, EDITOR_SAMPLE)
    fn = next(it for it in w.library.items("function"))
    w.library._activated(fn)
    assert w.tabs.tabs.count() == 2 and w.tabs.active.is_function
    crumbs = [b for b in w.tabs.crumbs.findChildren(QPushButton) if b.objectName() == "crumb"]
    back = [b for b in crumbs if b.isEnabled()]
    assert back, "a breadcrumb leads back to the material"
    back[0].click()
    assert w.tabs.active is w.tabs.material
    assert w.tabs.close_tab(1) and w.tabs.tabs.count() == 1


def test_diagnostics_click_selects_the_node(qtbot):
    from matedit.graph.commands import Connect
    from matedit.graph.model import Link

    w = make_window(qtbot, EDITOR_SAMPLE)
    # A wire from an output that does not exist (an unconnected input only warns now).
    w.controller.push(Connect(Link("mask_noise", "nope", "mask", "value")))
    settle(qtbot, w, 10)
    assert w.compiler.current is None
    problems = w.diagnostics.problems
    assert any(p.node_id == "mask_noise" and p.severity == "error" for p in problems)
    item = next(w.diagnostics.topLevelItem(i) for i in range(w.diagnostics.topLevelItemCount())
                if w.diagnostics.topLevelItem(i).text(1) == "mask_noise")
    w.diagnostics.itemClicked.emit(item, 0)
    assert w.tabs.material.canvas.selected_ids() == ["mask_noise"]
    assert w.inspector.node_id == "mask_noise"
