"""Texture colour spaces: an sRGB texture is decoded to linear before filtering, the same way
in the preview renderer, the CPU evaluator and the node thumbnails.

The expected values are written here from IEC 61966-2-1, not taken from matedit:
sRGB code 128 is ((128/255 + 0.055) / 1.055) ** 2.4 = 0.21586 linear.
"""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest
from graphs_util import link, material, node

from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.io.document import FileResolver

CODE_128 = ((128 / 255 + 0.055) / 1.055) ** 2.4  # 0.215861
TOL = 1e-3


def _srgb_to_linear(c):
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def write_png(path, codes: np.ndarray) -> None:
    h, w, c = codes.shape
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(w, h, c, "uint8"))
    assert out.write_image(np.ascontiguousarray(codes, np.uint8))
    out.close()


def texture_material(tmp_path, settings: dict):
    """Texture sample -> emissive, black base: with no lights and no environment the frame is
    the texture's linear value."""
    d = material(tmp_path / "m.json")
    node(d, "tex", "texture_parameter", {"name": "albedo", **settings})
    node(d, "uv", "texcoord")
    node(d, "s", "texture_sample")
    node(d, "make", "make_attributes", values={"baseColor": [0.0, 0.0, 0.0], "metallic": 0.0,
                                                "roughness": 1.0})
    node(d, "out", "material_output")
    link(d, "tex", "texture", "s", "texture")
    link(d, "uv", "uv", "s", "uv")
    link(d, "s", "rgb", "make", "emissive")
    link(d, "make", "attributes", "out", "attributes")
    return d


@pytest.fixture
def grey128(tmp_path):
    p = tmp_path / "grey128.png"
    write_png(p, np.full((8, 8, 3), 128, np.uint8))
    return p


class _Surface:
    def __init__(self, n=16):
        rng = np.random.default_rng(3)
        self.uv = rng.uniform(0, 1, (n, 2))
        self.position = np.zeros((n, 3))
        self.normal = np.tile([0.0, 0.0, 1.0], (n, 1))
        self.view = self.normal.copy()
        self.time = 0.0


def _cpu_emissive(tmp_path, settings):
    from matedit.compiler.cpu_nodes import SurfaceArrays

    s = _Surface()
    surface = SurfaceArrays(s.uv, s.position, s.normal, s.view, 0.0)
    ir = lower_document(texture_material(tmp_path, settings), FileResolver())
    return np.asarray(evaluate(ir, surface)["emissive"])


def test_cpu_evaluator_decodes_srgb_128(tmp_path, grey128):
    e = _cpu_emissive(tmp_path, {"path": grey128.name})
    assert np.allclose(e, CODE_128, atol=TOL), e[:2]
    lin = _cpu_emissive(tmp_path, {"path": grey128.name, "srgb": False})
    assert np.allclose(lin, 128 / 255, atol=1e-6)  # a data texture stays as stored
    explicit = _cpu_emissive(tmp_path, {"path": grey128.name, "color_space": "linear"})
    assert np.allclose(explicit, 128 / 255, atol=1e-6)


def test_ocio_space_through_openimageio(tmp_path, grey128):
    # "sRGB Encoded Rec.709 (sRGB)" of the built-in config is the sRGB curve: same as srgb.
    e = _cpu_emissive(tmp_path, {"path": grey128.name,
                                 "color_space": "sRGB Encoded Rec.709 (sRGB)"})
    assert np.allclose(e, CODE_128, atol=TOL)
    # ACEScg to linear Rec.709 mixes channels: a pure ACEScg red gains negative G and B.
    p = tmp_path / "red.png"
    write_png(p, np.tile(np.array([255, 0, 0], np.uint8), (4, 4, 1)))
    red = _cpu_emissive(tmp_path, {"path": p.name, "color_space": "ACEScg"})
    # AP1 -> Rec.709 matrix row sums (first column): R ~ 1.705, G ~ -0.130, B ~ -0.024
    assert red[0, 0] == pytest.approx(1.705, abs=0.01)
    assert red[0, 1] == pytest.approx(-0.130, abs=0.01)


def test_unknown_space_is_a_clear_error():
    from matedit.shading.colorspace import ColorSpaceError, check_space

    with pytest.raises(ColorSpaceError, match="unknown colour space 'nope'"):
        check_space("nope")


