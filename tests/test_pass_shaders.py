"""The preview and bake passes (shaders/render, shaders/bake) compile on llvmpipe and pass
glslangValidator as GLSL 330 stages."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from matedit.glsl.include import assemble, packing_prelude
from matedit.resources import shaders_dir

GLSLANG = shutil.which("glslangValidator")
STAGES = sorted(p for d in ("render", "bake") for p in (shaders_dir() / d).iterdir()
                if p.suffix in (".vert", ".frag"))


def _text(path) -> str:
    # bake shaders may rely on defines set by their caller; give them the common ones. The
    # lighting pass unpacks the G-buffer with GLSL 4.20's packing functions: at 330 its caller
    # (matedit/render/deferred.py) enables the extension in the prelude, as here.
    return assemble(path.read_text(), "330 core", [], path.name,
                    prelude=packing_prelude("330 core")).text


@pytest.mark.skipif(GLSLANG is None, reason="glslangValidator not installed (glslang-tools)")
@pytest.mark.parametrize("path", STAGES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_pass_shader_passes_glslang(path, tmp_path):
    f = tmp_path / f"shader{path.suffix}"
    f.write_text(_text(path))
    r = subprocess.run([GLSLANG, str(f)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:]


@pytest.mark.parametrize("path", [p for p in STAGES if p.suffix == ".frag"],
                         ids=lambda p: f"{p.parent.name}/{p.name}")
def test_pass_shader_links_on_llvmpipe(ctx, path):
    vert = shaders_dir() / path.parent.name / "fullscreen.vert"
    prog = ctx.program(vertex_shader=_text(vert), fragment_shader=_text(path))
    prog.release()
