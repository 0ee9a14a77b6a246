"""`matedit export OUT.mtlx` (and later `matedit import`): checked by MaterialX itself.

- every sample's document passes MaterialX's own `validate()` with its stdlib loaded;
- every nodegraph output, generated to GLSL by MaterialX's own GLSL generator and drawn
  on the bake plane (UV square, z = 0, +Z normal, camera far above) on EGL, matches our CPU
  evaluator of the same quantity at the texel centres within 2e-3 (float32 GPU maths
  against float64, and baked EXR images read at their texel centres).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from matedit.resources import graphs_dir

mx = pytest.importorskip("MaterialX")
SAMPLES = sorted((graphs_dir() / "materials").glob("*.json"))
SIZE = 24


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Every sample exported to the default surface (open_pbr_surface), maps as float EXR
    (the bake itself: the 2e-3 comparisons below; PNG's 8 bits are checked against it in
    tests/test_interop_mtlx_surfaces.py)."""
    return _export_samples(tmp_path_factory.mktemp("mtlx"))


@pytest.fixture(scope="module")
def exported_gltf(tmp_path_factory):
    return _export_samples(tmp_path_factory.mktemp("mtlx_gltf"), "gltf_pbr")


def _export_samples(folder: Path, surface: str = "open_pbr_surface"):
    notes = {}
    for path in SAMPLES:
        r = cli("export", str(path), "-o", str(folder / f"{path.stem}.mtlx"), "--size",
                str(SIZE), "--format", "exr", "--surface", surface)
        if path.stem in REFUSED.get(surface, {}):  # refused by name, never exported wrong
            assert r.returncode == 2 and REFUSED[surface][path.stem] in r.stderr, r.stderr
            continue
        assert r.returncode == 0, r.stderr
        notes[path.stem] = r.stderr
    return folder, notes


# Samples a surface cannot carry, and the field the export refuses them by: a varying
# anisotropy direction has no gltf_pbr (or standard_surface) input, whose rotation takes a
# constant here; OpenPBR's geometry_tangent takes it in world space.
REFUSED = {"gltf_pbr": {"radial_brushed_aluminium": "anisotropyDirection"}}


def _exportable(path: Path, surface: str = "open_pbr_surface") -> None:
    if path.stem in REFUSED.get(surface, {}):
        pytest.skip(f"{path.stem}: export refused by name ({REFUSED[surface][path.stem]})")


def load_with_stdlib(path: Path):
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(path))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    return doc


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_exported_mtlx_validates(exported, path):
    _exportable(path)
    folder, notes = exported
    out = folder / f"{path.stem}.mtlx"
    doc = load_with_stdlib(out)
    ok, msg = doc.validate()
    assert ok, msg
    text = out.read_text()
    assert str(folder) not in text and str(graphs_dir()) not in text
    surfaces = [n for n in doc.getNodes() if n.getCategory() == "open_pbr_surface"]
    assert len(surfaces) == 1
    assert [m.getName() for m in doc.getMaterialNodes()] == [f"M_{path.stem}"]
    # Every image the document references was written in its side folder, and is reported.
    images = doc.getNodeGraph(f"NG_{path.stem}").getNodes("image")
    for img in images:
        file = img.getInput("file").getValueString()
        assert file.startswith(f"{path.stem}_textures/") and (folder / file).is_file()
        # named <node>_<output>_baked; outputs may hold '_' themselves (tile_id)
        reported = re.findall(r"node (\w+): baked", notes[path.stem])
        assert any(img.getName().startswith(f"{n}_") for n in reported), img.getName()
    for line in notes[path.stem].splitlines():
        assert line.startswith("note: "), line
    if images:
        assert f"baked map(s) at {SIZE} x {SIZE} texels" in notes[path.stem]


@pytest.mark.parametrize("surface", ["open_pbr_surface", "gltf_pbr"])
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_exported_material_generates_with_materialx_glsl(request, path, surface):
    """The whole material (the surface shader on its nodegraph) goes through MaterialX's own
    GLSL generator, and the gltf_pbr export validates too."""
    _exportable(path, surface)
    from MaterialX import PyMaterialXGenGlsl as mx_glsl
    from MaterialX import PyMaterialXGenShader as mx_gen

    folder, _ = request.getfixturevalue(
        "exported" if surface == "open_pbr_surface" else "exported_gltf")
    doc = load_with_stdlib(folder / f"{path.stem}.mtlx")
    ok, msg = doc.validate()
    assert ok, msg
    assert [n.getCategory() for n in doc.getNodes() if n.getType() == "surfaceshader"] == [
        surface]
    gen = mx_glsl.GlslShaderGenerator.create()
    context = mx_gen.GenContext(gen)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    (mat,) = doc.getMaterialNodes()
    shader = gen.generate(mat.getName(), mat, context)
    assert "void main" in shader.getSourceCode(mx_gen.PIXEL_STAGE)


# standard_surface input -> our attribute
SURFACE_INPUTS = {
    "base_color": "baseColor", "base": "cavity", "specular": "cavity",
    "metalness": "metallic", "specular_roughness": "roughness",
    "normal": "normal", "emission_color": "emissive", "opacity": "opacity",
    "coat": "coat", "coat_color": "coatColor", "coat_roughness": "coatRoughness",
    "coat_IOR": "coatIor", "coat_normal": "coatNormal", "specular_color": "specularColor",
    "specular_IOR": "ior", "sheen_color": "sheenColor", "sheen_roughness": "sheenRoughness",
    "specular_anisotropy": "anisotropy", "subsurface": "subsurface",
    "subsurface_color": "subsurfaceColor", "subsurface_radius": "subsurfaceRadius",
    "subsurface_scale": "thickness",  # as 1 / thickness (docs/shading.md, Subsurface)
    "thin_film_thickness": "thinFilmThickness", "thin_film_IOR": "thinFilmIor",
    "transmission": "transmission", "transmission_depth": "attenuationDistance",
    "transmission_color": "transmissionColor",  # attenuationColor where a depth is set
}
# Each surface's inputs -> (our attribute, the surface's value of it): "" as is, "inverse"
# 1 / it (kept off 0, 1e-4), "milli" x 1e-3 (nm to um), "unit" normalised (world-space
# directions on the bake plane: tangent +X, bitangent +Y, normal +Z).
SURFACE_READS = {
    "open_pbr_surface": {
        "base_color": ("baseColor", ""), "base_weight": ("cavity", ""),
        "specular_weight": ("cavity", ""), "base_metalness": ("metallic", ""),
        "specular_roughness": ("roughness", ""), "geometry_normal": ("normal", "unit"),
        "emission_color": ("emissive", ""), "geometry_opacity": ("opacity", ""),
        "coat_weight": ("coat", ""), "coat_color": ("coatColor", ""),
        "coat_roughness": ("coatRoughness", ""), "coat_ior": ("coatIor", ""),
        "geometry_coat_normal": ("coatNormal", "unit"),
        "specular_color": ("specularColor", ""), "specular_ior": ("ior", ""),
        "fuzz_color": ("sheenColor", ""), "fuzz_roughness": ("sheenRoughness", ""),
        "specular_roughness_anisotropy": ("anisotropy", ""),
        "geometry_tangent": ("anisotropyDirection", "unit"),
        "subsurface_weight": ("subsurface", ""), "subsurface_color": ("subsurfaceColor", ""),
        "subsurface_radius_scale": ("subsurfaceRadius", ""),
        "subsurface_radius": ("thickness", "inverse"),
        "thin_film_thickness": ("thinFilmThickness", "milli"),
        "thin_film_ior": ("thinFilmIor", ""), "transmission_weight": ("transmission", ""),
        "transmission_depth": ("attenuationDistance", ""),
        "transmission_color": ("transmissionColor", "")},
    "gltf_pbr": {
        "base_color": ("baseColor", ""), "metallic": ("metallic", ""),
        "roughness": ("roughness", ""), "normal": ("normal", "unit"),
        "occlusion": ("cavity", ""), "emissive": ("emissive", ""), "alpha": ("opacity", ""),
        "specular_color": ("specularColor", ""), "ior": ("ior", ""),
        "clearcoat": ("coat", ""), "clearcoat_roughness": ("coatRoughness", ""),
        "clearcoat_normal": ("coatNormal", "unit"), "sheen_color": ("sheenColor", ""),
        "sheen_roughness": ("sheenRoughness", ""),
        "anisotropy_strength": ("anisotropy", ""), "transmission": ("transmission", ""),
        "attenuation_color": ("attenuationColor", ""),
        "attenuation_distance": ("attenuationDistance", ""),
        "iridescence_thickness": ("thinFilmThickness", ""),
        "iridescence_ior": ("thinFilmIor", ""), "thickness": ("thickness", "")},
}
# The talk's inputs, which every exported material has.
TALK_INPUTS = {"base_color", "base", "specular", "metalness", "specular_roughness", "normal",
               "emission_color", "opacity"}


