"""What the lobes beyond the talk cost the samples that do not use them (issue 23).

    MESA_SHADER_CACHE_DISABLE=true python benchmarks/bench_lobes.py [--old TREE]
        [--size 256] [--frames 9] [--edits 3] [--rounds 2]

For each of the 14 pre-lobe samples (the graphs stored in tests/data/sample_renders/graphs,
so both trees draw exactly the same documents) it measures, in ONE run, with the tree before
the lobes (OLD: commit 0fd033b, exported with `git archive` to a temporary folder unless
--old names a checkout) and with this tree (NEW):

- frame: median of --frames warm frames (render + glFinish, one warm-up frame first), at
  --size square, studio environment, default lights, split-sum;
- structural edit: compile the graph to GLSL and link the program (the renderer's program
  cache cleared first, as a structural edit does), median of --edits.

Each tree runs in its own child process (`python -P` with only that tree on PYTHONPATH, so
its own matedit and shaders are imported) with MESA_SHADER_CACHE_DISABLE=true, so every link
really compiles. The children alternate OLD, NEW, OLD, NEW ... for --rounds rounds so that
load on the (shared) machine hits both, and each figure is the smallest of its rounds'
medians (the least-disturbed one). The ratio NEW / OLD should be <= 1.05: the lobe fields
at their defaults compile to nothing. Timings are never asserted anywhere.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
GRAPHS = ROOT / "tests" / "data" / "sample_renders" / "graphs" / "materials"
OLD_COMMIT = "0fd033b"
TARGET = 1.05


def child(size: int, frames: int, edits: int) -> dict:
    """Runs inside one tree: {sample: {"frame": s, "edit": s}} for every stored sample."""
    import moderngl

    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer

    ctx = moderngl.create_standalone_context(backend="egl")
    r = Renderer(ctx, (size, size), environment="studio")
    r.render()
    ctx.finish()
    out: dict = {}
    for path in sorted(GRAPHS.glob("*.json")):
        doc = load(path)
        edit_times = []
        for _ in range(edits):
            r._programs.clear()  # a structural edit links a new program
            t0 = time.perf_counter()
            r.set_material(compile_document(doc, FileResolver()))
            ctx.finish()
            edit_times.append(time.perf_counter() - t0)
        r.render()  # warm-up frame
        ctx.finish()
        frame_times = []
        for _ in range(frames):
            t0 = time.perf_counter()
            r.render()
            ctx.finish()
            frame_times.append(time.perf_counter() - t0)
        out[path.stem] = {"frame": statistics.median(frame_times),
                          "edit": statistics.median(edit_times)}
    r.release()
    ctx.release()
    return out


def run_child(tree: Path, args) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), MESA_SHADER_CACHE_DISABLE="true")
    cmd = [sys.executable, "-P", str(Path(__file__).resolve()), "--child", "--size",
           str(args.size), "--frames", str(args.frames), "--edits", str(args.edits)]
    proc = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True)
    if proc.returncode:
        raise SystemExit(f"{tree}: child failed:\n{proc.stderr[-2000:]}")
    line = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")][-1]
    return json.loads(line[len("RESULT "):])


def export_old(dest: Path) -> Path:
    """The pre-lobe tree from git (matedit, shaders and the rest), read-only use."""
    proc = subprocess.run(["git", "-C", str(ROOT), "archive", OLD_COMMIT], capture_output=True,
                          check=True)
    tar = dest / "old.tar"
    tar.write_bytes(proc.stdout)
    with tarfile.open(tar) as t:
        t.extractall(dest / "old", filter="data")
    return dest / "old"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", type=Path, default=None, help=f"checkout of {OLD_COMMIT}")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--frames", type=int, default=9)
    ap.add_argument("--edits", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print("RESULT " + json.dumps(child(args.size, args.frames, args.edits)), flush=True)
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        old = args.old.resolve() if args.old else export_old(Path(tmp))
        runs: dict[str, list[dict]] = {"old": [], "new": []}
        t0 = time.perf_counter()
        for _ in range(args.rounds):
            runs["old"].append(run_child(old, args))
            runs["new"].append(run_child(ROOT, args))
        wall = time.perf_counter() - t0
    best = {k: {s: {m: min(run[s][m] for run in v) for m in ("frame", "edit")}
                for s in v[0]} for k, v in runs.items()}
    print(f"Pre-lobe samples, OLD = {OLD_COMMIT} ({old if args.old else 'git archive'}), "
          f"NEW = this tree; {args.size}x{args.size}, frame = median of {args.frames} warm "
          f"frames, edit = compile + link, median of {args.edits}; best of {args.rounds} "
          f"alternating rounds; MESA_SHADER_CACHE_DISABLE=true; {os.cpu_count()} cores "
          f"(shared: expect a few % noise); {wall:.0f} s")
    print()
    print("| sample | frame old ms | frame new ms | ratio | edit old ms | edit new ms | ratio |")
    print("|---|---|---|---|---|---|---|")
    ratios: dict[str, list[float]] = {"frame": [], "edit": []}
    for s in sorted(best["old"]):
        o, n = best["old"][s], best["new"][s]
        cells = [s]
        for m in ("frame", "edit"):
            ratio = n[m] / o[m]
            ratios[m].append(ratio)
            cells += [f"{o[m] * 1000:.2f}", f"{n[m] * 1000:.2f}", f"{ratio:.3f}"]
        print("| " + " | ".join(cells) + " |")
    print()
    for m, name in (("frame", "frame time"), ("edit", "structural edit")):
        med = statistics.median(ratios[m])
        print(f"{name}: median ratio new/old {med:.3f}, max {max(ratios[m]):.3f} "
              f"(target <= {TARGET}: {'met' if med <= TARGET else 'missed'} on the median)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
