"""The renderer's parts on their own: the program cache's variants, the texture cache's file
identity across recompiles, the accumulator's average and difference, the environment's
IblBlock, the light gizmos' placement, the frame block's packing."""

from __future__ import annotations

import copy
import math
import os
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from test_render_deferred import SMALL, flat_material
from test_shading_colorspace import write_png

from matedit.compiler import compile_document
from matedit.compiler.emit import PREVIEW_DEFINES, Entry
from matedit.glsl.layout import FRAME_BLOCK, IBL_BLOCK
from matedit.graph import nodes
from matedit.ibl import bake
from matedit.render import Renderer
from matedit.render import textures as T
from matedit.render.camera import OrbitCamera
from matedit.render.deferred import ENERGY_COMPENSATION, SPLIT_SUM_ONLY
from matedit.render.environment import EnvironmentLighting
from matedit.render.frames import Accumulator
from matedit.render.fullscreen import FullscreenQuad
from matedit.render.programs import MaterialStatus, ProgramCache
from matedit.render.uniforms import pack_frame_block
from matedit.shading.ibl import IBL_MODE_NONE, IBL_MODE_REFERENCE, IBL_MODE_SPLIT_SUM
from matedit.shading.lights import Light


# --- program cache ----------------------------------------------------------------------------
def test_program_cache_links_each_variant_once(gl_ctx):
    cm = compile_document(flat_material(roughness=0.35))
    cache = ProgramCache(gl_ctx)
    try:
        expected = {  # (forward, compensation) -> the variant the preview draws with
            (False, False): cm.variant(Entry.GBUFFER, PREVIEW_DEFINES),
            (True, False): cm.variant(Entry.FORWARD, (SPLIT_SUM_ONLY, *PREVIEW_DEFINES)),
            (True, True): cm.variant(Entry.FORWARD, (SPLIT_SUM_ONLY, ENERGY_COMPENSATION,
                                                     *PREVIEW_DEFINES)),
        }
        for (forward, compensation), variant in expected.items():
            prog = cache.material(cm, forward, compensation)
            assert cache.table[variant.structure_hash] is prog
        # deferred, the compensation option lives in the lighting pass: the same GBUFFER program
        assert cache.material(cm, False, True) is cache.material(cm, False, False)
        reference = cache.reference(cm, True)
        full = cm.variant(Entry.FORWARD, (ENERGY_COMPENSATION, *PREVIEW_DEFINES))
        assert cache.table[full.structure_hash] is reference
        assert cache.link_count == len(cache.table) == 4
        for (forward, compensation) in expected:  # all cached now
            assert cache.link(cm, forward, compensation) is cache.material(cm, forward,
                                                                          compensation)
        assert cache.link_count == 4
    finally:
        cache.release()
    assert cache.table == {}


def test_program_cache_locates_a_failed_link_in_the_variant_it_tried(gl_ctx, monkeypatch):
    d = flat_material(roughness=0.3)
    good = compile_document(d)
    # a generator fault: the kind's GLSL names a function no shader defines (the back-end
    # reads the definition, at compile and at each variant's link)
    make = nodes.definition("make_attributes")
    monkeypatch.setitem(nodes.REGISTRY, make.kind, replace(make, glsl="node_make_attributez"))
    broken = compile_document(d, ir=copy.deepcopy(good.ir))
    cache = ProgramCache(gl_ctx)
    try:
        for forward in (False, True):
            status = cache.link(broken, forward)
            assert isinstance(status, MaterialStatus) and not status.ok
            assert status.errors[0][0] == "make"
            assert "node_make_attributez" in status.log
        assert cache.link_count == 0 and cache.table == {}
        # the reference variant falls back to what the caller draws already
        assert cache.reference(broken, fallback=None) is None
    finally:
        cache.release()


# --- texture cache ----------------------------------------------------------------------------
def _info(name, path, srgb=True, color_space=""):
    """An IR texture record as TextureCache.sync reads it."""
    return SimpleNamespace(name=name, path=str(path), srgb=srgb, color_space=color_space)


