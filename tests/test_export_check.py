"""`matedit export ... --check`: the measured loss of an export's round trip.

The figure is CIEDE2000 (held to Sharma et al. 2005 in tests/test_color_difference.py) over
the pixels the mesh covers of two renders made alike. Here: it is 0 for a material against
itself, large for a clearly different one, the glTF re-import reads its lobe extensions
back, a few samples stay within 1.5 times their row of docs/materialx.md's table (made by
tools/roundtrip_table.py at the same sizes), and the options fail cleanly."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from matedit.io.document import FileResolver, load, save
from matedit.resources import graphs_dir
from tests.graphs_util import simple_material
from tools.roundtrip_table import BAKE_SIZE, DOC, LINE, RENDER_SIZE, read_table


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *map(str, args)],
                          capture_output=True, text=True)


@pytest.mark.gl
def test_the_figure_is_zero_for_the_same_material_and_large_for_another():
    """The same document twice: ΔE exactly 0 (the renderer is deterministic); the base colour
    turned from red to blue: mean ΔE over 20 (red and blue differ by about 50-70 in ΔE00)."""
    from matedit.commands.export_check import measure

    a = simple_material()
    b = simple_material()
    b.graph.nodes["col"].values["value"] = [0.1, 0.2, 0.8]
    same = measure(a, simple_material(), FileResolver(), 48, "sphere")
    assert same.mean == 0.0 and same.max == 0.0
    other = measure(a, b, FileResolver(), 48, "sphere")
    print(f"red vs blue: mean {other.mean:.2f} max {other.max:.2f}")
    assert other.mean > 20.0
    # the mesh's pixels only: a 48 px sphere covers roughly a third to two thirds of them
    covered = np.count_nonzero(other.delta_e)
    assert 0.25 * 48 * 48 < covered < 0.8 * 48 * 48


def test_gltf_lobe_extensions_are_read_back_as_constant_fields():
    from matedit.interop.gltf_readback import lobe_fields

    got = lobe_fields({"KHR_materials_clearcoat": {"clearcoatFactor": 0.7,
                                                   "clearcoatRoughnessFactor": 0.1},
                       "KHR_materials_anisotropy": {"anisotropyStrength": 0.5,
                                                    "anisotropyRotation": np.pi / 2},
                       "KHR_materials_sheen": {"sheenColorFactor": [0.2, 0.3, "x"]},
                       "KHR_texture_transform": {}})
    assert got["coat"] == 0.7 and got["coatRoughness"] == 0.1 and got["anisotropy"] == 0.5
    np.testing.assert_allclose(got["anisotropyDirection"], [0, 1, 0], atol=1e-12)
    assert "sheenColor" not in got  # not three finite numbers: ignored


@pytest.mark.gl
@pytest.mark.parametrize("sample, suffix", [("mossy_stone", ".glb"),
                                            ("dusty_plastic", ".mtlx"),
                                            ("car_paint", ".mtlx")])
def test_samples_stay_within_their_table_row(tmp_path, sample, suffix):
    """At the table's sizes (--size 64, --check-size 64), mean and max within 1.5 times the
    row of docs/materialx.md (plus 0.05, for rows that read 0.00)."""
    row = read_table(DOC.read_text())[sample][suffix]
    out = tmp_path / f"{sample}{suffix}"
    r = cli("export", graphs_dir() / "materials" / f"{sample}.json", "-o", out, "--size",
            BAKE_SIZE, "--check", "--check-size", RENDER_SIZE)
    assert r.returncode == 0, r.stderr
    m = LINE.search(r.stderr)
    assert m, r.stderr
    mean, worst = float(m.group(1)), float(m.group(2))
    assert "CIEDE2000 on the display image" in r.stderr
    assert mean <= 1.5 * row[0] + 0.05, (mean, row)
    assert worst <= 1.5 * row[1] + 0.05, (worst, row)


@pytest.mark.gl
def test_check_image_is_three_panels_and_never_overwrites_an_input(tmp_path):
    src = save(simple_material(), tmp_path / "m.json")
    img = tmp_path / "side.png"
    r = cli("export", src, "-o", tmp_path / "m.mtlx", "--check", "--check-size", "32",
            "--check-image", img)
    assert r.returncode == 0, r.stderr
    assert "round trip: mean ΔE 0.00" in r.stderr, r.stderr  # constants survive MaterialX
    from matedit.io.images import read_image

    assert read_image(img).pixels.shape[:2] == (32, 96)
    before = src.read_bytes()
    r = cli("export", src, "-o", tmp_path / "n.glb", "--size", "8", "--check",
            "--check-image", src.with_suffix(".png"))
    assert r.returncode == 0, r.stderr  # a new file beside the input is fine
    r = cli("export", src, "-o", tmp_path / "k.glb", "--size", "8", "--check",
            "--check-image", tmp_path / "m.json")
    assert r.returncode == 2 and r.stderr.startswith("error:"), r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert src.read_bytes() == before and not (tmp_path / "k.glb").exists()


@pytest.mark.parametrize("args, says", [
    (["--check-image", "x.png"], "need --check"),
    (["--check-size", "64"], "need --check"),
    (["--check", "--check-size", "8"], "16..4096"),
    (["--check", "--check-size", "big"], "whole number"),
    (["--check", "--check-image", "x.jpg"], "must be a .png"),
    (["--check", "--check-image", "nowhere/x.png"], "does not exist"),
])
def test_bad_check_options_fail_cleanly_before_writing(tmp_path, args, says):
    src = save(simple_material(), tmp_path / "m.json")
    args = [str(tmp_path / a) if a.endswith(".png") or a.endswith(".jpg") else a
            for a in args]
    r = subprocess.run([sys.executable, "-m", "matedit", "export", str(src), "-o",
                        str(tmp_path / "m.glb"), "--size", "8", *args],
                       capture_output=True, text=True)
    assert r.returncode == 2 and says in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "m.glb").exists()


def test_every_export_suffix_has_a_reimporter():
    from matedit.commands.export_check import REIMPORTERS

    assert {".gltf", ".glb", ".mtlx", ".usda", ".usdz"} <= set(REIMPORTERS)


def test_gltf_template_reads_the_maps_it_is_given():
    """The template compiles, and names the parameters the glTF re-import sets."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop.gltf_readback import TEMPLATE

    doc = load(graphs_dir().joinpath(*TEMPLATE))
    ir = lower_and_optimise(doc, FileResolver())
    textures = {t.name for t in ir.textures}  # uniform names: the parameter's, prefixed
    for name in ("base_color_texture", "metallic_roughness_texture", "normal_texture",
                 "emissive_texture"):
        assert any(t.endswith(name) for t in textures), (name, textures)
    uniforms = {u.name for u in ir.uniforms}
    for name in ("base_color_factor", "metallic_factor", "roughness_factor", "emissive_factor",
                 "emissive_strength"):
        assert any(u.endswith(name) for u in uniforms), (name, uniforms)


