"""Material instances: what an instance edit and a static switch toggle cost, headless.

Run: .venv/bin/python benchmarks/bench_instances.py [--quick]   (prints medians; passes or
fails nothing)

On `graphs/instances/worn_paint_red.json` (an instance of the three-layer
worn_painted_steel), 512² with 4x MSAA, sphere, studio environment, one EGL context:

- instance parameter edit -> next frame: what the instance editor does for a slider step
  (override in the instance, re-resolve the parent chain from disk, upload the uniform
  block) then `render()` + `ctx.finish()`; the program links it caused (expected 0).
- static switch toggle -> frame, cold: rust_on flipped, the chain re-resolved, the
  permutation compiled, linked and drawn, with the renderer's program cache emptied first.
- static switch toggle -> frame, warm: the same flips once both permutations are cached by
  structure hash: compile, no link, draw.
- a plain frame, for comparison.
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")


def main(argv=None) -> int:
    quick = "--quick" in (argv if argv is not None else sys.argv[1:])
    n_edit, n_switch = (8, 3) if quick else (30, 7)
    from matedit.compiler import compile_document
    from matedit.io.document import FileResolver
    from matedit.io.instance import load_instance, resolve
    from matedit.render import Renderer
    from matedit.render.context import headless_context
    from matedit.resources import graphs_dir

    path = graphs_dir() / "instances" / "worn_paint_red.json"
    ctx = headless_context()
    ren = Renderer(ctx, (512, 512), samples=4, environment="studio")
    resolver = FileResolver()
    doc = load_instance(path)

    def frame() -> None:
        ren.render()
        ctx.finish()

    def build():
        return compile_document(resolve(doc).document, resolver, "glsl330")

    assert ren.set_material(build()).ok
    for _ in range(5):  # llvmpipe compiles its draw variants at the first draws
        frame()
    links = ren.link_count
    edits, plain = [], []
    for i in range(n_edit):  # edits and plain frames side by side: load hits both alike
        t = time.perf_counter()
        doc.parameters["wear_amount"] = 0.3 if i % 2 else 0.7
        r = resolve(doc)
        ren.set_uniforms({"p_wear_amount": r.values["wear_amount"]})
        frame()
        edits.append(time.perf_counter() - t)
        t = time.perf_counter()
        frame()
        plain.append(time.perf_counter() - t)
    edit_links = ren.link_count - links

    def toggle(on: bool) -> float:
        t = time.perf_counter()
        doc.parameters["rust_on"] = on
        assert ren.set_material(build()).ok
        frame()
        return time.perf_counter() - t

    cold, cold_links = [], []
    for i in range(n_switch):
        for p in ren._programs.values():  # an empty program cache: the toggle must link
            p.release()
        ren._programs.clear()
        before = ren.link_count
        cold.append(toggle(i % 2 == 0))
        cold_links.append(ren.link_count - before)
    toggle(True)
    toggle(False)  # both permutations cached now
    warm, before = [], ren.link_count
    for i in range(n_switch * 2):
        warm.append(toggle(i % 2 == 0))
    warm_links = ren.link_count - before
    ren.release()
    ctx.release()

    def ms(xs) -> str:
        return f"{statistics.median(xs) * 1000:.0f}"

    print(f"worn_paint_red (instance of worn_painted_steel), 512² 4x MSAA, medians; "
          f"{n_edit} edits, {n_switch} cold and {2 * n_switch} warm toggles")
    print("| measure | ms | program links |")
    print("|---|---:|---:|")
    print(f"| plain frame | {ms(plain)} | 0 |")
    print(f"| instance parameter edit -> next frame | {ms(edits)} | {edit_links} in "
          f"{n_edit} edits |")
    print(f"| static switch toggle -> frame, cold cache | {ms(cold)} | "
          f"{sum(cold_links)} in {n_switch} toggles |")
    print(f"| static switch toggle -> frame, warm cache | {ms(warm)} | "
          f"{warm_links} in {2 * n_switch} toggles |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
