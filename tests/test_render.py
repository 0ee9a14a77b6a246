"""The preview renderer: samples render, symmetry, white furnace, analytic lights, program cache."""

from __future__ import annotations

import copy
import math
from dataclasses import replace

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.compiler import compile_document
from matedit.graph import nodes
from matedit.ibl import BakeSettings, Environment
from matedit.io import document as fmt
from matedit.io.document import FileResolver
from matedit.render import Renderer
from matedit.resources import graphs_dir
from matedit.shading import lights as L
from matedit.shading.lights import Light

MATERIALS = sorted((graphs_dir() / "materials").glob("*.json"))
SMALL = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
SIZE = (64, 64)


def constant_env(value=1.0) -> Environment:
    return Environment("constant", equirect=np.full((64, 128, 3), value, np.float32))


def flat_material(base=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.5):
    d = material()
    node(d, "r", "scalar_parameter", {"name": "rough"}, {"value": roughness})
    node(d, "make", "make_attributes", values={"baseColor": list(base), "metallic": metallic})
    node(d, "out", "material_output")
    link(d, "r", "value", "make", "roughness")
    link(d, "make", "attributes", "out", "attributes")
    return d


@pytest.fixture(scope="module")
def renderer(gl_ctx):
    r = Renderer(gl_ctx, SIZE, samples=4, environment="studio", bake_settings=SMALL)
    yield r
    r.release()


@pytest.fixture
def fresh(renderer):
    """The shared renderer, restored to defaults around each test."""
    from matedit.render.lights import default_rig

    renderer.mode = "splitsum"
    renderer.camera.reset()
    renderer.show_background = renderer.show_gizmos = True
    renderer.environment_intensity = 1.0
    renderer.set_lights(default_rig())
    renderer.set_mesh("sphere")
    yield renderer
    renderer.set_environment("studio")


@pytest.mark.parametrize("path", MATERIALS, ids=lambda p: p.stem)
def test_sample_renders_without_nan_and_not_blank(fresh, path):
    st = fresh.set_material(compile_document(fmt.load(path), FileResolver()))
    assert st.ok, st.errors
    fresh.render()
    hdr = fresh.read_hdr()
    img = fresh.read_image()
    assert np.all(np.isfinite(hdr))
    assert img.std() > 0.02  # not a flat fill
    centre = img[24:40, 24:40]
    corner = img[:6, :6]
    # the mesh stands out from the background: its pixels differ from the corner's colour
    # (a mirror can match the background's mean brightness, at 0 EV the chrome grip does)
    assert np.abs(centre - corner.mean(axis=(0, 1))).mean() > 0.01


def test_symmetric_setup_gives_symmetric_image(fresh):
    fresh.set_environment(constant_env(0.5))
    fresh.camera.yaw, fresh.camera.pitch = 0.0, 0.0
    fresh.show_gizmos = False
    fresh.set_lights([Light(kind="sphere", position=(0.0, 1.5, 4.0), intensity=10.0,
                            source_radius=0.2, influence_radius=30.0)])
    fresh.set_material(compile_document(flat_material((0.8, 0.3, 0.2), 0.0, 0.4)))
    fresh.render()
    hdr = fresh.read_hdr()
    # Mirror about the vertical axis. The silhouette is left out: the tessellation's quad
    # diagonals are not mirror symmetric. Tolerance: float32 rasterisation differences.
    h, w = hdr.shape[:2]
    yy, xx = np.mgrid[:h, :w]
    inside = (xx + 0.5 - w / 2) ** 2 + (yy + 0.5 - h / 2) ** 2 < (0.8 * 0.687 * h / 2) ** 2
    mirrored = hdr[:, ::-1]
    assert np.allclose(hdr[inside], mirrored[inside], atol=2e-3, rtol=2e-3)
    assert np.abs(hdr - mirrored).mean() < 2e-3


def _sphere_hits(r: Renderer):
    """Per pixel (top row first): hit mask, normal and view direction on the unit sphere."""
    w, h = r.size
    vp = r.camera.projection(w / h) @ r.camera.view_matrix()
    inv = np.linalg.inv(vp)
    xs = (np.arange(w) + 0.5) / w * 2 - 1
    ys = (np.arange(h) + 0.5) / h * 2 - 1
    X, Y = np.meshgrid(xs, ys[::-1])
    pts = np.stack([X, Y, np.ones_like(X), np.ones_like(X)], -1) @ inv.T
    far = pts[..., :3] / pts[..., 3:]
    eye = r.camera.eye
    d = far - eye
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = np.sum(d * eye, -1)
    c = np.dot(eye, eye) - 1.0
    disc = b * b - c
    hit = disc > 0
    t = -b - np.sqrt(np.where(hit, disc, 0))
    P = eye + d * t[..., None]
    return hit, P, -d


