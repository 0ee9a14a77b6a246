"""The deferred preview: entry variants, deferred image = forward image on every sample
material and mode, structural edits link only the GBUFFER program, translucency falls back."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.compiler import compile_document
from matedit.compiler.emit import PREVIEW_DEFINES, Entry, entry_text
from matedit.ibl import BakeSettings
from matedit.io.document import FileResolver, load
from matedit.render import Renderer
from matedit.render.paths import may_be_translucent, writes_lobes
from matedit.resources import graphs_dir, shaders_dir

MATERIALS = sorted((graphs_dir() / "materials").glob("*.json"))
SMALL = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)  # test_render_parts
# Deferred against forward, |a - b| / max(1, |b|) on every pixel of the resolved image. The
# G-buffer (matedit/render/deferred.py) holds the position and roughness as float32 copies, but
# baseColor, metallic, emissive and cavity as halves (11-bit significand: relative rounding
# 2^-12, about 2.4e-4) and the normal octahedral in 16 bits a coordinate (about 3e-5 rad).
# Shading amplifies those roundings: (1 - metallic) near metallic 1, and a low roughness's
# narrow highlight against the normal's quantisation (with float32 copies the bound was 1e-6).
# Measured with the packing alone: at most 7.3e-3 (split sum, a few highlight pixels; most
# pixels below 5e-4), 6.0e-3 in reference mode, 5.8e-3 in difference mode. Silhouette pixels
# are lit per sample and held to this bound.
REL = 1e-2
# Where two triangles of one smooth surface meet inside a pixel, the deferred pass lights
# sample 0 once for the pixel (shaders/render/lighting.frag, sameAsFirst) where the forward
# pass lights each triangle's fragment and averages: those pixels differ by the variation of
# the shading over a fraction of a pixel. Measured on the samples at 64 px (a pixel spans a
# lot of the sphere there), packing included: worst pixel 0.032 (hammered_copper's bump),
# worst image mean 2.7e-4.
REL_PIXEL = 0.06
REL_MEAN = 1e-3


def flat_material(opacity=None, roughness=0.4):
    d = material()
    node(d, "r", "scalar_parameter", {"name": "rough"}, {"value": roughness})
    values = {"baseColor": [0.8, 0.4, 0.2], "metallic": 0.3}
    if opacity is not None:
        node(d, "o", "scalar_parameter", {"name": "alpha"}, {"value": opacity})
    node(d, "make", "make_attributes", values=values)
    node(d, "out", "material_output")
    link(d, "r", "value", "make", "roughness")
    if opacity is not None:
        link(d, "o", "value", "make", "opacity")
    link(d, "make", "attributes", "out", "attributes")
    return d


def _both(render_pair, compiled, mode="splitsum"):
    out = {}
    for name, r in render_pair.items():
        r.mode = mode
        status = r.set_material(compiled)
        assert status.ok, status.errors
        r.render_converged()
        out[name] = r.read_linear().copy()
    return out["deferred"], out["forward"]


def _rel(a, b):
    return np.abs(a - b) / np.maximum(1.0, np.abs(b))


# --- entry variants ---------------------------------------------------------------------------

def test_entries_are_glsl_files_and_forward_is_what_compile_exports():
    for entry in Entry:
        assert (shaders_dir() / "entry" / f"{entry.value}.frag.glsl").is_file()
        assert entry_text(entry).startswith("void main() {")
    doc = load(MATERIALS[0])
    cm = compile_document(doc, FileResolver())
    assert cm.fragment_text == cm.variant(Entry.FORWARD).fragment_text
    assert cm.fragment_text.rstrip().endswith(entry_text(Entry.FORWARD))
    assert "shadeSurface" in cm.fragment_text
    gb = cm.variant(Entry.GBUFFER)
    assert "shadeSurface" not in gb.fragment_text and "LightsBlock" not in gb.fragment_text
    # the packed G-buffer (matedit/render/deferred.py): two uint targets and a float one
    for i, t in enumerate(("uvec4", "uvec4", "vec2")):
        assert f"layout(location = {i}) out {t} gbuffer{i};" in gb.fragment_text
    attrs = compile_document(doc, FileResolver(), mode=Entry.ATTRIBUTES)
    assert attrs.fragment_text == compile_document(doc, FileResolver(),
                                                   mode="attributes").fragment_text
    assert "out3 = vec4(m.opacity" in attrs.fragment_text
    assert len({cm.structure_hash, gb.structure_hash, attrs.structure_hash}) == 3


def test_extra_defines_are_names_only_and_change_the_hash():
    cm = compile_document(flat_material())
    split = cm.variant(Entry.FORWARD, ("MATEDIT_SPLIT_SUM_ONLY",))
    assert "#define MATEDIT_SPLIT_SUM_ONLY 1" in split.fragment_text
    assert split.structure_hash != cm.structure_hash
    with pytest.raises(ValueError, match="not a define name"):
        cm.variant(Entry.FORWARD, ("X 1\nvoid main(){}",))


def test_every_entry_of_every_sample_links(gl_ctx):
    doc = load(MATERIALS[-1])
    cm = compile_document(doc, FileResolver())
    for entry in Entry:
        v = cm.variant(entry)
        gl_ctx.program(vertex_shader=v.vertex_text, fragment_shader=v.fragment_text).release()


# --- deferred = forward -----------------------------------------------------------------------

@pytest.mark.parametrize("path", MATERIALS, ids=[p.stem for p in MATERIALS])
def test_deferred_equals_forward_split_sum(render_pair, path):

    cm = compile_document(load(path), FileResolver())
    a, b = _both(render_pair, cm)
    # a material with lobes beyond the talk takes the forward path in the deferred renderer
    # too (the G-buffer holds the talk's fields): the two must still agree
    assert render_pair["deferred"].is_forward == writes_lobes(cm.ir)
    assert render_pair["forward"].is_forward
    assert b.max() > 0.05
    assert _rel(a, b).max() <= REL_PIXEL
    assert _rel(a, b).mean() <= REL_MEAN


@pytest.mark.parametrize("mode", ["reference", "difference"])
def test_deferred_equals_forward_reference_and_difference(render_pair, mode):
    cm = compile_document(load(graphs_dir() / "materials" / "worn_painted_steel.json"),
                          FileResolver())
    a, b = _both(render_pair, cm, mode)
    assert np.abs(b).max() > 0.01
    assert _rel(a, b).max() <= REL_PIXEL
    assert _rel(a, b).mean() <= REL_MEAN


def test_silhouettes_are_antialiased_like_forward(render_pair):
    """Edge pixels mix the background and the surface in the proportion of covered samples:
    with a black background and no gizmos, a silhouette pixel is strictly between 0 and the
    surface; the deferred values equal the forward ones there (lit per sample in both)."""
    for r in render_pair.values():
        r.show_background = False
        r.show_gizmos = False
    try:
        a, b = _both(render_pair, compile_document(flat_material(roughness=0.2)))
    finally:
        for r in render_pair.values():
            r.show_background = r.show_gizmos = True
    lum = b.sum(axis=2)
    inside = lum > 0
    edge = inside & ~(np.roll(inside, 1, 0) & np.roll(inside, -1, 0) & np.roll(inside, 1, 1)
                      & np.roll(inside, -1, 1))
    assert edge.sum() > 20
    # partial coverage: many silhouette pixels far darker than the surface beside them
    dark = lum[edge] < 0.6 * np.median(lum[inside & ~edge])
    assert dark.sum() > 10
    assert _rel(a, b)[edge].max() <= REL
    assert _rel(a, b)[inside & ~edge].max() <= REL_PIXEL
    assert _rel(a, b)[inside & ~edge].mean() <= REL_MEAN


def test_energy_compensation_and_gizmos_match(render_pair):
    for r in render_pair.values():
        r.set_energy_compensation(True)
    try:
        a, b = _both(render_pair, compile_document(flat_material(roughness=0.9)))
    finally:
        for r in render_pair.values():
            r.set_energy_compensation(False)
    assert _rel(a, b).max() <= REL_PIXEL
    assert _rel(a, b).mean() <= REL_MEAN


# --- programs ---------------------------------------------------------------------------------

def test_a_structural_edit_links_only_the_gbuffer_program(render_pair):
    r = render_pair["deferred"]
    r.mode = "splitsum"
    r.set_material(compile_document(flat_material(roughness=0.3)))
    r.render()
    lighting, links = r.lighting.link_count, r.link_count
    d = flat_material(roughness=0.3)
    node(d, "extra", "scalar_parameter", {"name": "metal"}, {"value": 0.5})
    link(d, "extra", "value", "make", "metallic")
    r.set_material(compile_document(d))
    r.render()
    assert r.link_count == links + 1
    assert r.lighting.link_count == lighting  # the lighting program is shared
    prog = r._program
    linked = [k for k, p in r._programs.items() if p is prog]
    assert linked == [compile_document(d).variant(Entry.GBUFFER, PREVIEW_DEFINES).structure_hash]


def test_translucent_materials_fall_back_to_forward_and_back(render_pair):
    cm = compile_document(flat_material(opacity=1.0))
    assert not may_be_translucent(cm.ir)
    assert may_be_translucent(cm.ir, {"p_alpha": 0.5})
    r = render_pair["deferred"]
    r.mode = "splitsum"
    r.set_material(cm)
    assert not r.is_forward
    r.set_uniforms({"p_alpha": 0.5})
    assert r.is_forward
    r.render()
    a = r.read_linear().copy()
    f = render_pair["forward"]
    f.mode = "splitsum"
    f.set_material(cm)
    f.set_uniforms({"p_alpha": 0.5})
    f.render()
    assert np.array_equal(a, f.read_linear())
    links = r.link_count
    r.set_uniforms({"p_alpha": 1.0})
    assert not r.is_forward and r.link_count == links  # both programs kept
    translucent = compile_document(flat_material(opacity=0.5))
    r.set_material(translucent)
    assert r.is_forward


def test_render_command_uses_the_deferred_path(gl_ctx):
    """`matedit render` builds its renderer through commands.render._renderer with the
    defaults: the deferred preview (4 samples where GL has them; with 1 sample, forward). Its
    image equals the forward path's by the tests above."""
    from matedit.commands.render import _renderer

    r = _renderer(gl_ctx, (48, 48), Renderer)
    try:
        assert r.deferred == (r.samples >= 2)
        talk_only = graphs_dir() / "materials" / "worn_painted_steel.json"  # writes no lobe
        r.set_material(compile_document(load(talk_only), FileResolver()))
        assert r.is_forward == (not r.deferred)
    finally:
        r.release()
