"""Files in the editor: autosave and crash recovery, the close prompt, bad files, recent
files, shader export, the dock layout, and `matedit [FILE]` opening the editor."""

from __future__ import annotations

import shutil

import pytest
import shiboken6
from test_app_support import app_env, make_window, settle  # noqa: F401 - fixture

from matedit.graph.commands import SetValue
from matedit.io.document import dumps, load
from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]

SAMPLE = graphs_dir() / "materials" / "rusty_painted_metal.json"


@pytest.fixture
def sample_copy(tmp_path):
    """The sample material beside copies of the graphs it references."""
    root = tmp_path / "graphs"
    shutil.copytree(graphs_dir(), root)
    return root / "materials" / "rusty_painted_metal.json"


def test_a_crash_is_recovered_from_the_autosave(qtbot, sample_copy):
    from matedit.app.document_actions import recovery_path

    w = make_window(qtbot, sample_copy, track=False)
    assert w.controller.push(SetValue("amount", "value", 0.9))
    edited = dumps(w.controller.document)
    rec = w.actions.autosave()
    assert rec is not None and rec == recovery_path(sample_copy) and rec.is_file()
    assert w.actions.autosave() is None  # nothing new to write
    # The crash: the window is destroyed without a close event.
    shiboken6.delete(w)
    qtbot.wait(5)
    assert rec.is_file()

    asked = []
    w2 = make_window(qtbot, sample_copy,
                     answers={"recover": lambda p, r: asked.append((p, r)) or True})
    assert asked and asked[0][0] == sample_copy
    assert dumps(w2.controller.document) == edited
    assert w2.controller.dirty and w2.isWindowModified()
    assert load(sample_copy).graph.nodes["amount"].values["value"] == 0.45  # file untouched
    assert w2.actions.save()
    assert not rec.exists()  # a clean save removes the autosave
    assert load(sample_copy).graph.nodes["amount"].values["value"] == 0.9


def test_declining_recovery_drops_the_autosave(qtbot, sample_copy):
    w = make_window(qtbot, sample_copy, track=False)
    w.controller.push(SetValue("amount", "value", 0.1))
    rec = w.actions.autosave()
    shiboken6.delete(w)
    w2 = make_window(qtbot, sample_copy, answers={"recover": False})
    assert w2.controller.document.graph.nodes["amount"].values["value"] == 0.45
    assert not w2.controller.dirty and not rec.exists()


def test_close_with_unsaved_changes_prompts(qtbot, sample_copy):
    from matedit.app.document_actions import recovery_path

    w = make_window(qtbot, sample_copy, show=False)
    asked = []
    answer = {"value": "cancel"}
    w.actions.ask_save_changes = lambda name: asked.append(name) or answer["value"]
    assert w.close()  # nothing to save: no question
    assert asked == []
    w = make_window(qtbot, sample_copy)
    w.actions.ask_save_changes = lambda name: asked.append(name) or answer["value"]
    w.controller.push(SetValue("amount", "value", 0.2))
    assert w.windowTitle().startswith("rusty_painted_metal.json[*]") and w.isWindowModified()
    w.actions.autosave()
    assert not w.close()  # cancel keeps the window and the work
    assert asked == ["rusty_painted_metal.json"] and w.controller.dirty
    answer["value"] = "save"
    assert w.close()
    assert load(sample_copy).graph.nodes["amount"].values["value"] == 0.2
    assert not recovery_path(sample_copy).exists()


def test_a_bad_file_shows_a_message_and_keeps_the_document(qtbot, tmp_path):
    w = make_window(qtbot, SAMPLE)
    before = dumps(w.controller.document)
    bad = tmp_path / "broken.json"
    bad.write_text('{"format": "matedit.material", "version": 1, "nodes": [}')
    assert not w.actions.open(bad)
    assert not w.actions.open(tmp_path / "missing.json")
    newer = tmp_path / "newer.json"
    newer.write_text('{"format": "matedit.material", "version": 999}')
    assert not w.actions.open(newer)
    assert dumps(w.controller.document) == before
    texts = [t for _, t in w.shown_errors]
    assert "broken.json" in texts[0] and "not valid JSON" in texts[0]
    assert "missing.json" in texts[1] and "not found" in texts[1]
    assert "newer" in texts[2]


def test_recent_files_and_new_document(qtbot, sample_copy):
    from matedit.app.document_actions import DocumentActions

    w = make_window(qtbot, sample_copy)
    assert DocumentActions.recent_files()[0] == str(sample_copy.resolve())
    w.menus.recent.fill()
    assert any(a.text() == sample_copy.name for a in w.menus.recent.actions())
    assert w.actions.new()
    nodes = w.controller.document.graph.nodes  # a new material starts with its output
    assert [n.kind for n in nodes.values()] == ["material_output"]
    assert w.controller.document.path is None and not w.controller.dirty
    assert w.windowTitle().startswith("Untitled")


