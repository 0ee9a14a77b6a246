"""Document tabs: several materials in one window, each with its own undo history, dirty
mark, autosave and Save; File › Close, Close All and Save All; closing the window asks about
every tab with unsaved work."""

from __future__ import annotations

import shutil

import pytest
from test_app_support import app_env, make_window, settle  # noqa: F401

from matedit.app.document_actions import recovery_path
from matedit.graph.commands import SetValue
from matedit.io.document import load
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


@pytest.fixture
def two(tmp_path):
    """Two materials in a copy of the built-in library (a shipped file saves as a copy
    elsewhere: not these), with the layers and functions they use beside them."""
    root = tmp_path / "graphs"
    shutil.copytree(graphs_dir(), root)
    return [root / "materials" / f"{name}.json" for name in ("rusty_painted_metal", "velvet")]


def _first_scalar(doc):
    return next(n for n in doc.graph.nodes.values() if n.kind == "scalar_parameter")


def _menu(w, title):
    return next(a.menu() for a in w.menuBar().actions() if a.text() == title)


def test_two_documents_keep_their_own_undo_and_marks(qtbot, two):
    a, b = two
    w = make_window(qtbot, a, show=True)
    docs = w.documents
    assert docs.names() == ["Rusty Painted Metal"] and docs.bar.isVisibleTo(w)
    assert w.open_material(b)
    assert docs.names() == ["Rusty Painted Metal", "Velvet"] and docs.index == 1
    assert w.controller.document.path == b and w.windowTitle().startswith("velvet.json")
    settle(qtbot, w)
    assert w.compiler.current is not None  # the viewport compiles the active tab's material
    velvet_hash = w.compiler.current.structure_hash

    vb = _first_scalar(w.controller.document)
    assert w.controller.push(SetValue(vb.id, "value", 0.91))
    assert docs.names() == ["Rusty Painted Metal", "Velvet*"]

    docs.activate(0)
    settle(qtbot, w)
    assert w.controller.document.path == a and not w.controller.dirty
    assert w.undo_group.activeStack() is w.controller.undo_stack
    assert w.undo_group.activeStack().count() == 0  # Velvet's edit is not undone from here
    assert w.compiler.current is not None
    assert w.compiler.current.structure_hash != velvet_hash
    # the tab left with unsaved work was autosaved as it was left
    assert recovery_path(b).is_file()
    assert load(recovery_path(b)).graph.nodes[vb.id].values["value"] == 0.91
    assert w.controller.push(SetValue("amount", "value", 0.2))
    assert docs.names() == ["Rusty Painted Metal*", "Velvet*"]
    w.undo_group.undo()
    assert w.controller.document.graph.nodes["amount"].values["value"] == 0.45
    w.undo_group.redo()

    docs.activate(1)  # Velvet as it was left: its edit there, undoable
    assert w.controller.document.graph.nodes[vb.id].values["value"] == 0.91
    assert w.undo_group.canUndo()
    w.undo_group.undo()
    assert not w.controller.dirty and docs.names() == ["Rusty Painted Metal*", "Velvet"]

    assert w.open_material(a)  # already open: its tab, not another
    assert docs.count() == 2 and docs.index == 0
    assert w.controller.document.graph.nodes["amount"].values["value"] == 0.2


def test_open_reuses_an_untouched_untitled_tab_and_a_bad_file_leaves_no_tab(qtbot, two,
                                                                            tmp_path):
    w = make_window(qtbot, None, show=True)
    docs = w.documents
    assert docs.names() == ["Untitled"]
    assert w.open_material(two[0])
    assert docs.names() == ["Rusty Painted Metal"]  # the empty Untitled tab was reused
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    assert not w.open_material(bad)
    assert docs.names() == ["Rusty Painted Metal"] and w.controller.document.path == two[0]
    assert w.shown_errors and "bad.json" in w.shown_errors[-1][1]
    new = next(a for a in _menu(w, "&File").actions() if a.objectName() == "file.new")
    new.trigger()
    assert docs.names() == ["Rusty Painted Metal", "Untitled"] and docs.index == 1


def test_close_close_all_and_save_all(qtbot, two, tmp_path):
    a, b = two
    answers = {"save_changes": "cancel"}
    w = make_window(qtbot, a, show=True, answers=answers)
    w.actions.ask_save_changes = lambda name: answers["save_changes"]
    docs = w.documents
    w.open_material(b)
    ids = [x.objectName() for x in _menu(w, "&File").actions()]
    for name in ("file.close", "file.close_all", "file.save_all"):
        assert name in ids

    vb = _first_scalar(w.controller.document)
    w.controller.push(SetValue(vb.id, "value", 0.77))
    docs.activate(0)
    w.controller.push(SetValue("amount", "value", 0.3))
    assert docs.save_all()  # both written, each to its own file
    assert load(a).graph.nodes["amount"].values["value"] == 0.3
    assert load(b).graph.nodes[vb.id].values["value"] == 0.77
    assert docs.names() == ["Rusty Painted Metal", "Velvet"] and docs.index == 0

    w.controller.push(SetValue("amount", "value", 0.6))
    assert not docs.close()  # cancelled: the tab and its edit stay
    assert docs.count() == 2 and w.controller.dirty
    answers["save_changes"] = "discard"
    assert docs.close()
    assert docs.names() == ["Velvet"] and w.controller.document.path == b
    w.documents.new()
    assert docs.close_all()
    assert docs.names() == ["Untitled"] and not w.controller.dirty
    assert load(a).graph.nodes["amount"].values["value"] == 0.3  # discarded, not saved


