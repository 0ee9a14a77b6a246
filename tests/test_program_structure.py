"""The size of the per-material program, held structurally (no timings): llvmpipe's JIT at a
structural edit's first draw grows with the code the fragment shader holds, and so does the
frame. Layered samples define each noise body once (layers call it, they do not copy it),
fBm octaves are a loop, not copies; a material without a lobe carries none of its code; the
gradient noise picks its gradient by selects (no ladder of returns); and the deferred preview
culls the back faces of closed meshes (their fragments only cost material code)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import numpy as np
import pytest

from matedit.compiler import compile_document
from matedit.compiler.emit import Entry
from matedit.io.document import FileResolver, load
from matedit.render.mesh import MeshData, builtin_mesh
from matedit.resources import graphs_dir

MATERIALS = graphs_dir() / "materials"
GLSLANG = shutil.which("glslangValidator")


def layered_samples() -> list:
    """Sample materials with a layer stack or a layer function call."""
    out = []
    for path in sorted(MATERIALS.glob("*.json")):
        nodes = json.loads(path.read_text()).get("nodes", [])
        if any(n.get("kind") == "layer_stack" or "/layers/" in
               str((n.get("settings") or {}).get("function", "")) for n in nodes):
            out.append(path)
    return out


LAYERED = layered_samples()
# the variants the preview links: deferred GBUFFER, forward split sum
VARIANTS = ((Entry.GBUFFER, ()), (Entry.FORWARD, ("MATEDIT_SPLIT_SUM_ONLY",)))
_DEF = re.compile(r"^[A-Za-z_][\w ]*?\b(\w+)\s*\(([^;{]*)\)\s*\{", re.M)


def definitions(text: str) -> list[tuple[str, str]]:
    """(name, parameter list) of every function defined in a GLSL text."""
    return [(m.group(1), " ".join(m.group(2).split())) for m in _DEF.finditer(text)
            if m.group(1) not in ("if", "for", "while", "switch")]


def body(text: str, name: str) -> str:
    """The body of the (first) definition of `name` in a GLSL text."""
    m = re.search(r"^[A-Za-z_][\w ]*?\b" + re.escape(name) + r"\s*\([^;{]*\)\s*\{", text, re.M)
    assert m, f"{name} is not defined"
    depth, i = 1, m.end()
    while depth:
        depth += {"{": 1, "}": -1}.get(text[i], 0)
        i += 1
    return re.sub(r"//[^\n]*", "", text[m.end():i - 1])  # code only


def fragment(path, entry=Entry.GBUFFER, defines=()) -> str:
    cm = compile_document(load(path), FileResolver())
    return cm.variant(entry, tuple(defines)).fragment_text


def test_there_are_layered_samples():
    assert len(LAYERED) >= 6, [p.stem for p in LAYERED]


@pytest.mark.parametrize("path", LAYERED, ids=lambda p: p.stem)
def test_layered_sample_defines_each_function_once(path):
    for entry, defines in VARIANTS:
        text = fragment(path, entry, defines)
        defs = definitions(text)
        seen = [d for d in defs if defs.count(d) > 1]
        assert not seen, f"{entry}: defined more than once: {sorted(set(seen))}"
        # a noise body is a function the layers call, not code copied into each layer
        for name in ("nodeGradientNoise2", "nodeValueNoiseOctave", "nodeCellular2",
                     "nodeHashPcg"):
            count = sum(1 for n, _ in defs if n == name)
            assert count <= 1, (entry, name, count)


@pytest.mark.parametrize("path", LAYERED, ids=lambda p: p.stem)
def test_layered_sample_noise_nodes_are_calls(path):
    """Each noise node of the graph is one call of the library function in the generated
    code: as many calls as nodes, however many layers use the noise."""
    text = fragment(path)
    generated = text[text.rindex("layout(location = 0) out"):]  # material functions and main
    cm = compile_document(load(path), FileResolver())
    kinds: dict[str, int] = {}
    for scope in [cm.ir.main, *cm.ir.functions]:
        for op in scope.ops:
            kinds[op.kind] = kinds.get(op.kind, 0) + 1
    for kind in ("fbm", "ridged_noise", "value_noise", "cellular_noise", "domain_warp"):
        calls = len(re.findall(r"\bnode_" + kind + r"\(", generated))
        assert calls == kinds.get(kind, 0), (kind, calls, kinds.get(kind, 0))


def test_fbm_octaves_are_a_loop():
    """nodeFbm2 sums its octaves in a loop around one gradient-noise call (a fractional count
    fades the last octave in), not in copies of the octave."""
    text = fragment(MATERIALS / "worn_painted_steel.json")
    for name, octave in (("nodeFbm2", "nodeGradientNoise2"),
                         ("node_ridged_noise", "nodeGradientNoise2"),
                         ("node_value_noise", "nodeValueNoiseOctave")):
        b = body(text, name)
        assert re.search(r"\bfor\s*\(", b), name
        assert len(re.findall(r"\b" + octave + r"\(", b)) == 1, name


def test_gradient_is_chosen_by_selects():
    """nodeGradient2 has no ladder of `if ... return` (llvmpipe would run each branch of it
    under execution masks): one return of nested selects."""
    text = fragment(MATERIALS / "rusty_painted_metal.json")
    b = body(text, "nodeGradient2")
    assert not re.search(r"\bif\s*\(", b)
    assert b.count("return") == 1


def test_gradient_selects_give_the_table():
    """The selects give exactly the eight gradients of the numpy twin's table (matedit.nodes
    .noise._gradient2), top three bits of the hash 0..7."""
    from matedit.nodes.noise import _gradient2

    d = np.float32(0.70710678)
    hashes = (np.arange(8, dtype=np.uint32) << np.uint32(29)) | np.uint32(12345)
    # the GLSL expression, evaluated in float32 with the same operations
    k = hashes >> np.uint32(29)
    s = np.where((k & 1) == 0, np.float32(1.0), np.float32(-1.0)).astype(np.float32)
    diag = np.stack([s * d, np.where((k & 2) == 0, d, -d)], axis=1)
    g = np.where((k < 2)[:, None], np.stack([s, np.zeros(8, np.float32)], axis=1),
                 np.where((k < 4)[:, None], np.stack([np.zeros(8, np.float32), s], axis=1),
                          diag))
    np.testing.assert_array_equal(g.astype(np.float32), _gradient2(hashes, np.float32))


@pytest.mark.skipif(GLSLANG is None, reason="glslangValidator not installed (glslang-tools)")
@pytest.mark.parametrize("name", ["worn_painted_steel", "rusty_painted_metal"])
def test_material_without_lobes_has_no_lobe_code(name, tmp_path):
    """A material that writes no coat, sheen, anisotropy, subsurface, thin film or
    transmission defines none of them, and once preprocessed its forward program has none of
    their functions."""
    cm = compile_document(load(MATERIALS / f"{name}.json"), FileResolver())
    text = cm.variant(Entry.FORWARD, ("MATEDIT_SPLIT_SUM_ONLY",)).fragment_text
    for lobe in ("COAT", "SHEEN_COLOR", "ANISOTROPY", "SUBSURFACE", "THIN_FILM_THICKNESS",
                 "TRANSMISSION"):
        assert f"#define MATERIAL_HAS_{lobe} " not in text
    f = tmp_path / "m.frag"
    f.write_text(text)
    r = subprocess.run([GLSLANG, "-E", str(f)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:]
    names = {n for n, _ in definitions(r.stdout)}
    for lobe_function in ("coatLayer", "coatSpecularTowards", "sheenLayer", "makeAnisotropicLobe",
                          "makeSubsurfaceLobe", "thinFilmFresnel", "makeTransmissionLobe",
                          "layeredEnvironmentIBL"):
        assert lobe_function not in names, lobe_function
    assert "shadeSurface" in names


def test_closed_meshes():
    for name, closed in (("sphere", True), ("cube", True), ("cylinder", True),
                         ("plane", False)):
        assert builtin_mesh(name).is_closed() is closed, name
    s = builtin_mesh("sphere")
    inside_out = MeshData(s.positions, s.normals, s.tangents, s.uvs, s.indices[:, ::-1].copy())
    assert not inside_out.is_closed()  # wound clockwise seen from outside
    big = np.argmax(np.linalg.norm(np.cross(
        s.positions[s.indices[:, 1]] - s.positions[s.indices[:, 0]],
        s.positions[s.indices[:, 2]] - s.positions[s.indices[:, 0]]), axis=1))
    holed = MeshData(s.positions, s.normals, s.tangents, s.uvs, np.delete(s.indices, big, 0))
    assert not holed.is_closed()  # a border
    flipped = s.indices.copy()
    flipped[big] = flipped[big, ::-1]
    assert not MeshData(s.positions, s.normals, s.tangents, s.uvs, flipped).is_closed()


def test_seen_from_outside():
    from matedit.render.camera import OrbitCamera

    class _Mesh:  # GpuMesh's predicate without a context
        from matedit.render.mesh import GpuMesh as _G
        seen_from_outside = _G.seen_from_outside
        bounds = _G.bounds

        def __init__(self, data):
            self.data, self._bounds = data, None

    m = _Mesh(builtin_mesh("sphere"))
    cam = OrbitCamera()
    assert m.seen_from_outside(cam, 1.0)
    cam.distance = 0.5  # the eye inside the sphere's box
    assert not m.seen_from_outside(cam, 1.0)
    cam.distance = 1.0 + 0.06  # outside, but the near plane (0.05) reaches into the sphere
    assert not m.seen_from_outside(cam, 1.0)


def test_culling_back_faces_keeps_the_deferred_image(gl_ctx, monkeypatch):
    """The deferred frame of a closed mesh with its back faces culled is the frame without
    culling: each back face lies behind a front face, which the depth test keeps."""
    from matedit.ibl import BakeSettings
    from matedit.render import Renderer

    small = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
    r = Renderer(gl_ctx, (96, 80), samples=4, environment="studio", bake_settings=small)
    try:
        _same_with_and_without_culling(r, "worn_painted_steel", False, monkeypatch)
        # forward (lobes beyond the G-buffer's), opaque: blending replaces, culling is exact
        _same_with_and_without_culling(r, "varnished_oak", True, monkeypatch)
    finally:
        r.release()


def test_translucent_materials_draw_both_sides(gl_ctx):
    from graphs_util import link, material, node

    from matedit.ibl import BakeSettings
    from matedit.render import Renderer

    d = material()
    node(d, "o", "scalar_parameter", {"name": "alpha"}, {"value": 0.5})
    node(d, "make", "make_attributes", values={"baseColor": [0.8, 0.4, 0.2]})
    node(d, "out", "material_output")
    link(d, "o", "value", "make", "opacity")
    link(d, "make", "attributes", "out", "attributes")
    small = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
    r = Renderer(gl_ctx, (32, 32), samples=4, environment="studio", bake_settings=small)
    try:
        r.set_material(compile_document(d))
        assert r.is_forward and not r.material.opaque  # the back faces show through
        r.set_uniforms({"p_alpha": 1.0})
        assert r.material.opaque
    finally:
        r.release()


def _same_with_and_without_culling(r, name, forward, monkeypatch):
    from matedit.render.mesh import GpuMesh

    r.set_material(compile_document(load(MATERIALS / f"{name}.json"), FileResolver()))
    assert r.is_forward == forward and r.material.opaque
    for mesh in ("sphere", "cube", "cylinder"):
        r.set_mesh(mesh)
        for yaw, pitch in ((30.0, 15.0), (200.0, -60.0)):
            r.camera.yaw, r.camera.pitch = yaw, pitch
            assert r._mesh.closed and r._mesh.seen_from_outside(r.camera, 96 / 80)
            r.render()
            culled = r.read_linear().copy()
            with monkeypatch.context() as m:
                m.setattr(GpuMesh, "closed", property(lambda self: False))
                r.render()
                both = r.read_linear().copy()
            assert both.max() > 0.05
            rel = np.abs(culled - both) / np.maximum(1.0, np.abs(both))
            # exact but for a sample on a silhouette edge that the fill rule gives to the
            # back face's triangle (seen: at most 2 pixels of 49,152 at 256 x 192)
            assert (rel.max(axis=2) > 1e-6).sum() <= 2, (name, mesh, yaw, pitch)