@pytest.mark.slow
def test_white_furnace_reference_returns_lut_a_plus_b(fresh):
    """White metal (F0 = 1) under a constant white environment: radiance = A + B of the LUT."""
    fresh.set_environment(constant_env(1.0))
    fresh.show_background = fresh.show_gizmos = False
    fresh.set_lights([])
    fresh.mode = "reference"
    from matedit.ibl import bake
    from matedit.shading.ibl import sample_lut

    table = bake(constant_env(1.0), SMALL, ctx=fresh.ctx).lut  # (N, N, 2): roughness, NoV
    hit, P, V = _sphere_hits(fresh)
    N = P
    NoV = np.clip(np.sum(N * V, -1), 0, 1)
    inner = hit & (NoV > 0.25)
    # keep away from the silhouette, where the tessellated sphere departs from the analytic one
    for roughness in (0.2, 0.5, 0.9):
        fresh.set_material(compile_document(flat_material(roughness=roughness)))
        fresh.render_converged()
        got = fresh.read_hdr("reference").mean(-1)
        want = sample_lut(table, NoV[inner], np.full(inner.sum(), roughness))[..., :2].sum(-1)
        err = np.abs(got[inner] - want)
        # 2048 samples a pixel, rotated per frame: Monte Carlo noise ~1%; LUT bilinear ~0.5%.
        assert np.median(err) < 0.01, (roughness, np.median(err))
        assert np.percentile(err, 95) < 0.04, (roughness, np.percentile(err, 95))


def test_point_light_on_flat_material_matches_numpy_twin(fresh):
    fresh.set_environment(constant_env(0.0))
    fresh.environment_intensity = 0.0
    fresh.show_background = fresh.show_gizmos = False
    fresh.set_mesh("plane")  # 2 m square in XZ, facing +Y
    fresh.camera.yaw, fresh.camera.pitch, fresh.camera.distance = 20.0, 55.0, 2.2
    light = Light(kind="point", position=(0.3, 0.8, 0.2), color=(1.0, 0.9, 0.8), intensity=2.0,
                  influence_radius=3.0)
    fresh.set_lights([light])
    base, metal, rough = (0.7, 0.4, 0.2), 0.3, 0.45
    fresh.set_material(compile_document(flat_material(base, metal, rough)))
    fresh.render()
    got = fresh.read_hdr()
    w, h = fresh.size
    vp = fresh.camera.projection(w / h) @ fresh.camera.view_matrix()
    inv = np.linalg.inv(vp)
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(200):
        i, j = rng.integers(2, w - 2), rng.integers(2, h - 2)
        ndc = np.array([(i + 0.5) / w * 2 - 1, 1 - (j + 0.5) / h * 2])
        a = inv @ np.array([*ndc, -1, 1])
        b = inv @ np.array([*ndc, 1, 1])
        a, b = a[:3] / a[3], b[:3] / b[3]
        t = a[1] / (a[1] - b[1])
        P = a + (b - a) * t
        if np.max(np.abs(P[[0, 2]])) > 0.95:
            continue  # off the plane or too close to its edge
        V = fresh.camera.eye - P
        V /= np.linalg.norm(V)
        diffuse = np.asarray(base) * (1 - metal)
        F0 = 0.04 * (1 - metal) + np.asarray(base) * metal
        s = L.makeShadingContext(P[None], np.array([[0.0, 1.0, 0.0]]), V[None], diffuse[None],
                                 F0[None], np.array([rough]))
        want = L.evaluateLight(s, light)[0]
        # float32 shading against float64: 1e-3 relative; interpolated position: +1e-4
        assert np.allclose(got[j, i], want, rtol=2e-3, atol=2e-4), (i, j, got[j, i], want)
        checked += 1
    assert checked > 50


@pytest.mark.parametrize("small, big", [
    (Light(kind="sphere", position=(1.5, 2.0, 2.5), intensity=12.0, source_radius=1e-4,
           influence_radius=20.0),
     Light(kind="point", position=(1.5, 2.0, 2.5), intensity=12.0, influence_radius=20.0)),
    (Light(kind="tube", position=(1.5, 2.0, 2.5), direction=(0.0, 1.0, 0.0), intensity=12.0,
           source_radius=0.2, source_length=1e-4, influence_radius=20.0),
     Light(kind="sphere", position=(1.5, 2.0, 2.5), intensity=12.0, source_radius=0.2,
           influence_radius=20.0)),
], ids=["sphere_to_point", "tube_to_sphere"])
def test_area_lights_converge_as_they_shrink(fresh, small, big):
    fresh.set_environment(constant_env(0.0))
    fresh.show_background = fresh.show_gizmos = False
    fresh.set_material(compile_document(flat_material((0.6, 0.6, 0.6), 0.5, 0.3)))
    fresh.set_lights([small])
    fresh.render()
    a = fresh.read_hdr().copy()
    fresh.set_lights([big])
    fresh.render()
    b = fresh.read_hdr()
    assert a.max() > 0.05
    assert np.allclose(a, b, rtol=1e-2, atol=2e-3)