def test_closing_the_window_asks_about_every_tab_with_unsaved_work(qtbot, two):
    a, b = two
    asked = []
    w = make_window(qtbot, a, show=True)
    w.actions.ask_save_changes = lambda name: asked.append(name) or "cancel"
    w.open_material(b)
    w.controller.push(SetValue(_first_scalar(w.controller.document).id, "value", 0.5))
    w.documents.activate(0)
    w.controller.push(SetValue("amount", "value", 0.9))
    assert not w.close()  # the first tab's question was cancelled: nothing closes
    assert asked == ["rusty_painted_metal.json"] and w.documents.count() == 2
    asked.clear()
    w.actions.ask_save_changes = lambda name: asked.append(name) or "discard"
    assert w.close()
    assert asked == ["rusty_painted_metal.json", "velvet.json"]
    assert not recovery_path(b).exists() and not recovery_path(a).exists()


def test_an_instance_opens_in_a_tab_with_the_windows_undo_and_close(qtbot, two):
    root = two[0].parents[1]
    inst = root / "instances" / "worn_paint_green.json"
    asked = []
    w = make_window(qtbot, two[0], show=True)
    w.actions.ask_save_changes = lambda name: asked.append(name) or "discard"
    docs = w.documents
    assert w.open_material(inst)  # File › Open on an instance: a tab of its own
    assert docs.count() == 2 and docs.index == 1
    (editor,) = w.instances.editors
    assert docs.current.editor is editor and docs.pages.currentWidget() is editor
    assert not editor.isWindow() and docs.names()[1] == editor.name
    assert w.undo_group.activeStack() is editor.undo_stack

    name = next(n for n, p in editor.parameters.items() if p.type == "scalar")
    before = editor.value(name)
    editor.set_value(name, 0.123)
    editor.set_value(name, 0.321)  # one drag: one undo step
    assert editor.dirty and docs.names()[1].endswith("*")
    assert editor.undo_stack.count() == 1
    w.undo_group.undo()  # Edit › Undo in the instance's tab
    assert editor.value(name) == before and not editor.dirty
    w.undo_group.redo()
    assert editor.value(name) == 0.321 and editor.dirty

    docs.activate(0)  # the material: its canvas and its own undo again
    assert docs.pages.currentIndex() == 0 and w.controller.document.path == two[0]
    assert w.undo_group.activeStack() is w.controller.undo_stack
    assert w.open_material(inst) and docs.index == 1  # already open: its tab
    assert docs.close()  # the instance's unsaved override: asked, discarded
    assert asked == [editor.name] and docs.count() == 1 and docs.index == 0
    assert w.controller.document.path == two[0]


def test_opening_a_file_builds_the_canvas_in_a_turn_of_its_own(qtbot, two):
    """The open returns with the old document's items gone and the new one's still to come
    (a turn of the UI work queue of their own: the open, and the items with their first
    paint, are two blocks of the UI thread, not one). An edit made in between is in the
    items once built, and the view frames the graph once it is there."""
    from matedit.app.canvas.node_item import NodeItem
    from matedit.graph.commands import AddNode
    from matedit.graph.model import Node

    a, b = two
    w = make_window(qtbot, a, show=True)
    settle(qtbot, w)
    canvas = w.canvas
    scene = canvas.scene()
    assert scene.settled and set(scene.node_items) == set(w.controller.document.graph.nodes)
    assert w.open_material(b)
    assert not scene.settled and scene.node_items == {}
    assert not any(isinstance(it, NodeItem) for it in scene.items())
    assert not scene.defer_rebuilds  # only while opening
    extra = Node("late_node", "constant", (0.0, 900.0))
    assert w.controller.push(AddNode(extra))  # before the items are built
    qtbot.waitUntil(lambda: scene.settled, timeout=10000)
    graph = w.controller.document.graph
    assert set(scene.node_items) == set(graph.nodes) and "late_node" in scene.node_items
    assert set(scene.wire_items) == set(graph.links)
    # framed once built: every node in view
    view_rect = canvas.mapToScene(canvas.viewport().rect()).boundingRect()
    assert view_rect.contains(scene.nodes_bounding_rect())
    # other edits to the canvas after the build go through as usual
    w.controller.undo_stack.undo()
    assert "late_node" not in scene.node_items
    # switching tabs rebuilds at once, as before
    w.documents.activate(0)
    assert scene.settled and set(scene.node_items) == set(w.controller.document.graph.nodes)
