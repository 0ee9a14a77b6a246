"""The MaterialAttributes fields beyond the talk (specular colour, IOR, coat, sheen,
anisotropy): at their defaults they compile out and change nothing; written, they reach the
shading; their blends on the GPU equal the CPU evaluator's; moving a lobe input off its
default is one structural edit.

References are written here from the definitions (Fresnel at normal incidence,
((n - 1) / (n + 1))^2), not taken from matedit.shading.
"""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import link, node, simple_material

from matedit.compiler import compile_document
from matedit.graph import nodes
from matedit.graph.commands import SetValue
from matedit.graph.model import ChangeKind
from matedit.io.document import FileResolver
from matedit.nodes.material import blend_material_attributes
from tests.gpu_eval import gpu_eval_many

LOBE_FIELDS = [f for f in nodes.ATTRIBUTE_FIELDS if f.lobe]
BASE_FIELDS = [f for f in nodes.ATTRIBUTE_FIELDS if not f.lobe]


def _compiled(doc):
    return compile_document(doc, FileResolver(), "glsl330")


def test_the_talks_seven_fields_come_first_and_every_lobe_field_has_a_group():
    assert [f.name for f in BASE_FIELDS] == ["baseColor", "metallic", "roughness", "cavity",
                                             "normal", "emissive", "opacity"]
    assert nodes.ATTRIBUTE_NAMES[:7] == tuple(f.name for f in BASE_FIELDS)
    assert {f.group for f in BASE_FIELDS} == {"Base"}
    assert {f.group for f in LOBE_FIELDS} == {"Specular", "Coat", "Sheen", "Anisotropy",
                                              "Subsurface", "Thin film", "Transmission"}


def test_lobe_inputs_left_at_their_defaults_compile_out_with_no_uniform():
    cm = _compiled(simple_material())
    names = [u["name"] for u in cm.reflection()["uniforms"]]
    for f in LOBE_FIELDS:
        assert f"u_make_{f.name}" not in names
    assert not {f.name for f in LOBE_FIELDS} & set(cm.ir.attributes)
    for define in ("COAT", "IOR", "SPECULAR_COLOR", "SHEEN_COLOR", "ANISOTROPY"):
        assert f"#define MATERIAL_HAS_{define} 1" not in cm.fragment_text


@pytest.mark.parametrize("field", [f.name for f in LOBE_FIELDS])
def test_a_lobe_input_off_its_default_is_written_and_a_uniform(field):
    d = simple_material()
    fd = next(f for f in LOBE_FIELDS if f.name == field)
    value = 0.7 if fd.type == "float" else [0.2, 0.6, 0.3]
    d.graph.nodes["make"].values[field] = value
    cm = _compiled(d)
    assert field in cm.ir.attributes
    u = {x["name"]: x for x in cm.reflection()["uniforms"]}
    assert u[f"u_make_{field}"]["default"] == pytest.approx(value)
    define = "MATERIAL_HAS_" + "".join("_" + c if c.isupper() else c.upper() for c in field)
    assert f"#define {define} 1" in cm.fragment_text


def test_a_connected_lobe_input_is_written_whatever_its_value():
    d = simple_material()
    node(d, "c", "scalar_parameter", {"name": "coat"}, {"value": 0.0})
    link(d, "c", "value", "make", "coat")
    assert "coat" in _compiled(d).ir.attributes


def _kinds(doc, command):
    seen = []
    doc.graph.subscribe(lambda e: seen.append(e.kind))
    command.apply(doc.graph)
    return seen


def test_moving_a_lobe_input_off_or_back_to_its_default_is_structural_else_a_value():
    d = simple_material()
    assert _kinds(d, SetValue("make", "coat", 0.5)) == [ChangeKind.STRUCTURAL]
    assert _kinds(d, SetValue("make", "coat", 0.8)) == [ChangeKind.VALUE]
    undo = SetValue("make", "coat", 0.0)
    assert _kinds(d, undo) == [ChangeKind.STRUCTURAL]
    seen = []
    d.graph.subscribe(lambda e: seen.append(e.kind))
    undo.revert(d.graph)  # back to 0.8: the coat compiles in again
    assert seen == [ChangeKind.STRUCTURAL]
    # a vector lobe input, and a talk field (always a uniform)
    assert _kinds(d, SetValue("make", "sheenColor", [0.1, 0.1, 0.1])) == [ChangeKind.STRUCTURAL]
    assert _kinds(d, SetValue("make", "metallic", 0.3)) == [ChangeKind.VALUE]


def test_a_lobe_value_that_is_not_a_number_counts_as_written():
    n = nodes.REGISTRY["make_attributes"]
    from matedit.graph.model import Node

    fd = next(f for f in n.inputs if f.name == "ior")
    assert nodes.lobe_value_is_default(Node("m", "make_attributes"), fd)
    assert not nodes.lobe_value_is_default(Node("m", "make_attributes", values={"ior": "x"}), fd)
    assert nodes.lobe_value_is_default(Node("m", "make_attributes", values={"ior": 1.5}), fd)


