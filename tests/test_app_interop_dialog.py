"""File › Export glTF / MaterialX / USD / Baked Textures' options dialog
(matedit.app.interop_dialog): it runs `matedit export`'s own functions, so what it writes is
held to what the command writes and to the same references (usd-core's validators,
MaterialX's), on a material tab and on an instance tab. The dialog is driven through its
fields and `run_export()`, never shown modally."""

from __future__ import annotations

import os
import re
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_app_support import app_env, make_window  # noqa: F401 - fixture

from matedit.resources import graphs_dir

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]
SAMPLE = graphs_dir() / "materials" / "mossy_stone.json"
CHECKED = graphs_dir() / "materials" / "dusty_plastic.json"
INSTANCE = graphs_dir() / "instances" / "worn_paint_red.json"
FIGURE = re.compile(r"round trip: mean ΔE (\d+\.\d\d) max ΔE (\d+\.\d\d) "
                    r"\(CIEDE2000 on the display image\)")


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *map(str, args)],
                          capture_output=True, text=True)


def test_usd_export_at_256_passes_usd_cores_validators(qtbot, tmp_path):
    pytest.importorskip("pxr")
    from test_interop_usd import validation_errors

    w = make_window(qtbot, SAMPLE)
    dlg = w.menus.interop.export_dialog("usd")
    assert dlg is not None and dlg.check is not None  # --check reads the preview back
    assert dlg.size.currentData() == 1024  # the command's default for USD
    dlg.set_output(tmp_path / "m.usdz")
    assert dlg.arkit.isEnabled()  # --arkit: a .usdz only
    dlg.set_output(tmp_path / "m.usda")
    assert not dlg.arkit.isEnabled()
    dlg.arkit.setChecked(True)
    assert not dlg.options().arkit
    dlg.arkit.setChecked(False)
    dlg.size.setCurrentIndex(dlg.size.findData(256))
    assert dlg.run_export(), dlg.result.toPlainText()
    out = tmp_path / "m.usda"
    assert out in dlg.written and out.is_file()
    assert validation_errors(out) == []
    pngs = [p for p in dlg.written if p.suffix == ".png"]
    assert pngs, dlg.written
    for p in pngs:  # the PNG header's width and height
        head = p.read_bytes()[:24]
        assert head[:8] == b"\x89PNG\r\n\x1a\n", p
        assert struct.unpack(">II", head[16:24]) == (256, 256), p
    assert dlg.result.toPlainText().startswith("Exported m.usda")


def test_materialx_gltf_pbr_with_png_maps_and_remembered(qtbot, tmp_path):
    import MaterialX as mx

    w = make_window(qtbot, SAMPLE)
    ia = w.menus.interop
    dlg = ia.export_dialog("mtlx")
    assert dlg.size.currentData() == 512  # the command's default for the MaterialX bakes
    dlg.set_output(tmp_path / "m.mtlx")
    dlg.set_size(32)
    dlg.surface.setCurrentIndex(dlg.surface.findData("gltf_pbr"))
    dlg.map_format.setCurrentIndex(dlg.map_format.findData("png"))
    assert dlg.run_export(), dlg.result.toPlainText()
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(tmp_path / "m.mtlx"))
    assert [n.getCategory() for n in doc.getNodes() if n.getType() == "surfaceshader"] == \
        ["gltf_pbr"]
    files = [n.getInputValue("file") for n in doc.traverseTree()
             if isinstance(n, mx.Node) and n.getCategory() == "image"]
    assert files and all(str(f).endswith(".png") for f in files), files
    assert all((tmp_path / str(f)).is_file() for f in files)
    # the command's notes, in the result area and in Diagnostics
    text = dlg.result.toPlainText()
    assert "note: node stack_noise: baked to an image" in text
    assert any(p.source == "export" and p.message.startswith("node stack_noise")
               for p in w.problems.exported)
    # the options are the next dialog's (QSettings)
    again = ia.export_dialog("mtlx")
    assert again.surface.currentData() == "gltf_pbr"
    assert again.size.currentData() == 32
    assert again.output() == tmp_path / "mossy_stone.mtlx"  # the folder; the material's name
    # zip leaves no .mtlx to read back: no check then
    again.zip.setChecked(True)
    assert not again.check.isEnabled()
    again.zip.setChecked(False)
    assert again.check.isEnabled()


