"""`matedit bake` and `matedit export OUT.gltf|glb`.

References: the CPU evaluator for the baked maps (the GPU attribute pass must match it at
texel centres within 1/255 after 8-bit encoding, 1e-4 in float EXR), and the Khronos
glTF-Validator (npm `gltf-validator`) for the assets: 0 errors (warnings are reported too and
must also be 0 for our files).
"""

from __future__ import annotations

import copy
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from matedit.compiler.api import compile_document, lower_and_optimise
from matedit.graph.nodes import ATTRIBUTE_FIELDS
from matedit.interop import bake
from matedit.io.document import FileResolver, load
from matedit.io.images import read_image
from matedit.resources import graphs_dir
from tests.interop_tools import validate_gltf

SAMPLES = sorted((graphs_dir() / "materials").glob("*.json"))
SIZE = 32


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


def file_pixels(path: Path) -> np.ndarray:
    """A map read back as the bake stores it, row 0 = v = 0."""
    return read_image(path).pixels[::-1].astype(np.float64)


@pytest.mark.gl
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_gpu_attribute_bake_matches_cpu_evaluator(ctx, path):
    doc = load(path)
    r = FileResolver()
    ir = lower_and_optimise(doc, r)
    cm = compile_document(doc, r, "glsl330", mode="attributes", ir=ir)
    gpu = bake.attributes_gpu(ctx, cm, 48)
    cpu = bake.attributes_cpu(lower_and_optimise(doc, r), 48)
    # The ATTRIBUTES entry bakes the talk's seven fields (what glTF's core material takes);
    # the lobe fields' node code is checked against the CPU in tests/test_nodes_gpu.py.
    assert set(gpu) == {f.name for f in ATTRIBUTE_FIELDS if not f.lobe} <= set(cpu)
    for k in gpu:
        np.testing.assert_allclose(gpu[k], cpu[k], atol=1e-4, err_msg=f"{path.stem} {k}")


@pytest.mark.gl
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_baked_png_maps_match_cpu_at_texel_centres(tmp_path, path):
    r = cli("bake", str(path), "-o", str(tmp_path), "--size", str(SIZE))
    assert r.returncode == 0, r.stderr
    doc = load(path)
    ir = lower_and_optimise(doc, FileResolver())
    cpu = bake.attributes_cpu(ir, SIZE)
    expect = {
        "base_color": bake.linear_to_srgb(cpu["baseColor"]),
        "normal": np.clip(cpu["normal"] * 0.5 + 0.5, 0, 1),
        "orm": np.clip(np.concatenate([cpu["cavity"], cpu["roughness"], cpu["metallic"]], -1),
                       0, 1),
    }
    if "emissive" in ir.attributes and np.any(cpu["emissive"] != 0):
        expect["emissive"] = bake.linear_to_srgb(cpu["emissive"])
    if "opacity" in ir.attributes and np.any(cpu["opacity"] != 1):
        expect["opacity"] = np.clip(cpu["opacity"], 0, 1)
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == sorted(f"{path.stem}_{n}.png" for n in expect)
    for name, want in expect.items():
        got = file_pixels(tmp_path / f"{path.stem}_{name}.png")
        assert got.shape == (SIZE, SIZE, want.shape[-1])
        err = np.abs(got - want).max()
        assert err <= 1.0 / 255.0 + 1e-9, f"{name}: max error {err * 255:.3f}/255"


@pytest.mark.gl
def test_baked_exr_keeps_linear_floats(tmp_path):
    path = graphs_dir() / "materials" / "mossy_stone.json"
    r = cli("bake", str(path), "-o", str(tmp_path), "--size", "16", "--format", "exr")
    assert r.returncode == 0, r.stderr
    cpu = bake.attributes_cpu(lower_and_optimise(load(path), FileResolver()), 16)
    got = file_pixels(tmp_path / "mossy_stone_base_color.exr")
    np.testing.assert_allclose(got, cpu["baseColor"], atol=1e-4)
    orm = file_pixels(tmp_path / "mossy_stone_orm.exr")
    np.testing.assert_allclose(orm[..., 1], cpu["roughness"][..., 0], atol=1e-4)


