"""Data safety: atomic writes interrupted at every step, umask and kept modes, saves through
symbolic links, unknown fields kept, no output over an input, no predictable temporary names,
no absolute paths in outputs, bounded reads."""

from __future__ import annotations

import json
import os
import shutil
import stat
from pathlib import Path

import numpy as np
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


# === Every command's inputs, built-in names, import -o DIR (issue 22) =========================
#
# One tree holds every kind of input a command reads; each case plants one of them at one of
# a command's output names, directly (the input is read at that very name), through a
# symbolic link or a hard link, or is read through a link whose target is the output name.
# The command must exit 2 with one `error:` line naming the input and leave it unchanged.

_FACES = ("px", "nx", "py", "ny", "pz", "nz")
_TRIANGLE_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def _mtlx_text(image: str) -> str:
    return ('<?xml version="1.0"?>\n<materialx version="1.39">\n'
            '<nodegraph name="NG"><image name="img" type="color3"><input name="file" '
            f'type="filename" value="{image}"/></image>'
            '<output name="o" type="color3" nodename="img"/></nodegraph>'
            '<standard_surface name="S" type="surfaceshader"><input name="base_color" '
            'type="color3" nodegraph="NG" output="o"/></standard_surface>'
            '<surfacematerial name="mat" type="material"><input name="surfaceshader" '
            'type="surfaceshader" nodename="S"/></surfacematerial>\n</materialx>\n')


def _rel(path, start) -> str:
    return os.path.relpath(path, start).replace(os.sep, "/")


def _faces(px_path) -> list:
    """The six face files of a folder environment whose +X face is `px_path` (NAME_px.EXT)."""
    stem, ext = px_path.name.rsplit(".", 1)
    prefix = stem[:-2]
    return [px_path.with_name(f"{prefix}{f}.{ext}") for f in _FACES]


def _input_tree(tmp, at=None):
    """Every kind of input under tmp/src, the one in `at` (kind -> path) placed there
    instead; returns kind -> the file of that kind (for faces: the +X face)."""
    import numpy as np

    from matedit.io.images import write_image

    at = at or {}
    src = tmp / "src"
    src.mkdir(exist_ok=True)
    defaults = {"texture": "albedo.png", "function": "f.json", "preview_mesh": "pm.obj",
                "preview_face": "penv/sky_px.hdr", "mesh": "mesh.obj",
                "env_face": "env/sky_px.hdr", "env_file": "env.hdr", "rig": "rig.json",
                "mtlx": "a.mtlx", "mtlx_image": "mx.png", "gltf": "a.gltf",
                "gltf_bin": "a.bin"}
    p = {k: at.get(k, src / v) for k, v in defaults.items()}
    for f in p.values():
        f.parent.mkdir(parents=True, exist_ok=True)
    pixels = np.full((4, 4, 3), 0.5, np.float32)
    write_image(p["texture"], pixels) if p["texture"].suffix == ".png" else \
        p["texture"].write_bytes(b"texture")
    p["mtlx_image"].write_bytes(p["texture"].read_bytes())
    write(p["function"], function_doc())
    for k in ("preview_mesh", "mesh"):
        p[k].write_text(_TRIANGLE_OBJ)
    for k in ("preview_face", "env_face"):
        for f in _faces(p[k]):
            if not f.exists():
                f.write_bytes(b"face " + f.name.encode())
    write_image(p["env_file"], np.ones((8, 16, 3), np.float32)) \
        if p["env_file"].suffix == ".hdr" else p["env_file"].write_bytes(b"environment")
    write(p["rig"], {"format": "matedit.lightrig", "version": 1, "lights": []})
    p["mtlx"].write_text(_mtlx_text(_rel(p["mtlx_image"], p["mtlx"].parent)))
    png = p["mtlx_image"].read_bytes()  # a glTF asset whose .bin embeds the image
    p["gltf_bin"].write_bytes(png)
    write(p["gltf"], {"asset": {"version": "2.0"},
                      "buffers": [{"uri": _rel(p["gltf_bin"], p["gltf"].parent),
                                   "byteLength": len(png)}],
                      "bufferViews": [{"buffer": 0, "byteLength": len(png)}],
                      "images": [{"bufferView": 0, "mimeType": "image/png"}],
                      "textures": [{"source": 0}],
                      "materials": [{"name": "mat", "pbrMetallicRoughness": {
                          "baseColorTexture": {"index": 0}}}]})
    raw = base_material()
    raw["nodes"] += [
        {"id": "tex", "kind": "texture_parameter", "position": [0, 300],
         "settings": {"name": "albedo", "path": _rel(p["texture"], src)}},
        {"id": "samp", "kind": "texture_sample", "position": [200, 300]},
        {"id": "fn", "kind": "function_call", "position": [200, 500],
         "settings": {"function": _rel(p["function"], src)}},
    ]
    raw["links"] = [l for l in raw["links"] if l["to"] != ["make", "baseColor"]]
    raw["links"] += [{"from": ["tex", "texture"], "to": ["samp", "texture"]},
                     {"from": ["samp", "rgb"], "to": ["make", "baseColor"]},
                     {"from": ["r", "value"], "to": ["fn", "a"]},
                     {"from": ["fn", "result"], "to": ["make", "metallic"]}]
    raw["preview"] = {"mesh": _rel(p["preview_mesh"], src),
                      "environment": _rel(p["preview_face"].parent, src)}
    p["document"] = write(src / "m.json", raw)
    p["parent"] = p["document"]
    p["instance"] = write(src / "inst.json", {"format": "matedit.instance", "version": 2,
                                              "parent": "m.json", "parameters": {}})
    return p


# command -> (the kinds of input it reads, the output file a case plants, its arguments).
# `o` is the output folder; `p` the tree; `kind` the case's. A name None: no direct case.
def _compile(p, o, kind):
    return ["compile", p["instance"] if kind == "parent" else p["document"], "-o", o]


def _render(p, o, kind):
    extra = {"mesh": ["--mesh", p["mesh"]], "env_face": ["--env", p["env_face"].parent],
             "env_file": ["--env", p["env_file"]], "rig": ["--lights", p["rig"]]}
    out = o / ("r_px.exr" if kind.endswith("face") else "r.exr")
    return ["render", p["instance"] if kind == "parent" else p["document"], "-o", out,
            "--size", "16x16", *extra.get(kind, [])]


