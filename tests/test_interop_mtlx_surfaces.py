"""`matedit export OUT.mtlx --surface open_pbr_surface|standard_surface|gltf_pbr`: every
MaterialAttributes field each surface carries comes back from `matedit import` within 1e-6
(CPU evaluator at the texel centres), every field it cannot carry is a `note:` line naming it,
and the document passes MaterialX's own validate(); the self-contained folder (OUT.mtlx and
OUT_textures/: baked maps, texture copies) still validates and resolves every file it names
when copied elsewhere, PNG maps decode to within 1/255 of the EXR bake, and --zip holds the
same files by relative names."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

mx = pytest.importorskip("MaterialX")

SURFACES = ("open_pbr_surface", "standard_surface", "gltf_pbr")
_N = [0.2, -0.1, 0.0]
_N[2] = float(np.sqrt(1.0 - _N[0] ** 2 - _N[1] ** 2))
_C = [-0.3, 0.25, 0.0]
_C[2] = float(np.sqrt(1.0 - _C[0] ** 2 - _C[1] ** 2))
# Every field but the attenuation pair (whose depth makes transmission_color the absorption
# colour: the second material carries those).
FIELDS_A = {
    "baseColor": [0.7, 0.4, 0.2], "metallic": 0.3, "roughness": 0.45, "cavity": 0.8,
    "normal": _N, "emissive": [0.3, 0.2, 0.1], "opacity": 0.85,
    "specularColor": [0.9, 0.8, 0.7], "ior": 1.8, "coat": 0.75, "coatRoughness": 0.08,
    "coatColor": [0.96, 0.64, 0.54], "coatIor": 1.6, "coatNormal": _C,
    "sheenColor": [0.2, 0.3, 0.4], "sheenRoughness": 0.6, "anisotropy": 0.7,
    "anisotropyDirection": [0.0, 1.0, 0.0], "subsurface": 0.6,
    "subsurfaceColor": [0.9, 0.5, 0.4], "subsurfaceRadius": [0.3, 0.1, 0.05],
    "thickness": 0.25, "thinFilmThickness": 420.0, "thinFilmIor": 1.45,
    "transmission": 0.4, "transmissionColor": [0.8, 0.9, 0.7],
}
FIELDS_B = {"baseColor": [0.9, 0.9, 0.9], "roughness": 0.1, "transmission": 1.0,
            "attenuationColor": [0.6, 0.8, 0.3], "attenuationDistance": 0.05,
            "thickness": 0.5}
# Fields a surface does not carry: each is named in a note (and reads back as our default).
DROPPED = {
    "open_pbr_surface": {"thickness"},  # folded into the mean free path: radius / thickness
    "standard_surface": set(),
    "gltf_pbr": {"coatColor", "coatIor", "subsurface", "subsurfaceColor",
                 "subsurfaceRadius", "transmissionColor"},
}


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *map(str, args)],
                          capture_output=True, text=True)


def _material(path: Path, values: dict) -> Path:
    """make_attributes with `values`; the normal (a constant normal value is the surface's
    own, unwritten) through a constant node."""
    consts = {k: v for k, v in values.items() if k == "normal"}
    nodes = [{"id": "make", "kind": "make_attributes",
              "values": {k: v for k, v in values.items() if k not in consts}},
             {"id": "out", "kind": "material_output"}]
    links = [{"from": ["make", "attributes"], "to": ["out", "attributes"]}]
    for k, v in consts.items():
        nodes.append({"id": f"c_{k}", "kind": "constant",
                      "settings": {"type": "vec3", "value": v}})
        links.append({"from": [f"c_{k}", "value"], "to": ["make", k]})
    path.write_text(json.dumps({"format": "matedit.material", "version": 2,
                                "name": path.stem, "nodes": nodes, "links": links}))
    return path


def _load(path: Path):
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(path))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    return doc


def _attrs(path: Path):
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load

    return bake.attributes_cpu(lower_and_optimise(load(path), FileResolver()), 2)


def _glsl(doc) -> None:
    from MaterialX import PyMaterialXGenGlsl as mx_glsl
    from MaterialX import PyMaterialXGenShader as mx_gen

    gen = mx_glsl.GlslShaderGenerator.create()
    ctx = mx_gen.GenContext(gen)
    ctx.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    mat = doc.getMaterialNodes()[0]
    shader = gen.generate(mat.getName(), mat, ctx)
    assert "void main" in shader.getSourceCode(mx_gen.PIXEL_STAGE)


@pytest.mark.parametrize("surface", SURFACES)
@pytest.mark.parametrize("fields", ["A", "B"])
def test_every_field_round_trips_through_each_surface(tmp_path, surface, fields):
    values = FIELDS_A if fields == "A" else FIELDS_B
    src = _material(tmp_path / f"m{fields}.json", values)
    assert cli("validate", src).returncode == 0
    out = tmp_path / "x" / f"m{fields}.mtlx"
    out.parent.mkdir()
    r = cli("export", src, "-o", out, "--surface", surface)
    assert r.returncode == 0, r.stderr
    doc = _load(out)
    ok, msg = doc.validate()
    assert ok, msg
    assert [n.getCategory() for n in doc.getNodes() if n.getType() == "surfaceshader"] == [
        surface]
    _glsl(doc)
    dropped = DROPPED[surface] & set(values)
    for line in r.stderr.splitlines():
        assert line.startswith("note: "), line
    for name in dropped:
        assert f": {name}: " in r.stderr, (name, r.stderr)
    back = tmp_path / "back.json"
    r = cli("import", out, "-o", back)
    assert r.returncode == 0, r.stderr
    a, b = _attrs(src), _attrs(back)
    for k, v in values.items():
        np.testing.assert_allclose(a[k][0, 0], v, atol=1e-6, err_msg=k)
        if k in dropped or (surface == "open_pbr_surface" and k == "subsurfaceRadius"):
            continue  # the radius carries radius / thickness there (checked below)
        want = a[k]
        if k == "anisotropyDirection":
            want = want / np.linalg.norm(want, axis=-1, keepdims=True)
        np.testing.assert_allclose(b[k], want, atol=1e-6, err_msg=f"{surface}: {k}")
    if surface == "open_pbr_surface" and "subsurfaceRadius" in values:
        # what the shading reads of the two: radius / thickness
        np.testing.assert_allclose(b["subsurfaceRadius"] / b["thickness"],
                                   a["subsurfaceRadius"] / a["thickness"], rtol=1e-6)


def _textured(folder: Path) -> Path:
    """A material reading an sRGB albedo texture (its sheen, and a colour bake's input)
    and a linear one, and baking a noise (a data map) and an HSV adjust (a colour map)."""
    from tests.interop_tools import textured_material

    folder.mkdir(parents=True, exist_ok=True)
    src, _, _ = textured_material(folder, 8)
    d = json.loads(src.read_text())
    d["nodes"] += [{"id": "nz", "kind": "value_noise", "values": {"scale": 9.0}},
                   {"id": "hue", "kind": "hsv_adjust", "values": {"hue": 0.1}}]
    d["links"] = [lk for lk in d["links"] if lk["to"] != ["make", "baseColor"]]
    d["links"] += [{"from": ["nz", "value"], "to": ["make", "cavity"]},
                   {"from": ["nz", "value"], "to": ["hue", "saturation"]},
                   {"from": ["sa", "rgb"], "to": ["hue", "color"]},
                   {"from": ["sa", "rgb"], "to": ["make", "sheenColor"]},
                   {"from": ["hue", "result"], "to": ["make", "baseColor"]}]
    src.write_text(json.dumps(d))
    return src


def _named_files(doc) -> list[str]:
    """The file names of the document's own image nodes (not its libraries')."""
    return [i.getInput("file").getValueString() for g in doc.getNodeGraphs()
            if not g.hasSourceUri() for i in g.getNodes("image")]


def test_the_export_travels(tmp_path):
    src = _textured(tmp_path / "in")
    r = cli("validate", src)
    assert r.returncode == 0, r.stdout + r.stderr
    out = tmp_path / "out" / "look.mtlx"
    out.parent.mkdir()
    r = cli("export", src, "-o", out, "--size", "16")
    assert r.returncode == 0, r.stderr
    assert "baked map(s) at 16 x 16 texels" in r.stderr, r.stderr
    moved = tmp_path / "elsewhere"
    shutil.copytree(out.parent, moved)
    shutil.rmtree(out.parent)
    shutil.rmtree(tmp_path / "in")  # the textures it read are gone too
    doc = _load(moved / "look.mtlx")
    ok, msg = doc.validate()
    assert ok, msg
    files = _named_files(doc)
    assert files and all(f.startswith("look_textures/") for f in files), files
    # MaterialX resolves each name relative to the document: every one is there
    resolver = mx.FileSearchPath(str(moved))
    for f in files:
        found = resolver.find(mx.FilePath(f))
        assert Path(found.asString()).is_file(), f
    assert "look_textures/albedo.png" in files and "look_textures/data.png" in files
    for name in files:
        assert name.endswith(".png"), name
    assert not any(p.is_symlink() for p in moved.rglob("*"))


def test_png_maps_decode_to_the_exr_bake(tmp_path):
    from matedit.io.images import read_image

    src = _textured(tmp_path / "in")
    png, exr = tmp_path / "p" / "m.mtlx", tmp_path / "e" / "m.mtlx"
    for out, fmt in ((png, "png"), (exr, "exr")):
        out.parent.mkdir()
        r = cli("export", src, "-o", out, "--size", "16", "--format", fmt)
        assert r.returncode == 0, r.stderr
    dp, de = _load(png), _load(exr)
    spaces = {}
    for g in (g for g in dp.getNodeGraphs() if not g.hasSourceUri()):
        for i in g.getNodes("image"):
            spaces[i.getInput("file").getValueString()] = i.getInput("file").getColorSpace()
    baked = [f for f in _named_files(dp) if "_baked" in f]
    assert baked and {f[:-4] + ".exr" for f in baked} <= set(_named_files(de))
    colour = [f for f in baked if spaces[f] == "srgb_texture"]
    data = [f for f in baked if spaces[f] == "lin_rec709"]
    assert colour and data, spaces
    from matedit.interop.bake import linear_to_srgb

    for f in baked:
        p = read_image(png.parent / f).pixels.astype(np.float64)
        e = read_image(exr.parent / (f[:-4] + ".exr")).pixels.astype(np.float64)
        if f in colour:  # 8-bit sRGB codes against the encoded float bake
            e = linear_to_srgb(e)
        # rounding to 8 bits: half a code, and the float bake's own float32 rounding
        np.testing.assert_allclose(p, e, atol=1.0 / 255.0, err_msg=f)


def test_zip_holds_the_document_and_its_side_files(tmp_path):
    src = _textured(tmp_path / "in")
    out = tmp_path / "o" / "pack.mtlx"
    out.parent.mkdir()
    r = cli("export", src, "-o", out, "--size", "8", "--zip")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in out.parent.iterdir()) == ["pack.zip"]
    with zipfile.ZipFile(out.with_suffix(".zip")) as z:
        names = z.namelist()
        assert all(not n.startswith("/") and ".." not in n for n in names), names
        dest = tmp_path / "unz"
        z.extractall(dest)
    doc = _load(dest / "pack.mtlx")
    ok, msg = doc.validate()
    assert ok, msg
    assert set(_named_files(doc)) | {"pack.mtlx"} == set(names)


def test_fine_detail_is_noted_with_a_larger_size(tmp_path):
    d = {"format": "matedit.material", "version": 2, "name": "fine",
         "nodes": [{"id": "nz", "kind": "value_noise", "values": {"scale": 200.0}},
                   {"id": "make", "kind": "make_attributes"},
                   {"id": "out", "kind": "material_output"}],
         "links": [{"from": ["nz", "value"], "to": ["make", "roughness"]},
                   {"from": ["make", "attributes"], "to": ["out", "attributes"]}]}
    src = tmp_path / "fine.json"
    src.write_text(json.dumps(d))
    r = cli("export", src, "-o", tmp_path / "fine.mtlx", "--size", "8")
    assert r.returncode == 0, r.stderr
    assert "detail finer than its 8 x 8 texels" in r.stderr and "--size 16" in r.stderr
    d["nodes"][0]["values"]["scale"] = 0.5  # smooth over the square: no warning
    src.write_text(json.dumps(d))
    r = cli("export", src, "-o", tmp_path / "smooth.mtlx", "--size", "8")
    assert r.returncode == 0, r.stderr
    assert "baked map(s) at 8 x 8" in r.stderr and "detail finer" not in r.stderr


def test_side_files_never_follow_a_planted_link_nor_overwrite_an_input(tmp_path):
    """A link planted at OUT_textures (to a folder) is replaced by a real folder, nothing is
    written through it; a side file that would land on a texture the material reads is
    refused by name, and nothing is written."""
    src = _textured(tmp_path / "in")
    out = tmp_path / "o" / "look.mtlx"
    out.parent.mkdir()
    victim = tmp_path / "victim"
    victim.mkdir()
    (out.parent / "look_textures").symlink_to(victim)
    r = cli("export", src, "-o", out, "--size", "8")
    assert r.returncode == 0, r.stderr
    assert list(victim.iterdir()) == []
    side = out.parent / "look_textures"
    assert side.is_dir() and not side.is_symlink() and (side / "albedo.png").is_file()
    # exporting next to its own textures: the copy would be the texture itself
    inside = tmp_path / "in" / "textured.mtlx"
    shutil.rmtree(side)
    (tmp_path / "in" / "textured_textures").mkdir()
    shutil.move(str(tmp_path / "in" / "albedo.png"), tmp_path / "in" / "textured_textures")
    d = json.loads(src.read_text())
    for n in d["nodes"]:
        if n.get("settings", {}).get("path") == "albedo.png":
            n["settings"]["path"] = "textured_textures/albedo.png"
    src.write_text(json.dumps(d))
    before = (tmp_path / "in" / "textured_textures" / "albedo.png").read_bytes()
    r = cli("export", src, "-o", inside, "--size", "8")
    assert r.returncode == 2 and "refusing to write over" in r.stderr, r.stderr
    assert r.stderr.count("\n") == 1
    assert (tmp_path / "in" / "textured_textures" / "albedo.png").read_bytes() == before
    assert not inside.exists()


def _varying(path: Path, values: dict) -> Path:
    """Every field of `values` varying over the surface: v x (0.8 + 0.2 u) (a multiply_add of
    the texture coordinate's u), but the anisotropy direction (a constant: the export takes
    no other) and the normals (v + (0.1 u, 0, 0), normalised by the shading)."""
    nodes = [{"id": "uv", "kind": "texcoord"}, {"id": "sp", "kind": "split"},
             {"id": "make", "kind": "make_attributes",
              "values": {"anisotropyDirection": values["anisotropyDirection"]}
              if "anisotropyDirection" in values else {}},
             {"id": "out", "kind": "material_output"}]
    links = [{"from": ["uv", "uv"], "to": ["sp", "value"]},
             {"from": ["make", "attributes"], "to": ["out", "attributes"]}]
    for k, v in values.items():
        if k == "anisotropyDirection":
            continue
        v = np.asarray(v, dtype=np.float64)
        if k in ("normal", "coatNormal"):
            b, c = [0.1, 0.0, 0.0], v.tolist()
        else:
            b, c = (0.2 * v).tolist(), (0.8 * v).tolist()
        nodes.append({"id": f"f_{k}", "kind": "multiply_add", "values": {"b": b, "c": c}})
        links += [{"from": ["sp", "x"], "to": [f"f_{k}", "a"]},
                  {"from": [f"f_{k}", "result"], "to": ["make", k]}]
    path.write_text(json.dumps({"format": "matedit.material", "version": 2,
                                "name": path.stem, "nodes": nodes, "links": links}))
    return path


@pytest.mark.gl
@pytest.mark.parametrize("surface", SURFACES)
@pytest.mark.parametrize("fields", ["A", "B"])
def test_materialx_glsl_of_every_varying_field_matches_cpu(ctx, tmp_path, surface, fields):
    """Each surface input the export connects to its nodegraph, generated to GLSL by
    MaterialX's own generator and drawn on the bake plane, equals our CPU evaluator's field
    at the texel centres within 2e-3 (1e-3 relative for a 1 / thickness), every lobe of the
    two materials, on each surface."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load
    from tests.mtlx_gpu import MtlxDrawer
    from tests.test_interop_mtlx import SURFACE_INPUTS, SURFACE_READS

    size = 8
    src = _varying(tmp_path / f"v{fields}.json", FIELDS_A if fields == "A" else FIELDS_B)
    r = cli("validate", src)
    assert r.returncode == 0, r.stdout + r.stderr
    out = tmp_path / f"v{fields}.mtlx"
    r = cli("export", src, "-o", out, "--surface", surface, "--size", str(size))
    assert r.returncode == 0, r.stderr
    doc = _load(out)
    ok, msg = doc.validate()
    assert ok, msg
    reads = SURFACE_READS.get(surface) or {
        k: (v, "inverse" if k == "subsurface_scale" else
            "unit" if k in ("normal", "coat_normal") else "") for k, v in SURFACE_INPUTS.items()}
    cpu = bake.attributes_cpu(lower_and_optimise(load(src), FileResolver()), size)
    shader = next(n for n in doc.getNodes() if n.getCategory() == surface)
    drawer = MtlxDrawer(ctx, size)
    checked = set()
    try:
        for inp in shader.getInputs():
            if not inp.getNodeGraphString():
                continue
            o = doc.getNodeGraph(inp.getNodeGraphString()).getOutput(inp.getOutputString())
            got = drawer.draw(doc, o, tmp_path)
            attr, how = reads[inp.getName()]
            want = cpu[attr]
            if inp.getName() == "transmission_color" and shader.getInput("transmission_depth"):
                want = cpu["attenuationColor"]
            if how == "unit":
                want = want / np.linalg.norm(want, axis=-1, keepdims=True)
            if how == "milli":
                want = want * 1e-3
            k = want.shape[-1]
            if how == "inverse":
                np.testing.assert_allclose(got[..., :k], 1.0 / np.maximum(want, 1e-4),
                                           rtol=1e-3, err_msg=inp.getName())
            else:
                np.testing.assert_allclose(got[..., :k], want, atol=2e-3,
                                           err_msg=inp.getName())
            checked.add(attr)
    finally:
        drawer.release()
    # every field the surface carries varies, so each was drawn
    values = FIELDS_A if fields == "A" else FIELDS_B
    carried = {a for a, _ in reads.values()} & set(values)
    carried -= {"anisotropyDirection"} if surface != "open_pbr_surface" else set()
    if fields == "B":
        carried -= {"transmissionColor"}
    if fields == "A" and surface != "gltf_pbr":
        carried -= {"attenuationColor", "attenuationDistance"}
    assert carried <= checked, sorted(carried - checked)
