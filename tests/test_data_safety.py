"""Data safety: atomic writes interrupted at every step, umask and kept modes, saves through
symbolic links, unknown fields kept, no output over an input, no predictable temporary names,
no absolute paths in outputs, bounded reads."""

from __future__ import annotations

import json
import os
import stat

import pytest
from hostile import assert_clean_failure, base_material, cli, function_doc, write

from matedit.io import atomic
from matedit.io.atomic import atomic_output, atomic_write_bytes, read_bounded
from matedit.io.document import FormatError, dumps, load, loads, save


def _leftovers(folder):
    return sorted(p.name for p in folder.iterdir() if ".tmp" in p.name)


# --- the atomic helper -------------------------------------------------------------------------

STEPS = ["open", "fchmod", "write", "fsync", "close", "replace"]


@pytest.mark.parametrize("step", STEPS)
def test_write_interrupted_at_every_step_keeps_the_original(tmp_path, monkeypatch, step):
    target = tmp_path / "m.json"
    target.write_text("original")
    os.chmod(target, 0o640)  # so that the fchmod step runs

    def boom(*a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic.os, step, boom)
    with pytest.raises(OSError):
        atomic_write_bytes(target, b"new contents")
    monkeypatch.undo()
    assert target.read_text() == "original"
    assert _leftovers(tmp_path) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json"]


def test_document_save_interrupted_keeps_the_document(tmp_path, monkeypatch):
    path = write(tmp_path / "m.json", base_material())
    before = path.read_bytes()
    doc = load(path)
    doc.name = "changed"
    monkeypatch.setattr(atomic.os, "replace", lambda *a: (_ for _ in ()).throw(OSError(5, "EIO")))
    with pytest.raises(OSError):
        save(doc)
    monkeypatch.undo()
    assert path.read_bytes() == before and _leftovers(tmp_path) == []


def test_atomic_output_failure_leaves_nothing(tmp_path):
    target = tmp_path / "x.exr"
    with pytest.raises(RuntimeError), atomic_output(target) as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("writer failed")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_new_files_respect_the_umask(tmp_path, mask, mode):
    old = os.umask(mask)
    try:
        atomic_write_bytes(tmp_path / "a.txt", b"x")
        with atomic_output(tmp_path / "b.bin") as tmp:
            tmp.write_bytes(b"y")
        save(loads(json.dumps(base_material())), tmp_path / "c.json")
    finally:
        os.umask(old)
    for name in ("a.txt", "b.bin", "c.json"):
        assert stat.S_IMODE(os.stat(tmp_path / name).st_mode) == mode, name


def test_replacing_a_file_keeps_its_mode(tmp_path):
    path = write(tmp_path / "m.json", base_material())
    os.chmod(path, 0o604)
    doc = load(path)
    doc.description = "edited"
    save(doc)
    assert stat.S_IMODE(os.stat(path).st_mode) == 0o604
    assert load(path).description == "edited"


def test_saving_through_a_symbolic_link_writes_its_target(tmp_path):
    (tmp_path / "real").mkdir()
    real = write(tmp_path / "real" / "m.json", base_material())
    link = tmp_path / "link.json"
    link.symlink_to(real)
    doc = load(link)
    doc.name = "through the link"
    save(doc)
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert load(real).name == "through the link"


def test_temporary_names_are_unpredictable_and_links_at_them_are_not_followed(tmp_path):
    """The old `.{stem}.render-tmp.png` name: a link planted there once made `render` write
    over the link's target. Now the temporary is created exclusively at a random name."""
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    for name in (".out.png.tmp", ".out.render-tmp.png", ".out.tmp", ".out.png.render-tmp.png"):
        (tmp_path / name).symlink_to(victim)
    with atomic_output(tmp_path / "out.png") as tmp:
        assert tmp.parent.parent == tmp_path and stat.S_IMODE(os.stat(tmp.parent).st_mode) == 0o700
        tmp.write_bytes(b"png")
    atomic_write_bytes(tmp_path / "out.txt", b"txt")
    assert victim.read_text() == "precious"
    names = set()
    for _ in range(20):
        fd, tmp = atomic._exclusive_temp(tmp_path, "n")
        os.close(fd)
        names.add(tmp.name)
        tmp.unlink()
    assert len(names) == 20


