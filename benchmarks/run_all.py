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
)
OPTIONAL_TIMEOUT_S = 240

GOALS = {
    "structural_ms": 50.0,
    "structural_ratio": 80.0,
    "frame_ratio": 1.2,
    "compile_1000_ms": 30.0,
    "ibl_time_ratio": 4.0,
    "validate_ms": 300.0,
}


def ms(seconds: float, digits: int = 0) -> str:
    return f"{seconds * 1000:.{digits}f}"


# == child sections =============================================================================


def child_gl(quick: bool) -> dict:
    """Structural edits (matedit and MaterialX), parameter edit, frame time vs the floor."""
    import moderngl
    from bench_render import frame_time, frame_vs_floor, parameter_edit, structural_edit

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
        c, li, f, tot = structural_edit(r, ctx, doc, repeat=repeat)
        row = {"sample": path.stem, "compile": c, "link": li, "first_frame": f, "total": tot}
        if mx_side is not None:
            eq = equivalent_of(path)
            row["layers"] = eq.layers
            row["mx_shaders"] = mx_side.structural_edit(eq, repeat=repeat, mode="shaders")
            row["mx_shaders"]["describe"] = eq.describe("shaders")
            if eq.layers > 1:
                row["mx_inputs"] = mx_side.structural_edit(eq, repeat=repeat, mode="inputs")
                row["mx_inputs"]["describe"] = eq.describe("inputs")
        row["steady_frame"] = frame_time(r, ctx, frames=3)
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
    t_param, links = parameter_edit(r, ctx, material, repeat=9 if not quick else 3,
                                    values=values)
    out["parameter"] = {"sample": "worn_painted_steel", "parameter": floats[0].name,
                        "edit_to_frame": t_param, "links": links,
                        "frame": frame_time(r, ctx, frames=9 if not quick else 3)}

    # frame time against the hand-written floor
    out["frames"] = [{"size": s, "material": tm, "floor": tf}
                     for s, tm, tf in frame_vs_floor(r, ctx, material, (512, 1024),
                                                     frames=7 if not quick else 3)]
    r.release()
    return out


def child_gl_nopt(quick: bool) -> dict:
    """The layered sample's structural edit and frame with llvmpipe's LLVM optimisation off
    (GALLIVM_PERF=nopt, set by the parent): how much of the edit is the JIT's optimiser."""
    import moderngl
    from bench_render import frame_time, structural_edit

    from matedit.io.document import load
    from matedit.render import Renderer
    from matedit.resources import graphs_dir

    ctx = moderngl.create_standalone_context(backend="egl")
    r = Renderer(ctx, (512, 512))
    r.render()
    ctx.finish()
    doc = load(graphs_dir() / "materials" / "worn_painted_steel.json")
    c, li, f, tot = structural_edit(r, ctx, doc, repeat=1 if quick else 3)
    frame = frame_time(r, ctx, frames=3 if quick else 5)
    r.release()
    return {"gallivm_perf": os.environ.get("GALLIVM_PERF", ""), "compile": c, "link": li,
            "first_frame": f, "total": tot, "frame": frame}


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
    """pyinstrument over one structural edit of the layered sample: where the Python time
    goes, and how much is spent inside the GL calls (llvmpipe)."""
    import moderngl
    from pyinstrument import Profiler

    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer
    from matedit.resources import graphs_dir

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
    text = profiler.output_text(unicode=False, color=False, show_all=False)
    r.release()
    return {"text": text}


