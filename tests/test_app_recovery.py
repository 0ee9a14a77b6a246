"""Crash recovery never loses work: a recovery file per unsaved document, every one offered at
start-up (with or without a file argument), deleted only once the artist has answered."""

from __future__ import annotations

import json
import os
import shutil

import pytest
import shiboken6
from graphs_util import EDITOR_GRAPHS
from PySide6.QtCore import QPointF
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.graph.commands import SetLabel, SetValue
from matedit.io.document import dumps
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


@pytest.fixture
def graphs(tmp_path):
    root = tmp_path / "graphs"
    shutil.copytree(graphs_dir(), root)
    shutil.copytree(EDITOR_GRAPHS, root, dirs_exist_ok=True)  # the frozen editor sample
    return root


def _crash(w) -> None:
    """The editor dies: no close event, no prompt, the autosaves stay."""
    shiboken6.delete(w)


KEEP_ALL = {"recover_all": lambda entries: {e.rec: "keep" for e in entries}}


def _untitled_with_output(qtbot, label: str):
    w = make_window(qtbot, track=False, answers=KEEP_ALL)  # earlier crashes stay put
    nid = w.tabs.material.canvas.add_node_at("material_output", QPointF(0, 0))
    assert w.controller.push(SetLabel(nid, label))
    assert w.actions.autosave() is not None
    return w, dumps(w.controller.document)


def _recover_everything(seen: list):
    def answer(entries):
        seen.extend(entries)
        return {e.rec: "recover" for e in entries}
    return answer


def test_two_untitled_documents_autosave_to_files_of_their_own(qtbot):
    a, text_a = _untitled_with_output(qtbot, "first")
    b, text_b = _untitled_with_output(qtbot, "second")
    ra, rb = a.actions.recovery_file(), b.actions.recovery_file()
    assert ra != rb and ra.is_file() and rb.is_file()
    assert ra.read_text() == text_a and rb.read_text() == text_b
    old = a.actions.recovery_file()
    assert a.actions.new()  # discarded on purpose: a new untitled document, a new file
    assert a.actions.recovery_file() != old and not old.exists()
    for w in (a, b):
        w.actions.ask_save_changes = lambda _n: "discard"
        w.close()
    assert not rb.exists()


def test_start_without_a_file_offers_every_recovery_file(qtbot, graphs):
    sample = graphs / "materials" / "rusty_painted_metal.json"
    fn = graphs / "functions" / "uv_tile_rotate.json"
    u, untitled_text = _untitled_with_output(qtbot, "untitled work")
    _crash(u)
    w = make_window(qtbot, sample, track=False,
                    answers={"recover_all": lambda es: {e.rec: "keep" for e in es}})
    assert w.controller.push(SetValue("amount", "value", 0.9))
    w.actions.autosave()
    tab = w.tabs.open_function(fn)
    node = sorted(tab.controller.document.graph.nodes)[0]
    assert tab.controller.push(SetLabel(node, "edited in a tab"))
    tab.actions.autosave()
    sample_text = dumps(w.controller.document)
    _crash(w)

    seen: list = []
    w2 = make_window(qtbot, answers={"recover_all": _recover_everything(seen)})
    assert len(seen) == 3  # both materials and the function, one question
    assert {e.is_function for e in seen} == {True, False}
    # The oldest material (the untitled one) opens, unsaved; the other in a tab of its own.
    docs = w2.documents
    assert docs.count() == 2 and docs.index == 0
    assert dumps(w2.controller.document) == untitled_text and w2.controller.dirty
    assert docs.names()[1].endswith("*")
    docs.activate(1)
    assert dumps(w2.controller.document) == sample_text and w2.controller.dirty
    assert w2.controller.document.path == sample
    docs.activate(0)
    fn_tabs = [t for t in w2.tabs.all_tabs() if t.is_function]
    assert len(fn_tabs) == 1 and fn_tabs[0].controller.dirty
    assert fn_tabs[0].controller.document.graph.nodes[node].label == "edited in a tab"
    # Recovered files stay until the work is saved: a second crash loses nothing.
    assert all(e.rec.is_file() for e in seen)
    docs.activate(1)
    assert w2.actions.save()
    assert not next(e for e in seen if e.document == sample).rec.exists()
    assert next(e for e in seen if e.document is None).rec.is_file()  # still unsaved work