@pytest.mark.gl
@pytest.mark.parametrize("surface", ["open_pbr_surface", "gltf_pbr"])
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_materialx_glsl_of_each_output_matches_cpu(ctx, request, path, surface):
    _exportable(path, surface)
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load
    from tests.mtlx_gpu import MtlxDrawer

    folder, _ = request.getfixturevalue(
        "exported" if surface == "open_pbr_surface" else "exported_gltf")
    doc = load_with_stdlib(folder / f"{path.stem}.mtlx")
    cpu = bake.attributes_cpu(lower_and_optimise(load(path), FileResolver()), SIZE)
    shader = next(n for n in doc.getNodes() if n.getCategory() == surface)
    reads = SURFACE_READS[surface]
    drawer = MtlxDrawer(ctx, SIZE)
    checked = []
    try:
        for inp in shader.getInputs():
            if not inp.getNodeGraphString():
                continue
            out = doc.getNodeGraph(inp.getNodeGraphString()).getOutput(inp.getOutputString())
            got = drawer.draw(doc, out, folder)
            attr, how = reads[inp.getName()]
            want = cpu[attr]
            if inp.getName() == "transmission_color" and shader.getInput("transmission_depth"):
                want = cpu["attenuationColor"]  # the absorption colour at that depth
            if how == "unit":  # normalmap and rotate3d: T = +X, B = +Y, N = +Z
                want = want / np.linalg.norm(want, axis=-1, keepdims=True)
            if how == "milli":
                want = want * 1e-3
            k = want.shape[-1]
            if how == "inverse":  # 1 / thickness: relative, 1e-3
                np.testing.assert_allclose(got[..., :k], 1.0 / np.maximum(want, 1e-4),
                                           rtol=1e-3, err_msg=f"{path.stem}: {inp.getName()}")
                checked.append(inp.getName())
                continue
            np.testing.assert_allclose(got[..., :k], want, atol=2e-3,
                                       err_msg=f"{path.stem}: {inp.getName()}")
            checked.append(inp.getName())
    finally:
        drawer.release()
    print(path.stem, surface, "checked", checked)
    # every sample varies something over the surface (the soap bubble only its film), and a
    # base colour that varies is among what was compared
    assert checked, f"{path.stem}: no input is a node graph"
    base = shader.getInput("base_color")
    if base is not None and base.getNodeGraphString():
        assert "base_color" in checked, checked


# --- import ---------------------------------------------------------------------------------

@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_round_trip_import_compile_evaluate_equals_original(exported, path):
    """export -> import -> compile -> CPU evaluation equals the original at the texel centres
    of the bake (baked nodes come back as float EXR textures read there): within 1e-6."""
    _exportable(path)
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load

    folder, _ = exported
    out = folder / f"{path.stem}_imported.json"
    r = cli("import", str(folder / f"{path.stem}.mtlx"), "-o", str(out))
    assert r.returncode == 0, r.stderr
    r = cli("validate", str(out))
    assert r.returncode == 0, r.stdout + r.stderr
    assert str(folder) not in out.read_text()
    a = bake.attributes_cpu(lower_and_optimise(load(path), FileResolver()), SIZE)
    b = bake.attributes_cpu(lower_and_optimise(load(out), FileResolver()), SIZE)
    for k in a:
        if k in ("thickness", "subsurfaceRadius"):
            continue  # OpenPBR carries their ratio (and says so where thickness is not 1)
        np.testing.assert_allclose(b[k], a[k], atol=1e-6, err_msg=f"{path.stem} {k}")
    np.testing.assert_allclose(b["subsurfaceRadius"] / b["thickness"],
                               a["subsurfaceRadius"] / a["thickness"], rtol=1e-6,
                               atol=1e-6, err_msg=f"{path.stem} subsurfaceRadius / thickness")


def _doc(body: str) -> str:
    return f'<?xml version="1.0"?>\n<materialx version="1.39">\n{body}\n</materialx>\n'


def _import(tmp_path, text: str, name="in.mtlx"):
    src = tmp_path / name
    src.write_text(text)
    out = tmp_path / "out.json"
    return cli("import", str(src), "-o", str(out)), out


def _eval(path: Path):
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load

    return bake.attributes_cpu(lower_and_optimise(load(path), FileResolver()), 4)


def test_import_unsupported_nodes_are_named_each(tmp_path):
    text = _doc('''
  <nodegraph name="NG">
    <texcoord name="uv" type="vector2" />
    <noise2d name="bumpy" type="float"><input name="texcoord" type="vector2" nodename="uv"/>
    </noise2d>
    <cellnoise2d name="cells" type="float" />
    <output name="r" type="float" nodename="bumpy" />
    <output name="m" type="float" nodename="cells" />
  </nodegraph>
  <standard_surface name="S" type="surfaceshader">
    <input name="specular_roughness" type="float" nodegraph="NG" output="r" />
    <input name="metalness" type="float" nodegraph="NG" output="m" />
  </standard_surface>
  <surfacematerial name="M" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="S" />
  </surfacematerial>''')
    r, out = _import(tmp_path, text)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert all(ln.startswith("error: ") for ln in lines) and len(lines) == 2
    assert any("NG/bumpy" in ln and "noise2d" in ln for ln in lines)
    assert any("NG/cells" in ln and "cellnoise2d" in ln for ln in lines)
    assert not out.exists()


