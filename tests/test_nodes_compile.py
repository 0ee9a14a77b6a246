"""Every node kind, called alone as the compiler calls it (its GLSL function with the port
types of the catalogue, or its inline template), compiles on llvmpipe (GLSL 330) and
through glslangValidator for GLSL 330, Vulkan GLSL 450 (to SPIR-V) and ESSL 300. The node
files compiling on their own is tests/test_shading_compile.py; this checks the calls."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from matedit.compiler.cpu_nodes import COMPILER_HANDLED
from matedit.glsl.include import assemble
from matedit.graph.nodes import GENERIC, REGISTRY
from tests.test_shading_compile import _VERTEX, TARGETS

KINDS = sorted(k for k in REGISTRY if k not in COMPILER_HANDLED)
_VALUE = {"float": "0.25", "vec2": "vec2(0.25)", "vec3": "vec3(0.25)", "vec4": "vec4(0.25)"}
_SUM = {"float": "vec4({})", "vec2": "vec4({}, 0.0, 0.0)", "vec3": "vec4({}, 0.0)",
        "vec4": "{}"}


def _call(kind: str, generic: str, target: str) -> tuple[str, list[str]]:
    """A fragment main() calling `kind` with T = `generic`; returns (body, includes)."""
    d = REGISTRY[kind]
    decls, names = [], {}
    for i, p in enumerate(d.inputs + d.values):  # a parameter node is called with its value
        t = generic if p.type == GENERIC else p.type
        if t == "texture2d":
            names[p.name] = "u_tex"
            continue
        if t == "MaterialAttributes":
            decls.append(f"    MaterialAttributes i_{p.name} = defaultMaterialAttributes();")
        else:
            decls.append(f"    {t} i_{p.name} = {_VALUE[t]} + float({i}) * 0.01;")
        names[p.name] = f"i_{p.name}"
    outs = [(f"o_{o.name}", generic if o.type == GENERIC else o.type) for o in d.outputs]
    decls += [f"    {t} {n};" for n, t in outs]
    if d.glsl:
        decls.append(f"    {d.glsl}({', '.join([*names.values(), *(n for n, _ in outs)])});")
        includes = [f"nodes/{kind}.glsl"]
    else:
        decls.append(f"    {outs[0][0]} = {d.inline.format(**names)};")
        includes = []
    terms = [_SUM[t].format(n) if t in _SUM else f"{n}.baseColor.xyzz" for n, t in outs]
    sampler = ("layout(binding = 0) uniform sampler2D u_tex;" if target == "glsl450"
               else "uniform sampler2D u_tex;")
    out_decl = TARGETS[target][2]
    body = "\n".join([sampler, out_decl, "void main() {", *decls,
                      f"    color = {' + '.join(terms) or 'vec4(0.0)'};", "}"])
    return body, ["common.glsl", "material.glsl", "nodes/context.glsl", *includes]


def _cases():
    for kind in KINDS:
        generic = any(p.type == GENERIC for p in REGISTRY[kind].inputs)
        for t in (("float", "vec3") if generic else ("float",)):
            yield kind, t


CASES = list(_cases())


def _assembled(kind, generic, target):
    version, prelude, _, _ = TARGETS[target]
    body, includes = _call(kind, generic, target)
    return assemble(body, version=version, includes=includes, prelude=prelude)


@pytest.mark.gl
@pytest.mark.parametrize(("kind", "generic"), CASES)
def test_kind_compiles_alone_on_llvmpipe(ctx, kind, generic):
    asm = _assembled(kind, generic, "glsl330")
    try:
        ctx.program(vertex_shader=_VERTEX, fragment_shader=asm.text).release()
    except Exception as exc:
        pytest.fail(asm.map_log(str(exc)))


@pytest.mark.parametrize("target", sorted(TARGETS))
@pytest.mark.parametrize(("kind", "generic"), CASES)
def test_kind_compiles_alone_in_glslang(tmp_path, kind, generic, target):
    exe = shutil.which("glslangValidator")
    if exe is None:
        pytest.skip("glslangValidator is not installed: cannot check 450 / ES 300 targets")
    asm = _assembled(kind, generic, target)
    src = tmp_path / f"{kind}.{generic}.{target}.frag"
    src.write_text(asm.text)
    args = [exe, *TARGETS[target][3], str(src)]
    if "-V" in args:
        args += ["-o", str(tmp_path / "out.spv")]
    run = subprocess.run(args, capture_output=True, text=True)
    assert run.returncode == 0, asm.map_log(run.stdout + run.stderr)
