"""MaterialX's texture nodes, imported: each against MaterialX's own GLSL generator.

A document of the texture nodes real files use (tiledimage, place2d in both operation
orders, gltf_image, gltf_colorimage, gltf_normalmap, image under clamp, mirror, constant and
closest, hextiledimage, a normalmap of scale other than 1, rgbtohsv) on a 5 x 4 float
image: each output,
drawn by MaterialX's GLSL generator on the bake plane (tests/mtlx_gpu.py, which binds each
image's sampler as MaterialX's own GLSL renderer does), equals the imported material's
attribute from our CPU evaluator at the texel centres within 2e-3 (float32 GPU maths and
llvmpipe's 8-bit bilinear weights against float64), and so does our own GLSL of it (the
bake's GPU pass). The nodes made of nodegraphs are read
through MaterialX's definitions (matedit.interop.mtlx_import, `expand`), so this is the
check that each stdlib node inside them is read by MaterialX's rule.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

mx = pytest.importorskip("MaterialX")
SIZE = 24
W, H = 5, 4
TOL = 2e-3

# output name -> (the nodegraph's nodes for it, the node it reads, the surface input it
# feeds); place2d's texcoord defaults to (0, 0), not the mesh's UVs: it is connected
_IMG = '<input name="file" type="filename" value="tex.exr" />'
_PLACE = ('<texcoord name="{n}_uv" type="vector2" /><place2d name="{n}" type="vector2">'
          '<input name="texcoord" type="vector2" nodename="{n}_uv" />'
          '<input name="pivot" type="vector2" '
          'value="0.3, 0.6" /><input name="scale" type="vector2" value="{s}" />'
          '<input name="rotate" type="float" value="30" /><input name="offset" '
          'type="vector2" value="{o}" /><input name="operationorder" type="integer" '
          'value="{k}" /></place2d>')
CASES = {
    "tiled": (f'<tiledimage name="tiled_n" type="color3">{_IMG}<input name="uvtiling" '
              'type="vector2" value="2.5, 1.5" /><input name="uvoffset" type="vector2" '
              'value="0.3, -0.2" /><input name="realworldimagesize" type="vector2" '
              'value="2, 1" /><input name="realworldtilesize" type="vector2" value="1, 3" />'
              '</tiledimage>', "tiled_n", "base_color"),
    "srt": (_PLACE.format(n="p_srt", s="1.5, 0.7", o="0.1, 0.2", k=0)
            + f'<image name="srt_n" type="color3">{_IMG}<input name="texcoord" '
            'type="vector2" nodename="p_srt" /></image>', "srt_n", "base_color"),
    "trs": (_PLACE.format(n="p_trs", s="1.5, 0.7", o="0.1, 0.2", k=1)
            + f'<image name="trs_n" type="color3">{_IMG}<input name="texcoord" '
            'type="vector2" nodename="p_trs" /></image>', "trs_n", "base_color"),
    "gltf": (f'<gltf_image name="gltf_n" type="color3">{_IMG}<input name="factor" '
             'type="color3" value="0.5, 0.8, 1" /><input name="scale" type="vector2" '
             'value="2, 3" /><input name="rotate" type="float" value="40" /><input '
             'name="offset" type="vector2" value="0.25, 0.1" /></gltf_image>', "gltf_n",
             "base_color"),
    "gltf_color": (f'<gltf_colorimage name="gc_n" type="multioutput">{_IMG}<input '
                   'name="color" type="color4" value="0.9, 0.7, 0.5, 1" /><input '
                   'name="rotate" type="float" value="10" /><input name="offset" '
                   'type="vector2" value="0.1, 0.3" /></gltf_colorimage>', "gc_n",
                   "base_color"),
    "clamp_mirror": (_PLACE.format(n="p_cm", s="0.4, 0.3", o="0.5, 0.4", k=0)
                     + f'<image name="cm_n" type="color3">{_IMG}<input name="texcoord" '
                     'type="vector2" nodename="p_cm" /><input name="uaddressmode" '
                     'type="string" value="clamp" /><input name="vaddressmode" '
                     'type="string" value="mirror" /></image>', "cm_n", "base_color"),
    "constant": (_PLACE.format(n="p_c", s="0.4, 0.3", o="0.5, 0.4", k=0)
                 + f'<image name="c_n" type="color3">{_IMG}<input name="texcoord" '
                 'type="vector2" nodename="p_c" /><input name="uaddressmode" type="string" '
                 'value="constant" /><input name="vaddressmode" type="string" '
                 'value="mirror" /><input name="default" type="color3" '
                 'value="0.2, 0.9, 0.4" /></image>', "c_n", "base_color"),
    "closest": (f'<gltf_image name="cl_n" type="color3">{_IMG}<input name="scale" '
                'type="vector2" value="0.4, 0.3" /><input name="filtertype" type="string" '
                'value="closest" /><input name="vaddressmode" type="string" '
                'value="clamp" /></gltf_image>', "cl_n", "base_color"),
    "normal_scaled": (f'<image name="ni" type="vector3">{_IMG}</image><normalmap '
                      'name="nm_n" type="vector3"><input name="in" type="vector3" '
                      'nodename="ni" /><input name="scale" type="vector2" value="0.5, 1.8" />'
                      '</normalmap>', "nm_n", "normal"),
    "gltf_normal": (f'<gltf_normalmap name="gn_n" type="vector3">{_IMG}<input '
                    'name="rotate" type="float" value="25" /></gltf_normalmap>', "gn_n",
                    "normal"),
    "hex": (f'<hextiledimage name="hex_n" type="color3">{_IMG}<input name="tiling" '
            'type="vector2" value="1.7, 1.3" /><input name="rotationrange" type="vector2" '
            'value="10, 200" /><input name="scalerange" type="vector2" value="0.7, 1.6" />'
            '<input name="falloff" type="float" value="0.3" /><input name="falloffcontrast" '
            'type="float" value="0.8" /></hextiledimage>', "hex_n", "base_color"),
    "hex_defaults": (f'<hextiledimage name="hexd_n" type="color3">{_IMG}</hextiledimage>',
                     "hexd_n", "base_color"),
    # rgbtohsv (read as our RGB to HSV) of an image: hue in turns, saturation, value
    "hsv": (f'<image name="hi" type="color3">{_IMG}</image><rgbtohsv name="hsv_n" '
            'type="color3"><input name="in" type="color3" nodename="hi" /></rgbtohsv>',
            "hsv_n", "base_color"),
}
ATTRIBUTE = {"base_color": "baseColor", "normal": "normal"}


def _document() -> str:
    outputs, nodes, body = [], [], []
    for name, (xml, node, surface_input) in CASES.items():
        nodes.append(xml)
        out_type = "vector3" if surface_input == "normal" else "color3"
        port = ' output="outcolor"' if node == "gc_n" else ""
        outputs.append(f'<output name="o_{name}" type="{out_type}" nodename="{node}"{port} />')
        body.append(
            f'<standard_surface name="S_{name}" type="surfaceshader"><input '
            f'name="{surface_input}" type="{out_type}" nodegraph="NG" output="o_{name}" />'
            f'</standard_surface><surfacematerial name="M_{name}" type="material"><input '
            f'name="surfaceshader" type="surfaceshader" nodename="S_{name}" />'
            '</surfacematerial>')
    return ('<?xml version="1.0"?>\n<materialx version="1.39" colorspace="lin_rec709">'
            f'<nodegraph name="NG">{"".join(nodes)}{"".join(outputs)}</nodegraph>'
            f'{"".join(body)}</materialx>\n')


def _texture(folder: Path) -> np.ndarray:
    from matedit.io.images import write_image

    rng = np.random.default_rng(26)
    px = rng.uniform(0.05, 0.95, (H, W, 3)).astype(np.float32)
    write_image(folder / "tex.exr", px)
    return px


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    from matedit.interop.mtlx_import import import_all

    folder = tmp_path_factory.mktemp("tex")
    _texture(folder)
    src = folder / "textures.mtlx"
    src.write_text(_document(), encoding="utf-8")
    warnings: list[str] = []
    docs = import_all(src, folder / "out", warnings)
    for path, d in docs.items():
        from matedit.io.document import save

        path.parent.mkdir(exist_ok=True)
        save(d, path)
    return folder, src, {d.name: p for p, d in docs.items()}, warnings


def test_the_texture_nodes_import_without_a_warning(imported):
    _folder, _src, docs, warnings = imported
    assert sorted(docs) == sorted(f"M_{n}" for n in CASES)
    assert warnings == []


def test_the_addressing_and_placement_map_to_our_nodes(imported):
    from matedit.graph.nodes import Role, kind_for
    from matedit.io.document import load

    _folder, _src, docs, _ = imported
    addressed = kind_for(Role.ADDRESSED_TEXTURE_SAMPLE)
    got = {}
    for name in ("clamp_mirror", "constant", "closest", "tiled"):
        d = load(docs[f"M_{name}"])
        got[name] = [(n.values.get("u_address"), n.values.get("v_address"),
                      n.values.get("filter"), n.values.get("default_color"))
                     for n in d.graph.nodes.values() if n.kind == addressed]
    assert got["clamp_mirror"] == [(1.0, 2.0, 0.0, None)]
    assert got["constant"] == [(3.0, 2.0, 0.0, [0.2, 0.9, 0.4, 0.0])]
    assert got["closest"] == [(0.0, 1.0, 1.0, None)]
    assert got["tiled"] == []  # periodic and linear: the plain Texture Sample


@pytest.mark.gl
def test_each_texture_node_matches_materialx_glsl(ctx, imported):
    from matedit.compiler.api import lower_and_optimise
    from matedit.interop import bake
    from matedit.io.document import FileResolver, load
    from tests.mtlx_gpu import MtlxDrawer

    folder, src, docs, _ = imported
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(src))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    ok, msg = doc.validate()
    assert ok, msg
    drawer = MtlxDrawer(ctx, SIZE)
    checked = []
    try:
        for name, (_xml, _node, surface_input) in CASES.items():
            got = drawer.draw(doc, doc.getNodeGraph("NG").getOutput(f"o_{name}"), folder)
            ir = lower_and_optimise(load(docs[f"M_{name}"]), FileResolver())
            want = bake.attributes_cpu(ir, SIZE)[ATTRIBUTE[surface_input]]
            # our own GLSL of the imported material (the renderer's path) agrees too
            ours, _ = bake.bake_attributes(ctx, load(docs[f"M_{name}"]), FileResolver(), SIZE)
            np.testing.assert_allclose(ours[ATTRIBUTE[surface_input]][..., :3],
                                       want[..., :3], atol=TOL, err_msg=f"{name}: our GLSL")
            if surface_input == "normal":  # ours normalises in the (T, B, N) frame
                want = want / np.linalg.norm(want, axis=-1, keepdims=True)
            np.testing.assert_allclose(got[..., :3], want[..., :3], atol=TOL, err_msg=name)
            assert np.ptp(want[..., 0]) > 0.05, name  # a varying image, not a constant
            checked.append(name)
    finally:
        drawer.release()
    assert checked == list(CASES)


# --- what the import reads, warns about and refuses -----------------------------------------

def _one(graph: str, surface_input: str = "base_color", out_type: str = "color3",
         node: str = "n") -> str:
    return ('<?xml version="1.0"?>\n<materialx version="1.39"><nodegraph name="NG">'
            f'{graph}<output name="o" type="{out_type}" nodename="{node}" /></nodegraph>'
            f'<standard_surface name="S" type="surfaceshader"><input name="{surface_input}" '
            f'type="{out_type}" nodegraph="NG" output="o" /></standard_surface>'
            '<surfacematerial name="M" type="material"><input name="surfaceshader" '
            'type="surfaceshader" nodename="S" /></surfacematerial></materialx>\n')


def _import(tmp_path, text: str):
    from matedit.interop.mtlx_import import import_mtlx

    src = tmp_path / "in.mtlx"
    src.write_text(text, encoding="utf-8")
    warnings: list[str] = []
    doc = import_mtlx(src, tmp_path / "out.json", warnings=warnings)
    return doc, warnings


def _errors(tmp_path, text: str) -> list[str]:
    from matedit.interop.mtlx_import import MtlxImportError

    with pytest.raises(MtlxImportError) as exc:
        _import(tmp_path, text)
    return exc.value.messages


def test_a_second_uv_set_and_cubic_filtering_warn_by_name(tmp_path):
    text = _one('<texcoord name="uv1" type="vector2"><input name="index" type="integer" '
                f'value="1" /></texcoord><image name="n" type="color3">{_IMG}<input '
                'name="texcoord" type="vector2" nodename="uv1" /><input name="filtertype" '
                'type="string" value="cubic" /></image>')
    _doc, warnings = _import(tmp_path, text)
    assert sorted(warnings) == [
        "in.mtlx: material M: filtertype 'cubic' of image NG/n is read as linear (bilinear) "
        "filtering; approximated",
        "in.mtlx: material M: index 1 of texcoord NG/uv1 names a texture coordinate set "
        "matedit does not have (one UV set): set 0 is read; approximated"]


def test_inputs_an_expanded_node_does_not_use_warn_on_the_node(tmp_path):
    """gltf_colorimage's definition fixes periodic addressing whatever its own address
    inputs say; tiledimage's frame inputs are not ours: each is named, on the node."""
    text = _one(f'<gltf_colorimage name="gc" type="multioutput">{_IMG}<input '
                'name="uaddressmode" type="string" value="clamp" /></gltf_colorimage>'
                f'<tiledimage name="t" type="color3">{_IMG}<input name="frameoffset" '
                'type="integer" value="3" /></tiledimage><multiply name="n" type="color3">'
                '<input name="in1" type="color3" nodename="gc" output="outcolor" />'
                '<input name="in2" type="color3" nodename="t" /></multiply>')
    _doc, warnings = _import(tmp_path, text)
    assert sorted(warnings) == [
        "in.mtlx: material M: frameoffset 3 of tiledimage NG/t is not supported; dropped",
        "in.mtlx: material M: uaddressmode 'clamp' of gltf_colorimage NG/gc is not "
        "supported; dropped"]


