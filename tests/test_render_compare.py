"""The renderer's A/B split (Renderer.set_compare): the compared material left of the divider
and the current one right of it, each pixel exactly as that material alone draws it."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.compiler import compile_document
from matedit.ibl import BakeSettings
from matedit.io.document import FileResolver
from matedit.render import Renderer

SMALL = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
SIZE = (96, 64)


def _material(colour, metallic, opacity=None):
    d = material()
    node(d, "r", "scalar_parameter", {"name": "rough"}, {"value": 0.35})
    values = {"baseColor": colour, "metallic": metallic}
    if opacity is not None:
        values["opacity"] = opacity
    node(d, "make", "make_attributes", values=values)
    node(d, "out", "material_output")
    link(d, "r", "value", "make", "roughness")
    link(d, "make", "attributes", "out", "attributes")
    return compile_document(d, FileResolver())


def _linear(r, mode):
    r.mode = mode
    r.reset_accumulation()
    r.render_converged()
    return r.read_linear()


@pytest.mark.parametrize("deferred", [True, False], ids=["deferred", "forward"])
@pytest.mark.parametrize("mode", ["splitsum", "reference"])
def test_split_shows_a_left_and_b_right_each_as_drawn_alone(ctx, deferred, mode):
    gold = _material([0.9, 0.6, 0.3], 1.0)
    # a translucent blue: the forward path even when the renderer is deferred
    blue = _material([0.1, 0.2, 0.8], 0.0, opacity=0.6 if deferred else None)
    r = Renderer(ctx, SIZE, samples=4, environment="studio", bake_settings=SMALL,
                 deferred=deferred)
    try:
        r.reference_samples, r.reference_frames = 4, 2
        r.set_material(gold)
        a_alone = _linear(r, mode)
        r.set_material(blue)
        b_alone = _linear(r, mode)
        assert np.abs(a_alone - b_alone).max() > 0.05  # the two differ on the mesh

        assert r.set_compare(gold).ok
        r.set_split(0.4)
        split = _linear(r, mode)
        cut = int(round(0.4 * SIZE[0]))
        # exactly each material's own pixels on its side (the same program, sample set
        # and frame count: float32 sums in the same order)
        np.testing.assert_array_equal(split[:, :cut], a_alone[:, :cut])
        np.testing.assert_array_equal(split[:, cut:], b_alone[:, cut:])

        r.set_split(0.0)  # clamped: a sliver of A is always there
        assert r.split == pytest.approx(0.05)
        r.set_compare(None)  # the split ends: B everywhere
        np.testing.assert_array_equal(_linear(r, mode), b_alone)
    finally:
        r.release()


def test_the_compared_side_follows_the_view_and_its_own_values(ctx):
    gold = _material([0.9, 0.6, 0.3], 1.0)
    r = Renderer(ctx, SIZE, samples=4, environment="studio", bake_settings=SMALL)
    try:
        (name,) = [u.name for u in gold.ir.uniforms if u.name.endswith("rough")]
        r.set_material(gold)
        smooth = _linear(r, "splitsum")
        r.set_compare(gold, {name: 0.9})
        cut = int(round(0.5 * SIZE[0]))
        split = _linear(r, "splitsum")
        r.set_uniforms({name: 0.9})
        rough = _linear(r, "splitsum")
        np.testing.assert_array_equal(split[:, :cut], rough[:, :cut])  # A's own roughness
        np.testing.assert_array_equal(split[:, cut:], smooth[:, cut:])
        assert np.abs(rough[:, :cut] - smooth[:, :cut]).max() > 0.05
        r.set_uniforms({name: 0.35})
        r.set_view("roughness")  # an attribute view: both sides show their roughness
        grey = _linear(r, "splitsum")
        h = SIZE[1] // 2
        left, right = grey[h, cut - 20], grey[h, cut + 20]
        assert left[0] == pytest.approx(0.9, abs=0.02) and right[0] == pytest.approx(0.35,
                                                                                     abs=0.02)
    finally:
        r.release()