CHILDREN = {"gl": child_gl, "gl-nopt": child_gl_nopt, "compile": child_compile,
            "ibl": child_ibl, "profile": child_profile}


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
            f"{ms(mxs['generate'], 1)} / {ms(mxs['link'])} / {ms(mxs['first_frame'])}"
            if mxs else "–",
            f"**{ms(mxs['total'])}**" if mxs else "–",
            f"{mxs['total'] / r['total']:.1f}×" if mxs else "–",
            f"{ms(mxi['total'])}" if mxi else "–",
            f"{mxi['total'] / r['total']:.1f}×" if mxi else "–",
        ])
    rep.table(["sample", "layers", "matedit compile (ms)", "link (ms)", "first frame (ms)",
               "matedit total (ms)", "matedit next frame (ms)",
               "MaterialX per-layer gen / link / first frame (ms)",
               "MaterialX per-layer total (ms)", "ratio", "MaterialX mixed inputs total (ms)",
               "ratio"], "lrrrrrrrrrrr", rows)
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
        goals.append(["structural edit, layered sample", "< 50 ms",
                      f"{ms(min(r['total'] for r in layered))}–{ms(worst['total'])} ms",
                      verdict(worst["total"] * 1000 < GOALS["structural_ms"])])
        if all("mx_shaders" in r for r in layered):
            lo = min(r["mx_shaders"]["total"] / r["total"] for r in layered)
            hi = max(r["mx_shaders"]["total"] / r["total"] for r in layered)
            goals.append(["… vs MaterialX per-layer equivalent", "≥ 80× faster",
                          f"{lo:.0f}–{hi:.0f}×", verdict(lo >= GOALS["structural_ratio"])])
        if all("mx_inputs" in r for r in layered):
            lo = min(r["mx_inputs"]["total"] / r["total"] for r in layered)
            hi = max(r["mx_inputs"]["total"] / r["total"] for r in layered)
            goals.append(["… vs MaterialX mixed-inputs equivalent", "≥ 80× faster",
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
            "the edits, next to a plain frame measured right after.")
    rep.add()
    rep.table(["edit → frame (ms)", "plain frame (ms)", "ratio", "program links caused"],
              "rrrr", [[ms(p["edit_to_frame"]), ms(p["frame"]),
                        f"{p['edit_to_frame'] / p['frame']:.2f}", str(p["links"])]])
    goals.append(["parameter edit", "0 links, one frame",
                  f"{p['links']} links, {p['edit_to_frame'] / p['frame']:.2f}× a frame",
                  verdict(p["links"] == 0 and p["edit_to_frame"] / p["frame"] < 1.2)])


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
            "Median of the frames, each `render()` + `ctx.finish()`.")
    rep.add()
    rows = [[f"{f['size']}²", ms(f["material"]), ms(f["floor"]),
             f"{f['material'] / f['floor']:.2f}"] for f in gl["frames"]]
    rep.table(["size", "worn_painted_steel (ms)", "floor (ms)", "ratio"], "lrrr", rows)
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
        goals.append(["… linear beyond (1k → 10k)", "≈ 10× per decade", f"{g:.1f}×",
                      verdict(g <= 13.0)])


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
        rows.append([name, f"{t['prefilter_s']:.2f}", f"{t['lut_s']:.2f}",
                     f"{t['mean_error']:.4f} / {t['max_error']:.3f}", f"{t['lut_error']:.1e}",
                     ", ".join(f"{x:.2f}" for x in t["levels"])])
    rep.table(["tool", "prefiltered cube (s)", "LUT (s)", "cube error mean / max",
               "LUT max error", "levels (roughness)"], "lrrrrl", rows)
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
                "after one warm-up run.")
        rep.add()
        rep.table(["command", "median (ms)", "runs (ms)"], "lrl",
                  [["matedit validate worn_painted_steel.json", ms(v["median"]),
                    ", ".join(ms(x) for x in v["all"])]])
        goals.append(["`matedit validate` one file", "< 0.3 s", f"{v['median']:.2f} s",
                      verdict(v["median"] * 1000 < GOALS["validate_ms"])])
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
            "`matedit.app.app.run()` does (QApplication, `MainWindow` on the built-in sample "
            "material, show, exec) and hooks `ViewportWidget.frameDrawn`; times are from just "
            "before the parent starts the child (CLOCK_MONOTONIC) to the window shown, the "
            "first viewport frame, and the first frame drawn with the material's program. "
            "Fresh HOME; the first launch bakes the studio IBL into the empty cache (cold), "
            "the next ones load it (warm, median).")
    rep.add()
    rows = []
    cold = e.get("cold", {})

    def cells(d):
        if "error" in d:
            return ["failed", "", "", ""]
        return [ms(d.get("show", 0)), ms(d.get("first_frame", 0)),
                ms(d["material_frame"]) if "material_frame" in d else "not drawn",
                d.get("problem", "") or ""]

    rows.append(["cold (first launch)", *cells(cold)])
    if "material_frame" in e:
        rows.append([f"warm (median of {e['runs']})", ms(e["show"]), ms(e["first_frame"]),
                     ms(e["material_frame"]), ""])
    for i, w in enumerate(e.get("warm", [])):
        rows.append([f"warm run {i + 1}", *cells(w)])
    rep.table(["launch", "window built, show() called (ms)", "first viewport frame (ms)",
               "first frame with material (ms)", "viewport problem"], "lrrrl", rows)
    errors = [d["error"] for d in [cold, *e.get("warm", [])] if "error" in d]
    if errors:
        rep.add("Launch errors: " + errors[0].replace("\n", " ")[:600])
        rep.add()


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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", choices=sorted(CHILDREN))
    parser.add_argument("--quick", action="store_true", help="fewer repetitions, smaller IBL")
    parser.add_argument("--out", default=str(HERE / "RESULTS.md"))
    parser.add_argument("--skip", default="", help="comma-separated sections to skip: "
                        "gl,gl-nopt,compile,ibl,profile,startup,optional")
    args = parser.parse_args(argv)
    if args.child:
        result = CHILDREN[args.child](args.quick)
        print("RESULT " + json.dumps(result), flush=True)
        return 0

    skip = set(filter(None, args.skip.split(",")))
    started = time.perf_counter()
    when = datetime.datetime.now().astimezone()
    results: dict = {}
    budget = {"gl": 600, "gl-nopt": 120, "compile": 240, "ibl": 400, "profile": 120}
    for name in ("gl", "gl-nopt", "compile", "ibl", "profile"):
        if name in skip:
            results[name] = {"error": "skipped (--skip)"}
            continue
        print(f"[run_all] {name} …", file=sys.stderr, flush=True)
        env = {"GALLIVM_PERF": "nopt"} if name == "gl-nopt" else None
        results[name] = run_child(name, args.quick, budget[name], env)
        print(f"[run_all] {name}: {results[name].get('wall', 0):.0f} s", file=sys.stderr,
              flush=True)
    startup: dict = {}
    if "startup" not in skip:
        import bench_startup

        from matedit.resources import graphs_dir

        print("[run_all] startup …", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        try:
            startup["validate"] = bench_startup.validate_times(
                graphs_dir() / "materials" / "worn_painted_steel.json")
        except (subprocess.CalledProcessError, OSError) as exc:
            startup["validate"] = {"error": str(exc)}
        try:
            startup["editor"] = bench_startup.editor_times(repeat=1 if args.quick else 3)
        except (subprocess.SubprocessError, OSError) as exc:
            startup["editor"] = {"skipped": f"failed: {exc}"}
        startup["wall"] = time.perf_counter() - t0
    optional: dict = {}
    if "optional" not in skip:
        for script, _ in OPTIONAL_BENCHES:
            optional[script] = run_optional(script, OPTIONAL_TIMEOUT_S)
    total = time.perf_counter() - started

    gl = results["gl"]
    rep = Report()
    command = os.environ.get("MATEDIT_BENCH_COMMAND") or " ".join(
        ["python", "benchmarks/run_all.py", *(argv if argv is not None else sys.argv[1:])])
    rep.add("# matedit benchmark results")
    rep.add()
    rep.add(f"- Date: {when:%Y-%m-%d %H:%M %Z}")
    rep.add(f"- Machine: {platform.node()}, {os.cpu_count()} cores, "
            f"{platform.platform()}, Python {platform.python_version()}")
    rep.add(f"- GL: {gl.get('gl_renderer', '?')} ({gl.get('gl_version', '?')}), headless EGL; "
            f"MESA_SHADER_CACHE_DISABLE={os.environ.get('MESA_SHADER_CACHE_DISABLE')}")
    rep.add(f"- Command: `{command}`" + (" (quick mode)" if args.quick else ""))
    rep.add(f"- Wall time of the whole run: {total / 60:.1f} min")
    rep.add()
    goals: list = []
    structural_section(rep, gl, goals)
    parameter_section(rep, gl, goals)
    frame_section(rep, gl, goals)
    compile_section(rep, results["compile"], goals)
    ibl_section(rep, results["ibl"], goals)
    startup_section(rep, startup, goals) if startup else None
    optional_section(rep, optional) if optional else None
    nopt = results["gl-nopt"]
    extra_sections(rep, gl, nopt, results["profile"])
    rep.add("## Goals")
    rep.add()
    rep.table(["goal", "target", "measured", "verdict"], "llll", goals)
    notes = HERE / "RESULTS_NOTES.md"
    if notes.exists():
        rep.add(notes.read_text().rstrip())
        rep.add()
    Path(args.out).write_text("\n".join(rep.lines).rstrip() + "\n")
    print(f"[run_all] wrote {args.out} in {total / 60:.1f} min", file=sys.stderr)
    return 0


def extra_sections(rep: Report, gl: dict, nopt: dict, prof: dict) -> None:
    rep.add("## Where a structural edit's time goes")
    rep.add()
    layered = next((r for r in gl.get("structural", []) if r["sample"] == "worn_painted_steel"),
                   None)
    if layered and "error" not in nopt:
        jit = layered["first_frame"] - layered["steady_frame"]
        rep.add(f"`worn_painted_steel`: compile {ms(layered['compile'], 1)} ms, GL link "
                f"{ms(layered['link'])} ms, first frame {ms(layered['first_frame'])} ms of "
                f"which about {ms(jit)} ms is more than a steady frame "
                f"({ms(layered['steady_frame'])} ms): llvmpipe compiles the fragment shader's "
                "LLVM IR to machine code when the program is first drawn.")
        rep.add()
        rep.add("The same edit with llvmpipe's LLVM optimisation passes turned off "
                "(`GALLIVM_PERF=nopt`, a child process):")
        rep.add()
        rep.table(["GALLIVM_PERF", "compile (ms)", "link (ms)", "first frame (ms)",
                   "total (ms)", "steady frame (ms)"], "lrrrrr",
                  [["(default)", ms(layered["compile"], 1), ms(layered["link"]),
                    ms(layered["first_frame"]), ms(layered["total"]),
                    ms(layered["steady_frame"])],
                   ["nopt", ms(nopt["compile"], 1), ms(nopt["link"]), ms(nopt["first_frame"]),
                    ms(nopt["total"]), ms(nopt["frame"])]])
    if "text" in prof:
        rep.add("pyinstrument over one structural edit of `worn_painted_steel` (Python view; "
                "time inside `render`/`finish` is llvmpipe's native JIT and rasterisation):")
        rep.add()
        rep.add("```")
        text = "\n".join(x for x in prof["text"].splitlines() if x.strip())
        rep.add(text[:6000])
        rep.add("```")
        rep.add()
    elif "error" in prof:
        rep.add(f"Profile not taken: {prof['error'][:400]}")
        rep.add()


if __name__ == "__main__":
    sys.exit(main())
