"""resources.py finds shaders/, graphs/ and ui/ in a checkout and in an installed wheel."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from matedit import resources

ROOT = Path(__file__).resolve().parents[1]


def test_checkout_finds_resources():
    for kind in ("shaders", "graphs", "ui"):
        assert resources.resource_dir(kind) == ROOT / kind


def test_unknown_kind_is_refused():
    with pytest.raises(ValueError):
        resources.resource_dir("secrets")


@pytest.mark.slow
def test_installed_wheel_ships_and_finds_resources(tmp_path):
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(tmp_path / "dist"), str(ROOT)],
        capture_output=True, text=True,
    )
    if built.returncode != 0:
        pytest.fail(built.stderr[-2000:])
    (wheel,) = (tmp_path / "dist").glob("matedit-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "matedit/shaders/common.glsl" in names
    assert any(n.startswith("matedit/graphs/materials/") for n in names)
    # Install into a plain folder and import from there, away from the checkout.
    target = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(target)
    code = ("import matedit.resources as r, sys; "
            "print(r.shaders_dir()); print(r.graphs_dir()); print(r.ui_dir())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=tmp_path, env={"PYTHONPATH": str(target), "PATH": "/usr/bin"})
    assert out.returncode == 0, out.stderr
    for line in out.stdout.split():
        assert Path(line).is_dir() and str(target) in line