def test_import_foreign_standard_surface_with_defaults_and_hostile_names(tmp_path):
    text = _doc('''
  <nodegraph name="NG">
    <input name="gl_tint" type="color3" value="0.2, 0.4, 0.6" />
    <multiply name="9 bad name__x" type="color3">
      <input name="in1" type="color3" interfacename="gl_tint" />
      <input name="in2" type="float" value="0.5" />
    </multiply>
    <output name="c" type="color3" nodename="9 bad name__x" />
  </nodegraph>
  <standard_surface name="S" type="surfaceshader">
    <input name="base_color" type="color3" nodegraph="NG" output="c" />
    <input name="emission" type="float" value="2" />
    <input name="emission_color" type="color3" value="0.5, 0.25, 0" />
  </standard_surface>
  <surfacematerial name="M" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="S" />
  </surfacematerial>''')
    r, out = _import(tmp_path, text)
    assert r.returncode == 0, r.stderr
    import json

    data = json.loads(out.read_text())
    from matedit.graph.model import valid_id
    from matedit.graph.names import identifier_problem

    assert all(valid_id(n["id"]) for n in data["nodes"])
    assert "n_9_bad_name_x" in {n["id"] for n in data["nodes"]}
    params = [n["settings"]["name"] for n in data["nodes"] if n["kind"].endswith("_parameter")]
    assert params == ["p_gl_tint"] and identifier_problem(params[0]) is None
    a = _eval(out)
    np.testing.assert_allclose(a["baseColor"][0, 0], [0.1, 0.2, 0.3], atol=1e-9)
    np.testing.assert_allclose(a["emissive"][0, 0], [1.0, 0.5, 0.0], atol=1e-9)
    # Unset inputs take standard_surface's defaults: roughness 0.2, base 1 -> cavity 1.
    assert a["roughness"][0, 0, 0] == pytest.approx(0.2)
    assert a["cavity"][0, 0, 0] == pytest.approx(1.0)


@pytest.mark.parametrize("surface, inputs, expect", [
    ("gltf_pbr", '<input name="base_color" type="color3" value="0.1, 0.2, 0.3" />'
                 '<input name="roughness" type="float" value="0.7" />'
                 '<input name="occlusion" type="float" value="0.9" />',
     {"baseColor": [0.1, 0.2, 0.3], "roughness": [0.7], "cavity": [0.9]}),
    ("UsdPreviewSurface", '<input name="diffuseColor" type="color3" value="0.3, 0.2, 0.1" />'
                          '<input name="metallic" type="float" value="1" />'
                          '<input name="opacity" type="float" value="0.5" />',
     {"baseColor": [0.3, 0.2, 0.1], "metallic": [1.0], "opacity": [0.5]}),
    ("open_pbr_surface", '<input name="base_color" type="color3" value="0.5, 0.5, 0.1" />'
                         '<input name="base_metalness" type="float" value="0.25" />',
     {"baseColor": [0.5, 0.5, 0.1], "metallic": [0.25]}),
    # OpenPBR's mean free path: subsurface_radius x subsurface_radius_scale (at thickness 1)
    ("open_pbr_surface", '<input name="subsurface_weight" type="float" value="0.75" />'
                         '<input name="subsurface_color" type="color3" value="0.9, 0.4, 0.3" />'
                         '<input name="subsurface_radius" type="float" value="0.5" />'
                         '<input name="subsurface_radius_scale" type="color3" '
                         'value="1, 0.5, 0.25" />',
     {"subsurface": [0.75], "subsurfaceColor": [0.9, 0.4, 0.3],
      "subsurfaceRadius": [0.5, 0.25, 0.125], "thickness": [1.0]}),
    # OpenPBR's thin film: thickness in micrometres (ours nm), times its weight
    ("open_pbr_surface", '<input name="thin_film_weight" type="float" value="1" />'
                         '<input name="thin_film_thickness" type="float" value="0.42" />'
                         '<input name="thin_film_ior" type="float" value="1.45" />',
     {"thinFilmThickness": [420.0], "thinFilmIor": [1.45]}),
    # standard_surface's thin film: thickness in nm, as ours
    ("standard_surface", '<input name="thin_film_thickness" type="float" value="380" />'
                         '<input name="thin_film_IOR" type="float" value="1.6" />',
     {"thinFilmThickness": [380.0], "thinFilmIor": [1.6]}),
    # standard_surface: subsurface_scale is 1 / thickness
    ("standard_surface", '<input name="subsurface" type="float" value="1" />'
                         '<input name="subsurface_radius" type="color3" value="1, 0.4, 0.2" />'
                         '<input name="subsurface_scale" type="float" value="0.5" />',
     {"subsurface": [1.0], "subsurfaceRadius": [1.0, 0.4, 0.2], "thickness": [2.0]}),
])
def test_import_other_surfaces(tmp_path, surface, inputs, expect):
    text = _doc(f'''
  <{surface} name="S" type="surfaceshader">{inputs}</{surface}>
  <surfacematerial name="M" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="S" />
  </surfacematerial>''')
    r, out = _import(tmp_path, text)
    assert r.returncode == 0, r.stderr
    a = _eval(out)
    for k, v in expect.items():
        np.testing.assert_allclose(a[k][0, 0], v, atol=1e-9, err_msg=k)