# --- bounded reads ----------------------------------------------------------------------------

def test_reads_are_bounded_while_reading(tmp_path):
    big = tmp_path / "big"
    big.write_bytes(b"x" * 5000)
    with pytest.raises(atomic.UnsafeFileError):
        read_bounded(big, 4096)
    with pytest.raises(atomic.UnsafeFileError):
        read_bounded("/dev/zero", 1 << 20)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(atomic.UnsafeFileError):
        read_bounded(fifo, 100)  # returns at once: opened non-blocking, refused by type
    assert read_bounded(big, 5000) == b"x" * 5000


# --- unknown fields, duplicates, odd values -----------------------------------------------------

def test_unknown_fields_survive_a_round_trip_everywhere(tmp_path):
    raw = base_material()
    raw["x_top"] = {"nested": [1, 2.5, "three"]}
    raw["nodes"][0]["x_node"] = "kept"
    raw["links"][0]["x_link"] = 7
    raw["comments"][0]["x_comment"] = [True, None]
    raw["nodes"][0]["settings"]["x_setting"] = 1
    raw["preview"] = {"mesh": "cube", "x_preview": 2}
    path = write(tmp_path / "m.json", raw)
    doc = load(path)
    save(doc, tmp_path / "again.json")
    back = json.loads((tmp_path / "again.json").read_text())
    assert back["x_top"] == {"nested": [1, 2.5, "three"]}
    assert back["nodes"][0]["x_node"] == "kept"
    link = next(l for l in back["links"] if l["from"] == raw["links"][0]["from"])
    assert link["x_link"] == 7
    assert back["comments"][0]["x_comment"] == [True, None]
    assert back["nodes"][0]["settings"]["x_setting"] == 1
    assert back["preview"]["x_preview"] == 2
    assert dumps(load(tmp_path / "again.json")) == (tmp_path / "again.json").read_text()


def test_unknown_fields_survive_editing_commands():
    from matedit.graph.commands import MoveNodes, SetValue

    raw = base_material()
    raw["nodes"][1]["x_node"] = "kept"
    doc = loads(json.dumps(raw), "m.json")
    SetValue("r", "value", 0.9).apply(doc.graph)
    MoveNodes({"r": (5.0, 6.0)}).apply(doc.graph)
    assert json.loads(dumps(doc))["nodes"][[n["id"] for n in json.loads(dumps(doc))["nodes"]]
                                          .index("r")]["x_node"] == "kept"


@pytest.mark.parametrize("text, where", [
    ('{"format": "matedit.material", "format": "matedit.function", "version": 2}', "format"),
    ('{"format": "matedit.material", "version": 2, "nodes": [{"id": "a", "id": "b", '
     '"kind": "add"}]}', "id"),
])
def test_duplicate_keys_are_an_error_naming_the_key(tmp_path, text, where):
    rc, _, err = cli("validate", write(tmp_path / "d.json", text))
    assert_clean_failure(rc, err)
    assert f"key '{where}' appears twice" in err


def test_a_bom_is_a_clean_error(tmp_path):
    path = tmp_path / "bom.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps(base_material()).encode())
    rc, _, err = cli("validate", path)
    assert_clean_failure(rc, err)
    assert "byte-order mark" in err


def test_over_long_texture_path_names_the_node_and_field(tmp_path):
    raw = base_material()
    raw["nodes"].append({"id": "tex", "kind": "texture_parameter", "position": [0, 0],
                         "settings": {"name": "albedo", "path": "a" * 5000 + ".png"}})
    rc, _, err = cli("compile", write(tmp_path / "m.json", raw), "-o", tmp_path / "o")
    assert_clean_failure(rc, err)
    assert "node tex" in err and "field path" in err


