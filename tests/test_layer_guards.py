"""The preview's hidden-layer guards (matedit.compiler.schedule.hidden_layer_guards): a layer of
a stack is evaluated only where its blend weight is non-zero in the pixel's quad. The guard is
exact, so the checks are exact: the guarded preview renders bit for bit what the unguarded one
does, and shaders without the preview's define (every export) carry no guard."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

from matedit.compiler import compile_document
from matedit.compiler import ops as cops
from matedit.compiler.emit import PREVIEW_DEFINES, Entry
from matedit.compiler.ir import Op as IROp
from matedit.compiler.ir import Scope, Var
from matedit.compiler.schedule import hidden_layer_guards
from matedit.compiler.targets import TARGETS
from matedit.graph.types import PortType
from matedit.io.document import FileResolver, load
from matedit.resources import graphs_dir

GLSLANG = shutil.which("glslangValidator")
MA = PortType.MATERIAL


def _sample(name: str):
    return compile_document(load(graphs_dir() / "materials" / f"{name}.json"), FileResolver())


def test_worn_steel_guards_its_upper_layers_only_in_the_preview():
    cm = _sample("worn_painted_steel")
    assert "layerShows" not in cm.fragment_text  # the exported FORWARD entry
    assert "layerShows" not in cm.variant(Entry.GBUFFER).fragment_text
    for entry in (Entry.GBUFFER, Entry.FORWARD):
        text = cm.variant(entry, PREVIEW_DEFINES).fragment_text
        guarded = [line for line in text.splitlines() if "if (layerShows(" in line]
        # the paint over the steel, the rust over both; never the base layer (steel)
        assert len(guarded) == 2, guarded
        assert any("fn_rust(" in line and "layerShows(l_stack_rust_w_result)" in line
                   for line in guarded)
        assert not any("fn_chrome(" in line for line in guarded)
        # the rust's weight is computed before the guarded call that reads it
        assert text.index("float l_stack_rust_w_result") < text.index("fn_rust(u_stack")


def test_height_blend_guard_uses_the_blend_weight():
    text = _sample("mossy_stone").variant(Entry.GBUFFER, PREVIEW_DEFINES).fragment_text
    line, = [x for x in text.splitlines() if "if (layerShows(" in x]
    assert "fn_moss(" in line and "heightBlendWeight(" in line


def _call(var: str, outs) -> IROp:
    return IROp(var, var, cops.CALL, [], outs, {"function": f"fn_{var}"})


def _weight(var: str) -> IROp:
    return IROp(var, var, cops.WEIGHT, [], [("result", PortType.FLOAT)])


def test_a_layer_read_twice_or_with_another_output_read_is_not_guarded():
    base, top, w = _call("base", [("attributes", MA)]), _call("top", [("attributes", MA)]), \
        _weight("w")
    blend = IROp("b", "b", cops.BLEND, [base.out("attributes"), top.out("attributes"),
                                        w.out("result")], [("result", MA)])
    scope = Scope("evaluateMaterial", [base, top, w, blend],
                  outputs=[("attributes", MA, blend.out("result"))])
    order, guards = hidden_layer_guards(scope)
    assert list(guards) == [id(top)] and guards[id(top)].args == (w.out("result"),)
    assert order == [base, w, top, blend]  # moved after its weight, just before its blend

    # the layer's attributes also read by another op: evaluated everywhere
    other = IROp("o", "o", cops.BLEND, [top.out("attributes"), base.out("attributes"),
                                        w.out("result")], [("result", MA)])
    scope2 = Scope("evaluateMaterial", [base, top, w, blend, other],
                   outputs=[("attributes", MA, other.out("result"))])
    assert hidden_layer_guards(scope2)[1] == {}

    # a second output of the layer read elsewhere: evaluated everywhere
    top2 = _call("top2", [("attributes", MA), ("height", PortType.FLOAT)])
    blend2 = IROp("b2", "b2", cops.BLEND, [base.out("attributes"), top2.out("attributes"),
                                           w.out("result")], [("result", MA)])
    use_h = IROp("h", "h", cops.WEIGHT, [top2.out("height"), Var("w.result", PortType.FLOAT)],
                 [("result", PortType.FLOAT)])
    scope3 = Scope("evaluateMaterial", [base, top2, w, blend2, use_h],
                   outputs=[("attributes", MA, blend2.out("result"))])
    assert hidden_layer_guards(scope3)[1] == {}


@pytest.mark.parametrize("name", ["worn_painted_steel", "mossy_stone", "varnished_oak",
                                  "oil_slick_metal"])
def test_guarded_preview_renders_the_same_pixels(ctx, name, monkeypatch):
    """Exact (tolerance 0): where a layer is skipped its weight is 0 and the blend gives the
    stack below bit for bit; elsewhere the same code runs."""
    from matedit.render import Renderer, programs

    images = []
    for defines in ((), PREVIEW_DEFINES):
        monkeypatch.setattr(programs, "PREVIEW_DEFINES", defines)
        r = Renderer(ctx, (160, 160))
        try:
            cm = _sample(name)
            r.set_material(cm)
            r.render()
            ctx.finish()
            text = r.programs.drawn_variant(cm, r.is_forward).fragment_text
            assert ("if (layerShows(" in text) == bool(defines)
            images.append(r.read_linear())
        finally:
            r.release()
    assert np.isfinite(images[0]).all()
    np.testing.assert_array_equal(images[0], images[1])


def test_guarded_glsl330_links_on_mesa_and_falls_back_where_refused(ctx, monkeypatch):
    """At GLSL 3.30 the guard's fine derivatives come from GL_ARB_derivative_control, which
    Mesa accepts there; a driver that refuses it gets the variant without guards."""
    from matedit.render.programs import ProgramCache

    cm = _sample("worn_painted_steel")
    cache = ProgramCache(ctx, bind=lambda prog: None)
    _, variant = cache.get(cm, Entry.GBUFFER, PREVIEW_DEFINES)
    assert "if (layerShows(" in variant.fragment_text
    assert "#extension GL_ARB_derivative_control : enable" in variant.fragment_text
    real = ctx.program

    def refuse_guards(vertex_shader, fragment_shader):
        if "layerShows(" in fragment_shader:
            import moderngl

            raise moderngl.Error("dFdxFine: no matching overloaded function found")
        return real(vertex_shader=vertex_shader, fragment_shader=fragment_shader)

    cache2 = ProgramCache(ctx, bind=lambda prog: None)
    monkeypatch.setattr(ctx, "program", refuse_guards)
    _, variant2 = cache2.get(cm, Entry.GBUFFER, PREVIEW_DEFINES)
    assert "layerShows(" not in variant2.fragment_text
    cache.release()
    cache2.release()


@pytest.mark.skipif(GLSLANG is None, reason="glslangValidator not installed (glslang-tools)")
@pytest.mark.parametrize("target", sorted(t for t in TARGETS if t != "glsl330"))
def test_guarded_variants_pass_glslang(target, tmp_path):
    """glsl450 (fine derivatives in core) and essl300 (no fine derivatives: the guard is
    `true`); glslang follows GL_ARB_derivative_control's GLSL 4.00 requirement, so the 3.30
    variant is checked by Mesa's compiler above."""
    cm = compile_document(load(graphs_dir() / "materials" / "worn_painted_steel.json"),
                          FileResolver(), target)
    for entry in (Entry.GBUFFER, Entry.FORWARD):
        text = cm.variant(entry, PREVIEW_DEFINES).fragment_text
        assert "if (layerShows(" in text
        f = tmp_path / f"m.{entry.value}.frag"
        f.write_text(text)
        args = [GLSLANG, str(f)]
        if TARGETS[target].vulkan:
            args += ["-V", "-o", str(tmp_path / "m.spv")]
        r = subprocess.run(args, capture_output=True, text=True)
        assert r.returncode == 0, f"{target} {entry.value}:\n{r.stdout[-3000:]}"


