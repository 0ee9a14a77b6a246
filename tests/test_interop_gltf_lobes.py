"""glTF export of the lobes beyond the talk's fields: KHR_materials_ior, specular, clearcoat,
sheen, anisotropy, transmission, volume and iridescence factors, each equal to the value the
material sets (read from the document, not from the exporter), the Khronos glTF-Validator
clean, and a `note:` line for every field glTF cannot carry exactly."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pygltflib as g
import pytest
from graphs_util import link, material, node

from matedit.io.document import save
from matedit.resources import graphs_dir
from tests.interop_tools import validate_gltf

pytestmark = pytest.mark.gl

ROOT = Path(__file__).resolve().parent.parent
SAMPLES = graphs_dir() / "materials"

LOBES = {  # every value set constant on Make Attributes, so each factor is known exactly
    "ior": 1.7, "specularColor": [0.9, 0.8, 0.7],
    "coat": 0.7, "coatRoughness": 0.2,
    "sheenColor": [0.3, 0.2, 0.1], "sheenRoughness": 0.5,
    "anisotropy": 0.4, "anisotropyDirection": [0.0, 1.0, 0.0],
    "transmission": 0.5, "attenuationDistance": 0.3, "attenuationColor": [0.8, 0.6, 0.4],
    "thickness": 0.05, "thinFilmThickness": 400.0, "thinFilmIor": 1.4,
}


def export(src: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "matedit", "export", str(src), "-o",
                           str(out), "--size", "16", *extra], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)


def _material(tmp: Path, values: dict, settings: dict | None = None) -> Path:
    doc = material(tmp / "lobes.json")
    node(doc, "make", "make_attributes", values=values)
    node(doc, "out", "material_output", settings=settings or {})
    link(doc, "make", "attributes", "out", "attributes")
    save(doc, doc.path)
    return doc.path


def _extensions(path: Path) -> dict:
    return g.GLTF2().load(str(path)).materials[0].extensions or {}


def _close(a, b, tol=1e-5) -> bool:
    if isinstance(a, list):
        return len(a) == len(b) and all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))
    return abs(a - b) <= tol


def test_every_lobe_factor_is_the_value_the_material_sets(tmp_path):
    src = _material(tmp_path, LOBES)
    out = tmp_path / "lobes.glb"
    r = export(src, out)
    assert r.returncode == 0, r.stderr
    ext = _extensions(out)
    want = {
        "KHR_materials_ior": {"ior": 1.7},
        "KHR_materials_specular": {"specularFactor": 1.0, "specularColorFactor": [0.9, 0.8, 0.7]},
        "KHR_materials_clearcoat": {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.2},
        "KHR_materials_sheen": {"sheenColorFactor": [0.3, 0.2, 0.1], "sheenRoughnessFactor": 0.5},
        "KHR_materials_anisotropy": {"anisotropyStrength": 0.4,
                                     "anisotropyRotation": math.pi / 2},
        "KHR_materials_transmission": {"transmissionFactor": 0.5},
        "KHR_materials_volume": {"thicknessFactor": 0.05, "attenuationDistance": 0.3,
                                 "attenuationColor": [0.8, 0.6, 0.4]},
        "KHR_materials_iridescence": {"iridescenceFactor": 1.0, "iridescenceIor": 1.4,
                                      "iridescenceThicknessMaximum": 400.0},
    }
    assert set(ext) == set(want), sorted(ext)
    for name, fields in want.items():
        assert set(ext[name]) == set(fields), (name, ext[name])
        for k, v in fields.items():
            assert _close(ext[name][k], v), (name, k, ext[name][k], v)
    doc = g.GLTF2().load(str(out))
    assert set(want) <= set(doc.extensionsUsed)
    issues = validate_gltf(out, tmp_path)
    assert (issues["numErrors"], issues["numWarnings"], issues["numInfos"]) == (0, 0, 0), \
        issues["messages"][:5]
    # constant fields say nothing; the anisotropy's different stretch is said
    notes = [ln for ln in r.stderr.splitlines() if ln.startswith("note:")]
    assert any("anisotropy" in n and "roughness" in n for n in notes), notes
    assert not any("varies" in n for n in notes), notes


def test_a_thin_wall_has_no_volume_and_the_talks_material_no_lobe_extension(tmp_path):
    thin = _material(tmp_path, {"transmission": 1.0}, {"thin_walled": True})
    r = export(thin, tmp_path / "thin.glb")
    assert r.returncode == 0, r.stderr
    assert set(_extensions(tmp_path / "thin.glb")) == {"KHR_materials_transmission"}
    r = export(SAMPLES / "rusty_painted_metal.json", tmp_path / "rust.glb")
    assert r.returncode == 0, r.stderr
    assert set(_extensions(tmp_path / "rust.glb")) <= {"KHR_materials_emissive_strength"}
    assert "note:" not in r.stderr


@pytest.mark.parametrize("sample, extension, said", [
    ("honey", "KHR_materials_volume", None),
    ("soap_bubble", "KHR_materials_iridescence", "thinFilmThickness varies"),
    ("velvet", "KHR_materials_sheen", "sheenColor varies"),
    ("car_paint", "KHR_materials_clearcoat", "coatNormal is not baked"),
    ("skin", None, "subsurface has no ratified glTF extension"),
])
def test_samples_export_their_lobes_and_say_what_glTF_cannot_hold(tmp_path, sample, extension,
                                                                   said):
    out = tmp_path / f"{sample}.glb"
    r = export(SAMPLES / f"{sample}.json", out)
    assert r.returncode == 0, r.stderr
    if extension:
        assert extension in _extensions(out)
    if said:
        assert any(said in ln for ln in r.stderr.splitlines() if ln.startswith("note:")), \
            r.stderr
    issues = validate_gltf(out, tmp_path)
    assert (issues["numErrors"], issues["numWarnings"]) == (0, 0), issues["messages"][:5]
