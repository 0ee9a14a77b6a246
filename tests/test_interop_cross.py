"""HLSL and MSL of every sample through SPIR-V (glslangValidator, spirv-val, spirv-cross).

The references are other people's tools: glslang compiles our glsl450 to SPIR-V and spirv-val
validates it; spirv-cross translates; the HLSL is then compiled back to SPIR-V by glslang's
own HLSL front end (`-D`) and validated again by spirv-val. There is no Metal compiler on
Debian, so the MSL is checked for its entry points and its bindings, which must equal the
reflection's binding numbers.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import pytest

from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING
from matedit.interop import cross
from matedit.interop.export import compile_targets
from matedit.io.document import FileResolver, load
from matedit.resources import graphs_dir

SAMPLES = sorted((graphs_dir() / "materials").glob("*.json"))
pytestmark = pytest.mark.skipif(not cross.available(),
                                reason="glslang-tools, spirv-tools or spirv-cross missing "
                                "(./dev.sh setup installs them)")


@pytest.fixture(scope="module")
def compiled():
    out = {}
    for path in SAMPLES:
        doc = load(path)
        out[path.stem] = compile_targets(doc, FileResolver(), ["hlsl", "msl"])
    return out


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_hlsl_compiles_back_and_validates(compiled, path):
    cc = compiled[path.stem]["hlsl"]
    assert "float4 main" in cc.fragment_text or "main(" in cc.fragment_text
    cross.check_hlsl(cc)  # raises CrossCompileError with the tool's log
    regs = {b["name"]: b["register"] for b in cc.bindings["fragment"]}
    refl = cc.reflection()
    assert regs["FrameBlock"] == f"b{FRAME_BINDING}"
    if refl["uniform_block"]:
        assert regs["MaterialParams"] == f"b{MATERIAL_BINDING}"
    for t in refl["textures"]:
        assert regs[t["name"]] == f"t{t['binding']}"
        assert t["binding"] >= FIRST_TEXTURE_BINDING
    assert {b["name"]: b["register"] for b in cc.bindings["vertex"]} == \
        {"FrameBlock": f"b{FRAME_BINDING}"}


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_msl_entry_points_and_bindings(compiled, path):
    cc = compiled[path.stem]["msl"]
    assert "#include <metal_stdlib>" in cc.vertex_text
    assert any(ln.startswith("vertex ") for ln in cc.vertex_text.splitlines())
    assert any(ln.startswith("fragment ") for ln in cc.fragment_text.splitlines())
    frag = {(b["kind"], b["index"]) for b in cc.bindings["fragment"]}
    refl = cc.reflection()
    assert ("buffer", FRAME_BINDING) in frag
    if refl["uniform_block"]:
        assert ("buffer", MATERIAL_BINDING) in frag
    for t in refl["textures"]:
        assert ("texture", t["binding"]) in frag and ("sampler", t["binding"]) in frag
    assert {b["name"] for b in cc.bindings["fragment"] if b["kind"] == "texture"} >= \
        {t["name"] for t in refl["textures"]}


def run(*args, env=None):
    return subprocess.run([sys.executable, "-m", "matedit", "compile", *args],
                          capture_output=True, text=True, env=env)


def test_cli_all_writes_hlsl_and_msl_with_bindings(tmp_path):
    r = run(str(SAMPLES[0]), "-o", str(tmp_path), "--target", "all")
    assert r.returncode == 0, r.stderr
    stem = SAMPLES[0].stem
    for t in ("glsl330", "glsl450", "essl300"):
        assert (tmp_path / f"{stem}.{t}.vert").is_file()
        assert (tmp_path / f"{stem}.{t}.frag").is_file()
    for suffix in ("hlsl", "metal"):  # HLSL and MSL end in their languages' extensions
        assert (tmp_path / f"{stem}.vert.{suffix}").is_file()
        assert (tmp_path / f"{stem}.frag.{suffix}").is_file()
        assert not list(tmp_path.glob(f"*.{'msl' if suffix == 'metal' else suffix}.*"))
    refl = json.loads((tmp_path / f"{stem}.reflection.json").read_text())
    assert refl["targets"]["hlsl"]["bindings"]["vertex"] == [
        {"name": "FrameBlock", "register": f"b{FRAME_BINDING}"}]
    assert str(tmp_path) not in (tmp_path / f"{stem}.reflection.json").read_text()


def test_missing_tool_names_the_debian_package(tmp_path):
    bindir = tmp_path / "bin"
    bindir.mkdir()
    # Only python and glslang on PATH: spirv-cross is missing.
    for name in ("glslangValidator", "spirv-val"):
        os.symlink(shutil.which(name), bindir / name)
    env = dict(os.environ, PATH=str(bindir))
    r = run(str(SAMPLES[0]), "-o", str(tmp_path / "out"), "--target", "msl", env=env)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert "spirv-cross" in lines[0] and "Debian package spirv-cross" in lines[0]
    assert not (tmp_path / "out").exists()


def test_textured_material_bindings_in_hlsl_and_msl(tmp_path):
    from tests.test_interop_mtlx import _all_kinds_material

    src = _all_kinds_material(tmp_path)
    out = compile_targets(load(src), FileResolver(), ["hlsl", "msl"])
    hlsl, msl = out["hlsl"], out["msl"]
    cross.check_hlsl(hlsl)
    (tex,) = hlsl.reflection()["textures"]
    assert tex["binding"] == FIRST_TEXTURE_BINDING
    regs = {b["name"]: b["register"] for b in hlsl.bindings["fragment"]}
    assert regs[tex["name"]] == f"t{FIRST_TEXTURE_BINDING}"
    assert regs["MaterialParams"] == f"b{MATERIAL_BINDING}"
    frag = {(b["kind"], b["index"]) for b in msl.bindings["fragment"]}
    assert {("texture", FIRST_TEXTURE_BINDING), ("sampler", FIRST_TEXTURE_BINDING),
            ("buffer", MATERIAL_BINDING)} <= frag
