"""Interop timings per sample, in one run on one EGL context:

- bake 1024²: the GPU attribute pass over UV space (matedit.interop.bake), read back;
- glTF export: bake 1024², encode the PNGs, build and write the .glb (pygltflib);
- MaterialX export: the nodegraph + standard_surface document, validate(), baked EXRs
  (512²) written;
- MaterialX generate: MaterialX's own GLSL generator (MaterialXGenGlsl) on that exported
  document's material, the figure to set the export against.

Run: MESA_SHADER_CACHE_DISABLE=true .venv/bin/python benchmarks/bench_interop.py [--quick]
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "true")


def median(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    import MaterialX as mx
    import numpy as np
    from MaterialX import PyMaterialXGenGlsl as mx_glsl
    from MaterialX import PyMaterialXGenShader as mx_gen

    from matedit.compiler.api import compile_document, lower_and_optimise
    from matedit.compiler.lower import lower_document
    from matedit.interop import bake, gltf, mtlx_export
    from matedit.io.document import FileResolver, load
    from matedit.render.context import headless_context
    from matedit.render.mesh import builtin_mesh
    from matedit.resources import graphs_dir

    quick = "--quick" in sys.argv
    repeat = 1 if quick else 3
    size = 1024
    ctx = headless_context()
    lib = mx.createDocument()
    search = mx.getDefaultDataSearchPath()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), search, lib)
    gen = mx_glsl.GlslShaderGenerator.create()
    gctx = mx_gen.GenContext(gen)
    gctx.registerSourceCodeSearchPath(search)
    mesh = builtin_mesh("sphere")
    print(f"# Interop, {ctx.info['GL_RENDERER']}, MaterialX {mx.__version__}, median of "
          f"{repeat}")
    print("| sample | bake 1024² (ms) | glTF .glb export (ms) | .glb (KiB) | MaterialX export "
          "(ms) | baked nodes | MaterialX GLSL generate (ms) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for path in sorted((graphs_dir() / "materials").glob("*.json")):
            doc = load(path)
            res = FileResolver()
            ir = lower_and_optimise(doc, res)
            cm = compile_document(doc, res, "glsl330", mode="attributes", ir=ir)
            t_bake = median(lambda cm=cm: bake.attributes_gpu(ctx, cm, size), repeat)
            out = folder / f"{path.stem}.glb"

            def export_glb(cm=cm, ir=ir, out=out, stem=path.stem):
                attrs = bake.attributes_gpu(ctx, cm, size)
                emax = float(max(1.0, np.max(attrs["emissive"])))
                attrs["emissive"] = attrs["emissive"] / emax
                maps = bake.maps_from(attrs, ir.attributes, "png")
                gltf.write(gltf.files_for(out, maps, mesh, stem, emax))
            t_gltf = median(export_glb, repeat)
            mout = folder / f"{path.stem}.mtlx"
            result = {}

            def export_mtlx(doc=doc, res=res, mout=mout, stem=path.stem, result=result):
                r = mtlx_export.export_ir(lower_document(doc, res), mout, 512, stem)
                mtlx_export.write(r)
                result["r"] = r
            t_mtlx = median(export_mtlx, repeat)
            mdoc = mx.createDocument()
            mx.readFromXmlString(mdoc, result["r"].text)
            mdoc.importLibrary(lib)
            material = mdoc.getMaterialNodes()[0]
            t_gen = median(lambda m=material: gen.generate(m.getName(), m, gctx), repeat)
            print(f"| {path.stem} | {t_bake * 1e3:.0f} | {t_gltf * 1e3:.0f} | "
                  f"{out.stat().st_size / 1024:.0f} | {t_mtlx * 1e3:.0f} | "
                  f"{len(result['r'].baked)} | {t_gen * 1e3:.0f} |")
    ctx.release()


if __name__ == "__main__":
    main()
