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
    "import-dir": (True, lambda s, d, mp: cli("import", s / "two.mtlx", "-o", d,
                                              *_replacing("import"))),
    "import-json": (False, lambda s, d, mp: cli("import", s / "two.mtlx", "-o", d / "one.json",
                                                "--material", "M_b", *_replacing("import"))),
    "contact-sheet": (False, lambda s, d, mp: cli("contact-sheet", s / "m.json", "-o",
                                                  d / "sheet.png", "--size", "32")),
    "ibl-cache": (True, _ibl_cache_case),
}
MULTI_FILE_CASES = ["compile", "bake", "bake-ibl", "export-gltf", "export-mtlx", "import-dir"]
GL_CASES = {"render", "bake", "bake-ibl", "brdf-lut", "export-gltf", "export-glb",
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
        _LEARNED[case] = sorted(p.name for p in dest.iterdir())
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
    if case == "ibl-cache" and kind == "fifo":
        pytest.skip("a FIFO cache entry is refused when read (the cache's own validation)")
    names = _output_names(case, _sources, tmp_path, monkeypatch)
    dest = tmp_path / "planted" / ("ibl" if case == "ibl-cache" else "out")
    dest.mkdir(parents=True)
    decoys = {}
    for i, name in enumerate(names):
        decoys[name] = _decoy(tmp_path / "decoys", kind, i)
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


def _old_set(dest, names):
    dest.mkdir(parents=True, exist_ok=True)
    for name in names:
        (dest / name).write_text(f"old {name}")


def _assert_old_set(dest, names):
    assert sorted(p.name for p in dest.iterdir()) == sorted(names), "files added or removed"
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
    _full_disk_while_writing(monkeypatch, tmp_path / "full",
                             names[-1] if victim == "last" else names[0])
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
@pytest.mark.parametrize("sig, status", [("SIGTERM", 143), ("SIGINT", 130)])
def test_a_signal_mid_bake_cleans_up(tmp_path, sig, status):
    """SIGTERM or SIGINT while a bake writes its maps: one `error: interrupted` line, and
    neither a map nor a temporary is left (the folder it created is gone too)."""
    import signal

    doc = write(tmp_path / "m.json", base_material())
    dest = tmp_path / "maps"
    proc = _bake_until_mid_write(tmp_path, doc, dest)
    proc.send_signal(getattr(signal, sig))
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
