"""Layer blend modes beyond alpha and height: `coat` (a layer laid over the stack as a clear
coat) and the catalogue's colour blends (a layer's base colour composited by a Blend node).

The coat blend is checked against a reference written here from its definition (coverage of
independent presences, the new coat's share of it), its GPU code against its CPU twin, the
fields it writes (so MATERIAL_HAS_COAT and the others are defined), and a stack with a coat
layer over a sample's compiles on every target and passes glslang, spirv-val and the HLSL
re-compile. Every blend mode the Layers panel lists compiles and renders, GPU = CPU.
"""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from gpu_eval import gpu_eval_many
from material_gpu import render_attributes, surface

from matedit.compiler import compile_document
from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.graph import nodes
from matedit.graph.layers import Layer, LayerStack
from matedit.graph.ports import COLOR_LAYER_BLENDS, LAYER_BLENDS
from matedit.io.document import FileResolver, load
from matedit.nodes.material import coat_material_attributes
from matedit.resources import graphs_dir

GLSLANG = shutil.which("glslangValidator")
SAMPLE = graphs_dir() / "materials" / "rusty_painted_metal.json"
VARNISH = str((graphs_dir() / "layers" / "varnish.json").resolve())
DEFAULTS = {f.name: f.default for f in nodes.ATTRIBUTE_FIELDS}


def _defaults(n: int) -> dict[str, np.ndarray]:
    return {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (n,) + np.shape(v)).copy()
            for k, v in DEFAULTS.items()}


def _f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _coated_sample(blend: str = "coat"):
    """The sample's stack with a varnish layer on top in `blend` mode, its mask wired."""
    doc = load(SAMPLE)
    stack = LayerStack.find(doc.graph, FileResolver(), doc)
    stack.add(Layer("varnish", VARNISH, "Varnish", blend=blend)).apply(doc.graph)
    return doc, stack


def test_every_mode_is_listed():
    assert LAYER_BLENDS[:3] == ("alpha", "height", "coat")
    # the catalogue's 11 colour blends (blend_normals takes normals, not base / blend colours)
    assert set(COLOR_LAYER_BLENDS) == {
        "multiply", "screen", "overlay", "soft_light", "add", "subtract", "difference",
        "dodge", "burn", "lighten", "darken"}
    for mode in COLOR_LAYER_BLENDS:
        assert f"blend_{mode}" in nodes.REGISTRY


def test_coat_blend_follows_its_definition():
    """Reference from the definition: coat weight by coverage, 1 - (1 - a)(1 - w); the coat
    fields move to the layer's by the new coat's share w / (w + (1 - w) a); nothing else."""
    rng = np.random.default_rng(3)
    n = 64
    base, layer = _defaults(n), _defaults(n)
    for m in (base, layer):
        for k in ("baseColor", "coatColor", "emissive"):
            m[k] = rng.uniform(0, 1, (n, 3))
        for k in ("roughness", "metallic", "coat", "coatRoughness", "sheenRoughness"):
            m[k] = rng.uniform(0, 1, n)
        m["ior"] = rng.uniform(1.0, 2.5, n)
        m["coatIor"] = rng.uniform(1.0, 2.5, n)
        m["normal"] = _unit(rng.uniform(-1, 1, (n, 3)) + (0, 0, 2))
        m["coatNormal"] = _unit(rng.uniform(-1, 1, (n, 3)) + (0, 0, 2))
    w = rng.uniform(0, 1, n)
    w[:3] = (0.0, 1.0, 0.5)
    base["coat"][2] = 0.0  # no coat below: the layer's fields exactly
    got = coat_material_attributes(base, layer, w)
    a = base["coat"]
    cover = w + (1 - w) * a
    share = np.where(cover > 0, w / np.where(cover > 0, cover, 1), 0.0)
    np.testing.assert_allclose(got["coat"], 1 - (1 - a) * (1 - w), atol=1e-12)
    np.testing.assert_allclose(got["coat"], cover, atol=1e-12)  # the same union, two ways
    np.testing.assert_allclose(got["coatRoughness"],
                               base["coatRoughness"] * (1 - share)
                               + layer["roughness"] * share, atol=1e-12)
    np.testing.assert_allclose(got["coatColor"], base["coatColor"] * (1 - share[:, None])
                               + layer["baseColor"] * share[:, None], atol=1e-12)
    np.testing.assert_allclose(got["coatIor"], base["coatIor"] * (1 - share)
                               + layer["ior"] * share, atol=1e-12)
    want_n = _unit(base["coatNormal"] * (1 - share[:, None])
                   + layer["normal"] * share[:, None])
    np.testing.assert_allclose(got["coatNormal"], want_n, atol=1e-12)
    for k in DEFAULTS:  # the base's own fields are untouched
        if not k.startswith("coat"):
            np.testing.assert_array_equal(got[k], base[k], err_msg=k)
    # w = 0 keeps the stack as it was; w = 1 is the layer's coat; no coat below: the layer's
    for k in ("coat", "coatRoughness", "coatIor"):
        assert got[k][0] == base[k][0], k
    assert got["coat"][1] == 1.0 and got["coatRoughness"][1] == layer["roughness"][1]
    assert got["coatRoughness"][2] == pytest.approx(layer["roughness"][2], abs=1e-15)
    np.testing.assert_allclose(got["coatColor"][2], layer["baseColor"][2], atol=1e-15)