def test_linear_mips_of_an_srgb_checker():
    """A black/white sRGB checker averages to 0.5 linear in its mips (not to code 128 =
    0.216, which filtering the encoded values would give)."""
    from matedit.shading.colorspace import decode, mip_chain

    codes = (np.add.outer(np.arange(8), np.arange(8)) % 2 * 255).astype(np.float32) / 255
    img = decode(np.repeat(codes[:, :, None], 3, axis=2), True, "srgb")
    levels = mip_chain(img)
    assert [lv.shape[0] for lv in levels] == [8, 4, 2, 1]
    for lv in levels[1:]:
        assert np.allclose(lv[..., :3], 0.5, atol=1e-6)
    odd = mip_chain(np.ones((5, 3, 4), np.float32))  # GL sizes: floor(n / 2), at least 1
    assert [lv.shape[:2] for lv in odd] == [(5, 3), (2, 1), (1, 1)]
    assert all(np.allclose(lv, 1.0) for lv in odd)


@pytest.mark.gl
def test_preview_renderer_samples_srgb_128_as_linear(gl_ctx, tmp_path, grey128):
    from matedit.compiler import compile_document
    from matedit.render import Renderer

    # a mip-level test too: a checker, seen so small that the GPU reads its last mips
    check = tmp_path / "check.png"
    codes = (np.add.outer(np.arange(64), np.arange(64)) % 2 * 255).astype(np.uint8)
    write_png(check, np.repeat(codes[:, :, None], 3, axis=2))
    r = Renderer(gl_ctx, (32, 32), samples=0, environment=None)  # no partly covered pixels
    try:
        r.set_lights([])
        r.show_gizmos = False
        r.show_background = False
        r.set_mesh("plane")
        r.camera.pitch, r.camera.distance = 89.0, 2.5  # looking down on the plane
        compiled = compile_document(texture_material(tmp_path, {"path": grey128.name}),
                                    FileResolver(), "glsl330")
        assert r.set_material(compiled).ok
        r.render()
        hdr = r.read_hdr()
        covered = hdr[hdr.sum(axis=2) > 0]
        assert covered.shape[0] > 500
        # GL decodes the sRGB internal format; llvmpipe's decode measures 0.21664 (its
        # polynomial approximation, 7.8e-4 from the exact 0.21586)
        assert np.allclose(covered, CODE_128, atol=TOL), covered.mean(axis=0)
        # the same texture marked linear: stored values
        r.set_texture("t_albedo", str(grey128), "linear")
        r.render()
        covered = r.read_hdr()
        covered = covered[covered.sum(axis=2) > 0]
        assert np.allclose(covered, 128 / 255, atol=TOL)
        # checker minified (the plane is a few pixels wide from far away): linear mips give
        # 0.5, filtering the encoded codes would give 0.216
        r.set_texture("t_albedo", str(check), "srgb")
        r.camera.distance = 50.0
        r.render()
        far = r.read_hdr()
        far = far[far.sum(axis=2) > 0]
        assert far.size > 0
        assert np.allclose(far.mean(axis=0), 0.5, atol=0.03), far.mean(axis=0)
    finally:
        r.release()


@pytest.mark.gui
def test_thumbnail_decodes_srgb_like_the_evaluator(qtbot, tmp_path, grey128):
    """The texture sample's thumbnail reads 0.2158 linear, shown (sRGB-encoded) as code 128."""
    from matedit.app.previews import preview_sphere, to_image

    ir = lower_document(texture_material(tmp_path, {"path": grey128.name}), FileResolver())
    probe: dict = {}
    surface, inside = preview_sphere()
    evaluate(ir, surface, probe=probe)
    value = np.asarray(probe["s.rgb"])[inside]
    assert np.allclose(value, CODE_128, atol=TOL)
    img = to_image(probe["s.rgb"], inside)
    px = img.pixelColor(img.width() // 2, img.height() // 2)
    assert abs(px.red() - 128) <= 1 and abs(px.green() - 128) <= 1
    assert _srgb_to_linear(px.red() / 255) == pytest.approx(CODE_128, abs=2e-3)
