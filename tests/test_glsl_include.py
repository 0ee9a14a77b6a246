"""The include mechanism: spliced files keep their own line numbers in driver errors."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from matedit.glsl.include import Assembly, IncludeError, assemble

_VERTEX = "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n"
_MAIN = "out vec4 color;\nvoid main() {\n    color = vec4(helper());\n}\n"


@pytest.fixture
def library(tmp_path):
    (tmp_path / "good.glsl").write_text("// fine\nfloat one() { return 1.0; }\n")
    (tmp_path / "bad.glsl").write_text(
        '#include "good.glsl"\n'
        "// line 2\n"
        "float helper() {\n"
        "    return one() + undeclared_thing;\n"  # line 4
        "}\n"
    )
    (tmp_path / "outer.glsl").write_text('// outer\n#include "bad.glsl"\n#include "good.glsl"\n')
    return tmp_path


def _compile_log(ctx, asm: Assembly) -> str:
    with pytest.raises(Exception) as info:
        ctx.program(vertex_shader=_VERTEX, fragment_shader=asm.text)
    return asm.map_log(str(info.value))


def test_error_in_nested_include_maps_to_its_file_and_line(ctx, library):
    asm = assemble(_MAIN, includes=["outer.glsl"], roots=[library])
    log = _compile_log(ctx, asm)
    assert "bad.glsl:4" in log, log


def test_error_after_an_include_maps_to_the_including_file(ctx, library):
    body = 'out vec4 color;\n#include "good.glsl"\nvoid main() {\n    color = vec4(oops);\n}\n'
    asm = assemble(body, roots=[library], name="main.frag")
    log = _compile_log(ctx, asm)
    assert "main.frag:4" in log, log


def test_glslang_errors_map_the_same_way(tmp_path, library):
    exe = shutil.which("glslangValidator")
    if exe is None:
        pytest.skip("glslangValidator not installed")
    asm = assemble(_MAIN, includes=["outer.glsl"], roots=[library])
    src = tmp_path / "shader.frag"
    src.write_text(asm.text)
    out = subprocess.run([exe, str(src)], capture_output=True, text=True).stdout
    assert "bad.glsl:4" in asm.map_log(out), out


def test_each_file_is_spliced_once(library):
    asm = assemble(_MAIN, includes=["outer.glsl", "good.glsl"], roots=[library])
    assert asm.text.count("float one()") == 1


def test_circular_include_is_an_error_naming_the_chain(tmp_path):
    (tmp_path / "a.glsl").write_text('#include "b.glsl"\n')
    (tmp_path / "b.glsl").write_text('#include "a.glsl"\n')
    with pytest.raises(IncludeError, match="a.glsl -> b.glsl -> a.glsl"):
        assemble("void main() {}\n", includes=["a.glsl"], roots=[tmp_path])


def test_missing_include_names_file_and_line(tmp_path):
    (tmp_path / "a.glsl").write_text('// one\n#include "nowhere.glsl"\n')
    with pytest.raises(IncludeError, match=r"a.glsl:2: cannot find include \"nowhere.glsl\""):
        assemble("void main() {}\n", includes=["a.glsl"], roots=[tmp_path])


def test_map_log_leaves_code_quoted_in_messages_alone():
    asm = Assembly(text="", sources=["x.glsl", "y.glsl"])
    log = "1:100007(3): error: cannot convert vec3(1) to 0:2 here\n"
    assert asm.map_log(log) == "y.glsl:7(3): error: cannot convert vec3(1) to 0:2 here\n"


def _expected(text: str, src: int) -> list[str]:
    """What splicing a file without includes writes, written out: its `#line` then its lines."""
    return [f"#line {src * 100_000 + 1} {src}", *text.splitlines()]


def test_files_are_parsed_once_per_version_and_edits_or_removals_are_seen(tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    first = "float one() { return 1.0; }\n\n"  # a blank last line is kept
    (lib / "a.glsl").write_text(first)
    (lib / "b.glsl").write_text('\n#include "a.glsl"\n\nfloat two() { return 2.0; }\n')
    asm = assemble("void main() {}", includes=["b.glsl"], roots=[lib])
    lines = asm.text.splitlines()
    # b: its #line, a blank line, then a spliced whole (a's #line and lines), back to line 3.
    assert lines == ["#version 330 core", "#line 1 0", "", *_expected(first, 1), "#line 3 0",
                     "", "float two() { return 2.0; }", "#line 200001 2", "void main() {}"]
    assert asm.sources == ["b.glsl", "a.glsl", "<main>"]
    assert assemble("void main() {}", includes=["b.glsl"], roots=[lib]).text == asm.text

    edited = "float one() { return 1.5; }  // longer, so the size changes too\n"
    (lib / "a.glsl").write_text(edited)
    again = assemble("void main() {}", includes=["b.glsl"], roots=[lib])
    assert "return 1.5" in again.text and "return 1.0" not in again.text

    (lib / "a.glsl").unlink()
    with pytest.raises(IncludeError, match="a.glsl"):
        assemble("void main() {}", includes=["b.glsl"], roots=[lib])