def test_check_round_trip_shows_the_commands_figure(qtbot, tmp_path):
    w = make_window(qtbot, CHECKED)
    ia = w.menus.interop
    (tmp_path / "gui").mkdir()
    assert ia.export_gltf(tmp_path / "gui" / "m.glb", size=64, check=True), ia.last_message
    line = ia.dialog.round_trip_line()
    m = FIGURE.search(line)
    assert m, ia.dialog.result.toPlainText()
    mean, worst = float(m.group(1)), float(m.group(2))
    assert 0.0 <= mean <= worst
    assert line in ia.dialog.result.toPlainText()
    assert any(FIGURE.search(p.message) for p in w.problems.exported)
    # the same figure as `matedit export --check` on the same file, size and check size
    r = cli("export", CHECKED, "-o", tmp_path / "m.glb", "--size", "64", "--check")
    assert r.returncode == 0, r.stderr
    theirs = FIGURE.search(r.stderr)
    assert theirs, r.stderr
    # tolerance: the two runs render alike; llvmpipe is deterministic, 0.01 is one digit
    assert abs(float(theirs.group(1)) - mean) <= 0.01
    assert abs(float(theirs.group(2)) - worst) <= 0.01


def test_instance_tab_exports_the_instances_resolved_material(qtbot, tmp_path):
    import MaterialX as mx

    w = make_window(qtbot, SAMPLE)
    editor = w.instances.open(str(INSTANCE))
    assert editor is not None and w.documents.current.editor is editor
    ia = w.menus.interop
    (tmp_path / "gui").mkdir()
    (tmp_path / "cli").mkdir()
    assert ia.export_mtlx(tmp_path / "gui" / "paint.mtlx", size=16), ia.last_message
    assert ia.dialog.windowTitle() == "Export MaterialX (instance)"
    r = cli("export", INSTANCE, "-o", tmp_path / "cli" / "paint.mtlx", "--size", "16")
    assert r.returncode == 0, r.stderr

    def read(path: Path):
        d = mx.createDocument()
        mx.readFromXmlFile(d, str(path))
        return d

    ours, theirs = read(tmp_path / "gui" / "paint.mtlx"), read(tmp_path / "cli" / "paint.mtlx")
    assert [m.getName() for m in ours.getMaterialNodes()] == [f"M_{INSTANCE.stem}"]
    assert [m.getName() for m in ours.getMaterialNodes()] == \
        [m.getName() for m in theirs.getMaterialNodes()]

    def values(d):
        return {(e.getParent().getName(), e.getName()): e.getValueString()
                for e in d.traverseTree() if isinstance(e, mx.Input) and e.getValueString()}

    assert values(ours) == values(theirs)
    assert values(ours)  # there are parameter values to compare
    # the parent material's export differs: it is the instance's, not the material behind
    assert ia.export_mtlx(tmp_path / "gui" / "other.mtlx", size=16) and \
        ia.dialog.target.instance
    w.documents.bar.setCurrentIndex(0)  # the material tab
    assert ia.export_mtlx(tmp_path / "gui" / "stone.mtlx", size=16), ia.last_message
    assert not ia.dialog.target.instance
    assert [m.getName() for m in read(tmp_path / "gui" / "stone.mtlx").getMaterialNodes()] \
        == [f"M_{SAMPLE.stem}"]


def test_a_planted_link_at_the_output_name_is_never_written_through(qtbot, tmp_path):
    shutil.copytree(graphs_dir(), tmp_path / "graphs")  # the layers and functions it reads
    src = tmp_path / "graphs" / "materials" / "stone.json"
    shutil.copy(CHECKED, src)
    before = src.read_bytes()
    w = make_window(qtbot, src)
    ia = w.menus.interop
    out = src.with_suffix(".glb")
    os.symlink(src, out)  # a link to the document itself: refused, as the command refuses
    assert not ia.export_gltf(out, size=16)
    text = ia.dialog.result.toPlainText()
    assert "Nothing more was written" in text and "refusing to write over the document" in text
    assert src.read_bytes() == before and out.is_symlink()
    assert any(p.severity == "error" for p in w.problems.exported)
    victim = tmp_path / "victim.bin"
    victim.write_bytes(b"precious")
    link = tmp_path / "other.glb"
    os.symlink(victim, link)  # a link elsewhere: replaced by the export, never followed
    assert ia.export_gltf(link, size=16), ia.last_message
    assert victim.read_bytes() == b"precious"
    assert not link.is_symlink() and link.read_bytes()[:4] == b"glTF"


