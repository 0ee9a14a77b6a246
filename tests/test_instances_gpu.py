"""Instances on the GPU: the instance's shaders evaluate like the CPU evaluator with the
instance's values, differ from the parent only where an override changes a value, and static
switch permutations are cached by structure hash."""

from __future__ import annotations

import numpy as np
import pytest
from material_gpu import render_attributes, surface

from matedit.compiler import compile_document
from matedit.compiler.cpu_eval import evaluate
from matedit.compiler.lower import lower_document
from matedit.io import document as fmt
from matedit.io.document import FileResolver
from matedit.io.instance import InstanceDocument, load_instance, resolve
from matedit.resources import graphs_dir

MASTER = graphs_dir() / "materials" / "worn_painted_steel.json"
INSTANCES = graphs_dir() / "instances"
# As tests/test_compiler_gpu.py: float32 GPU against float64 numpy through transcendental
# chains, 2e-3 on the 99.5th percentile of per-pixel error (hard pattern edges may flip).
TOL = 2e-3
W = H = 48

pytestmark = pytest.mark.gl


def _attrs(ctx, doc, resolver):
    cm = compile_document(doc, resolver, "glsl330", mode="attributes")
    gpu = render_attributes(ctx, cm, W, H)
    cpu = evaluate(lower_document(doc, resolver), surface(W, H))
    cpu = {k: np.asarray(cpu[k], np.float64).reshape(g.shape) for k, g in gpu.items()}
    return cm, gpu, cpu


def _err(a, b):
    e = np.abs(a - b)
    return e.max(axis=1) if e.ndim == 2 else e


def test_instance_differs_from_parent_exactly_where_the_override_acts(ctx):
    resolver = FileResolver()
    parent = fmt.load(MASTER)
    only_colour = InstanceDocument(parent=MASTER.name, path=MASTER.with_name("_probe.json"),
                                   parameters={"paint_color": [0.9, 0.1, 0.05]})
    r = resolve(only_colour)
    assert r.problems == []
    pcm, pg, pc = _attrs(ctx, parent, resolver)
    icm, ig, ic = _attrs(ctx, r.document, resolver)
    assert icm.structure_hash == pcm.structure_hash  # one program serves both
    for field in ig:  # each evaluates like the CPU with its own values
        assert np.percentile(_err(ig[field], ic[field]), 99.5) < TOL, field
    # The CPU says where paint shows (base colour moved); the GPU differs there and only
    # there, and no other attribute moves at all.
    cpu_moved = _err(ic["baseColor"], pc["baseColor"]) > 1e-2
    gpu_moved = _err(ig["baseColor"], pg["baseColor"]) > 1e-2
    # (On the flat UV grid the curvature wear of the master finds no edges, so paint may
    # cover every pixel: the check is that the GPU moves exactly where the CPU does.)
    assert cpu_moved.mean() > 0.05
    assert (cpu_moved == gpu_moved).mean() > 0.995
    for field in ("metallic", "roughness", "normal", "emissive", "cavity", "opacity"):
        assert _err(ig[field], pg[field]).max() < 1e-6, field


def test_switch_permutation_matches_cpu(ctx):
    resolver = FileResolver()
    r = resolve(load_instance(INSTANCES / "worn_paint_red_no_rust.json"))
    cm, gpu, cpu = _attrs(ctx, r.document, resolver)
    assert cm.ir.switches == {"rust_on": False}
    for field in gpu:
        assert np.percentile(_err(gpu[field], cpu[field]), 99.5) < TOL, field


def test_permutations_cached_by_structure_hash(gl_ctx):
    from matedit.ibl import BakeSettings
    from matedit.render import Renderer

    small = BakeSettings(size=16, samples=16, lut_size=16, lut_samples=64)
    ren = Renderer(gl_ctx, (32, 32), samples=1, environment="studio", bake_settings=small)
    try:
        resolver = FileResolver()
        red = compile_document(resolve(load_instance(INSTANCES / "worn_paint_red.json"))
                               .document, resolver)
        off = compile_document(resolve(load_instance(
            INSTANCES / "worn_paint_red_no_rust.json")).document, resolver)
        assert ren.set_material(red).ok
        ren.render()
        links = ren.link_count
        assert ren.set_material(off).ok  # cold: a new permutation links
        ren.render()
        assert ren.link_count == links + 1
        assert ren.set_material(red).ok  # warm: back to the cached program
        ren.render()
        assert ren.set_material(off).ok
        ren.render()
        assert ren.link_count == links + 1
    finally:
        ren.release()