def test_two_instances_of_one_definition_keep_their_own_inputs(tmp_path):
    from matedit.graph.nodes import Role, kind_for

    text = _one(f'<tiledimage name="a" type="color3">{_IMG}<input name="uvtiling" '
                'type="vector2" value="2, 3" /></tiledimage>'
                f'<tiledimage name="b" type="color3">{_IMG}<input name="uvtiling" '
                'type="vector2" value="5, 7" /></tiledimage><add name="n" type="color3">'
                '<input name="in1" type="color3" nodename="a" /><input name="in2" '
                'type="color3" nodename="b" /></add>')
    doc, warnings = _import(tmp_path, text)
    assert warnings == []
    samples = [n for n in doc.graph.nodes.values() if n.kind == kind_for(Role.TEXTURE_SAMPLE)]
    assert len(samples) == 2
    tilings = sorted(tuple(n.values.get("b", ())) for n in doc.graph.nodes.values()
                     if isinstance(n.values.get("b"), list) and len(n.values["b"]) == 2)
    assert [(2.0, 3.0), (5.0, 7.0)] == [t for t in tilings if t in ((2.0, 3.0), (5.0, 7.0))]


@pytest.mark.parametrize("graph, needle", [
    (f'<image name="n" type="color3">{_IMG}<input name="uaddressmode" type="string" '
     'value="wrap" /></image>', "node NG/n: uaddressmode 'wrap' is not supported"),
    (f'<image name="n" type="color3">{_IMG}<input name="filtertype" type="string" '
     'value="sharp" /></image>', "node NG/n: filtertype 'sharp' is not supported"),
    (f'<image name="n" type="color3">{_IMG}<input name="uaddressmode" type="string" '
     'value="constant" /><input name="default" type="color3" value="1e39, 0, 0" /></image>',
     "node NG/n: input default"),
    (f'<place2d name="p" type="vector2"><input name="operationorder" type="integer" '
     'value="x" /></place2d><image name="n" type="color3">'
     f'{_IMG}<input name="texcoord" type="vector2" nodename="p" /></image>',
     "input which"),
    (f'<image name="n" type="color3">{_IMG}</image><image name="t" type="vector3">{_IMG}'
     '</image><normalmap name="nm" type="vector3"><input name="in" type="vector3" '
     'nodename="t" /><input name="tangent" type="vector3" nodename="n" /></normalmap>',
     "node NG/nm: a normalmap with its own tangent input is not supported"),
    (f'<image name="t" type="vector3">{_IMG}</image><normalmap name="nm" type="vector3">'
     '<input name="in" type="vector3" nodename="t" /><input name="scale" type="float" '
     'value="3e38" /></normalmap>', "node NG/nm: input scale"),
    ('<fractal3d name="n" type="color3" />',
     "node NG/n (fractal3d, its N_fractal3d): unsupported MaterialX node 'fractal3d'"),
])
def test_what_the_texture_import_refuses_is_an_error_naming_the_node(tmp_path, graph, needle):
    surface = "normal" if "normalmap" in graph else "base_color"
    out = "vector3" if surface == "normal" else "color3"
    node = "nm" if surface == "normal" else "n"
    errors = _errors(tmp_path, _one(graph, surface, out, node))
    assert any(needle in e for e in errors), errors
    assert all(e.startswith("in.mtlx: ") for e in errors)


def test_a_normalmap_on_the_surfaces_own_frame_imports(tmp_path):
    text = _one(f'<image name="t" type="vector3">{_IMG}</image><bitangent name="bt" '
                'type="vector3"><input name="space" type="string" value="world" /></bitangent>'
                '<normalmap name="nm" type="vector3"><input name="in" type="vector3" '
                'nodename="t" /><input name="bitangent" type="vector3" nodename="bt" />'
                '<input name="scale" type="float" value="0.5" /></normalmap>', "normal",
                "vector3", "nm")
    doc, warnings = _import(tmp_path, text)
    assert warnings == []
    scaled = [n.values["b"] for n in doc.graph.nodes.values()
              if isinstance(n.values.get("b"), list) and len(n.values["b"]) == 3]
    assert [1.0, 1.0, 2.0] in scaled and [0.5, 0.5, 1.0] in scaled  # in x 2s - s
