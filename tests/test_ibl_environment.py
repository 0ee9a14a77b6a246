"""Loading environments: good files, LDR files, bad files, built-ins."""

from __future__ import annotations

import numpy as np
import pytest

from matedit.ibl import BUILTIN_NAMES, EnvironmentMapError, load_environment
from matedit.ibl.cubemap import faces_to_cross
from matedit.io.images import ImageError, read_image, write_image


@pytest.fixture
def hdr_image() -> np.ndarray:
    rng = np.random.default_rng(7)
    return (rng.random((64, 128, 3)) * 8.0).astype(np.float32)


@pytest.mark.parametrize("ext", [".exr", ".hdr"])
def test_hdr_equirect_loads_linear_without_warnings(tmp_path, hdr_image, ext):
    path = tmp_path / f"env{ext}"
    write_image(path, hdr_image)
    env = load_environment(path)
    assert env.faces is None and env.equirect.shape == (64, 128, 3)
    assert env.warnings == []
    # .hdr is RGBE: an 8-bit mantissa per channel under the brightest channel's exponent.
    atol = 0.0 if ext == ".exr" else 8.0 / 128
    np.testing.assert_allclose(env.equirect, hdr_image, rtol=1e-6, atol=atol)


def test_cube_cross_loads_as_faces(tmp_path):
    faces = np.random.default_rng(1).random((6, 16, 16, 3)).astype(np.float32) + 0.5
    path = tmp_path / "cross.exr"
    write_image(path, faces_to_cross(faces))
    env = load_environment(path)
    assert env.equirect is None
    np.testing.assert_array_equal(env.faces, faces)


def test_ldr_png_is_linearised_with_a_warning(tmp_path):
    path = tmp_path / "env.png"
    write_image(path, np.full((16, 32, 3), 128 / 255, dtype=np.float32))
    env = load_environment(path)
    assert len(env.warnings) == 1 and str(path) in env.warnings[0] and "sRGB" in env.warnings[0]
    np.testing.assert_allclose(env.equirect, ((128 / 255 + 0.055) / 1.055) ** 2.4, rtol=1e-5)


def test_jpeg_grey_image_becomes_rgb(tmp_path):
    path = tmp_path / "env.jpg"
    write_image(path, np.full((16, 32, 1), 0.5, dtype=np.float32))
    env = load_environment(path)
    assert env.equirect.shape == (16, 32, 3) and env.warnings


def _raises_naming(path, *fragments):
    with pytest.raises(EnvironmentMapError) as info:
        load_environment(path)
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert message.startswith(str(path))
    for fragment in fragments:
        assert fragment in message
    return message


def test_missing_file_is_a_clear_error(tmp_path):
    _raises_naming(tmp_path / "nothere.hdr", "no such file", "studio")


def test_empty_file_is_a_clear_error(tmp_path):
    path = tmp_path / "empty.exr"
    path.write_bytes(b"")
    _raises_naming(path, "empty")


def test_truncated_exr_is_a_clear_error(tmp_path, hdr_image):
    good = tmp_path / "good.exr"
    write_image(good, np.tile(hdr_image, (4, 4, 1)))
    data = good.read_bytes()
    bad = tmp_path / "truncated.exr"
    bad.write_bytes(data[: len(data) * 6 // 10])
    _raises_naming(bad)


def test_truncated_hdr_is_a_clear_error(tmp_path, hdr_image):
    good = tmp_path / "good.hdr"
    write_image(good, np.tile(hdr_image, (4, 4, 1)))
    data = good.read_bytes()
    bad = tmp_path / "truncated.hdr"
    bad.write_bytes(data[: len(data) // 2])
    _raises_naming(bad)


def test_corrupt_file_is_a_clear_error(tmp_path):
    path = tmp_path / "corrupt.exr"
    path.write_bytes(b"\x76\x2f\x31\x01" + bytes(range(256)) * 8)  # EXR magic, then garbage
    _raises_naming(path)


def test_unsupported_file_is_a_clear_error(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("not an image")
    _raises_naming(path)


def test_wrong_aspect_is_a_clear_error(tmp_path):
    path = tmp_path / "square.exr"
    write_image(path, np.ones((32, 50, 3), np.float32))
    _raises_naming(path, "50x32", "equirectangular")


def test_directory_is_a_clear_error(tmp_path):
    _raises_naming(tmp_path)


def test_non_finite_pixels_are_zeroed_with_a_warning(tmp_path):
    image = np.ones((8, 16, 3), np.float32)
    image[0, 0, 0] = np.nan
    image[1, 1, 1] = -3.0
    path = tmp_path / "nan.exr"
    write_image(path, image)
    env = load_environment(path)
    assert env.warnings and "2 pixels" in env.warnings[0]
    assert np.isfinite(env.equirect).all() and env.equirect.min() == 0.0


@pytest.mark.parametrize("name", BUILTIN_NAMES)
def test_builtins_are_deterministic_hdr(name):
    a = load_environment(name, size=64)
    b = load_environment(name, size=64)
    assert a.content_hash() == b.content_hash()
    assert a.equirect.shape == (128, 256, 3)
    assert a.equirect.min() > 0.0 and a.equirect.max() > 5.0  # lights well above 1
    assert np.isfinite(a.equirect).all()


def test_sun_energy_does_not_depend_on_resolution():
    from matedit.ibl.builtin import sky

    def sun_irradiance(width):
        img = sky(width).astype(np.float64)
        h = width // 2
        theta = np.pi * (np.arange(h) + 0.5) / h
        omega = (2 * np.pi / width) * (np.pi / h) * np.sin(theta)[:, None]
        bright = img[..., 0] > 100.0
        return float(np.sum(img[..., 0] * omega * bright))

    assert sun_irradiance(512) == pytest.approx(sun_irradiance(2048), rel=0.02)


def test_read_image_errors_are_image_errors(tmp_path):
    with pytest.raises(ImageError):
        read_image(tmp_path / "missing.exr")
    with pytest.raises(ImageError):
        write_image(tmp_path / "no_folder" / "x.exr", np.ones((2, 2, 3)))
