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
