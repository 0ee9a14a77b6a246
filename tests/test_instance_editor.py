"""The instance editor and parameter panel (real widgets and GL under Xvfb)."""

from __future__ import annotations

import json

import pytest
from PySide6.QtCore import Qt
from test_app_support import app_env, make_window  # noqa: F401

from matedit.io.instance import load_instance, resolve
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

MASTER = graphs_dir() / "materials" / "worn_painted_steel.json"


def _master_value(name: str):
    """The master's own value of a parameter (the samples keep being tuned)."""
    for n in json.loads(MASTER.read_text())["nodes"]:
        if n.get("settings", {}).get("name") == name:
            return n.get("values", {}).get("value")
    raise KeyError(name)


WEAR = _master_value("wear_amount")


@pytest.fixture
def window(qtbot):
    return make_window(qtbot)


def _renderer(qtbot, editor):
    view = editor.view
    qtbot.waitUntil(lambda: view.renderer is not None or bool(view.problem), timeout=60000)
    assert view.renderer is not None, view.problem
    return view.renderer


def _frame(qtbot, editor):
    serial = editor.view.request_frame()  # a picture after every change sent so far
    qtbot.waitUntil(lambda: editor.view.shown_serial >= serial > 0, timeout=20000)


def test_create_override_reset_switch_save_reopen(window, qtbot, tmp_path):
    path = tmp_path / "my_paint.json"
    editor = window.create_instance(str(MASTER), str(path))
    qtbot.addWidget(editor)
    assert json.loads(path.read_text())["parameters"] == {}
    # grouped and ordered as the master's settings say; each layer's own inputs and its
    # visibility follow in its group, and a layer with no parameter node of its own last
    order = editor.panel.group_order()
    assert [g for g, _ in order] == ["Paint", "Rust", "Bare Steel"]
    assert order[0][1][:4] == ["paint_color", "wear_amount", "scratch_amount", "scratch_angle"]
    assert order[0][1][4] == "paint_visible" and "paint_roughness" in order[0][1]
    assert order[1][1][:4] == ["rust_on", "rust_amount", "rust_reach", "rust_visible"]
    assert order[2][1] == ["steel_tint", "steel_roughness"]
    head, body = editor.panel.groups["Rust"]
    head.click()
    assert not head.isChecked() and body.isHidden()
    head.click()
    renderer = _renderer(qtbot, editor)
    _frame(qtbot, editor)
    links, compiles = renderer.link_count, editor.compile_count

    # override: a value edit is a uniform update, marked as overridden
    row = editor.panel.rows["wear_amount"]
    assert not row.check.isChecked() and not editor.panel.is_marked("wear_amount")
    row.field.edited.emit(0.9, None)
    assert editor.doc.parameters == {"wear_amount": 0.9}
    assert row.check.isChecked() and editor.panel.is_marked("wear_amount")
    assert renderer.material.values["p_wear_amount"] == pytest.approx(0.9)
    _frame(qtbot, editor)
    assert (renderer.link_count, editor.compile_count) == (links, compiles)

    # reset to parent
    qtbot.mouseClick(row.reset, Qt.MouseButton.LeftButton)
    assert editor.doc.parameters == {} and not editor.panel.is_marked("wear_amount")
    assert row.field.value() == pytest.approx(WEAR)
    assert renderer.material.values["p_wear_amount"] == pytest.approx(WEAR)

    # the override checkbox overrides with the inherited value
    colour = editor.panel.rows["paint_color"]
    colour.check.setChecked(True)
    assert editor.doc.parameters == {"paint_color": [0.05, 0.22, 0.45]}

    # static switch off: one compile and one link; back on: compiled, but the program is
    # the cached one (no link)
    switch = editor.panel.rows["rust_on"].field
    switch.setChecked(False)
    _frame(qtbot, editor)
    assert editor.compile_count == compiles + 1 and renderer.link_count == links + 1
    assert "p_rust_amount" not in renderer.material.values
    assert not editor.panel.rows["rust_amount"].field.isEnabled()
    switch.setChecked(True)
    _frame(qtbot, editor)
    assert editor.compile_count == compiles + 2 and renderer.link_count == links + 1
    assert "p_rust_amount" in renderer.material.values
    switch.setChecked(False)
    _frame(qtbot, editor)
    assert renderer.link_count == links + 1

    # save and reopen
    assert editor.dirty
    assert editor.save() and not editor.dirty
    saved = json.loads(path.read_text())
    assert saved["parameters"] == {"paint_color": [0.05, 0.22, 0.45], "rust_on": False}
    assert saved["parent_parameters"]["rust_on"] == "switch"
    again = window.open_instance(str(path))
    qtbot.addWidget(again)
    assert again.doc.parameters == saved["parameters"]
    assert again.panel.rows["rust_on"].field.isChecked() is False
    assert again.panel.is_marked("rust_on") and not again.panel.is_marked("rust_reach")
    for e in (editor, again):
        e.dirty = False
        e.close()