@pytest.mark.gl
def test_coat_blend_on_the_gpu_equals_the_cpu_twin(ctx):
    rng = np.random.default_rng(11)
    n = 256
    ins = {
        "b_coat": _f32(rng.uniform(0, 1, n)), "b_coatRoughness": _f32(rng.uniform(0, 1, n)),
        "b_coatColor": _f32(rng.uniform(0, 1, (n, 3))),
        "b_coatIor": _f32(rng.uniform(1, 2.5, n)),
        "b_coatNormal": _f32(_unit(rng.uniform(-1, 1, (n, 3)) + (0, 0, 1.5))),
        "b_roughness": _f32(rng.uniform(0, 1, n)),
        "l_roughness": _f32(rng.uniform(0, 1, n)), "l_baseColor": _f32(rng.uniform(0, 1, (n, 3))),
        "l_ior": _f32(rng.uniform(1, 2.5, n)),
        "l_normal": _f32(_unit(rng.uniform(-1, 1, (n, 3)) + (0, 0, 1.5))),
        "w": _f32(rng.uniform(0, 1, n)),
    }
    ins["w"][:4] = (0.0, 1.0, 0.0, 1.0)
    ins["b_coat"][2:4] = 0.0
    base, layer = _defaults(n), _defaults(n)
    for k, v in ins.items():
        if k != "w":
            side, name = k.split("_", 1)
            (base if side == "b" else layer)[name] = v
    cpu = coat_material_attributes(base, layer, ins["w"])
    outs = {"o_coat": "float", "o_coatRoughness": "float", "o_coatColor": "vec3",
            "o_coatIor": "float", "o_coatNormal": "vec3", "o_roughness": "float"}
    body = ("MaterialAttributes b = defaultMaterialAttributes(); "
            "MaterialAttributes l = defaultMaterialAttributes(); " +
            " ".join(f"{k[0]}.{k[2:]} = {k};" for k in ins if k != "w") +
            " MaterialAttributes r = coatMaterialAttributes(b, l, w); " +
            " ".join(f"{o} = r.{o[2:]};" for o in outs))
    got = gpu_eval_many(ctx, body, ins, outs, includes=["nodes/layer_blend.glsl"])
    for o in outs:
        # a few float32 products, one division by a coverage >= w and one normalisation on
        # values in [0, 2.5]: 2e-6 absolute (float64 twin from float32 inputs)
        np.testing.assert_allclose(got[o], cpu[o[2:]], rtol=0, atol=2e-6, err_msg=o)


def test_coat_layer_writes_the_coat_fields():
    """The varnish layer writes base colour and roughness: the coat writes weight, roughness
    and tint; no normal and no IOR in the layer, so coatNormal and coatIor stay compiled out,
    and the stack's own fields are still written (the paint and rust below)."""
    doc, _ = _coated_sample()
    ir = lower_document(doc, FileResolver())
    below = set(lower_document(load(SAMPLE), FileResolver()).attributes)
    assert set(ir.attributes) == below | {"coat", "coatRoughness", "coatColor"}
    cm = compile_document(doc, FileResolver(), "glsl330")
    for d in ("COAT", "COAT_ROUGHNESS", "COAT_COLOR"):
        assert f"#define MATERIAL_HAS_{d} 1" in cm.fragment_text
    for d in ("COAT_NORMAL", "COAT_IOR"):
        assert f"#define MATERIAL_HAS_{d} 1" not in cm.fragment_text
    # a coat layer that writes a normal (the rust layer has a bump) writes coatNormal too
    doc2 = load(SAMPLE)
    stack = LayerStack.find(doc2.graph, FileResolver(), doc2)
    stack.set("rust", blend="coat").apply(doc2.graph)
    ir2 = lower_document(doc2, FileResolver())
    assert "coatNormal" in ir2.attributes and "coat" in ir2.attributes