def test_parameter_edit_links_nothing_and_changes_the_image(fresh):
    fresh.set_material(compile_document(flat_material(roughness=0.3)))
    fresh.render()
    before = fresh.read_hdr().copy()
    links = fresh.link_count
    fresh.set_uniforms({"p_rough": 0.9})
    fresh.render()
    assert fresh.link_count == links
    assert np.abs(fresh.read_hdr() - before).max() > 0.01


def test_same_structure_reuses_program(fresh):
    d = flat_material(roughness=0.3)
    fresh.set_material(compile_document(d))
    links = fresh.link_count
    d.graph.nodes["r"].values["value"] = 0.7
    fresh.set_material(compile_document(d))
    assert fresh.link_count == links


def test_broken_program_keeps_the_last_good_one_and_names_the_node(fresh, monkeypatch):
    d = flat_material(roughness=0.3)
    good = compile_document(d)
    fresh.set_material(good)
    fresh.render()
    image = fresh.read_hdr().copy()
    # a generator fault: the node's call names a function that does not exist (the renderer
    # links entry variants emitted from the IR by the definitions, so the fault goes into
    # the kind's definition while the broken material links)
    make = nodes.definition("make_attributes")
    with monkeypatch.context() as m:
        m.setitem(nodes.REGISTRY, make.kind, replace(make, glsl="node_make_attributez"))
        broken = compile_document(d, ir=copy.deepcopy(good.ir))
        assert "node_make_attributez(" in broken.fragment_text
        status = fresh.set_material(broken)
    assert not status.ok
    assert status.errors[0][0] == "make"
    fresh.render()
    assert np.array_equal(fresh.read_hdr(), image)


def test_bad_obj_is_a_clear_error(fresh, tmp_path):
    from matedit.render import MeshError

    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(MeshError, match=r"bad.obj:3: vertex index 7"):
        fresh.set_mesh(bad)
    good = tmp_path / "tri.obj"
    good.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    fresh.set_mesh(good)
    assert math.isclose(float(np.max(np.linalg.norm(fresh._mesh.data.positions, axis=1))), 1.0,
                        rel_tol=1e-5)


# Anisotropic samples whose split sum is further off the reference than the talk's few
# percent: the three taps along the lobe (docs/shading.md, Anisotropy) read a long lobe of the
# studio's bright panels as three narrow lookups. Measured (benchmarks/bench_aniso_samples.py):
# brushed gold 0.223, brushed steel 0.179 (the bent single lookup before the taps: 0.637 and
# 0.641; with anisotropy 0 both are 0.07); bound = measured x 1.3, so a change that makes
# them worse fails. The radial disc (0.095; 0.307 before) is under the common 0.12.
# oil_slick_metal 0.110: the thin film's split sum looks its Airy colour up at N.V only,
# where the reference's varies with V.H across the lobe (docs/shading.md, Thin film; the
# variants F0 + (F_film - F_Schlick) and F_film (A + B) measure 0.107 and 0.108).
# Frosted glass 0.205 (docs/shading.md, Transmission): the rough solid's single lookup along
# the exit ray against reference mode's sampled refraction through the sphere, largest at
# the silhouette, where the exit bends the rays most.
# Velvet 0.113 (fabric weave 0.044 is under the common bound): the sheen's split sum reads one
# lookup around N at roughness 1 for the wide Charlie lobe (docs/shading.md, Sheen; at the
# sheen roughness, before: 0.224 and 0.074).
SPLIT_SUM_MEASURED = {"brushed_gold": 0.223, "brushed_steel": 0.179, "oil_slick_metal": 0.110,
                      "frosted_glass": 0.205, "velvet": 0.113}


def test_split_sum_and_reference_agree_on_samples(fresh):
    """Mean |split-sum - reference| over the mesh, relative to the mean radiance."""
    fresh.show_gizmos = False
    fresh.set_lights([])
    fresh.reference_frames = 32
    try:
        for path in MATERIALS:
            cm = compile_document(fmt.load(path), FileResolver())
            fresh.set_material(cm)
            fresh.mode = "splitsum"
            fresh.render()
            split = fresh.read_hdr().copy()
            fresh.mode = "reference"
            fresh.render_converged()
            ref = fresh.read_hdr("reference")
            rel = np.abs(split - ref).mean() / max(ref.mean(), 1e-6)
            # The split sum's known error (N = V = R lobes, separate integrals) is a few
            # percent; 12% bounds it with room for the reference's Monte Carlo noise.
            bound = 1.3 * SPLIT_SUM_MEASURED[path.stem] if path.stem in SPLIT_SUM_MEASURED \
                else 0.12
            assert rel < bound, (path.stem, rel, bound)
    finally:
        fresh.reference_frames = 64