def test_import_reads_an_unset_geometric_default_from_the_surface(tmp_path):
    """MaterialX's reflect reads the world normal where its normal input is unset
    (defaultgeomprop Nworld): the import connects our world normal there, so on a tilted
    surface the result is I − 2 (N·I) N with the surface's N, not +Z."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.compiler.cpu_eval import evaluate
    from matedit.compiler.cpu_nodes import SurfaceArrays
    from matedit.io.document import FileResolver, load

    text = _doc('<nodegraph name="NG"><reflect name="r" type="vector3">'
                '<input name="in" type="vector3" value="0, 0, -1"/></reflect>'
                '<convert name="c" type="color3"><input name="in" type="vector3" '
                'nodename="r"/></convert><output name="o" type="color3" nodename="c"/>'
                '</nodegraph><standard_surface name="S" type="surfaceshader">'
                '<input name="base_color" type="color3" nodegraph="NG" output="o"/>'
                '</standard_surface><surfacematerial name="M" type="material">'
                '<input name="surfaceshader" type="surfaceshader" nodename="S"/>'
                '</surfacematerial>')
    r, out = _import(tmp_path, text)
    assert r.returncode == 0, r.stderr
    n = np.array([0.0, 0.6, 0.8])
    incident = np.array([0.0, 0.0, -1.0])
    surface = SurfaceArrays(np.zeros((1, 2)), np.zeros((1, 3)), n[None], n[None])
    got = evaluate(lower_and_optimise(load(out), FileResolver()), surface)["baseColor"]
    want = incident - 2.0 * n.dot(incident) * n  # (0, 0.96, 0.28)
    np.testing.assert_allclose(got[0], want, atol=1e-6)


@pytest.mark.parametrize("text, needle", [
    ("<materialx version='1.39'><bad", "not a MaterialX document"),
    (_doc('<disney_brdf_2012 name="S" type="surfaceshader"/><surfacematerial name="M" '
          'type="material"><input name="surfaceshader" type="surfaceshader" nodename="S"/>'
          '</surfacematerial>'), "unsupported surface"),
    (_doc('<nodegraph name="NG"><image name="img" type="float"><input name="file" '
          'type="filename" value="/etc/passwd"/></image><output name="o" type="float" '
          'nodename="img"/></nodegraph><standard_surface name="S" type="surfaceshader">'
          '<input name="metalness" type="float" nodegraph="NG" output="o"/>'
          '</standard_surface><surfacematerial name="M" type="material"><input '
          'name="surfaceshader" type="surfaceshader" nodename="S"/></surfacematerial>'),
     "relative path"),
    (_doc('<standard_surface name="S" type="surfaceshader"><input name="metalness" '
          'type="float" value="nan"/></standard_surface><surfacematerial name="M" '
          'type="material"><input name="surfaceshader" type="surfaceshader" nodename="S"/>'
          '</surfacematerial>'), "not finite"),
    (_doc(''), "no surfacematerial"),
])
def test_import_bad_input_is_one_error_line(tmp_path, text, needle):
    r, out = _import(tmp_path, text)
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("error: ") and needle in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and not out.exists()


def test_import_does_not_follow_xinclude(tmp_path):
    (tmp_path / "other.mtlx").write_text(_doc('<standard_surface name="S" '
                                              'type="surfaceshader"/><surfacematerial name="M" '
                                              'type="material"><input name="surfaceshader" '
                                              'type="surfaceshader" nodename="S"/>'
                                              '</surfacematerial>'))
    text = ('<?xml version="1.0"?>\n<materialx version="1.39" '
            'xmlns:xi="http://www.w3.org/2001/XInclude">\n'
            '<xi:include href="other.mtlx" />\n</materialx>\n')
    r, out = _import(tmp_path, text)
    assert r.returncode == 2 and "no surfacematerial" in r.stderr


def test_import_refuses_to_overwrite_its_source(tmp_path):
    src = tmp_path / "a.json"
    src.write_text(_doc(""))
    r = cli("import", str(src), "-o", str(src))
    assert r.returncode == 2 and "refusing to write over" in r.stderr


# --- every mapped kind ----------------------------------------------------------------------

def _all_kinds_material(folder: Path) -> Path:
    """A material using every catalogue kind with a MaterialX mapping (and a texture)."""
    from matedit.io.document import save
    from matedit.io.images import write_image
    from tests.graphs_util import link, material, node

    ramp = np.stack(np.meshgrid(np.linspace(0, 1, 8), np.linspace(1, 0, 8)), -1)
    write_image(folder / "ramp.exr", np.concatenate([ramp, ramp[..., :1] * 0.5], -1))
    d = material()
    node(d, "uv", "texcoord", values={"tiling": [2.0, 3.0], "offset": [0.1, 0.2]})
    node(d, "sp", "split")
    link(d, "uv", "uv", "sp", "value")
    node(d, "sn", "sin")
    link(d, "sp", "x", "sn", "value")
    node(d, "cs", "cos")
    link(d, "sp", "y", "cs", "value")
    node(d, "cb", "combine")
    link(d, "sn", "result", "cb", "x")
    link(d, "cs", "result", "cb", "y")
    link(d, "sp", "x", "cb", "z")
    node(d, "mk", "component_mask", {"channels": "zy"})
    link(d, "cb", "xyz", "mk", "value")
    node(d, "ap", "append")
    link(d, "mk", "result", "ap", "a")
    link(d, "sn", "result", "ap", "b")
    node(d, "cr", "cross")
    link(d, "ap", "result", "cr", "a")
    link(d, "cb", "xyz", "cr", "b")
    node(d, "ln", "length")
    link(d, "cr", "result", "ln", "value")
    node(d, "nr", "normalize")
    link(d, "cr", "result", "nr", "value")
    node(d, "m3", "multiply", values={"b": 2.5})
    link(d, "ap", "result", "m3", "a")
    node(d, "fr", "frac")
    link(d, "m3", "result", "fr", "value")
    node(d, "fl", "floor")
    link(d, "m3", "result", "fl", "value")
    node(d, "st", "step", values={"edge": 0.3})
    link(d, "sn", "result", "st", "value")
    node(d, "sq", "sqrt")
    link(d, "cs", "result", "sq", "value")
    node(d, "ab", "abs")
    link(d, "sn", "result", "ab", "value")
    node(d, "mn", "min")
    link(d, "ab", "result", "mn", "a")
    link(d, "sq", "result", "mn", "b")
    node(d, "mxn", "max", values={"b": 0.05})
    link(d, "mn", "result", "mxn", "a")
    node(d, "dv", "divide", values={"b": 2.0})
    link(d, "mxn", "result", "dv", "a")
    node(d, "cl", "clamp", values={"min": 0.1, "max": 0.9})
    link(d, "ln", "result", "cl", "value")
    node(d, "om", "one_minus")
    link(d, "cl", "result", "om", "value")
    node(d, "pw", "power", values={"exponent": 1.7})
    link(d, "om", "result", "pw", "base")
    node(d, "ss", "smoothstep", values={"edge0": 0.2, "edge1": 0.8})
    link(d, "pw", "result", "ss", "value")
    node(d, "rm", "remap", values={"in_min": -1.0, "in_max": 1.0, "out_min": 0.1,
                                   "out_max": 0.6})
    link(d, "sn", "result", "rm", "value")
    node(d, "wp", "world_position")
    node(d, "wn", "world_normal")
    node(d, "vd", "view_direction")
    node(d, "dt", "dot")
    link(d, "wn", "normal", "dt", "a")
    link(d, "vd", "direction", "dt", "b")
    node(d, "wpm", "component_mask", {"channels": "x"})
    link(d, "wp", "position", "wpm", "value")
    node(d, "tm", "time")
    node(d, "vp", "vector_parameter", {"name": "tint4"}, {"value": [0.3, 0.6, 0.9, 1.0]})
    node(d, "sat", "saturate")
    link(d, "dt", "result", "sat", "value")
    node(d, "tex", "texture_parameter", {"name": "ramp", "path": "ramp.exr", "srgb": False})
    node(d, "smp", "texture_sample")
    link(d, "tex", "texture", "smp", "texture")
    link(d, "uv", "uv", "smp", "uv")
    node(d, "lp", "lerp")
    link(d, "fr", "result", "lp", "a")
    link(d, "vp", "xyz", "lp", "b")
    link(d, "st", "result", "lp", "alpha")
    node(d, "ad", "add")
    link(d, "dv", "result", "ad", "a")
    link(d, "wpm", "result", "ad", "b")
    node(d, "sb", "subtract")
    link(d, "ss", "result", "sb", "a")
    link(d, "tm", "seconds", "sb", "b")
    node(d, "em", "multiply")
    link(d, "smp", "rgb", "em", "a")
    link(d, "fl", "result", "em", "b")
    node(d, "to", "tiling_offset", values={"tiling": [1.5, 0.5], "offset": [-0.2, 0.3]})
    link(d, "uv", "uv", "to", "uv")
    node(d, "ro", "rotate_uv", values={"angle": 40.0, "pivot": [0.3, 0.6]})
    link(d, "to", "uv", "ro", "uv")
    node(d, "gr", "gradient", values={"angle": 30.0})
    link(d, "ro", "uv", "gr", "uv")
    # filter_width 0: MaterialX's checkerboard has hard edges (ours band-limits by default)
    node(d, "ck", "checker", values={"scale": 3.0, "color_a": [0.9, 0.2, 0.1],
                                     "color_b": [0.1, 0.3, 0.8], "filter_width": 0.0})
    link(d, "uv", "uv", "ck", "uv")
    node(d, "un", "unpack_normal", values={"strength": 1.5})
    link(d, "fr", "result", "un", "packed")
    node(d, "bn", "blend_normals")
    link(d, "nr", "result", "bn", "base")
    link(d, "un", "normal", "bn", "detail")
    node(d, "fn", "flatten_normal")
    link(d, "bn", "normal", "fn", "normal")
    link(d, "gr", "value", "fn", "flatness")
    node(d, "ckm", "multiply")
    link(d, "ck", "color", "ckm", "a")
    link(d, "ck", "mask", "ckm", "b")
    node(d, "bc", "add")
    link(d, "lp", "result", "bc", "a")
    link(d, "ckm", "result", "bc", "b")
    # maths with a stdlib twin: u in [0.1, 2.1] keeps sin(u) > 0, off atan2's branch cut
    node(d, "at", "atan2")
    link(d, "sn", "result", "at", "y")
    link(d, "cs", "result", "at", "x")
    node(d, "ex", "exp")
    link(d, "sn", "result", "ex", "value")
    node(d, "tn", "tan")
    link(d, "sn", "result", "tn", "value")
    node(d, "sg", "sign")
    link(d, "cs", "result", "sg", "value")
    node(d, "ig", "if_greater", values={"b": 0.5})  # sin(u) stays 0.03 off 0.5 on the grid
    link(d, "sn", "result", "ig", "a")
    link(d, "ex", "result", "ig", "if_true")
    link(d, "at", "result", "ig", "if_false")
    node(d, "rad", "radians")
    link(d, "tn", "result", "rad", "value")
    node(d, "deg", "degrees")
    link(d, "sg", "result", "deg", "value")
    node(d, "ng", "negate")
    link(d, "rad", "result", "ng", "value")
    node(d, "rc", "reciprocal")
    link(d, "ex", "result", "rc", "value")
    node(d, "f1", "multiply_add", values={"b": 0.002})
    link(d, "deg", "result", "f1", "a")
    link(d, "ig", "result", "f1", "c")
    node(d, "f2", "add")
    link(d, "ng", "result", "f2", "a")
    link(d, "rc", "result", "f2", "b")
    node(d, "f3", "add")
    link(d, "f1", "result", "f3", "a")
    link(d, "f2", "result", "f3", "b")
    node(d, "lg", "log")
    link(d, "ex", "result", "lg", "value")
    node(d, "as", "asin")
    link(d, "sn", "result", "as", "value")
    node(d, "ac", "acos")
    link(d, "cs", "result", "ac", "value")
    node(d, "rn", "round")
    link(d, "tn", "result", "rn", "value")
    node(d, "tr", "trunc")
    link(d, "ng", "result", "tr", "value")  # −radians(tan(sin u)), in [−0.03, 0)
    node(d, "ds", "distance")
    link(d, "sn", "result", "ds", "a")
    link(d, "cs", "result", "ds", "b")
    node(d, "ds3", "distance")
    link(d, "nr", "result", "ds3", "a")
    link(d, "wn", "normal", "ds3", "b")
    node(d, "ie", "if_equal", values={"b": 0.0, "tolerance": 0.5})  # |cos v| off 0.5
    link(d, "cs", "result", "ie", "a")
    link(d, "as", "result", "ie", "if_true")
    link(d, "ac", "result", "ie", "if_false")
    node(d, "lu", "luminance")
    link(d, "v3", "result", "lu", "color")
    node(d, "ps", "posterize", values={"steps": 5.0})  # 5 exp(sin u) stays 0.04 off integers
    link(d, "ex", "result", "ps", "value")
    node(d, "tb", "triplanar_blend")
    link(d, "ps", "result", "tb", "x")
    link(d, "cs", "result", "tb", "y")
    link(d, "ex", "result", "tb", "z")
    link(d, "h2r", "color", "tb", "weights")
    node(d, "sph", "spherical_gradient", values={"center": [0.5, 0.5], "radius": 2.0})
    link(d, "ro", "uv", "sph", "uv")
    total = "f3"
    for k, term in enumerate(("lg", "rn", "tr", "ds", "ds3", "ie", "lu", "tb", "sph")):
        node(d, f"g{k}", "add")
        link(d, total, "result", f"g{k}", "a")
        link(d, term, "value" if term in ("lu", "sph") else "result", f"g{k}", "b")
        total = f"g{k}"
    node(d, "cav", "multiply_add", values={"b": 0.05})
    link(d, total, "result", "cav", "a")
    link(d, "rm", "result", "cav", "c")
    node(d, "md", "mod", values={"b": 0.7})
    link(d, "m3", "result", "md", "a")
    node(d, "ce", "ceil")
    link(d, "m3", "result", "ce", "value")
    node(d, "rf", "reflect")
    link(d, "nr", "result", "rf", "incident")
    link(d, "wn", "normal", "rf", "normal")
    node(d, "rr", "refract", values={"eta": 0.67})
    link(d, "nr", "result", "rr", "incident")
    link(d, "wn", "normal", "rr", "normal")
    node(d, "v1", "add")
    link(d, "md", "result", "v1", "a")
    link(d, "ce", "result", "v1", "b")
    node(d, "v2", "add")
    link(d, "rf", "result", "v2", "a")
    link(d, "rr", "result", "v2", "b")
    node(d, "v3", "add")
    link(d, "v1", "result", "v3", "a")
    link(d, "v2", "result", "v3", "b")
    node(d, "hsv", "combine", values={"z": 0.8})
    link(d, "sp", "y", "hsv", "x")  # hue wraps: v runs over [0.2, 3.2] turns
    link(d, "cl", "result", "hsv", "y")
    node(d, "h2r", "hsv_to_rgb")
    link(d, "hsv", "xyz", "h2r", "hsv")
    node(d, "v4", "add")
    link(d, "v3", "result", "v4", "a")
    link(d, "h2r", "color", "v4", "b")
    node(d, "s2l", "srgb_to_linear")
    link(d, "h2r", "color", "s2l", "color")
    node(d, "l2s", "linear_to_srgb")
    link(d, "v4", "result", "l2s", "color")
    node(d, "v5", "add")
    link(d, "s2l", "result", "v5", "a")
    link(d, "l2s", "result", "v5", "b")
    node(d, "iv", "invert", values={"amount": 0.3})
    link(d, "v5", "result", "iv", "color")
    node(d, "sa", "saturation", values={"amount": 1.4})
    link(d, "iv", "result", "sa", "color")
    node(d, "bcn", "brightness_contrast", values={"brightness": 0.1, "contrast": 0.2})
    link(d, "sa", "result", "bcn", "color")
    last = "bcn"
    for mode in ("multiply", "screen", "add", "subtract", "difference", "lighten", "darken"):
        node(d, f"bl_{mode}", f"blend_{mode}", values={"opacity": 0.7})
        link(d, last, "result", f"bl_{mode}", "base")
        link(d, "h2r", "color", f"bl_{mode}", "blend")
        last = f"bl_{mode}"
    node(d, "gm", "gamma", values={"gamma": 2.2})
    link(d, last, "result", "gm", "color")
    node(d, "bc2", "multiply_add", values={"b": 0.5})
    link(d, "gm", "result", "bc2", "a")
    link(d, "bc", "result", "bc2", "c")
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "bc2", "result", "make", "baseColor")
    link(d, "ad", "result", "make", "metallic")
    link(d, "sb", "result", "make", "roughness")
    link(d, "cav", "result", "make", "cavity")
    link(d, "fn", "normal", "make", "normal")
    node(d, "em2", "multiply_add", values={"b": 0.5})  # the sRGB curves, seen unmixed
    link(d, "v5", "result", "em2", "a")
    link(d, "em", "result", "em2", "c")
    link(d, "em2", "result", "make", "emissive")
    link(d, "sat", "result", "make", "opacity")
    link(d, "make", "attributes", "out", "attributes")
    return save(d, folder / "all_kinds.json")


@pytest.mark.gl
def test_every_mapped_kind_matches_materialx_glsl_and_round_trips(ctx, tmp_path):
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load
    from tests.mtlx_gpu import MtlxDrawer

    src = _all_kinds_material(tmp_path)
    assert cli("validate", str(src)).returncode == 0
    out = tmp_path / "all_kinds.mtlx"
    r = cli("export", str(src), "-o", str(out), "--size", str(SIZE), "--surface",
            "standard_surface")
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""  # nothing baked: every kind here maps
    doc = load_with_stdlib(out)
    ok, msg = doc.validate()
    assert ok, msg
    cpu = bake.attributes_cpu(lower_and_optimise(load(src), FileResolver()), SIZE)
    shader = next(n for n in doc.getNodes() if n.getCategory() == "standard_surface")
    drawer = MtlxDrawer(ctx, SIZE)
    checked = []
    try:
        for inp in shader.getInputs():
            if not inp.getNodeGraphString():
                continue
            o = doc.getNodeGraph(inp.getNodeGraphString()).getOutput(inp.getOutputString())
            got = drawer.draw(doc, o, tmp_path)
            want = cpu[SURFACE_INPUTS[inp.getName()]]
            if inp.getName() in ("normal", "coat_normal"):
                want = want / np.linalg.norm(want, axis=-1, keepdims=True)
            k = 1 if inp.getName() == "opacity" else want.shape[-1]
            np.testing.assert_allclose(got[..., :k], want[..., :k], atol=2e-3,
                                       err_msg=inp.getName())
            checked.append(inp.getName())
    finally:
        drawer.release()
    assert set(checked) == TALK_INPUTS, checked
    back = tmp_path / "back.json"
    r = cli("import", str(out), "-o", str(back))
    assert r.returncode == 0, r.stderr
    again = bake.attributes_cpu(lower_and_optimise(load(back), FileResolver()), SIZE)
    for k in cpu:
        np.testing.assert_allclose(again[k], cpu[k], atol=1e-6, err_msg=k)


def test_mtlx_export_refuses_a_link_to_the_document(tmp_path):
    import shutil

    folder = tmp_path / "g"
    shutil.copytree(graphs_dir(), folder)
    doc = folder / "materials" / "car_paint.json"
    before = doc.read_bytes()
    trap = tmp_path / "car.mtlx"
    trap.symlink_to(doc)
    r = cli("export", str(doc), "-o", str(trap), "--size", "8")
    assert r.returncode == 2 and "refusing to write over the document" in r.stderr
    assert doc.read_bytes() == before
    assert not list(tmp_path.glob("*.exr"))


def test_import_of_a_very_deep_chain_is_one_error_or_a_material(tmp_path):
    n = 3000
    nodes = ['<add name="a0" type="float"><input name="in1" type="float" value="0.001"/></add>']
    for i in range(1, n):
        nodes.append(f'<add name="a{i}" type="float"><input name="in1" type="float" '
                     f'nodename="a{i - 1}"/><input name="in2" type="float" value="0.0001"/>'
                     '</add>')
    text = _doc('<nodegraph name="NG">' + "".join(nodes) +
                f'<output name="o" type="float" nodename="a{n - 1}"/></nodegraph>'
                '<standard_surface name="S" type="surfaceshader"><input name="metalness" '
                'type="float" nodegraph="NG" output="o"/></standard_surface>'
                '<surfacematerial name="M" type="material"><input name="surfaceshader" '
                'type="surfaceshader" nodename="S"/></surfacematerial>')
    r, out = _import(tmp_path, text)
    assert "Traceback" not in r.stderr
    if r.returncode == 2:
        assert r.stderr.startswith("error: ") and "too deep" in r.stderr
        assert not out.exists()
    else:
        assert r.returncode == 0 and out.is_file()


@pytest.mark.gl
def test_texture_colour_spaces_in_materialx(ctx, tmp_path):
    """An sRGB texture's image reads its file as srgb_texture (a color4 image, the type
    MaterialX decodes), a linear one as lin_rec709, in a lin_rec709 document that validates;
    MaterialX's own GLSL, with its colour management, then gives the CPU evaluator's decoded
    values (2e-3), and the import brings the sRGB flag back (round trip within 1e-6)."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load
    from tests.interop_tools import srgb_decode, textured_material
    from tests.mtlx_gpu import MtlxDrawer

    n = 8
    src, albedo, _ = textured_material(tmp_path, n)
    out = tmp_path / "textured.mtlx"
    r = cli("export", str(src), "-o", str(out), "--size", str(n), "--surface",
            "standard_surface")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    doc = load_with_stdlib(out)
    ok, msg = doc.validate()
    assert ok, msg
    assert doc.getColorSpace() == "lin_rec709"
    images = {i.getInput("file").getValueString(): i
              for i in doc.getNodeGraph("NG_textured").getNodes("image")}
    # copies of the textures, in the export's side folder
    albedo_file, data_file = "textured_textures/albedo.png", "textured_textures/data.png"
    assert set(images) == {albedo_file, data_file}
    assert images[albedo_file].getInput("file").getColorSpace() == "srgb_texture"
    assert images[albedo_file].getType() == "color4"
    assert images[data_file].getInput("file").getColorSpace() == "lin_rec709"
    assert (tmp_path / albedo_file).read_bytes() == (tmp_path / "albedo.png").read_bytes()
    cpu = bake.attributes_cpu(lower_and_optimise(load(src), FileResolver()), n)
    np.testing.assert_allclose(cpu["baseColor"], srgb_decode(albedo), atol=1.0 / 255.0)
    shader = next(s for s in doc.getNodes() if s.getCategory() == "standard_surface")
    drawer = MtlxDrawer(ctx, n)
    try:
        for inp in ("base_color", "specular_roughness", "metalness"):
            i = shader.getInput(inp)
            o = doc.getNodeGraph(i.getNodeGraphString()).getOutput(i.getOutputString())
            got = drawer.draw(doc, o, tmp_path)
            want = cpu[SURFACE_INPUTS[inp]]
            np.testing.assert_allclose(got[..., :want.shape[-1]], want, atol=2e-3,
                                       err_msg=inp)
    finally:
        drawer.release()
    back = tmp_path / "back.json"
    r = cli("import", str(out), "-o", str(back))
    assert r.returncode == 0, r.stderr
    textures = {nd.settings["path"]: nd.settings for nd in load(back).graph.nodes.values()
                if nd.kind == "texture_parameter"}
    assert textures[albedo_file]["srgb"] is True
    assert textures[data_file]["srgb"] is False
    again = bake.attributes_cpu(lower_and_optimise(load(back), FileResolver()), n)
    for k in cpu:
        np.testing.assert_allclose(again[k], cpu[k], atol=1e-6, err_msg=k)