def test_sample_varnished_oak_is_a_coat_over_the_oak():
    doc = load(graphs_dir() / "materials" / "varnished_oak.json")
    assert doc.name == "Varnished Oak"
    stack = LayerStack.find(doc.graph, FileResolver(), doc)
    assert [(l.id, l.blend) for l in stack.layers] == [("oak", "alpha"), ("varnish", "coat")]
    ir = lower_document(doc, FileResolver())
    assert {"coat", "coatRoughness", "coatColor", "normal"} <= set(ir.attributes)
    a = evaluate(ir, surface(8, 8))
    np.testing.assert_allclose(a["coat"], 1.0)  # varnish_amount 1, mask 1: fully coated
    np.testing.assert_allclose(a["coatRoughness"], 0.06, atol=1e-7)
    np.testing.assert_allclose(a["coatColor"], np.broadcast_to([0.93, 0.78, 0.52], (64, 3)),
                               atol=1e-7)
    # the oak's own grain and roughness are left below the film, not averaged with it
    oak = evaluate(lower_document(load(graphs_dir() / "materials" / "oak_planks.json"),
                                  FileResolver()), surface(8, 8))
    for k in ("baseColor", "roughness", "normal"):
        np.testing.assert_allclose(a[k], oak[k], atol=1e-12, err_msg=k)


@pytest.mark.skipif(GLSLANG is None or not shutil.which("spirv-val")
                    or not shutil.which("spirv-cross"),
                    reason="glslang-tools, spirv-tools or spirv-cross missing")
def test_coat_over_the_sample_stack_compiles_on_all_five_targets(tmp_path):
    from matedit.compiler.targets import CROSS_TARGETS, TARGETS
    from matedit.interop import cross
    from matedit.interop.export import compile_targets

    doc, _ = _coated_sample()  # the varnish's mask and opacity at 1: a full coat
    out = compile_targets(doc, FileResolver(), [*TARGETS, *CROSS_TARGETS])
    assert set(out) == {*TARGETS, *CROSS_TARGETS}
    for name in TARGETS:
        cm = out[name]
        assert "coatMaterialAttributes(" in cm.fragment_text
        for stage, text in (("vert", cm.vertex_text), ("frag", cm.fragment_text)):
            f = tmp_path / f"m.{name}.{stage}"
            f.write_text(text)
            args = [GLSLANG, str(f)]
            if TARGETS[name].vulkan:
                spv = tmp_path / f"{name}.{stage}.spv"
                args += ["-V", "-o", str(spv)]
            r = subprocess.run(args, capture_output=True, text=True)
            assert r.returncode == 0, f"{name} {stage}:\n{r.stdout[-3000:]}"
            if TARGETS[name].vulkan:
                r = subprocess.run(["spirv-val", str(spv)], capture_output=True, text=True)
                assert r.returncode == 0, r.stderr
    cross.check_hlsl(out["hlsl"])  # HLSL compiled back to SPIR-V and validated
    assert "fragment" in out["msl"].bindings


@pytest.mark.gl
@pytest.mark.parametrize("mode", [b for b in LAYER_BLENDS if b != "height"])
def test_each_listed_mode_compiles_and_renders_gpu_equals_cpu(ctx, mode):
    """The sample's rust layer switched to each mode (height has its own sample, mossy
    stone): compiles, links on llvmpipe, and the attributes it renders equal the CPU
    evaluator's (the tolerance of tests/test_compiler_gpu.py: float32 against float64
    through the layers' noise, 2e-3 at the 99.5th percentile)."""
    doc = load(SAMPLE)
    stack = LayerStack.find(doc.graph, FileResolver(), doc)
    stack.set("rust", blend=mode).apply(doc.graph)
    resolver = FileResolver()
    cm = compile_document(doc, resolver, "glsl330", mode="attributes")
    if mode in COLOR_LAYER_BLENDS:
        assert f"node_blend_{mode}(" in cm.fragment_text
    gpu = render_attributes(ctx, cm, 32, 32)
    cpu = evaluate(lower_document(doc, resolver), surface(32, 32))
    for field, g in gpu.items():
        c = np.asarray(cpu[field], dtype=np.float64).reshape(g.shape)
        assert np.all(np.isfinite(g)), field
        err = np.abs(g - c)
        err = err.max(axis=1) if err.ndim == 2 else err
        assert np.percentile(err, 99.5) < 2e-3, f"{mode} {field}"
    plain = evaluate(lower_document(load(SAMPLE), resolver), surface(32, 32))
    if mode in COLOR_LAYER_BLENDS:
        # the colour is the Blend node's of the rust over the paint, mixed by the weight
        # the alpha blend uses; roughness is the alpha blend's exactly
        np.testing.assert_allclose(cpu["roughness"], plain["roughness"], atol=1e-12)
        assert not np.allclose(cpu["baseColor"], plain["baseColor"], atol=1e-3)
    if mode == "coat":
        assert np.any(cpu["coat"] > 0.1)