def test_library_lists_instances_under_their_parent(window, qtbot):
    window.library.refresh()
    mats = {it.data(0, 0x0100): it for it in window.library.items("material")}
    master = mats[str(MASTER.resolve())]
    kids = {master.child(i).text(0): master.child(i) for i in range(master.childCount())}
    assert {"Worn paint, red", "Worn paint, green", "Worn paint, yellow"} <= set(kids)
    red = kids["Worn paint, red"]
    grand = {red.child(i).text(0) for i in range(red.childCount())}
    assert {"Worn paint, red, scuffed", "Worn paint, red, no rust"} <= grand
    qtbot.waitUntil(lambda: not red.icon(0).isNull(), timeout=10000)  # from the instance


def test_file_open_of_an_instance_opens_the_editor(window, qtbot):
    path = graphs_dir() / "instances" / "worn_paint_green.json"
    assert window.actions.open(path, ask=False)
    (editor,) = window.instances.editors
    qtbot.addWidget(editor)
    assert editor.doc.parameters == load_instance(path).parameters
    assert editor.panel.is_marked("scratch_amount")
    assert editor.value("rust_on") is resolve(load_instance(path)).values["rust_on"]
    editor.close()


def test_material_parameters_dock_is_grouped_and_edits_by_command(qtbot):
    w = make_window(qtbot, MASTER)
    panel = w.instances.parameters_panel
    # built for the opened document once control is back in the event loop
    qtbot.waitUntil(lambda: panel.settled)
    assert [g for g, _ in panel.group_order()] == ["Paint", "Rust"]
    panel.rows["wear_amount"].field.edited.emit(0.75, None)
    node = w.controller.document.graph.nodes["wear_amt"]
    assert node.values["value"] == 0.75
    w.controller.undo_stack.undo()
    assert node.values["value"] == WEAR
    assert panel.rows["wear_amount"].field.value() == pytest.approx(WEAR)
    panel.rows["rust_on"].field.setChecked(False)
    assert w.controller.document.graph.nodes["rust_on"].settings["value"] is False
    assert panel.rows["rust_on"].field.isChecked() is False


def test_presentation_settings_shape_the_fields(qtbot):
    from matedit.app.parameter_panel import CurveFloatField, ParameterPanel, _ColourVector
    from matedit.io.instance import ParameterInfo

    infos = {
        "gloss": ParameterInfo("gloss", "scalar", "g", "scalar_parameter", 0.25,
                               {"group": "B", "order": 2, "ui_min": 0.0, "ui_max": 4.0,
                                "exponent": 2.0, "tooltip": "how shiny"}),
        "count": ParameterInfo("count", "scalar", "c", "scalar_parameter", 3.0,
                               {"group": "B", "order": 1, "slider": False}),
        "tint": ParameterInfo("tint", "vector", "t", "vector_parameter", [1, 0, 0, 1],
                              {"group": "A", "order": 5, "usage": "color"}),
        "loose": ParameterInfo("loose", "scalar", "l", "scalar_parameter", 0.5, {}),
    }
    panel = ParameterPanel()
    qtbot.addWidget(panel)
    panel.set_parameters(infos, {n: p.default for n, p in infos.items()})
    assert panel.group_order() == [("Parameters", ["loose"]), ("B", ["count", "gloss"]),
                                   ("A", ["tint"])]
    gloss = panel.rows["gloss"].field
    assert isinstance(gloss, CurveFloatField)
    # exponent 2: the slider's middle is a quarter of the range (0 + 4 * 0.5^2 = 1.0)
    assert gloss._from_steps(500) == pytest.approx(1.0)
    assert gloss._to_steps(1.0) == 500
    assert panel.rows["count"].field.slider.isHidden()
    assert isinstance(panel.rows["tint"].field, _ColourVector)
    assert "how shiny" in panel.labels["gloss"].toolTip()
    assert not panel.rows["gloss"].check.isVisibleTo(panel)  # a material: no override column


