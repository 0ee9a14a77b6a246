"""Compile time against graph size, and the GL link time of each sample on this machine.

Run: MESA_SHADER_CACHE_DISABLE=true .venv/bin/python benchmarks/bench_compile.py [--samples]

--samples: only `compile_document` of each sample material (no GL), a new FileResolver per
compile as every CLI command makes one: the first compile (files read and schema-checked)
and the median of the next ones (matedit.io.document's cache of unchanged files).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")

from common import machine, median_time, synthetic_material  # noqa: E402

from matedit.compiler import compile_document  # noqa: E402
from matedit.io.document import FileResolver, load  # noqa: E402
from matedit.resources import graphs_dir  # noqa: E402


def compile_scaling(sizes=(10, 100, 1000, 10000)) -> list[tuple[int, int, float]]:
    rows = []
    for n in sizes:
        doc = synthetic_material(n)
        real = len(doc.graph.nodes)
        t = median_time(lambda d=doc: compile_document(d, FileResolver()),
                        repeat=3 if n >= 10000 else 5)
        rows.append((n, real, t))
    return rows


def link_times() -> list[tuple[str, float, float]]:
    import moderngl

    ctx = moderngl.create_standalone_context(backend="egl")
    rows = []
    for path in sorted((graphs_dir() / "materials").glob("*.json")):
        doc = load(path)
        cm = compile_document(doc, FileResolver())
        t_compile = median_time(lambda d=doc: compile_document(d, FileResolver()), repeat=5)

        def link(cm=cm):
            ctx.program(vertex_shader=cm.vertex_text, fragment_shader=cm.fragment_text).release()

        rows.append((path.stem, t_compile, median_time(link, repeat=3)))
    ctx.release()
    return rows


def sample_compile_times(repeat: int = 9) -> list[tuple[str, float, float]]:
    """(sample, first compile, median of the next `repeat`) in seconds, in one process."""
    import time

    rows = []
    for path in sorted((graphs_dir() / "materials").glob("*.json")):
        doc = load(path)
        t0 = time.perf_counter()
        compile_document(doc, FileResolver())
        first = time.perf_counter() - t0
        rows.append((path.stem, first,
                     median_time(lambda d=doc: compile_document(d, FileResolver()),
                                 repeat=repeat)))
    return rows


def main() -> None:
    if "--samples" in sys.argv[1:]:
        print(f"# sample compiles on {machine()}, a new FileResolver per compile")
        print("\n| sample | first compile (ms) | next compiles (ms, median of 9) |")
        print("|---|---:|---:|")
        for name, first, rest in sample_compile_times():
            print(f"| {name} | {first * 1000:.1f} | {rest * 1000:.1f} |")
        return
    print(f"# compile benchmark on {machine()}")
    print(f"# MESA_SHADER_CACHE_DISABLE={os.environ.get('MESA_SHADER_CACHE_DISABLE')}")
    print("\n| nodes | graph -> GLSL (ms, median) | growth per decade |")
    print("|---:|---:|---:|")
    rows = compile_scaling()
    for i, (_n, real, t) in enumerate(rows):
        growth = f"{t / rows[i - 1][2]:.1f}x" if i else ""
        print(f"| {real} | {t * 1000:.1f} | {growth} |")
    print("\n| sample | graph -> GLSL (ms) | GL compile + link on llvmpipe (ms) |")
    print("|---|---:|---:|")
    for name, tc, tl in link_times():
        print(f"| {name} | {tc * 1000:.1f} | {tl * 1000:.0f} |")


if __name__ == "__main__":
    main()