def test_mesa_takes_the_fine_derivative_branch_at_330(ctx):
    """The guard's 3.30 path is live on the preview's driver (else it would evaluate every
    layer and skip nothing): the prelude's define and the extension's macro are both there
    and dFdxFine compiles."""
    from matedit.glsl.include import assemble, derivative_prelude

    body = ("out vec4 color;\nvoid main() {\n"
            "#if defined(MATEDIT_DERIVATIVE_CONTROL) && defined(GL_ARB_derivative_control)\n"
            "    color = vec4(dFdxFine(gl_FragCoord.x));\n#else\n#error no fine derivatives\n"
            "#endif\n}\n")
    asm = assemble(body, version="330 core", includes=[], prelude=derivative_prelude("330 core"))
    ctx.program(vertex_shader="#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n",
                fragment_shader=asm.text).release()
    assert derivative_prelude("450") == "" and derivative_prelude("300 es") == ""


def test_a_material_that_fails_either_way_reports_the_guarded_variants_log(ctx, monkeypatch):
    """The fallback relinks without guards; when that fails too, the error raised is the
    guarded variant's, so the caller locates it in the text it holds (ProgramCache.link)."""
    import moderngl

    from matedit.render.programs import ProgramCache

    cm = _sample("worn_painted_steel")
    cache = ProgramCache(ctx, bind=lambda prog: None)
    tried = []

    def refuse_all(vertex_shader, fragment_shader):
        tried.append("layerShows(" in fragment_shader)
        raise moderngl.Error("guarded" if tried[-1] else "unguarded")

    monkeypatch.setattr(ctx, "program", refuse_all)
    with pytest.raises(moderngl.Error, match="^guarded$"):
        cache.get(cm, Entry.GBUFFER, PREVIEW_DEFINES)
    assert tried == [True, False]
