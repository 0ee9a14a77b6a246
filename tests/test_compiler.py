"""Compiler: determinism, structure hash, passes, functions, layers, targets, source map."""

from __future__ import annotations

import json
import random
import shutil
import subprocess
import sys

import pytest
from graphs_util import link, node, simple_material

from matedit.compiler import TARGETS, CompileError, compile_all, compile_document
from matedit.compiler.api import lower_and_optimise
from matedit.graph.commands import Connect, SetSetting, SetValue
from matedit.graph.model import Link
from matedit.io import document as fmt
from matedit.io.document import FileResolver
from matedit.resources import graphs_dir

MATERIALS = sorted((graphs_dir() / "materials").glob("*.json"))
GLSLANG = shutil.which("glslangValidator")


def compiled(doc, target="glsl330"):
    return compile_document(doc, FileResolver(), target)


@pytest.mark.parametrize("path", MATERIALS, ids=lambda p: p.stem)
def test_compiling_twice_or_shuffled_gives_identical_text(path):
    a = compiled(fmt.load(path))
    b = compiled(fmt.load(path))
    raw = json.loads(path.read_text())
    rnd = random.Random(7)
    rnd.shuffle(raw["nodes"])
    rnd.shuffle(raw["links"])
    c = compiled(fmt.from_dict(raw, str(path), path))
    assert a.fragment_text == b.fragment_text == c.fragment_text
    assert a.vertex_text == c.vertex_text
    assert a.structure_hash == c.structure_hash


def test_value_edit_keeps_text_and_hash_structural_edit_changes_it():
    d = simple_material()
    before = compiled(d)
    SetValue("r", "value", 0.95).apply(d.graph)
    SetValue("m", "b", 0.25).apply(d.graph)
    after_value = compiled(d)
    assert after_value.fragment_text == before.fragment_text
    assert after_value.structure_hash == before.structure_hash
    assert after_value.ir.uniforms != before.ir.uniforms  # the new defaults are reflected
    node(d, "k", "scalar_parameter", {"name": "metal"})
    Connect(Link("k", "value", "make", "metallic")).apply(d.graph)
    after_link = compiled(d)
    assert after_link.structure_hash != before.structure_hash


def test_texture_file_is_a_value_edit(tmp_path):
    d = simple_material(tmp_path / "m.json")
    node(d, "tex", "texture_parameter", {"name": "albedo", "path": "a.png"})
    node(d, "s", "texture_sample")
    link(d, "tex", "texture", "s", "texture")
    d.graph.links.discard(d.graph.incoming("make", "baseColor"))
    link(d, "s", "rgb", "make", "baseColor")
    a = compiled(d)
    SetSetting("tex", "path", "b.png").apply(d.graph)
    b = compiled(d)
    assert a.structure_hash == b.structure_hash
    assert b.reflection()["textures"][0]["path"].endswith("b.png")


def test_parameters_and_unconnected_inputs_become_predictable_uniforms():
    cm = compiled(simple_material())
    names = [u["name"] for u in cm.reflection()["uniforms"]]
    assert "p_tint" in names and "p_rough" in names and "u_m_b" in names
    assert "u_make_metallic" in names
    assert "uniform MaterialParams" in cm.fragment_text
    u = {x["name"]: x for x in cm.reflection()["uniforms"]}
    assert u["u_m_b"]["node"] == "m" and u["u_m_b"]["port"] == "b" and u["u_m_b"]["default"] == 0.5


def test_constant_folding_and_dead_code():
    d = simple_material()
    node(d, "c1", "constant", {"type": "float", "value": 0.25})
    node(d, "c2", "constant", {"type": "float", "value": 2.0})
    node(d, "prod", "multiply")
    link(d, "c1", "value", "prod", "a")
    link(d, "c2", "value", "prod", "b")
    d.graph.links.discard(d.graph.incoming("make", "metallic"))
    link(d, "prod", "result", "make", "metallic")
    node(d, "unused", "sin")  # not connected to the output
    ir = lower_and_optimise(d, FileResolver())
    kinds = [op.kind for op in ir.main.ops]
    assert "sin" not in kinds
    assert [op for op in ir.main.ops if op.node == "prod"] == []  # folded away
    text = compiled(d).fragment_text
    assert "make_attributes(" not in text or "0.5" in text


def test_common_subexpressions_are_merged():
    d = simple_material()
    for nid in ("s1", "s2"):
        node(d, nid, "sin")
        link(d, "r", "value", nid, "value")
    node(d, "sum", "add")
    link(d, "s1", "result", "sum", "a")
    link(d, "s2", "result", "sum", "b")
    d.graph.links.discard(d.graph.incoming("make", "metallic"))
    link(d, "sum", "result", "make", "metallic")
    ir = lower_and_optimise(d, FileResolver())
    assert sum(op.kind == "sin" for op in ir.main.ops) == 1


def test_float_splat_is_explicit():
    d = simple_material()
    node(d, "a", "add")
    link(d, "r", "value", "a", "a")
    link(d, "col", "color", "a", "b")
    d.graph.links.discard(d.graph.incoming("make", "baseColor"))
    link(d, "a", "result", "make", "baseColor")
    assert "vec3(p_rough)" in compiled(d).fragment_text


def test_invalid_graph_raises_compile_error_with_node():
    d = simple_material()
    node(d, "uv", "texcoord")
    d.graph.links.discard(d.graph.incoming("make", "baseColor"))
    link(d, "uv", "uv", "make", "baseColor")
    with pytest.raises(CompileError) as info:
        compiled(d)
    assert info.value.diagnostics[0].node_id == "make"


LAYERED = [p for p in MATERIALS if '"layer_stack"' in p.read_text()]


