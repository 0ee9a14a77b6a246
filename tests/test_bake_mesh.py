"""The glTF export's bake on the mesh (matedit.interop.bake.bake_for_export).

References: the CPU evaluator at the mesh's own surface points, found by this file's own
rasteriser (barycentric coordinates of each texel centre in the UV triangle that holds it,
numpy), and the Khronos glTF-Validator for the asset."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from matedit.compiler.api import compile_document, lower_and_optimise
from matedit.compiler.cpu_eval import evaluate
from matedit.interop import bake
from matedit.io.document import FileResolver, load, save
from matedit.nodes.twin import SurfaceArrays
from matedit.render.mesh import mesh_from_spec
from matedit.resources import graphs_dir
from tests.interop_tools import validate_gltf

MOSSY = graphs_dir() / "materials" / "mossy_stone.json"


def cli(*args):
    return subprocess.run([sys.executable, "-m", "matedit", *args], capture_output=True,
                          text=True)


def mesh_points(mesh, size: int):
    """For each texel centre of a size x size map (row 0 = v = 0): the mesh's interpolated
    position, normal and tangent there, and whether a triangle holds it."""
    uv = np.asarray(mesh.uvs, np.float64)
    tri = np.asarray(mesh.indices).reshape(-1, 3)
    c = (np.arange(size) + 0.5) / size
    pu, pv = np.meshgrid(c, c)
    pts = np.stack([pu.ravel(), pv.ravel()], 1)
    found = np.full(len(pts), -1)
    bary = np.zeros((len(pts), 3))
    for k, (i0, i1, i2) in enumerate(tri):
        a, b, d = uv[i0], uv[i1], uv[i2]
        lo, hi = np.minimum(np.minimum(a, b), d), np.maximum(np.maximum(a, b), d)
        box = np.all((pts >= lo - 1e-9) & (pts <= hi + 1e-9), axis=1) & (found < 0)
        if not box.any():
            continue
        m = np.array([[b[0] - a[0], d[0] - a[0]], [b[1] - a[1], d[1] - a[1]]])
        if abs(np.linalg.det(m)) < 1e-14:
            continue
        st = np.linalg.solve(m, (pts[box] - a).T).T
        w = np.stack([1 - st[:, 0] - st[:, 1], st[:, 0], st[:, 1]], 1)
        inside = np.all(w >= -1e-9, axis=1)
        ids = np.flatnonzero(box)[inside]
        found[ids] = k
        bary[ids] = w[inside]
    ok = found >= 0
    corners = tri[np.maximum(found, 0)]

    def interp(attr):
        a = np.asarray(attr, np.float64)
        return np.einsum("nk,nkc->nc", bary, a[corners])

    return pts, interp(mesh.positions), interp(mesh.normals), interp(mesh.tangents), ok


@pytest.mark.gl
def test_mossy_stone_sphere_keeps_its_moss_on_top(tmp_path):
    """The exported sphere's base colour map (read back from the .glb) is greener near the
    north pole (v > 0.8, where the world normal points up) than near the south pole
    (v < 0.2): mean G - (R + B) / 2 in sRGB codes / 255 is at least 0.05 higher at the top
    (measured at 64 texels: +0.164 top, +0.010 bottom), while the plane bake (flat, +Z up,
    the same moss everywhere) has no such difference (|top - bottom| < 0.02; measured +0.008
    and +0.010)."""
    import pygltflib

    from tests.test_interop_bake_gltf import file_pixels

    out = tmp_path / "moss.glb"
    r = cli("export", str(MOSSY), "-o", str(out), "--size", "64", "--mesh", "sphere")
    assert r.returncode == 0, r.stderr
    issues = validate_gltf(out, tmp_path)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    g = pygltflib.GLTF2().load(str(out))
    blob = g.binary_blob()
    view = g.bufferViews[g.images[g.textures[
        g.materials[0].pbrMetallicRoughness.baseColorTexture.index].source].bufferView]
    png = tmp_path / "base.png"
    png.write_bytes(blob[view.byteOffset or 0:(view.byteOffset or 0) + view.byteLength])
    base = file_pixels(png)[..., :3]  # row 0 = v = 0 (south pole)

    def green(rows):
        px = rows.reshape(-1, 3)
        return float(np.mean(px[:, 1] - (px[:, 0] + px[:, 2]) / 2))

    top, bottom = green(base[int(0.8 * 64):]), green(base[:int(0.2 * 64)])
    print(f"sphere: greenness top {top:+.4f} bottom {bottom:+.4f}")
    assert top > bottom + 0.05, (top, bottom)
    r = cli("bake", str(MOSSY), "-o", str(tmp_path / "flat"), "--size", "64")
    assert r.returncode == 0, r.stderr
    flat = file_pixels(tmp_path / "flat" / "mossy_stone_base_color.png")[..., :3]
    ftop, fbottom = green(flat[int(0.8 * 64):]), green(flat[:int(0.2 * 64)])
    print(f"plane: greenness top {ftop:+.4f} bottom {fbottom:+.4f}")
    assert abs(ftop - fbottom) < 0.02


@pytest.mark.gl
@pytest.mark.parametrize("name", ["mossy_stone", "muddy_tiles"])
def test_mesh_bake_matches_cpu_evaluator_at_the_mesh_points(ctx, name):
    """GPU bake on the sphere vs the CPU evaluator at the same surface points (this file's
    rasteriser, view along the normal, texel grid for derivatives): base colour, roughness,
    metallic, cavity and the (bumped, tangent-space) normal within 1e-4 at every texel
    (measured on llvmpipe: 2.4e-5 at most)."""
    size = 48
    mesh = mesh_from_spec("sphere")
    doc = load(graphs_dir() / "materials" / f"{name}.json")
    r = FileResolver()
    ir = lower_and_optimise(doc, r)
    compiled = compile_document(doc, r, "glsl330", mode="attributes", ir=ir)
    gpu, covered = bake.attributes_on_mesh(ctx, compiled, size, mesh)
    uv, pos, nrm, tan, ok = mesh_points(mesh, size)
    assert ok.all() and covered.all()  # the UV sphere fills the unit square
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    surf = SurfaceArrays(uv, pos, nrm, nrm.copy(), 0.0, grid=(size, size), tangent=tan)
    cpu = evaluate(lower_and_optimise(doc, r), surf, textures=bake.load_textures(ir))
    for key in ("baseColor", "roughness", "metallic", "cavity", "normal"):
        want = np.asarray(cpu[key], np.float64).reshape(size, size, -1)
        err = np.abs(gpu[key] - want).max(axis=-1)
        p99 = float(np.quantile(err, 0.99))
        print(f"{name} {key}: 99% {p99:.2e} max {err.max():.2e}")
        assert err.max() <= 1e-4, (key, float(err.max()))


@pytest.mark.gl
def test_view_dependent_node_is_baked_along_the_normal_and_noted(tmp_path):
    """facing_ratio -> base colour: on the mesh every texel sees itself head-on (1.0, within
    1e-5 in the float bake), the export says so in a note; a cube (overlapping UVs) is baked
    on the plane, with a note saying why."""
    from tests.graphs_util import link, material, node

    d = material()
    node(d, "f", "facing_ratio")
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    node(d, "c", "combine")
    link(d, "f", "value", "c", "x")
    link(d, "f", "value", "c", "y")
    link(d, "f", "value", "c", "z")
    link(d, "c", "xyz", "make", "baseColor")
    link(d, "make", "attributes", "out", "attributes")
    src = save(d, tmp_path / "facing.json")
    from matedit.render.context import headless

    with headless() as ctx:
        attrs, _, notes = bake.bake_for_export(ctx, load(src), FileResolver(), 32,
                                               mesh_from_spec("sphere"))
    np.testing.assert_allclose(attrs["baseColor"], 1.0, atol=1e-5)
    assert any("baked for a view along the normal" in n for n in notes), notes
    r = cli("export", str(src), "-o", str(tmp_path / "f.glb"), "--size", "16", "--mesh",
            "cube")
    assert r.returncode == 0, r.stderr
    assert "note:" in r.stderr and "UVs overlap" in r.stderr, r.stderr
    assert "baked for a view straight down on the plane" in r.stderr, r.stderr


def test_dilation_fills_past_the_islands():
    """Two texels of one island: the ring around it takes their mean, further texels the
    mean of the covered ones; covered texels are unchanged."""
    out = np.zeros((1, 6, 6, 1))
    covered = np.zeros((6, 6), bool)
    out[0, 2, 2, 0], out[0, 2, 3, 0] = 1.0, 3.0
    covered[2, 2] = covered[2, 3] = True
    grown = bake.dilate_into(out, covered, 1)
    assert grown[0, 2, 2, 0] == 1.0 and grown[0, 2, 3, 0] == 3.0
    assert grown[0, 1, 1, 0] == 1.0 and grown[0, 1, 4, 0] == 3.0
    assert grown[0, 1, 2, 0] == 2.0 and grown[0, 5, 5, 0] == 2.0
