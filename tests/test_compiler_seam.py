"""The compiler's back-end seam: GLSL lives only in the GLSL back-end (and the ops table's
`glsl` column), graph/ knows no GLSL, and the emitter and the CPU evaluator dispatch every op
from the one table in matedit/compiler/ops.py."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

import matedit
from matedit.compiler import cpu_eval, ops
from matedit.compiler.emit import fragment_source
from matedit.compiler.ir import Lit, MaterialIR, Op, Scope, SurfaceUV
from matedit.compiler.schedule import schedule
from matedit.compiler.targets import TARGETS
from matedit.graph import nodes
from matedit.graph.types import PortType

PKG = Path(matedit.__file__).resolve().parent
COMPILER = PKG / "compiler"
BACK_END = COMPILER / "glsl_backend.py"

# What only GLSL text contains: its vector, matrix and sampler type names, preprocessor lines,
# qualifiers, and the shading library's names the generated code calls. (The file format
# spells port types as GLSL does, "vec3": those spellings belong to graph/types.py, and the
# compiler names types by PortType, never by string.)
GLSL = re.compile(r"\b(?:[iu]?vec[234]|mat[234]|sampler2D|samplerCube)\b|#\s*(?:define|version)"
                  r"|\blayout\s*\(|\bprecision\s+highp\b|\)\s*uniform\b|\bout\s+\w+\s+\w"
                  r"|defaultMaterialAttributes|blendMaterialAttributes|g_surface\.")


def _docstrings(tree: ast.AST) -> set[int]:
    ids = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = n.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                ids.add(id(body[0].value))
    return ids


def glsl_strings(path: Path) -> list[tuple[int, str]]:
    """String constants of a module that read as GLSL (docstrings aside; in the ops table the
    `glsl=` column is the GLSL back-end's own)."""
    tree = ast.parse(path.read_text(), str(path))
    skip = _docstrings(tree)
    for n in ast.walk(tree):
        if isinstance(n, ast.keyword) and n.arg == "glsl" and isinstance(n.value, ast.Constant):
            skip.add(id(n.value))
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in skip
            and GLSL.search(n.value)]


def test_the_scan_finds_glsl_in_the_back_end():
    # the pattern is not blind: the back-end writes type names, declarations and defines
    found = " ".join(s for _, s in glsl_strings(BACK_END))
    for needle in ("vec3", "sampler2D", "#define", "layout(", "defaultMaterialAttributes"):
        assert needle in found


@pytest.mark.parametrize("path", sorted(p for p in COMPILER.glob("*.py") if p != BACK_END),
                         ids=lambda p: p.name)
def test_no_glsl_outside_the_back_end(path):
    assert glsl_strings(path) == []


def test_graph_knows_no_glsl_type_names():
    # the port types keep their file spellings; the GLSL names are the back-end's
    assert not hasattr(PortType.VEC3, "glsl")
    assert "sampler2D" not in (PKG / "graph" / "types.py").read_text()


def _one_op_ir(op: Op) -> MaterialIR:
    scope = Scope("evaluateMaterial", source="<test>")
    scope.ops.append(op)
    set_op = Op("s", "s", ops.op_kind(ops.SET_ATTRIBUTES),
                [Lit(None, PortType.MATERIAL), op.out("result")],
                [("attributes", PortType.MATERIAL)], {"fields": ("roughness",)})
    scope.ops.append(set_op)
    scope.outputs.append(("attributes", PortType.MATERIAL, set_op.out("attributes")))
    return MaterialIR(scope, [], [], [], set(), ["roughness"])


def test_a_new_table_row_reaches_both_the_emitter_and_the_evaluator(monkeypatch):
    # One row, read by both sides: a made-up op emits its template and evaluates its numpy.
    row = ops.OpImpl("test_negate_u", lambda op, args, env: (-args[0][:, 0],), glsl="(-{0}.x)")
    monkeypatch.setitem(ops._CACHE, row.kind, row)
    op = Op("n", "n", row.kind, [SurfaceUV()], [("result", PortType.FLOAT)])
    ir = _one_op_ir(op)
    asm, smap = fragment_source(ir, TARGETS["glsl330"], "attributes")
    assert "float l_n_result = (-g_surface.uv.x);" in asm.text
    assert "MaterialAttributes l_s_attributes = defaultMaterialAttributes(); " \
           "l_s_attributes.roughness = l_n_result;" in asm.text
    assert ("n", "<test>") in smap.lines.values()

    uv = np.array([[0.25, 0.5], [0.75, 1.0]])
    surface = type("S", (), {"uv": uv})()
    attrs = cpu_eval.evaluate(ir, surface)
    assert np.array_equal(attrs["roughness"], -uv[:, 0])  # exact: one negation


def test_every_op_of_the_samples_has_a_row_with_both_columns():
    from matedit.compiler.api import lower_and_optimise
    from matedit.io.document import FileResolver
    from matedit.io.instance import load_effective
    from matedit.resources import graphs_dir

    seen = set()
    for path in sorted((graphs_dir() / "materials").glob("*.json")):
        doc, _ = load_effective(path)
        ir = lower_and_optimise(doc, FileResolver())
        for scope in [ir.main, *ir.functions]:
            for op in scope.ops:
                impl = ops.implementation(op.kind)
                assert callable(impl.numpy)
                # GLSL: the row's template, the kind's definition (a template or a
                # function), or the op's data names the material function it calls
                d = nodes.get(op.kind)
                assert impl.glsl or (d is not None and (d.inline or d.glsl)) \
                    or op.data.get("function"), op.kind
                seen.add(op.kind)
    assert {ops.BLEND, ops.WEIGHT, ops.CALL, ops.MASK} <= seen  # the samples use the builtins


def test_builtin_numpy_column_matches_its_definition():
    # mask and append against direct indexing; weight against saturate(mask * opacity)
    v = np.arange(12.0).reshape(3, 4)
    (m,) = ops.BUILTINS[ops.MASK].numpy(Op("m", "m", ops.MASK, [], [], {"channels": "wx"}),
                                        [v], None)
    assert np.array_equal(m, v[:, [3, 0]])
    (a,) = ops.BUILTINS[ops.APPEND].numpy(Op("a", "a", ops.op_kind(ops.APPEND), [], []),
                                          [v[:, :2], v[:, 2]], None)
    assert np.array_equal(a, v[:, :3])
    mask, opacity = np.array([0.5, 2.0, -1.0]), np.array([0.5, 0.75, 1.0])
    (w,) = ops.BUILTINS[ops.WEIGHT].numpy(Op("w", "w", ops.WEIGHT, [], []), [mask, opacity], None)
    assert np.array_equal(w, [0.25, 1.0, 0.0])


def test_schedule_holds_no_text_and_names_locals_in_first_use_order():
    a = Op("a_b", "x", "add", [Lit(1.0, PortType.FLOAT), SurfaceUV()], [("c", PortType.VEC2)])
    b = Op("a", "y", "add", [a.out("c"), a.out("c")], [("b_c", PortType.VEC2)])
    scope = Scope("evaluateMaterial", [a, b], outputs=[])
    plan = schedule(MaterialIR(scope, [], [], [], {"add"}, []), "attributes")
    (main,) = plan.scopes
    # node a_b port c and node a port b_c meet at l_a_b_c: the first named keeps it
    assert [outs for _, outs in main.steps] == [[("l_a_b_c", PortType.VEC2)],
                                                [("l_a_b_c_2", PortType.VEC2)]]
    assert plan.units == ["common", "material", "nodes/context"]