# --- the GPU against the definitions and the CPU evaluator --------------------------------
def _f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


@pytest.mark.gl
def test_material_f0_from_ior_and_specular_colour_on_the_gpu(ctx):
    rng = np.random.default_rng(3)
    n = 512
    ior = _f32(rng.uniform(1.0, 3.0, n))
    ior[:3] = (1.5, 1.0, 3.0)
    spec = _f32(rng.uniform(0.0, 1.0, (n, 3)))
    spec[0] = 1.0
    base = _f32(rng.uniform(0.0, 1.0, (n, 3)))
    metal = _f32(rng.uniform(0.0, 1.0, n))
    metal[:3] = 0.0
    inputs = {"ior": ior, "spec": spec, "base": base, "metal": metal}
    body = ("MaterialAttributes m = defaultMaterialAttributes(); m.ior = ior; "
            "m.specularColor = spec; m.baseColor = base; m.metallic = metal; "
            "f0 = materialF0(m); talk = computeF0(base, metal);")
    outs = {"f0": "vec3", "talk": "vec3"}
    plain = gpu_eval_many(ctx, body, inputs, outs, includes=["material.glsl"])
    # Without MATERIAL_HAS_IOR the talk's 0.04 is compiled in: exactly computeF0.
    np.testing.assert_array_equal(plain["f0"], plain["talk"])
    got = gpu_eval_many(ctx, body, inputs, outs, includes=["material.glsl"],
                        defines=("MATERIAL_HAS_IOR",))["f0"]
    r = (ior - 1.0) / (ior + 1.0)
    dielectric = np.minimum(r[:, None] ** 2 * spec, 1.0)
    want = (1 - metal[:, None]) * dielectric + metal[:, None] * base
    # float32 arithmetic of a few operations on values <= 1: 2e-7 absolute
    np.testing.assert_allclose(got, want, rtol=0, atol=2e-7)
    assert abs(got[0, 0] - 0.04) < 1e-8  # ior 1.5, white: the talk's dielectric F0
    assert got[1, 0] == 0.0  # ior 1: no reflection at normal incidence
    assert abs(got[2, 0] - 0.25 * spec[2, 0]) < 1e-7  # ior 3: (2 / 4)^2


@pytest.mark.gl
def test_blending_two_attribute_structs_on_the_gpu_equals_the_cpu_evaluator(ctx):
    """The lobe fields blend like the talk's (lerp; the coat normal and the anisotropy
    direction by nlerp). The talk's fields stay at their defaults here: one texture an input,
    and GL guarantees only 16 units."""
    rng = np.random.default_rng(5)
    n = 256
    vals = {}
    for side in "ab":
        for f in LOBE_FIELDS:
            k = 3 if f.type == "vec3" else 1
            lo = -1.0 if f.name in ("coatNormal", "anisotropyDirection") else 0.0
            v = _f32(rng.uniform(lo, 1.0, (n, k)))
            vals[f"{side}_{f.name}"] = v if k == 3 else v[:, 0]
    t = _f32(rng.uniform(0.0, 1.0, n))
    t[:2] = (0.0, 1.0)
    defaults = nodes.ATTRIBUTE_FIELDS
    cpu = blend_material_attributes(
        *({f.name: vals.get(f"{s}_{f.name}", np.broadcast_to(
            np.asarray(f.default, dtype=np.float64), (n,) + np.shape(f.default)))
           for f in defaults} for s in "ab"), t)
    for chunk in [LOBE_FIELDS[i:i + 6] for i in range(0, len(LOBE_FIELDS), 6)]:
        inputs = {k: v for k, v in vals.items() if k.split("_", 1)[1] in
                  {f.name for f in chunk}} | {"t": t}
        body = ("MaterialAttributes a = defaultMaterialAttributes(); "
                "MaterialAttributes b = defaultMaterialAttributes(); " +
                " ".join(f"{s}.{f.name} = {s}_{f.name};" for s in "ab" for f in chunk) +
                " MaterialAttributes r = blendMaterialAttributes(a, b, t); " +
                " ".join(f"o_{f.name} = r.{f.name};" for f in chunk))
        out = gpu_eval_many(ctx, body, inputs, {f"o_{f.name}": f.type for f in chunk},
                            includes=["nodes/layer_blend.glsl"])
        for f in chunk:
            # a lerp and a normalisation in float32: 1e-6 absolute on values in [-1, 1]
            np.testing.assert_allclose(out[f"o_{f.name}"], cpu[f.name], rtol=0, atol=1e-6,
                                       err_msg=f.name)
