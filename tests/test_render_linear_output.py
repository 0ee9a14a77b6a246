"""`matedit render` linear output: .exr is the scene-referred frame, .png its display
transform; `--lights none|RIG.json`; `--samples`; the white furnace through the command line.

The references here are written in numpy from the formulas (docs/shading.md#display, Karis 2013, IEC
61966-2-1, Narkowicz 2015); nothing is imported from matedit.shading.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from graphs_util import link, material, node

from matedit.io.document import dumps
from matedit.io.images import read_image, write_image
from matedit.render.camera import OrbitCamera
from matedit.resources import graphs_dir

SAMPLE = graphs_dir() / "materials" / "brushed_gold.json"


def run(*args):
    return subprocess.run([sys.executable, "-m", "matedit", "render", *map(str, args)],
                          capture_output=True, text=True, env=dict(os.environ))


def white_metal(path, roughness: float, compensation: bool | None = None):
    d = material(path)
    node(d, "make", "make_attributes", values={"baseColor": [1.0, 1.0, 1.0], "metallic": 1.0,
                                                "roughness": roughness})
    node(d, "out", "material_output")
    link(d, "make", "attributes", "out", "attributes")
    path.write_text(dumps(d))
    return path


def display(hdr, ev):
    """2^EV, the ACES fit (Narkowicz 2015), sRGB encode (IEC 61966-2-1)."""
    x = np.maximum(hdr * 2.0 ** ev, 0.0)
    t = np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0, 1)
    return np.where(t <= 0.0031308, 12.92 * t, 1.055 * t ** (1 / 2.4) - 0.055)


def test_exr_is_the_linear_frame_and_png_its_display_transform(gl_ctx, tmp_path):
    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer

    exr, png = tmp_path / "f.exr", tmp_path / "f.png"
    for out in (exr, png):
        r = run(SAMPLE, "-o", out, "--size", "40x32", "--exposure", "0.25", "--env", "sky")
        assert r.returncode == 0, r.stderr
    linear = read_image(exr).pixels
    assert linear.shape == (32, 40, 4) and np.all(linear[..., 3] == 1.0)
    assert linear[..., :3].max() > 1.0  # HDR survives: not display-referred
    # the same frame, drawn in this process
    rend = Renderer(gl_ctx, (40, 32), environment=None)
    try:
        rend.set_environment("sky")
        assert rend.set_material(compile_document(load(SAMPLE), FileResolver(), "glsl330")).ok
        rend.exposure = 0.25
        rend.render()
        frame = rend.read_linear()
    finally:
        rend.release()
    assert np.array_equal(linear[..., :3], frame)  # float32 EXR: bit for bit
    shown = read_image(png).pixels[..., :3]
    expected = display(linear[..., :3].astype(np.float64), 0.25)
    # PNG codes round the GPU's display pass: at most one code apart
    assert np.abs(shown - expected).max() <= 1.0 / 255 + 1e-6


def test_half_exr(tmp_path):
    out = tmp_path / "h.exr"
    r = run(SAMPLE, "-o", out, "--size", "16x16", "--half")
    assert r.returncode == 0, r.stderr
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(out))
    assert inp.spec().format == oiio.HALF and inp.spec().nchannels == 4
    inp.close()


# --- the white furnace through the command line --------------------------------------------


def env_brdf_white(nov: np.ndarray, roughness: float, ny=4096, nphi=64) -> np.ndarray:
    """A + B for F0 = 1: the specular integral of a white metal under a constant white
    environment, with G Schlick-Smith k = a / 2, by a midpoint quadrature in the GGX
    half-vector CDF variables (y, phi): the integrand is then G VoH / (NoH NoV)."""
    a = roughness * roughness
    k = a / 2
    y = (np.arange(ny) + 0.5) / ny
    phi = (np.arange(nphi) + 0.5) / nphi * 2 * np.pi
    cos_h = np.sqrt((1 - y) / (1 + (a * a - 1) * y))
    sin_h = np.sqrt(1 - cos_h ** 2)
    hx = sin_h[:, None] * np.cos(phi)[None, :]
    hz = np.broadcast_to(cos_h[:, None], hx.shape)
    out = np.empty(len(nov))
    for i, c in enumerate(nov):
        vx, vz = math.sqrt(max(0.0, 1 - c * c)), c
        voh = vx * hx + vz * hz
        nol = 2 * voh * hz - vz
        ok = nol > 0
        g = (nol / (nol * (1 - k) + k)) * (c / (c * (1 - k) + k))
        w = np.where(ok, g * voh / (hz * c), 0.0)
        out[i] = w.mean()
    return out


def sphere_nov(width: int, height: int):
    """N.V per pixel (top row first) of the unit sphere under the default orbit camera, by
    ray casting through pixel centres; NaN off the sphere."""
    cam = OrbitCamera()
    vp = cam.projection(width / height) @ cam.view_matrix()
    inv = np.linalg.inv(vp)
    j, i = np.mgrid[0:height, 0:width]
    ndc = np.stack([(i + 0.5) / width * 2 - 1, 1 - (j + 0.5) / height * 2], axis=-1)
    far = np.concatenate([ndc, np.ones(ndc.shape[:2] + (1,)), np.ones(ndc.shape[:2] + (1,))],
                         axis=-1) @ inv.T
    far = far[..., :3] / far[..., 3:]
    eye = cam.eye
    d = far - eye
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ eye
    disc = b * b - (eye @ eye - 1.0)
    t = -b - np.sqrt(np.where(disc > 0, disc, np.nan))
    p = eye + t[..., None] * d
    return np.sum(p * -d, axis=-1)  # N = p on the unit sphere, V = -d


@pytest.mark.parametrize("roughness", [0.3, 0.9])
def test_white_metal_furnace_matches_integrated_a_plus_b(tmp_path, roughness):
    env = tmp_path / "constant-white.exr"
    write_image(env, np.ones((32, 64, 3), np.float32))
    mat = white_metal(tmp_path / "white.json", roughness)
    w = h = 48
    nov = sphere_nov(w, h)
    inside = np.isfinite(nov)
    for _ in range(2):  # two pixels away from the silhouette, where MSAA mixes in background
        inside = inside & np.roll(inside, 1, 0) & np.roll(inside, -1, 0) \
            & np.roll(inside, 1, 1) & np.roll(inside, -1, 1)
    assert nov[inside].min() < 0.45  # grazing angles are in
    ref_nov = np.linspace(0.05, 1.0, 39)
    ref = np.interp(nov[inside], ref_nov, env_brdf_white(ref_nov, roughness))
    results = {}
    for mode in ("reference", "splitsum"):
        out = tmp_path / f"{mode}.exr"
        r = run(mat, "-o", out, "--lights", "none", "--env", env, "--size", f"{w}x{h}",
                "--ibl", mode, "--samples", "4096")
        assert r.returncode == 0, r.stderr
        img = read_image(out).pixels[..., 0]
        results[mode] = img[inside]
        # off the sphere: the white background
        assert np.allclose(img[~np.isfinite(nov)][:50], 1.0, atol=1e-6)
    # reference mode: 4,096 Hammersley samples a pixel, rotated per frame (measured max error
    # ~1e-3; 1,024 samples give ~6e-3); the tessellated sphere's normals move NoV ~1e-3
    assert np.abs(results["reference"] - ref).max() < 3e-3, \
        np.abs(results["reference"] - ref).max()
    # split sum: the baked LUT's bilinear lookup and the prefiltered constant (1); measured
    # max ~7e-4
    assert np.abs(results["splitsum"] - ref).max() < 2e-3, np.abs(results["splitsum"] - ref).max()
    if roughness == 0.9:
        assert results["splitsum"].min() < 0.6  # the loss the compensation addresses


# --- --lights and --samples ----------------------------------------------------------------


def test_lights_none_and_a_rig_file(tmp_path):
    mat = white_metal(tmp_path / "m.json", 0.5)
    black = tmp_path / "black.exr"
    write_image(black, np.zeros((16, 32, 3), np.float32))
    none = tmp_path / "none.exr"
    r = run(mat, "-o", none, "--lights", "none", "--env", black, "--size", "24x24")
    assert r.returncode == 0, r.stderr
    assert np.abs(read_image(none).pixels[..., :3]).max() == 0.0  # nothing lights it
    rig = tmp_path / "rig.json"
    rig.write_text(json.dumps({"format": "matedit.lightrig", "version": 1, "lights": [
        {"type": "directional", "direction": [0, 0, -1], "intensity": 2.0}]}))
    lit = tmp_path / "lit.exr"
    r = run(mat, "-o", lit, "--lights", rig, "--env", black, "--size", "24x24")
    assert r.returncode == 0, r.stderr
    assert read_image(lit).pixels[..., :3].max() > 0.1
    default = tmp_path / "default.exr"
    assert run(mat, "-o", default, "--env", black, "--size", "24x24").returncode == 0
    assert not np.array_equal(read_image(default).pixels, read_image(lit).pixels)


@pytest.mark.parametrize("rig, needle", [
    ({"format": "matedit.lightrig", "version": 1, "lights": [{"type": "spot"}]},
     "light 0, field type"),
    ({"format": "matedit.lightrig", "version": 1,
      "lights": [{"type": "point"}, {"type": "sphere", "radius": -1}]}, "light 1, field radius"),
    ({"format": "matedit.lightrig", "version": 1,
      "lights": [{"type": "tube", "colour": [1, 1, 1]}]}, "light 0, field colour"),
    ({"format": "matedit.lightrig", "version": 9, "lights": []}, "field version"),
    ({"format": "matedit.material", "version": 1}, "not a light rig"),
])
def test_bad_rig_exits_2_naming_file_light_field(tmp_path, rig, needle):
    p = tmp_path / "rig.json"
    p.write_text(json.dumps(rig))
    r = run(SAMPLE, "-o", tmp_path / "x.png", "--lights", p, "--size", "8x8")
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {p}: ") and needle in lines[0], \
        r.stderr


def test_bad_options_exit_2(tmp_path):
    for args, needle in ((["--samples", "0"], "--samples"), (["--lights", "nope.json"],
                                                             "nope.json")):
        r = run(SAMPLE, "-o", tmp_path / "x.png", *args)
        assert r.returncode == 2 and needle in r.stderr and r.stderr.count("\n") == 1, r.stderr
    r = run(SAMPLE, "-o", tmp_path / "x.tif")
    assert r.returncode == 2 and ".exr" in r.stderr
    env = tmp_path / "env.exr"
    write_image(env, np.ones((8, 16, 3), np.float32))
    before = env.read_bytes()
    r = run(SAMPLE, "-o", env, "--env", env)  # never overwrite an input
    assert r.returncode == 2 and env.read_bytes() == before


def test_rig_round_trip(tmp_path):
    from matedit.io import rig as rigio
    from matedit.render.lights import default_rig

    p = tmp_path / "r.json"
    rigio.save(default_rig(), p)
    back = rigio.load(p)
    assert len(back) == 3
    for a, b in zip(default_rig(), back):
        assert a.kind == b.kind and np.allclose(a.position, b.position)
        assert a.source_radius == pytest.approx(b.source_radius)
        assert a.source_length == pytest.approx(b.source_length)
        assert a.intensity == b.intensity and np.allclose(a.color, b.color)


# --- multiple-scattering compensation -----------------------------------------------------


@pytest.mark.parametrize("roughness", [0.2, 0.6, 1.0])
def test_compensated_white_metal_furnace_at_least_097(tmp_path, roughness):
    env = tmp_path / "constant-white.exr"
    write_image(env, np.ones((32, 64, 3), np.float32))
    mat = white_metal(tmp_path / "white.json", roughness)
    w = h = 40
    nov = sphere_nov(w, h)
    inside = np.isfinite(nov)
    for _ in range(2):
        inside = inside & np.roll(inside, 1, 0) & np.roll(inside, -1, 0) \
            & np.roll(inside, 1, 1) & np.roll(inside, -1, 1)
    for mode, extra in (("splitsum", []), ("reference", ["--samples", "1024"])):
        out = tmp_path / f"{mode}.exr"
        r = run(mat, "-o", out, "--lights", "none", "--env", env, "--size", f"{w}x{h}",
                "--ibl", mode, "--energy-compensation", *extra)
        assert r.returncode == 0, r.stderr
        v = read_image(out).pixels[..., 0][inside]
        # F0 = 1: single + multiple scattering = 1 exactly in the split sum; the reference's
        # own noise at 1,024 samples is ~6e-3
        assert v.min() >= 0.97, (mode, v.min())
        assert v.max() <= 1.0 + (1e-4 if mode == "splitsum" else 1e-2), (mode, v.max())
    # the uncompensated image of the same material loses energy at high roughness
    out = tmp_path / "plain.exr"
    assert run(mat, "-o", out, "--lights", "none", "--env", env, "--size", f"{w}x{h}"
               ).returncode == 0
    plain = read_image(out).pixels[..., 0][inside]
    if roughness >= 0.6:
        assert plain.min() < 0.9


def test_material_option_reaches_the_exported_shader(tmp_path):
    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver, load

    mat = white_metal(tmp_path / "m.json", 0.5)
    doc = load(mat)
    assert "#define MATEDIT_ENERGY_COMPENSATION" not in \
        compile_document(doc, FileResolver(), "glsl330").fragment_text
    doc.preview = {"energy_compensation": True}
    exe = shutil.which("glslangValidator")
    for target in ("glsl330", "glsl450", "essl300"):
        frag = compile_document(doc, FileResolver(), target).fragment_text
        assert "#define MATEDIT_ENERGY_COMPENSATION 1" in frag
        assert "#ifdef MATEDIT_ENERGY_COMPENSATION" in frag
        if exe is not None:  # the compensated shader compiles for every target
            src = tmp_path / f"m.{target}.frag"
            src.write_text(frag)
            args = [exe, str(src)] + (["-V", "-o", str(tmp_path / "m.spv")]
                                      if target == "glsl450" else [])
            run_ = subprocess.run(args, capture_output=True, text=True)
            assert run_.returncode == 0, run_.stdout[-2000:]


def test_energy_compensation_twin(ctx):
    """ibl.glsl's energyCompensation against its numpy twin and against the formulas."""
    from gpu_eval import gpu_eval_many

    from matedit.shading.ibl import energyCompensation

    rng = np.random.default_rng(5)
    n = 512
    f0 = rng.uniform(0, 1, (n, 3)).astype(np.float32)
    ab = np.stack([rng.uniform(0.0, 0.9, n), rng.uniform(0.0, 0.1, n)], 1).astype(np.float32)
    out = gpu_eval_many(ctx, "energyCompensation(F0, AB, s, d);", {"F0": f0, "AB": ab},
                        {"s": "vec3", "d": "vec3"}, includes=["ibl.glsl"])
    s, d = energyCompensation(f0.astype(np.float64), ab.astype(np.float64))
    assert np.allclose(out["s"], s, rtol=1e-4, atol=1e-5)
    assert np.allclose(out["d"], d, rtol=1e-4, atol=1e-5)
    # formulas: F0 = 1 makes single + multiple scattering exactly 1
    s1, d1 = energyCompensation(np.ones((n, 3)), ab.astype(np.float64))
    ess = (ab[:, 0] + ab[:, 1]).astype(np.float64)
    assert np.allclose(s1[:, 0] * ess, 1.0, atol=1e-9) and np.allclose(d1, 0.0, atol=1e-9)