def _listing(library) -> list[tuple[str, str, str]]:
    return [(it.data(0, 0x0101), it.text(0), it.toolTip(0)) for it in library.items()]


def test_the_library_lists_in_turns_and_thumbnails_a_step_a_turn(window, qtbot, monkeypatch):
    """The start-up listing reads a few files a turn of the event loop, with the timer's
    events between turns, and fills the same tree as `refresh`; the instances' thumbnails
    come a step a turn, not all in one stretch."""
    import time

    from PySide6.QtCore import QTimer

    import matedit.app.instance_editor as ie
    import matedit.app.library as lib

    library = window.library
    library.refresh()
    expected = _listing(library)
    turns = []
    monkeypatch.setattr(lib, "LIST_BUDGET_S", 0.002)  # several turns on any machine
    real_turn = lib.LibraryPanel._list_turn
    monkeypatch.setattr(lib.LibraryPanel, "_list_turn",
                        lambda self: (turns.append(time.perf_counter()), real_turn(self)))
    made, done = [], []  # when each step of a thumbnail ran; the thumbnails finished
    real_thumb = ie._thumbnail

    def traced(it, f):
        for _ in real_thumb(it, f):
            made.append(time.perf_counter())
            yield
        made.append(time.perf_counter())
        done.append(it)

    monkeypatch.setattr(ie, "_thumbnail", traced)
    ticks = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start(0)
    library.listed = False
    library.list_in_turns()
    assert not library.listed and library._listing is not None
    qtbot.waitUntil(lambda: library.listed, timeout=20000)
    qtbot.waitUntil(lambda: len(done) >= 6, timeout=20000)  # the six instances of graphs/
    timer.stop()
    assert len(turns) >= 3
    assert _listing(library) == expected
    assert all(not it.icon(0).isNull() for it in done)
    # between two turns, and between two steps of the thumbnails (three each), the loop ran
    # other events
    assert len(made) == 3 * len(done)
    for stamps in (turns, made):
        for a, b in zip(stamps, stamps[1:]):
            assert any(a < t < b for t in ticks), (a, b)

    # a listing under way is finished at once when the tree is asked for
    library.listed = False
    library.list_in_turns()
    assert library.items("material") and library.listed and library._listing is None
    assert _listing(library) == expected


def test_toggling_a_switch_keeps_the_parameters_rows(qtbot):
    """A switch's value is a setting of its node, but not part of what the rows are made of:
    toggling it updates its row in place (no rebuild of the dock, row by row)."""
    w = make_window(qtbot, MASTER)
    panel = w.instances.parameters_panel
    qtbot.waitUntil(lambda: panel.settled)
    rows = dict(panel.rows)
    switch = panel.rows["rust_on"].field
    switch.setChecked(not switch.isChecked())
    assert panel.settled and panel.rows == rows
    assert panel.rows["rust_on"].field.isChecked() is \
        w.controller.document.graph.nodes["rust_on"].settings["value"]
    w.controller.undo_stack.undo()  # and back, shown in the same row
    assert panel.rows == rows
    assert panel.rows["rust_on"].field.isChecked() is \
        w.controller.document.graph.nodes["rust_on"].settings["value"]
