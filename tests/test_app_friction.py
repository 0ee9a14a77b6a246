"""What got in an artist's way (issue 18, "Friction"), through the real widgets."""

from __future__ import annotations

import pytest
from graphs_util import EDITOR_SAMPLE
from PySide6.QtCore import QPoint, QPointF, Qt
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = EDITOR_SAMPLE


def short_inspector(qtbot, w) -> None:
    """A window whose inspector is short enough to scroll (the default layout gives it the
    height to show a layer stack whole)."""
    w.resizeDocks([w.panels.viewport_dock, w.panels.inspector_dock], [620, 160],
                  Qt.Orientation.Vertical)
    qtbot.wait(10)


def test_a_new_material_starts_with_an_output_and_the_palette_ranks_it_first(qtbot):
    w = make_window(qtbot, SAMPLE)
    assert w.actions.new()
    kinds = [n.kind for n in w.controller.document.graph.nodes.values()]
    assert kinds == ["material_output"] and not w.controller.dirty
    pal = w.tabs.material.canvas.node_palette
    w.tabs.material.canvas.open_palette(QPointF(0, 0))
    pal.search.setText("output")
    found = pal.visible_kinds()
    assert found.index("material_output") < found.index("function_output")
    pal.close_palette()
    tab = w.tabs.open_function(graphs_dir() / "functions" / "rotate_uv.json")
    tab.canvas.open_palette(QPointF(0, 0))
    tab.canvas.node_palette.search.setText("output")
    found = tab.canvas.node_palette.visible_kinds()
    assert found.index("function_output") < found.index("material_output")  # in a function


def test_file_open_on_a_function_opens_it_in_a_tab(qtbot):
    w = make_window(qtbot, SAMPLE)
    fn = graphs_dir() / "functions" / "rotate_uv.json"
    w.actions.ask_open_path = lambda: str(fn)
    assert w.actions.open_dialog()
    assert w.tabs.active.is_function and w.tabs.active.controller.document.path == fn
    assert w.controller.document.path == SAMPLE  # the material stays
    assert not w.shown_errors


def test_view_menu_shows_dock_check_states(qtbot):
    w = make_window(qtbot, SAMPLE, show=True)
    view_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&View")
    docks = {a.text(): a for a in view_menu.actions() if a.isCheckable()}
    assert "Inspector" in docks and "Lights && Environment" in docks
    for a in docks.values():
        assert a.icon().isNull()  # an icon would be drawn instead of the check mark
    assert docks["Inspector"].isChecked()
    w.panels.inspector_dock.close()
    assert not docks["Inspector"].isChecked()


def test_the_wheel_never_changes_an_unfocused_slider_it_scrolls_the_panel(qtbot):
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    from matedit.app.fields import FloatField

    w = make_window(qtbot, SAMPLE, show=True)
    short_inspector(qtbot, w)
    w.inspector.show_node("stack")
    qtbot.wait(10)
    field = next(f for f in w.inspector._fields.values() if isinstance(f, FloatField))
    bar = w.inspector.verticalScrollBar()
    assert bar.maximum() > 0
    before, scroll = field.slider.value(), bar.value()
    for target in (field.slider, field.spin):
        pos = QPointF(target.rect().center())
        ev = QWheelEvent(pos, QPointF(target.mapToGlobal(pos.toPoint())), QPoint(0, 0),
                         QPoint(0, -120), Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier,
                         Qt.ScrollPhase.NoScrollPhase, False)
        QApplication.sendEvent(target, ev)
    assert field.slider.value() == before and field.value() == pytest.approx(
        field._from_steps(before), abs=1e-3)
    assert bar.value() > scroll  # the panel scrolled instead


def test_the_inspector_keeps_its_scroll_position_across_edits(qtbot):
    from matedit.graph.commands import SetSetting

    w = make_window(qtbot, SAMPLE, show=True)
    short_inspector(qtbot, w)
    w.inspector.show_node("stack")
    qtbot.wait(10)
    bar = w.inspector.verticalScrollBar()
    assert bar.maximum() > 40
    bar.setValue(40)
    layers = w.controller.document.graph.nodes["stack"].settings["layers"]
    renamed = [dict(e) for e in layers]
    renamed[1]["name"] = "Old rust"
    assert w.controller.push(SetSetting("stack", "layers", renamed))  # rebuilds the body
    settle(qtbot, w, 20)
    assert w.inspector._fields  # rebuilt
    assert bar.value() == 40
    w.inspector.show_node("mask_noise")  # another node starts at the top
    assert bar.value() == 0


