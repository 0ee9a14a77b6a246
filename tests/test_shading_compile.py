"""Every library file of shaders/ (top level and nodes/) compiles on its own: llvmpipe
(GLSL 330 core) and glslangValidator for GLSL 330, Vulkan GLSL 450 (to SPIR-V) and ESSL 300."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from matedit.glsl.include import assemble, packing_prelude
from matedit.resources import shaders_dir

FILES = sorted(p.name for p in shaders_dir().glob("*.glsl")) + sorted(
    f"nodes/{p.name}" for p in (shaders_dir() / "nodes").glob("*.glsl"))
_VERTEX = "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n"
_ES_PRELUDE = "precision highp float;\nprecision highp int;\n"
TARGETS = {
    # name: (#version, prelude, main, glslangValidator arguments)
    "glsl330": ("330 core", "", "out vec4 color;", []),
    "glsl450": ("450", "", "layout(location = 0) out vec4 color;", ["-V"]),
    "essl300": ("300 es", _ES_PRELUDE, "out vec4 color;", []),
}


def _wrapped(name: str, target: str):
    version, prelude, out_decl, _ = TARGETS[target]
    if name == "gbuffer.glsl":  # packs halves: at 330 its includers enable the extension
        prelude = "\n".join(x for x in (packing_prelude(version), prelude) if x)
    body = f"{out_decl}\nvoid main() {{\n    color = vec4(0.0);\n}}\n"
    return assemble(body, version=version, includes=[name], prelude=prelude)


def test_the_library_has_the_expected_files():
    expected = {"common", "sampling", "brdf", "material", "lights", "lights_block", "ibl",
                "ibl_inputs", "output", "surface"}  # fmt: skip
    assert expected <= {f.removesuffix(".glsl") for f in FILES}


@pytest.mark.gl
@pytest.mark.parametrize("name", FILES)
def test_compiles_alone_on_llvmpipe(ctx, name):
    asm = _wrapped(name, "glsl330")
    try:
        ctx.program(vertex_shader=_VERTEX, fragment_shader=asm.text).release()
    except Exception as exc:
        pytest.fail(asm.map_log(str(exc)))


@pytest.mark.parametrize("target", sorted(TARGETS))
@pytest.mark.parametrize("name", FILES)
def test_compiles_alone_in_glslang(tmp_path, name, target):
    exe = shutil.which("glslangValidator")
    if exe is None:
        pytest.skip("glslangValidator is not installed: cannot check 450 / ES 300 targets")
    asm = _wrapped(name, target)
    src = tmp_path / f"{name.replace('/', '_')}.{target}.frag"
    src.write_text(asm.text)
    args = [exe, *TARGETS[target][3], str(src)]
    if "-V" in args:
        args += ["-o", str(tmp_path / "out.spv")]
    run = subprocess.run(args, capture_output=True, text=True)
    assert run.returncode == 0, asm.map_log(run.stdout + run.stderr)