@pytest.mark.parametrize("path", LAYERED, ids=lambda p: p.stem)
def test_layers_cost_a_blend_not_a_brdf(path):
    cm = compiled(fmt.load(path))
    body = cm.fragment_text.split("MaterialAttributes evaluateMaterial()")[1]
    assert body.count("shadeSurface(") == 1
    # a layer blends by the mask (alpha, height, colour modes), lies on as a coat or as a
    # thin film
    assert any(f"{f}MaterialAttributes(" in body for f in ("blend", "coat", "film"))
    # each material function is defined once, whatever the number of calls
    for f in cm.ir.functions:
        assert cm.fragment_text.count(f"void {f.name}(") == 1


def test_material_has_defines_follow_written_attributes():
    d = simple_material()
    cm = compiled(d)
    assert "#define MATERIAL_HAS_BASE_COLOR 1" in cm.fragment_text
    assert "MATERIAL_HAS_NORMAL 1" not in cm.fragment_text
    node(d, "n", "unpack_normal")
    link(d, "n", "normal", "make", "normal")
    assert "#define MATERIAL_HAS_NORMAL 1" in compiled(d).fragment_text


def test_gl_error_is_reported_on_the_node(ctx):
    cm = compiled(simple_material())
    line = next(l for l in cm.fragment_text.splitlines() if "m_result" in l and "=" in l)
    broken = cm.fragment_text.replace(line, line.replace("*", "* undefined_thing *"))
    with pytest.raises(Exception) as info:
        ctx.program(vertex_shader=cm.vertex_text, fragment_shader=broken)
    located = [n for n, _, _, msg in cm.locate_error(str(info.value)) if "error" in msg]
    assert located and located[0] == "m"


@pytest.mark.parametrize("path", MATERIALS, ids=lambda p: p.stem)
def test_samples_link_on_llvmpipe(ctx, path):
    cm = compiled(fmt.load(path))
    prog = ctx.program(vertex_shader=cm.vertex_text, fragment_shader=cm.fragment_text)
    prog.release()


@pytest.mark.skipif(GLSLANG is None, reason="glslangValidator not installed (glslang-tools)")
@pytest.mark.parametrize("path", MATERIALS, ids=lambda p: p.stem)
def test_samples_pass_glslang_for_all_targets(path, tmp_path):
    for name, cm in compile_all(fmt.load(path), FileResolver()).items():
        for stage, text in (("vert", cm.vertex_text), ("frag", cm.fragment_text)):
            f = tmp_path / f"m.{name}.{stage}"
            f.write_text(text)
            args = [GLSLANG, str(f)]
            if TARGETS[name].vulkan:
                args += ["-V", "-o", str(tmp_path / f"{name}.{stage}.spv")]
            r = subprocess.run(args, capture_output=True, text=True)
            assert r.returncode == 0, f"{name} {stage}:\n{r.stdout[-3000:]}"


def test_compile_command_writes_files_and_reflection(tmp_path):
    src = MATERIALS[0]
    r = subprocess.run([sys.executable, "-m", "matedit", "compile", str(src), "-o",
                        str(tmp_path), "--target", "all"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    stem = src.stem
    for t in TARGETS:
        assert (tmp_path / f"{stem}.{t}.vert").is_file()
        assert (tmp_path / f"{stem}.{t}.frag").is_file()
    refl = json.loads((tmp_path / f"{stem}.reflection.json").read_text())
    assert not (tmp_path / f"{stem}.json").exists()
    assert str(tmp_path) not in json.dumps(refl) and "/work" not in json.dumps(refl)
    from matedit.compiler.targets import CROSS_TARGETS
    from matedit.interop.cross import available

    assert set(refl["targets"]) == set(TARGETS) | (set(CROSS_TARGETS) if available() else set())
    for t in refl["targets"].values():
        assert {"uniforms", "textures", "attributes", "structure_hash", "target"} <= set(t)


def test_compile_command_bad_input_exits_2(tmp_path):
    bad = tmp_path / "bad.json"
    # (an unconnected output is only a warning now: it takes the default material)
    bad.write_text('{"format": "matedit.material", "version": 2, "nodes": '
                   '[{"id": "o", "kind": "material_output"}], "links": '
                   '[{"from": ["ghost", "value"], "to": ["o", "attributes"]}]}')
    r = subprocess.run([sys.executable, "-m", "matedit", "compile", str(bad), "-o",
                        str(tmp_path / "o")], capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.startswith("error: ") and "node o" in r.stderr and "Traceback" not in r.stderr
    fn = graphs_dir() / "layers" / "rust.json"
    r = subprocess.run([sys.executable, "-m", "matedit", "compile", str(fn), "-o",
                        str(tmp_path / "o")], capture_output=True, text=True)
    assert r.returncode == 2 and "material function" in r.stderr


def test_a_call_lowered_without_a_resolver_is_a_compile_error():
    """Validation reports a call nothing can resolve; should lowering ever meet one anyway,
    it is a CompileError on the calling node, not an AttributeError on None."""
    from matedit.compiler.ir import Scope
    from matedit.compiler.lower import CompileError, _Ctx, _Lowerer
    from matedit.graph.validate import analyse
    from matedit.io.document import FileResolver, load
    from matedit.resources import graphs_dir

    doc = load(graphs_dir() / "functions" / "scratches.json")  # calls rotate_uv.json
    checked = analyse(doc, FileResolver(), calls=False)
    low = _Lowerer(_Ctx(None), doc, checked, top=False, scope=Scope("fn"))
    with pytest.raises(CompileError, match="cannot resolve function 'rotate_uv.json' without "
                       "a resolver") as info:
        low.lower()
    assert info.value.diagnostics[0].node_id == "rot"
