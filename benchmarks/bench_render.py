"""Viewport frame time against a hand-written floor, and structural-edit latency per sample.

Run: MESA_SHADER_CACHE_DISABLE=true .venv/bin/python benchmarks/bench_render.py
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")

from common import machine, median_time  # noqa: E402

from matedit.compiler import compile_document  # noqa: E402
from matedit.compiler.api import CompiledMaterial  # noqa: E402
from matedit.compiler.emit import FRAME_BLOCK, SHADE_MAIN, SourceMap, vertex_source  # noqa: E402
from matedit.compiler.ir import MaterialIR, Scope  # noqa: E402
from matedit.compiler.targets import FRAME_BINDING, TARGETS  # noqa: E402
from matedit.glsl.include import assemble  # noqa: E402
from matedit.io.document import FileResolver, load  # noqa: E402
from matedit.resources import graphs_dir  # noqa: E402

FLOOR_BODY = f"""{FRAME_BLOCK.format(binding=FRAME_BINDING)}
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
layout(location = 0) out vec4 fragColor;
MaterialAttributes evaluateMaterial() {{
    MaterialAttributes m;
    m.baseColor = vec3(0.8, 0.5, 0.3);
    m.metallic = 0.5;
    m.roughness = 0.4;
    m.cavity = 1.0;
    m.normal = vec3(0.0, 0.0, 1.0);
    m.emissive = vec3(0.0);
    m.opacity = 1.0;
    return m;
}}
{SHADE_MAIN}
"""


def floor_material() -> CompiledMaterial:
    """The same lighting with constant material inputs, written by hand: the cost floor."""
    t = TARGETS["glsl330"]
    frag = assemble(FLOOR_BODY, t.version, ["common.glsl", "material.glsl",
                                            "nodes/context.glsl", "surface.glsl"],
                    "<floor>", prelude=t.prelude())
    ir = MaterialIR(Scope("evaluateMaterial"), [], [], [], set(), [])
    return CompiledMaterial("glsl330", vertex_source(t), frag, SourceMap(), ir, "floor")


def frame_time(renderer, ctx, frames: int = 5) -> float:
    def one():
        renderer.render()
        ctx.finish()

    return median_time(one, repeat=frames, warmup=1)


def frame_vs_floor(renderer, ctx, material: CompiledMaterial, sizes=(512, 1024),
                   frames: int = 5) -> list[tuple[int, float, float]]:
    """[(size, material frame s, floor frame s)]: medians of frames that alternate between
    the two programs (both linked and drawn once first), so load on the machine hits both."""
    import statistics

    floor = floor_material()
    rows = []
    for size in sizes:
        renderer.resize(size, size)
        times: dict[str, list[float]] = {"material": [], "floor": []}
        for i in range(frames + 1):
            for name, m in (("material", material), ("floor", floor)):
                renderer.set_material(m)
                t = time.perf_counter()
                renderer.render()
                ctx.finish()
                if i:  # the first round links and JITs
                    times[name].append(time.perf_counter() - t)
        rows.append((size, statistics.median(times["material"]),
                     statistics.median(times["floor"])))
    return rows


def structural_edit(renderer, ctx, doc, repeat: int = 3) -> tuple[float, float, float, float]:
    """Median (compile, GL link, first frame, total) seconds of a structural edit to `doc`:
    compile, link a new program (the program cache is cleared first), draw, finish."""
    rows = []
    for _ in range(repeat):
        renderer._programs.clear()  # force a new link, as a structural edit does
        t0 = time.perf_counter()
        cm = compile_document(doc, FileResolver())
        t1 = time.perf_counter()
        renderer.set_material(cm)
        ctx.finish()
        t2 = time.perf_counter()
        renderer.render()
        ctx.finish()
        t3 = time.perf_counter()
        rows.append((t1 - t0, t2 - t1, t3 - t2, t3 - t0))
    rows.sort(key=lambda x: x[3])
    return rows[len(rows) // 2]


def parameter_edit(renderer, ctx, material: CompiledMaterial, repeat: int = 5,
                   values: list[dict] | None = None) -> tuple[float, int]:
    """Median seconds from a parameter edit (set_uniforms) to the next finished frame, and the
    number of program links the edits caused."""
    renderer.set_material(material)
    renderer.render()
    ctx.finish()
    links = renderer.link_count
    if values is None:
        values = [{u.name: u.default for u in material.ir.uniforms}]
    times = []
    for i in range(repeat):
        t0 = time.perf_counter()
        renderer.set_uniforms(values[i % len(values)])
        renderer.render()
        ctx.finish()
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[len(times) // 2], renderer.link_count - links


def main() -> None:
    import moderngl

    from matedit.render import Renderer

    ctx = moderngl.create_standalone_context(backend="egl")
    r = Renderer(ctx, (512, 512))
    print(f"# render benchmark on {machine(ctx)}")
    print("# split-sum IBL + default rig (key sphere, tube, fill), 4x MSAA, sphere mesh\n")
    sample = load(graphs_dir() / "materials" / "worn_painted_steel.json")
    material = compile_document(sample, FileResolver())
    print("| size | worn_painted_steel (ms) | hand-written floor (ms) | ratio |")
    print("|---|---:|---:|---:|")
    for size, t_mat, t_floor in frame_vs_floor(r, ctx, material):
        print(f"| {size}² | {t_mat * 1000:.0f} | {t_floor * 1000:.0f} | {t_mat / t_floor:.2f} |")

    r.resize(512, 512)
    print("\n| sample | compile (ms) | GL link (ms) | first frame (ms) "
          "| structural edit total (ms) |")
    print("|---|---:|---:|---:|---:|")
    for path in sorted((graphs_dir() / "materials").glob("*.json")):
        c, li, f, tot = structural_edit(r, ctx, load(path))
        print(f"| {path.stem} | {c * 1000:.1f} | {li * 1000:.0f} | {f * 1000:.0f} | "
              f"{tot * 1000:.0f} |")

    t, links = parameter_edit(r, ctx, material, repeat=1)
    print(f"\nparameter edit -> next frame at 512²: {t * 1000:.0f} ms, "
          f"program links caused: {links}")
    r.release()

if __name__ == "__main__":
    main()