def test_preview_environment_must_be_a_string(tmp_path):
    raw = base_material()
    raw["preview"] = {"environment": {"file": "x.hdr"}}
    path = write(tmp_path / "m.json", raw)
    for command in (["validate", path], ["compile", path, "-o", tmp_path / "o"]):
        rc, _, err = cli(*command)
        assert_clean_failure(rc, err)
        assert "preview.environment" in err


def test_obj_with_nan_prints_no_numpy_warning(tmp_path, recwarn):
    from matedit.render.mesh import MeshError, load_obj

    obj = tmp_path / "nan.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt nan inf\nvn nan 0 1\nf 1/1/1 2/1/1 3/1/1\n")
    with pytest.raises(MeshError, match="not finite"):
        load_obj(obj)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


# --- validation and compilation agree -----------------------------------------------------------

def test_auto_uniform_names_that_would_meet_are_kept_apart(tmp_path):
    """Node `a_b` input `c` and node `a` input `b_c` both made `u_a_b_c`; the compile error
    told the user to rename a parameter though neither node was one."""
    raw = base_material()
    raw["nodes"] += [
        {"id": "a_b", "kind": "add", "position": [0, 0]},
        {"id": "a", "kind": "function_call", "position": [0, 0],
         "settings": {"function": "f.json"}},
    ]
    write(tmp_path / "f.json", function_doc(inputs=(("b_a", "float"),)))
    raw["links"] += [{"from": ["a_b", "result"], "to": ["make", "metallic"]},
                     {"from": ["a", "result"], "to": ["make", "cavity"]}]
    path = write(tmp_path / "m.json", raw)
    assert cli("validate", path)[0] == 0
    rc, _, err = cli("compile", path, "-o", tmp_path / "o", "--target", "all")
    assert rc == 0, err
    refl = json.loads((tmp_path / "o" / "m.reflection.json").read_text())
    names = [u["name"] for u in refl["uniforms"]]
    assert len(names) == len(set(names)) and "u_a_b_a" in names and "u_a_b_a_2" in names


def test_layer_variables_do_not_clash_with_node_variables(tmp_path):
    layer = function_doc(inputs=(), outputs=(("attributes", "MaterialAttributes"),), body=[])
    layer["nodes"].append({"id": "mk", "kind": "make_attributes", "position": [100, 0]})
    layer["links"] = [{"from": ["mk", "attributes"], "to": ["o0", "value"]}]
    write(tmp_path / "lay.json", layer)
    raw = base_material()
    raw["nodes"] += [
        {"id": "s", "kind": "layer_stack", "position": [300, 0], "settings": {"layers": [
            {"id": "base", "function": "lay.json"},
            {"id": "top", "function": "lay.json", "blend": "alpha"}]}},
        # a node whose variables once shared names with the stack's own (`s_top_...`)
        {"id": "s_top", "kind": "multiply", "position": [0, 0]},
    ]
    raw["links"] = [l for l in raw["links"] if l["to"] != ["out", "attributes"]]
    raw["links"] += [{"from": ["s", "attributes"], "to": ["out", "attributes"]},
                     {"from": ["s_top", "result"], "to": ["s", "top_mask"]}]
    path = write(tmp_path / "m.json", raw)
    assert cli("validate", path)[0] == 0
    rc, _, err = cli("compile", path, "-o", tmp_path / "o", "--target", "all")
    assert rc == 0, err


# --- no output over an input, no absolute paths ---------------------------------------------------

def _material_with_texture(tmp_path):
    import numpy as np

    from matedit.io.images import write_image

    write_image(tmp_path / "albedo.png", np.full((4, 4, 3), 0.5, np.float32))
    raw = base_material()
    raw["nodes"] += [
        {"id": "tex", "kind": "texture_parameter", "position": [0, 300],
         "settings": {"name": "albedo", "path": "albedo.png"}},
        {"id": "samp", "kind": "texture_sample", "position": [200, 300]},
    ]
    raw["links"] = [l for l in raw["links"] if l["to"] != ["make", "baseColor"]]
    raw["links"] += [{"from": ["tex", "texture"], "to": ["samp", "texture"]},
                     {"from": ["samp", "rgb"], "to": ["make", "baseColor"]}]
    return write(tmp_path / "m.json", raw)