def _sheet(p, o, kind):
    out = o / ("s_px.png" if kind.endswith("face") else "s.png")
    return ["contact-sheet", p["document"], "-o", out, "--size", "32",
            *(["--mesh", p["mesh"]] if kind == "mesh" else [])]


def _export(suffix):
    def argv(p, o, kind):
        return ["export", p["document"], "-o", o / f"m.{suffix}", "--size", "8",
                *(["--mesh", p["mesh"]] if kind == "mesh" else [])]
    return argv


_DOC_KINDS = ("document", "texture", "function", "preview_mesh", "preview_face")
COMMAND_CASES = {
    "compile": (_DOC_KINDS + ("parent",), lambda kind: "inst.reflection.json"
                if kind == "parent" else "m.reflection.json", _compile),
    "render": (_DOC_KINDS + ("parent", "mesh", "env_face", "env_file", "rig"),
               lambda kind: "r_px.exr" if kind.endswith("face") else "r.exr", _render),
    "bake-ibl": (("env_face", "env_file"), lambda kind: "ibl.json",
                 lambda p, o, kind: ["bake-ibl", p[kind].parent if kind == "env_face"
                                     else p[kind], "-o", o, "--size", "16", "--samples", "16"]),
    "contact-sheet": (_DOC_KINDS + ("mesh",),
                      lambda kind: "s_px.png" if kind.endswith("face") else "s.png", _sheet),
    "bake": (_DOC_KINDS, lambda kind: "m_orm.png",
             lambda p, o, kind: ["bake", p["document"], "-o", o, "--size", "8"]),
    "export": (("document", "texture", "function", "preview_mesh", "mesh"),
               lambda kind: "m.bin", _export("gltf")),
    "export .mtlx": (("document", "texture", "function"), lambda kind: "m.mtlx",
                     _export("mtlx")),
    "export .usda": (("document", "texture", "function", "preview_mesh", "mesh"),
                     lambda kind: "m_orm.png", _export("usda")),
    "export .usdz": (("document", "texture", "function", "preview_mesh", "mesh"),
                     lambda kind: "m.usdz", _export("usdz")),
    "export --check-image": (("texture",), lambda kind: "chk.png",
                             lambda p, o, kind: ["export", p["document"], "-o", o / "m.glb",
                                                 "--size", "8", "--check", "--check-size",
                                                 "16", "--check-image", o / "chk.png"]),
    "export .mtlx --zip": (("document", "texture", "function"), lambda kind: "m.zip",
                           lambda p, o, kind: _export("mtlx")(p, o, kind) + ["--zip"]),
    "import": (("mtlx", "mtlx_image"), lambda kind: "mat.json",
               lambda p, o, kind: ["import", p["mtlx"], "-o", o]),
    "import .json": (("mtlx", "mtlx_image"), lambda kind: "mat.json",
                     lambda p, o, kind: ["import", p["mtlx"], "-o", o / "mat.json"]),
    # a glTF's embedded image, extracted beside the material, over the asset or its .bin
    "import .gltf": (("gltf", "gltf_bin"), lambda kind: "mat_image0.png",
                     lambda p, o, kind: ["import", p["gltf"], "-o", o / "mat.json"]),
}
# Commands that write no file: their declaration must say they read nothing to protect, or
# only documents (validate).
NO_OUTPUT = {"validate", "nodes", "brdf-lut", "stats"}  # stats prints, writes nothing


def _direct_ok(command, kind, name) -> bool:
    """Whether the input can itself sit at the output name and still be read as that kind."""
    if kind in ("document", "parent", "gltf", "gltf_bin"):
        return False  # a document's outputs are named after it; an asset's by its suffix
    if kind.endswith("face"):
        return name.rsplit(".", 1)[0].endswith("_px")
    return True


def _cases():
    for command, (kinds, name, _) in COMMAND_CASES.items():
        for kind in kinds:
            for how in ("direct", "symlink", "hardlink", "read through a link"):
                if how == "direct" and not _direct_ok(command, kind, name(kind)):
                    continue
                if how == "read through a link" and kind in ("parent", "gltf_bin"):
                    continue  # an instance reads its parent's references from the real file;
                    # a .bin linked from outside the asset's folder is refused as leaving it
                yield pytest.param(command, kind, how, id=f"{command}-{kind}-{how}")


def test_every_command_declares_its_inputs():
    """Every command of the parser declares its inputs; a new command without a declaration,
    or one writing files that this section has no cases for, fails here."""
    from matedit.cli import build_parser, subcommand_names

    parser = build_parser()
    names = subcommand_names(parser)
    sub = next(a for a in parser._actions if a.dest == "command")
    covered = {c.split(" ")[0] for c in COMMAND_CASES}
    assert names == covered | NO_OUTPUT, "a command with no input cases here"
    for name in names:
        declared = sub.choices[name].get_default("inputs")
        assert isinstance(declared, dict), f"{name} declares no inputs (declare_inputs)"
        if name in COMMAND_CASES:
            assert declared, name
    from matedit.io.inputs import command_inputs

    with pytest.raises(LookupError, match="declares no inputs"):
        import argparse

        command_inputs(argparse.Namespace(command="new"))