def test_texture_cache_keeps_file_identity_across_recompiles(gl_ctx, tmp_path):
    big, small = tmp_path / "big.png", tmp_path / "small.png"
    write_png(big, np.full((8, 8, 3), 60, np.uint8))
    write_png(small, np.full((4, 4, 3), 120, np.uint8))
    cache = T.TextureCache(gl_ctx)
    try:
        reads = T.READS["count"]
        cache.sync([_info("a", big)])
        assert T.READS["count"] == reads + 1 and cache["a"].size == (8, 8)
        assert not cache.set("a", str(big), "srgb")  # the same file, space and time
        assert T.READS["count"] == reads + 1
        assert cache.set("a", str(small), "srgb")  # a value edit names another file
        assert T.READS["count"] == reads + 2 and cache["a"].size == (4, 4)
        # a recompile of the same material keeps what the value edit set, reading nothing
        cache.sync([_info("a", big)])
        assert T.READS["count"] == reads + 2 and cache["a"].size == (4, 4)
        # the file changes on disk: its next naming reads it again
        write_png(small, np.full((2, 2, 3), 200, np.uint8))
        os.utime(small, ns=(1, 10**18))
        assert cache.set("a", str(small), "srgb")
        assert T.READS["count"] == reads + 3 and cache["a"].size == (2, 2)
        # the recompiled material reads it as linear: the same file again, in the new space
        cache.sync([_info("a", big, srgb=False)])
        assert T.READS["count"] == reads + 4 and cache["a"].size == (2, 2)
        # a new texture loads; one the material no longer has goes
        cache.sync([_info("b", big)])
        assert "a" not in cache and "b" in cache and T.READS["count"] == reads + 5
    finally:
        cache.release()
    assert "b" not in cache


# --- accumulator ------------------------------------------------------------------------------
def _constant_frame(ctx, size, rgb):
    fbo = ctx.framebuffer([ctx.texture(size, 4, dtype="f4")])
    fbo.use()
    ctx.clear(*rgb, 1.0)
    return fbo


def test_accumulator_averages_reference_frames_and_differences_the_split_sum(gl_ctx):
    size = (6, 4)
    quad = FullscreenQuad(gl_ctx)
    acc = Accumulator(gl_ctx, quad)
    frames = [(0.25, 0.5, 2.0), (0.75, 0.0, 4.0), (0.5, 1.0, 3.0)]
    fbos = [_constant_frame(gl_ctx, size, c) for c in frames]
    try:
        acc.resize(size)
        for fbo in fbos:
            acc.add(fbo)
        assert acc.frames == 3
        mean = np.mean(frames, axis=0)
        ref = acc.read_hdr("reference", "reference", fbos[0])
        assert ref.shape == (4, 6, 3)
        assert np.allclose(ref, mean, rtol=1e-6, atol=0)  # float32 sums of three values
        split = _constant_frame(gl_ctx, size, (1.0, 1.0, 1.0))
        fbos.append(split)
        acc.keep_split_sum(split)
        diff = acc.read_linear("difference", fbos[0])
        assert np.allclose(diff, 1.0 - mean, rtol=0, atol=1e-6)
        assert acc.difference_mean("difference", fbos[0]) == pytest.approx(
            float(np.mean(np.abs(1.0 - mean))), abs=1e-6)
        assert acc.difference_mean("reference", fbos[0]) is None
        # split-sum mode reads the resolved frame itself, unscaled
        assert np.allclose(acc.read_linear("splitsum", fbos[1]), frames[1], atol=0)
        acc.frames = 0  # a reset: the next frame clears the sum
        acc.add(fbos[2])
        assert np.allclose(acc.read_hdr("reference", "reference", fbos[0]), frames[2], atol=0)
    finally:
        gl_ctx.detect_framebuffer(0).use()  # none of these stays bound once released
        for fbo in fbos:
            fbo.release()
        acc.release()
        quad.release()