def test_exposure_has_a_numeric_entry_and_steps_a_tenth_of_an_ev(qtbot):
    w = make_window(qtbot, SAMPLE, show=True)
    vp = w.viewport
    vp.exposure_spin.setValue(1.5)
    assert vp.view._exposure == pytest.approx(1.5) and vp.exposure.value() == 15
    vp.exposure.setFocus()
    qtbot.keyClick(vp.exposure, Qt.Key.Key_Right)
    assert vp.view._exposure == pytest.approx(1.6)
    assert vp.exposure_spin.value() == pytest.approx(1.6)
    assert vp.exposure.width() >= 140


def test_double_clicking_a_wire_inserts_a_reroute_as_one_step(qtbot):
    w = make_window(qtbot, SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    g = w.controller.document.graph
    link = g.incoming("mask", "value")
    wire = canvas.scene().wire_items[link]
    canvas.centerOn(wire)
    qtbot.wait(5)
    path = wire.path()
    mid = path.pointAtPercent(0.5)
    steps = w.controller.undo_stack.count()
    qtbot.mouseDClick(canvas.viewport(), Qt.MouseButton.LeftButton,
                      pos=canvas.mapFromScene(wire.mapToScene(mid)))
    settle(qtbot, w)
    (reroute,) = [n for n in g.nodes.values() if n.kind == "reroute"]
    assert g.incoming(reroute.id, "value").src == link.src
    assert g.incoming("mask", "value").src == reroute.id
    assert link not in g.links and w.controller.undo_stack.count() == steps + 1
    w.controller.undo_stack.undo()
    assert link in g.links and reroute.id not in g.nodes


def test_tab_opens_the_palette_when_the_pointer_is_over_the_canvas_wherever_focus_is(qtbot):
    from PySide6.QtGui import QCursor

    w = make_window(qtbot, SAMPLE, show=True)
    w.activateWindow()
    canvas = w.tabs.material.canvas
    w.inspector.show_node("mask_noise")
    focus = w.viewport.mesh_combo
    focus.setFocus()
    qtbot.waitUntil(focus.hasFocus, timeout=3000)
    QCursor.setPos(canvas.viewport().mapToGlobal(canvas.viewport().rect().center()))
    qtbot.keyClick(focus, Qt.Key.Key_Tab)
    assert canvas.node_palette.isVisible()
    canvas.node_palette.close_palette()
    QCursor.setPos(w.viewport.mapToGlobal(w.viewport.rect().center()))  # elsewhere: focus moves
    focus.setFocus()
    qtbot.keyClick(focus, Qt.Key.Key_Tab)
    assert not canvas.node_palette.isVisible()


def test_f2_renames_a_node_inline_as_one_undo_step(qtbot):
    w = make_window(qtbot, SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    canvas.select_nodes(["mask_noise"])
    canvas.setFocus()
    steps = w.controller.undo_stack.count()
    qtbot.keyClick(canvas, Qt.Key.Key_F2)
    edit = canvas._rename_edit
    assert edit is not None and edit.isVisible() and edit.text() == "Value Noise"
    edit.setText("Rust mask noise")
    qtbot.keyClick(edit, Qt.Key.Key_Return)
    assert w.controller.document.graph.nodes["mask_noise"].label == "Rust mask noise"
    assert w.controller.undo_stack.count() == steps + 1
    assert canvas.scene().node_items["mask_noise"].title == "Rust mask noise"


def test_help_keyboard_reference_is_searchable(qtbot):
    w = make_window(qtbot, SAMPLE)
    ref = w.show_shortcuts()
    assert len(ref.shown_rows()) > 20
    ref.search.setText("reroute")
    rows = ref.shown_rows()
    assert rows and all("reroute" in " ".join(r).lower() for r in rows)
    assert any(r[0] == "Double-click a wire" for r in rows)
    help_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&Help")
    assert w.menus.shortcuts in help_menu.actions() and w.menus.about in help_menu.actions()


def test_node_docs_open_from_f1_the_palette_and_the_inspector(qtbot):
    from matedit.graph import nodes

    w = make_window(qtbot, SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    canvas.select_nodes(["mask_noise"])
    canvas.setFocus()
    qtbot.keyClick(canvas, Qt.Key.Key_F1)
    docs = w._docs
    assert docs is not None and docs.isVisible() and docs.kind == "value_noise"
    text = docs.browser.toPlainText()
    d = nodes.REGISTRY["value_noise"]
    assert d.description in text
    for i in d.inputs:  # every port, with its range where it has one
        assert i.name in text
        if i.range:
            assert f"{i.range[0]:g} … {i.range[1]:g}" in text
    canvas.open_palette(QPointF(0, 0))
    canvas.node_palette.search.setText("checker")
    qtbot.keyClick(canvas.node_palette.search, Qt.Key.Key_F1)
    assert w._docs.kind == "checker"
    canvas.node_palette.close_palette()
    w.inspector.show_node("stack")
    w.inspector.docs_button.click()
    assert w._docs.kind == "layer_stack"


def test_about_names_the_versions_and_the_gl_renderer(qtbot):
    from test_app_support import wait_for_renderer

    from matedit.app.help import about_text

    w = make_window(qtbot, SAMPLE, show=True)
    wait_for_renderer(qtbot, w)
    gl = w.viewport.view.gl_renderer()
    assert gl and "?" not in gl
    text = about_text(gl)
    assert gl in text and "PySide6" in text and "matedit" in text


def test_snap_to_grid_lands_moved_nodes_on_the_grid(qtbot):
    from matedit.app.canvas import constants as C

    w = make_window(qtbot, SAMPLE, show=True)
    assert not w.menus.snap.isChecked()
    w.menus.snap.trigger()
    canvas = w.tabs.material.canvas
    canvas.select_nodes(["mask_noise"])
    item = canvas.scene().node_items["mask_noise"]
    item.setPos(item.pos() + QPointF(13.0, 27.0))  # what a drag does
    canvas.scene().commit_moves()
    x, y = w.controller.document.graph.nodes["mask_noise"].position
    assert x % C.GRID_MINOR == 0 and y % C.GRID_MINOR == 0
    assert (item.pos().x(), item.pos().y()) == (x, y)


def test_viewport_view_light_rig_snap_and_export_targets_are_remembered(qtbot):
    from matedit.app.export_dialog import ExportDialog

    w = make_window(qtbot, SAMPLE)
    w.viewport.mesh_combo.setCurrentText("cube")
    w.viewport.mode_combo.setCurrentText("Reference")
    w.viewport.exposure_spin.setValue(-1.3)
    rig = w.lights.lights[:1] if w.lights.lights else []
    from matedit.shading.lights import Light

    rig = [Light(kind="point", position=(1.0, 2.0, 3.0), intensity=7.0)]
    w.lights.set_lights(rig, emit=True)
    w.menus.snap.setChecked(True)
    w.save_layout()
    dlg = ExportDialog(w.controller.document, w.controller.resolver, w)
    dlg.boxes["glsl450"].setChecked(True)
    dlg.close()

    w2 = make_window(qtbot, SAMPLE)
    w2.restore_layout()
    settle(qtbot, w2, 20)
    assert w2.viewport.mesh_combo.currentText() == "cube"
    assert w2.viewport.mode_combo.currentText() == "Reference"
    assert w2.viewport.view._exposure == pytest.approx(-1.3)
    assert w2.lights.lights == rig
    assert w2.menus.snap.isChecked()
    dlg2 = ExportDialog(w2.controller.document, w2.controller.resolver, w2)
    assert set(dlg2.targets()) == {"glsl330", "glsl450"}
    dlg2.close()


def test_reference_mode_shows_its_progress_and_the_label_never_shifts_the_bar(qtbot):
    from test_app_support import wait_for_renderer
    from test_app_viewport import frame

    w = make_window(qtbot, SAMPLE, show=True)
    r = wait_for_renderer(qtbot, w)
    bar_x = w.viewport.save_button.x()
    r.reference_frames = 4  # converge fast: the count is what is checked
    w.viewport.mode_combo.setCurrentText("Reference")
    frame(qtbot, w.viewport.view)
    text = w.viewport.diff_label.text()
    assert "samples" in text
    qtbot.waitUntil(lambda: r.converged, timeout=20000)
    frame(qtbot, w.viewport.view)
    assert w.viewport.diff_label.text() == f"{4 * r.reference_samples} samples"
    w.viewport.mode_combo.setCurrentText("Difference")
    qtbot.waitUntil(lambda: r.converged, timeout=20000)
    frame(qtbot, w.viewport.view)
    assert "mean |Δ|" in w.viewport.diff_label.text()
    assert w.viewport.save_button.x() == bar_x  # nothing moved along the bar


def test_the_colour_picker_is_not_modal_and_edits_live_as_one_undo_step(qtbot):
    from PySide6.QtGui import QColor

    from matedit.app.fields import ColorField

    w = make_window(qtbot, SAMPLE, show=True)
    w.inspector.show_node("stack")
    field = w.inspector._fields[("value", "paint_color")]
    assert isinstance(field, ColorField)
    field.intensity.setValue(3.0)  # HDR through the intensity
    steps = w.controller.undo_stack.count()
    dlg = field.pick()
    assert dlg is not None and dlg.isVisible() and not dlg.isModal()
    node = w.controller.document.graph.nodes["stack"]
    for c in (QColor(255, 0, 0), QColor(0, 255, 0)):  # what dragging in the picker does
        dlg.setCurrentColor(c)
        assert node.values["paint_color"] == pytest.approx(
            [0.0, 3.0, 0.0] if c.green() else [3.0, 0.0, 0.0])
    assert w.controller.undo_stack.count() == steps + 1  # the whole pick: one step
    dlg.accept()
    w.controller.undo_stack.undo()
    assert node.values["paint_color"][1] != pytest.approx(3.0)


def test_a_document_saves_its_preview_with_a_user_hdr_relative_to_it(qtbot, tmp_path,
                                                                       monkeypatch):
    import json

    from matedit.io.images import write_image

    (tmp_path / "env").mkdir()
    (tmp_path / "mat").mkdir()
    hdr = tmp_path / "env" / "sky.exr"
    write_image(hdr, np_ones())
    w = make_window(qtbot, SAMPLE)
    w.viewport.mesh_combo.setCurrentText("cylinder")
    monkeypatch.setattr(w.viewport.view, "set_environment", lambda *_a: None)  # no bake
    assert w.viewport.choose_environment(str(hdr))
    w.actions.ask_save_path = lambda _s: str(tmp_path / "mat" / "m.json")
    assert w.actions.save_as()
    saved = json.loads((tmp_path / "mat" / "m.json").read_text())
    assert saved["preview"] == {"mesh": "cylinder", "environment": "../env/sky.exr"}

    w2 = make_window(qtbot)
    chosen = []
    monkeypatch.setattr(w2.viewport, "choose_environment", chosen.append)
    assert w2.actions.open(tmp_path / "mat" / "m.json")
    assert w2.viewport.mesh_combo.currentText() == "cylinder"
    assert chosen == [str(hdr.resolve())]


def np_ones():
    import numpy as np

    return np.ones((8, 16, 3), np.float32)


def test_save_as_names_an_untitled_document_after_its_file_and_retitles_the_window(
        qtbot, tmp_path):
    """A new material saved as rusty_panel.json is called "rusty_panel" in the file and the
    window title, even when nothing was edited (Save As of a clean document); saved again
    under another name it follows; a name the artist gave is kept."""
    import json

    w = make_window(qtbot)
    assert w.controller.document.name in ("", "Untitled")
    w.actions.ask_save_path = lambda _s: str(tmp_path / "rusty_panel.json")
    assert w.actions.save_as()
    assert json.loads((tmp_path / "rusty_panel.json").read_text())["name"] == "rusty_panel"
    assert w.windowTitle().startswith("rusty_panel.json")
    w.actions.ask_save_path = lambda _s: str(tmp_path / "rusty_panel_v2.json")
    assert w.actions.save_as()
    assert json.loads((tmp_path / "rusty_panel_v2.json").read_text())["name"] == \
        "rusty_panel_v2"
    assert w.windowTitle().startswith("rusty_panel_v2.json")
    w.controller.document.name = "Weathered Copper"
    w.actions.ask_save_path = lambda _s: str(tmp_path / "copper.json")
    assert w.actions.save_as()
    assert json.loads((tmp_path / "copper.json").read_text())["name"] == "Weathered Copper"
    assert w.windowTitle().startswith("copper.json")


@pytest.mark.parametrize("typed, value, shown", [
    ("1e9", 1e9, "1000000000"), ("2,5", 2.5, "2.500"), ("2.5", 2.5, "2.500"),
    ("-3.5E-1", -0.35, "-0.350"), ("123456", 123456.0, "123456"),
])
def test_a_number_field_reads_what_an_artist_types(qtbot, typed, value, shown):
    """Typed into a float field's box and confirmed with Enter: an exponent is an exponent
    (1e9 was read as 19), the locale's decimal comma is a decimal point (2,5 was 25), and a
    large value shows all its digits."""
    from PySide6.QtTest import QTest

    from matedit.app.fields import FloatField

    f = FloatField(0.5)
    qtbot.addWidget(f)
    f.show()
    got = []
    f.edited.connect(lambda v, _m: got.append(v))
    f.spin.lineEdit().selectAll()
    QTest.keyClicks(f.spin, typed)
    QTest.keyClick(f.spin, Qt.Key.Key_Return)
    assert got and got[-1] == pytest.approx(value)
    assert f.value() == pytest.approx(value)
    assert f.spin.text() == shown


def test_a_black_colour_shows_black_and_a_pick_on_it_takes(qtbot):
    """A colour ramp's black stop, shown by the field that showed a grey one: the swatch is
    black at x 1 (it was the old grey at x 0, and a picked colour stayed black). An artist's
    own x 0 keeps its hue, and a pick then brings the intensity back to 1."""
    from PySide6.QtGui import QColor

    from matedit.app.fields import ColorField

    f = ColorField([0.5, 0.5, 0.5])
    qtbot.addWidget(f)
    got = []
    f.edited.connect(lambda v, _m: got.append(v))
    f.set_value([0.0, 0.0, 0.0])
    assert f.intensity.value() == 1.0
    assert "rgb(0,0,0)" in f.swatch.styleSheet()
    f.dialog_factory = lambda *_a: QColor(255, 0, 0)
    f.pick()
    assert got[-1] == [1.0, 0.0, 0.0] and "rgb(255,0,0)" in f.swatch.styleSheet()
    f.intensity.setValue(0.0)  # typed by the artist: the value is black, the hue stays
    assert got[-1] == [0.0, 0.0, 0.0]
    f.set_value(got[-1])  # the model's value coming back
    assert f.intensity.value() == 0.0 and "rgb(0,0,0)" in f.swatch.styleSheet()
    f.dialog_factory = lambda *_a: QColor(0, 255, 0)
    f.pick()
    assert got[-1] == [0.0, 1.0, 0.0] and f.intensity.value() == 1.0


def test_the_lights_list_grows_with_the_rig_and_selecting_keeps_the_panel_scrolled(qtbot):
    """Eight lights: the list shows them all (it was three rows tall); in a short dock,
    scrolled down to the form, picking another light leaves the panel where it was (it
    jumped back to the top)."""
    from PySide6.QtWidgets import QApplication, QScrollArea

    from matedit.app.lights_panel import MAX_LIST_ROWS
    from matedit.shading.lights import Light

    w = make_window(qtbot, SAMPLE, show=True)
    panel = w.panels.lights
    rig = [Light("sphere", position=(float(i), 2.0, 3.0)) for i in range(MAX_LIST_ROWS)]
    panel.set_lights(rig)
    lst = panel.list
    assert lst.height() >= lst.sizeHintForRow(0) * MAX_LIST_ROWS
    assert lst.verticalScrollBar().maximum() == 0  # every light in view
    scroll = w.findChild(QScrollArea, "lightsScroll")
    w.panels.lights_dock.setFloating(True)
    w.panels.lights_dock.resize(320, 260)
    qtbot.wait(20)
    qtbot.wait(50)
    QApplication.processEvents()
    bar = scroll.verticalScrollBar()
    assert bar.maximum() > 0
    bar.setValue(bar.maximum())
    at = bar.value()
    assert at > 0
    lst.setCurrentRow(5)
    qtbot.wait(20)
    QApplication.processEvents()
    assert bar.value() == at


def test_a_function_tabs_diagnostics_do_not_say_the_material_compiles_when_it_does_not(
        qtbot):
    """The status bar says the material does not compile; a function tab with no problems of
    its own said "No problems: the material compiles." It speaks of itself, and of the
    material's failure."""
    from matedit.app.diagnostics import Problem

    w = make_window(qtbot, SAMPLE)
    w.tabs.open_function(graphs_dir() / "functions" / "rotate_uv.json")
    assert w.tabs.active is not w.tabs.material

    def row() -> str:
        w._refresh_problems()
        return w.diagnostics.topLevelItem(0).text(3)
    w.problems.compile = []
    assert row() == "No problems in this function."
    w.problems.compile = [Problem("error", "parameter name 'p' is used by q too", "p", "name",
                                  "compiler")]
    assert row() == ("No problems in this function; the material does not compile "
                     "(see its tab).")