@pytest.mark.parametrize("command, kind, how", list(_cases()))
def test_no_command_writes_over_any_input(tmp_path, command, kind, how):
    _, name, argv = COMMAND_CASES[command]
    out = tmp_path / "out"
    out.mkdir()
    planted = out / name(kind)
    if how == "direct":
        p = _input_tree(tmp_path, {kind: planted})
        victim = planted
    else:
        p = _input_tree(tmp_path)
        victim = p[kind]
        if how == "symlink":
            planted.symlink_to(victim)
        elif how == "hardlink":
            os.link(victim, planted)
        else:  # the command reads the input through a link to the output name
            os.replace(victim, planted)
            victim.symlink_to(planted)
            victim = planted
    before = victim.read_bytes()
    rc, _, err = cli(*argv(p, out, kind))
    assert_clean_failure(rc, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "refusing to write over" in lines[0], err
    assert str(os.path.realpath(victim)) in lines[0], err
    assert victim.read_bytes() == before


MULTI_FILE_OUTPUTS = {  # command -> its arguments, the input planted, each of its file names
    "compile": (lambda p, o: ["compile", p["document"], "-o", o, "--target", "glsl330"],
                ["m.glsl330.vert", "m.glsl330.frag", "m.reflection.json"]),
    "bake": (lambda p, o: ["bake", p["document"], "-o", o, "--size", "8"],
             [f"m_{n}.png" for n in ("base_color", "normal", "orm", "emissive", "opacity")]),
    "bake-ibl": (lambda p, o: ["bake-ibl", p["preview_face"].parent, "-o", o, "--size", "16",
                               "--samples", "16"],
                 ["prefiltered_mip0.exr", "prefiltered_mip4.exr", "brdf_lut.exr", "sh.json",
                  "ibl.json"]),
    "export": (lambda p, o: ["export", p["document"], "-o", o / "m.gltf", "--size", "8"],
               ["m.gltf", "m.bin"]),
    "export .usda": (lambda p, o: ["export", p["document"], "-o", o / "m.usda", "--size", "8"],
                     ["m.usda", "m_base_color.png", "m_normal.png", "m_orm.png",
                      "m_texture0.png"]),
}


@pytest.mark.parametrize("command, file", [(c, f) for c, (_, files) in
                                           MULTI_FILE_OUTPUTS.items() for f in files])
def test_every_file_of_a_multi_file_output_is_checked(tmp_path, command, file):
    """Each file name of a multi-file output, planted as a link to a cube face of the
    material's preview environment (for bake-ibl: of the folder it bakes)."""
    argv, _ = MULTI_FILE_OUTPUTS[command]
    p = _input_tree(tmp_path)
    face = p["preview_face"]
    out = tmp_path / "out"
    out.mkdir()
    (out / file).symlink_to(face)
    before = face.read_bytes()
    rc, _, err = cli(*argv(p, out))
    assert_clean_failure(rc, err)
    assert len(err.strip().splitlines()) == 1 and "refusing to write over" in err, err
    assert str(face) in err and face.read_bytes() == before
    assert sorted(x.name for x in out.iterdir()) == [file]


# --- import -o DIR never replaces a material silently ---------------------------------------

def test_import_into_a_folder_refuses_an_existing_material_without_overwrite(tmp_path):
    p = _input_tree(tmp_path)
    out = tmp_path / "mats"
    assert cli("import", p["mtlx"], "-o", out)[0] == 0
    target = out / "mat.json"
    target.write_text("my edits")
    decoy = tmp_path / "decoy.txt"
    decoy.write_text("precious")
    rc, _, err = cli("import", p["mtlx"], "-o", out)
    assert_clean_failure(rc, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and str(target) in lines[0] and "--overwrite" in lines[0], err
    assert target.read_text() == "my edits"
    target.unlink()
    target.symlink_to(decoy)  # anything at the name, a link too, is refused
    rc, _, err = cli("import", p["mtlx"], "-o", out, "--material", "mat")
    assert_clean_failure(rc, err)
    assert str(target) in err and decoy.read_text() == "precious"
    target.unlink()
    target.write_text("my edits")
    rc, _, err = cli("import", p["mtlx"], "-o", out, "--overwrite")
    assert rc == 0, err
    assert json.loads(target.read_text())["format"] == "matedit.material"


# --- built-in names against files and folders of the same name ------------------------------

def test_builtin_names_and_paths_are_told_apart(tmp_path):
    from matedit.io.inputs import BuiltinNameError, as_reference, builtin_name

    assert builtin_name("studio", "environment") == "studio"
    assert builtin_name("builtin:sky", "environment") == "sky"
    assert builtin_name("builtin:cube", "mesh") == "cube"
    for path in ("./studio", "studio/", str(tmp_path / "studio"), "a/studio", "Studio"):
        assert builtin_name(path, "environment") is None, path
    assert builtin_name(tmp_path / "sphere", "mesh") is None  # a Path is always a file
    assert builtin_name("sphere", "environment") is None  # a mesh's name, not an environment's
    with pytest.raises(BuiltinNameError, match="builtin:studio, builtin:sky"):
        builtin_name("builtin:nope", "environment")
    assert as_reference("studio", "environment") == "./studio"
    assert as_reference("builtin:x", "mesh") == "./builtin:x"
    assert as_reference("studio", "mesh") == "studio"


def test_a_preview_built_in_is_no_file_and_a_path_is(tmp_path):
    from matedit.io.inputs import document_inputs, preview_file

    (tmp_path / "studio").mkdir()
    for f in _FACES:
        (tmp_path / "studio" / f"{f}.hdr").write_bytes(b"face")
    (tmp_path / "sphere").write_text(_TRIANGLE_OBJ)
    for preview, files in [({"environment": "studio", "mesh": "sphere"}, set()),
                           ({"environment": "builtin:studio", "mesh": "builtin:sphere"}, set()),
                           ({"environment": "./studio", "mesh": "./sphere"},
                            {f"studio/{f}.hdr" for f in _FACES} | {"sphere"})]:
        raw = base_material()
        raw["preview"] = preview
        doc = load(write(tmp_path / "m.json", raw))
        assert (preview_file(doc, "environment") is None) == (not files)
        found = {_rel(p, tmp_path) for p in document_inputs(doc)} - {"m.json"}
        assert found == files, preview


def test_an_instance_moved_beside_its_preview_folder_keeps_it_a_path(tmp_path):
    from matedit.io.instance import load_instance, save_instance

    (tmp_path / "a").mkdir()
    (tmp_path / "b" / "studio").mkdir(parents=True)
    write(tmp_path / "m.json", base_material())
    write(tmp_path / "a" / "inst.json", {"format": "matedit.instance", "version": 2,
                                         "parent": "../m.json", "parameters": {},
                                         "preview": {"environment": "../b/studio",
                                                     "mesh": "cube"}})
    doc = load_instance(tmp_path / "a" / "inst.json")
    save_instance(doc, tmp_path / "b" / "inst.json")
    saved = json.loads((tmp_path / "b" / "inst.json").read_text())
    assert saved["preview"] == {"environment": "./studio", "mesh": "cube"}


@pytest.fixture
def builtin_lookalikes(tmp_path, monkeypatch):
    """A working folder holding a folder `studio`, a folder `sphere` and a file `sky`."""
    (tmp_path / "studio").mkdir()
    (tmp_path / "studio" / "notes.txt").write_text("not an environment")
    (tmp_path / "sphere").mkdir()
    (tmp_path / "sky").write_text("not an image")
    write(tmp_path / "m.json", base_material())
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.gl
@pytest.mark.parametrize("options, error", [
    pytest.param([], None, id="defaults"),  # the defaults are built-ins too
    pytest.param(["--env", "studio"], None, id="studio"),
    pytest.param(["--env", "builtin:studio"], None, id="builtin:studio"),
    pytest.param(["--env", "sky", "--mesh", "builtin:cube"], None, id="sky-builtin:cube"),
    pytest.param(["--mesh", "sphere"], None, id="sphere"),
    pytest.param(["--env", "./studio"], "studio: a folder environment needs six cube-face "
                 "files", id="./studio"),
    pytest.param(["--mesh", "./sphere"], "is a folder", id="./sphere"),
    pytest.param(["--env", "builtin:studi0"], "builtin:studio, builtin:sky", id="builtin:typo"),
    pytest.param(["--mesh", "builtin:ball"], "builtin:sphere, builtin:cube", id="builtin:ball"),
    pytest.param(["--env", "stuido"], "builtin:studio, builtin:sky", id="env-typo"),
    pytest.param(["--mesh", "spehre"], "builtin:sphere, builtin:cube", id="mesh-typo"),
])
def test_render_built_in_names_beside_folders_of_those_names(builtin_lookalikes, options,
                                                            error):
    rc, _, err = cli("render", "m.json", "-o", "out.png", "--size", "16x16", *options)
    if error is None:
        assert rc == 0, err
        assert (builtin_lookalikes / "out.png").is_file()
    else:
        assert_clean_failure(rc, err)
        assert len(err.strip().splitlines()) == 1 and error in err, err


@pytest.mark.gl
def test_other_commands_read_built_in_names_beside_folders(builtin_lookalikes):
    rc, _, err = cli("bake-ibl", "studio", "-o", "ibl", "--size", "16", "--samples", "16")
    assert rc == 0, err
    rc, _, err = cli("bake-ibl", "./studio", "-o", "ibl2", "--size", "16", "--samples", "16")
    assert_clean_failure(rc, err)
    assert "six cube-face files" in err and not (builtin_lookalikes / "ibl2").exists()
    rc, _, err = cli("export", "m.json", "-o", "m.gltf", "--size", "8", "--mesh", "sphere")
    assert rc == 0, err
    rc, _, err = cli("export", "m.json", "-o", "n.gltf", "--size", "8", "--mesh", "./sphere")
    assert_clean_failure(rc, err)
    raw = base_material()
    raw["preview"] = {"environment": "builtin:sky", "mesh": "sphere"}
    write(builtin_lookalikes / "p.json", raw)
    rc, _, err = cli("render", "p.json", "-o", "p.png", "--size", "16x16")
    assert rc == 0, err


# --- issue 22: no output writes through a planted link; outputs of several files whole or ----
# --- not at all (full disk, read-only folder); SIGTERM/SIGINT/SIGKILL leave nothing behind ----
#
# Every command case below writes its outputs into one folder, `dest`. A first, clean run of
# the case (cached per case) says which names it writes; the tests then plant links at every
# one of those names, fill the disk while one of them is written, or make `dest` read-only.

_TWO_MATERIALS = """<?xml version="1.0"?>
<materialx version="1.38">
  <standard_surface name="SR_a" type="surfaceshader">
    <input name="base_color" type="color3" value="0.8, 0.2, 0.1" />
  </standard_surface>
  <surfacematerial name="M_a" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR_a" />
  </surfacematerial>
  <standard_surface name="SR_b" type="surfaceshader">
    <input name="specular_roughness" type="float" value="0.3" />
  </standard_surface>
  <surfacematerial name="M_b" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR_b" />
  </surfacematerial>
</materialx>
"""


def _baking_material() -> dict:
    """`base_material` with a radial gradient, which a MaterialX export bakes to an EXR."""
    raw = base_material()
    raw["nodes"].append({"id": "rg", "kind": "radial_gradient", "position": [0, 200]})
    raw["links"] = [l for l in raw["links"] if l["to"] != ["m", "a"]]
    raw["links"].append({"from": ["rg", "value"], "to": ["m", "a"]})
    return raw


@pytest.fixture(scope="module")
def _sources(tmp_path_factory):
    """The inputs every case reads: a material, and a MaterialX document of two materials."""
    src = tmp_path_factory.mktemp("sources")
    write(src / "m.json", _baking_material())
    (src / "two.mtlx").write_text(_TWO_MATERIALS)
    return src


def _replacing(command) -> list[str]:
    """`--overwrite` where the command has it: it would otherwise refuse, before writing, the
    old file or planted link these cases put at an output's name on purpose."""
    import argparse

    from matedit.cli import build_parser

    for action in build_parser()._actions:
        if isinstance(action, argparse._SubParsersAction):
            options = action.choices[command]._option_string_actions
            return ["--overwrite"] if "--overwrite" in options else []
    return []


def _ibl_cache_case(src, dest, monkeypatch):
    """bake-ibl, seen from its cache: `dest` is the cache's ibl folder."""
    monkeypatch.setenv("MATEDIT_CACHE_DIR", str(dest.parent))
    return cli("bake-ibl", "studio", "-o", dest.parent / "bake", "--size", "16",
               "--samples", "16")


# name -> (writes a folder it may create, run(src, dest, monkeypatch) -> cli's result)
OUTPUT_CASES = {
    "compile": (True, lambda s, d, mp: cli("compile", s / "m.json", "-o", d, "--target", "all")),
    "render": (False, lambda s, d, mp: cli("render", s / "m.json", "-o", d / "r.png",
                                           "--size", "16x16")),
    "bake": (True, lambda s, d, mp: cli("bake", s / "m.json", "-o", d, "--size", "8")),
    "bake-ibl": (True, lambda s, d, mp: cli("bake-ibl", "studio", "-o", d, "--size", "16",
                                            "--samples", "16", "--no-cache")),
    "brdf-lut": (False, lambda s, d, mp: cli("brdf-lut", "-o", d / "lut.exr", "--size", "16",
                                             "--samples", "64", "--no-cache")),
    "export-gltf": (False, lambda s, d, mp: cli("export", s / "m.json", "-o", d / "e.gltf",
                                                "--size", "8")),
    "export-glb": (False, lambda s, d, mp: cli("export", s / "m.json", "-o", d / "e.glb",
                                               "--size", "8")),
    "export-mtlx": (False, lambda s, d, mp: cli("export", s / "m.json", "-o", d / "x.mtlx",
                                                "--size", "8")),
    "export-usda": (False, lambda s, d, mp: cli("export", s / "m.json", "-o", d / "u.usda",
                                                "--size", "8")),
    "export-usdz": (False, lambda s, d, mp: cli("export", s / "m.json", "-o", d / "u.usdz",
                                                "--size", "8")),
    "export-mtlx-zip": (False, lambda s, d, mp: cli("export", s / "m.json", "-o",
                                                    d / "x.mtlx", "--size", "8", "--zip")),
    "import-dir": (True, lambda s, d, mp: cli("import", s / "two.mtlx", "-o", d,
                                              *_replacing("import"))),
    "import-json": (False, lambda s, d, mp: cli("import", s / "two.mtlx", "-o", d / "one.json",
                                                "--material", "M_b", *_replacing("import"))),
    "contact-sheet": (False, lambda s, d, mp: cli("contact-sheet", s / "m.json", "-o",
                                                  d / "sheet.png", "--size", "32")),
    "ibl-cache": (True, _ibl_cache_case),
}
MULTI_FILE_CASES = ["compile", "bake", "bake-ibl", "export-gltf", "export-mtlx", "export-usda",
                    "import-dir"]
# export-mtlx writes OUT.mtlx and OUT_textures/ (its baked maps); --zip one OUT.zip
GL_CASES = {"render", "bake", "bake-ibl", "brdf-lut", "export-gltf", "export-glb",
            "export-usda", "export-usdz",
            "contact-sheet", "ibl-cache"}
_LEARNED: dict[str, list[str]] = {}


def _case_params(names):
    return [pytest.param(n, marks=pytest.mark.gl) if n in GL_CASES else n for n in names]


def _run_case(case, src, dest, monkeypatch):
    creates_folder, run = OUTPUT_CASES[case]
    if not creates_folder:
        dest.mkdir(parents=True, exist_ok=True)
    with monkeypatch.context() as mp:
        return run(src, dest, mp)


def _output_names(case, src, root, monkeypatch) -> list[str]:
    """The names a clean run of `case` writes into its folder (learned once per case)."""
    if case not in _LEARNED:
        dest = root / "learn" / ("ibl" if case == "ibl-cache" else "out")
        rc, _, err = _run_case(case, src, dest, monkeypatch)
        assert rc == 0, err
        _LEARNED[case] = _files(dest)
        assert _LEARNED[case] and _leftovers(dest) == []
    return _LEARNED[case]


def _decoy(folder, kind, i):
    """A file a link may point at: a precious file, a FIFO standing in for a device such as
    /dev/zero, or a name that does not exist (a write through the link would create it)."""
    folder.mkdir(exist_ok=True)
    path = folder / f"{kind}{i}"
    if kind == "file":
        path.write_text(f"precious {i}")
    elif kind == "fifo":
        os.mkfifo(path)
    return path


def _decoy_intact(path, kind, i) -> bool:
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return kind == "dangling"
    if kind == "file":
        return stat.S_ISREG(st.st_mode) and path.read_text() == f"precious {i}"
    return kind == "fifo" and stat.S_ISFIFO(st.st_mode)


@pytest.mark.parametrize("kind", ["file", "fifo", "dangling"])
@pytest.mark.parametrize("case", _case_params(OUTPUT_CASES))
def test_outputs_replace_a_link_planted_at_their_name(tmp_path, monkeypatch, _sources, case,
                                                      kind):
    """A link planted at an output's name (in a shared or downloaded folder) is replaced by
    the output; what it pointed at is untouched. Run as root, `bake-ibl` once replaced
    /dev/zero through a planted cache entry."""
    names = _output_names(case, _sources, tmp_path, monkeypatch)
    dest = tmp_path / "planted" / ("ibl" if case == "ibl-cache" else "out")
    dest.mkdir(parents=True)
    decoys = {}
    for i, name in enumerate(names):
        decoys[name] = _decoy(tmp_path / "decoys", kind, i)
        (dest / name).parent.mkdir(parents=True, exist_ok=True)  # a side folder's file
        (dest / name).symlink_to(decoys[name])
    rc, _, err = _run_case(case, _sources, dest, monkeypatch)
    assert rc == 0, err
    for i, name in enumerate(names):
        assert _decoy_intact(decoys[name], kind, i), f"{case} wrote through the link {name}"
        assert stat.S_ISREG(os.lstat(dest / name).st_mode), f"{name} is not a regular file"
    assert _leftovers(dest) == []


def test_document_formats_follow_a_link_only_when_saved_where_they_were_opened(tmp_path):
    """A document opened through a link is saved through it (the artist's file); saved as
    any other name that is a planted link, the link is replaced. The same for instances and
    light rigs (whose save follows a link only when asked to)."""
    from matedit.io import instance as inst_io
    from matedit.io import rig as rigio
    from matedit.render.lights import default_rig

    (tmp_path / "real").mkdir()
    real = write(tmp_path / "real" / "m.json", base_material())
    opened = tmp_path / "opened.json"
    opened.symlink_to(real)
    decoy = _decoy(tmp_path / "decoys", "file", 0)
    planted = tmp_path / "planted.json"
    planted.symlink_to(decoy)
    doc = load(opened)
    doc.name = "through the link"
    save(doc)  # the document's own name: through the link
    assert opened.is_symlink() and load(real).name == "through the link"
    save(doc, planted)  # Save As onto a planted link
    assert _decoy_intact(decoy, "file", 0) and not planted.is_symlink()
    assert load(planted).name == "through the link"

    inst = write(tmp_path / "real" / "i.json", {"format": "matedit.instance", "version": 2,
                                                "parent": "m.json", "parameters": {}})
    (tmp_path / "i.json").symlink_to(inst)
    idoc = inst_io.load_instance(tmp_path / "i.json")
    inst_io.save_instance(idoc)
    assert (tmp_path / "i.json").is_symlink()
    (tmp_path / "planted_i.json").symlink_to(_decoy(tmp_path / "decoys", "file", 1))
    inst_io.save_instance(idoc, tmp_path / "planted_i.json")
    assert _decoy_intact(tmp_path / "decoys" / "file1", "file", 1)
    assert not (tmp_path / "planted_i.json").is_symlink()

    rig_real = tmp_path / "real" / "rig.json"
    rigio.save(default_rig(), rig_real)
    (tmp_path / "rig.json").symlink_to(rig_real)
    before = rig_real.read_text()
    rigio.save(default_rig()[:1], tmp_path / "rig.json", follow_link=True)
    assert (tmp_path / "rig.json").is_symlink() and rig_real.read_text() != before
    (tmp_path / "planted_rig.json").symlink_to(_decoy(tmp_path / "decoys", "file", 2))
    rigio.save(default_rig(), tmp_path / "planted_rig.json")
    assert _decoy_intact(tmp_path / "decoys" / "file2", "file", 2)
    assert not (tmp_path / "planted_rig.json").is_symlink()


def _full_disk_while_writing(monkeypatch, folder, victim):
    """ENOSPC from write(2) or fsync(2) on any file whose path below `folder` names
    `victim` (the output itself, its temporary, or its staged copy)."""
    import errno

    real_write, real_fsync = os.write, os.fsync

    def hit(fd):
        try:
            p = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            return False
        return p.startswith(str(folder) + os.sep) and victim in p[len(str(folder)):]

    def write_(fd, data):
        if hit(fd):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(fd, data)

    def fsync_(fd):
        if hit(fd):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_fsync(fd)

    monkeypatch.setattr(os, "write", write_)
    monkeypatch.setattr(os, "fsync", fsync_)


def _files(dest):
    """The files below `dest`, by their paths relative to it (side folders' too)."""
    return sorted(p.relative_to(dest).as_posix() for p in dest.rglob("*") if not p.is_dir())


def _old_set(dest, names):
    dest.mkdir(parents=True, exist_ok=True)
    for name in names:
        (dest / name).parent.mkdir(parents=True, exist_ok=True)
        (dest / name).write_text(f"old {name}")


def _assert_old_set(dest, names):
    assert _files(dest) == sorted(names), "files added or removed"
    for name in names:
        assert (dest / name).read_text() == f"old {name}", f"{name} was replaced"


@pytest.mark.parametrize("victim, before", [("last", "nothing"), ("first", "an old set")])
@pytest.mark.parametrize("case", _case_params(MULTI_FILE_CASES))
def test_outputs_of_several_files_are_whole_or_absent_on_a_full_disk(
        tmp_path, monkeypatch, _sources, case, victim, before):
    """The disk fills up while one file of the output is written: the command fails cleanly
    and the folder holds exactly what it held before (no half pair: never a new .gltf beside
    an old .bin), with no temporary left."""
    names = _output_names(case, _sources, tmp_path, monkeypatch)
    creates_folder = OUTPUT_CASES[case][0]
    dest = tmp_path / "full" / "out"
    dest.parent.mkdir()
    if before == "an old set":
        _old_set(dest, names)
    elif not creates_folder:
        dest.mkdir(parents=True)
    _full_disk_while_writing(monkeypatch, tmp_path / "full",  # a side file's own name
                             Path(names[-1] if victim == "last" else names[0]).name)
    rc, _, err = _run_case(case, _sources, dest, monkeypatch)
    monkeypatch.undo()
    assert_clean_failure(rc, err)
    assert "No space left on device" in err and ".tmp" not in err, err
    if before == "an old set":
        _assert_old_set(dest, names)
    elif creates_folder:
        assert not dest.exists(), sorted(p.name for p in dest.iterdir())
    else:
        assert list(dest.iterdir()) == []
    assert list((tmp_path / "full").iterdir()) == (
        [dest] if dest.exists() else []), "something was left beside the output folder"


def _read_only(monkeypatch, folder):
    """`folder` made read-only; as root, who writes anyway, by refusing the calls that would
    add, replace or remove an entry of it."""
    import errno

    os.chmod(folder, 0o555)
    if os.geteuid() != 0:
        return

    def inside(path):
        return os.path.dirname(os.path.abspath(os.fspath(path))) == str(folder)

    def refuse(path):
        raise PermissionError(errno.EACCES, "Permission denied", os.fspath(path))

    real = {n: getattr(os, n) for n in ("open", "mkdir", "replace", "rename", "link",
                                        "unlink", "rmdir", "symlink")}
    creating = os.O_CREAT | os.O_WRONLY | os.O_RDWR | os.O_TRUNC

    def open_(path, flags, *a, **k):
        if flags & creating and inside(path):
            refuse(path)
        return real["open"](path, flags, *a, **k)

    def entry(name, which):
        def call(*args, **kw):
            for p in args[:2] if name in ("replace", "rename", "link", "symlink") else args[:1]:
                if which(p):
                    refuse(p)
            return real[name](*args, **kw)
        return call

    monkeypatch.setattr(os, "open", open_)
    for name in real:
        if name != "open":
            monkeypatch.setattr(os, name, entry(name, inside))


@pytest.mark.parametrize("case", _case_params(MULTI_FILE_CASES))
def test_outputs_of_several_files_into_a_read_only_folder_fail_cleanly(
        tmp_path, monkeypatch, _sources, case):
    names = _output_names(case, _sources, tmp_path, monkeypatch)
    dest = tmp_path / "ro" / "out"
    _old_set(dest, names)
    try:
        _read_only(monkeypatch, dest)
        rc, _, err = _run_case(case, _sources, dest, monkeypatch)
        monkeypatch.undo()
    finally:
        os.chmod(dest, 0o755)
    assert_clean_failure(rc, err)
    assert len(err.splitlines()) == 1 and ".tmp" not in err, err
    _assert_old_set(dest, names)



@pytest.mark.parametrize("failing", [0, 1, 2])
def test_staged_outputs_put_every_old_file_back_when_a_move_fails(tmp_path, monkeypatch,
                                                                 failing):
    """The moves into place are the last step: if one fails (here the `failing`-th), those
    already made are undone, so the folder holds the old set (and no new file) again."""
    import errno

    names = ["a.bin", "b.txt", "c.gltf"]
    _old_set(tmp_path, names[:2])  # c.gltf is new
    real = os.replace

    def replace(src, dst):
        if os.fspath(dst) == os.fspath(tmp_path / names[failing]):  # a move into place
            raise OSError(errno.EIO, "Input/output error")
        return real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(OSError, match="Input/output"):
        with atomic.staged_outputs(tmp_path) as stage:
            for name in names:
                stage.write_text(tmp_path / name, "new")
    monkeypatch.undo()
    _assert_old_set(tmp_path, names[:2])
    with pytest.raises(ValueError, match="not in the output folder"):
        with atomic.staged_outputs(tmp_path) as stage:
            stage.path(tmp_path / "sub" / "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == names[:2]


def test_staged_outputs_respect_the_umask_and_keep_modes(tmp_path):
    """A new output folder and new files get the umask; a replaced file keeps its mode."""
    _old_set(tmp_path, ["kept.txt"])
    os.chmod(tmp_path / "kept.txt", 0o604)
    old = os.umask(0o027)
    try:
        with atomic.staged_outputs(tmp_path / "new" / "out") as stage:
            stage.write_bytes(tmp_path / "new" / "out" / "a.bin", b"a")
        with atomic.staged_outputs(tmp_path) as stage:
            stage.write_text(tmp_path / "kept.txt", "new")
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat(tmp_path / "new" / "out").st_mode) == 0o750
    assert stat.S_IMODE(os.stat(tmp_path / "new" / "out" / "a.bin").st_mode) == 0o640
    assert stat.S_IMODE(os.stat(tmp_path / "kept.txt").st_mode) == 0o604
    assert (tmp_path / "kept.txt").read_text() == "new" and stage.written == [
        tmp_path / "kept.txt"]

# --- leftovers and signals --------------------------------------------------------------------

def _dead_pid() -> int:
    import subprocess
    import sys

    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_leftovers_of_dead_processes_are_removed_and_nothing_else(tmp_path):
    """A folder written into loses the temporaries of this user's dead processes on this host,
    matched by their exact pattern, and keeps everything else; links are never followed."""
    dead, host, rand = _dead_pid(), atomic._host_tag(), "0123456789abcdef"
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.txt").write_text("keep")
    work = tmp_path / "work"
    work.mkdir()
    gone = work / f".m.png.{dead}-{host}.{rand}.tmpdir"
    gone.mkdir()
    (gone / "out.png").write_text("half")
    (gone / "link").symlink_to(outside)
    (work / f".m.json.{dead}-{host}.{rand}.tmp").write_text("half")
    kept = [
        f".m.png.{os.getpid()}-{host}.{rand}.tmpdir",  # a live process (this one)
        f".m.png.{dead}-{'f' * 8 if host != 'f' * 8 else '0' * 8}.{rand}.tmpdir",  # elsewhere
        f".m.png.{dead}-{host}.{rand[:-1]}.tmpdir",  # near misses of the pattern
        f"m.png.{dead}-{host}.{rand}.tmpdir",
        f".m.png.{dead}-{host}.{rand}.tmpdir.bak",
        f".m.png.{dead}-{host}.{rand}.TMPDIR",
        f".m.png.{dead}.{rand}.tmpdir",
    ]
    for name in kept:
        (work / name).mkdir()
    odd = [f".a.{dead}-{host}.{rand}.tmpdir", f".b.{dead}-{host}.{rand}.tmp"]
    (work / odd[0]).symlink_to(outside)  # the pattern, but a link: never followed
    (work / odd[1]).mkdir()  # the pattern of a file, but a folder
    atomic_write_bytes(work / "new.txt", b"x")
    assert sorted(p.name for p in work.iterdir()) == sorted([*kept, *odd, "new.txt"])
    assert (outside / "keep.txt").read_text() == "keep" and (work / odd[0]).is_symlink()
    names = {atomic.temporary_name("out.png", "tmpdir") for _ in range(3)}
    assert len(names) == 3 and all(
        n.startswith(f".out.png.{os.getpid()}-{host}.") for n in names)
    assert len(atomic.temporary_name("x" * 255)) < 255


_SLOW_BAKE = r"""
import sys, time
from pathlib import Path
import matedit.io.images as images

marker, real, calls = Path(sys.argv[1]), images.write_oiio, []


def slow(path, spec, pixels):  # the second map waits, with the first one written
    calls.append(path)
    if len(calls) == 2:
        marker.write_text("writing")
        time.sleep(120)
    return real(path, spec, pixels)


images.write_oiio = slow
from matedit.cli import main

sys.exit(main(sys.argv[2:]))
"""


def _bake_until_mid_write(tmp_path, doc, dest):
    """`matedit bake` in a child process, returned once it is writing its second map."""
    import subprocess
    import sys
    import time

    import matedit

    root = os.path.dirname(os.path.dirname(matedit.__file__))
    env = {**os.environ, "PYTHONPATH": root}
    marker = tmp_path / "marker"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_BAKE, str(marker), "bake", str(doc),
                             "-o", str(dest), "--size", "8"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not marker.exists():
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            out, err = proc.communicate()
            pytest.fail(f"the bake ended before its second map ({proc.returncode}): {err}")
        time.sleep(0.02)
    return proc


@pytest.mark.gl
@pytest.mark.parametrize("sig, status", [("SIGTERM", 143), ("SIGINT", 130),
                                         ("SIGINT SIGINT", 130), ("SIGINT SIGTERM", 130)])
def test_a_signal_mid_bake_cleans_up(tmp_path, sig, status):
    """SIGTERM or SIGINT while a bake writes its maps: one `error: interrupted` line, and
    neither a map nor a temporary is left (the folder it created is gone too). A second
    signal while the first one's clean-up runs is ignored, not a traceback."""
    import signal
    import time

    doc = write(tmp_path / "m.json", base_material())
    dest = tmp_path / "maps"
    proc = _bake_until_mid_write(tmp_path, doc, dest)
    for i, name in enumerate(sig.split()):
        if i:
            time.sleep(0.005)
        proc.send_signal(getattr(signal, name))
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    assert err.splitlines() == ["error: interrupted"], err
    assert not dest.exists(), sorted(p.name for p in dest.iterdir())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json", "marker"]


@pytest.mark.gl
def test_a_bake_killed_mid_write_leaves_a_leftover_the_next_run_removes(tmp_path):
    """SIGKILL cannot be caught: the half-written bake stays in its temporary folder (no map
    under its real name), named so that the next run into the folder removes it."""
    import signal

    doc = write(tmp_path / "m.json", base_material())
    dest = tmp_path / "maps"
    proc = _bake_until_mid_write(tmp_path, doc, dest)
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    left = sorted(p.name for p in dest.iterdir())
    assert left and all(n.startswith(".") and n.endswith(".tmpdir") for n in left), left
    handler = signal.getsignal(signal.SIGTERM)
    rc, _, err = cli("bake", doc, "-o", dest, "--size", "8")
    assert rc == 0, err
    assert sorted(p.name for p in dest.iterdir()) == ["m_base_color.png", "m_normal.png",
                                                      "m_orm.png"]
    assert signal.getsignal(signal.SIGTERM) == handler  # a command leaves it as it was


# --- a real full disk (a small tmpfs), where root may mount one ------------------------------
# Writers that buffer through stdio (OpenImageIO's PNG) lose ENOSPC in their close, so an
# injected error in Python cannot stand in for this one: the disk must really be full.


@pytest.fixture
def tiny_disk(tmp_path):
    import shutil as _shutil
    import subprocess

    mnt = tmp_path / "tiny"
    mnt.mkdir()
    mount = _shutil.which("mount")
    if os.geteuid() != 0 or mount is None or subprocess.run(
            [mount, "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
            capture_output=True).returncode != 0:
        pytest.skip("a 64 KiB tmpfs needs root and mount")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


@pytest.mark.parametrize("ext", [".png", ".exr", ".tif"])
def test_an_image_that_does_not_fit_on_the_disk_is_an_error_and_keeps_the_old_file(
        tiny_disk, ext):
    from matedit.io.images import ImageError, write_image

    target = tiny_disk / f"noise{ext}"
    target.write_bytes(b"old")
    noise = np.random.default_rng(1).random((256, 256, 3), dtype=np.float32)  # ~190 KiB
    with pytest.raises(ImageError, match=rf"{target.name}: cannot write image") as info:
        write_image(target, noise)
    assert ".tmpdir" not in str(info.value)  # the message names the output, not a temporary
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tiny_disk.iterdir()) == [target.name]


@pytest.mark.gl
def test_render_and_bake_to_a_full_disk_exit_2_and_keep_old_files(tiny_disk):
    import glob

    from matedit.resources import graphs_dir

    sample = sorted(glob.glob(str(graphs_dir() / "materials" / "rusty_painted_metal.json")))[0]
    old = tiny_disk / "r.png"
    old.write_bytes(b"old")
    rc, _, err = cli("render", sample, "-o", old, "--size", "384x384")
    assert_clean_failure(rc, err)
    assert "r.png" in err and old.read_bytes() == b"old"
    rc, _, err = cli("bake", sample, "-o", tiny_disk / "maps", "--size", "256")
    assert_clean_failure(rc, err)
    assert sorted(p.name for p in tiny_disk.iterdir()) == ["r.png"]


@pytest.mark.gl
@pytest.mark.parametrize("command", ["render", "bake"])
@pytest.mark.parametrize("where", ["through the link", "lexically"])
def test_a_texture_reached_through_a_link_and_dotdot_is_an_input(tmp_path, command, where):
    """`lnk/../NAME.png`, with lnk a link into another folder, names the NAME.png the system
    reaches (beside the link's target), which the compiler reads; the one a reader that
    tidies `..` away would open (beside the document) is guarded too."""
    name = "albedo.png" if command == "render" else "m_base_color.png"  # a map bake writes
    folder = tmp_path / "D"
    (tmp_path / "far" / "sub").mkdir(parents=True)
    folder.mkdir()
    (folder / "lnk").symlink_to("../far/sub")
    doc = _material_with_texture(folder)
    raw = json.loads(doc.read_text())
    raw["nodes"][-2]["settings"]["path"] = f"lnk/../{name}"
    doc.write_text(json.dumps(raw))
    physical, lexical = tmp_path / "far" / name, folder / name
    os.replace(folder / "albedo.png", physical)
    shutil.copyfile(physical, lexical)
    before = {p: p.read_bytes() for p in (physical, lexical)}
    target = physical if where == "through the link" else lexical
    out = ["-o", target, "--size", "16x16"] if command == "render" else \
        ["-o", target.parent, "--size", "16"]
    rc, _, err = cli(command, doc, *out)
    assert_clean_failure(rc, err)
    assert "the texture" in err
    assert {p: p.read_bytes() for p in before} == before


@pytest.mark.gl
def test_an_instance_texture_override_through_a_link_and_dotdot_is_an_input(tmp_path):
    """An instance's `lnk/../tex2.png` override: the file beside the instance, as a reader
    that tidies `..` away would open it, may not be the render's output either."""
    src = tmp_path / "src"
    src.mkdir()
    doc = _material_with_texture(src)
    folder = tmp_path / "D"
    (tmp_path / "far" / "sub").mkdir(parents=True)
    folder.mkdir()
    (folder / "lnk").symlink_to(tmp_path / "far" / "sub")
    shutil.copyfile(src / "albedo.png", folder / "tex2.png")
    before = (folder / "tex2.png").read_bytes()
    inst = folder / "i.json"
    inst.write_text(json.dumps({"format": "matedit.instance", "version": 2,
                                "parent": os.path.relpath(doc, folder),
                                "parameters": {"albedo": "lnk/../tex2.png"}}))
    rc, _, err = cli("render", inst, "-o", folder / "tex2.png", "--size", "16x16")
    assert_clean_failure(rc, err)
    assert "the texture" in err and (folder / "tex2.png").read_bytes() == before
