"""The viewport's views (matedit.shading.views): lobe views shade with a MATEDIT_LOBES mask,
attribute views draw a field in place of the shading (FORWARD entry), `lit` is the default
program byte for byte. Checked on the fields and the masks, not on what the lobes look like
(their shading is the lobes' own tests'): the lobe views add up to lit, and an attribute view
reads the field's value in the linear image."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.commands.render import VIEW_NAMES
from matedit.compiler import compile_document
from matedit.compiler.emit import Entry, entry_text
from matedit.ibl import BakeSettings
from matedit.io.document import FileResolver, load, save
from matedit.render import Renderer
from matedit.resources import graphs_dir
from matedit.shading.views import ATTRIBUTE_VIEWS, VIEWS, lobe_mask, view_defines

SMALL = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
SIZE = (48, 48)
OAK = graphs_dir() / "materials" / "varnished_oak.json"


def plain(roughness=0.3, coat=None, emissive=(0.0, 0.0, 0.0), film=None):
    """A talk material (a constant one, so that every mesh pixel reads the same field)."""
    d = material()
    values = {"baseColor": [0.7, 0.4, 0.2], "metallic": 0.0, "roughness": roughness,
              "emissive": list(emissive)}
    if coat is not None:
        values |= {"coat": coat, "coatRoughness": 0.1}
    if film is not None:
        values |= {"thinFilmThickness": film}
    node(d, "make", "make_attributes", values=values)
    node(d, "out", "material_output")
    link(d, "make", "attributes", "out", "attributes")
    return d


@pytest.fixture(scope="module")
def renderer(gl_ctx):
    r = Renderer(gl_ctx, SIZE, samples=4, environment="studio", bake_settings=SMALL)
    r.show_background = False  # black behind the mesh: views add up where it is not drawn
    r.show_gizmos = False
    yield r
    r.release()


def _interior(mask: np.ndarray, k: int = 2) -> np.ndarray:
    """The mask less a border of k pixels (edge pixels are partly covered: MSAA averages)."""
    out = mask.copy()
    for dy in range(-k, k + 1):
        for dx in range(-k, k + 1):
            out &= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    return out


def _frame(r: Renderer, view: str) -> np.ndarray:
    r.set_view(view)
    r.render()
    return r.read_linear().astype(np.float64)


def test_the_views_and_the_cli_agree():
    assert tuple(VIEWS) == VIEW_NAMES
    assert set(ATTRIBUTE_VIEWS) == {"roughness", "normal", "coat-weight", "anisotropy",
                                    "thin-film"}
    assert lobe_mask("base") == 1 | 2 and lobe_mask("specular") == 2 | 4
    assert lobe_mask("coat") == 4 and lobe_mask("sheen") == 8 and lobe_mask("lit") == 127
    assert lobe_mask("subsurface") == 32 and lobe_mask("transmission") == 64


def test_lit_is_the_default_program_byte_for_byte():
    cm = compile_document(load(OAK), FileResolver())
    assert view_defines("lit") == ()
    assert cm.variant(Entry.FORWARD, view_defines("lit")).fragment_text == cm.fragment_text
    # the attribute view's block is not in the default text (nor its library file)
    assert "MATEDIT_ATTRIBUTE_VIEW" not in cm.fragment_text
    assert "attributeView" not in cm.fragment_text
    assert "MATEDIT_ATTRIBUTE_VIEW" not in entry_text(Entry.FORWARD)
    view = cm.variant(Entry.FORWARD, view_defines("roughness"))
    assert "#define MATEDIT_ATTRIBUTE_VIEW 1" in view.fragment_text
    assert "attributeView(MATEDIT_ATTRIBUTE_VIEW" in view.fragment_text
    coat = cm.variant(Entry.FORWARD, view_defines("coat"))
    assert "#define MATEDIT_LOBES 4" in coat.fragment_text
    with pytest.raises(ValueError, match="not a define name"):
        cm.variant(Entry.FORWARD, ("MATEDIT_LOBES=4 void",))


@pytest.mark.parametrize("deferred", [False, True], ids=["forward", "deferred"])
def test_lobe_views_add_up_to_lit_for_the_talks_material(gl_ctx, deferred):
    """base (diffuse + specular) + coat + sheen + emissive = lit. Emissive has no view of its
    own: it is lit - base on a material with no coat or sheen, and equals its emissive."""
    r = Renderer(gl_ctx, SIZE, samples=4, environment="studio", bake_settings=SMALL,
                 deferred=deferred)
    r.show_background = r.show_gizmos = False
    try:
        emissive = (0.25, 0.5, 0.125)
        assert r.set_material(compile_document(plain(0.4, emissive=emissive))).ok
        assert r.is_forward is not deferred  # a talk material keeps its path in every view
        frames = {v: _frame(r, v) for v in ("lit", "base", "coat", "sheen", "specular")}
        assert r.is_forward is not deferred
        mesh = _interior(frames["lit"].max(axis=-1) > 0.3)  # pixels the sphere covers fully
        assert mesh.sum() > 200
        # float32 sums of the same terms in another order, and 4x MSAA resolves of each:
        # 1e-5 relative to the lit value (above 0.3 here)
        np.testing.assert_allclose(frames["coat"], 0.0, atol=1e-7)  # no coat, no sheen
        np.testing.assert_allclose(frames["sheen"], 0.0, atol=1e-7)
        glow = frames["lit"] - frames["base"] - frames["coat"] - frames["sheen"]
        np.testing.assert_allclose(glow[mesh], np.broadcast_to(emissive, glow[mesh].shape),
                                   rtol=0, atol=1e-5 * frames["lit"][mesh].max())
        # specular only is the base's specular: below base (diffuse and specular) everywhere
        assert np.all(frames["specular"] <= frames["base"] + 1e-6)
        assert frames["specular"][mesh].mean() < 0.8 * frames["base"][mesh].mean()
        r.set_view("roughness")
        assert r.is_forward  # an attribute view draws the FORWARD entry
        r.set_view("lit")
        assert r.is_forward is not deferred  # and lit is back on the material's own path
    finally:
        r.release()


def test_lobe_views_add_up_to_lit_for_a_coated_material(renderer):
    """Varnished oak (forward: it writes coat fields): base + coat + sheen = lit (no emissive)
    whatever the coat's lobe computes, since each view masks the same sum's terms."""
    r = renderer
    assert r.set_material(compile_document(load(OAK), FileResolver())).ok
    frames = {v: _frame(r, v) for v in ("lit", "base", "coat", "sheen", "specular")}
    assert r.is_forward
    total = frames["base"] + frames["coat"] + frames["sheen"]
    # float32 sums of the same terms in another order: 1e-5 of the brightest lit value
    np.testing.assert_allclose(total, frames["lit"], rtol=0,
                               atol=1e-5 * frames["lit"].max())
    r.set_view("lit")


@pytest.mark.parametrize("deferred", [True, False], ids=["deferred", "forward"])
def test_roughness_and_coat_weight_views_read_the_field_linear(gl_ctx, deferred):
    r = Renderer(gl_ctx, SIZE, samples=4, environment="studio", bake_settings=SMALL,
                 deferred=deferred)
    r.show_background = r.show_gizmos = False
    try:
        assert r.set_material(compile_document(plain(0.3, coat=0.7, film=640.0))).ok
        _frame(r, "lit")
        # the centre of the sphere is covered by every sample: the field exactly, in float32
        rough = _frame(r, "roughness")
        assert r.is_forward  # an attribute view draws the FORWARD entry
        c = SIZE[0] // 2
        np.testing.assert_allclose(rough[c, c], 0.3, rtol=0, atol=1e-6)
        np.testing.assert_allclose(_frame(r, "coat-weight")[c, c], 0.7, rtol=0, atol=1e-6)
        # the thin film's 640 nm in micrometres
        np.testing.assert_allclose(_frame(r, "thin-film")[c, c], 0.64, rtol=0, atol=1e-6)
        normal = _frame(r, "normal")
        n = 2.0 * normal[c, c] - 1.0  # the sphere's centre faces the camera: |n| = 1
        assert abs(np.linalg.norm(n) - 1.0) < 1e-3
        # The default direction is the mesh tangent (the sphere's u, around it): lines along
        # the latitudes. Down the centre column they alternate with the dimmed surface;
        # along the equator's row (one latitude) they do not.
        # (160 pixels: a stripe a few pixels wide; the middle fifth, where the camera's
        # elevation bends the latitudes least)
        r.resize(160, 160)
        stripes = _frame(r, "anisotropy").mean(axis=-1)
        mid = slice(64, 96)
        col, row = stripes[mid, 80], stripes[80, mid]
        assert col.max() - col.min() > 0.2, col
        assert row.std() < 0.25 * col.std(), (row.std(), col.std())
        r.resize(*SIZE)
        _frame(r, "lit")
        assert r.is_forward  # it writes a coat: forward in lit too
    finally:
        r.release()


def test_unknown_view_is_refused(renderer):
    with pytest.raises(ValueError, match="unknown view"):
        renderer.set_view("wireframe")


def test_render_command_view_writes_the_field(tmp_path):
    from matedit.io.images import read_image

    src = tmp_path / "m.json"
    save(plain(0.3), src)
    out = tmp_path / "r.exr"
    r = subprocess.run([sys.executable, "-m", "matedit", "render", str(src), "-o", str(out),
                        "--size", "32x32", "--view", "roughness"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    px = read_image(out).pixels
    np.testing.assert_allclose(px[16, 16, :3], 0.3, atol=1e-6)  # linear EXR: the value
    r = subprocess.run([sys.executable, "-m", "matedit", "render", str(src), "-o", str(out),
                        "--view", "bogus"], capture_output=True, text=True)
    assert r.returncode == 2 and "--view" in r.stderr
