"""File › Export glTF / MaterialX / baked textures / HLSL and MSL, and File › Import MaterialX,
in the editor: the same outputs as the command line, checked by the same references."""

from __future__ import annotations

import pytest
from test_app_support import app_env, make_window  # noqa: F401 - fixture

from matedit.resources import graphs_dir
from tests.interop_tools import validate_gltf

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]
SAMPLE = graphs_dir() / "materials" / "mossy_stone.json"


def test_file_menu_offers_the_interop_entries(qtbot):
    w = make_window(qtbot, SAMPLE)
    file_menu = w.menuBar().actions()[0].menu()
    texts = [a.text() for a in file_menu.actions() if not a.isSeparator()]
    i = texts.index("&Export Shaders…")
    # HLSL and MSL are targets of Export Shaders, not an entry of their own
    assert texts[i + 1:i + 6] == ["Export &glTF…", "Export &MaterialX…", "Export &USD…",
                                  "Export &Baked Textures…", "&Import MaterialX or glTF…"]


def test_editor_exports_and_imports(qtbot, tmp_path):
    from matedit.interop.mtlx_export import validate

    w = make_window(qtbot, SAMPLE)
    ia = w.menus.interop
    assert ia.export_gltf(tmp_path / "m.glb", size=16), ia.last_message
    issues = validate_gltf(tmp_path / "m.glb", tmp_path)
    assert issues["numErrors"] == 0, issues["messages"][:5]
    assert ia.export_mtlx(tmp_path / "m.mtlx", size=16), ia.last_message
    ok, msg = validate((tmp_path / "m.mtlx").read_text())
    assert ok, msg
    assert "baked" in ia.last_message
    maps = tmp_path / "maps"
    maps.mkdir()
    assert ia.export_baked(maps, size=8), ia.last_message
    assert sorted(p.name for p in maps.iterdir()) == [
        "mossy_stone_base_color.png", "mossy_stone_normal.png", "mossy_stone_orm.png"]
    assert ia.import_mtlx(tmp_path / "m.mtlx", tmp_path / "back.json"), ia.last_message
    assert w.controller.document.path == tmp_path / "back.json"
    assert any(n.kind == "texture_sample" for n in w.controller.document.graph.nodes.values())
    # the import is arranged before it is saved: no node on another. (The repair of wires
    # through nodes has a time budget: on this 115-node OpenPBR import some are left.)
    from matedit.app.canvas.arrange import layout_problems

    assert [p for p in layout_problems(w.canvas.scene()) if p.startswith("nodes ")] == []


def test_editor_imports_gltf_with_its_embedded_images(qtbot, tmp_path):
    w = make_window(qtbot, SAMPLE)
    ia = w.menus.interop
    assert ia.export_gltf(tmp_path / "m.glb", size=16), ia.last_message
    assert ia.import_mtlx(tmp_path / "m.glb", tmp_path / "back.json"), ia.last_message
    assert w.controller.document.path == tmp_path / "back.json"
    written = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("back"))
    assert written == ["back.json", "back_image0.png", "back_image1.png", "back_image2.png"]
    from matedit.app.canvas.arrange import layout_problems

    assert layout_problems(w.canvas.scene()) == []
    assert any("occlusionTexture" in p.message for p in w.problems.imported)