def test_opencolorio_spaces_map_to_materialx_names_or_are_refused(tmp_path):
    """An OpenColorIO space MaterialX 1.39 knows is written by its MaterialX name (ACEScg as
    acescg) and imported back to the same space; one it lacks (Linear Rec.2020) is an
    `error:` naming the node and the space."""
    from matedit.io.document import load, save

    src, _, _ = textured_material_with(tmp_path, "ACEScg")
    out = tmp_path / "t.mtlx"
    r = cli("export", str(src), "-o", str(out), "--size", "4")
    assert r.returncode == 0, r.stderr
    doc = load_with_stdlib(out)
    assert doc.validate()[0]
    (img,) = [i for i in doc.getNodeGraph("NG_textured").getNodes("image")
              if i.getInputValue("file") == "t_textures/albedo.png"]
    assert img.getInput("file").getColorSpace() == "acescg"
    back = tmp_path / "back.json"
    r = cli("import", str(out), "-o", str(back))
    assert r.returncode == 0, r.stderr
    (tex,) = [nd for nd in load(back).graph.nodes.values()
              if nd.kind == "texture_parameter"
              and nd.settings["path"] == "t_textures/albedo.png"]
    assert tex.settings["color_space"] == "ACEScg"

    d = load(src)
    d.graph.nodes["ta"].settings["color_space"] = "Linear Rec.2020"
    save(d, src)
    r = cli("export", str(src), "-o", str(tmp_path / "u.mtlx"), "--size", "4")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert lines[0].startswith(f"error: {src}: node sa: colour space 'Linear Rec.2020'")
    assert "srgb_texture" in lines[0]  # the names MaterialX knows are listed
    assert not (tmp_path / "u.mtlx").exists()


