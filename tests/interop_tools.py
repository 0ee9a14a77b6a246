"""Shared helpers for the interop tests: the Khronos glTF-Validator from npm, run by node."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NODE_PREFIX = ROOT / ".venv" / "node"  # ignored by git; the validator is cached here
VALIDATOR = NODE_PREFIX / "node_modules" / "gltf-validator"

_SCRIPT = r"""
const v = require(process.argv[2]);
const fs = require('fs'); const path = require('path');
const file = process.argv[3];
v.validateBytes(new Uint8Array(fs.readFileSync(file)), {
  uri: path.basename(file),
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    try { resolve(new Uint8Array(fs.readFileSync(
      path.join(path.dirname(file), decodeURIComponent(uri))))); }
    catch (e) { reject(e.toString()); }
  })
}).then(r => console.log(JSON.stringify(r.issues)),
        e => { console.error(String(e)); process.exit(3); });
"""


def gltf_validator() -> Path:
    """The installed validator package, installing it with npm on first use; skips the test
    (stating why) only when node or npm is absent."""
    if not shutil.which("node") or not shutil.which("npm"):
        pytest.skip("node/npm not installed: cannot run the Khronos glTF-Validator "
                    "(apt-get install nodejs npm)")
    if not (VALIDATOR / "package.json").is_file():
        r = subprocess.run(["npm", "install", "--no-audit", "--no-fund", "--prefix",
                            str(NODE_PREFIX), "gltf-validator"],
                           capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, f"npm install gltf-validator failed: {r.stderr[-800:]}"
    return VALIDATOR


def validate_gltf(path: Path, tmp: Path) -> dict:
    """The validator's `issues` object (numErrors, numWarnings, messages...)."""
    script = tmp / "validate_gltf.js"
    if not script.exists():
        script.write_text(_SCRIPT)
    r = subprocess.run(["node", str(script), str(gltf_validator()), str(path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def write_png8(path: Path, codes) -> None:
    """An 8-bit PNG of `codes` (H, W, C) uint8, row 0 = v = 0 (stored top row first), written
    with OpenImageIO directly and no colour-space tag: what a texture file on disk is."""
    import numpy as np
    import OpenImageIO as oiio

    h, w, c = codes.shape
    out = oiio.ImageOutput.create(str(path))
    assert out is not None and out.open(str(path), oiio.ImageSpec(w, h, c, "uint8"))
    assert out.write_image(np.ascontiguousarray(codes[::-1]))
    out.close()


def textured_material(folder: Path, n: int = 8):
    """A material whose base colour is an sRGB 8-bit texture (albedo.png) and whose roughness
    and metallic are the R and G of a linear 8-bit one (data.png), both n x n, sampled on the
    mesh UV. Returns (document path, albedo codes, data codes), codes row 0 = v = 0."""
    import numpy as np

    from matedit.io.document import save
    from tests.graphs_util import link, material, node

    rng = np.random.default_rng(15)
    albedo = rng.integers(0, 256, (n, n, 3), dtype=np.uint8)
    data = rng.integers(0, 256, (n, n, 3), dtype=np.uint8)
    write_png8(folder / "albedo.png", albedo)
    write_png8(folder / "data.png", data)
    d = material()
    node(d, "uv", "texcoord")
    node(d, "ta", "texture_parameter", {"name": "albedo", "path": "albedo.png", "srgb": True})
    node(d, "td", "texture_parameter", {"name": "data", "path": "data.png", "srgb": False})
    node(d, "sa", "texture_sample")
    node(d, "sd", "texture_sample")
    link(d, "ta", "texture", "sa", "texture")
    link(d, "uv", "uv", "sa", "uv")
    link(d, "td", "texture", "sd", "texture")
    link(d, "uv", "uv", "sd", "uv")
    node(d, "make", "make_attributes")
    node(d, "out", "material_output")
    link(d, "sa", "rgb", "make", "baseColor")
    link(d, "sd", "r", "make", "roughness")
    link(d, "sd", "g", "make", "metallic")
    link(d, "make", "attributes", "out", "attributes")
    return save(d, folder / "textured.json"), albedo, data


def srgb_decode(codes):
    """IEC 61966-2-1's decoding of 8-bit codes, written out here (the test's own reference)."""
    import numpy as np

    c = np.asarray(codes, np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