def test_baked_textures_in_exr(qtbot, tmp_path):
    w = make_window(qtbot, SAMPLE)
    ia = w.menus.interop
    assert ia.export_baked(tmp_path, size=8, format="exr"), ia.last_message
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "mossy_stone_base_color.exr", "mossy_stone_normal.exr", "mossy_stone_orm.exr"]


def test_an_instance_whose_override_does_not_resolve_is_refused(qtbot, tmp_path):
    import json

    bad = tmp_path / "bad.json"
    data = json.loads(INSTANCE.read_text())
    data["parent"] = str((INSTANCE.parent / data["parent"]).resolve())
    data["parameters"]["wear_amount"] = "lots"
    bad.write_text(json.dumps(data))
    w = make_window(qtbot, SAMPLE)
    assert w.instances.open(str(bad)) is not None
    ia = w.menus.interop
    assert not ia.export_mtlx(tmp_path / "bad.mtlx", size=16)
    assert w.shown_errors and "wear_amount" in w.shown_errors[-1][1], w.shown_errors
    assert "wear_amount" in ia.last_message and not (tmp_path / "bad.mtlx").exists()


def test_usdz_in_apples_profile_with_its_round_trip(qtbot, tmp_path):
    """The dialog's ARKit profile and check are the command's: the package holds no
    MaterialX shader, and the figure is `matedit export --arkit --check`'s (within 0.01)."""
    pytest.importorskip("pxr")
    from test_interop_usd import arkit_violations

    w = make_window(qtbot, CHECKED)
    ia = w.menus.interop
    (tmp_path / "gui").mkdir()
    assert ia.export_usd(tmp_path / "gui" / "m.usdz", size=64, check=True, arkit=True), \
        ia.last_message
    got = FIGURE.search(ia.dialog.round_trip_line())
    assert got, ia.last_message
    assert "ARKit profile" in ia.last_message
    assert arkit_violations(tmp_path / "gui" / "m.usdz") == []
    r = cli("export", CHECKED, "-o", tmp_path / "m.usdz", "--size", "64", "--check",
            "--arkit")
    want = FIGURE.search(r.stderr)
    assert r.returncode == 0 and want, r.stderr
    assert abs(float(got.group(1)) - float(want.group(1))) <= 0.01


def test_the_mesh_choice_is_the_commands_mesh(qtbot, tmp_path):
    """The dialog's Mesh (a built-in or an OBJ file) bakes on and ships the mesh `matedit
    export --mesh` does: the same POSITION accessor (count, bounds within 1e-6)."""
    import pygltflib

    obj = tmp_path / "quad.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                   "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
    w = make_window(qtbot, CHECKED)
    ia = w.menus.interop

    def positions(path):
        g = pygltflib.GLTF2().load(str(path))
        acc = g.accessors[g.meshes[0].primitives[0].attributes.POSITION]
        return acc.count, np.array(acc.min), np.array(acc.max)

    for spec, name in (("cube", "cube"), (str(obj), "quad")):
        (tmp_path / name).mkdir()
        dlg = ia.export_dialog("gltf")
        assert dlg.mesh.itemText(0) == "The material's preview mesh"
        dlg.set_mesh(spec)
        assert dlg.options().mesh == spec
        dlg.set_output(tmp_path / name / "gui.glb")
        dlg.set_size(256)
        assert dlg.run_export(), dlg.result.toPlainText()
        r = cli("export", CHECKED, "-o", tmp_path / name / "cli.glb", "--size", "256",
                "--mesh", spec)
        assert r.returncode == 0, r.stderr
        got, want = positions(tmp_path / name / "gui.glb"), positions(tmp_path / name /
                                                                       "cli.glb")
        assert got[0] == want[0]
        np.testing.assert_allclose(got[1], want[1], atol=1e-6)
        np.testing.assert_allclose(got[2], want[2], atol=1e-6)
    assert positions(tmp_path / "quad" / "gui.glb")[0] == 4
