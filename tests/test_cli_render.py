"""`matedit render` per the command-line contract: headless, deterministic, clear errors."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from matedit.io.images import read_image
from matedit.resources import graphs_dir

SAMPLE = graphs_dir() / "materials" / "brushed_gold.json"


def run(*args):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "matedit", "render", *args],
                          capture_output=True, text=True, env=env)


def test_render_writes_a_deterministic_png(tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    for out in (a, b):
        r = run(str(SAMPLE), "-o", str(out), "--size", "48x32", "--exposure", "0.5")
        assert r.returncode == 0, r.stderr
    assert a.read_bytes() == b.read_bytes()
    img = read_image(a).pixels
    assert img.shape == (32, 48, 3) and img.std() > 0.02


@pytest.mark.slow
def test_render_reference_and_difference(tmp_path):
    r = run(str(SAMPLE), "-o", str(tmp_path / "ref.png"), "--size", "32x32", "--ibl",
            "reference", "--mesh", "cube", "--env", "sky")
    assert r.returncode == 0, r.stderr
    r = run(str(SAMPLE), "-o", str(tmp_path / "diff.png"), "--size", "32x32", "--ibl",
            "difference")
    assert r.returncode == 0, r.stderr
    assert "mean |split-sum - reference|" in r.stdout
    assert np.isfinite(read_image(tmp_path / "diff.png").pixels).all()


@pytest.mark.parametrize("args, needle", [
    (["missing.json"], "not found"),
    ([str(SAMPLE), "--size", "big"], "--size"),
    ([str(SAMPLE), "--mesh", "teapot"], "teapot"),
    ([str(SAMPLE), "--env", "nowhere.hdr"], "nowhere.hdr"),
    ([str(graphs_dir() / "layers" / "rust.json")], "material function"),
])
def test_render_bad_input_exits_2_with_one_line(tmp_path, args, needle):
    r = run(*args[:1], "-o", str(tmp_path / "x.png"), *args[1:])
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], r.stderr