def test_start_with_a_file_argument_still_offers_the_other_recovery_files(qtbot, graphs):
    u, untitled_text = _untitled_with_output(qtbot, "left over")
    _crash(u)
    seen: list = []
    car = graphs / "materials" / "car_paint.json"
    w = make_window(qtbot, car, answers={"recover_all": _recover_everything(seen)})
    assert len(seen) == 1 and seen[0].document is None
    assert w.controller.document.path == car and not w.controller.dirty  # the file asked for
    assert w.documents.count() == 2  # the left-over untitled work: a tab of its own
    w.documents.activate(1)
    assert dumps(w.controller.document) == untitled_text and w.controller.dirty


def test_recovery_files_are_deleted_only_once_the_artist_has_answered(qtbot):
    u, _ = _untitled_with_output(qtbot, "maybe later")
    rec = u.actions.recovery_file()
    _crash(u)
    w = make_window(qtbot, answers={"recover_all": lambda entries: {}})  # dialog closed
    assert rec.is_file()
    w.close()
    w = make_window(qtbot, answers={"recover_all": lambda es: {e.rec: "keep" for e in es}})
    assert rec.is_file() and not w.controller.dirty
    w.close()
    seen: list = []
    make_window(qtbot, answers={"recover_all": lambda es: seen.extend(es) or {
        e.rec: "discard" for e in es}})
    assert [e.rec for e in seen] == [rec]  # still offered after two starts
    assert not rec.exists() and not rec.with_suffix(".meta").exists()


def test_the_autosave_of_an_editor_still_running_is_not_offered(qtbot):
    u, _ = _untitled_with_output(qtbot, "another editor's")
    rec = u.actions.recovery_file()
    meta = json.loads(rec.with_suffix(".meta").read_text())
    assert meta["pid"] == os.getpid() and meta["name"] == "Untitled"
    _crash(u)
    meta["pid"] = os.getppid()  # a live process: another editor writing it right now
    rec.with_suffix(".meta").write_text(json.dumps(meta))
    seen: list = []
    make_window(qtbot, answers={"recover_all": lambda es: seen.extend(es) or {}})
    assert seen == [] and rec.is_file()


def test_an_unreadable_recovery_file_is_set_aside_not_deleted(qtbot):
    u, _ = _untitled_with_output(qtbot, "soon broken")
    rec = u.actions.recovery_file()
    _crash(u)
    rec.write_text("{ not json")
    w = make_window(qtbot, answers={"recover_all": lambda es: {e.rec: "recover" for e in es}})
    assert w.shown_errors and "unreadable" in w.shown_errors[0][1]
    assert rec.with_name(rec.name + ".unreadable").is_file()
    settle(qtbot, w)


def test_the_recovery_dialog_recovers_the_checked_and_discards_the_rest(qtbot):
    from PySide6.QtCore import Qt

    from matedit.app.recovery import DISCARD, KEEP, RECOVER, RecoveryDialog, find_recoveries

    for label in ("one", "two"):
        u, _ = _untitled_with_output(qtbot, label)
        _crash(u)
    entries = find_recoveries()
    assert len(entries) == 2
    dlg = RecoveryDialog(entries)
    qtbot.addWidget(dlg)
    assert set(dlg.decision.values()) == {KEEP}  # closing the dialog keeps everything
    assert all("never saved" in dlg.list.item(i).text() for i in range(2))
    dlg.list.item(1).setCheckState(Qt.CheckState.Unchecked)
    dlg._recover()
    assert [dlg.decision[e.rec] for e in entries] == [RECOVER, DISCARD]
