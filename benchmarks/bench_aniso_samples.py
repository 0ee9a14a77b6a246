"""Split sum against the reference on the anisotropic samples (not a test).

    .venv/bin/python benchmarks/bench_aniso_samples.py

The loop of tests/test_render.py::test_split_sum_and_reference_agree_on_samples, the same
renderer settings (64 x 64, 4x MSAA, the studio baked small, no lights, 32 reference frames),
for the samples that write `anisotropy`: mean |split sum - reference| over the image,
relative to the reference's mean, and the ratio of their means (energy).
"""

from __future__ import annotations

import sys

import numpy as np

from matedit.compiler import compile_document
from matedit.ibl import BakeSettings
from matedit.io import document as fmt
from matedit.io.document import FileResolver
from matedit.render import Renderer
from matedit.resources import graphs_dir

SMALL = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)


def main() -> int:
    import moderngl

    ctx = moderngl.create_standalone_context(require=330, backend="egl")
    r = Renderer(ctx, (64, 64), samples=4, environment="studio", bake_settings=SMALL)
    r.show_gizmos = False
    r.set_lights([])
    r.reference_frames = 32
    paths = sorted((graphs_dir() / "materials").glob("*.json"))
    for path in paths:
        doc = fmt.load(path)
        cm = compile_document(doc, FileResolver())
        if "anisotropy" not in cm.ir.attributes:
            continue
        r.set_material(cm)
        r.mode = "splitsum"
        r.render()
        split = r.read_hdr().copy()
        r.mode = "reference"
        r.render_converged()
        ref = r.read_hdr("reference").copy()
        rel = np.abs(split - ref).mean() / max(ref.mean(), 1e-6)
        print(f"{path.stem:28s} rel {rel:6.3f}  split/ref mean {split.mean() / ref.mean():6.3f}")
        sys.stdout.flush()
    r.release()
    ctx.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