def textured_material_with(folder: Path, space: str):
    from matedit.io.document import load, save
    from tests.interop_tools import textured_material

    src, albedo, data = textured_material(folder, 4)
    d = load(src)
    d.graph.nodes["ta"].settings["color_space"] = space
    save(d, src)
    return src, albedo, data


# --- several materials in one document ----------------------------------------------------

MATERIALS = {"Red_Paint": (0.8, 0.1, 0.1), "9lives": (0.1, 0.8, 0.1), "blue": (0.1, 0.1, 0.8)}


def _several(extra: str = "") -> str:
    body = "".join(f'''
  <standard_surface name="S_{name}" type="surfaceshader">
    <input name="base_color" type="color3" value="{', '.join(map(str, c))}" />
  </standard_surface>
  <surfacematerial name="{name}" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="S_{name}" />
  </surfacematerial>''' for name, c in MATERIALS.items())
    return _doc(body + extra)


def test_import_of_several_materials_asks_for_one_or_a_folder(tmp_path):
    src = tmp_path / "many.mtlx"
    src.write_text(_several())
    out = tmp_path / "out.json"
    r = cli("import", str(src), "-o", str(out))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {src}: 3 materials (")
    assert "Red_Paint, 9lives, blue" in lines[0]
    assert "--material NAME" in lines[0] and "-o DIR" in lines[0]
    assert not out.exists()
    r = cli("import", str(src), "-o", str(out), "--material", "nope")
    assert r.returncode == 2 and "no material named 'nope'" in r.stderr
    assert "Red_Paint, 9lives, blue" in r.stderr and not out.exists()
    r = cli("import", str(src), "-o", str(out), "--material", "9lives")
    assert r.returncode == 0, r.stderr
    np.testing.assert_allclose(_eval(out)["baseColor"][0, 0], MATERIALS["9lives"], atol=1e-9)


def test_import_of_every_material_into_a_folder(tmp_path):
    src = tmp_path / "many.mtlx"
    src.write_text(_several())
    folder = tmp_path / "mats"  # created
    r = cli("import", str(src), "-o", str(folder))
    assert r.returncode == 0, r.stderr
    files = {"Red_Paint": "Red_Paint.json", "9lives": "m_9lives.json", "blue": "blue.json"}
    assert sorted(p.name for p in folder.iterdir()) == sorted(files.values())
    for name, file in files.items():
        assert cli("validate", str(folder / file)).returncode == 0
        np.testing.assert_allclose(_eval(folder / file)["baseColor"][0, 0], MATERIALS[name],
                                   atol=1e-9, err_msg=name)
    one = tmp_path / "one"
    r = cli("import", str(src), "-o", str(one), "--material", "blue")
    assert r.returncode == 0, r.stderr
    assert [p.name for p in one.iterdir()] == ["blue.json"]


def test_import_into_a_folder_writes_nothing_when_one_material_fails(tmp_path):
    src = tmp_path / "many.mtlx"
    src.write_text(_several('''
  <nodegraph name="NG"><cellnoise2d name="cells" type="float" />
    <output name="m" type="float" nodename="cells" /></nodegraph>
  <standard_surface name="S_bad" type="surfaceshader">
    <input name="metalness" type="float" nodegraph="NG" output="m" /></standard_surface>
  <surfacematerial name="bad" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="S_bad" /></surfacematerial>'''))
    folder = tmp_path / "mats"
    r = cli("import", str(src), "-o", str(folder))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "NG/cells" in lines[0] and "cellnoise2d" in lines[0]
    assert not folder.exists()


def test_output_names_are_checked_identifiers_and_distinct():
    from matedit.graph.names import identifier_problem
    from matedit.interop.mtlx_import import output_paths

    names = ["a b", "a_b", "A_B", "gl_x", "for", "../../etc", "x" * 80]
    paths = output_paths(names, Path("d"))
    stems = [paths[n].stem for n in names]
    assert stems[:3] == ["a_b", "a_b_2", "A_B_3"]
    assert all(identifier_problem(s) is None for s in stems), stems
    assert all(paths[n].parent == Path("d") for n in names)
    assert len({s.lower() for s in stems}) == len(stems)


# --- the lobes beyond the talk, both ways ----------------------------------------------------
_LOBE_VALUES = {
    "baseColor": [0.955, 0.638, 0.538], "metallic": 1.0, "roughness": 0.35,
    "specularColor": [0.9, 0.8, 0.7], "ior": 1.8, "coat": 0.75, "coatRoughness": 0.08,
    "coatColor": [0.96, 0.64, 0.54], "coatIor": 1.6, "sheenColor": [0.2, 0.3, 0.4],
    "sheenRoughness": 0.6, "anisotropy": 0.7, "anisotropyDirection": [0.0, 1.0, 0.0],
    "subsurface": 0.6, "subsurfaceColor": [0.9, 0.5, 0.4], "subsurfaceRadius": [0.3, 0.1, 0.05],
    "thickness": 0.25, "thinFilmThickness": 420.0, "thinFilmIor": 1.45,
}


def _lobe_material(path: Path) -> Path:
    import json

    path.write_text(json.dumps({
        "format": "matedit.material", "version": 2, "name": "lobes",
        "nodes": [{"id": "make", "kind": "make_attributes", "values": _LOBE_VALUES},
                  {"id": "out", "kind": "material_output"}],
        "links": [{"from": ["make", "attributes"], "to": ["out", "attributes"]}]}))
    return path


def test_every_lobe_field_exports_to_standard_surface_and_imports_back(tmp_path):
    """Constant lobe fields survive export -> MaterialX validate() -> import, within 1e-6
    (the direction through standard_surface's rotation in turns)."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load

    src = _lobe_material(tmp_path / "lobes.json")
    r = cli("validate", str(src))
    assert r.returncode == 0, r.stdout + r.stderr
    out = tmp_path / "x" / "lobes.mtlx"
    out.parent.mkdir()
    r = cli("export", str(src), "-o", str(out), "--surface", "standard_surface")
    assert r.returncode == 0, r.stderr
    doc = load_with_stdlib(out)
    ok, msg = doc.validate()
    assert ok, msg
    shader = next(n for n in doc.getNodes() if n.getCategory() == "standard_surface")
    sets = {i.getName(): i.getValueString() for i in shader.getInputs()}
    assert float(sets["coat"]) == pytest.approx(0.75)
    assert float(sets["specular_rotation"]) == pytest.approx(0.25)  # +Y: a quarter turn
    assert float(sets["sheen"]) == 1.0
    assert float(sets["subsurface_scale"]) == pytest.approx(4.0)  # 1 / thickness
    assert float(sets["thin_film_thickness"]) == pytest.approx(420.0)  # nm, both
    assert float(sets["thin_film_IOR"]) == pytest.approx(1.45)
    back = tmp_path / "back.json"
    r = cli("import", str(out), "-o", str(back))
    assert r.returncode == 0, r.stderr
    a = bake.attributes_cpu(lower_and_optimise(load(src), FileResolver()), 4)
    b = bake.attributes_cpu(lower_and_optimise(load(back), FileResolver()), 4)
    for k, v in _LOBE_VALUES.items():
        np.testing.assert_allclose(b[k], a[k], atol=1e-6, err_msg=k)
        np.testing.assert_allclose(a[k][0, 0], v, atol=1e-6, err_msg=k)


def test_a_coated_copper_imports_its_coat_and_a_velvet_its_sheen(tmp_path):
    """The way real MaterialX copper is written (white metal under a copper-tinted coat) and
    a sheen weight times a sheen colour come in as our coat and sheenColor, not dropped."""
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load

    f = tmp_path / "copper.mtlx"
    f.write_text(_doc(
        '<standard_surface name="SR_copper" type="surfaceshader">'
        '<input name="base_color" type="color3" value="1, 1, 1" />'
        '<input name="metalness" type="float" value="1" />'
        '<input name="coat" type="float" value="1" />'
        '<input name="coat_color" type="color3" value="0.96, 0.64, 0.54" />'
        '<input name="sheen" type="float" value="0.5" />'
        '<input name="sheen_color" type="color3" value="0.8, 0.6, 0.4" />'
        '<input name="specular_rotation" type="float" value="0.125" />'
        '<input name="specular_anisotropy" type="float" value="0.5" />'
        '</standard_surface>'
        '<surfacematerial name="Copper" type="material">'
        '<input name="surfaceshader" type="surfaceshader" nodename="SR_copper" />'
        '</surfacematerial>'))
    out = tmp_path / "copper.json"
    r = cli("import", str(f), "-o", str(out))
    assert r.returncode == 0, r.stderr
    ir = lower_and_optimise(load(out), FileResolver())
    a = bake.attributes_cpu(ir, 2)
    assert {"coat", "coatColor", "sheenColor", "anisotropy", "anisotropyDirection"} <= set(
        ir.attributes)
    assert "coatRoughness" not in ir.attributes  # not set in the file: our default
    np.testing.assert_allclose(a["coatColor"][0, 0], [0.96, 0.64, 0.54], atol=1e-6)
    np.testing.assert_allclose(a["sheenColor"][0, 0], [0.4, 0.3, 0.2], atol=1e-6)
    h = 0.5 ** 0.5
    np.testing.assert_allclose(a["anisotropyDirection"][0, 0], [h, h, 0.0], atol=1e-6)


def test_a_varying_anisotropy_direction_is_refused_on_export_with_its_name(tmp_path):
    import json

    src = tmp_path / "v.json"
    src.write_text(json.dumps({
        "format": "matedit.material", "version": 2, "name": "v",
        "nodes": [{"id": "p", "kind": "world_position"},
                  {"id": "make", "kind": "make_attributes", "values": {"anisotropy": 0.5}},
                  {"id": "out", "kind": "material_output"}],
        "links": [{"from": ["p", "position"], "to": ["make", "anisotropyDirection"]},
                  {"from": ["make", "attributes"], "to": ["out", "attributes"]}]}))
    for surface in ("standard_surface", "gltf_pbr"):
        r = cli("export", str(src), "-o", str(tmp_path / "v.mtlx"), "--surface", surface)
        assert r.returncode == 2, r.stdout + r.stderr
        assert r.stderr.count("error:") == 1 and "anisotropyDirection" in r.stderr
        assert not (tmp_path / "v.mtlx").exists()
