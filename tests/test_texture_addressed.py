"""The Addressed Texture Sample (MaterialX image's address modes and filter types) against
OpenGL's own samplers, which is how MaterialX's GLSL renderer reads them
(MaterialXRenderGlsl's texture handler binds periodic GL_REPEAT, clamp GL_CLAMP_TO_EDGE,
mirror GL_MIRRORED_REPEAT, constant GL_CLAMP_TO_BORDER with the default as border colour,
closest GL_NEAREST, linear GL_LINEAR).

Three readings of every mode pair and filter: the reference (a texture() call on a texture
whose sampler state is set so, through libGL), our node's GLSL (one read on the renderer's
GL_REPEAT / GL_LINEAR sampler, see shaders/nodes/texture_sample_addressed.glsl) and its
numpy twin (tap by tap, matedit.nodes.textures.sample_addressed). Tolerance 4e-3 on texels
in 0..1: llvmpipe quantises bilinear weights to 8 bits (1/256 of a texel difference).
"""

from __future__ import annotations

import ctypes
import itertools

import numpy as np
import pytest

from matedit.graph.nodes import Role, definition, kind_for
from matedit.nodes.textures import ADDRESS_MODES, sample_addressed
from tests.gpu_eval import _libgl, gpu_eval_many

TOL = 4e-3
GL_TEXTURE_2D, WRAP_S, WRAP_T, BORDER = 0x0DE1, 0x2802, 0x2803, 0x1004
GL_WRAP = {"periodic": 0x2901, "clamp": 0x812F, "mirror": 0x8370, "constant": 0x812D}
W, H = 7, 5
DEFAULT = np.array([0.9, 0.1, 0.6, 0.3], np.float32)


def _texture(ctx, texels, u: str, v: str, closest: bool):
    tex = ctx.texture((W, H), 4, np.ascontiguousarray(texels, np.float32).tobytes(),
                      dtype="f4")
    f = ctx.NEAREST if closest else ctx.LINEAR
    tex.filter = (f, f)
    tex.use(location=0)
    gl = _libgl()
    gl.glTexParameteri(GL_TEXTURE_2D, WRAP_S, GL_WRAP[u])
    gl.glTexParameteri(GL_TEXTURE_2D, WRAP_T, GL_WRAP[v])
    gl.glTexParameterfv(GL_TEXTURE_2D, BORDER,
                        (ctypes.c_float * 4)(*[float(x) for x in DEFAULT]))
    return tex


def _uvs(rng, closest: bool) -> np.ndarray:
    """Coordinates over -2.3..3.3 (every mode's outside on both sides); for closest, kept
    a tenth of a texel off texel edges (where the nearest texel is a float32 coin toss)."""
    uv = rng.uniform(-2.3, 3.3, (600, 2))
    if closest:
        n = np.array([W, H])
        cell = np.floor(uv * n)
        uv = (cell + rng.uniform(0.1, 0.9, uv.shape)) / n
    return uv.astype(np.float32)


@pytest.mark.parametrize("closest", [False, True], ids=["linear", "closest"])
def test_every_address_mode_pair_reads_as_opengl_samples_it(ctx, rng, closest):
    texels = rng.uniform(0.0, 1.0, (H, W, 4)).astype(np.float32)
    repeat = ctx.texture((W, H), 4, texels.tobytes(), dtype="f4")  # the renderer's sampler
    repeat.filter = (ctx.LINEAR, ctx.LINEAR)
    uv = _uvs(rng, closest)
    worst = 0.0
    for (ui, u), (vi, v) in itertools.product(enumerate(ADDRESS_MODES), repeat=2):
        ref_tex = _texture(ctx, texels, u, v, closest)
        try:
            got = gpu_eval_many(
                ctx, "ref = texture(reference, uv);\n"
                f"vec3 rgb; float r, g, b, a;\n"
                f"node_texture_sample_addressed(ours, uv, vec4{tuple(map(float, DEFAULT))}, "
                f"{ui}.0, {vi}.0, {1.0 if closest else 0.0}, node, rgb, r, g, b, a);",
                {"uv": uv}, {"ref": "vec4", "node": "vec4"},
                includes=["nodes/texture_sample_addressed.glsl"],
                preamble="uniform sampler2D reference;\nuniform sampler2D ours;",
                textures={"reference": ref_tex, "ours": repeat})
        finally:
            ref_tex.release()
        twin = sample_addressed(texels, uv, DEFAULT, ui, vi, 1.0 if closest else 0.0)
        if u == v == "constant":  # the test reaches the border: it is not a vacuous read
            assert np.any(np.all(np.isclose(got["ref"], DEFAULT, atol=1e-6), axis=1))
        for name, val in (("GLSL", got["node"]), ("twin", twin)):
            err = float(np.max(np.abs(val - got["ref"])))
            worst = max(worst, err)
            assert err < TOL, f"{name}, u {u}, v {v}: {err:.2e} from OpenGL's sampler"
    repeat.release()
    assert worst > 0.0 or closest  # the comparison does compare (bilinear differs a little)


def test_the_periodic_linear_reading_is_the_plain_texture_sample(rng):
    from matedit.nodes.textures import sample_bilinear

    texels = rng.uniform(0.0, 1.0, (H, W, 4))
    uv = rng.uniform(-2.0, 3.0, (200, 2))
    np.testing.assert_allclose(sample_addressed(texels, uv, DEFAULT, 0, 0, 0),
                               sample_bilinear(texels, uv), atol=1e-12)


def test_the_kind_is_its_role_and_bakes_on_export():
    d = definition(kind_for(Role.ADDRESSED_TEXTURE_SAMPLE))
    assert d.mtlx == "bake" and d.impure
    assert [i.name for i in d.inputs] == ["texture", "uv", "default_color", "u_address",
                                          "v_address", "filter"]
