"""`matedit contact-sheet`: every material rendered and labelled into one PNG."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

from matedit.resources import graphs_dir

pytestmark = pytest.mark.gl


def run(*args):
    return subprocess.run([sys.executable, "-m", "matedit", "contact-sheet", *args],
                          capture_output=True, text=True)


def test_sheet_has_a_tile_per_material(tmp_path):
    files = [graphs_dir() / "materials" / n for n in ("red_brick.json", "oak_planks.json",
                                                      "veined_marble.json")]
    out = tmp_path / "sheet.png"
    r = run(*map(str, files), "-o", str(out), "--size", "64", "--columns", "2")
    assert r.returncode == 0, r.stderr
    img = oiio.ImageBuf(str(out))
    assert (img.spec().width, img.spec().height) == (128, 128)
    px = np.asarray(img.get_pixels(oiio.FLOAT))
    tiles = [px[:64, :64], px[:64, 64:], px[64:, :64]]
    means = [t[8:48, 16:48].mean(axis=(0, 1)) for t in tiles]
    assert means[0][0] > means[0][2] + 0.1  # brick is red
    assert means[2].min() > 0.5  # marble is light
    assert np.all(px[64:, 64:] < 0.1)  # the empty fourth tile stays dark
    assert r.stderr == ""  # progress is drawn only on a terminal (docs/cli.md)


def test_bad_input_exits_2_with_one_line(tmp_path):
    r = run(str(tmp_path / "missing.json"), "-o", str(tmp_path / "s.png"))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and r.stderr.startswith("error:")
    r = run("-o", str(tmp_path / "s.jpg"))
    assert r.returncode == 2 and "must be a .png" in r.stderr
