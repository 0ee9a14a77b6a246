"""Every benchmark in one process tree, side by side, with the report in benchmarks/RESULTS.md.

Run: benchmarks/run.sh   (sets up the benchmark-only dependencies, then runs this file)
 or: MESA_SHADER_CACHE_DISABLE=true .venv/bin/python benchmarks/run_all.py [--quick]

Sections run in child processes of this one (`--child NAME` prints one `RESULT {json}`
line), so that each gets a clean GL state: the IBL bake creates and releases its own
context, which must not happen beside another live context in one process. The GL section
keeps one standalone EGL context for matedit and MaterialX alike, so that their figures are
measured on the same context, in the same run, one after the other.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")

# Benchmarks other people write: run when present (under Xvfb, their stdout goes into the
# report verbatim). To add one, name it here.
OPTIONAL_BENCHES = (
    ("bench_canvas.py", "Node canvas with 1,000 nodes"),
    ("bench_editor.py", "Editor responsiveness"),
    ("bench_instances.py", "Material instances and static switches"),
    ("bench_interop.py", "Interop: bake, glTF and MaterialX export"),
    ("bench_lobes.py", "Lobes beyond the talk: pre-lobe samples, old tree vs this one"),
)
OPTIONAL_TIMEOUT_S = 240
IMPORT_ROWS = ("matedit.commands", "matedit.commands.validate", "matedit.graph.validate",
               "networkx", "matedit.commands.compile", "numpy", "matedit.commands.render",
               "matedit.commands.bake_ibl")

# The preview engine's targets on this kind of machine (llvmpipe, 2 cores).
GOALS = {
    "structural_ms": 120.0,  # median structural edit -> pixels, every layered sample
    "structural_ratio": 10.0,  # times faster than MaterialX's mixed-inputs equivalent
    "param_ratio": 1.05,  # parameter edit -> frame, against a plain frame
    "ui_block_ms": 50.0,  # longest UI-thread stall during a structural edit
    "frame_ratio": 1.2,
    "compile_1000_ms": 30.0,
    "ibl_time_ratio": 4.0,
    "validate_ms": 300.0,
    "startup_warm_ms": 1500.0,  # editor launch -> first viewport frame with the material
    "startup_cold_ms": 3000.0,  # the same into empty IBL and Mesa shader caches
}


def code_lines(text: str) -> int:
    """Lines of GLSL code in a shader text: not blank, not only a comment, not a `#line`."""
    return sum(1 for line in text.splitlines()
               if line.strip() and not line.lstrip().startswith(("//", "#line")))


def jit_share(row: dict) -> float:
    """The share of a structural edit's total that the first frame spends beyond a plain
    frame (first frame - next frame, over the total): llvmpipe's JIT at the first draw."""
    return max(0.0, row["first_frame"] - row["steady_frame"]) / row["total"]


def ms(seconds: float, digits: int = 0) -> str:
    return f"{seconds * 1000:.{digits}f}"


# == child sections =============================================================================


