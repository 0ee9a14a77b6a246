"""The generated GLSL of every sample graph stays byte-identical (refactors must not change it).

tests/data/glsl_hashes.json holds the sha256 of the vertex text, fragment text and reflection
of each (sample, target, entry). Work that is meant to change the generated code (shading,
a new entry, the emitter) regenerates it and commits the result with the change:

    python tools/glsl_hashes.py --regen

(`--check` lists the (sample, target, entry) whose text changed.)
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _tool():
    spec = importlib.util.spec_from_file_location("glsl_hashes", ROOT / "tools" / "glsl_hashes.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_generated_glsl_is_unchanged():
    tool = _tool()
    was = json.loads(tool.HASHES.read_text())
    now = tool.compute()
    assert len(now) >= 100  # every sample material and instance, 3 targets, 3 entries
    changed = sorted(k for k in was.keys() | now.keys() if was.get(k) != now.get(k))
    assert changed == [], (f"{len(changed)} generated shaders changed (first: {changed[:5]}); "
                           "if meant, run `python tools/glsl_hashes.py --regen`")