# --- environment ------------------------------------------------------------------------------
def _ibl_params(env):
    offsets = IBL_BLOCK.offsets()
    data = np.frombuffer(env._block.read(), "<f4")
    sh = data[offsets["sh"] // 4:][: 9 * 4].reshape(9, 4)[:, :3]
    return data[offsets["params"] // 4:][:4], sh, data[offsets["sampleOffset"] // 4:][:4]


def test_environment_block_says_none_until_an_environment_is_set(gl_ctx):
    quad = FullscreenQuad(gl_ctx)
    env = EnvironmentLighting(gl_ctx, quad)
    try:
        env.bind(IBL_MODE_SPLIT_SUM, 1.5, 8)
        params, sh, _ = _ibl_params(env)
        assert params[3] == IBL_MODE_NONE and not env.loaded
        assert np.all(sh == 0)
        env.set("studio", SMALL)
        env.bind(IBL_MODE_REFERENCE, 1.5, 8, (0.25, 0.75), reference_lights=True)
        params, sh, offset = _ibl_params(env)
        assert tuple(params) == (env.levels, 1.5, 8, IBL_MODE_REFERENCE)
        assert tuple(offset[:3]) == (0.25, 0.75, 1.0)
        # irradiance -> radiance coefficients: divided by the cosine lobe's A_l per band
        irradiance = np.asarray(bake("studio", SMALL).sh, np.float64)
        a_l = np.array([math.pi] + [2 * math.pi / 3] * 3 + [math.pi / 4] * 5)[:, None]
        assert np.allclose(sh, irradiance / a_l, rtol=1e-6, atol=1e-7)
    finally:
        env.release()
        quad.release()


# --- frame block and gizmos -------------------------------------------------------------------
def test_frame_block_holds_the_camera_column_major():
    cam = OrbitCamera()
    data, vp = pack_frame_block(cam, (40, 20), 1.25, -0.5)
    floats = np.frombuffer(data, "<f4")
    off = {k: v // 4 for k, v in FRAME_BLOCK.offsets().items()}
    expected = cam.projection(2.0) @ cam.view_matrix()
    assert np.allclose(vp, expected)
    # GLSL reads a mat4 by columns: the first four floats are the first column
    stored = floats[off["viewProjection"]:off["viewProjection"] + 16].reshape(4, 4).T
    assert np.allclose(stored, expected, rtol=1e-6, atol=1e-6)
    assert np.allclose(floats[off["cameraPosition"]:][:3], cam.eye, rtol=1e-6)
    assert tuple(floats[off["params"]:][:4]) == (1.25, -0.5, 40.0, 20.0)


def _pixel(vp, point, size):
    """Where `point` lands in a read_hdr image (top row first), by the camera's matrices."""
    clip = vp @ np.array([*point, 1.0])
    ndc = clip[:3] / clip[3]
    w, h = size
    return int((1.0 - (ndc[1] * 0.5 + 0.5)) * h), int((ndc[0] * 0.5 + 0.5) * w)


def test_gizmos_stand_where_the_lights_are(gl_ctx):
    size = (96, 96)
    r = Renderer(gl_ctx, size, environment=None)
    try:
        point = Light(kind="point", position=(0.6, 0.4, 0.0), color=(1.0, 0.5, 0.25),
                      intensity=10.0, influence_radius=20.0, source_radius=0.1)
        tube = Light(kind="tube", position=(-0.6, 0.0, 0.0), direction=(0.0, 2.0, 0.0),
                     color=(0.2, 0.4, 1.0), intensity=100.0, influence_radius=20.0,
                     source_radius=0.08, source_length=1.0)
        sun = Light(kind="directional", direction=(0.0, -1.0, 0.0), intensity=5.0)
        r.set_lights([point, tube, sun])
        r.render()  # no material: only the gizmos
        image = r.read_hdr().copy()
        vp = r.camera.projection(1.0) @ r.camera.view_matrix()
        # a flat colour each: intensity scales it (capped at 50), lifted by 0.2
        want = {(0.6, 0.4, 0.0): np.array([1.0, 0.5, 0.25]) * 1.0 + 0.2,
                (-0.6, -0.5, 0.0): np.array([0.2, 0.4, 1.0]) * 5.0 + 0.2,  # tube ends
                (-0.6, 0.5, 0.0): np.array([0.2, 0.4, 1.0]) * 5.0 + 0.2}
        for where, colour in want.items():
            y, x = _pixel(vp, where, size)
            assert np.allclose(image[y, x], colour, rtol=1e-5), where
        # the line between the tube's ends (a pixel wide, partly covered at its edges)
        y, x = _pixel(vp, (-0.6, 0.0, 0.0), size)
        assert image[y - 1:y + 2, x - 1:x + 2].sum(axis=2).max() > 0.5
        lit = image.sum(axis=2) > 0
        assert 0 < lit.mean() < 0.2  # small shapes, and nothing for the directional light
        r.show_gizmos = False
        r.render()
        assert not np.any(r.read_hdr())
    finally:
        r.release()


def test_the_renderer_warm_up_frame_can_be_left_to_the_first_material(gl_ctx):
    """`warm_up=False`: no constant material linked and drawn at start (the editor's viewport
    passes it when its first material takes the deferred path)."""
    cold = Renderer(gl_ctx, (32, 32), environment=None, warm_up=False)
    warm = Renderer(gl_ctx, (32, 32), environment=None)
    try:
        assert cold.deferred and warm.deferred
        assert cold.link_count == 0 and warm.link_count == 1
        assert cold.environment_name == "" and cold.environment_warnings == []
    finally:
        cold.release()
        warm.release()