def child_gl(quick: bool) -> dict:
    """Structural edits (matedit and MaterialX), parameter edit, frame time vs the floor."""
    import moderngl
    from bench_render import (
        frame_time,
        frame_vs_floor,
        parameter_edit,
        promoted_vs_floor,
        structural_edit,
    )

    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer
    from matedit.resources import graphs_dir

    repeat = 1 if quick else 3
    ctx = moderngl.create_standalone_context(backend="egl")
    out: dict = {"gl_renderer": ctx.info["GL_RENDERER"], "gl_version": ctx.info["GL_VERSION"],
                 "repeat": repeat}
    r = Renderer(ctx, (512, 512))
    r.render()
    ctx.finish()

    try:
        from bench_materialx import MaterialXSide, equivalent_of

        mx_side = MaterialXSide(ctx, (512, 512), r.camera)
        out["materialx_version"] = mx_side.version
    except ImportError as exc:
        mx_side, equivalent_of = None, None
        out["materialx_error"] = f"{exc} (pip install materialx)"

    rows = []
    paths = sorted((graphs_dir() / "materials").glob("*.json"))
    for path in paths:
        doc = load(path)
        eq = equivalent_of(path) if mx_side is not None else None
        mine, mx_runs = [], {"shaders": [], "inputs": []}
        for _ in range(repeat):  # interleaved: matedit, then MaterialX, edit after edit
            mine.append(structural_edit(r, ctx, doc, repeat=1))
            if eq is not None:
                mx_runs["shaders"].append(mx_side.structural_edit(eq, repeat=1))
                if eq.layers > 1:
                    mx_runs["inputs"].append(mx_side.structural_edit(eq, repeat=1,
                                                                     mode="inputs"))
        mine.sort(key=lambda x: x[3])
        c, li, f, tot = mine[len(mine) // 2]
        row = {"sample": path.stem, "compile": c, "link": li, "first_frame": f, "total": tot,
               "totals": [m[3] for m in mine]}
        if eq is not None:
            row["layers"] = eq.layers
            for mode, runs in mx_runs.items():
                if runs:
                    runs.sort(key=lambda x: x["total"])
                    med = dict(runs[len(runs) // 2])
                    med["totals"] = [x["total"] for x in runs]
                    med["steady_frame"] = statistics.median(x["steady_frame"] for x in runs)
                    med["describe"] = eq.describe(mode)
                    row["mx_" + mode] = med
        row["steady_frame"] = frame_time(r, ctx, frames=3)
        # the fragment shader the preview linked (GBUFFER, or forward the split-sum FORWARD)
        text = r.programs.drawn_variant(compile_document(doc, FileResolver()), r.is_forward,
                                        r.energy_compensation, r.view).fragment_text
        row["fragment_bytes"] = len(text.encode())
        row["fragment_lines"] = code_lines(text)
        row["path"] = "forward" if r.is_forward else "deferred"
        rows.append(row)
        print(f"  structural edit {path.stem}: matedit {ms(tot)} ms"
              + (f", MaterialX {ms(row['mx_shaders']['total'])} ms" if "mx_shaders" in row
                 else ""), file=sys.stderr, flush=True)
    out["structural"] = rows
    if mx_side is not None:
        mx_side.release()

    # parameter edit: alternate a float parameter between two values each frame
    sample = load(graphs_dir() / "materials" / "worn_painted_steel.json")
    material = compile_document(sample, FileResolver())
    r.resize(512, 512)
    floats = [u for u in material.ir.uniforms if isinstance(u.default, float)]
    values = [{u.name: (u.default * 0.5 if k % 2 else u.default) for u in floats[:1]}
              for k in range(2)]
    plain: list[float] = []
    t_param, links = parameter_edit(r, ctx, material, repeat=9 if not quick else 3,
                                    values=values, plain=plain)
    out["parameter"] = {"sample": "worn_painted_steel", "parameter": floats[0].name,
                        "edit_to_frame": t_param, "links": links,
                        "frame": sorted(plain)[len(plain) // 2]}

    # frame time against the hand-written floor
    out["frames"] = [{"size": s, "material": tm, "floor": tf}
                     for s, tm, tf in frame_vs_floor(r, ctx, material, (512, 1024),
                                                     frames=9 if not quick else 3)]
    r.release()
    # the same once the viewport has been idle: both promoted to the forward path
    out["promoted_frames"] = [{"size": s, "material": tm, "floor": tf}
                              for s, tm, tf in promoted_vs_floor(
                                  ctx, material, (512, 1024), frames=9 if not quick else 3)]
    return out


def child_jit(quick: bool) -> dict:
    """Link + first frame of the layered sample's FORWARD entry under whatever GALLIVM_PERF
    the parent set, with and without the reference-IBL estimator: the variant the forward
    preview's split-sum mode links (MATEDIT_SPLIT_SUM_ONLY defined, through the compiler's
    Entry/defines mechanism, no shader text edited here), the variant its reference mode links
    (no define: both IBL branches), and the hand-written floor (constant material, same
    lighting library). A forward renderer (deferred=False), so that these are the programs
    drawn; reference mode at 1 sample a pixel and 1 frame, so that the first frame is the
    driver's compile plus one cheap frame, as in split-sum mode."""
    import moderngl
    from bench_render import floor_material
    from common import median_time

    from matedit.compiler import compile_document
    from matedit.compiler.emit import Entry
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer
    from matedit.render.deferred import SPLIT_SUM_ONLY
    from matedit.resources import graphs_dir

    ctx = moderngl.create_standalone_context(backend="egl")
    r = Renderer(ctx, (512, 512), deferred=False)
    r.reference_samples, r.reference_frames = 1, 1
    r.render()
    ctx.finish()
    cm = compile_document(load(graphs_dir() / "materials" / "worn_painted_steel.json"),
                          FileResolver())
    variants = {"worn_painted_steel, both IBL branches": (cm, "reference"),
                "worn_painted_steel, split-sum branch only": (cm, "splitsum"),
                "hand-written floor": (floor_material(), "splitsum")}
    out = {"gallivm_perf": os.environ.get("GALLIVM_PERF", ""), "variants": [],
           "renderer_specialises": True}

    def link_and_draw(material, mode: str) -> tuple[float, float, float]:
        r.programs.table.clear()  # links anew (not released: no program name is reused)
        r.mode = mode
        t0 = time.perf_counter()
        r.set_material(material)  # the split-sum variant, FORWARD + MATEDIT_SPLIT_SUM_ONLY
        if mode == "reference":  # and the one reference mode draws, FORWARD without it
            t0 = time.perf_counter()  # (the split-sum variant's link is not this row's)
            r.programs.get(material, Entry.FORWARD, ())
        ctx.finish()
        t1 = time.perf_counter()
        r.render()
        ctx.finish()
        t2 = time.perf_counter()
        return t1 - t0, t2 - t1, t2 - t0

    runs: dict[str, list] = {name: [] for name in variants}
    for _ in range(1 if quick else 5):  # interleaved, so that load on the machine hits all
        for name, (material, mode) in variants.items():
            runs[name].append(link_and_draw(material, mode))
    for name, (material, mode) in variants.items():
        rows = sorted(runs[name], key=lambda x: x[2])
        link, first, total = rows[len(rows) // 2]
        r.mode = mode
        r.set_material(material)
        variant = material.variant(Entry.FORWARD,
                                   () if mode == "reference" else (SPLIT_SUM_ONLY,))

        def frame():  # reference mode has converged after its one frame: start it again
            r.reset_accumulation()
            r.render()
            ctx.finish()

        out["variants"].append({"name": name, "link": link, "first_frame": first,
                                "total": total, "frame": median_time(frame, repeat=3),
                                "fragment_chars": len(variant.fragment_text)})
    r.release()
    return out


def child_edit_loop(quick: bool) -> dict:
    """Structural edits of the layered sample, for py-spy to sample."""
    import moderngl
    from bench_render import structural_edit

    from matedit.io.document import load
    from matedit.render import Renderer
    from matedit.resources import graphs_dir

    ctx = moderngl.create_standalone_context(backend="egl")
    r = Renderer(ctx, (512, 512))
    r.render()
    ctx.finish()
    doc = load(graphs_dir() / "materials" / "worn_painted_steel.json")
    structural_edit(r, ctx, doc, repeat=3 if quick else 5)
    r.release()
    return {}


NATIVE_BUCKETS = (
    ("matedit compile (Python)", lambda s: "compile_document" in s),
    ("GL link: Mesa's GLSL compiler (set_material)", lambda s: "set_material" in s),
    ("first draw: LLVM JIT (libLLVM)", lambda s: "Renderer.render" in s and "libLLVM" in s),
    ("first draw: resolve/copy, waiting for the raster threads",
     lambda s: "copy_framebuffer" in s or "Context.finish" in s),
    ("first draw: Mesa draw setup, other", lambda s: "Renderer.render" in s),
)


def native_profile(quick: bool) -> dict:
    """py-spy --native over `--child edit-loop`: shares of the structural edits' samples on
    the main thread (llvmpipe's raster threads are not Python threads and are not seen)."""
    pyspy = shutil.which("py-spy") or str(Path(sys.executable).parent / "py-spy")
    if not Path(pyspy).exists():
        return {"error": "py-spy not installed (pip install py-spy)"}
    raw = Path(tempfile.mkdtemp(prefix="matedit-pyspy-")) / "edit.raw"
    cmd = [pyspy, "record", "--native", "-r", "100", "-f", "raw", "-o", str(raw), "--",
           sys.executable, str(Path(__file__).resolve()), "--child", "edit-loop"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=240, cwd=ROOT)
    except subprocess.TimeoutExpired:
        return {"error": "py-spy timed out"}
    if not raw.exists():
        return {"error": f"py-spy failed: {(proc.stderr or proc.stdout)[-600:]}"}
    counts = dict.fromkeys([b[0] for b in NATIVE_BUCKETS] + ["other"], 0)
    total = 0
    for line in raw.read_text().splitlines():
        stack, _, n = line.rpartition(" ")
        if "structural_edit" not in stack or not n.isdigit():
            continue
        total += int(n)
        name = next((b[0] for b in NATIVE_BUCKETS if b[1](stack)), "other")
        counts[name] += int(n)
    shutil.rmtree(raw.parent, ignore_errors=True)
    return {"samples": total, "shares": {k: v / max(total, 1) for k, v in counts.items()}}


def child_compile(quick: bool) -> dict:
    from bench_compile import compile_scaling

    sizes = (10, 100, 1000) if quick else (10, 100, 1000, 10000)
    return {"scaling": [{"nodes": n, "real_nodes": real, "seconds": t}
                        for n, real, t in compile_scaling(sizes)]}


def child_ibl(quick: bool) -> dict:
    from bench_ibl import compare

    size, samples, lut = (128, 128, 64) if quick else (256, 256, 128)
    res = compare(size, samples, lut, repeat=1 if quick else 3)
    out: dict = {"size": size, "samples": samples, "lut": lut, "tools": {}}
    for name, r in res.items():
        errs = r["prefilter_errors"]
        out["tools"][name] = {
            "prefilter_s": r["prefilter_s"], "prefilter_all": r["prefilter_s_all"],
            "lut_s": r["lut_s"], "lut_all": r["lut_s_all"],
            "levels": [lv[0] for lv in r["levels"]],
            "errors": errs,
            "mean_error": statistics.fmean(e[1] for e in errs),
            "max_error": max(e[2] for e in errs),
            "lut_error": r["lut_error"][0],
        }
    return out


def child_profile(quick: bool) -> dict:
    """pyinstrument over one structural edit of the layered sample (where the Python time
    goes, and how much is inside the GL calls), and over compiles of the 1,000-node graph."""
    import moderngl
    from common import synthetic_material
    from pyinstrument import Profiler

    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer
    from matedit.resources import graphs_dir

    options = {"filter_threshold": 0.02}
    ctx = moderngl.create_standalone_context(backend="egl")
    r = Renderer(ctx, (512, 512))
    r.render()
    ctx.finish()
    doc = load(graphs_dir() / "materials" / "worn_painted_steel.json")
    r._programs.clear()
    profiler = Profiler(interval=0.0005)
    profiler.start()
    cm = compile_document(doc, FileResolver())
    r.set_material(cm)
    r.render()
    ctx.finish()
    profiler.stop()
    edit = profiler.output_text(processor_options=options)
    r.release()

    big = synthetic_material(1000)
    compile_document(big, FileResolver())
    profiler = Profiler(interval=0.0005)
    profiler.start()
    for _ in range(10):
        compile_document(big, FileResolver())
    profiler.stop()
    return {"edit": edit, "compile": profiler.output_text(processor_options=options)}


CHILDREN = {"gl": child_gl, "jit": child_jit, "edit-loop": child_edit_loop,
            "compile": child_compile, "ibl": child_ibl, "profile": child_profile}


def run_child(name: str, quick: bool, timeout: float, env: dict | None = None) -> dict:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", name]
    if quick:
        cmd.append("--quick")
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                              env=dict(os.environ, **(env or {})), cwd=ROOT)
    except subprocess.TimeoutExpired:
        return {"error": f"timed out after {timeout:.0f} s", "wall": timeout}
    sys.stderr.write(proc.stderr[-4000:] if proc.returncode else "")
    line = next((x for x in proc.stdout.splitlines() if x.startswith("RESULT ")), None)
    if line is None:
        return {"error": f"exit {proc.returncode}: {(proc.stderr or proc.stdout)[-1500:]}",
                "wall": time.perf_counter() - t0}
    result = json.loads(line[len("RESULT "):])
    result["wall"] = time.perf_counter() - t0
    return result


def run_optional(script: str, timeout: float) -> dict:
    """The hook for benchmarks written elsewhere: runs benchmarks/SCRIPT under Xvfb when it
    exists and keeps its standard output for the report."""
    path = HERE / script
    if not path.exists():
        return {"missing": True}
    cmd = [sys.executable, str(path)]
    if shutil.which("xvfb-run") and not os.environ.get("DISPLAY"):
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", *cmd]
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=ROOT)
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
        return {"stdout": out, "error": f"timed out after {timeout:.0f} s", "wall": timeout}
    res = {"stdout": proc.stdout, "wall": time.perf_counter() - t0}
    if proc.returncode:
        res["error"] = f"exit {proc.returncode}: {proc.stderr[-1500:]}"
    return res


# == report =====================================================================================


def verdict(ok: bool | None) -> str:
    return "n/a" if ok is None else ("met" if ok else "**missed**")


class Report:
    def __init__(self) -> None:
        self.lines: list[str] = []

    def add(self, text: str = "") -> None:
        self.lines.append(text)
        print(text, flush=True)

    def table(self, header: list[str], align: str, rows: list[list[str]]) -> None:
        self.add("| " + " | ".join(header) + " |")
        self.add("|" + "|".join("---:" if a == "r" else "---" for a in align) + "|")
        for row in rows:
            self.add("| " + " | ".join(row) + " |")
        self.add()


def structural_section(rep: Report, gl: dict, goals: list) -> None:
    rep.add("## 1. Structural edit: compile + GL link + first frame, matedit vs MaterialX")
    rep.add()
    if "error" in gl:
        rep.add(f"Not measured: {gl['error']}")
        rep.add()
        return
    rep.add(f"Median of {gl['repeat']} edits per sample, 512² with 4x MSAA, sphere, on one "
            "EGL context. matedit: `compile_document` + `Renderer.set_material` (program "
            "cache cleared, so it links) + `render()` + `ctx.finish()`; its first frame is the "
            "whole viewport frame (background, material, light gizmos, resolve, tonemap). "
            f"MaterialX {gl.get('materialx_version', '?')}: `GlslShaderGenerator.generate` "
            "(library loaded and GenContext kept, as an editor would), link, bind the "
            "matrices, eye and environment map (the other uniforms keep their GLSL defaults, "
            "0 lights), draw the same sphere mesh with the same camera, `ctx.finish()`. "
            "Equivalent per sample: one `standard_surface` per layer mixed by `mix` nodes of "
            "surfaceshaders whose masks are `noise2d` (column *MaterialX per-layer*), and for "
            "layered samples also one `standard_surface` whose inputs are mixed by the same "
            "masks (column *MaterialX mixed inputs*, matedit's own one-BSDF scheme, the "
            "cheaper of the two). Specular IBL: MaterialX's prefiltered method. "
            "`MESA_SHADER_CACHE_DISABLE=true` for both.")
    rep.add()
    if "materialx_error" in gl:
        rep.add(f"MaterialX side not measured: {gl['materialx_error']}")
        rep.add()
    rows = []
    for r in gl["structural"]:
        mxs, mxi = r.get("mx_shaders"), r.get("mx_inputs")
        rows.append([
            r["sample"], str(r.get("layers", "?")), ms(r["compile"], 1), ms(r["link"]),
            ms(r["first_frame"]), f"**{ms(r['total'])}**", ms(r["steady_frame"]),
            f"{100 * jit_share(r):.0f} %",
            f"{r['fragment_lines']:,} / {r['fragment_bytes'] / 1024:.1f}"
            if "fragment_bytes" in r else "–",
            f"{ms(mxs['generate'], 1)} / {ms(mxs['link'])} / {ms(mxs['first_frame'])}"
            if mxs else "–",
            f"**{ms(mxs['total'])}**" if mxs else "–",
            f"{mxs['total'] / r['total']:.1f}×" if mxs else "–",
            f"{ms(mxi['total'])}" if mxi else "–",
            f"{mxi['total'] / r['total']:.1f}×" if mxi else "–",
        ])
    rep.table(["sample", "layers", "matedit compile (ms)", "link (ms)", "first frame (ms)",
               "matedit total (ms)", "matedit next frame (ms)", "JIT share of the total",
               "fragment lines / KiB",
               "MaterialX per-layer gen / link / first frame (ms)",
               "MaterialX per-layer total (ms)", "ratio", "MaterialX mixed inputs total (ms)",
               "ratio"], "lrrrrrrrrrrrrr", rows)
    rep.add("*JIT share*: the first frame minus the next frame (a plain frame of the same "
            "program), over the total: what llvmpipe's compile at the first draw takes of the "
            "edit. *Fragment lines / KiB*: the fragment shader the preview linked (the GBUFFER "
            "entry on the deferred path, the split-sum FORWARD entry on the forward path), "
            "lines of code (no blank, comment-only or `#line` lines) and its size as linked.")
    rep.add()
    mx_rows = [r for r in gl["structural"] if "mx_shaders" in r]
    if mx_rows:
        rep.add("MaterialX's steady frame (second draw of the same program), per-layer "
                "variant: " + ", ".join(f"{r['sample']} {ms(r['mx_shaders']['steady_frame'])} ms"
                                        for r in mx_rows)
                + f"; fragment shader size {mx_rows[-1]['mx_shaders']['fragment_chars']:,} "
                  "characters for the last one.")
        rep.add()
    layered = [r for r in gl["structural"] if r.get("layers", 0) > 1]
    if layered:
        worst = max(layered, key=lambda r: r["total"])
        goals.append(["structural edit, layered sample (median)",
                      f"≤ {GOALS['structural_ms']:.0f} ms",
                      f"{ms(min(r['total'] for r in layered))}–{ms(worst['total'])} ms",
                      verdict(worst["total"] * 1000 <= GOALS["structural_ms"])])
        if all("mx_shaders" in r for r in layered):
            lo = min(r["mx_shaders"]["total"] / r["total"] for r in layered)
            hi = max(r["mx_shaders"]["total"] / r["total"] for r in layered)
            goals.append(["… vs MaterialX per-layer equivalent (for comparison)", "–",
                          f"{lo:.0f}–{hi:.0f}×", "–"])
        if all("mx_inputs" in r for r in layered):
            lo = min(r["mx_inputs"]["total"] / r["total"] for r in layered)
            hi = max(r["mx_inputs"]["total"] / r["total"] for r in layered)
            goals.append(["… vs MaterialX mixed-inputs equivalent",
                          f"≥ {GOALS['structural_ratio']:.0f}× faster",
                          f"{lo:.0f}–{hi:.0f}×", verdict(lo >= GOALS["structural_ratio"])])


def parameter_section(rep: Report, gl: dict, goals: list) -> None:
    rep.add("## 2. Parameter edit → next frame")
    rep.add()
    if "parameter" not in gl:
        rep.add("Not measured (the GL section failed).")
        rep.add()
        return
    p = gl["parameter"]
    rep.add(f"`{p['sample']}` at 512², `Renderer.set_uniforms` on `{p['parameter']}` "
            "(alternating between two values) then `render()` + `ctx.finish()`; median of "
            "the edits, against the median of plain frames, one drawn after each edit's "
            "(edits and plain frames alternate, so that load on the machine hits both).")
    rep.add()
    rep.table(["edit → frame (ms)", "plain frame (ms)", "ratio", "program links caused"],
              "rrrr", [[ms(p["edit_to_frame"]), ms(p["frame"]),
                        f"{p['edit_to_frame'] / p['frame']:.2f}", str(p["links"])]])
    goals.append(["parameter edit", f"0 links, ≤ {GOALS['param_ratio']}× a frame",
                  f"{p['links']} links, {p['edit_to_frame'] / p['frame']:.2f}× a frame",
                  verdict(p["links"] == 0
                          and p["edit_to_frame"] / p["frame"] <= GOALS["param_ratio"])])


def frame_section(rep: Report, gl: dict, goals: list) -> None:
    rep.add("## 3. Viewport frame time vs the hand-written floor")
    rep.add()
    if "frames" not in gl:
        rep.add("Not measured (the GL section failed).")
        rep.add()
        return
    rep.add("Default rig (key sphere light, tube light, fill) with split-sum IBL (studio), "
            "4x MSAA, background, gizmos and tonemap; `worn_painted_steel` against the same "
            "lighting with constant material inputs written by hand (bench_render's floor). "
            "Median of 9 frames each, each `render()` + `ctx.finish()`, alternating between "
            "the two programs so that load on the machine hits both alike.")
    rep.add()
    promoted = {f["size"]: f for f in gl.get("promoted_frames", [])}
    rows = [[f"{f['size']}²", ms(f["material"]), ms(f["floor"]),
             f"{f['material'] / f['floor']:.2f}"]
            + ([ms(promoted[f["size"]]["material"]), ms(promoted[f["size"]]["floor"]),
                f"{promoted[f['size']]['material'] / promoted[f['size']]['floor']:.2f}"]
               if f["size"] in promoted else ["–", "–", "–"]) for f in gl["frames"]]
    rep.table(["size", "worn_painted_steel (ms)", "floor (ms)", "ratio",
               "once idle: worn_painted_steel (ms)", "once idle: floor (ms)", "ratio"],
              "lrrrrrr", rows)
    rep.add("*Once idle*: the frames the viewport draws after it has been idle a while after a "
            "structural edit (matedit.render.server.FORWARD_WHEN_IDLE_S): the material, and "
            "the floor, promoted to the forward path (`Renderer.promote_forward`), measured "
            "the same way on a renderer of each size. The first columns, and the goal's "
            "verdict, are the deferred frames an edit's first pictures take.")
    rep.add()
    worst = max(f["material"] / f["floor"] for f in gl["frames"])
    goals.append(["frame time vs floor", "≤ 1.2×", f"{worst:.2f}× (worst size)",
                  verdict(worst <= GOALS["frame_ratio"])])


def compile_section(rep: Report, comp: dict, goals: list) -> None:
    rep.add("## 4. Compile scaling: graph → GLSL")
    rep.add()
    if "error" in comp:
        rep.add(f"Not measured: {comp['error']}")
        rep.add()
        return
    rep.add("`compile_document` on `synthetic_material(n)` (random maths DAG on UVs, noise "
            "and parameters, every node live); median of 5 (3 at 10,000).")
    rep.add()
    rows = []
    prev = None
    for s in comp["scaling"]:
        growth = f"{s['seconds'] / prev['seconds']:.1f}×" if prev else ""
        per = s["seconds"] / s["real_nodes"] * 1e6
        rows.append([f"{s['nodes']:,}", str(s["real_nodes"]), ms(s["seconds"], 1),
                     f"{per:.0f}", growth])
        prev = s
    rep.table(["nodes", "nodes in graph", "graph → GLSL (ms)", "µs per node",
               "growth per decade"], "rrrrr", rows)
    by = {s["nodes"]: s for s in comp["scaling"]}
    if 1000 in by:
        t = by[1000]["seconds"]
        goals.append(["graph → GLSL at 1,000 nodes", "< 30 ms", f"{ms(t, 1)} ms",
                      verdict(t * 1000 < GOALS["compile_1000_ms"])])
    if 1000 in by and 10000 in by:
        g = by[10000]["seconds"] / by[1000]["seconds"]
        per = [by[n]["seconds"] / by[n]["real_nodes"] * 1e6 for n in (1000, 10000)]
        goals.append(["… linear beyond (1k → 10k)", "≈ 10× per decade (≤ 12×)",
                      f"{g:.1f}× ({per[0]:.0f} → {per[1]:.0f} µs a node)",
                      verdict(g <= 12.0)])


def ibl_section(rep: Report, ibl: dict, goals: list) -> None:
    rep.add("## 5. IBL bake and BRDF LUT vs Filament's cmgen")
    rep.add()
    if "error" in ibl:
        rep.add(f"Not measured: {ibl['error']}")
        rep.add()
        return
    tools = ibl["tools"]
    rep.add(f"Both bake the built-in studio environment written as a 2048×1024 EXR into a "
            f"{ibl['size']}² GGX-prefiltered cube with mips (matedit: {ibl['samples']} "
            f"samples a texel; cmgen: its defaults) and a {ibl['lut']}² DFG/BRDF LUT; wall "
            "time includes reading the input and writing EXRs, and for matedit creating its "
            "GL context. Error against brute force: prefiltered texels, relative, 48 random "
            "texels a level against a direct GGX-weighted sum over the source at the level's "
            "roughness (mean of the levels' means / worst texel); LUT, max |error| at 32×32 "
            "texel centres against a midpoint integration of each tool's own visibility term "
            "(bench_ibl.py). Times: median of the runs.")
    rep.add()
    rows = []
    for name, t in tools.items():
        runs = ", ".join(f"{x:.2f}" for x in t["prefilter_all"])
        rows.append([name, f"{t['prefilter_s']:.2f}", runs, f"{t['lut_s']:.2f}",
                     f"{t['mean_error']:.4f} / {t['max_error']:.3f}", f"{t['lut_error']:.1e}",
                     ", ".join(f"{x:.2f}" for x in t["levels"])])
    rep.table(["tool", "prefiltered cube (s)", "each run (s)", "LUT (s)",
               "cube error mean / max", "LUT max error", "levels (roughness)"], "lrlrrrl", rows)
    if "cmgen" in tools:
        m, c = tools["matedit"], tools["cmgen"]
        rp, rl = c["prefilter_s"] / m["prefilter_s"], c["lut_s"] / m["lut_s"]
        rep.add(f"cmgen / matedit time: prefiltered cube {rp:.2f}×, LUT {rl:.2f}×.")
        rep.add()
        goals.append(["IBL bake vs cmgen", "≤ ¼ of cmgen's time",
                      f"{1 / rp:.2f} of cmgen's time", verdict(rp >= GOALS["ibl_time_ratio"])])
        goals.append(["… with lower error", "lower than cmgen",
                      f"mean {m['mean_error']:.4f} vs {c['mean_error']:.4f}; LUT "
                      f"{m['lut_error']:.1e} vs {c['lut_error']:.1e}",
                      verdict(m["mean_error"] < c["mean_error"]
                              and m["lut_error"] < c["lut_error"])])
    else:
        rep.add("cmgen was not found, so only matedit's side ran.")
        rep.add()


def startup_section(rep: Report, st: dict, goals: list) -> None:
    rep.add("## 6. Start-up")
    rep.add()
    v = st.get("validate")
    if v and "error" not in v:
        rep.add(f"`{v['command'].replace(str(ROOT) + '/', '')}` as a subprocess: median of 5 "
                "after one warm-up run, with Python's bytecode cache on (in a fresh folder the "
                "warm-up run fills, as an installed matedit has its bytecode).")
        rep.add()
        rep.table(["command", "median (ms)", "runs (ms)"], "lrl",
                  [["matedit validate worn_painted_steel.json", ms(v["median"]),
                    ", ".join(ms(x) for x in v["all"])]])
        goals.append(["`matedit validate` one file", "< 0.3 s", f"{v['median']:.2f} s",
                      verdict(v["median"] * 1000 < GOALS["validate_ms"])])
        imp = st.get("imports")
        if imp:
            named = imp["named_ms"]
            parts = ", ".join(f"`{k}` {named[k]:.0f}" for k in IMPORT_ROWS if k in named)
            rep.add(f"Where it goes (`python -X importtime -m matedit validate`, one run of "
                    f"{imp['wall_ms']:.0f} ms): top-level imports {imp['imports_ms']:.0f} ms; "
                    f"cumulative ms, each counted where first imported: {parts}.")
            rep.add()
    elif v:
        rep.add(f"`matedit validate` not measured: {v['error']}")
        rep.add()
    e = st.get("editor", {})
    if "skipped" in e:
        rep.add(f"Editor start-up not measured: {e['skipped']}")
        rep.add()
        return
    rep.add("Editor, launch to first viewport frame, under Xvfb (one `xvfb-run` server for "
            "all launches). The editor has no exit-after-first-frame hook, so "
            "benchmarks/bench_startup.py drives it: a child process does what "
            "`matedit.app.app.run()` does (QApplication, compiles off the UI thread, "
            "`MainWindow` on the built-in sample material, show, exec) and hooks "
            "`ViewportWidget.frameDrawn`; times are from just "
            "before the parent starts the child (CLOCK_MONOTONIC) to the window shown, the "
            "first viewport frame, the first frame drawn with the material's program (the "
            "start-up figure), and the first frame with the environment's lighting (baked or "
            "loaded once the first frame is on screen). Python's bytecode cache is on, in one "
            "fresh folder (PYTHONPYCACHEPREFIX). The first launch is the cold one, the goal's: a "
            "fresh HOME and Mesa shader cache (MESA_SHADER_CACHE_DIR, the cache on) and the "
            "empty bytecode folder, so it bakes the studio IBL, compiles every shader, and "
            "Python compiles every module it imports (the standard library's and numpy's "
            "included). The second, for comparison, has another fresh HOME and Mesa shader "
            "cache and the bytecode the first wrote, as on a user's machine, where matedit, "
            "Python and numpy come with their bytecode. The warm ones (median) reuse the "
            "second's HOME, every cache filled.")
    rep.add()
    rows = []
    cold = e.get("cold", {})

    def cells(d):
        if "error" in d:
            return ["failed", "", "", "", ""]
        return [ms(d.get("show", 0)), ms(d.get("first_frame", 0)),
                ms(d["material_frame"]) if "material_frame" in d else "not drawn",
                ms(d["environment_frame"]) if "environment_frame" in d else "not drawn",
                d.get("problem", "") or ""]

    installed = e.get("cold_installed", {})
    rows.append(["cold (first launch: IBL, shader and bytecode caches empty)", *cells(cold)])
    if installed:
        rows.append(["cold, bytecode as installed (IBL and shader caches empty)",
                     *cells(installed)])
    if "material_frame" in e:
        rows.append([f"warm (median of {e['runs']})", ms(e["show"]), ms(e["first_frame"]),
                     ms(e["material_frame"]),
                     ms(e["environment_frame"]) if "environment_frame" in e else "", ""])
    for i, w in enumerate(e.get("warm", [])):
        rows.append([f"warm run {i + 1}", *cells(w)])
    rep.table(["launch", "window built, show() called (ms)", "first viewport frame (ms)",
               "first frame with material (ms)", "first frame with the environment (ms)",
               "viewport problem"], "lrrrrl", rows)
    if "material_frame" in e:
        warm = e["material_frame"]
        goals.append(["editor start-up, warm (launch → first frame with the material)",
                      f"≤ {GOALS['startup_warm_ms'] / 1000:g} s", f"{warm:.2f} s",
                      verdict(warm * 1000 <= GOALS["startup_warm_ms"])])
    if "material_frame" in cold:
        c = cold["material_frame"]
        goals.append(["editor start-up, cold (empty IBL, shader and bytecode caches)",
                      f"≤ {GOALS['startup_cold_ms'] / 1000:g} s", f"{c:.2f} s",
                      verdict(c * 1000 <= GOALS["startup_cold_ms"])])
    if "material_frame" in installed:
        goals.append(["… cold with the bytecode an install brings (for comparison)", "–",
                      f"{installed['material_frame']:.2f} s", "–"])
    errors = [d["error"] for d in [cold, installed, *e.get("warm", [])] if "error" in d]
    if errors:
        rep.add("Launch errors: " + errors[0].replace("\n", " ")[:600])
        rep.add()


def ui_block_section(rep: Report, ub: dict, goals: list) -> None:
    rep.add("## 6b. The editor's UI thread: structural edits, reference mode, drag, "
            "environment, resize")
    rep.add()
    rep.add("benchmarks/bench_ui_block.py: the real MainWindow under Xvfb on the sample layered "
            "material, compiles off the UI thread (as `matedit edit`), each structural edit "
            "(add a constant node and wire it into `e1.b`, through the undo stack; a new "
            "program every time) timed from the push to the first frame painted with the new "
            "program. *UI block* is the longest gap between ticks of a 5 ms timer on the UI "
            "thread over that time. The viewport draws in its render process "
            "(matedit.render.server) and the UI thread paints the pictures it sends; the link "
            "is timed from the compiled material's arrival to the server's reply, the frames "
            "are the server's GL time. Each row is its own child process with Mesa's shader "
            "cache enabled in a fresh, empty temporary MESA_SHADER_CACHE_DIR (the only part "
            "of this report with the cache on): with the compile worker's warm-up "
            "(matedit.render.warmup) and without it (`CompileWorker.warm_up = False`).")
    rep.add()
    rows = []
    for key, label in (("cold", "no warm-up"), ("warm", "warm-up in a child process")):
        r = ub.get(key, {})
        if "error" in r or not r:
            rows.append([label, r.get("error", "not run"), "", "", "", "", ""])
            continue
        rows.append([label, f"**{r['ui_block_max_ms']:.0f}**", f"{r['ui_block_median_ms']:.0f}",
                     f"{r['latency_median_ms']:.0f}", f"{r['apply_median_ms']:.0f}",
                     f"{r['first_paint_median_ms']:.0f}", f"{r['plain_paint_median_ms']:.0f}"])
    rep.table(["", "UI block max (ms)", "UI block median (ms)", "edit → pixels median (ms)",
               "link, render process (ms)", "first frame (ms)", "plain frame (ms)"], "lrrrrrr",
              rows)
    w = ub.get("warm", {})
    if "ui_block_max_ms" in w:
        rep.add(f"{w['edits']} edits each, viewport {w['viewport'][0]}×{w['viewport'][1]} px; "
                f"the longest UI block is {w['ui_block_max_ms'] / w['plain_paint_median_ms']:.2f}"
                " of a plain frame's GL time.")
        rep.add()
        goals.append(["UI thread blocked during a structural edit",
                      f"≤ {GOALS['ui_block_ms']:.0f} ms",
                      f"{w['ui_block_max_ms']:.0f} ms (plain frame "
                      f"{w['plain_paint_median_ms']:.0f} ms)",
                      verdict(w["ui_block_max_ms"] <= GOALS["ui_block_ms"])])
    c = ub.get("cases", {})
    if "error" in c:
        rep.add(f"Other cases: error: {c['error']}")
        rep.add()
    elif c.get("cases"):
        rep.add(f"The other cases (benchmarks/bench_ui_block.py `--child cases`, no warm-up "
                f"child), viewport {c['viewport'][0]}×{c['viewport'][1]} px: reference "
                "accumulation from the mode chooser until converged, a slider drag, "
                "environment changes, window resizes, opening samples, deleting every node, "
                "undoing that and duplicating every node.")
        rep.add()
        rows = []
        for name, r in c["cases"].items():
            if name == "reference":
                what = (f"{r['samples']} samples a pixel, {r['frames']} frames in "
                        f"{r['converge_ms'] / 1e3:.1f} s"
                        + ("" if r["converged"] else " (not converged)")
                        + f", {r['paints']} paints; tick gaps p50 {r.get('gap_p50_ms', 0):.0f}"
                        f", p90 {r.get('gap_p90_ms', 0):.0f} ms, {r['gaps_over_50_ms']} over "
                        "50 ms")
            elif name == "slider":
                what = f"{r['edits']} value edits over {r['drag_ms']:.0f} ms"
            elif name == "open":
                what = "File › Open, each: " + ", ".join(
                    f"{x['sample']} {x['block_ms']:.0f}" for x in r["runs"]) + " ms"
            elif name == "delete":
                what = (f"all {r['nodes']} nodes of the last one opened: " + ", ".join(
                    f"{x['step']} {x['block_ms']:.0f}" for x in r["runs"]) + " ms")
            else:
                what = "each: " + ", ".join(f"{x['block_ms']:.0f}" for x in r["runs"]) + " ms"
            rows.append([name, f"**{r['ui_block_max_ms']:.0f}**", what])
            goals.append([f"UI thread blocked: {name}", f"≤ {GOALS['ui_block_ms']:.0f} ms",
                          f"{r['ui_block_max_ms']:.0f} ms",
                          verdict(r["ui_block_max_ms"] <= GOALS["ui_block_ms"])])
        rep.table(["case", "UI block max (ms)", "what"], "lrl", rows)


def results_json(results: dict, uiblock: dict, meta: dict, startup: dict | None = None) -> dict:
    """The report's figures under stable keys (benchmarks/README.md); milliseconds as `_ms`,
    seconds as `_seconds`; a figure not measured in this run is absent."""
    out: dict = {"meta": dict(meta, cores=os.cpu_count())}
    gl = results.get("gl", {})
    out["meta"]["gl_renderer"] = gl.get("gl_renderer")
    out["meta"]["mesa_shader_cache_disable"] = os.environ.get("MESA_SHADER_CACHE_DISABLE")
    per: dict[str, dict] = {"structural_edit_ms": {}, "materialx_per_layer_ms": {},
                            "materialx_mixed_ms": {}, "structural_jit_share": {},
                            "fragment_lines": {}, "fragment_bytes": {}}
    for r in gl.get("structural", []):
        per["structural_edit_ms"][r["sample"]] = r["total"] * 1e3
        per["structural_jit_share"][r["sample"]] = jit_share(r)
        if "fragment_bytes" in r:
            per["fragment_lines"][r["sample"]] = r["fragment_lines"]
            per["fragment_bytes"][r["sample"]] = r["fragment_bytes"]
        if "mx_shaders" in r:
            per["materialx_per_layer_ms"][r["sample"]] = r["mx_shaders"]["total"] * 1e3
        if "mx_inputs" in r:
            per["materialx_mixed_ms"][r["sample"]] = r["mx_inputs"]["total"] * 1e3
    out.update({k: v for k, v in per.items() if v})
    if "parameter" in gl:
        p = gl["parameter"]
        out["param_edit_links"] = p["links"]
        out["param_edit_ms"] = p["edit_to_frame"] * 1e3
        out["param_plain_frame_ms"] = p["frame"] * 1e3
    if "frames" in gl:
        out["frame_ms"] = {str(f["size"]): f["material"] * 1e3 for f in gl["frames"]}
        out["floor_ms"] = {str(f["size"]): f["floor"] * 1e3 for f in gl["frames"]}
    if "promoted_frames" in gl:
        out["frame_promoted_ms"] = {str(f["size"]): f["material"] * 1e3
                                    for f in gl["promoted_frames"]}
        out["floor_promoted_ms"] = {str(f["size"]): f["floor"] * 1e3
                                    for f in gl["promoted_frames"]}
    comp = results.get("compile", {})
    if "scaling" in comp:
        out["compile_ms"] = {str(s["nodes"]): s["seconds"] * 1e3 for s in comp["scaling"]}
    tools = results.get("ibl", {}).get("tools", {})
    if "matedit" in tools:
        out["ibl_seconds"] = tools["matedit"]["prefilter_s"]
        out["ibl_lut_error"] = tools["matedit"]["lut_error"]
    if "cmgen" in tools:
        out["cmgen_seconds"] = tools["cmgen"]["prefilter_s"]
        out["cmgen_lut_error"] = tools["cmgen"]["lut_error"]
    for key, suffix in (("warm", ""), ("cold", "_no_warmup")):
        r = uiblock.get(key, {})
        if "ui_block_max_ms" in r:
            out["ui_block_max_ms" + suffix] = r["ui_block_max_ms"]
            out["editor_structural_edit_ms" + suffix] = r["latency_median_ms"]
    for name, r in uiblock.get("cases", {}).get("cases", {}).items():
        out[f"ui_block_{name}_max_ms"] = r["ui_block_max_ms"]
    ref = uiblock.get("cases", {}).get("cases", {}).get("reference", {})
    if ref.get("converged"):
        out["reference_converge_ms"] = ref["converge_ms"]
    v = (startup or {}).get("validate", {})
    if "median" in v:
        out["validate_ms"] = v["median"] * 1e3
    editor = (startup or {}).get("editor", {})
    if "material_frame" in editor:
        out["startup_warm_ms"] = editor["material_frame"] * 1e3
    if "material_frame" in editor.get("cold", {}):
        out["startup_cold_ms"] = editor["cold"]["material_frame"] * 1e3
    if "environment_frame" in editor:
        out["startup_environment_warm_ms"] = editor["environment_frame"] * 1e3
    if "environment_frame" in editor.get("cold", {}):
        out["startup_environment_cold_ms"] = editor["cold"]["environment_frame"] * 1e3
    if "material_frame" in editor.get("cold_installed", {}):
        out["startup_cold_installed_ms"] = editor["cold_installed"]["material_frame"] * 1e3
    return out


def optional_section(rep: Report, opt: dict) -> None:
    rep.add("## 7. Node canvas and editor responsiveness (benchmarks written elsewhere)")
    rep.add()
    rep.add("run_all.py runs these when they exist (hook: `OPTIONAL_BENCHES` / "
            "`run_optional()` in benchmarks/run_all.py), under Xvfb, and keeps their output "
            "verbatim.")
    rep.add()
    for script, title in OPTIONAL_BENCHES:
        res = opt.get(script, {"missing": True})
        rep.add(f"### {title} (benchmarks/{script})")
        rep.add()
        if res.get("missing"):
            rep.add(f"benchmarks/{script} did not exist when this report was written; the next "
                    "`benchmarks/run.sh` picks it up.")
            rep.add()
            continue
        if res.get("stdout", "").strip():
            rep.add("```")
            rep.add(res["stdout"].rstrip())
            rep.add("```")
            rep.add()
        if "error" in res:
            rep.add(f"Failed: {res['error'][:800]}")
            rep.add()
        rep.add(f"({res['wall']:.0f} s)")
        rep.add()


def load_average() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "?"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", choices=sorted(CHILDREN))
    parser.add_argument("--quick", action="store_true", help="fewer repetitions, smaller IBL")
    parser.add_argument("--out", default=str(HERE / "RESULTS.md"))
    parser.add_argument("--skip", default="", help="comma-separated sections to skip: "
                        "gl,jit,compile,ibl,profile,native,startup,uiblock,optional")
    args = parser.parse_args(argv)
    if args.child:
        result = CHILDREN[args.child](args.quick)
        print("RESULT " + json.dumps(result), flush=True)
        return 0

    skip = set(filter(None, args.skip.split(",")))
    started = time.perf_counter()
    when = datetime.datetime.now().astimezone()
    load_before = load_average()
    results: dict = {}
    plan = [("gl", "gl", 660, None), ("jit", "jit", 120, None),
            ("jit-nopt", "jit", 120, {"GALLIVM_PERF": "nopt"}),
            ("compile", "compile", 240, None), ("ibl", "ibl", 420, None),
            ("profile", "profile", 120, None)]
    for key, child, timeout, env in plan:
        if child in skip:
            results[key] = {"error": "skipped (--skip)"}
            continue
        print(f"[run_all] {key} …", file=sys.stderr, flush=True)
        results[key] = run_child(child, args.quick, timeout, env)
        print(f"[run_all] {key}: {results[key].get('wall', 0):.0f} s", file=sys.stderr,
              flush=True)
    if "native" in skip:
        results["native"] = {"error": "skipped (--skip)"}
    else:
        print("[run_all] native profile …", file=sys.stderr, flush=True)
        results["native"] = native_profile(args.quick)
    startup: dict = {}
    if "startup" not in skip:
        import bench_startup

        from matedit.resources import graphs_dir

        print("[run_all] startup …", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        sample = graphs_dir() / "materials" / "worn_painted_steel.json"
        try:
            startup["validate"] = bench_startup.validate_times(sample)
            startup["imports"] = bench_startup.import_breakdown(sample)
        except (subprocess.CalledProcessError, OSError) as exc:
            startup["validate"] = {"error": str(exc)}
        try:
            startup["editor"] = bench_startup.editor_times(repeat=1 if args.quick else 3)
        except (subprocess.SubprocessError, OSError) as exc:
            startup["editor"] = {"skipped": f"failed: {exc}"}
        startup["wall"] = time.perf_counter() - t0
    uiblock: dict = {}
    if "uiblock" not in skip:
        import bench_ui_block

        print("[run_all] ui block …", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        uiblock = bench_ui_block.run(edits=4 if args.quick else 8)
        uiblock["wall"] = time.perf_counter() - t0
    optional: dict = {}
    if "optional" not in skip:
        for script, _ in OPTIONAL_BENCHES:
            print(f"[run_all] {script} …", file=sys.stderr, flush=True)
            optional[script] = run_optional(script, OPTIONAL_TIMEOUT_S)
    total = time.perf_counter() - started

    gl = results["gl"]
    rep = Report()
    command = os.environ.get("MATEDIT_BENCH_COMMAND") or " ".join(
        ["python", "benchmarks/run_all.py", *(argv if argv is not None else sys.argv[1:])])
    rep.add("# matedit benchmark results")
    rep.add()
    rep.add("Written by `benchmarks/run_all.py`; every figure below comes from the run "
            "described here (medians; ratios of figures measured side by side in this run).")
    rep.add()
    rep.add(f"- Date: {when:%Y-%m-%d %H:%M %Z}")
    rep.add(f"- Machine: {os.cpu_count()} cores, {platform.platform()}, "
            f"Python {platform.python_version()}; load average before / after the run: "
            f"{load_before} / {load_average()} (other work on the machine shows up as noise)")
    rep.add(f"- GL: {gl.get('gl_renderer', '?')}, {gl.get('gl_version', '?')}, headless EGL "
            f"through moderngl; MESA_SHADER_CACHE_DISABLE="
            f"{os.environ.get('MESA_SHADER_CACHE_DISABLE')}")
    rep.add(f"- Command: `{command}`" + (" (quick mode: fewer repetitions)" if args.quick
                                         else ""))
    rep.add(f"- Wall time of the whole run: {total / 60:.1f} min")
    rep.add()
    goals: list = []
    structural_section(rep, gl, goals)
    parameter_section(rep, gl, goals)
    frame_section(rep, gl, goals)
    compile_section(rep, results["compile"], goals)
    ibl_section(rep, results["ibl"], goals)
    if startup:
        startup_section(rep, startup, goals)
    if uiblock:
        ui_block_section(rep, uiblock, goals)
    if optional:
        optional_section(rep, optional)
    rep.add("## Goals")
    rep.add()
    rep.add("Each verdict is this run's measured value against the target (the report holds no "
            "reading written before the run: a verdict that flips between runs flips here).")
    rep.add()
    rep.table(["goal", "target", "measured", "verdict"], "llll", goals)
    profile_sections(rep, gl, results)
    from matedit.io.atomic import atomic_write_text

    atomic_write_text(Path(args.out), "\n".join(rep.lines).rstrip() + "\n")
    figures = results_json(results, uiblock, {"date": when.isoformat(timespec="minutes"),
                                              "command": command, "quick": bool(args.quick)},
                           startup)
    json_out = Path(args.out).with_name("results.json")
    atomic_write_text(json_out, json.dumps(figures, indent=1, sort_keys=True) + "\n")
    print(f"[run_all] wrote {args.out} and {json_out.name} in {total / 60:.1f} min",
          file=sys.stderr)
    return 0


def _tree(text: str, limit: int = 60) -> str:
    lines = [x for x in text.splitlines() if x.strip()]
    body = [x for x in lines if not x.lstrip().startswith(("_", "/", "Recorded", "Program"))]
    return "\n".join(body[:limit])


def profile_sections(rep: Report, gl: dict, results: dict) -> None:
    rep.add("## Profiles: where the time goes")
    rep.add()
    rep.add("### Structural edit on llvmpipe")
    rep.add()
    native = results.get("native", {})
    if "shares" in native:
        rep.add(f"py-spy `--native` over structural edits of `worn_painted_steel` "
                f"({native['samples']} samples of the main thread, 100 Hz; shares, since "
                "sampling slows the process):")
        rep.add()
        rep.table(["where", "share"], "lr",
                  [[k, f"{v * 100:.0f} %"] for k, v in native["shares"].items()])
    elif "error" in native:
        rep.add(f"py-spy profile not taken: {native['error']}")
        rep.add()
    jit, nopt = results.get("jit", {}), results.get("jit-nopt", {})
    if "variants" in jit:
        linked = ("split-sum branch only" if jit.get("renderer_specialises")
                  else "both IBL branches")
        rep.add("Link and first frame of variants of the layered sample's program (median of "
                "5 each, interleaved, 512²), with llvmpipe's LLVM optimisation passes on "
                "(default) and off (`GALLIVM_PERF=nopt`). *Both IBL branches* keeps the "
                "reference-IBL estimator (a sampling loop) next to the split sum, *split-sum "
                "branch only* leaves it out; the renderer in this tree links the "
                f"*{linked}* program for the split-sum preview. The floor is constant "
                "material inputs with the same lighting library:")
        rep.add()
        rows = []
        for label, res in (("default", jit), ("nopt", nopt)):
            for v in res.get("variants", []):
                rows.append([v["name"], label, f"{v['fragment_chars']:,}", ms(v["link"]),
                             ms(v["first_frame"]), f"**{ms(v['total'])}**", ms(v["frame"])])
        rep.table(["program", "GALLIVM_PERF", "fragment chars", "link (ms)",
                   "first frame (ms)", "link + first frame (ms)", "next frame (ms)"],
                  "llrrrrr", rows)
        v = {x["name"].split(", ")[-1]: x for x in jit["variants"]}
        if len(v) == 3:
            both, split = v["both IBL branches"], v["split-sum branch only"]
            floor = v["hand-written floor"]
            n = {x["name"].split(", ")[-1]: x for x in nopt.get("variants", [])}
            line = (f"In this run: leaving the reference branch out changes link + first "
                    f"frame by {100 * (split['total'] / both['total'] - 1):+.0f} %; the floor "
                    f"costs {100 * floor['total'] / split['total']:.0f} % of the split-sum "
                    f"program, so the graph's own code accounts for about "
                    f"{ms(split['total'] - floor['total'])} ms of it")
            if "split-sum branch only" in n:
                ns = n["split-sum branch only"]
                line += (f"; `GALLIVM_PERF=nopt` changes the split-sum program's link + "
                         f"first frame by {100 * (ns['total'] / split['total'] - 1):+.0f} % "
                         f"and its next frame by {100 * (ns['frame'] / split['frame'] - 1):+.0f}"
                         " %")
            rep.add(line + ".")
            rep.add()
    prof = results.get("profile", {})
    for key, title in (("edit", "pyinstrument over one structural edit of "
                                "`worn_painted_steel` (Python's view: time inside moderngl's "
                                "`render`/`copy_framebuffer` is llvmpipe)"),
                       ("compile", "pyinstrument over 10 compiles of the 1,000-node synthetic "
                                   "graph")):
        if key in prof:
            rep.add(title + ":")
            rep.add()
            rep.add("```")
            rep.add(_tree(prof[key]))
            rep.add("```")
            rep.add()
    if "error" in prof:
        rep.add(f"pyinstrument profiles not taken: {prof['error'][:400]}")
        rep.add()


if __name__ == "__main__":
    sys.exit(main())
