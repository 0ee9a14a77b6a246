"""`matedit export OUT.usda|OUT.usdz`.

References: usd-core's own validators (the UsdValidation framework that `usdchecker` runs;
usd-core 26 has no `UsdUtils.ComplianceChecker` any more — where an older usd-core has it,
it runs too): no errors but one kind, MissingShaderIdInRegistry for the MaterialX `ND_*`
shader ids, which the pip usd-core's shader registry cannot know (it is built without
usdMtlx). Those ids are checked instead against MaterialX's own standard library: every
`ND_*` a node definition there, every authored input and output one of its own with its
type, and the network the MaterialX export's document node for node (values within 1e-6).
The UsdPreviewSurface constants are the document's values (within 1e-6), the baked base
colour and ORM textures the CPU evaluator's attributes at the texel centres (within 2/255
after 8-bit encoding, the glTF export's test's bound plus one for the GPU bake), and the
usdz's entries are stored and 64-byte aligned as the usdz specification asks.
"""

from __future__ import annotations

import copy
import json
import os
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pxr")

from pxr import Sdf, Usd, UsdGeom, UsdShade  # noqa: E402

from matedit.interop import bake  # noqa: E402
from matedit.io.images import read_image  # noqa: E402
from matedit.resources import graphs_dir  # noqa: E402

SIZE = 64
MATERIALS = graphs_dir() / "materials"
# sheen, coat (tinted), thin film, anisotropy, subsurface + ior, transmission + volume
SAMPLES = ["velvet", "coated_copper", "oil_slick_metal", "brushed_steel", "skin", "honey"]
pytestmark = pytest.mark.gl


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "matedit", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd)


def validation_errors(path: Path) -> list[str]:
    """usd-core's validators on the stage: every error but the MaterialX shader ids."""
    from pxr import UsdValidation

    reg = UsdValidation.ValidationRegistry()
    kw = ["UsdCoreValidators", "UsdShadeValidators", "UsdGeomValidators",
          "UsdUtilsValidators"]
    names = [m.name for m in reg.GetValidatorMetadataForKeywords(kw)]
    assert len(names) >= 15, names
    ctx = UsdValidation.ValidationContext(reg.GetOrLoadValidatorsByName(names))
    stage = Usd.Stage.Open(str(path))
    out = []
    for e in ctx.Validate(stage):
        if e.GetType() != UsdValidation.ValidationErrorType.Error:
            continue
        if e.GetName() == "MissingShaderIdInRegistry" and "shaderId 'ND_" in e.GetMessage():
            continue
        out.append(f"{e.GetName()}: {e.GetMessage()}")
    checker = getattr(__import__("pxr.UsdUtils").UsdUtils, "ComplianceChecker", None)
    if checker is not None:  # an older usd-core
        c = checker(arkit=False, skipARKitRootLayerCheck=True)
        c.CheckCompliance(str(path))
        out += [e for e in c.GetErrors() if "ND_" not in e]
    return out


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    """name -> (the .usda, the notes printed) for every sample."""
    root = tmp_path_factory.mktemp("usd")
    out = {}
    for name in SAMPLES:
        folder = root / name
        folder.mkdir()
        r = cli("export", MATERIALS / f"{name}.json", "-o", folder / f"{name}.usda",
                "--size", SIZE)
        assert r.returncode == 0, r.stderr
        out[name] = (folder / f"{name}.usda", r.stderr)
    return out