def test_compensated_white_dielectric_furnace_is_one(tmp_path):
    """Without compensation the talk's white dielectric reflects more than it receives at
    grazing angles (diffuse not reduced by the specular); with it, diffuse keeps what the
    specular leaves: the split sum returns 1 (SH irradiance of a constant is exact)."""
    env = tmp_path / "constant-white.exr"
    write_image(env, np.ones((32, 64, 3), np.float32))
    d = material(tmp_path / "dielectric.json")
    node(d, "make", "make_attributes", values={"baseColor": [1.0, 1.0, 1.0], "metallic": 0.0,
                                                "roughness": 0.5})
    node(d, "out", "material_output")
    link(d, "make", "attributes", "out", "attributes")
    mat = tmp_path / "dielectric.json"
    mat.write_text(dumps(d))
    inside = np.isfinite(sphere_nov(40, 40))
    for _ in range(2):
        inside = inside & np.roll(inside, 1, 0) & np.roll(inside, -1, 0) \
            & np.roll(inside, 1, 1) & np.roll(inside, -1, 1)
    values = {}
    for flag in ([], ["--energy-compensation"]):
        out = tmp_path / f"d{len(flag)}.exr"
        r = run(mat, "-o", out, "--lights", "none", "--env", env, "--size", "40x40", *flag)
        assert r.returncode == 0, r.stderr
        values[bool(flag)] = read_image(out).pixels[..., 0][inside]
    assert values[False].min() > 1.03  # more than 1 everywhere (1.44 at grazing angles)
    assert np.abs(values[True] - 1.0).max() < 2e-3, np.abs(values[True] - 1.0).max()
