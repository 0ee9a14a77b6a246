"""Viewport frame time against a hand-written floor, and structural-edit latency per sample.

Run: MESA_SHADER_CACHE_DISABLE=true .venv/bin/python benchmarks/bench_render.py
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")

from common import machine, median_time  # noqa: E402

from matedit.compiler import compile_document  # noqa: E402
from matedit.compiler.api import CompiledMaterial  # noqa: E402
from matedit.compiler.emit import (  # noqa: E402
    FRAME_BLOCK,
    Entry,
    SourceMap,
    entry_text,
    vertex_source,
)
from matedit.compiler.glsl_backend import prelude  # noqa: E402
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
{entry_text(Entry.FORWARD)}
"""


def floor_material() -> CompiledMaterial:
    """The same lighting with constant material inputs: the cost floor. The renderer links the
    entry variants of a material's IR (an empty IR: the default attributes, constants), so in
    the deferred preview this floor is a GBUFFER program of constants and the same lighting
    pass; in the forward preview, the FORWARD entry of constants."""
    t = TARGETS["glsl330"]
    frag = assemble(FLOOR_BODY, t.version, ["common.glsl", "material.glsl",
                                            "nodes/context.glsl", "surface.glsl"],
                    "<floor>", prelude=prelude(t))
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


def promoted_vs_floor(ctx, material: CompiledMaterial, sizes=(512, 1024),
                      frames: int = 5) -> list[tuple[int, float, float]]:
    """As frame_vs_floor, for the frames the viewport draws once idle after an edit: the
    material and the floor promoted to the forward path (Renderer.promote_forward, whose
    image and program are the forward renderer's: tests/test_render_promote.py), each on a
    renderer of its own (a structural edit, as switching materials is, ends a promotion)."""
    import statistics

    from matedit.render import Renderer

    rows = []
    for size in sizes:
        rs = {name: Renderer(ctx, (size, size), environment="studio")
              for name in ("material", "floor")}
        try:
            for name, m in (("material", material), ("floor", floor_material())):
                rs[name].set_material(m)
                rs[name].render()  # the deferred program, as after the structural edit
                if not rs[name].promote_forward():
                    raise RuntimeError(f"{name}: not promoted")
                rs[name].render()  # the forward program's link and JIT
            times: dict[str, list[float]] = {"material": [], "floor": []}
            for _ in range(frames):
                for name, r in rs.items():
                    t = time.perf_counter()
                    r.render()
                    ctx.finish()
                    times[name].append(time.perf_counter() - t)
            rows.append((size, statistics.median(times["material"]),
                         statistics.median(times["floor"])))
        finally:
            for r in rs.values():
                r.release()
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
                   values: list[dict] | None = None, plain: list[float] | None = None
                   ) -> tuple[float, int]:
    """Median seconds from a parameter edit (set_uniforms) to the next finished frame, and the
    number of program links the edits caused. With `plain` (a list), a plain frame is drawn
    after each edit's and its time appended there: the two alternate, so that load on the
    machine hits both alike."""
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
        if plain is not None:
            t0 = time.perf_counter()
            renderer.render()
            ctx.finish()
            plain.append(time.perf_counter() - t0)
    times.sort()
    return times[len(times) // 2], renderer.link_count - links


def structural_edit_paths(ctx, size: int = 512, repeat: int = 3,
                          names: list[str] | None = None) -> list[dict]:
    """Structural edit latency of each sample, forward and deferred previews side by side (two
    renderers, alternating, so that load on the machine hits both), medians in seconds."""
    from matedit.render import Renderer

    paths = {"forward": Renderer(ctx, (size, size), deferred=False),
             "deferred": Renderer(ctx, (size, size), deferred=True)}
    for r in paths.values():
        r.render()
        ctx.finish()
    rows = []
    files = sorted((graphs_dir() / "materials").glob("*.json"))
    for path in files:
        if names and path.stem not in names:
            continue
        doc = load(path)
        runs: dict[str, list] = {k: [] for k in paths}
        for _ in range(repeat):
            for k, r in paths.items():
                runs[k].append(structural_edit(r, ctx, doc, repeat=1))
        row = {"sample": path.stem}
        for k in paths:
            ordered = sorted(runs[k], key=lambda x: x[3])
            c, li, f, tot = ordered[len(ordered) // 2]
            row[k] = {"compile": c, "link": li, "first_frame": f, "total": tot}
        row["deferred_path"] = not paths["deferred"].is_forward
        rows.append(row)
    for r in paths.values():
        r.release()
    return rows


def frames_forward_deferred(ctx, material: CompiledMaterial, sizes=(512, 1024),
                            frames: int = 5) -> list[dict]:
    """Frame medians (s) of the material and the floor on both paths, and of the deferred path
    with edges lit once (no anti-aliasing of the lighting): what per-sample edges cost."""
    import statistics

    from matedit.render import Renderer

    rows = []
    floor = floor_material()
    for size in sizes:
        rs = {"forward": Renderer(ctx, (size, size), deferred=False),
              "deferred": Renderer(ctx, (size, size), deferred=True)}
        times: dict[str, list[float]] = {}
        for i in range(frames + 1):
            for path, r in rs.items():
                for name, m in (("material", material), ("floor", floor)):
                    r.set_material(m)
                    for edges_once in ((False, True) if path == "deferred" and
                                       name == "material" else (False,)):
                        r.lighting.edges_once = edges_once
                        t = time.perf_counter()
                        r.render()
                        ctx.finish()
                        key = f"{path} {name}" + (" edges once" if edges_once else "")
                        if i:
                            times.setdefault(key, []).append(time.perf_counter() - t)
                    r.lighting.edges_once = False
        row = {"size": size, **{k: statistics.median(v) for k, v in times.items()}}
        g = rs["deferred"].targets.gbuffer
        if g is not None:  # the share of edge pixels (samples that disagree), for the cost
            t3 = np.frombuffer(_resolve_coverage(ctx, g, size), np.float32)
            row["edge_pixel_share"] = float(((t3 > 0) & (t3 < 1)).mean())
        for r in rs.values():
            r.release()
        rows.append(row)
    return rows


_COVERAGE_FRAG = """#version 330 core
uniform sampler2DMS uGBuffer2;  // g: the coverage, 1 where drawn (deferred.py)
uniform int uSamples;
out vec4 color;
void main() {
    int covered = 0;
    for (int s = 0; s < uSamples; s++) {
        if (texelFetch(uGBuffer2, ivec2(gl_FragCoord.xy), s).g > 0.5) covered++;
    }
    color = vec4(float(covered) / float(uSamples));
}
"""
_COVERAGE_VERT = """#version 330 core
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"""


def _resolve_coverage(ctx, gbuffer, size: int) -> bytes:
    """The G-buffer's coverage (target 2's second channel) averaged over the samples: 0 < c < 1
    at a silhouette pixel."""
    tex = ctx.texture((size, size), 1, dtype="f4")
    fbo = ctx.framebuffer([tex])
    prog = ctx.program(vertex_shader=_COVERAGE_VERT, fragment_shader=_COVERAGE_FRAG)
    prog["uSamples"].value = gbuffer.textures[0].samples
    gbuffer.textures[2].use(location=0)
    prog["uGBuffer2"].value = 0
    vao = ctx.vertex_array(prog, [])
    fbo.use()
    ctx.disable(ctx.DEPTH_TEST | ctx.BLEND)
    vao.render(mode=ctx.TRIANGLES, vertices=3)
    raw = fbo.read(components=1, dtype="f4")
    for x in (vao, prog, fbo, tex):
        x.release()
    return raw


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

    print("\n## forward and deferred previews side by side (MESA_SHADER_CACHE_DISABLE="
          f"{os.environ.get('MESA_SHADER_CACHE_DISABLE')})\n")
    print("| sample | forward link (ms) | forward first frame (ms) | forward total (ms) "
          "| deferred link (ms) | deferred first frame (ms) | deferred total (ms) "
          "| deferred / forward |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for row in structural_edit_paths(ctx):
        f, d = row["forward"], row["deferred"]
        note = "" if row["deferred_path"] else " (translucent: forward)"
        print(f"| {row['sample']}{note} | {f['link'] * 1e3:.0f} | {f['first_frame'] * 1e3:.0f} "
              f"| {f['total'] * 1e3:.0f} | {d['link'] * 1e3:.0f} "
              f"| {d['first_frame'] * 1e3:.0f} | {d['total'] * 1e3:.0f} "
              f"| {d['total'] / f['total']:.2f} |")
    print("\n| size | forward (ms) | forward floor (ms) | deferred (ms) | deferred floor (ms) "
          "| deferred, edges lit once (ms) | edge pixels |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for row in frames_forward_deferred(ctx, material):
        print(f"| {row['size']}² | {row['forward material'] * 1e3:.0f} "
              f"| {row['forward floor'] * 1e3:.0f} | {row['deferred material'] * 1e3:.0f} "
              f"| {row['deferred floor'] * 1e3:.0f} "
              f"| {row['deferred material edges once'] * 1e3:.0f} "
              f"| {100 * row.get('edge_pixel_share', 0):.1f} % |")

if __name__ == "__main__":
    main()