def test_table_reader_reads_the_doc():
    rows = read_table(DOC.read_text())
    samples = {p.stem for p in (graphs_dir() / "materials").glob("*.json")}
    assert set(rows) == samples, "docs/materialx.md's round-trip table is not of every sample"
    assert Path(__file__).name in DOC.read_text()


def _figure(stderr: str) -> tuple[float, float]:
    (line,) = [x for x in stderr.splitlines() if "round trip: mean" in x]
    words = line.split()
    return float(words[words.index("mean") + 2]), float(words[words.index("max") + 2])


@pytest.mark.gl
def test_usd_check_reads_the_preview_surface_back(tmp_path):
    """USD's round trip is its UsdPreviewSurface on its own maps. coated_copper's maps and
    coat are what the glTF export carries too, so the two figures agree (within 0.1 ΔE: the
    same bakes, read back through the same template); velvet's sheen has no preview input,
    so USD loses more than glTF, which carries KHR_materials_sheen (by over 3 ΔE)."""
    figures = {}
    for sample in ("coated_copper", "velvet"):
        src = graphs_dir() / "materials" / f"{sample}.json"
        for suffix in (".usda", ".glb", ".usdz"):
            if suffix == ".usdz" and sample == "velvet":
                continue
            r = cli("export", src, "-o", tmp_path / f"{sample}{suffix}", "--size", BAKE_SIZE,
                    "--check", "--check-size", RENDER_SIZE)
            assert r.returncode == 0, r.stderr
            figures[sample, suffix] = _figure(r.stderr)
            if suffix != ".glb":
                assert "the MaterialX network is not read back" in r.stderr
    print(figures)
    for k in (0, 1):
        assert abs(figures["coated_copper", ".usda"][k] - figures["coated_copper", ".glb"][k]) \
            < 0.1
        assert figures["coated_copper", ".usdz"][k] == figures["coated_copper", ".usda"][k]
    assert figures["velvet", ".usda"][0] > figures["velvet", ".glb"][0] + 3.0


def test_usd_read_back_refuses_a_texture_outside_its_folder(tmp_path):
    from matedit.interop.usd_readback import UsdReadbackError, _texture_bytes

    class Asset:
        path = "../elsewhere/secret.png"

    with pytest.raises(UsdReadbackError, match="not a file beside the layer"):
        _texture_bytes(tmp_path / "m.usda", Asset())