def test_bake_rejects_bad_size(tmp_path):
    r = cli("bake", str(SAMPLES[0]), "-o", str(tmp_path), "--size", "0")
    assert r.returncode == 2 and r.stderr.startswith("error: --size")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.gl
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_exported_glb_passes_khronos_validator(tmp_path, path):
    out = tmp_path / f"{path.stem}.glb"
    r = cli("export", str(path), "-o", str(out), "--size", str(SIZE))
    assert r.returncode == 0, r.stderr
    issues = validate_gltf(out, tmp_path)
    assert issues["numErrors"] == 0, issues["messages"][:5]
    assert issues["numWarnings"] == 0, issues["messages"][:5]


@pytest.mark.gl
def test_exported_gltf_with_bin_and_mesh(tmp_path):
    out = tmp_path / "asset.gltf"
    r = cli("export", str(SAMPLES[0]), "-o", str(out), "--size", "16", "--mesh", "cube")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["asset.bin", "asset.gltf"]
    issues = validate_gltf(out, tmp_path)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    doc = json.loads(out.read_text())
    assert doc["buffers"][0]["uri"] == "asset.bin" and str(tmp_path) not in out.read_text()
    prim = doc["meshes"][0]["primitives"][0]
    assert {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0"} <= set(prim["attributes"])
    mat = doc["materials"][0]
    assert mat["normalTexture"]["index"] != mat["occlusionTexture"]["index"]
    assert mat["occlusionTexture"]["index"] == \
        mat["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"]
    # The validator is live: a broken accessor is reported as an error.
    doc["accessors"][0]["count"] += 1000
    bad = tmp_path / "bad.gltf"
    bad.write_text(json.dumps(doc))
    assert validate_gltf(bad, tmp_path)["numErrors"] > 0


def test_export_refuses_to_overwrite_its_mesh(tmp_path):
    mesh = tmp_path / "out.bin"  # an OBJ under another name, read by --mesh
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    before = mesh.read_bytes()
    r = cli("export", str(SAMPLES[0]), "-o", str(tmp_path / "out.gltf"), "--size", "8",
            "--mesh", str(mesh))
    assert r.returncode == 2 and "refusing to write over" in r.stderr
    assert mesh.read_bytes() == before and not (tmp_path / "out.gltf").exists()


def test_export_rejects_unknown_suffix(tmp_path):
    r = cli("export", str(SAMPLES[0]), "-o", str(tmp_path / "x.fbx"))
    assert r.returncode == 2 and r.stderr.count("\n") == 1
    assert ".gltf, .glb, .mtlx, .usda or .usdz" in r.stderr


@pytest.mark.gl
def test_emissive_hdr_and_opacity_bake_and_export(tmp_path):
    from matedit.io.document import save
    from tests.graphs_util import link, node, simple_material

    d = simple_material()
    node(d, "g", "gradient")
    node(d, "e", "multiply", values={"b": [3.0, 1.5, 0.5]})
    link(d, "g", "value", "e", "a")
    link(d, "e", "result", "make", "emissive")
    link(d, "g", "value", "make", "opacity")
    src = save(d, tmp_path / "glow.json")
    r = cli("bake", str(src), "-o", str(tmp_path / "maps"), "--size", "16")
    assert r.returncode == 0, r.stderr
    names = sorted(p.name for p in (tmp_path / "maps").iterdir())
    assert names == [f"glow_{n}.png" for n in
                     ("base_color", "emissive", "normal", "opacity", "orm")]
    cpu = bake.attributes_cpu(lower_and_optimise(load(src), FileResolver()), 16)
    got = file_pixels(tmp_path / "maps" / "glow_opacity.png")[..., 0]
    assert np.abs(got - cpu["opacity"][..., 0]).max() <= 1 / 255 + 1e-9
    out = tmp_path / "glow.glb"
    r = cli("export", str(src), "-o", str(out), "--size", "16")
    assert r.returncode == 0, r.stderr
    issues = validate_gltf(out, tmp_path)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    import pygltflib

    g = pygltflib.GLTF2().load(str(out))
    mat = g.materials[0]
    assert mat.alphaMode == "BLEND" and mat.emissiveTexture is not None
    strength = mat.extensions["KHR_materials_emissive_strength"]["emissiveStrength"]
    assert strength == pytest.approx(cpu["emissive"].max(), rel=1e-4)


@pytest.mark.gl
def test_bake_decodes_textures_by_their_colour_space(ctx, tmp_path):
    """An sRGB 8-bit texture bakes as its decoded values (IEC 61966-2-1, the test's own
    formula), a linear one as its codes / 255: the GPU bake and the CPU evaluator both within
    1/255 at texel centres (bake size = texture size), and the baked base colour PNG, sRGB
    encoded again, gives back the texture's own codes within one code."""
    from tests.interop_tools import srgb_decode, textured_material

    src, albedo, data = textured_material(tmp_path, 8)
    doc = load(src)
    r = FileResolver()
    ir = lower_and_optimise(doc, r)
    cm = compile_document(doc, r, "glsl330", mode="attributes", ir=ir)
    gpu = bake.attributes_gpu(ctx, cm, 8)
    cpu = bake.attributes_cpu(lower_and_optimise(doc, r), 8)
    tol = 1.0 / 255.0
    for name, got in (("gpu", gpu), ("cpu", cpu)):
        np.testing.assert_allclose(got["baseColor"], srgb_decode(albedo), atol=tol,
                                   err_msg=f"{name} base colour")
        np.testing.assert_allclose(got["roughness"][..., 0], data[..., 0] / 255.0, atol=tol,
                                   err_msg=f"{name} roughness")
        np.testing.assert_allclose(got["metallic"][..., 0], data[..., 1] / 255.0, atol=tol,
                                   err_msg=f"{name} metallic")
    out = tmp_path / "maps"
    res = cli("bake", str(src), "-o", str(out), "--size", "8")
    assert res.returncode == 0, res.stderr
    base = file_pixels(out / "textured_base_color.png") * 255.0
    assert np.abs(base - albedo).max() <= 1.0
    orm = file_pixels(out / "textured_orm.png") * 255.0
    assert np.abs(orm[..., 1] - data[..., 0]).max() <= 1.0
    assert np.abs(orm[..., 2] - data[..., 1]).max() <= 1.0


@pytest.mark.gl
def test_gltf_base_colour_is_srgb_and_orm_linear(tmp_path):
    """In the .glb the base colour map holds sRGB codes (glTF decodes it as sRGB) and the
    metallic-roughness map linear values: from an sRGB albedo and a linear data texture
    each comes back as the source texture's codes within one."""
    import OpenImageIO as oiio
    import pygltflib

    from tests.interop_tools import textured_material

    src, albedo, data = textured_material(tmp_path, 8)
    out = tmp_path / "t.glb"
    res = cli("export", str(src), "-o", str(out), "--size", "8")
    assert res.returncode == 0, res.stderr
    issues = validate_gltf(out, tmp_path)
    assert issues["numErrors"] == 0, issues["messages"][:5]
    g = pygltflib.GLTF2().load(str(out))
    blob = g.binary_blob()

    def image(index: int) -> np.ndarray:
        view = g.bufferViews[g.images[g.textures[index].source].bufferView]
        png = tmp_path / f"img{index}.png"
        png.write_bytes(blob[view.byteOffset or 0:(view.byteOffset or 0) + view.byteLength])
        buf = oiio.ImageBuf(str(png))
        px = buf.get_pixels(oiio.UINT8)
        assert px is not None, buf.geterror()
        return np.asarray(px, np.float64)[::-1]  # row 0 = v = 0

    pbr = g.materials[0].pbrMetallicRoughness
    base = image(pbr.baseColorTexture.index)
    mr = image(pbr.metallicRoughnessTexture.index)
    assert np.abs(base[..., :3] - albedo).max() <= 1.0
    assert np.abs(mr[..., 1] - data[..., 0]).max() <= 1.0  # G roughness
    assert np.abs(mr[..., 2] - data[..., 1]).max() <= 1.0  # B metallic


def _on_a_terminal(args: list[str], timeout: float = 300) -> tuple[int, str]:
    """Run `python -m matedit ARGS` with its stderr (and stdout) on a pseudo-terminal."""
    import os
    import pty

    pid, fd = pty.fork()
    if pid == 0:  # the child: exec at once
        os.execv(sys.executable, [sys.executable, "-m", "matedit", *args])
    chunks = []
    while True:
        try:
            data = os.read(fd, 4096)
        except OSError:  # EIO: the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    _, status = os.waitpid(pid, 0)
    os.close(fd)
    return os.waitstatus_to_exitcode(status), b"".join(chunks).decode("utf-8", "replace")


@pytest.mark.gl
@pytest.mark.parametrize("command", ["bake", "export"])
def test_bake_and_gltf_export_show_progress_on_a_terminal(tmp_path, command):
    """On a terminal both report the bake's progress up to 100% (tiles of bake.TILE texels:
    a map of 2 x TILE is four steps); piped, they print nothing (checked elsewhere)."""
    path = graphs_dir() / "materials" / "mossy_stone.json"
    out = tmp_path / ("maps" if command == "bake" else "m.glb")
    code, text = _on_a_terminal([command, str(path), "-o", str(out), "--size",
                                 str(2 * bake.TILE)])
    assert code == 0, text
    steps = [float(s) for s in re.findall(r"baking\s+([\d.]+)%", text)]
    assert steps == [25.0, 50.0, 75.0, 100.0], text


def test_bake_refuses_to_write_over_a_texture_the_material_reads(tmp_path):
    """The texture is named as the bake's base colour map would be: refused, exit 2, the
    texture untouched and no map written."""
    from matedit.io.document import save
    from tests.interop_tools import textured_material

    src, _, _ = textured_material(tmp_path, 4)
    trap = tmp_path / "textured_base_color.png"
    (tmp_path / "albedo.png").rename(trap)
    doc = load(src)
    doc.graph.nodes["ta"].settings["path"] = trap.name
    save(doc, src)
    before = trap.read_bytes()
    r = cli("bake", str(src), "-o", str(tmp_path), "--size", "4")
    assert r.returncode == 2 and r.stderr.startswith("error: "), r.stderr
    assert "refusing to write over" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert trap.read_bytes() == before
    assert not (tmp_path / "textured_orm.png").exists()


ANISOTROPIC = [p for p in SAMPLES
               if "anisotropy" in lower_and_optimise(load(p), FileResolver()).attributes]


@pytest.mark.gl
@pytest.mark.parametrize("path", ANISOTROPIC, ids=lambda p: p.stem)
def test_bake_of_an_anisotropic_sample_shades_nothing_and_binds_what_it_declares(ctx, path):
    """The bake writes attributes, it does not shade: its program (ATTRIBUTES mode) of a
    material that writes anisotropy declares no anisotropy table (binding 31, the viewport's
    shading input) nor any other sampler but the material's own textures, which
    attributes_gpu binds; and anisotropy is no baked map: the maps at the sample's
    anisotropy equal those at anisotropy 0 (a shaded bake would differ)."""
    doc = load(path)
    ir = lower_and_optimise(doc, FileResolver())
    compiled = compile_document(doc, FileResolver(), "glsl330", mode="attributes", ir=ir)
    declared = set(re.findall(r"uniform\s+(?:\w+\s+)?sampler\w*\s+(\w+)\s*;",
                              compiled.fragment_text))  # fmt: skip
    assert "uAnisotropyLut" not in compiled.fragment_text
    assert declared <= set(bake.load_textures(ir)), declared
    flat = copy.deepcopy(doc)
    changed = 0
    for n in flat.graph.nodes.values():
        if n.kind == "scalar_parameter" and n.settings.get("name") == "anisotropy":
            n.values["value"] = 0.0
            changed += 1
    assert changed, "the sample's anisotropy input was not found"
    at_sample = bake.bake_attributes(ctx, doc, FileResolver(), 16)[0]
    at_zero = bake.bake_attributes(ctx, flat, FileResolver(), 16)[0]
    for name in ("baseColor", "metallic", "normal", "roughness", "emissive", "cavity",
                 "opacity"):
        np.testing.assert_array_equal(at_sample[name], at_zero[name], err_msg=name)