def _material(stage) -> tuple:
    meshes = [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    assert len(meshes) == 1
    mat, rel = UsdShade.MaterialBindingAPI(meshes[0]).ComputeBoundMaterial()
    assert mat and rel, "the mesh's material binding does not resolve"
    return meshes[0], mat


def _preview(mat) -> UsdShade.Shader:
    shader, _, _ = mat.ComputeSurfaceSource()
    assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
    return shader


def _source(inp):
    (info,) = inp.GetConnectedSources()[0]
    return UsdShade.Shader(info.source.GetPrim()), info.sourceName


@pytest.mark.parametrize("name", SAMPLES)
def test_the_validators_report_no_errors(exports, name):
    path, _ = exports[name]
    assert validation_errors(path) == []


def test_the_validators_see_a_broken_asset(exports, tmp_path):
    """The check can fail: a texture removed from beside the layer is an error."""
    path, _ = exports["velvet"]
    copy_ = tmp_path / "v.usda"
    copy_.write_bytes(path.read_bytes())
    for f in path.parent.iterdir():
        if f.suffix in (".png", ".exr") and "orm" not in f.name:
            (tmp_path / f.name).write_bytes(f.read_bytes())
    errors = validation_errors(copy_)
    assert any("orm.png" in e for e in errors), errors


@pytest.mark.parametrize("name", SAMPLES)
def test_stage_binding_and_files(exports, name):
    path, _ = exports[name]
    stage = Usd.Stage.Open(str(path))
    assert stage.GetDefaultPrim().GetName() == "Root"
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    mesh, mat = _material(stage)
    st = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st")
    assert st and st.GetTypeName() == Sdf.ValueTypeNames.TexCoord2fArray
    assert len(st.Get()) == len(UsdGeom.Mesh(mesh).GetPointsAttr().Get())
    _preview(mat)
    assert mat.GetSurfaceOutput("mtlx").HasConnectedSource()
    mx, _, _ = mat.ComputeSurfaceSource("mtlx")
    assert mx.GetIdAttr().Get() == "ND_standard_surface_surfaceshader"
    text = path.read_text()
    assert str(path.parent) not in text and "/tmp" not in text and os.sep + "work" not in text
    named = set()
    for prim in stage.Traverse():
        for attr in prim.GetAttributes():
            if attr.GetTypeName() == Sdf.ValueTypeNames.Asset and attr.Get() is not None:
                asset = attr.Get().path
                assert asset.startswith("./") and "/" not in asset[2:], asset
                assert (path.parent / asset[2:]).is_file(), asset
                named.add(asset[2:])
    beside = {p.name for p in path.parent.iterdir()} - {path.name}
    assert named == beside  # every file written is named, and nothing else was written


def _doc_value(raw: dict, field: str):
    """The value the document gives a make_attributes field: its own, or a parameter's."""
    make = next(n for n in raw["nodes"] if n["kind"] == "make_attributes")
    for link in raw["links"]:
        if link["to"] == [make["id"], field]:
            src = next(n for n in raw["nodes"] if n["id"] == link["from"][0])
            assert src["kind"].endswith("_parameter"), src["kind"]
            return src["values"]["value"]
    return make.get("values", {}).get(field)


@pytest.mark.parametrize("name, fields", [
    ("coated_copper", {"coat": "clearcoat", "coatRoughness": "clearcoatRoughness"}),
    ("skin", {"ior": "ior"}), ("honey", {"ior": "ior"})])
def test_preview_constants_are_the_documents(exports, name, fields):
    path, _ = exports[name]
    raw = json.loads((MATERIALS / f"{name}.json").read_text())
    stage = Usd.Stage.Open(str(path))
    surf = _preview(_material(stage)[1])
    for field, inp in fields.items():
        want = _doc_value(raw, field)
        assert want is not None, field
        assert abs(surf.GetInput(inp).Get() - want) <= 1e-6, (field, want)
    assert surf.GetInput("useSpecularWorkflow").Get() == 0


@pytest.mark.parametrize("name", ["velvet", "oil_slick_metal"])
def test_preview_textures_are_the_cpu_attributes(exports, name):
    """The base colour (sRGB) and ORM (raw) maps the preview reads, through the stage's own
    file names and channels, against the CPU evaluator at the texel centres: also proves the
    orientation (USD's st has v = 0 at the image's bottom, as the bake)."""
    from matedit.commands.bake import load_material
    from matedit.compiler.api import lower_and_optimise
    from matedit.io.document import FileResolver

    path, _ = exports[name]
    stage = Usd.Stage.Open(str(path))
    surf = _preview(_material(stage)[1])
    ir = lower_and_optimise(load_material(MATERIALS / f"{name}.json"), FileResolver())
    cpu = bake.attributes_cpu(ir, SIZE)

    def texels(inp):
        tex, channel = _source(surf.GetInput(inp))
        assert tex.GetIdAttr().Get() == "UsdUVTexture"
        pix = read_image(path.parent / tex.GetInput("file").Get().path[2:]).pixels[::-1]
        space = tex.GetInput("sourceColorSpace").Get()
        return np.asarray(pix, np.float64), channel, space

    pix, channel, space = texels("diffuseColor")
    assert (channel, space) == ("rgb", "sRGB")
    want = bake.linear_to_srgb(cpu["baseColor"])
    assert np.max(np.abs(pix[..., :3] - want)) <= 2 / 255
    for inp, field, k in (("occlusion", "cavity", 0), ("roughness", "roughness", 1),
                          ("metallic", "metallic", 2)):
        pix, channel, space = texels(inp)
        assert (channel, space) == ("rgb"[k], "raw")
        assert np.max(np.abs(pix[..., k] - np.clip(cpu[field][..., 0], 0, 1))) <= 2 / 255, inp
    tex, _ = _source(surf.GetInput("normal"))
    assert tex.GetInput("sourceColorSpace").Get() == "raw"
    assert tuple(tex.GetInput("scale").Get()) == (2, 2, 2, 1)
    assert tuple(tex.GetInput("bias").Get()) == (-1, -1, -1, 0)


def _mx_doc(name: str, out: Path):
    """The MaterialX export of the sample as the USD export makes it (the same stem)."""
    import MaterialX as mx

    from matedit.commands.bake import load_material
    from matedit.compiler.lower import lower_document
    from matedit.interop import mtlx_export
    from matedit.interop.mtlx_colorspace import stdlib
    from matedit.interop.usd import file_stem, texture_copies
    from matedit.io.document import FileResolver

    ir = lower_document(load_material(MATERIALS / f"{name}.json"), FileResolver())
    copies = {name: file for name, (file, _) in texture_copies(ir, out).items()}
    result = mtlx_export.export_ir(ir, out, SIZE, file_stem(out), "standard_surface", "exr",
                                   texture_files=copies, side="")
    doc = mx.createDocument()
    mx.readFromXmlString(doc, result.text)
    own = [n.getName() for n in doc.getNodeGraphs()], [n.getName() for n in doc.getNodes()]
    doc.importLibrary(stdlib())
    return doc, own


_SDF = {"float": "float", "integer": "int", "boolean": "bool", "color3": "color3f",
        "color4": "color4f", "vector2": "float2", "vector3": "float3", "vector4": "float4",
        "filename": "asset", "string": "string", "surfaceshader": "token"}


def _same_value(usd_value, mx_input) -> bool:
    v = mx_input.getValue()
    if mx_input.getType() == "filename":
        return usd_value.path == f"./{v}"
    if isinstance(v, (bool, int, float)):
        return abs(float(usd_value) - float(v)) <= 1e-6
    return np.allclose(np.asarray(tuple(usd_value)), np.asarray(v.asTuple()), atol=1e-6)


def _check_node(prim, node, graph_path) -> None:
    """A UsdShade shader against its MaterialX node: the id is the node's definition and
    every input is the node's, with the same type and value or connection."""
    shader = UsdShade.Shader(prim)
    nd = node.getNodeDef()
    assert nd is not None and shader.GetIdAttr().Get() == nd.getName(), node.getName()
    inputs = {i.GetBaseName(): i for i in shader.GetInputs()}
    assert set(inputs) == {i.getName() for i in node.getInputs()}, node.getName()
    for mi in node.getInputs():
        ui = inputs[mi.getName()]
        assert nd.getActiveInput(mi.getName()) is not None, (node.getName(), mi.getName())
        assert str(ui.GetTypeName()) == _SDF[mi.getType()], (node.getName(), mi.getName())
        srcs = ui.GetConnectedSources()[0]
        if mi.getInterfaceName():
            (s,) = srcs
            assert s.source.GetPath() == graph_path and s.sourceName == mi.getInterfaceName()
        elif mi.getNodeName():
            (s,) = srcs
            assert s.source.GetPath() == graph_path.AppendChild(mi.getNodeName())
            assert s.sourceName == (mi.getOutputString() or "out")
        elif mi.getNodeGraphString():
            (s,) = srcs
            assert s.source.GetPath().name == mi.getNodeGraphString()
            assert s.sourceName == mi.getOutputString()
        else:
            assert not srcs and _same_value(ui.Get(), mi), (node.getName(), mi.getName())
    outs = {o.GetBaseName() for o in shader.GetOutputs()}
    assert outs == {o.getName() for o in nd.getActiveOutputs()}


@pytest.mark.parametrize("name", SAMPLES)
def test_mtlx_network_is_the_materialx_export(exports, name):
    path, notes = exports[name]
    doc, (graphs, nodes) = _mx_doc(name, path)
    stage = Usd.Stage.Open(str(path))
    _, mat = _material(stage)
    stage = mat.GetPrim().GetStage()
    for gname in graphs:
        ng = doc.getNodeGraph(gname)
        gpath = mat.GetPath().AppendChild(gname)
        graph = UsdShade.NodeGraph(stage.GetPrimAtPath(gpath))
        assert graph, gname
        assert {i.GetBaseName() for i in graph.GetInputs()} == {
            i.getName() for i in ng.getInputs()}
        for mi in ng.getInputs():
            assert _same_value(graph.GetInput(mi.getName()).Get(), mi), mi.getName()
        children = [c for c in stage.GetPrimAtPath(gpath).GetChildren()]
        assert {c.GetName() for c in children} == {n.getName() for n in ng.getNodes()}
        for node in ng.getNodes():
            _check_node(stage.GetPrimAtPath(gpath.AppendChild(node.getName())), node, gpath)
        for mo in ng.getOutputs():
            (s,) = graph.GetOutput(mo.getName()).GetConnectedSources()[0]
            assert s.source.GetPath() == gpath.AppendChild(mo.getNodeName())
    (sr,) = [doc.getNode(n) for n in nodes if doc.getNode(n).getType() == "surfaceshader"]
    shader, _, _ = mat.ComputeSurfaceSource("mtlx")
    _check_node(shader.GetPrim(), sr, mat.GetPath())


NOTED = {"velvet": ["sheenColor"], "coated_copper": ["coatColor"],
         "oil_slick_metal": ["thinFilmThickness"], "brushed_steel": ["anisotropy"],
         "skin": ["subsurface"], "honey": ["transmission", "attenuationDistance"]}


@pytest.mark.parametrize("name", SAMPLES)
def test_lobes_the_preview_cannot_hold_are_noted(exports, name):
    _, notes = exports[name]
    for field in NOTED[name]:
        line = (f"note: {MATERIALS / name}.json: {field} has no UsdPreviewSurface input; "
                "the mtlx render context's MaterialX network carries it")
        assert line in notes.splitlines(), notes


def _emissive_doc(tmp_path: Path) -> Path:
    raw = json.loads((MATERIALS / "velvet.json").read_text())
    raw = copy.deepcopy(raw)
    make = next(n for n in raw["nodes"] if n["kind"] == "make_attributes")
    make.setdefault("values", {}).update({"emissive": [3.0, 1.5, 0.75], "opacity": 0.5})
    p = tmp_path / "glow.json"
    p.write_text(json.dumps(raw))
    return p


def test_emission_and_opacity(tmp_path):
    """Emission above 1 is the 8-bit map scaled back by its peak; opacity is its own map."""
    doc = _emissive_doc(tmp_path)
    out = tmp_path / "glow.usda"
    r = cli("export", doc, "-o", out, "--size", 16)
    assert r.returncode == 0, r.stderr
    assert validation_errors(out) == []
    stage = Usd.Stage.Open(str(out))
    surf = _preview(_material(stage)[1])
    em, ch = _source(surf.GetInput("emissiveColor"))
    assert ch == "rgb" and em.GetInput("sourceColorSpace").Get() == "sRGB"
    assert np.allclose(tuple(em.GetInput("scale").Get()), (3, 3, 3, 1))
    pix = read_image(out.parent / em.GetInput("file").Get().path[2:]).pixels
    lin = bake.srgb_to_linear(pix[..., :3]) * 3.0
    assert np.allclose(lin, [3.0, 1.5, 0.75], atol=3.0 * 2 / 255)
    op, ch = _source(surf.GetInput("opacity"))
    assert ch == "r" and op.GetInput("sourceColorSpace").Get() == "raw"
    assert np.allclose(read_image(out.parent / op.GetInput("file").Get().path[2:]).pixels,
                       0.5, atol=1 / 255)
    assert surf.GetInput("opacityThreshold").Get() == 0.0


def _local_data_offsets(path: Path) -> dict[str, tuple[int, int]]:
    """Each entry's (data offset, compression method) read from its local file header."""
    out = {}
    raw = path.read_bytes()
    with zipfile.ZipFile(path) as z:
        for info in z.infolist():
            h = info.header_offset
            sig, = struct.unpack_from("<I", raw, h)
            assert sig == 0x04034B50
            method, = struct.unpack_from("<H", raw, h + 8)
            n, m = struct.unpack_from("<HH", raw, h + 26)
            out[info.filename] = (h + 30 + n + m, method)
    return out


def test_usdz_is_a_valid_package(tmp_path):
    out = tmp_path / "pkg.usdz"
    r = cli("export", MATERIALS / "velvet.json", "-o", out, "--size", SIZE)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pkg.usdz"]  # nothing beside it
    entries = _local_data_offsets(out)
    names = list(entries)
    assert names[0] == "pkg.usdc"  # the root layer first
    for name, (offset, method) in entries.items():
        assert method == 0, f"{name} is compressed"
        assert offset % 64 == 0, f"{name} starts at {offset}"
    assert {"pkg_base_color.png", "pkg_normal.png", "pkg_orm.png"} <= set(names)
    layer = Sdf.Layer.FindOrOpen(f"{out}[pkg.usdc]")
    assert layer is not None and layer.defaultPrim == "Root"
    assert validation_errors(out) == []
    stage = Usd.Stage.Open(str(out))
    _, mat = _material(stage)
    tex, _ = _source(_preview(mat).GetInput("diffuseColor"))
    assert tex.GetInput("file").Get().resolvedPath.endswith("[pkg_base_color.png]")
    assert os.fsencode(str(tmp_path)) not in out.read_bytes()


@pytest.mark.parametrize("instance", ["worn_paint_red"])
def test_instances_export(tmp_path, instance):
    src = graphs_dir() / "instances" / f"{instance}.json"
    out = tmp_path / "i.usda"
    r = cli("export", src, "-o", out, "--size", 16)
    assert r.returncode == 0, r.stderr
    assert validation_errors(out) == []
    stage = Usd.Stage.Open(str(out))
    _, mat = _material(stage)
    assert mat.GetPrim().GetName() == instance  # named after the instance
    _preview(mat)
    assert mat.ComputeSurfaceSource("mtlx")[0].GetIdAttr().Get().startswith("ND_")


def test_a_planted_link_to_an_input_at_a_texture_name_is_refused(tmp_path):
    """A link at a side file's name that points at an input: exit 2, nothing written,
    the input untouched."""
    doc = tmp_path / "m.json"
    doc.write_bytes((MATERIALS / "velvet.json").read_bytes())
    out = tmp_path / "out"
    out.mkdir()
    (out / "e_orm.png").symlink_to(doc)
    before = doc.read_bytes()
    r = cli("export", doc, "-o", out / "e.usda", "--size", 8)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert "refusing to write over" in lines[0]
    assert doc.read_bytes() == before
    assert sorted(p.name for p in out.iterdir()) == ["e_orm.png"]


def test_usd_refuses_an_output_that_is_the_input(tmp_path):
    doc = tmp_path / "m.usda"
    doc.write_bytes((MATERIALS / "velvet.json").read_bytes())
    r = cli("export", doc, "-o", doc, "--size", 8)
    assert r.returncode == 2 and r.stderr.startswith("error: "), r.stderr
    assert doc.read_bytes() == (MATERIALS / "velvet.json").read_bytes()


def test_a_material_materialx_refuses_exports_its_preview(tmp_path):
    """A material the MaterialX export refuses (a varying anisotropy direction) still
    exports: the preview network alone, and a note says why there is no mtlx network."""
    out = tmp_path / "r.usda"
    r = cli("export", MATERIALS / "radial_brushed_aluminium.json", "-o", out, "--size", 16)
    assert r.returncode == 0, r.stderr
    assert "note: " in r.stderr and "no MaterialX network" in r.stderr, r.stderr
    assert "anisotropy has no UsdPreviewSurface input; dropped" in r.stderr, r.stderr
    assert validation_errors(out) == []
    stage = Usd.Stage.Open(str(out))
    _, mat = _material(stage)
    _preview(mat)
    assert not mat.GetSurfaceOutput("mtlx")


def test_a_texture_the_material_reads_is_copied_beside_the_layer(tmp_path):
    """The MaterialX network's image node reads a copy of the material's texture, beside
    the layer under a portable name, with the texture's colour space; the usdz holds it."""
    from hostile import base_material

    from matedit.io.images import write_image

    src = tmp_path / "src"
    src.mkdir()
    pixels = np.zeros((4, 4, 3), np.float32)
    pixels[..., 0] = 0.5
    write_image(src / "my albedo.png", pixels)
    raw = base_material()
    raw["nodes"] += [
        {"id": "tex", "kind": "texture_parameter", "position": [0, 300],
         "settings": {"name": "albedo", "path": "my albedo.png"}},
        {"id": "samp", "kind": "texture_sample", "position": [200, 300]}]
    raw["links"] = [lk for lk in raw["links"] if lk["to"] != ["make", "baseColor"]]
    raw["links"] += [{"from": ["tex", "texture"], "to": ["samp", "texture"]},
                     {"from": ["samp", "rgb"], "to": ["make", "baseColor"]}]
    doc = src / "m.json"
    doc.write_text(json.dumps(raw))
    out = tmp_path / "out" / "t.usda"
    out.parent.mkdir()
    r = cli("export", doc, "-o", out, "--size", 8)
    assert r.returncode == 0, r.stderr
    assert (out.parent / "t_texture0.png").read_bytes() == (src / "my albedo.png").read_bytes()
    assert validation_errors(out) == []
    stage = Usd.Stage.Open(str(out))
    images = [UsdShade.Shader(p) for p in stage.Traverse()
              if p.IsA(UsdShade.Shader) and
              str(UsdShade.Shader(p).GetIdAttr().Get()).startswith("ND_image_")]
    (image,) = images
    file = image.GetInput("file")
    assert file.Get().path == "./t_texture0.png"
    assert file.GetAttr().GetColorSpace() == "srgb_texture"
    r = cli("export", doc, "-o", tmp_path / "out" / "t.usdz", "--size", 8)
    assert r.returncode == 0, r.stderr
    with zipfile.ZipFile(tmp_path / "out" / "t.usdz") as z:
        assert z.read("t_texture0.png") == (src / "my albedo.png").read_bytes()


# Apple's usdz profile (what AR Quick Look loads; the rules the older ComplianceChecker ran
# with arkit=True, restated from the usdz specification and Apple's USDZ notes): the root
# layer is the only USD layer and is binary (usdc), it comes first, entries are stored and
# 64-byte aligned, files are only layers, PNG/JPEG images and audio, prims are of the
# geometry, shading and skinning types the viewer knows, and shaders are only the
# UsdPreviewSurface family.
ARKIT_FILES = {".usdc", ".usda", ".usd", ".png", ".jpg", ".jpeg", ".m4a", ".mp3", ".wav"}
ARKIT_PRIMS = {"", "Scope", "Xform", "Camera", "Shader", "NodeGraph", "Material", "Mesh",
               "Sphere", "Cube", "Cylinder", "Cone", "Capsule", "GeomSubset", "Points",
               "SkelRoot", "Skeleton", "SkelAnimation", "BlendShape", "SpatialAudio"}
ARKIT_SHADERS = {"UsdPreviewSurface", "UsdUVTexture", "UsdTransform2d"} | {
    f"UsdPrimvarReader_{t}" for t in ("float", "float2", "float3", "float4", "int", "string",
                                      "normal", "point", "vector", "matrix")}


def arkit_violations(path: Path) -> list[str]:
    out = []
    entries = _local_data_offsets(path)
    names = list(entries)
    layers = [n for n in names if Path(n).suffix.lower() in (".usdc", ".usda", ".usd")]
    if not names or Path(names[0]).suffix.lower() != ".usdc":
        out.append(f"the first entry {names[:1]} is not a usdc layer")
    if len(layers) != 1:
        out.append(f"the package holds {len(layers)} USD layers: {layers}")
    for name, (offset, method) in entries.items():
        if Path(name).suffix.lower() not in ARKIT_FILES:
            out.append(f"{name}: a file type the profile does not allow")
        if method != 0 or offset % 64:
            out.append(f"{name}: compressed or not 64-byte aligned")
    stage = Usd.Stage.Open(str(path))
    for prim in stage.Traverse():
        if prim.GetTypeName() not in ARKIT_PRIMS:
            out.append(f"{prim.GetPath()}: prim type {prim.GetTypeName()}")
        if prim.IsA(UsdShade.Shader):
            sid = UsdShade.Shader(prim).GetIdAttr().Get()
            if sid not in ARKIT_SHADERS:
                out.append(f"{prim.GetPath()}: shader {sid}")
            if sid == "UsdUVTexture":
                file = UsdShade.Shader(prim).GetInput("file").Get()
                if not file.resolvedPath or "[" not in file.resolvedPath:
                    out.append(f"{prim.GetPath()}: {file.path} is not inside the package")
    return out


@pytest.mark.parametrize("name", ["velvet", "honey"])
def test_arkit_usdz_follows_apples_profile(tmp_path, name):
    out = tmp_path / f"{name}.usdz"
    r = cli("export", MATERIALS / f"{name}.json", "-o", out, "--size", SIZE, "--arkit")
    assert r.returncode == 0, r.stderr
    assert "ARKit profile" in r.stderr and "MaterialX" in r.stderr, r.stderr
    assert arkit_violations(out) == []
    assert validation_errors(out) == []
    stage = Usd.Stage.Open(str(out))
    _, mat = _material(stage)
    assert _preview(mat).GetInput("diffuseColor").HasConnectedSource()
    assert os.fsencode(str(tmp_path)) not in out.read_bytes()


def test_the_arkit_rules_see_the_full_usdz(tmp_path):
    """The check can fail: the default usdz carries the MaterialX network (ND_* shaders)."""
    out = tmp_path / "full.usdz"
    r = cli("export", MATERIALS / "velvet.json", "-o", out, "--size", SIZE)
    assert r.returncode == 0, r.stderr
    problems = arkit_violations(out)
    assert any("shader ND_" in p for p in problems), problems


def test_arkit_is_for_usdz_only(tmp_path):
    r = cli("export", MATERIALS / "velvet.json", "-o", tmp_path / "v.usda", "--arkit")
    assert r.returncode == 2 and r.stderr.strip() == "error: --arkit applies to .usdz exports only"
    assert list(tmp_path.iterdir()) == []