def test_editor_import_error_names_the_node(qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    src = tmp_path / "bad.mtlx"
    src.write_text('<?xml version="1.0"?>\n<materialx version="1.39">'
                   '<nodegraph name="NG"><noise3d name="lumpy" type="float"/>'
                   '<output name="o" type="float" nodename="lumpy"/></nodegraph>'
                   '<standard_surface name="S" type="surfaceshader"><input name="metalness"'
                   ' type="float" nodegraph="NG" output="o"/></standard_surface>'
                   '<surfacematerial name="M" type="material"><input name="surfaceshader" '
                   'type="surfaceshader" nodename="S"/></surfacematerial></materialx>\n')
    shown = []
    monkeypatch.setattr(QMessageBox, "critical", lambda *a: shown.append(a[2]))
    w = make_window(qtbot, SAMPLE)
    assert not w.menus.interop.import_mtlx(src, tmp_path / "x.json")
    assert shown and "NG/lumpy" in shown[0] and "noise3d" in shown[0]
    assert not (tmp_path / "x.json").exists()
    assert w.controller.document.path == SAMPLE


def test_export_shaders_dialog_offers_every_compile_target(qtbot, tmp_path):
    """Every `matedit compile --target` choice is a box in File › Export Shaders, and the
    dialog writes byte-for-byte what `matedit compile --target all` writes."""
    import argparse

    from matedit.app.export_dialog import ExportDialog
    from matedit.cli import main
    from matedit.commands.compile import register
    from matedit.interop.cross import available

    sub = argparse.ArgumentParser().add_subparsers()
    register(sub)
    (compile_parser,) = sub.choices.values()
    (choices,) = [a.choices for a in compile_parser._actions if a.dest == "target"]
    w = make_window(qtbot, SAMPLE)
    dlg = ExportDialog(w.controller.document, w.controller.resolver, w)
    assert set(dlg.boxes) == set(choices) - {"all"}
    if not available():
        pytest.skip("glslang-tools, spirv-tools or spirv-cross missing: only the GLSL targets")
    assert dlg.boxes["hlsl"].isEnabled() and dlg.boxes["msl"].isEnabled()
    for box in dlg.boxes.values():
        box.setChecked(True)
    dlg.folder.setText(str(tmp_path / "dialog"))
    assert dlg.run_export()
    assert main(["compile", str(SAMPLE), "-o", str(tmp_path / "cli"), "--target", "all"]) == 0
    ours = {p.name: p.read_bytes() for p in (tmp_path / "dialog").iterdir()}
    theirs = {p.name: p.read_bytes() for p in (tmp_path / "cli").iterdir()}
    assert "mossy_stone.frag.hlsl" in ours and "mossy_stone.vert.metal" in ours
    assert ours == theirs


def test_export_shaders_dialog_greys_hlsl_and_msl_without_spirv_cross(qtbot, tmp_path,
                                                                     monkeypatch):
    """With spirv-cross off PATH the HLSL/MSL boxes are greyed (a remembered choice of them
    is not exported) and the tooltip names the Debian package."""
    import os
    import shutil

    from PySide6.QtCore import QSettings

    from matedit.app.export_dialog import TARGETS_KEY, ExportDialog

    bindir = tmp_path / "bin"
    bindir.mkdir()
    for name in ("glslangValidator", "spirv-val"):
        if shutil.which(name):
            os.symlink(shutil.which(name), bindir / name)
    QSettings().setValue(TARGETS_KEY, ["glsl330", "hlsl"])
    monkeypatch.setenv("PATH", str(bindir))
    w = make_window(qtbot, SAMPLE)
    dlg = ExportDialog(w.controller.document, w.controller.resolver, w)
    for t in ("hlsl", "msl"):
        box = dlg.boxes[t]
        assert not box.isEnabled() and not box.isChecked()
        assert "Debian package spirv-cross" in box.toolTip()
        assert "apt-get install spirv-cross" in box.toolTip()
    assert dlg.boxes["glsl330"].isEnabled() and dlg.targets() == ["glsl330"]
    dlg.folder.setText(str(tmp_path / "out"))
    assert dlg.run_export()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "mossy_stone.glsl330.frag", "mossy_stone.glsl330.vert", "mossy_stone.reflection.json"]