def test_export_writes_the_same_files_as_matedit_compile(qtbot, tmp_path):
    from matedit.app.export_dialog import ExportDialog
    from matedit.cli import main
    from matedit.interop.export import export_shaders

    w = make_window(qtbot, SAMPLE)
    ours = tmp_path / "ours"
    written = export_shaders(w.controller.document, w.controller.resolver,
                             ["glsl330", "essl300"], ours)
    theirs = tmp_path / "theirs"
    assert main(["compile", str(SAMPLE), "-o", str(theirs), "--target", "glsl330"]) == 0
    names = {p.name for p in written}
    assert {"rusty_painted_metal.glsl330.frag", "rusty_painted_metal.glsl330.vert",
            "rusty_painted_metal.essl300.frag", "rusty_painted_metal.reflection.json"} <= names
    for name in ("rusty_painted_metal.glsl330.frag", "rusty_painted_metal.glsl330.vert"):
        assert (ours / name).read_text() == (theirs / name).read_text()
    dlg = ExportDialog(w.controller.document, w.controller.resolver, w)
    dlg.boxes["glsl450"].setChecked(True)
    dlg.folder.setText(str(tmp_path / "dialog"))
    assert dlg.run_export()
    assert (tmp_path / "dialog" / "rusty_painted_metal.glsl450.frag").is_file()


def test_export_next_to_the_material_keeps_it_and_refuses_a_link_to_it(qtbot, tmp_path,
                                                                      monkeypatch):
    """Exporting into the material's own folder once replaced the material with the
    reflection; now the reflection has its own name, and an output that resolves to the
    document (here a symbolic link planted at an output name) is refused before anything is
    written, with a message box, not an exception."""
    import shutil

    from PySide6.QtWidgets import QMessageBox

    from matedit.app.export_dialog import ExportDialog
    from matedit.io import document as fmt

    folder = tmp_path / "mat"
    shutil.copytree(SAMPLE.parent.parent, folder / "graphs")
    doc_path = folder / "graphs" / "materials" / SAMPLE.name
    before = doc_path.read_bytes()
    w = make_window(qtbot, doc_path)
    dlg = ExportDialog(w.controller.document, w.controller.resolver, w)
    dlg.folder.setText(str(doc_path.parent))
    assert dlg.run_export()
    assert doc_path.read_bytes() == before
    assert fmt.load(doc_path).graph.nodes  # still a material
    stem = SAMPLE.name[:-5]
    assert (doc_path.parent / f"{stem}.reflection.json").is_file()
    trap = tmp_path / "out"
    trap.mkdir()
    (trap / f"{stem}.glsl330.vert").symlink_to(doc_path)
    shown = []
    monkeypatch.setattr(QMessageBox, "critical", lambda *a: shown.append(a[2]))
    dlg.folder.setText(str(trap))
    assert not dlg.run_export()
    assert shown and "refusing to write over the document" in shown[0]
    assert doc_path.read_bytes() == before
    assert not (trap / f"{stem}.glsl330.frag").exists()  # nothing written at all


def test_dock_layout_is_restored(qtbot):
    from matedit.app.main_window import MainWindow

    w = make_window(qtbot, SAMPLE, show=True)
    w.panels.code_dock.show()
    w.panels.history_dock.hide()
    assert w.close()
    w2 = MainWindow(start=False)
    qtbot.addWidget(w2)
    w2.show()
    qtbot.waitExposed(w2)
    assert w2.panels.history_dock.isHidden() and not w2.panels.code_dock.isHidden()
    w2.reset_layout()
    assert not w2.panels.history_dock.isHidden()


def test_matedit_with_a_file_opens_the_editor_and_subcommands_still_work(monkeypatch,
                                                                         capsys, tmp_path):
    import matedit.app.app as app_module
    from matedit.cli import main

    opened = []
    monkeypatch.setattr(app_module, "run", lambda path=None: opened.append(path) or 0)
    assert main([]) == 0
    assert main([str(SAMPLE)]) == 0
    assert opened == [None, str(SAMPLE)]
    assert main([str(tmp_path / "missing.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "missing.json" in err and "Traceback" not in err
    assert main([str(graphs_dir() / "functions" / "rotate_uv.json")]) == 2
    assert main(["validate", str(SAMPLE)]) == 0
    assert len(opened) == 2


def test_a_function_tab_autosaves_and_is_recovered(qtbot, sample_copy):
    fn_path = sample_copy.parent.parent / "functions" / "uv_tile_rotate.json"
    w = make_window(qtbot, sample_copy, track=False)
    tab = w.tabs.open_function(fn_path)
    assert tab is not None and tab.is_function
    node = next(iter(sorted(tab.controller.document.graph.nodes)))
    from matedit.graph.commands import SetLabel

    assert tab.controller.push(SetLabel(node, "edited"))
    assert tab.actions.autosave() is not None
    shiboken6.delete(w)
    w2 = make_window(qtbot, sample_copy)
    tab2 = w2.tabs.open_function(fn_path)
    assert tab2.controller.document.graph.nodes[node].label == "edited"
    assert tab2.controller.dirty
    assert tab2.actions.save()
    assert load(fn_path).graph.nodes[node].label == "edited"
