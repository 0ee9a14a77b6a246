"""`matedit export INSTANCE.json OUT.(gltf|glb|mtlx)` and `matedit bake INSTANCE.json`: the
instance's effective material (its overrides applied to its parent), named after the
instance, checked by the same validators as a material's export (glTF-Validator, MaterialX's
own validate())."""

from __future__ import annotations

import json
import subprocess
import sys

import MaterialX as mx
import numpy as np
import pytest

from matedit.resources import graphs_dir
from tests.interop_tools import validate_gltf

INSTANCE = graphs_dir() / "instances" / "worn_paint_red.json"
SIZE = 16


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


def _overrides():
    data = json.loads(INSTANCE.read_text())
    return data["parameters"]


@pytest.mark.parametrize("suffix", ["gltf", "glb"])
def test_an_instance_exports_to_gltf(tmp_path, suffix):
    out = tmp_path / f"paint.{suffix}"
    r = cli("export", str(INSTANCE), "-o", str(out), "--size", str(SIZE))
    assert r.returncode == 0, r.stderr
    assert "error:" not in r.stderr
    issues = validate_gltf(out, tmp_path)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    if suffix == "gltf":
        doc = json.loads(out.read_text())
        # named after the instance (its file), not after the parent material
        assert [m["name"] for m in doc["materials"]] == [INSTANCE.stem]


def test_an_instance_exports_to_materialx_with_its_overrides(tmp_path):
    out = tmp_path / "paint.mtlx"
    r = cli("export", str(INSTANCE), "-o", str(out), "--size", str(SIZE))
    assert r.returncode == 0, r.stderr
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(out))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    ok, msg = doc.validate()
    assert ok, msg
    assert [m.getName() for m in doc.getMaterialNodes()] == [f"M_{INSTANCE.stem}"]
    ng = doc.getNodeGraphs()[0]
    # the instance's values, not the parent's, on the interface inputs it has (a parameter
    # that only feeds a baked node is in the bake)
    present = {n: v for n, v in _overrides().items() if ng.getInput(n) is not None}
    assert "paint_color" in present
    for name, value in present.items():
        got = [float(x) for x in ng.getInput(name).getValueString().split(",")]
        np.testing.assert_allclose(got, np.ravel([value]), atol=1e-6, err_msg=name)
    parent = json.loads(INSTANCE.read_text())["parent"]
    base = cli("export", str((INSTANCE.parent / parent).resolve()), "-o",
               str(tmp_path / "parent.mtlx"), "--size", str(SIZE))
    assert base.returncode == 0, base.stderr
    pdoc = mx.createDocument()
    mx.readFromXmlFile(pdoc, str(tmp_path / "parent.mtlx"))
    theirs = [float(x) for x in pdoc.getNodeGraphs()[0].getInput("paint_color")
              .getValueString().split(",")]
    assert np.max(np.abs(np.subtract(theirs, present["paint_color"]))) > 0.05  # overridden


def test_an_instance_bakes_and_compiles(tmp_path):
    r = cli("bake", str(INSTANCE), "-o", str(tmp_path / "maps"), "--size", "8")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "maps").iterdir())[0].startswith(
        f"{INSTANCE.stem}_")
    r = cli("compile", str(INSTANCE), "-o", str(tmp_path / "glsl"), "--target", "glsl330")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "glsl" / f"{INSTANCE.stem}.glsl330.frag").exists()


def test_an_instance_with_a_broken_override_is_one_error_line(tmp_path):
    bad = tmp_path / "bad.json"
    data = json.loads(INSTANCE.read_text())
    data["parent"] = str((INSTANCE.parent / data["parent"]).resolve())
    data["parameters"]["wear_amount"] = "lots"
    bad.write_text(json.dumps(data))
    r = cli("export", str(bad), "-o", str(tmp_path / "bad.mtlx"))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "wear_amount" in lines[0]
    assert not (tmp_path / "bad.mtlx").exists()
