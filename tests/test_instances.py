"""Material instances: the file format, its validation, the effective material, and the
command line (validate, compile, render) on instance files."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from graphs_util import link, material, node

from matedit.compiler import compile_all, compile_document
from matedit.io import document as fmt
from matedit.io import instance as inst_io
from matedit.io.document import FileResolver, FormatError
from matedit.io.inputs import document_inputs
from matedit.io.instance import InstanceError, resolve, save_instance
from matedit.resources import graphs_dir

INSTANCES = sorted((graphs_dir() / "instances").glob("*.json"))
MASTER = graphs_dir() / "materials" / "worn_painted_steel.json"


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True, cwd=cwd)


def write(path: Path, data: dict) -> Path:
    path.write_text(json.dumps(data, indent=2))
    return path


def instance(path: Path, parent: str, parameters=None, **more) -> Path:
    return write(path, {"format": "matedit.instance", "version": 2, "parent": parent,
                        "parameters": parameters or {}, **more})


@pytest.fixture
def master(tmp_path) -> Path:
    """A material with one parameter of each type and a static switch over a texture."""
    d = material(tmp_path / "mat" / "master.json")
    (tmp_path / "mat").mkdir()
    node(d, "col", "color_parameter", {"name": "tint", "group": "Look", "order": 1},
         {"value": [0.8, 0.2, 0.1]})
    node(d, "r", "scalar_parameter", {"name": "rough", "group": "Look", "order": 0},
         {"value": 0.4})
    node(d, "v", "vector_parameter", {"name": "offset"}, {"value": [0.0, 0.0, 0.0, 1.0]})
    node(d, "tex", "texture_parameter", {"name": "grain", "path": "grain.png"})
    node(d, "smp", "texture_sample")
    node(d, "sw", "static_switch", {"name": "use_grain", "value": True})
    node(d, "add", "add")
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "tex", "texture", "smp", "texture")
    link(d, "smp", "r", "sw", "true")
    link(d, "r", "value", "sw", "false")
    link(d, "sw", "result", "make", "roughness")
    link(d, "col", "color", "add", "a")
    link(d, "v", "xyz", "add", "b")
    link(d, "add", "result", "make", "baseColor")
    link(d, "make", "attributes", "out", "attributes")
    fmt.save(d)
    return d.path


# --- format -----------------------------------------------------------------------------------

@pytest.mark.parametrize("path", INSTANCES, ids=lambda p: p.name)
def test_sample_round_trip_is_byte_identical_and_valid(path, tmp_path):
    doc = inst_io.load_instance(path)
    assert inst_io.dumps(doc).encode() == path.read_bytes()
    r = resolve(doc)
    assert r.problems == []
    moved = tmp_path / "elsewhere" / path.name
    moved.parent.mkdir()
    save_instance(inst_io.load_instance(path), moved, resolved=r)
    # the parent was rebased: the moved copy resolves to the same material and values
    again = resolve(inst_io.load_instance(moved))
    assert again.chain[1:] == r.chain[1:] and again.values == r.values


def test_samples_cover_the_issue():
    docs = {p.stem: inst_io.load_instance(p) for p in INSTANCES}
    assert len(docs) >= 6
    of_master = [s for s, d in docs.items()
                 if resolve(d).chain[-1] == MASTER.resolve()]
    assert len(of_master) >= 3
    assert any(inst_io.is_instance_file(d.parent_path()) for d in docs.values())
    assert any(resolve(d).instance.parameters.get("rust_on") is False for d in docs.values())
    params = inst_io.material_parameters(fmt.load(MASTER))
    assert {p.group for p in params.values()} == {"Paint", "Rust"}
    assert len({p.order for p in params.values() if p.group == "Paint"}) == 4


def test_unknown_fields_are_kept_and_saves_are_sorted(tmp_path, master):
    p = instance(tmp_path / "i.json", "mat/master.json", {"rough": 0.9},
                 custom={"kept": [1, 2]}, preview={"mesh": "cube", "future": 1})
    doc = inst_io.load_instance(p)
    save_instance(doc)
    out = json.loads(p.read_text())
    assert out["custom"] == {"kept": [1, 2]} and out["preview"] == {"mesh": "cube", "future": 1}
    assert list(out) == sorted(out)
    assert "parent_parameters" not in out  # only written when the parent was resolved


def test_migration_from_version_1(tmp_path, master):
    p = write(tmp_path / "old.json", {
        "format": "matedit.instance", "version": 1, "parent": "mat/master.json",
        "overrides": [{"name": "rough", "value": 0.25}, {"name": "tint", "value": [1, 1, 1]}]})
    doc = inst_io.load_instance(p)
    assert doc.parameters == {"rough": 0.25, "tint": [1, 1, 1]}
    assert "overrides" not in inst_io.to_dict(doc)
    assert inst_io.to_dict(doc)["version"] == 2
    bad = write(tmp_path / "bad.json", {"format": "matedit.instance", "version": 1,
                                        "parent": "x.json", "overrides": [{"value": 1}]})
    with pytest.raises(FormatError, match=r"bad.json: cannot migrate from version 1: "
                       r"overrides\[0\]"):
        inst_io.load_instance(bad)


@pytest.mark.parametrize("data, message", [
    ({"version": 2, "parent": "m.json"}, "'format' must be 'matedit.instance'"),
    ({"format": "matedit.instance", "version": 9, "parent": "m.json"}, "newer matedit"),
    ({"format": "matedit.instance", "version": 2}, "'parent' must name"),
    ({"format": "matedit.instance", "version": 2, "parent": ""}, "'parent' must name"),
    ({"format": "matedit.instance", "version": 2, "parent": "m.json", "parameters": []},
     "'parameters' must be an object"),
    ({"format": "matedit.instance", "version": 2, "parent": "m.json",
      "preview": {"mesh": 3}}, "preview.mesh"),
    ({"format": "matedit.instance", "version": 2, "parent": "m.json",
      "parent_parameters": {"a": "blob"}}, "parent_parameters"),
])
def test_structural_errors_name_file_and_field(tmp_path, data, message):
    p = write(tmp_path / "i.json", data)
    with pytest.raises(FormatError) as exc:
        inst_io.load_instance(p)
    assert message in str(exc.value) and str(p) in str(exc.value)


def test_duplicate_keys_and_bounded_reads(tmp_path):
    p = tmp_path / "dup.json"
    p.write_text('{"format": "matedit.instance", "version": 2, "parent": "a.json", '
                 '"parameters": {"x": 1, "x": 2}}')
    with pytest.raises(FormatError, match="appears twice"):
        inst_io.load_instance(p)
    with pytest.raises(FormatError, match="is a directory"):
        inst_io.load_instance(tmp_path)


# --- validation -----------------------------------------------------------------------------

@pytest.mark.parametrize("name, value, message", [
    ("nope", 1.0, "the parent material has no parameter of this name"),
    ("rough", [1, 2], "a scalar parameter takes a number"),
    ("rough", True, "a scalar parameter takes a number"),
    ("tint", [1, 2], "a color parameter takes a list of 3 numbers"),
    ("offset", [1, 2, 3], "a vector parameter takes a list of 4 numbers"),
    ("grain", 3, "a texture parameter takes a file path"),
    ("use_grain", 1, "a static switch takes true or false"),
])
def test_parameter_errors_name_the_parameter(tmp_path, master, name, value, message):
    p = instance(tmp_path / "i.json", "mat/master.json", {name: value})
    r = resolve(inst_io.load_instance(p))
    (err,) = r.errors
    assert err.parameter == name and message in err.message and err.file == str(p)
    res = run("validate", str(p))
    assert res.returncode == 2
    assert res.stderr.strip() == f"error: {p}: parameter {name}: {err.message}"


def test_type_changed_in_parent_is_an_error(tmp_path, master):
    p = instance(tmp_path / "i.json", "mat/master.json", {"rough": 0.5},
                 parent_parameters={"rough": "color"})
    (err,) = resolve(inst_io.load_instance(p)).errors
    assert err.parameter == "rough" and "was a color parameter" in err.message


def test_orphan_override_warns_and_is_kept(tmp_path, master):
    p = instance(tmp_path / "i.json", "mat/master.json", {"rough": 0.5})
    doc = inst_io.load_instance(p)
    save_instance(doc, resolved=resolve(doc))  # records the parent's parameters
    m = fmt.load(master)
    m.graph.nodes["r"].settings["name"] = "roughness_amount"  # renamed in the parent
    fmt.save(m)
    doc = inst_io.load_instance(p)
    r = resolve(doc)
    assert r.errors == []
    (w,) = r.warnings
    assert w.parameter == "rough" and "no longer has this parameter" in w.message
    save_instance(doc, resolved=r)
    saved = json.loads(p.read_text())
    assert saved["parameters"] == {"rough": 0.5}
    assert saved["parent_parameters"]["rough"] == "scalar"
    assert "roughness_amount" in saved["parent_parameters"]
    res = run("validate", str(p))
    assert res.returncode == 0 and res.stderr.startswith(f"warning: {p}: parameter rough:")


def test_cycle_names_the_files(tmp_path):
    a = instance(tmp_path / "a.json", "b.json")
    b = instance(tmp_path / "b.json", "a.json")
    with pytest.raises(InstanceError) as exc:
        resolve(inst_io.load_instance(a))
    msg = str(exc.value)
    assert "cycle" in msg and str(a.resolve()) in msg and str(b.resolve()) in msg
    res = run("validate", str(a))
    assert res.returncode == 2 and "cycle" in res.stderr and len(res.stderr.splitlines()) == 1
    selfref = instance(tmp_path / "s.json", "s.json")
    with pytest.raises(InstanceError, match="cycle"):
        resolve(inst_io.load_instance(selfref))


def test_bad_parents(tmp_path, master):
    missing = instance(tmp_path / "m.json", "nowhere.json")
    with pytest.raises(InstanceError, match=r"m.json: parent nowhere.json: file not found"):
        resolve(inst_io.load_instance(missing))
    fn = shutil.copy(graphs_dir() / "functions" / "edge_wear.json", tmp_path / "fn.json")
    f = instance(tmp_path / "f.json", Path(fn).name)
    with pytest.raises(InstanceError, match="is a material function"):
        resolve(inst_io.load_instance(f))
    (tmp_path / "broken.json").write_text("{")
    b = instance(tmp_path / "b.json", "broken.json")
    with pytest.raises(InstanceError, match="broken.json: not valid JSON"):
        resolve(inst_io.load_instance(b))
    res = run("compile", str(b), "-o", str(tmp_path / "out"))
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr.startswith("error: ") and "broken.json" in res.stderr


# --- the effective material -------------------------------------------------------------------

def test_chain_merges_overrides_leaf_last(tmp_path, master):
    instance(tmp_path / "a.json", "mat/master.json", {"rough": 0.9, "tint": [0, 0, 1]})
    sub = tmp_path / "sub"
    sub.mkdir()
    b = instance(sub / "b.json", "../a.json", {"rough": 0.1})
    r = resolve(inst_io.load_instance(b))
    assert r.values["rough"] == 0.1 and r.values["tint"] == [0, 0, 1]
    assert r.inherited["rough"] == 0.9 and r.inherited["tint"] == [0, 0, 1]
    assert r.chain == [b.resolve(), (tmp_path / "a.json").resolve(), master.resolve()]
    ins = document_inputs(r.document, FileResolver())
    assert {b.resolve(), (tmp_path / "a.json").resolve(), master.resolve()} <= set(ins)


def test_texture_overrides_are_relative_to_their_instance(tmp_path, master):
    (tmp_path / "mat" / "grain.png").write_bytes(b"")
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "other.png").write_bytes(b"")
    instance(tmp_path / "a" / "a.json", "../mat/master.json", {"grain": "other.png"})
    (tmp_path / "b").mkdir()
    b = instance(tmp_path / "b" / "b.json", "../a/a.json", {"rough": 0.3})
    cm = compile_document(resolve(inst_io.load_instance(b)).document, FileResolver())
    (tex,) = cm.ir.textures
    assert Path(tex.path).resolve() == (tmp_path / "a" / "other.png").resolve()
    plain = instance(tmp_path / "b" / "c.json", "../mat/master.json")
    (tex,) = compile_document(resolve(inst_io.load_instance(plain)).document).ir.textures
    assert Path(tex.path).resolve() == (tmp_path / "mat" / "grain.png").resolve()


def test_shaders_identical_to_parent_without_switch_overrides():
    resolver = FileResolver()
    parent = compile_all(fmt.load(MASTER), resolver)
    for path in INSTANCES:
        r = resolve(inst_io.load_instance(path))
        if r.chain[-1] != MASTER.resolve() or r.values["rust_on"] is not True:
            continue
        mine = compile_all(r.document, resolver)
        for target, cm in mine.items():
            assert cm.vertex_text == parent[target].vertex_text
            assert cm.fragment_text == parent[target].fragment_text
            assert cm.structure_hash == parent[target].structure_hash
        defaults = {u["parameter"]: u["default"] for u in mine["glsl330"].reflection()["uniforms"]
                    if "parameter" in u}
        for name, value in r.values.items():
            if name in defaults:
                assert defaults[name] == pytest.approx(value), name


def test_switch_override_removes_the_dead_branch(tmp_path, master):
    resolver = FileResolver()
    on = compile_document(fmt.load(master), resolver).reflection()
    off_path = instance(tmp_path / "off.json", "mat/master.json", {"use_grain": False})
    off = compile_document(resolve(inst_io.load_instance(off_path)).document,
                           resolver).reflection()
    assert on["static_switches"] == {"use_grain": True}
    assert off["static_switches"] == {"use_grain": False}
    assert [t["parameter"] for t in on["textures"]] == ["grain"]
    assert off["textures"] == []
    on_params = {u.get("parameter") for u in on["uniforms"]}
    off_params = {u.get("parameter") for u in off["uniforms"]}
    assert "rough" not in on_params and "rough" in off_params  # the other branch, each way
    assert on["structure_hash"] != off["structure_hash"]
    # and in the sample: rust off drops the rust parameters
    red = resolve(inst_io.load_instance(graphs_dir() / "instances" / "worn_paint_red.json"))
    nr = resolve(inst_io.load_instance(graphs_dir() / "instances" /
                                       "worn_paint_red_no_rust.json"))
    names = {p: {u.get("parameter") for u in compile_document(r.document, resolver)
                 .reflection()["uniforms"]} for p, r in (("red", red), ("no", nr))}
    assert {"rust_amount", "rust_reach"} <= names["red"]
    assert not {"rust_amount", "rust_reach"} & names["no"]


def test_switch_rules(tmp_path):
    from matedit.compiler import CompileError

    d = material(tmp_path / "m.json")
    node(d, "a", "scalar_parameter", {"name": "x"})
    node(d, "s1", "static_switch", {"name": "x"})
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "a", "value", "s1", "true")
    link(d, "s1", "result", "make", "roughness")
    link(d, "make", "attributes", "out", "attributes")
    with pytest.raises(CompileError, match="static switch name 'x' is a parameter of a"):
        compile_document(d)
    d.graph.nodes["s1"].settings.update({"name": "ok", "value": "yes"})
    with pytest.raises(CompileError, match="switch value must be true or false"):
        compile_document(d)
    d.graph.nodes["s1"].settings.update({"value": False, "name": "bad name"})
    with pytest.raises(CompileError, match="switch name 'bad name'"):
        compile_document(d)


# --- command line -----------------------------------------------------------------------------

def test_validate_accepts_every_sample():
    res = run("validate", *map(str, INSTANCES))
    assert res.returncode == 0 and res.stderr == ""


def test_compile_instance_writes_its_permutation(tmp_path):
    red = graphs_dir() / "instances" / "worn_paint_red.json"
    nr = graphs_dir() / "instances" / "worn_paint_red_no_rust.json"
    out = tmp_path / "out"
    for f in (MASTER, red, nr):
        res = run("compile", str(f), "-o", str(out), "--target", "all")
        assert res.returncode == 0, res.stderr
    for t in ("glsl330", "glsl450", "essl300"):
        for ext in ("vert", "frag"):
            assert (out / f"worn_paint_red.{t}.{ext}").read_bytes() == \
                (out / f"worn_painted_steel.{t}.{ext}").read_bytes()
        assert (out / f"worn_paint_red_no_rust.{t}.frag").read_bytes() != \
            (out / f"worn_painted_steel.{t}.frag").read_bytes()
    refl = json.loads((out / "worn_paint_red.reflection.json").read_text())
    assert refl["source"] == "worn_paint_red.json"
    by = {u.get("parameter"): u["default"] for u in refl["uniforms"]}
    assert by["paint_color"] == [0.42, 0.03, 0.02] and by["wear_amount"] == 0.6
    assert refl["static_switches"] == {"rust_on": True}
    nrr = json.loads((out / "worn_paint_red_no_rust.reflection.json").read_text())
    assert nrr["static_switches"] == {"rust_on": False}
    text = "".join(p.read_text() for p in out.iterdir())
    assert str(graphs_dir()) not in text and os.path.expanduser("~") + "/" not in text


def test_compile_refuses_to_overwrite_a_parent(tmp_path, master):
    a = instance(tmp_path / "a.json", "mat/master.json")
    b = instance(tmp_path / "b.json", "a.json")
    out = tmp_path / "out"
    out.mkdir()
    (out / "b.reflection.json").symlink_to(a)
    res = run("compile", str(b), "-o", str(out))
    assert res.returncode == 2
    assert "refusing to write over a parent of the instance" in res.stderr
    assert json.loads(a.read_text())["format"] == "matedit.instance"


@pytest.mark.gl
def test_render_instance_shows_its_overrides(tmp_path):
    import numpy as np
    import OpenImageIO as oiio

    red = graphs_dir() / "instances" / "worn_paint_red.json"
    imgs = {}
    for f in (MASTER, red):
        out = tmp_path / f"{f.stem}.png"
        res = run("render", str(f), "-o", str(out), "--size", "48x48")
        assert res.returncode == 0, res.stderr
        imgs[f.stem] = oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT)
    a, b = imgs["worn_painted_steel"], imgs["worn_paint_red"]
    # blue paint becomes red paint: red rises and blue falls on the paint
    assert (b[..., 0] - a[..., 0]).max() > 0.2 and (a[..., 2] - b[..., 2]).max() > 0.2
    assert np.abs(a - b).max(axis=2)[:4].max() < 1e-6  # the background row is untouched


def test_preview_settings_layer_over_the_parent(tmp_path, master):
    m = fmt.load(master)
    m.preview = {"mesh": "sphere", "environment": "studio_hdr.exr"}
    fmt.save(m)
    (tmp_path / "sub").mkdir()
    p = instance(tmp_path / "sub" / "i.json", "../mat/master.json",
                 preview={"mesh": "cube", "exposure": 1.5})
    r = resolve(inst_io.load_instance(p))
    assert r.document.preview["mesh"] == "cube" and r.document.preview["exposure"] == 1.5
    # the parent's environment file is found from the instance's folder
    assert (p.parent / r.document.preview["environment"]).resolve() == \
        (tmp_path / "mat" / "studio_hdr.exr").resolve()
