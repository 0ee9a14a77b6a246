"""`matedit bake-ibl` and `matedit brdf-lut` (docs/cli.md, the command line contract)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from matedit.cli import main
from matedit.io.images import read_image, write_image


def run_cli(*args, cache_dir):
    env = dict(os.environ, MATEDIT_CACHE_DIR=str(cache_dir))
    return subprocess.run(
        [sys.executable, "-m", "matedit", *map(str, args)],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )


def ggx_lut_cell(nov: float, roughness: float, n: int = 1024) -> np.ndarray:
    """(A, B) at one cell by a plain midpoint rule over the GGX sampling square (Xi in [0,1)^2).

    Independent of the baker's quadrature; at these cells 1024^2 points agree with it to 1e-4.
    """
    a = roughness * roughness
    k = a / 2
    x = (np.arange(n) + 0.5) / n
    phi = 2 * np.pi * x[:, None]
    cos_t = np.sqrt((1 - x[None, :]) / (1 + (a * a - 1) * x[None, :]))
    sin_t = np.sqrt(1 - cos_t * cos_t)
    voh = np.sqrt(1 - nov * nov) * sin_t * np.cos(phi) + nov * cos_t
    nol = 2 * voh * cos_t - nov
    nol_c = np.maximum(nol, 0)
    g = nol_c / (nol_c * (1 - k) + k) * nov / (nov * (1 - k) + k)
    gvis = np.where(nol > 0, g * voh / (cos_t * nov), 0)
    fc = (1 - voh) ** 5
    return np.array([np.mean((1 - fc) * gvis), np.mean(fc * gvis)])


def test_brdf_lut_writes_the_documented_layout(tmp_path):
    out = tmp_path / "lut.exr"
    result = run_cli("brdf-lut", "-o", out, "--size", 16, cache_dir=tmp_path / "cache")
    assert result.returncode == 0, result.stderr
    image = read_image(out)
    assert image.pixels.shape == (16, 16, 3) and image.channel_names == ("R", "G", "B")
    # Row k = roughness (k + .5)/N, column i = NoV (i + .5)/N, as OpenImageIO reads it.
    for k, i in [(1, 15), (12, 2), (8, 8)]:
        expected = ggx_lut_cell((i + 0.5) / 16, (k + 0.5) / 16)
        np.testing.assert_allclose(image.pixels[k, i, :2], expected, atol=3e-3)  # A, B


def test_bake_ibl_writes_mips_lut_and_sh(tmp_path):
    out = tmp_path / "baked"
    result = run_cli(
        "bake-ibl", "sky", "-o", out, "--size", 16, "--samples", 16, cache_dir=tmp_path / "c"
    )
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # no progress unless stderr is a terminal
    manifest = json.loads((out / "ibl.json").read_text())
    sizes = [m["face_size"] for m in manifest["mips"]]
    assert sizes == [16, 8, 4]
    assert [m["roughness"] for m in manifest["mips"]] == [0.0, 0.5, 1.0]
    for m, size in enumerate(sizes):
        cross = read_image(out / f"prefiltered_mip{m}.exr").pixels
        assert cross.shape == (3 * size, 4 * size, 3)
        assert np.isfinite(cross).all()
    assert read_image(out / "brdf_lut.exr").pixels.shape == (128, 128, 3)  # A, B, sheen E
    sh = json.loads((out / "sh.json").read_text())
    coeffs = np.array(sh["coefficients"])
    assert coeffs.shape == (9, 3) and coeffs[0].min() > 0
    # A second run reads the cache and writes the same files.
    again = run_cli(
        "bake-ibl",
        "sky",
        "-o",
        tmp_path / "b2",
        "--size",
        16,
        "--samples",
        16,
        cache_dir=tmp_path / "c",
    )
    assert again.returncode == 0
    np.testing.assert_array_equal(
        read_image(tmp_path / "b2" / "prefiltered_mip1.exr").pixels,
        read_image(out / "prefiltered_mip1.exr").pixels,
    )


def test_bake_ibl_warns_about_ldr_input(tmp_path):
    png = tmp_path / "env.png"
    write_image(png, np.full((16, 32, 3), 0.5, np.float32))
    result = run_cli(
        "bake-ibl", png, "-o", tmp_path / "o", "--size", 8, "--samples", 8, cache_dir=tmp_path / "c"
    )
    assert result.returncode == 0, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"warning: {png}: LDR")


def one_error_line(capsys, *fragments) -> str:
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ")
    for fragment in fragments:
        assert fragment in lines[0]
    return lines[0]


@pytest.fixture
def cache_env(monkeypatch, tmp_path):
    monkeypatch.setenv("MATEDIT_CACHE_DIR", str(tmp_path / "cache"))


def test_bake_ibl_missing_file_exits_2(tmp_path, capsys, cache_env):
    missing = tmp_path / "nothere.exr"
    assert main(["bake-ibl", str(missing), "-o", str(tmp_path / "o")]) == 2
    one_error_line(capsys, str(missing), "no such file")


def test_bake_ibl_truncated_file_exits_2(tmp_path, capsys, cache_env):
    good = tmp_path / "good.exr"
    write_image(good, np.ones((128, 256, 3), np.float32) * np.arange(256)[None, :, None])
    bad = tmp_path / "bad.exr"
    bad.write_bytes(good.read_bytes()[:2000])
    assert main(["bake-ibl", str(bad), "-o", str(tmp_path / "o")]) == 2
    one_error_line(capsys, str(bad))


def test_bake_ibl_bad_size_exits_2(tmp_path, capsys, cache_env):
    assert main(["bake-ibl", "studio", "-o", str(tmp_path / "o"), "--size", "100"]) == 2
    one_error_line(capsys, "power of two")


def test_bake_ibl_output_is_a_file_exits_2(tmp_path, capsys, cache_env):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["bake-ibl", "studio", "-o", str(blocker)]) == 2
    one_error_line(capsys, str(blocker))


def test_brdf_lut_bad_options_exit_2(tmp_path, capsys, cache_env):
    assert main(["brdf-lut", "-o", str(tmp_path / "lut.png")]) == 2
    one_error_line(capsys, "lut.png", "exr")
    assert main(["brdf-lut", "-o", str(tmp_path / "no" / "lut.exr")]) == 2
    one_error_line(capsys, "does not exist")
    assert main(["brdf-lut", "-o", str(tmp_path / "lut.exr"), "--size", "1"]) == 2
    one_error_line(capsys, "LUT size")
    assert main(["brdf-lut", "-o", str(tmp_path / "lut.exr"), "--size", "many"]) == 2
    one_error_line(capsys, "--size")