def test_compile_refuses_outputs_that_resolve_to_inputs(tmp_path):
    doc = _material_with_texture(tmp_path)
    before = doc.read_bytes()
    out = tmp_path / "out"
    out.mkdir()
    (out / "m.glsl330.frag").symlink_to(doc)
    rc, _, err = cli("compile", doc, "-o", out)
    assert_clean_failure(rc, err)
    assert "refusing to write over the document" in err
    assert doc.read_bytes() == before and not (out / "m.glsl330.vert").exists()
    (out / "m.glsl330.frag").unlink()
    os.link(tmp_path / "albedo.png", out / "m.reflection.json")  # a hard link to the texture
    rc, _, err = cli("compile", doc, "-o", out)
    assert_clean_failure(rc, err)
    assert "the texture" in err


@pytest.mark.gl
def test_render_refuses_to_write_over_its_inputs(tmp_path):
    doc = _material_with_texture(tmp_path)
    before = doc.read_bytes()
    for out in (doc.with_suffix(".png").with_name("albedo.png"), tmp_path / "." / "albedo.png"):
        rc, _, err = cli("render", doc, "-o", out, "--size", "16x16")
        assert_clean_failure(rc, err)
        assert "refusing to write over the texture" in err
    (tmp_path / "link.png").symlink_to(doc)
    rc, _, err = cli("render", doc, "-o", tmp_path / "link.png", "--size", "16x16")
    assert_clean_failure(rc, err)
    assert doc.read_bytes() == before


@pytest.mark.gl
def test_render_leaves_no_temporary_and_ignores_planted_links(tmp_path):
    doc = write(tmp_path / "m.json", base_material())
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    (tmp_path / ".r.render-tmp.png").symlink_to(victim)
    old = os.umask(0o022)
    try:
        rc, _, err = cli("render", doc, "-o", tmp_path / "r.png", "--size", "16x16")
    finally:
        os.umask(old)
    assert rc == 0, err
    assert victim.read_text() == "precious"
    assert stat.S_IMODE(os.stat(tmp_path / "r.png").st_mode) == 0o644
    assert sorted(p.name for p in tmp_path.iterdir()) == [".r.render-tmp.png", "m.json",
                                                          "r.png", "victim.txt"]


@pytest.mark.gl
def test_bake_ibl_refuses_to_overwrite_its_environment(tmp_path):
    import numpy as np

    from matedit.io.images import write_image

    env = tmp_path / "brdf_lut.exr"
    write_image(env, np.ones((8, 16, 3), np.float32))
    before = env.read_bytes()
    rc, _, err = cli("bake-ibl", env, "-o", tmp_path, "--size", "16", "--samples", "16")
    assert_clean_failure(rc, err)
    assert "refusing to write over the environment" in err and env.read_bytes() == before


def test_compiled_outputs_carry_no_absolute_path(tmp_path):
    doc = _material_with_texture(tmp_path)
    rc, _, err = cli("compile", doc, "-o", tmp_path / "o", "--target", "all")
    assert rc == 0, err
    for f in (tmp_path / "o").iterdir():
        text = f.read_text()
        assert str(tmp_path) not in text and os.sep + "work" + os.sep not in text, f.name
    refl = json.loads((tmp_path / "o" / "m.reflection.json").read_text())
    assert refl["source"] == "m.json"
    assert refl["textures"][0]["path"] == "albedo.png"


def test_a_file_that_loads_also_saves(tmp_path):
    raw = base_material()
    raw["nodes"][1]["values"]["value"] = 10**300  # an int that is still a float
    doc = loads(json.dumps(raw), "m.json")
    assert loads(dumps(doc), "m.json").graph.nodes["r"].values["value"] == 10**300
    with pytest.raises(FormatError, match="64-bit float"):
        loads(json.dumps(raw).replace(str(10**300), "1" + "0" * 400), "m.json")
