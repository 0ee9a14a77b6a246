"""Loose ends: the sampling frame at N = +Z, environments as six cube-face files, and cavity
multiplying all lighting (docs/shading.md#the-material-model)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from gpu_eval import gpu_eval_many
from graphs_util import link, material, node

from matedit.io.images import write_image


@pytest.mark.gl
def test_tangent_frame_is_the_identity_at_plus_z(ctx):
    N = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.6, 0.8]], np.float32)
    out = gpu_eval_many(ctx, "tangentFrame(N, T, B);", {"N": N}, {"T": "vec3", "B": "vec3"},
                        includes=["sampling.glsl"])
    assert np.allclose(out["T"][0], [1, 0, 0], atol=1e-6)
    assert np.allclose(out["B"][0], [0, 1, 0], atol=1e-6)
    for T, B, n in zip(out["T"], out["B"], N):  # orthonormal and right-handed everywhere
        assert np.allclose([T @ T, B @ B, T @ n, B @ n, T @ B], [1, 1, 0, 0, 0], atol=1e-6)
        assert np.allclose(np.cross(T, B), n, atol=1e-6)
    # a Hammersley point's azimuth is its world azimuth at N = +Z: phi = 2 pi x
    xi = np.array([[0.0, 0.5], [0.25, 0.5], [0.125, 0.3]], np.float32)
    h = gpu_eval_many(ctx, "H = importanceSampleGGX(Xi, 0.5, vec3(0.0, 0.0, 1.0));",
                      {"Xi": xi}, {"H": "vec3"}, includes=["sampling.glsl"])["H"]
    phi = np.arctan2(h[:, 1], h[:, 0]) % (2 * math.pi)
    assert np.allclose(phi, 2 * math.pi * xi[:, 0], atol=1e-5)


def test_six_cube_face_files_equal_the_cross(tmp_path):
    from matedit.ibl.cubemap import FACE_NAMES, faces_to_cross
    from matedit.ibl.environment import EnvironmentMapError, load_environment

    rng = np.random.default_rng(2)
    faces = rng.uniform(0, 4, (6, 8, 8, 3)).astype(np.float32)
    folder = tmp_path / "sky"
    folder.mkdir()
    for f, img in zip(FACE_NAMES, faces):
        write_image(folder / f"sky_{f}.exr", img)
    cross = tmp_path / "cross.exr"
    write_image(cross, faces_to_cross(faces))
    a, b = load_environment(folder), load_environment(cross)
    assert a.faces is not None and np.array_equal(a.faces, b.faces)
    assert a.content_hash() == b.content_hash()  # same radiance, same bake
    (folder / "sky_pz.exr").unlink()
    with pytest.raises(EnvironmentMapError, match="missing pz"):
        load_environment(folder)
    write_image(folder / "sky_pz.exr", np.ones((4, 4, 3), np.float32))
    with pytest.raises(EnvironmentMapError, match="differ in size"):
        load_environment(folder)


def test_render_accepts_a_face_folder(tmp_path):
    import subprocess
    import sys

    from matedit.ibl.cubemap import FACE_NAMES
    from matedit.resources import graphs_dir

    folder = tmp_path / "faces"
    folder.mkdir()
    for i, f in enumerate(FACE_NAMES):
        write_image(folder / f"{f}.hdr", np.full((8, 8, 3), 0.5 + 0.1 * i, np.float32))
    out = tmp_path / "x.png"
    r = subprocess.run([sys.executable, "-m", "matedit", "render",
                        str(graphs_dir() / "materials" / "brushed_gold.json"), "-o", str(out),
                        "--env", str(folder), "--size", "16x16"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 0


def _cavity_material(cavity: float, emissive=(0.0, 0.0, 0.0)):
    d = material()
    node(d, "c", "scalar_parameter", {"name": "cav"}, {"value": cavity})
    node(d, "make", "make_attributes", values={"baseColor": [0.7, 0.5, 0.3], "metallic": 0.3,
                                                "roughness": 0.45, "emissive": list(emissive)})
    node(d, "out", "material_output")
    link(d, "c", "value", "make", "cavity")
    link(d, "make", "attributes", "out", "attributes")
    return d


@pytest.mark.gl
@pytest.mark.parametrize("mode", ["splitsum", "reference"])
def test_cavity_multiplies_all_lighting_not_emissive(gl_ctx, mode):
    """(direct + ibl) * cavity + emissive: direct and image-based, diffuse and specular."""
    from test_render import SMALL

    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver
    from matedit.render import Renderer

    r = Renderer(gl_ctx, (24, 24), environment="studio", bake_settings=SMALL)
    try:
        r.show_background = r.show_gizmos = False
        r.mode = mode
        r.set_reference_samples(64)
        frames = {}
        for key, cav, emis in (("full", 1.0, (0, 0, 0)), ("third", 1 / 3, (0, 0, 0)),
                               ("emis", 0.0, (0.2, 0.4, 0.8)), ("both", 0.5, (0.2, 0.4, 0.8))):
            compiled = compile_document(_cavity_material(cav, emis), FileResolver(), "glsl330")
            assert r.set_material(compiled).ok
            r.render_converged()
            frames[key] = r.read_hdr()
        lit = frames["full"]
        assert lit.max() > 0.1
        # the deferred preview's G-buffer holds cavity and emissive as halves: 1/3 rounds by
        # 2.4e-4 relative, 0.2 by 2.4e-4 (matedit/render/deferred.py); 0.5 and 1 are exact
        assert np.allclose(frames["third"], lit / 3, rtol=5e-4, atol=1e-5)
        assert np.allclose(frames["both"], 0.5 * lit + frames["emis"], rtol=1e-4, atol=1e-5)
        covered = frames["emis"][frames["emis"].sum(axis=2) > 0]
        assert np.allclose(covered.max(axis=0), [0.2, 0.4, 0.8], rtol=5e-4, atol=1e-5)  # halves
    finally:
        r.release()
