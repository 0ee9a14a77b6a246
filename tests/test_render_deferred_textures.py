"""Texture identity: naming the same unchanged file again (what every value edit does for every
texture) reads and uploads nothing; a changed file or colour space reloads that one texture.
The deferred image of a textured material equals the forward one."""

from __future__ import annotations

import os

import numpy as np
import pytest
from test_render_deferred import REL_MEAN, REL_PIXEL
from test_shading_colorspace import texture_material, write_png

from matedit.compiler import compile_document
from matedit.io.document import FileResolver
from matedit.render import Renderer
from matedit.render import textures as T


@pytest.fixture
def textured(tmp_path):
    p = tmp_path / "grey.png"
    write_png(p, np.full((8, 8, 3), 100, np.uint8))
    cm = compile_document(texture_material(tmp_path, {"path": p.name}), FileResolver(),
                          "glsl330")
    return p, cm


def test_the_same_file_again_reads_nothing(gl_ctx, textured):
    path, cm = textured
    r = Renderer(gl_ctx, (32, 32), environment=None)
    r.set_lights([])  # no light, no environment: the frame is the emissive texture
    r.show_gizmos = False
    try:
        assert r.set_material(cm).ok
        (name,) = [t.name for t in cm.ir.textures]
        r.set_texture(name, str(path))
        r.render()
        r.render()
        tex = r.material.textures[name]
        reads = T.READS["count"]
        for _ in range(20):  # a slider drag: set_values names every texture at every step
            r.set_texture(name, str(path))
        assert T.READS["count"] == reads
        assert r.material.textures[name] is tex
        # another colour space: that texture again
        r.set_texture(name, str(path), "linear")
        assert T.READS["count"] == reads + 1
        # the file changes on disk (new size and time): read again
        write_png(path, np.full((4, 4, 3), 200, np.uint8))
        os.utime(path, ns=(1, 10**18))
        r.set_texture(name, str(path), "linear")
        assert T.READS["count"] == reads + 2
        r.render()
        covered = r.read_hdr()
        covered = covered[covered.sum(axis=2) > 0]
        assert covered.shape[0] > 50
        assert np.allclose(np.median(covered, axis=0), 200 / 255, atol=1e-3)
    finally:
        r.release()


def test_textured_material_deferred_equals_forward(gl_ctx, textured):
    _, cm = textured
    out = {}
    for deferred in (False, True):
        r = Renderer(gl_ctx, (48, 48), environment="studio", deferred=deferred)
        try:
            assert r.set_material(cm).ok
            assert r.is_forward == (not deferred)
            r.render()
            out[deferred] = r.read_linear().copy()
        finally:
            r.release()
    a, b = out[True], out[False]
    assert b.max() > 0.05
    rel = np.abs(a - b) / np.maximum(1.0, np.abs(b))
    # test_render_deferred's bounds: triangles of one surface meeting in a pixel are lit once
    assert rel.max() <= REL_PIXEL and rel.mean() <= REL_MEAN