def test_editor_import_of_several_materials_asks_which(qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QInputDialog

    from tests.test_interop_mtlx import MATERIALS, _several

    src = tmp_path / "many.mtlx"
    src.write_text(_several())
    asked = []

    def pick(parent, title, label, items, current, editable):
        asked.append(list(items))
        return pick.answer

    monkeypatch.setattr(QInputDialog, "getItem", pick)
    w = make_window(qtbot, SAMPLE)
    ia = w.menus.interop
    pick.answer = ("", False)  # cancelled: nothing imported
    assert not ia.import_mtlx(src, tmp_path / "none.json")
    assert not (tmp_path / "none.json").exists()
    pick.answer = ("blue", True)
    assert ia.import_mtlx(src, tmp_path / "blue.json"), ia.last_message
    assert asked == [list(MATERIALS)] * 2
    doc = w.controller.document
    assert doc.path == tmp_path / "blue.json"
    (surface,) = [n for n in doc.graph.nodes.values() if n.kind == "make_attributes"]
    assert surface.values["baseColor"] == pytest.approx(list(MATERIALS["blue"]))


def _one_material_mtlx(name: str) -> str:
    return ('<?xml version="1.0"?>\n<materialx version="1.39">'
            f'<standard_surface name="S" type="surfaceshader"><input name="base_color" '
            'type="color3" value="0.2, 0.4, 0.8"/></standard_surface>'
            f'<surfacematerial name="{name}" type="material"><input name="surfaceshader" '
            'type="surfaceshader" nodename="S"/></surfacematerial></materialx>\n')


def test_editor_import_proposes_a_new_name_and_never_replaces_the_open_document(
        qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QFileDialog

    from matedit.app import file_dialogs
    from matedit.app.document_actions import new_material
    from matedit.graph.commands import SetLabel
    from matedit.io.document import save

    doc = new_material()
    doc.name = "tile"
    save(doc, tmp_path / "tile.json")
    mine = tmp_path / "tile.json"
    before = mine.read_bytes()
    (tmp_path / "tile_2.json").write_text("{}")  # taken too: the proposal skips it
    src = tmp_path / "tile.mtlx"
    src.write_text(_one_material_mtlx("tile"))  # its material's name is the open file's
    w = make_window(qtbot, mine)
    assert w.controller.push(SetLabel("out", "unsaved edit"))

    asked = []
    monkeypatch.setattr(file_dialogs, "save_file",
                        lambda parent, caption, directory, filter: (asked.append(directory)
                                                                    or answer[0], ""))
    answer = [str(mine)]  # the artist picks the open document's own file anyway
    assert not w.menus.interop.import_mtlx(src)
    assert asked == [str(tmp_path / "tile_3.json")]  # a new name, in the document's folder
    assert w.shown_errors and "open in the editor" in w.shown_errors[-1][1]
    assert "tile.json" in w.shown_errors[-1][1]
    assert mine.read_bytes() == before  # never replaced
    assert w.controller.document.path == mine and w.controller.dirty
    assert w.controller.document.graph.nodes["out"].label == "unsaved edit"
    # Asked without a dialog, the same refusal.
    assert not w.menus.interop.import_mtlx(src, mine)
    assert mine.read_bytes() == before and w.controller.dirty

    # An existing file other than the open document: the save dialog asks before replacing.
    dlg = file_dialogs.make_dialog(None, "save", str(tmp_path), mode="save")
    assert not dlg.testOption(QFileDialog.Option.DontConfirmOverwrite)
    dlg.deleteLater()
    answer[0] = asked[0]  # the proposal, taken
    assert w.menus.interop.import_mtlx(src), w.menus.interop.last_message
    assert w.controller.document.path == tmp_path / "tile_3.json"
    assert mine.read_bytes() == before


def test_editor_import_lists_the_warnings_and_puts_them_in_diagnostics(qtbot, tmp_path):
    """The same `warning:` lines as `matedit import`: shown in a message and in Diagnostics
    while the imported material is open, gone when another document is opened."""
    from pathlib import Path

    from matedit.interop.mtlx_import import import_mtlx

    src = Path(__file__).parent / "data" / "mtlx" / "ss_coated_copper.mtlx"
    expect: list[str] = []
    import_mtlx(src, tmp_path / "ref.json", None, expect)
    assert len(expect) == 5
    w = make_window(qtbot, SAMPLE)
    ia = w.menus.interop
    assert ia.import_mtlx(src, tmp_path / "copper.json"), ia.last_message
    assert ia.import_report is not None and ia.import_report.isVisible()
    assert all(m in ia.import_report.text() for m in expect)
    rows = [p for p in w.diagnostics.problems if p.source == "import"]
    assert [p.message for p in rows] == expect and all(p.severity == "warning" for p in rows)
    texts = [w.diagnostics.topLevelItem(i).text(3)
             for i in range(w.diagnostics.topLevelItemCount())]
    assert all(m in texts for m in expect)
    ia.import_report.close()
    assert w.actions.open(SAMPLE, ask=False)
    assert not [p for p in w.diagnostics.problems if p.source == "import"]
